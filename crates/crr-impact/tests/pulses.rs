//! Uplift and overturning of a block under ground motion (docs/physics.md §6), and activation of a
//! one-DOF mechanism at its multiplier λ.

use std::path::Path;

use crr_dynamics::ground_motion::{
    Axis, ComponentSpec, ConstantSpec, GroundMotion, RectangularPulseSpec, SignalSpec, SineSpec,
};
use crr_dynamics::{InitialSpec, solve_initial};
use crr_impact::{Parameters, Simulation, SlotState, Trajectory};
use crr_kinematics::fixtures::{single_block, trilithon};
use crr_kinematics::{Model, StructureSpec};

const G: f64 = 9.81;

fn ground_x(signal: SignalSpec) -> GroundMotion {
    GroundMotion::none()
        .with_component(Axis::X, &ComponentSpec::new(signal), Path::new("."))
        .unwrap()
}

fn run_from_rest(spec: &StructureSpec, ground: &GroundMotion, duration: f64) -> Trajectory {
    let model = Model::from_spec(spec).unwrap();
    let init = solve_initial(&model, &InitialSpec::default()).unwrap();
    let params = Parameters {
        duration,
        ..Parameters::default()
    };
    Simulation::new(&model, ground, &init, params)
        .unwrap()
        .run()
        .map_err(|f| f.error)
        .unwrap()
}

/// A block at rest under a(t) = A sin(2πt/T) uplifts when A sin(2πt/T) = g tan α, on the edge
/// away from the acceleration (the effective gravity −a_x pushes it towards −x).
#[test]
fn uplift_under_a_sine_pulse() {
    let (b, h): (f64, f64) = (0.2, 1.0);
    let alpha: f64 = (b / h).atan();
    for (a, period) in [(3.0, 0.5), (5.0, 1.0), (2.2, 0.3)] {
        let ground = ground_x(SignalSpec::Sine(SineSpec {
            amplitude: a,
            period: Some(period),
            frequency: None,
            phase: 0.0,
            cycles: Some(1.0),
            start: 0.0,
        }));
        let traj = run_from_rest(&single_block(b, h, 2500.0), &ground, period / 2.0);
        let expected = period / (2.0 * std::f64::consts::PI) * (G * alpha.tan() / a).asin();
        let t_up = traj.uplift_time.expect("the block uplifts");
        // Located by bisection on the release test to the integrator's event tolerance.
        assert!(
            (t_up - expected).abs() < 1e-9,
            "A = {a}: uplift at {t_up}, expected {expected}"
        );
        let after = traj.samples.iter().find(|s| s.t > t_up + 1e-3).unwrap();
        assert_eq!(after.states[0], SlotState::Negative, "rocks on the −x edge");
        assert!(after.q[0] < 0.0);
    }
    // Below the threshold it never uplifts.
    let ground = ground_x(SignalSpec::Sine(SineSpec {
        amplitude: 0.98 * G * alpha.tan(),
        period: Some(0.5),
        frequency: None,
        phase: 0.0,
        cycles: Some(1.0),
        start: 0.0,
    }));
    let traj = run_from_rest(&single_block(b, h, 2500.0), &ground, 0.5);
    assert!(traj.uplift_time.is_none());
    assert!(traj.samples.iter().all(|s| s.q[0] == 0.0));
}

/// A ground velocity step ΔV (a rectangular pulse ΔV/τ lasting τ = 1e-5 s) gives θ̇₀ = 3ΔV cos α/(4R);
/// the block overturns iff θ̇₀² ≥ 2p²(1 − cos α). Tested 2 % below and above the threshold.
#[test]
fn velocity_step_overturning_threshold() {
    let (b, h): (f64, f64) = (0.2, 1.0);
    let (alpha, r): (f64, f64) = ((b / h).atan(), (b * b + h * h).sqrt());
    let p2 = 3.0 * G / (4.0 * r);
    let dv_critical = (2.0 * p2 * (1.0 - alpha.cos())).sqrt() * 4.0 * r / (3.0 * alpha.cos());
    let tau = 1e-5;
    for (factor, overturns) in [(0.98, false), (1.02, true)] {
        let dv = factor * dv_critical;
        let ground = ground_x(SignalSpec::RectangularPulse(RectangularPulseSpec {
            amplitude: dv / tau,
            duration: tau,
            start: 0.0,
        }));
        let traj = run_from_rest(&single_block(b, h, 2500.0), &ground, 6.0);
        // The rate right after the step: 3ΔV cos α/(4R) to O(τ).
        let after = traj.samples.iter().find(|s| s.t >= 0.01).unwrap();
        assert!(after.q[0] < 0.0);
        assert_eq!(
            traj.collapse.is_some(),
            overturns,
            "ΔV = {factor} ΔV_c: collapse {:?}",
            traj.collapse
        );
        if !overturns {
            assert!(!traj.impacts.is_empty(), "it rocks back and impacts");
        } else {
            assert_eq!(traj.collapse.as_ref().unwrap().body, "block");
        }
    }
    // The rate imparted by the step, checked on its own at the end of the pulse.
    let dv = 0.5 * dv_critical;
    let ground = ground_x(SignalSpec::RectangularPulse(RectangularPulseSpec {
        amplitude: dv / tau,
        duration: tau,
        start: 0.0,
    }));
    let model = Model::from_spec(&single_block(b, h, 2500.0)).unwrap();
    let init = solve_initial(&model, &InitialSpec::default()).unwrap();
    let mut sim = Simulation::new(
        &model,
        &ground,
        &init,
        Parameters {
            duration: 1.0,
            ..Parameters::default()
        },
    )
    .unwrap();
    while sim.time() < tau {
        sim.step().unwrap();
    }
    let expected = -3.0 * dv * alpha.cos() / (4.0 * r);
    // During the pulse gravity acts for τ: relative error O(g τ/ΔV + θ̇τ) < 1e-4.
    assert!(
        (sim.qdot()[0] - expected).abs() < 1e-4 * expected.abs(),
        "{} vs {expected}",
        sim.qdot()[0]
    );
}

/// Rectangular pulse of duration t₁ from rest, overturning without impact (linearised):
/// a_min/(gα) = 1/(1 − e^(−p t₁)). At α = 0.05 the engine's exact threshold, found by bisection on
/// the amplitude, is within 1 %.
#[test]
fn rectangular_pulse_threshold_at_small_slenderness() {
    let alpha: f64 = 0.05;
    let h: f64 = 1.0;
    let b = h * alpha.tan();
    let r = (b * b + h * h).sqrt();
    let p = (3.0 * G / (4.0 * r)).sqrt();
    for pt1 in [0.5, 1.0, 2.0] {
        let t1 = pt1 / p;
        let pt1_f: f64 = pt1;
        let predicted = G * alpha / (1.0 - (-pt1_f).exp());
        let overturns = |a: f64| {
            let ground = ground_x(SignalSpec::RectangularPulse(RectangularPulseSpec {
                amplitude: a,
                duration: t1,
                start: 0.0,
            }));
            run_from_rest(&single_block(b, h, 2500.0), &ground, t1 + 8.0 / p)
                .collapse
                .is_some()
        };
        let (mut lo, mut hi) = (0.8 * predicted, 1.2 * predicted);
        assert!(!overturns(lo) && overturns(hi));
        for _ in 0..14 {
            let mid = 0.5 * (lo + hi);
            if overturns(mid) { hi = mid } else { lo = mid }
        }
        let found = 0.5 * (lo + hi);
        eprintln!(
            "p t₁ = {pt1}: a_min/(gα) engine {:.5}, linearised {:.5}",
            found / (G * alpha),
            predicted / (G * alpha)
        );
        assert!(
            (found / predicted - 1.0).abs() < 0.01,
            "p t₁ = {pt1}: {found} vs {predicted}"
        );
    }
}

/// A trilithon at rest under a constant ground acceleration activates at a_x = g λ with
/// λ = tan α (the collapse multiplier): 0.5 % above it the frame rocks as a mechanism (all four
/// joints open together), 0.5 % below it stays seated.
#[test]
fn trilithon_activates_at_its_multiplier() {
    let (b, h): (f64, f64) = (0.25, 1.5);
    let alpha: f64 = (b / h).atan();
    let spec = trilithon(b, h, 2.0, 0.5, 1.0);
    for (factor, opens) in [(1.005, true), (0.995, false)] {
        let ground = ground_x(SignalSpec::Constant(ConstantSpec {
            value: factor * G * alpha.tan(),
        }));
        let traj = run_from_rest(&spec, &ground, 0.3);
        assert_eq!(traj.uplift_time.is_some(), opens, "factor {factor}");
        let last = traj.samples.last().unwrap();
        if opens {
            assert_eq!(traj.uplift_time, Some(0.0));
            // Slots: base_left, base_right, top_left, then the closure top_right. Columns on their
            // −x edges, the architrave on the columns' +x corners.
            assert_eq!(
                last.states,
                vec![
                    SlotState::Negative,
                    SlotState::Negative,
                    SlotState::Positive,
                    SlotState::Positive
                ]
            );
            assert!(last.q[0] < -1e-4);
        } else {
            assert!(last.states.iter().all(|s| *s == SlotState::Seated));
        }
    }
}

/// Under a record (linear between samples) a block at rest uplifts where the interpolated
/// acceleration first reaches g tan α: a single triangular spike rising from 0.6 g tan α to
/// 1.5 g tan α between two samples 0.01 s apart crosses the threshold at
/// t* = t₀ + dt (1 − 0.6)/(1.5 − 0.6). The seated state is not integrated (nothing moves): until
/// t* every sample is exactly at rest with no work done.
#[test]
fn uplift_under_a_record_is_located_between_its_samples() {
    use crr_dynamics::ground_motion::Record;
    let (b, h): (f64, f64) = (0.2, 1.0);
    let threshold = G * (b / h);
    let dt = 0.01;
    // Quiet below the threshold for 0.3 s, then the spike's rising side between samples 30 and 31.
    let mut accel: Vec<f64> = (0..=30)
        .map(|i| 0.6 * threshold * (i as f64 / 30.0))
        .collect();
    accel.extend([1.5 * threshold, 0.0, 0.0]);
    let ground =
        GroundMotion::from_record(Axis::X, Record::uniform(dt, accel).unwrap(), 1.0).unwrap();
    let expected = 30.0 * dt + dt * (1.0 - 0.6) / (1.5 - 0.6);
    let traj = run_from_rest(&single_block(b, h, 2500.0), &ground, 0.4);
    let t_up = traj.uplift_time.expect("the block uplifts");
    // Bisection to 1e-13·max(1, t) on the release test; its threshold (an opening acceleration
    // of 1e-9 g/L) is passed tol/(dφ̈/dt) ≈ 8e-11 s after the acceleration crosses g tan α.
    assert!(
        (t_up - expected).abs() < 1e-9,
        "uplift at {t_up}, expected {expected}"
    );
    for s in traj.samples.iter().filter(|s| s.t < t_up) {
        assert_eq!(
            (s.q[0], s.qdot[0], s.kinetic, s.work_in),
            (0.0, 0.0, 0.0, 0.0)
        );
        assert_eq!(s.states[0], SlotState::Seated);
    }
    // Output samples every 0.01 s through the rest, none missing.
    let before = traj.samples.iter().filter(|s| s.t < t_up).count();
    assert_eq!(before, 31, "samples at 0, 0.01, …, 0.30 s");
    let after = traj.samples.iter().find(|s| s.t > t_up).unwrap();
    assert!(
        after.q[0] < 0.0 && after.qdot[0] < 0.0,
        "rocks on the −x edge"
    );
    assert_eq!(after.states[0], SlotState::Negative);
}
