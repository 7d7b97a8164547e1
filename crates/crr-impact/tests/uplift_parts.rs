//! The uplift test batches its single releases over the model's connected parts (one solve
//! releases one seated slot in each part). Checked here against the definition computed
//! independently, one full solve per release: on random forests of chains at random states,
//! with random seated sets and sides, `opening_mode` picks the same release (the strongest
//! opening acceleration above 1e-9 g/size, first in slot order on ties) as the per-release
//! solves, with both forward solvers.

use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::{Dynamics, ForwardSolver};
use crr_impact::simulation::opening_mode;
use crr_kinematics::fixtures::{SplitMix, forest, random_chain, single_block};
use crr_kinematics::*;
use nalgebra::DVector;

/// The best single release by one global solve per (slot, side), the definition of the test.
fn reference(
    model: &Model,
    template: &Dynamics,
    solver: ForwardSolver,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Option<(usize, Side, f64)> {
    let ground = GroundMotion::none();
    let tol = 1e-9 * model.gravity / model.size;
    let mut best: Option<(usize, Side, f64)> = None;
    for &k in &template.seated {
        for side in [Side::Positive, Side::Negative] {
            let mut pivots = template.pivots.clone();
            pivots.sides[k] = side;
            let mut d = Dynamics::new(model, pivots);
            d.solver = solver;
            d.seated = template
                .seated
                .iter()
                .copied()
                .filter(|&s| s != k)
                .collect();
            if d.accelerations(model, &ground, 0.0, q, qdot).is_err() {
                continue;
            }
            let o = side.sign() * d.qddot[k];
            if o > tol && best.is_none_or(|b| o > b.2) {
                best = Some((k, side, o));
            }
        }
    }
    best
}

#[test]
fn batched_releases_match_one_solve_per_release() {
    let mut rng = SplitMix(0xB10C);
    let mut opened = 0;
    for case in 0..60u64 {
        let mut parts: Vec<_> = (0..1 + rng.below(6))
            .map(|i| random_chain(7 * case + i as u64, 1 + rng.below(4), 0))
            .collect();
        for _ in 0..rng.below(4) {
            parts.push(single_block(
                rng.uniform(0.15, 0.4),
                rng.uniform(0.8, 2.0),
                2500.0,
            ));
        }
        let model = Model::from_spec(&forest(&parts, 10.0)).expect("valid forest");
        assert!(model.parts().len() >= parts.len());
        let n = model.dof();
        let mut pivots = ActivePivots::uniform(&model, Side::Positive);
        for s in pivots.sides.iter_mut() {
            if rng.below(2) == 0 {
                *s = Side::Negative;
            }
        }
        // Seated slots hold q = 0 (q̇ = 0); the others are at a random state.
        let seated: Vec<usize> = (0..n).filter(|_| rng.below(3) != 0).collect();
        let q = DVector::from_fn(n, |k, _| {
            if seated.contains(&k) {
                0.0
            } else {
                rng.uniform(-0.3, 0.3)
            }
        });
        let qdot = DVector::from_fn(n, |k, _| {
            if seated.contains(&k) {
                0.0
            } else {
                rng.uniform(-1.0, 1.0)
            }
        });
        for solver in [ForwardSolver::Auto, ForwardSolver::Cholesky] {
            let mut template = Dynamics::new(&model, pivots.clone());
            template.solver = solver;
            template.seated = seated.clone();
            let got = opening_mode(&model, &GroundMotion::none(), &template, 0.0, &q, &qdot);
            let want = reference(&model, &template, solver, &q, &qdot);
            match (&got, want) {
                (None, None) => {}
                (Some(mode), Some((k, side, _))) => {
                    assert_eq!(mode, &vec![(k, side)], "case {case}, {solver:?}");
                    opened += 1;
                }
                _ => panic!("case {case}, {solver:?}: got {got:?}, want {want:?}"),
            }
        }
    }
    // The cases exercise releases, not only seated states that hold.
    assert!(opened > 30, "only {opened} cases opened");
}
