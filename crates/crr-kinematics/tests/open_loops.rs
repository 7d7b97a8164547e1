//! `Model::without_loop_closures`: the chain left when loop-closing interfaces lift off is the
//! model the file would give without them (built independently by `Model::from_spec`, whose
//! spanning tree does not use a loop-closing interface), and a tree interface is refused.

use crr_kinematics::fixtures::{
    SplitMix, colonnade_row, random_chain, running_bond_wall, trilithon, voussoir_arch,
};
use crr_kinematics::spec::StructureSpec;
use crr_kinematics::{
    ActivePivots, Data, Interface, Model, Parent, Role, Side, forward_kinematics,
};
use nalgebra::{DVector, Matrix3, Rotation3, Unit, Vector3};

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

/// Opening only loop-closing interfaces keeps the file's tree: the general re-rooting builder
/// gives the model of the file without them, and turns nothing round.
#[test]
fn opening_loop_closures_keeps_the_files_tree() {
    for spec in [
        voussoir_arch(9, 1.0, 1.3, 0.5),
        running_bond_wall(4, 4, 0.6, 0.25, 0.3),
        random_chain(11, 8, 4),
    ] {
        let model = Model::from_spec(&spec).unwrap();
        for cl in &model.closures {
            let (general, turned) = model.with_open_interfaces(&[cl.interface], &[]).unwrap();
            let name = model.interfaces[cl.interface].name.as_str();
            assert_eq!(
                general,
                Model::from_spec(&spec_without(&spec, &[name])).unwrap()
            );
            assert!(turned.iter().all(|t| !t));
        }
        let (same, _) = model.with_open_interfaces(&[], &[]).unwrap();
        assert_eq!(same, model);
    }
}

/// The rotation the file's interface `iface` describes for its angles (file order of the
/// components): R(u, φ) for a hinge, R(e₁, θ₁)R(e₂, θ₂) for a rocking base, and its pivot.
fn file_rotation(iface: &Interface, angles: &[f64]) -> (Matrix3<f64>, Vector3<f64>) {
    let sides: Vec<Side> = angles
        .iter()
        .map(|&a| Side::of(a, Side::Positive))
        .collect();
    let rot = (0..angles.len()).fold(Matrix3::identity(), |r, c| {
        r * Rotation3::from_axis_angle(&Unit::new_normalize(iface.kind.axis(c)), angles[c])
            .into_inner()
    });
    (rot, iface.kind.pivot(&sides))
}

/// A tree interface that opens while its bodies keep other supports: the chain is grown again
/// from the ground, turning round the interfaces it must follow from child to parent. Checked
/// against the file's own definition of every interface kept in the tree: at random angles of
/// the new chain, each one's child turns relative to its parent (the file's parent and child) by
/// the rotation the file's axes give for its angles, and its two bodies meet at the file's pivot.
#[test]
fn a_chain_grown_again_moves_every_tree_interface_as_the_file_defines_it() {
    let mut rng = SplitMix(5);
    let (mut turned_round, mut turned_bases) = (0, 0);
    for spec in [
        trilithon(0.3, 2.0, 2.0, 0.5, 0.5),
        voussoir_arch(7, 1.0, 1.3, 0.5),
        running_bond_wall(4, 3, 0.6, 0.25, 0.3),
        colonnade_row(3, 2),
        random_chain(7, 6, 3),
        random_chain(13, 9, 4),
    ] {
        let file = Model::from_spec(&spec).unwrap();
        for k in 0..file.interfaces.len() {
            let Ok((chain, turned)) = file.with_open_interfaces(&[k], &[]) else {
                continue;
            };
            turned_round += turned.iter().filter(|&&t| t).count();
            turned_bases += turned
                .iter()
                .zip(&chain.interfaces)
                .filter(|(t, i)| **t && i.kind.angle_count() == 2)
                .count();
            let q = DVector::from_fn(chain.dof(), |_, _| rng.uniform(-0.2, 0.2));
            let mut data = Data::new(&chain);
            let pivots = ActivePivots {
                sides: (0..chain.slot_count)
                    .map(|s| Side::of(if s < chain.dof() { q[s] } else { 0.0 }, Side::Positive))
                    .collect(),
            };
            forward_kinematics(&chain, &mut data, &q, &pivots);
            let pose = |b: Option<usize>| match b {
                None => (Matrix3::identity(), Vector3::zeros()),
                Some(b) => {
                    let f = chain.body_coord[b];
                    (data.rot_ops[f], data.frame_translation[f])
                }
            };
            for (j, iface) in chain.interfaces.iter().enumerate() {
                let Role::Tree { first_coord } = iface.role else {
                    continue;
                };
                let f = &file.interfaces[file.interface_index(&iface.name).unwrap()];
                let count = iface.kind.angle_count();
                let mut angles: Vec<f64> = (0..count).map(|c| q[first_coord + c]).collect();
                if turned[j] {
                    angles.reverse();
                }
                let parent = match f.parent {
                    Parent::Ground => None,
                    Parent::Body(b) => Some(b),
                };
                let (rp, tp) = pose(parent);
                let (rc, tc) = pose(Some(f.child));
                let (expected, pivot) = file_rotation(f, &angles);
                let relative = rp.transpose() * rc;
                assert!(
                    (relative - expected).norm() < 1e-12,
                    "{} opened, {}: relative rotation off by {:e}",
                    file.interfaces[k].name,
                    iface.name,
                    (relative - expected).norm()
                );
                let gap = (rc * pivot + tc) - (rp * pivot + tp);
                assert!(
                    gap.norm() < 1e-12 * file.size,
                    "{} opened, {}: pivot apart by {:e} m",
                    file.interfaces[k].name,
                    iface.name,
                    gap.norm()
                );
            }
        }
    }
    assert!(turned_round >= 10, "{turned_round} interfaces turned round");
    assert!(
        turned_bases >= 1,
        "{turned_bases} rocking bases turned round"
    );
}
