//! Mobility DOF(2) = DOF(1) − rank Φ_q of the reference structures, computed by the engine:
//! single block 1, trilithon 1, four-hinge arch 1, 2×2 colonnade on rocking bases 2 (with
//! redundant closure rows), a spatial four-hinge loop with non-parallel axes 0 (locked).

use crr_dynamics::mobility;
use crr_kinematics::fixtures::{
    colonnade, four_hinge_arch, single_block, skew_four_hinge_loop, trilithon,
};
use crr_kinematics::{ActivePivots, Model, Side, StructureSpec};
use nalgebra::DVector;

fn mobility_at_rest(spec: &StructureSpec) -> crr_dynamics::Mobility {
    let model = Model::from_spec(spec).unwrap();
    mobility(
        &model,
        &DVector::zeros(model.dof()),
        &ActivePivots::uniform(&model, Side::Positive),
    )
}

#[test]
fn single_block_has_one_dof() {
    let m = mobility_at_rest(&single_block(0.2, 1.0, 2500.0));
    assert_eq!((m.dof1, m.rank, m.dof2, m.locked), (1, 0, 1, false));
}

#[test]
fn trilithon_has_one_dof() {
    let m = mobility_at_rest(&trilithon(0.25, 1.5, 2.0, 0.5, 1.0));
    // Three tree coordinates; the planar hinge closure has rank 2 of its 5 rows.
    assert_eq!(
        (m.dof1, m.closures, m.constraint_rows, m.rank, m.dof2),
        (3, 1, 5, 2, 1)
    );
}

#[test]
fn four_hinge_arch_has_one_dof() {
    for two_sided in [false, true] {
        let m = mobility_at_rest(&four_hinge_arch(4.0, 4.6, 1.0, two_sided));
        assert_eq!(
            (m.dof1, m.rank, m.dof2),
            (3, 2, 1),
            "two_sided = {two_sided}"
        );
    }
}

#[test]
fn colonnade_has_two_dof_with_redundant_rows() {
    let m = mobility_at_rest(&colonnade(0.2, 1.5, 1.0, 0.3));
    assert_eq!(m.dof1, 10);
    assert_eq!(m.constraint_rows, 12);
    assert_eq!(m.dof2, 2, "{m:?}");
    assert_eq!(m.redundant, 12 - m.rank);
    assert!(m.redundant > 0);
}

#[test]
fn skew_four_hinge_loop_is_locked() {
    let m = mobility_at_rest(&skew_four_hinge_loop());
    assert_eq!((m.dof1, m.dof2, m.locked), (3, 0, true), "{m:?}");
}
