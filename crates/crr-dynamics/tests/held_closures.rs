//! Projections that keep a seated closing joint where it is: the angle of a closure slot and its
//! rate row agree (finite differences of the bodies' poses), and a projection onto the closed
//! loop that holds such a slot leaves its angle unchanged and its rate at 0, while changing the
//! free coordinates only.

use crr_dynamics::closed_chain::{
    held_at, project_positions, project_positions_holding, project_velocities_holding,
};
use crr_dynamics::eom::slot_row;
use crr_dynamics::{InitialSpec, solve_initial};
use crr_kinematics::fixtures::{colonnade, voussoir_arch};
use crr_kinematics::{
    ActivePivots, Data, Model, Side, closure_angles, constraint_residual, forward_kinematics,
    velocities,
};
use nalgebra::DVector;

/// The 9-voussoir arch with every slot on its positive pivot.
fn arch() -> (Model, ActivePivots) {
    let model = Model::from_spec(&voussoir_arch(9, 2.0, 2.5, 1.0)).unwrap();
    let pivots = ActivePivots::uniform(&model, Side::Positive);
    (model, pivots)
}

fn closing_angle(model: &Model, kin: &mut Data, q: &DVector<f64>, pivots: &ActivePivots) -> f64 {
    forward_kinematics(model, kin, q, pivots);
    let mut angles = vec![0.0; model.slot_count - model.dof()];
    closure_angles(model, kin, &mut angles);
    angles[0]
}

/// |Φ| at q in metres.
fn open_by(model: &Model, kin: &mut Data, q: &DVector<f64>, pivots: &ActivePivots) -> f64 {
    forward_kinematics(model, kin, q, pivots);
    constraint_residual(model, kin, pivots, q);
    kin.phi.amax()
}

/// The rate row against central differences of the angle of every closure slot, at q along a
/// direction.
fn check_rate_rows(model: &Model, q: &DVector<f64>, pivots: &ActivePivots) {
    let n = model.dof();
    let mut kin = Data::new(model);
    let dir = DVector::from_fn(n, |k, _| (k as f64 * 0.7 + 0.4).cos());
    let angles_at = |kin: &mut Data, q: &DVector<f64>| {
        forward_kinematics(model, kin, q, pivots);
        let mut angles = vec![0.0; model.slot_count - n];
        closure_angles(model, kin, &mut angles);
        angles
    };
    let h = 1e-6;
    let plus = angles_at(&mut kin, &(q + h * &dir));
    let minus = angles_at(&mut kin, &(q - h * &dir));
    forward_kinematics(model, &mut kin, q, pivots);
    velocities(model, &mut kin, &dir);
    let mut row = DVector::zeros(n);
    for slot in n..model.slot_count {
        let fd = (plus[slot - n] - minus[slot - n]) / (2.0 * h);
        slot_row(model, &kin, slot, &mut row);
        // Central differences: error h² ψ''' ~ 1e-12 relative, and round-off 1e-16/h ~ 1e-10.
        assert!(
            (row.dot(&dir) - fd).abs() <= 1e-8 * fd.abs().max(1.0),
            "slot {slot}: row {} against finite differences {fd}",
            row.dot(&dir)
        );
    }
}

/// ψ̇ = aᵀq̇ for the closure slots, against central differences of their angles along a
/// direction (the angles from the two frames' poses): the rows the held projections use are the
/// angles' derivatives. On the planar arch (a hinge: ψ linear in q) and on the 3D colonnade
/// (four columns under a slab; rocking-base seats, two tilts each) at a closed state with both
/// tilts, where the rows are the exact derivatives.
#[test]
fn a_closure_angle_s_rate_row_is_its_derivative() {
    let (model, pivots) = arch();
    let q = DVector::from_fn(model.dof(), |k, _| 1e-3 * (k as f64 * 1.3).sin());
    check_rate_rows(&model, &q, &pivots);
    let colonnade = Model::from_spec(&colonnade(0.2, 1.5, 1.0, 0.3)).unwrap();
    let tilted = solve_initial(
        &colonnade,
        &InitialSpec {
            angles: [
                ("base_1.1".to_string(), 0.03),
                ("base_1.2".to_string(), -0.02),
            ]
            .into(),
            ..Default::default()
        },
    )
    .unwrap();
    assert!(colonnade.slot_count - colonnade.dof() >= 2);
    check_rate_rows(&colonnade, &tilted.q, &tilted.pivots);
}

/// A closed state with the closing joint turned by ψ₀, a tree coordinate moved so that the loop
/// opens, then projected over the other coordinates: with the closing slot held, Φ = 0 and ψ = ψ₀
/// to round-off; without, the minimum-norm correction turns it (the test has something to catch).
#[test]
fn a_held_closing_joint_keeps_its_angle_through_a_projection() {
    let (model, pivots) = arch();
    let n = model.dof();
    let slot = n;
    let mut kin = Data::new(&model);
    // A closed configuration near rest: the loop closed from a small tilt of the first voussoir.
    let mut q = DVector::zeros(n);
    q[0] = 2e-4;
    let free: Vec<usize> = (1..n).collect();
    project_positions(&model, &mut kin, &pivots, &mut q, Some(&free)).unwrap();
    assert!(open_by(&model, &mut kin, &q, &pivots) < 1e-12);
    let psi0 = closing_angle(&model, &mut kin, &q, &pivots);
    assert!(
        psi0.abs() > 1e-6,
        "the closing joint turns with the mechanism: {psi0}"
    );
    // Open the loop by moving one coordinate, then close it over the others.
    let mut opened = q.clone();
    opened[0] += 3e-6;
    let free: Vec<usize> = (1..n).collect();
    let mut held_q = opened.clone();
    // The target: the angle at the closed state (on the opened one the frames' angle takes the
    // gap too).
    let target = held_at(&model, &mut kin, &q, &pivots, &[slot]);
    project_positions_holding(&model, &mut kin, &pivots, &mut held_q, Some(&free), &target)
        .unwrap();
    assert!(open_by(&model, &mut kin, &held_q, &pivots) < 1e-12);
    let held_psi = closing_angle(&model, &mut kin, &held_q, &pivots);
    assert!(
        (held_psi - psi0).abs() < 1e-12,
        "held: ψ {held_psi} against {psi0}"
    );
    assert_eq!(held_q[0], opened[0], "only the free coordinates change");
    let mut plain_q = opened.clone();
    project_positions(&model, &mut kin, &pivots, &mut plain_q, Some(&free)).unwrap();
    let plain_psi = closing_angle(&model, &mut kin, &plain_q, &pivots);
    assert!(
        (plain_psi - psi0).abs() > 1e-8,
        "without the row the closing joint turns: {plain_psi} against {psi0}"
    );
    // Velocities: any q̇ projected with the slot held has Φ_q q̇ = 0 and ψ̇ = 0, by the angle's
    // finite differences along q̇ (not by the row the projection used).
    let mut qdot = DVector::from_fn(n, |k, _| 0.01 * ((k as f64 * 2.1).cos()));
    project_velocities_holding(
        &model,
        &mut kin,
        &pivots,
        &held_q,
        &mut qdot,
        Some(&free),
        &[slot],
    );
    // Central differences along q̇: the closing angle's rate, and the loop's gap on both sides
    // (|Φ(q ± hq̇)| is second order in h when Φ_q q̇ = 0: h|q̇|²·size ~ 1e-10 m at h = 1e-6, over
    // h, plus round-off 1e-16·size/h).
    let h = 1e-6;
    let rate = (closing_angle(&model, &mut kin, &(&held_q + h * &qdot), &pivots)
        - closing_angle(&model, &mut kin, &(&held_q - h * &qdot), &pivots))
        / (2.0 * h);
    let gap_rate = open_by(&model, &mut kin, &(&held_q + h * &qdot), &pivots).max(open_by(
        &model,
        &mut kin,
        &(&held_q - h * &qdot),
        &pivots,
    )) / h;
    assert!(rate.abs() < 1e-9, "ψ̇ = {rate}");
    assert!(gap_rate < 1e-8, "the loop opens at {gap_rate} m/s");
    // Set on its seat: the target 0 of a seated joint, from the turned state ψ₀.
    let mut seated_q = held_q.clone();
    project_positions_holding(
        &model,
        &mut kin,
        &pivots,
        &mut seated_q,
        Some(&free),
        &[(slot, 0.0)],
    )
    .unwrap();
    assert!(open_by(&model, &mut kin, &seated_q, &pivots) < 1e-12);
    let seated_psi = closing_angle(&model, &mut kin, &seated_q, &pivots);
    assert!(seated_psi.abs() < 1e-12, "ψ = {seated_psi}");
    assert_eq!(seated_q[0], held_q[0], "only the free coordinates change");
}
