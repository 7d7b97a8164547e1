//! A planar model (every interface a hinge about y) under a ground motion with a y part: the
//! hinges carry that part bilaterally, so it does no work on any coordinate (Qₖ = m a_y
//! ŷ·(ŷ × (r − pₖ)) = 0 for every hinge about ŷ through pₖ) and the motion is the one without
//! it (while the x part does change it); the run says so in a warning. The hypotheses monitor
//! still sees it: with `friction` set, the friction a y pulse demands at the hinges (sliding out
//! of plane) is reported. A model with rocking bases under two components gets no such warning
//! (it answers for both).
//!
//! The histories with and without the y part agree to 1e-10 (relative to the largest |q|, |q̇|
//! and t): the y part enters the equations only through products that vanish, leaving terms of
//! round-off size (1e-16 of the loads) that the run's impacts amplify (1.3e-12 measured on q̇);
//! a y part that acted would move them by its own order, 3 m/s² against g.

use crate::common::{bundled_text, write_model};

const OUT_OF_PLANE: &str = "the hinges of a planar model carry it bilaterally";
const HINGES: &str = "the model is not planar but has hinges";

fn run(tag: &str, text: &str) -> crr::Run {
    let run = run_any(tag, text);
    assert!(run.completed(), "{tag}: {:?}", run.summary.error);
    run
}

fn run_any(tag: &str, text: &str) -> crr::Run {
    let path = write_model(tag, text);
    let model = crr::ModelInput::read(&path).unwrap_or_else(|e| panic!("{tag}: {e}"));
    let opts = crr::RunOptions {
        duration: Some(3.0),
        ..Default::default()
    };
    crr::run(&model, &opts).unwrap_or_else(|e| panic!("{tag}: {e}"))
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
    // The x pulse acts: the trilithon rocks otherwise without it (from its initial tilt).
    let free = run("trilithon_free", &crate::common::bundled_text("trilithon"));
    let moved = a
        .samples
        .q()
        .iter()
        .zip(free.trajectory.samples.q())
        .fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()));
    assert!(
        moved > 1e-3,
        "the x pulse moves the trilithon by {moved:e} rad only"
    );
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
        run.warnings()
            .iter()
            .all(|w| !w.contains(OUT_OF_PLANE) && !w.contains(HINGES)),
        "{:?}",
        run.warnings()
    );
}

#[test]
fn hinges_in_a_three_dimensional_model_are_named() {
    // One base of the baldachin a hinge about y: the run names it (and only it).
    let mixed = run(
        "baldachin_hinge_base",
        &crate::common::baldachin_with_a_hinge_base(),
    );
    let named: Vec<&String> = mixed
        .warnings()
        .iter()
        .filter(|w| w.contains(HINGES))
        .collect();
    assert_eq!(named.len(), 1, "{:?}", mixed.warnings());
    assert!(named[0].contains("(base_1)"), "{}", named[0]);
    // A planar model's hinges are its model, not a warning.
    let planar = run(
        "trilithon_planar",
        &crate::common::bundled_text("trilithon"),
    );
    assert!(planar.warnings().iter().all(|w| !w.contains(HINGES)));
}

#[test]
fn the_monitor_still_prices_the_friction_the_part_along_the_hinges_needs() {
    // A y pulse of 0.61 g against μ = 0.5: the lintel would slide out of plane.
    let tail = "[analysis]\nfriction = 0.5\n";
    let x = "x = { one_sine_pulse = { amplitude = 2.0, period = 0.8 } }";
    let y = "y = { one_sine_pulse = { amplitude = 6.0, period = 0.5 } }";
    let in_plane = run_any(
        "trilithon_mu_x",
        &format!("{}\n{tail}", with_ground_motion("trilithon", x)),
    );
    let both = run_any(
        "trilithon_mu_xy",
        &format!(
            "{}\n{tail}",
            with_ground_motion("trilithon", &format!("{x}\n{y}"))
        ),
    );
    assert!(
        in_plane.trajectory.violation.is_none(),
        "{:?}",
        in_plane.trajectory.violation
    );
    let v = both
        .trajectory
        .violation
        .as_ref()
        .expect("the y pulse's friction demand is reported");
    assert_eq!(v.kind, "sliding", "{v:?}");
    // A sliding violation is a demand |F_t|/N above μ.
    assert!(v.friction_demand > 0.5, "{v:?}");
}

/// The single block turned by θ = 0.3 rad about x (its hinge axis rises θ from the horizontal):
/// the hinge carries g sin θ along the axis and the block rocks under g cos θ in its plane, the
/// bundled block's motion with g scaled by cos θ, so every time scales by 1/√cos θ (the equations
/// of motion scaled by g, the impact laws independent of it). The first five impacts (4 s) from the
/// same 0.1 rad tilt agree so to 1e-8 relative (2e-12 measured; the impact times are located to round-off); the run
/// warns about the inclined axis, the upright block's not.
#[test]
fn an_inclined_hinge_axis_rocks_under_the_in_plane_part_of_gravity() {
    let theta: f64 = 0.3;
    // 4 s: the tilted block's fifth impact comes near 3.5 s.
    let run = |tag: &str, text: &str| {
        let path = write_model(tag, text);
        let model = crr::ModelInput::read(&path).unwrap();
        let opts = crr::RunOptions {
            duration: Some(4.0),
            ..Default::default()
        };
        let run = crr::run(&model, &opts).unwrap();
        assert!(run.completed(), "{tag}: {:?}", run.summary.error);
        run
    };
    let tilted = run(
        "tilted_block_free",
        &format!(
            "{}\n[initial]\nangles = {{ base = 0.1 }}\n",
            crate::common::tilted_block(theta)
        ),
    );
    let upright = run("upright_block_free", &bundled_text("single_block"));
    let (a, b) = (&tilted.trajectory.impacts, &upright.trajectory.impacts);
    assert!(
        a.len() >= 5 && b.len() >= 5,
        "{} and {} impacts",
        a.len(),
        b.len()
    );
    let scale = 1.0 / theta.cos().sqrt();
    for (k, (x, y)) in a.iter().zip(b).take(5).enumerate() {
        assert!(
            (x.t - y.t * scale).abs() <= 1e-8 * x.t,
            "impact {k}: {} against {} / √cos θ = {}",
            x.t,
            y.t,
            y.t * scale
        );
    }
    let tilt = |r: &crr::Run| {
        r.warnings()
            .iter()
            .any(|w| w.contains("from the horizontal"))
    };
    assert!(tilt(&tilted), "{:?}", tilted.warnings());
    assert!(!tilt(&upright), "{:?}", upright.warnings());
}
