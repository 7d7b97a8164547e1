//! Uplift under ground motions faster than the seated grid. While joints are seated the uplift
//! test runs on a time grid; it was a fixed 1 ms grid, so a 2 cm block under a 500 Hz sine was
//! sampled at the sine's zeros only and never moved (at 499 Hz it uplifted 3 ms late), and a
//! 1–2 ms pulse could be stepped over. The grid is now min(1 ms, shortest period / 32).
//!
//! Checked against the closed form: a block of slenderness tan α = b/h on the ground under
//! a_x = A sin(2πft) uplifts when A sin(2πft) first reaches g tan α, t = asin(g tan α / A)/(2πf)
//! (1e-9 s: the bisection locates the crossing to 1e-13 s; the grid only brackets it).
use crate::common;

/// The block's support: a hinge along y (planar rocking), or a square rocking base whose first
/// tilt is about x (rocking in y) and whose second is about y, on the same ±x edges.
const HINGE: &str = "axis = [0.0, 1.0, 0.0]\npivot_positive = [0.002, 0.0, 0.0]\n\
                     pivot_negative = [-0.002, 0.0, 0.0]";
const SQUARE_BASE: &str = "rocking_base = { corners = [[-0.002, -0.002, 0.0], [0.002, -0.002, 0.0], \
                           [0.002, 0.002, 0.0], [-0.002, 0.002, 0.0]] }";

fn tiny_block(signal: &str) -> String {
    tiny_block_on(HINGE, signal)
}

fn tiny_block_on(support: &str, signal: &str) -> String {
    format!(
        "name = \"tiny\"\ngravity = 9.81\n\
         [[body]]\nname = \"block\"\ndensity = 2500.0\n\
         box = {{ center = [0.0, 0.0, 0.01], size = [0.004, 0.004, 0.02] }}\n\
         [[interface]]\nname = \"base\"\nparent = \"ground\"\nchild = \"block\"\n\
         {support}\n\
         [ground_motion]\nx = {{ {signal} }}\n[analysis]\nduration = 0.02\n"
    )
}

const G: f64 = 9.81;
const TAN_ALPHA: f64 = 0.2;
const AMPLITUDE: f64 = 100.0;
/// The block's half-width b and half-height h (m).
const B: f64 = 0.002;
const H: f64 = 0.01;

/// The run of the tiny block on `support` under A sin(2πft) along x, its model file named by
/// `test` (tests run in parallel: each writes its own files).
fn sine_run(test: &str, support: &str, f: f64) -> crr::Run {
    let tag = format!("tiny_sine_{test}_{f}_{}", support.len());
    let text = tiny_block_on(
        support,
        &format!("sine = {{ amplitude = {AMPLITUDE}, frequency = {f} }}"),
    );
    let path = common::write_model(&tag, &text);
    let model = crr::ModelInput::read(&path).unwrap();
    crr::run(&model, &crr::RunOptions::default()).unwrap()
}

/// Asserts that `run` uplifts at the closed form's instant and stops on the flight of `block`
/// rocking about y on a ±x edge (its coordinate `rocking` of the samples), where the block on a
/// corner's closed form gives a normal force N = m (g + z̈_G) of at most 1e-6 m g; returns the
/// flight's instant.
fn assert_flight_by_closed_form(run: &crr::Run, f: f64, rocking: usize) -> f64 {
    let traj = &run.trajectory;
    let expected = (G * TAN_ALPHA / AMPLITUDE).asin() / (2.0 * std::f64::consts::PI * f);
    let uplift = traj.uplift_time.expect("it uplifts");
    assert!(
        (uplift - expected).abs() < 1e-9,
        "{f} Hz: uplift at {uplift} s against {expected} s"
    );
    let Some(crr::impact::SimulationError::LiftOff { t, in_flight, .. }) = &run.failure else {
        panic!("{f} Hz: {:?}, not a flight", run.failure);
    };
    assert_eq!(in_flight, &["block"], "{f} Hz");
    assert!(*t > uplift, "{f} Hz: flight at {t} s");
    let last = traj.samples.iter().next_back().unwrap();
    assert_eq!(last.t, *t, "{f} Hz: the flight's own sample");
    // The −x corner mirrors the +x one (θ and a_g change sign).
    let sign = match last.states[rocking] {
        crr::impact::SlotState::Positive => 1.0,
        crr::impact::SlotState::Negative => -1.0,
        other => panic!("{f} Hz: the block rocks, not {other:?}"),
    };
    let (theta, rate) = (sign * last.q[rocking], sign * last.qdot[rocking]);
    assert!(theta > 0.0, "{f} Hz: it rocks on its corner ({theta} rad)");
    let a_g = sign * AMPLITUDE * (2.0 * std::f64::consts::PI * f * t).sin();
    let lever = B * theta.sin() + H * theta.cos();
    let theta_dd =
        (-a_g * lever + G * (H * theta.sin() - B * theta.cos())) / (4.0 / 3.0 * (B * B + H * H));
    let z_dd = (B * theta.cos() - H * theta.sin()) * theta_dd - lever * rate * rate;
    let normal = (G + z_dd) / G;
    println!("{f} Hz: flight at {t} s, θ = {theta:.3e} rad, N = {normal:.2e} m g");
    assert!(
        normal.abs() <= 1e-6,
        "{f} Hz: N = {normal} m g at the flight"
    );
    *t
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
    for f in [499.0, 500.0, 501.0, 1000.0] {
        assert_flight_by_closed_form(&sine_run("hinge", HINGE, f), f, 0);
    }
}

/// The same block on a square rocking base (two tilts) under the same sine along x turns on an
/// edge, its tilt about x seated, and flies where the edge's whole normal force reaches zero:
/// at the closed form's state (|N| ≤ 1e-6 m g) and at the hinge's instant, to 1e-12 s (the
/// two models' events are located to 1e-13 s; measured 7e-17 to 1e-13 s). Before, the edge's
/// force was not watched: the run went on with the edge pulling, the seated tilt released
/// into a rattle about x, and at 499 Hz the block "flew" at 3.24 ms after two impacts, with no
/// hypothesis reported.
#[test]
fn a_block_on_a_square_base_flies_off_its_edge_where_the_planar_block_flies() {
    for f in [499.0, 500.0, 1000.0] {
        let run = sine_run("base", SQUARE_BASE, f);
        let flight = assert_flight_by_closed_form(&run, f, 1);
        let tilt_x_seated = run
            .trajectory
            .samples
            .iter()
            .all(|s| s.states[0] == crr::impact::SlotState::Seated && s.q[0] == 0.0);
        assert!(tilt_x_seated, "{f} Hz: the tilt about x stays seated");
        let planar = assert_flight_by_closed_form(&sine_run("base", HINGE, f), f, 0);
        assert!(
            (flight - planar).abs() <= 1e-12,
            "{f} Hz: flight at {flight} s on the base, {planar} s on the hinge"
        );
    }
}

/// A one-sine pulse of 1.5 ms that starts at 5 ms (after the block has been at rest on the grid):
/// its crossing of g tan α, 5 ms + asin(g tan α / A)/(2π/T), is found.
#[test]
fn a_short_pulse_is_not_stepped_over() {
    let (g, tan_alpha, amplitude, period, start): (f64, f64, f64, f64, f64) =
        (G, TAN_ALPHA, 50.0, 1.5e-3, 5e-3);
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
