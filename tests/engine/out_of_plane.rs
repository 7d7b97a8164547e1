//! A planar model (every interface a hinge about y) under a ground motion with a y part: the
//! hinges carry that part bilaterally, so it does no work on any coordinate (Qₖ = m a_y
//! ŷ·(ŷ × r) = 0 for every hinge about ŷ) and the run is the one without it; the run says so in
//! a warning. A model with rocking bases under the same two components gets no such warning (it
//! answers for both).
//!
//! The histories with and without the y part agree to 1e-10 (relative to the largest |q|, |q̇|
//! and t): the y part enters the equations only through products that vanish, leaving terms of
//! round-off size (1e-16 of the loads) that the run's impacts amplify (1.3e-12 measured on q̇);
//! a y part that acted would move them by its own order, 3 m/s² against g.

use crate::common::{bundled_text, write_model};

const OUT_OF_PLANE: &str = "the hinges of a planar model carry it bilaterally";

fn run(tag: &str, text: &str) -> crr::Run {
    let path = write_model(tag, text);
    let model = crr::ModelInput::read(&path).unwrap_or_else(|e| panic!("{tag}: {e}"));
    let opts = crr::RunOptions {
        duration: Some(3.0),
        ..Default::default()
    };
    let run = crr::run(&model, &opts).unwrap_or_else(|e| panic!("{tag}: {e}"));
    assert!(run.completed(), "{tag}: {:?}", run.summary.error);
    run
}

fn with_ground_motion(name: &str, ground_motion: &str) -> String {
    format!("{}\n[ground_motion]\n{ground_motion}\n", bundled_text(name))
}

#[test]
fn a_planar_model_ignores_and_names_the_part_along_its_hinges() {
    let x = "x = { one_sine_pulse = { amplitude = 2.0, period = 0.8 } }";
    let y = "y = { one_sine_pulse = { amplitude = 3.0, period = 0.5 } }";
    let in_plane = run("trilithon_x", &with_ground_motion("trilithon", x));
    let both = run(
        "trilithon_xy",
        &with_ground_motion("trilithon", &format!("{x}\n{y}")),
    );

    let named = |r: &crr::Run| r.warnings().iter().any(|w| w.contains(OUT_OF_PLANE));
    assert!(
        !named(&in_plane),
        "an in-plane record is warned about: {:?}",
        in_plane.warnings()
    );
    assert!(named(&both), "no warning: {:?}", both.warnings());
    let warning = both
        .warnings()
        .iter()
        .find(|w| w.contains(OUT_OF_PLANE))
        .unwrap();
    // The y pulse's peak, 3 m/s², along the hinges' axis (0, 1, 0).
    assert!(
        warning.contains("(0.000, 1.000, 0.000)") && warning.contains("3.000e0 m/s²"),
        "{warning}"
    );

    let (a, b) = (&in_plane.trajectory, &both.trajectory);
    assert!(!a.impacts.is_empty(), "the trilithon does not rock");
    assert_eq!(a.impacts.len(), b.impacts.len(), "impacts differ");
    assert_eq!(a.samples.len(), b.samples.len(), "sample counts differ");
    for (label, u, v) in [
        ("t", a.samples.times(), b.samples.times()),
        ("q", a.samples.q(), b.samples.q()),
        ("q̇", a.samples.qdot(), b.samples.qdot()),
    ] {
        let scale = u.iter().fold(1e-300_f64, |m, x| m.max(x.abs()));
        let worst = u
            .iter()
            .zip(v)
            .fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()));
        assert!(
            worst <= 1e-10 * scale,
            "{label} differs by {worst:e} (scale {scale:e})"
        );
    }
}

#[test]
fn a_model_with_rocking_bases_answers_for_both_components() {
    // The bundled baldachin: columns on rocking bases under a diagonal pulse (x and y).
    let text = crate::common::bundled_text_with_records("baldachin");
    let run = run("baldachin_xy", &text);
    assert!(
        run.warnings().iter().all(|w| !w.contains(OUT_OF_PLANE)),
        "{:?}",
        run.warnings()
    );
}
