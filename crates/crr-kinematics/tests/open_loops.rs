//! `Model::without_loop_closures`: the chain left when loop-closing interfaces lift off is the
//! model the file would give without them (built independently by `Model::from_spec`, whose
//! spanning tree does not use a loop-closing interface), and a tree interface is refused.

use crr_kinematics::fixtures::{random_chain, running_bond_wall, trilithon, voussoir_arch};
use crr_kinematics::spec::StructureSpec;
use crr_kinematics::{Model, Role};

/// The structure of `spec` without the interfaces named in `open`, as a file without them.
fn spec_without(spec: &StructureSpec, open: &[&str]) -> StructureSpec {
    let mut s = spec.clone();
    s.interface.retain(|i| !open.contains(&i.name.as_str()));
    s
}

/// Every subset of up to two loop closures of `spec`, dropped both ways, gives the same model.
fn check_every_small_subset(spec: &StructureSpec) -> usize {
    let model = Model::from_spec(spec).expect("valid fixture");
    let closing: Vec<usize> = model.closures.iter().map(|c| c.interface).collect();
    assert!(!closing.is_empty(), "{}: the fixture has loops", spec.name);
    let mut checked = 0;
    let mut subsets: Vec<Vec<usize>> = closing.iter().map(|&k| vec![k]).collect();
    for (a, &ka) in closing.iter().enumerate() {
        for &kb in &closing[a + 1..] {
            subsets.push(vec![kb, ka]);
        }
    }
    for open in subsets {
        let names: Vec<&str> = open
            .iter()
            .map(|&k| model.interfaces[k].name.as_str())
            .collect();
        let derived = model.without_loop_closures(&open).expect("closures");
        let rebuilt = Model::from_spec(&spec_without(spec, &names)).expect("still connected");
        assert_eq!(derived, rebuilt, "{}: dropping {names:?}", spec.name);
        assert_eq!(derived.dof(), model.dof());
        checked += 1;
    }
    checked
}

#[test]
fn dropping_loop_closures_is_the_file_without_them() {
    let fixtures = [
        trilithon(0.3, 2.0, 2.0, 0.5, 0.5),
        voussoir_arch(9, 1.0, 1.3, 0.5),
        running_bond_wall(4, 4, 0.6, 0.25, 0.3),
        random_chain(7, 6, 3),
        random_chain(11, 8, 4),
    ];
    let checked: usize = fixtures.iter().map(check_every_small_subset).sum();
    assert!(checked > 20, "{checked} subsets checked");
}

#[test]
fn a_tree_interface_cannot_be_dropped_without_re_rooting() {
    let model = Model::from_spec(&trilithon(0.3, 2.0, 2.0, 0.5, 0.5)).unwrap();
    let tree = model
        .interfaces
        .iter()
        .position(|i| matches!(i.role, Role::Tree { .. }))
        .unwrap();
    let err = model
        .without_loop_closures(&[tree])
        .unwrap_err()
        .to_string();
    assert!(err.contains(&model.interfaces[tree].name), "{err}");
    assert!(err.contains("re-rooted"), "{err}");
    assert!(model.without_loop_closures(&[99]).is_err());
}
