//! Closed chains through impacts: the trilithon behaves as its equivalent single block (p̂, and
//! r = (1 − 1.5 sin²α + 3γ cos 2α)/(1 + 3γ)); the four-hinge arch switches to the mirrored
//! mechanism at its first closure and loses energy at every impact.

mod common;

use crr_dynamics::ground_motion::GroundMotion;
use crr_impact::{Parameters, Simulation, SlotState};
use crr_kinematics::Model;
use crr_kinematics::fixtures::{four_hinge_arch, trilithon};

const G: f64 = 9.81;

fn tight(duration: f64) -> Parameters {
    Parameters {
        duration,
        options: crr_dynamics::integrator::Options {
            rtol: 1e-12,
            atol: 1e-14,
            ..Default::default()
        },
        ..Parameters::default()
    }
}

#[test]
fn trilithon_is_its_equivalent_block_through_impacts() {
    let (b, h): (f64, f64) = (0.25, 1.5);
    let (alpha, rr) = ((b / h).atan(), (b * b + h * h).sqrt());
    for gamma in [0.5, 1.0, 2.0] {
        let model = Model::from_spec(&trilithon(b, h, 2.0, 0.5, gamma)).unwrap();
        let init = common::released_at(&model, "base_left", alpha / 2.0);
        let traj = Simulation::new(&model, &GroundMotion::none(), &init, tight(8.0))
            .unwrap()
            .run()
            .map_err(|f| f.error)
            .unwrap();
        let r = (1.0 - 1.5 * alpha.sin().powi(2) + 3.0 * gamma * (2.0 * alpha).cos())
            / (1.0 + 3.0 * gamma);
        let p_hat = (3.0 * G / (4.0 * rr) * (1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma)).sqrt();
        assert!(
            traj.impacts.len() >= 5,
            "γ = {gamma}: {} impacts",
            traj.impacts.len()
        );
        let (mut t, mut level) = (
            common::fall_time(p_hat, alpha, alpha / 2.0),
            (alpha / 2.0).cos() - alpha.cos(),
        );
        let (mut worst_t, mut worst_r): (f64, f64) = (0.0, 0.0);
        for imp in traj.impacts.iter().take(5) {
            // All four joints close together: one simultaneous impact.
            assert_eq!(imp.slots.len(), 4, "{imp:?}");
            assert!(!imp.energy_gain);
            let k = imp.slots.iter().position(|&s| s == 0).unwrap();
            let ratio = imp.rates_after[k] / imp.rates_before[k];
            worst_r = worst_r.max((ratio - r).abs());
            worst_t = worst_t.max((imp.t - t).abs());
            level *= r * r;
            t += 2.0 * common::fall_time(p_hat, alpha, alpha - (level + alpha.cos()).acos());
        }
        eprintln!("trilithon γ = {gamma}: |r − r_MV| ≤ {worst_r:e}, |t − t_block| ≤ {worst_t:e} s");
        assert!(worst_r < 1e-10, "γ = {gamma}: r error {worst_r:e}");
        assert!(worst_t < 1e-8, "γ = {gamma}: impact time error {worst_t:e}");
    }
}

#[test]
fn arch_switches_to_the_mirrored_mechanism_and_loses_energy() {
    let model = Model::from_spec(&four_hinge_arch(4.0, 4.6, 1.0, true)).unwrap();
    let init = common::released_at(&model, "springing_right", 0.01);
    let sides0 = init.pivots.sides.clone();
    let traj = Simulation::new(&model, &GroundMotion::none(), &init, tight(6.0))
        .unwrap()
        .run()
        .map_err(|f| f.error)
        .unwrap();
    assert!(traj.collapse.is_none());
    assert!(traj.impacts.len() >= 2, "{} impacts", traj.impacts.len());
    let first = &traj.impacts[0];
    assert_eq!(
        first.slots.len(),
        4,
        "all four hinges close together: {first:?}"
    );
    // Right after the first closure every hinge rocks on its other pivot: the mirrored mechanism.
    let after = traj.samples.iter().find(|s| s.t > first.t + 1e-3).unwrap();
    for (s, side) in sides0.iter().enumerate() {
        let expected = match side {
            crr_kinematics::Side::Positive => SlotState::Negative,
            crr_kinematics::Side::Negative => SlotState::Positive,
        };
        assert_eq!(after.states[s], expected, "slot {s}");
    }
    // Energy is lost, never gained, at every impact; T + U falls accordingly.
    let mut previous =
        traj.samples.first().unwrap().kinetic + traj.samples.first().unwrap().potential;
    for imp in &traj.impacts {
        assert!(imp.energy_lost > 0.0 && !imp.energy_gain, "{imp:?}");
        let post = traj.samples.iter().rev().find(|s| s.t == imp.t).unwrap();
        let e = post.kinetic + post.potential;
        assert!(
            e < previous,
            "mechanical energy after the impact at {}: {e} ≥ {previous}",
            imp.t
        );
        previous = e;
    }
    // No hinge ever rocks on the wrong pivot (its angle always on the side of its active pivot),
    // and the arch ends at rest with all four hinges seated together.
    for smp in &traj.samples {
        for k in 0..3 {
            let side = match smp.states[k] {
                SlotState::Positive => 1.0,
                SlotState::Negative => -1.0,
                SlotState::Seated => 0.0,
                // No pivot while its face is open: nothing to check.
                SlotState::Open => continue,
            };
            assert!(
                side * smp.q[k] >= -1e-9,
                "t = {}: slot {k} {:?} at {}",
                smp.t,
                smp.states[k],
                smp.q[k]
            );
        }
    }
    assert!(
        traj.samples
            .last()
            .unwrap()
            .states
            .iter()
            .all(|s| *s == SlotState::Seated)
    );
    let e0 = traj.samples.first().unwrap().potential;
    assert!(
        traj.energy_balance_error < 1e-7 * e0,
        "balance {:e} of {e0}",
        traj.energy_balance_error
    );
}
