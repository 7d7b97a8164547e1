//! `Dynamics::loop_residual`, the closure rows' Φ_q q̈ + Φ̇_q q̇, against the second difference of
//! Φ itself along the path q(t) = q₀ + t q̇ + ½t² q̈ (whose second derivative at t = 0 is exactly
//! that), for arbitrary q₀, q̇, q̈ on structures with loops of hinges and of rocking bases.

use crr_dynamics::eom::Dynamics;
use crr_dynamics::ground_motion::GroundMotion;
use crr_kinematics::fixtures::{colonnade, voussoir_arch};
use crr_kinematics::{ActivePivots, Data, Model, Side, constraint_residual, forward_kinematics};
use nalgebra::DVector;

/// The largest closure row of d²Φ/dt² by central differences, an orientation row times the
/// model size (as `loop_residual` reports it).
fn second_difference(model: &Model, pivots: &ActivePivots, q: &[DVector<f64>; 3], h: f64) -> f64 {
    let mut kin = Data::new(model);
    let mut phi = |q: &DVector<f64>| {
        forward_kinematics(model, &mut kin, q, pivots);
        constraint_residual(model, &mut kin, pivots, q);
        kin.phi.clone()
    };
    let (minus, zero, plus) = (phi(&q[0]), phi(&q[1]), phi(&q[2]));
    let mut worst: f64 = 0.0;
    for closure in &model.closures {
        for r in 0..closure.rows {
            let i = closure.first_row + r;
            let d2 = (plus[i] - 2.0 * zero[i] + minus[i]) / (h * h);
            worst = worst.max(if r < 3 { d2 } else { d2 * model.size }.abs());
        }
    }
    worst
}

fn check(tag: &str, model: &Model, side: Side) {
    let n = model.dof();
    let pivots = ActivePivots::uniform(model, side);
    let mut d = Dynamics::new(model, pivots.clone());
    for seed in 0..3 {
        let s = seed as f64;
        let q0 = DVector::from_fn(n, |k, _| 0.02 * ((k as f64 + 1.0) * (0.9 + s)).sin());
        let v = DVector::from_fn(n, |k, _| 0.3 * ((k as f64) * 1.3 + s).cos());
        let a = DVector::from_fn(n, |k, _| ((k as f64) * 0.7 + 2.0 * s).sin());
        d.evaluate(model, &GroundMotion::none(), 0.0, &q0, &v);
        d.qddot.copy_from(&a);
        let own = d.loop_residual(model);
        // h = 1e-4 s: truncation h²/12 · Φ'''' (Φ'''' of order 1 m/s⁴ here) about 1e-9, round-off
        // 4 ε |Φ| / h² (|Φ| below the model size, 3 m) about 1e-7; the values are of order 1.
        let h = 1e-4;
        let path = |t: f64| &q0 + &v * t + &a * (0.5 * t * t);
        let fd = second_difference(model, &pivots, &[path(-h), path(0.0), path(h)], h);
        eprintln!("{tag}, seed {seed}: {own:.9e} against {fd:.9e}");
        assert!(
            own > 1e-2,
            "{tag}, seed {seed}: an arbitrary q̈ leaves the loops open ({own})"
        );
        assert!(
            (own - fd).abs() <= 1e-5 * own.max(1.0),
            "{tag}, seed {seed}: loop_residual {own} against the second difference {fd}"
        );
    }
}

#[test]
fn the_loop_residual_is_the_second_derivative_of_the_closures() {
    let arch = Model::from_spec(&voussoir_arch(9, 2.0, 2.5, 1.0)).unwrap();
    assert!(!arch.closures.is_empty());
    check("9-voussoir arch", &arch, Side::Positive);
    check("9-voussoir arch", &arch, Side::Negative);
    let columns = Model::from_spec(&colonnade(0.5, 2.0, 2.0, 0.4)).unwrap();
    assert!(!columns.closures.is_empty());
    check("colonnade", &columns, Side::Positive);
    check("colonnade", &columns, Side::Negative);
}
