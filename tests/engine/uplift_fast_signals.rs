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

#[test]
fn a_fast_sine_uplifts_at_its_first_crossing_of_the_threshold() {
    let (g, tan_alpha, amplitude): (f64, f64, f64) = (9.81, 0.2, 100.0);
    for f in [499.0, 500.0, 501.0, 1000.0] {
        let (_, traj) = common::run_model_text(
            &format!("tiny_sine_{f}"),
            &tiny_block(&format!(
                "sine = {{ amplitude = {amplitude}, frequency = {f} }}"
            )),
            None,
        );
        let expected = (g * tan_alpha / amplitude).asin() / (2.0 * std::f64::consts::PI * f);
        let uplift = traj.uplift_time.expect("it uplifts");
        assert!(
            (uplift - expected).abs() < 1e-9,
            "{f} Hz: uplift at {uplift} s against {expected} s"
        );
        assert!(
            traj.peak_abs[0] > 1e-3,
            "{f} Hz: it rocks ({})",
            traj.peak_abs[0]
        );
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
