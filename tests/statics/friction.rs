//! The collapse multiplier grows with the friction coefficient: with Coulomb's pyramid of a
//! larger μ every distribution of a smaller one stays admissible (the same equilibrium, the
//! same compressions, a wider bound on the shears), so max λ cannot fall, and without sliding
//! (μ → ∞) it is the largest. The search for sliding lift-offs (`statics::sliding_lift_offs`)
//! relies on it: where its probe with the smallest μ does not lower λ, it solves no other.

use nalgebra::Vector3;

use crate::common::bundled_model as bundled;
use crr::impact::statics::{Friction, StaticsOptions, collapse_multiplier};
use crr::kinematics::Model;
use crr::kinematics::fixtures::{running_bond_wall, running_bond_wall_3d};

/// The bundled temple, wall and trilithon and two walls in running bond (planar and 3D), along
/// ±x and ±y: λ(0.25) ≤ λ(0.5) ≤ λ(1) ≤ λ(2) ≤ λ(no sliding), each to 1e-7 of the larger (the
/// statics' interior point solves to 1e-12, and an answer only almost solved is accepted with
/// clarabel's reduced tolerances, 5e-5 on the gap; the largest fall here was 1.6e-12 of λ;
/// "holds up to the bound" counts as the bound). Some pair grows strictly,
/// so that the order is not met by equal values alone.
#[test]
fn the_multiplier_grows_with_the_friction_coefficient() {
    let models = [
        bundled("temple"),
        bundled("wall"),
        bundled("trilithon"),
        Model::from_spec(&running_bond_wall(4, 3, 0.6, 0.25, 0.3)).unwrap(),
        Model::from_spec(&running_bond_wall_3d(3, 3, 0.6, 0.25, 0.3)).unwrap(),
    ];
    let frictions = [
        Friction::Pyramid(0.25),
        Friction::Pyramid(0.5),
        Friction::Pyramid(1.0),
        Friction::Pyramid(2.0),
        Friction::NoSliding,
    ];
    let (mut strictly, mut worst_fall) = (0, 0.0f64);
    for model in &models {
        for d in [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()] {
            let lambdas: Vec<f64> = frictions
                .iter()
                .map(|&friction| {
                    let options = StaticsOptions {
                        friction,
                        sliding_lift_off: false,
                        ..StaticsOptions::default()
                    };
                    collapse_multiplier(model, d, &options)
                        .unwrap_or_else(|e| panic!("{} along {d:?}: {e}", model.name))
                        .lambda
                        .unwrap_or(options.lambda_max)
                })
                .collect();
            for (pair, w) in lambdas.windows(2).enumerate() {
                worst_fall = worst_fall.max((w[0] - w[1]) / w[1].abs().max(1e-3));
                assert!(
                    w[0] <= w[1] + 1e-7 * w[1].abs().max(1e-3),
                    "{} along {d:?}: λ falls from {} to {} between {:?} and {:?}",
                    model.name,
                    w[0],
                    w[1],
                    frictions[pair],
                    frictions[pair + 1]
                );
                if w[1] > w[0] * (1.0 + 1e-6) {
                    strictly += 1;
                }
            }
        }
    }
    eprintln!("{strictly} pairs grow strictly; the largest relative fall {worst_fall:.1e}");
    assert!(strictly >= 5, "{strictly} pairs grow strictly");
}
