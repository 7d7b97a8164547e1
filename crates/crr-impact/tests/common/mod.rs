//! Shared references for the simulation tests: the exact free-rocking quarter period by
//! Gauss–Legendre quadrature of the energy integral, a structure released from rest, and a run
//! to its end.
// Each test binary uses part of it.
#![allow(dead_code)]

use std::collections::BTreeMap;

use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::{InitialSpec, InitialState, solve_initial};
use crr_impact::{Parameters, Simulation, Trajectory};
use crr_kinematics::Model;

/// The run of `model` from `init` under `ground`, to its end: a run that stops with an error
/// fails the test with that error.
pub fn run_to_end(
    model: &Model,
    ground: &GroundMotion,
    init: &InitialState,
    params: Parameters,
) -> Trajectory {
    Simulation::new(model, ground, init, params)
        .unwrap()
        .run()
        .unwrap_or_else(|f| panic!("the run stops: {}", f.error))
}

/// The consistent initial state of `model` released from rest with coordinate `name` at
/// `angle` (rad), the loops closed by [`solve_initial`].
pub fn released_at(model: &Model, name: &str, angle: f64) -> InitialState {
    solve_initial(
        model,
        &InitialSpec {
            angles: BTreeMap::from([(name.into(), angle)]),
            ..Default::default()
        },
    )
    .unwrap()
}

/// Gauss–Legendre nodes and weights on [0, 1] (Newton on Pₙ).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            ((1.0 - x) / 2.0, 1.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Time for a block (p, α) to fall from rest at amplitude A to θ = 0: τ(A) = ∫₀ᴬ dθ/θ̇ with
/// θ̇² = 2p²[cos(α − A) − cos(α − θ)]. The substitution θ = A(1 − v²) removes the endpoint
/// singularity; 8 panels of 40-point Gauss–Legendre then give round-off accuracy.
pub fn fall_time(p: f64, alpha: f64, a: f64) -> f64 {
    let nodes = gauss_legendre(40);
    let panels = 8;
    let mut total = 0.0;
    for k in 0..panels {
        let (lo, hi) = (k as f64 / panels as f64, (k + 1) as f64 / panels as f64);
        for &(x, w) in &nodes {
            let v = lo + (hi - lo) * x;
            let theta = a * (1.0 - v * v);
            let f = (alpha - a).cos() - (alpha - theta).cos();
            // dθ = 2 A v dv; near v = 0, f ≈ A v² sin(α − A), so the ratio stays finite.
            let integrand = if v == 0.0 {
                2.0 * a / (2.0 * p * p * a * (alpha - a).sin()).sqrt()
            } else {
                2.0 * a * v / (2.0 * p * p * f).sqrt()
            };
            total += w * (hi - lo) * integrand;
        }
    }
    total
}
