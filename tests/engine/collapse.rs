//! Collapse is reported whenever a structure is past its point of no return, from any initial
//! state, and never for one whose potential energy has not dropped past the threshold
//! (docs/simulation.md, "Collapse"). Initial states a rocking joint cannot have (turned beyond
//! ±π/2, non-finite) are refused with a message naming the joint.

use crate::common;

use crr::RunOptions;
use crr::impact::Trajectory;
use crr::kinematics::Model;

/// The collapse threshold: U − U(rest) < −collapse_drop·W·L (collapse_drop = 1e-3 by default).
fn threshold(model: &Model) -> f64 {
    -1e-3 * model.total_mass() * model.gravity * model.size
}

/// Every collapse reported happened below the threshold; returns the collapse time.
fn checked_collapse(model: &Model, traj: &Trajectory) -> Option<f64> {
    let c = traj.collapse.as_ref()?;
    let last = traj.samples.last().unwrap();
    assert_eq!(last.t, c.t);
    // At the threshold or below it (a start past it). The root is located on the dense output,
    // and the step that lands on it may differ from the interpolant by up to DENSE_TRUST = 1e3
    // tolerances (rtol 1e-10): about 1e-7 relative in the state, hence 1e-6 on U (observed:
    // 1.2e-8 on the block released from 0.25 rad).
    let u_c = threshold(model);
    assert!(
        last.potential <= u_c + 1e-6 * u_c.abs(),
        "collapse at U = {} > {u_c}",
        last.potential
    );
    Some(c.t)
}

#[test]
fn a_block_released_past_its_point_of_no_return_collapses() {
    // α = atan(0.2/1) = 0.197 rad for the bundled block. Between α and 2α it falls over and
    // collapses when U drops past the threshold; beyond 2α its centre is already below the rest
    // height: collapsed at t = 0.
    let text = common::bundled_text("single_block");
    for (angle, at_start) in [
        (0.25, false),
        (0.39, false),
        (0.5, true),
        (1.0, true),
        (-0.5, true),
        (-1.5, true),
    ] {
        let tag = format!("block_{angle}");
        let (model, traj) = common::run_model_text(
            &tag,
            &text.replace("base = 0.1", &format!("base = {angle}")),
            Some(5.0),
        );
        let t = checked_collapse(&model, &traj).unwrap_or_else(|| panic!("{tag}: no collapse"));
        assert_eq!(t == 0.0, at_start, "{tag}: collapse at {t}");
        // It never swings through the ground: the angle stays within ±π/2.
        assert!(traj.samples.iter().all(|s| s.q[0].abs() < 1.6), "{tag}");
    }
    // Inside α it rocks and never collapses.
    let (model, traj) = common::run_model_text(
        "block_0.19",
        &text.replace("base = 0.1", "base = 0.19"),
        Some(5.0),
    );
    assert_eq!(checked_collapse(&model, &traj), None);
}

#[test]
fn impossible_initial_states_are_refused_naming_the_joint() {
    let block = common::bundled_text("single_block");
    for angle in ["1.6", "3.0", "7.0", "-1.6", "1e300", "-1e300"] {
        let path = common::write_model(
            &format!("refused_{angle}"),
            &block.replace("base = 0.1", &format!("base = {angle}")),
        );
        let e = crr::analysis::simulation::prepare(
            &crr::ModelInput::read(&path).unwrap(),
            &RunOptions::default(),
        )
        .expect_err("refused")
        .to_string();
        assert!(
            e.contains("initial angle of base") && e.contains("±π/2"),
            "{angle}: {e}"
        );
    }
    let trilithon = common::bundled_text("trilithon");
    let path = common::write_model(
        "trilithon_2",
        &trilithon.replace("base_left = 0.06", "base_left = 2.0"),
    );
    let e = crr::analysis::simulation::prepare(
        &crr::ModelInput::read(&path).unwrap(),
        &RunOptions::default(),
    )
    .expect_err("refused")
    .to_string();
    assert!(e.contains("±π/2"), "{e}");
}

#[test]
fn pulses_too_short_to_open_a_block_leave_it_at_rest() {
    // A rectangular pulse of 3 m/s² (above g tan α = 1.96 m/s²) lasting ε: the block lifts by
    // about ½·(a − g tan α)/(h)·ε² and sinks back onto its seat; it must never rock through the
    // seat and be reported as collapsed (as it was for ε ≤ 1e-10 s).
    let text =
        common::bundled_text("single_block").replace("[initial]\nangles = { base = 0.1 }\n", "");
    for duration in ["1e-12", "1e-10", "1e-8", "1e-6"] {
        let tag = format!("pulse_{duration}");
        let with_pulse = format!(
            "{text}\n[ground_motion]\nx = {{ rectangular_pulse = {{ amplitude = 3.0, duration = {duration} }} }}\n"
        );
        let (model, traj) = common::run_model_text(&tag, &with_pulse, Some(2.0));
        assert_eq!(checked_collapse(&model, &traj), None, "{tag}");
        let peak = traj
            .samples
            .iter()
            .map(|s| s.q[0].abs())
            .fold(0.0, f64::max);
        // Angular impulse (3 − 1.96) m/s² × ε over a lever of ~1 m: far below 1e-6 rad.
        assert!(peak < 1e-6, "{tag}: peak {peak}");
    }
}
