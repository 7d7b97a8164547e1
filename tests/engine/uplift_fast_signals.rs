//! Uplift under ground motions faster than the seated grid. While joints are seated the uplift
//! test runs on a time grid; it was a fixed 1 ms grid, so a 2 cm block under a 500 Hz sine was
//! sampled at the sine's zeros only and never moved (at 499 Hz it uplifted 3 ms late), and a
//! 1–2 ms pulse could be stepped over. The grid is now min(1 ms, shortest period / 32).
//!
//! Checked against the closed form: a block of slenderness tan α = b/h on the ground under
//! a_x = A sin(2πft) uplifts when A sin(2πft) first reaches g tan α, t = asin(g tan α / A)/(2πf)
//! (1e-9 s: the bisection locates the crossing to 1e-13 s; the grid only brackets it).
use crate::common;

fn tiny_block(signal: &str) -> String {
    format!(
        "name = \"tiny\"\ngravity = 9.81\n\
         [[body]]\nname = \"block\"\ndensity = 2500.0\n\
         box = {{ center = [0.0, 0.0, 0.01], size = [0.004, 0.004, 0.02] }}\n\
         [[interface]]\nname = \"base\"\nparent = \"ground\"\nchild = \"block\"\n\
         axis = [0.0, 1.0, 0.0]\npivot_positive = [0.002, 0.0, 0.0]\npivot_negative = [-0.002, 0.0, 0.0]\n\
         [ground_motion]\nx = {{ {signal} }}\n[analysis]\nduration = 0.02\n"
    )
}

/// Each run uplifts at the closed form's instant and rocks, and then flies: under 10 g the
/// block's pivot stops pressing as the sine swings back (1.23 ms in at 499–501 Hz, 0.61 ms at
/// 1000 Hz, θ = 3.2e-3 and 8e-4 rad), and the run stops there on the flight of `block` (an
/// open chain's pivot that would pull, docs/simulation.md, "Faces that open"; before, the run
/// went on with the pivot pulling, reported by the monitor at its next sample). That instant is
/// checked against the closed form of a block rocking on a corner of the ground: its contact
/// force's vertical component N = m (g + z̈_G), z_G = b sin θ + h cos θ over the corner
/// (half-width b, half-height h, θ about +y on the +x corner), θ̈ from the moment about the
/// corner, (4/3) R² θ̈ = −a_g (b sin θ + h cos θ) + g (h sin θ − b cos θ), R² = b² + h², at the
/// state the run stops in: |N| ≤ 1e-6 m g (measured 5e-13 to 3.3e-10 m g).
#[test]
fn a_fast_sine_uplifts_at_its_first_crossing_of_the_threshold() {
    let (g, tan_alpha, amplitude): (f64, f64, f64) = (9.81, 0.2, 100.0);
    let (b, h) = (0.002, 0.01);
    for f in [499.0, 500.0, 501.0, 1000.0] {
        let tag = format!("tiny_sine_{f}");
        let path = common::write_model(
            &tag,
            &tiny_block(&format!(
                "sine = {{ amplitude = {amplitude}, frequency = {f} }}"
            )),
        );
        let model = crr::ModelInput::read(&path).unwrap();
        let run = crr::run(&model, &crr::RunOptions::default()).unwrap();
        let traj = &run.trajectory;
        let expected = (g * tan_alpha / amplitude).asin() / (2.0 * std::f64::consts::PI * f);
        let uplift = traj.uplift_time.expect("it uplifts");
        assert!(
            (uplift - expected).abs() < 1e-9,
            "{f} Hz: uplift at {uplift} s against {expected} s"
        );
        match &run.failure {
            Some(crr::impact::SimulationError::LiftOff { t, in_flight, .. }) => {
                assert_eq!(in_flight, &["block"], "{f} Hz");
                assert!(*t > uplift, "{f} Hz: flight at {t} s");
                let last = traj.samples.iter().next_back().unwrap();
                assert_eq!(last.t, *t, "{f} Hz: the flight's own sample");
                // The −x corner mirrors the +x one (θ and a_g change sign).
                let sign = match last.states[0] {
                    crr::impact::SlotState::Positive => 1.0,
                    crr::impact::SlotState::Negative => -1.0,
                    other => panic!("{f} Hz: the block rocks, not {other:?}"),
                };
                let (theta, rate) = (sign * last.q[0], sign * last.qdot[0]);
                assert!(theta > 0.0, "{f} Hz: it rocks on its corner ({theta} rad)");
                let a_g = sign * amplitude * (2.0 * std::f64::consts::PI * f * t).sin();
                let lever = b * theta.sin() + h * theta.cos();
                let theta_dd = (-a_g * lever + g * (h * theta.sin() - b * theta.cos()))
                    / (4.0 / 3.0 * (b * b + h * h));
                let z_dd = (b * theta.cos() - h * theta.sin()) * theta_dd - lever * rate * rate;
                let normal = (g + z_dd) / g;
                println!("{f} Hz: flight at {t} s, θ = {theta:.3e} rad, N = {normal:.2e} m g");
                assert!(
                    normal.abs() <= 1e-6,
                    "{f} Hz: N = {normal} m g at the flight"
                );
            }
            other => panic!("{f} Hz: {other:?}, not a flight"),
        }
    }
}

/// A one-sine pulse of 1.5 ms that starts at 5 ms (after the block has been at rest on the grid):
/// its crossing of g tan α, 5 ms + asin(g tan α / A)/(2π/T), is found.
#[test]
fn a_short_pulse_is_not_stepped_over() {
    let (g, tan_alpha, amplitude, period, start): (f64, f64, f64, f64, f64) =
        (9.81, 0.2, 50.0, 1.5e-3, 5e-3);
    let (_, traj) = common::run_model_text(
        "tiny_pulse",
        &tiny_block(&format!(
            "one_sine_pulse = {{ amplitude = {amplitude}, period = {period}, start = {start} }}"
        )),
        None,
    );
    let expected =
        start + (g * tan_alpha / amplitude).asin() / (2.0 * std::f64::consts::PI / period);
    let uplift = traj.uplift_time.expect("it uplifts");
    assert!(
        (uplift - expected).abs() < 1e-9,
        "uplift at {uplift} s against {expected} s"
    );
}
