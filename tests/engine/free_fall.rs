//! A ground that falls faster than g. Under a vertical ground acceleration a_z below −g the
//! effective gravity g_eff = (0, 0, −g − a_z) points up: every body of a structure at rest falls
//! freely off the ground (no contact force anywhere, each body accelerating with g_eff relative
//! to the ground, every point on the ground moving off its horizontal bed), the one motion
//! Gauss' principle allows. That is outside the CRR model, and the run must stop there as a
//! flight naming every body, not go on seated with a tension warning (as open chains did).
//!
//! Checked against the closed form: under a_z = −A sin(2πt/T) with A = 1.2 g, g_eff turns up
//! when A sin(2πt/T) first reaches g, t* = T asin(g/A)/(2π). The engine's threshold (g_eff · n
//! above 1e-9 g) moves the instant by 1e-9 g/(dA sin/dt at t*) = 2.4e-10 s for T = 1 s, and the
//! uplift bisection locates it to 1e-13 s: 1e-9 s. Until t* every body stays at rest with no
//! hypothesis failing; a ground falling at 0.99 g leaves every structure at rest.
use crate::common;

const G: f64 = 9.81;

/// `text` without the table `[header]` (its header line and the lines up to the next table).
fn without_table(text: &str, header: &str) -> String {
    let mut skipping = false;
    let mut out = String::new();
    for line in text.lines() {
        if line.trim_start().starts_with('[') {
            skipping = line.trim() == header;
        }
        if !skipping {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// The bundled model `name` at rest (no initial tilt) under the vertical ground motion `z`, for
/// `duration` s.
fn at_rest_under(name: &str, z: &str, duration: f64) -> String {
    let text = without_table(&common::bundled_text(name), "[initial]");
    let text = without_table(&text, "[ground_motion]");
    let text = without_table(&text, "[analysis]");
    format!("{text}\n[ground_motion]\nz = {{ {z} }}\n\n[analysis]\nduration = {duration}\n")
}

const MODELS: [&str; 5] = [
    "single_block",
    "two_block_stack",
    "trilithon",
    "arch",
    "baldachin",
];

#[test]
fn a_ground_falling_faster_than_g_throws_every_body_into_flight() {
    let amplitude = 1.2 * G;
    let expected = (G / amplitude).asin() / (2.0 * std::f64::consts::PI);
    for name in MODELS {
        let text = at_rest_under(
            name,
            &format!("sine = {{ amplitude = {}, period = 1.0 }}", -amplitude),
            1.0,
        );
        let path = common::write_model(&format!("free_fall_{name}"), &text);
        let model = crr::ModelInput::read(&path).unwrap();
        let run = crr::run(&model, &crr::RunOptions::default()).unwrap();
        let Some(crr::impact::SimulationError::LiftOff { t, in_flight, .. }) = &run.failure else {
            panic!("{name}: {:?}, not a flight", run.failure);
        };
        assert!(
            (t - expected).abs() < 1e-9,
            "{name}: flight at {t} s against {expected} s"
        );
        let mut bodies: Vec<&str> = run.model.bodies.iter().map(|b| b.name.as_str()).collect();
        let mut flying: Vec<&str> = in_flight.iter().map(String::as_str).collect();
        bodies.sort_unstable();
        flying.sort_unstable();
        assert_eq!(flying, bodies, "{name}: every body flies");
        // Until then the structure stands still, and nothing it was asked to hold pulled.
        let traj = &run.trajectory;
        assert!(traj.impacts.is_empty(), "{name}: no impact");
        assert!(traj.violation.is_none(), "{name}: {:?}", traj.violation);
        for s in traj.samples.iter() {
            assert!(
                s.q.iter().chain(s.qdot.iter()).all(|&x| x == 0.0),
                "{name}: moved at {} s",
                s.t
            );
        }
    }
}

/// A constant a_z = −1.01 g: the flight is at t = 0. On open chains the uplift test used to
/// release the block onto a pivot there, and the run went on for its whole duration rocking the
/// block about a pivot that pulled (0.37 rad at 10 s), with a tension warning at t = 0 only.
#[test]
fn a_ground_falling_faster_than_g_from_the_start_throws_every_body_off_at_once() {
    for name in MODELS {
        let text = at_rest_under(
            name,
            &format!("constant = {{ value = {} }}", -1.01 * G),
            1.0,
        );
        let path = common::write_model(&format!("thrown_{name}"), &text);
        let model = crr::ModelInput::read(&path).unwrap();
        let run = crr::run(&model, &crr::RunOptions::default()).unwrap();
        let Some(crr::impact::SimulationError::LiftOff { t, in_flight, .. }) = &run.failure else {
            panic!("{name}: {:?}, not a flight", run.failure);
        };
        assert_eq!(*t, 0.0, "{name}");
        assert_eq!(
            in_flight.len(),
            run.model.bodies.len(),
            "{name}: {in_flight:?}"
        );
        assert!(run.trajectory.impacts.is_empty(), "{name}");
    }
}

#[test]
fn a_ground_falling_slower_than_g_leaves_every_structure_at_rest() {
    for name in MODELS {
        let text = at_rest_under(
            name,
            &format!("constant = {{ value = {} }}", -0.99 * G),
            0.5,
        );
        let (_, traj) = common::run_model_text(&format!("slow_fall_{name}"), &text, None);
        assert!(traj.impacts.is_empty(), "{name}: no impact");
        assert!(traj.uplift_time.is_none(), "{name}: no uplift");
        assert!(traj.violation.is_none(), "{name}: {:?}", traj.violation);
        let last = traj.samples.iter().next_back().unwrap();
        assert_eq!(last.t, 0.5, "{name}: the run's end");
        assert!(last.q.iter().all(|&x| x == 0.0), "{name}: {:?}", last.q);
    }
}

/// The bundled block (half-width b = 0.2 m, half-height h = 1 m) at rest under g_eff =
/// (−γ g, 0, ε g), rocking about the −x edge that the horizontal part pushes it over: the
/// pivot's normal force over m g. About the pivot P, r = (b, 0, h) to the centre; the torque of
/// m g_eff about y is m g (−γ h − ε b), I_P = (4/3) m (b² + h²), α = torque / I_P about y, the
/// centre accelerates by α ŷ × r = α (h, 0, −b), and the ground's force is m (a_c − g_eff).
fn pivot_normal_by_hand(gamma: f64, epsilon: f64) -> f64 {
    let (b, h) = (0.2, 1.0);
    let alpha = (-gamma * h - epsilon * b) / (4.0 / 3.0 * (b * b + h * h));
    -alpha * b - epsilon
}

/// With a horizontal part as well, the motion decides: the block released onto its pivot pulls
/// there under a small one (a flight at once: every body, t = 0), and presses under a large one
/// (it rocks, thrown off later, when its pivot's force falls to zero). By hand at t = 0:
/// N = −0.0096 m g under (γ, ε) = (0.001, 0.01), +0.0624 m g under (0.5, 0.01).
#[test]
fn with_a_horizontal_part_the_motion_decides_whether_the_ground_presses() {
    for (gamma, flies_at_once) in [(0.001, true), (0.5, false)] {
        let normal = pivot_normal_by_hand(gamma, 0.01);
        assert_eq!(
            normal < 0.0,
            flies_at_once,
            "γ = {gamma}: N = {normal} m g by hand"
        );
        let text = at_rest_under(
            "single_block",
            &format!("constant = {{ value = {} }}", -1.01 * G),
            1.0,
        )
        .replace(
            "[ground_motion]\n",
            &format!(
                "[ground_motion]\nx = {{ constant = {{ value = {} }} }}\n",
                gamma * G
            ),
        );
        let path = common::write_model(&format!("thrown_across_{gamma}"), &text);
        let model = crr::ModelInput::read(&path).unwrap();
        let run = crr::run(&model, &crr::RunOptions::default()).unwrap();
        let Some(crr::impact::SimulationError::LiftOff { t, in_flight, .. }) = &run.failure else {
            panic!("γ = {gamma}: {:?}, not a flight", run.failure);
        };
        assert_eq!(in_flight, &["block"], "γ = {gamma}");
        if flies_at_once {
            assert_eq!(*t, 0.0, "γ = {gamma}");
        } else {
            assert_eq!(
                run.trajectory.uplift_time,
                Some(0.0),
                "γ = {gamma}: it rocks at once"
            );
            assert!(
                *t > 0.1,
                "γ = {gamma}: thrown off at {t} s, while its pivot pressed"
            );
        }
    }
}

/// A block let go from a tilt (nothing seated, every rate 0) under −1.01 g: its pivot pulls
/// (the bound of `free_fall`'s docs), a flight at t = 0; it used to rock about it.
#[test]
fn a_block_let_go_from_a_tilt_under_a_ground_falling_faster_than_g_flies_at_once() {
    let text = format!(
        "{}\n[initial]\nangles = {{ base = 0.1 }}\n",
        at_rest_under(
            "single_block",
            &format!("constant = {{ value = {} }}", -1.01 * G),
            1.0
        )
    );
    let path = common::write_model("thrown_from_a_tilt", &text);
    let model = crr::ModelInput::read(&path).unwrap();
    let run = crr::run(&model, &crr::RunOptions::default()).unwrap();
    let Some(crr::impact::SimulationError::LiftOff { t, in_flight, .. }) = &run.failure else {
        panic!("{:?}, not a flight", run.failure);
    };
    assert_eq!(
        (*t, in_flight.as_slice()),
        (0.0, ["block".to_string()].as_slice())
    );
}
