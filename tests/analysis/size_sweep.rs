//! `crr check MODEL… --size-sweep s0:s1:n [--amplitude-ratio R]`: geometric scaling laws of the
//! generalized Housner frequency and of the engine's free rocking, several models on one figure,
//! and the errors on bad input.

use std::path::Path;

use crate::common::{crr, scratch};
use serde_json::Value;

fn json(args: &[&str]) -> Value {
    let o = crr(args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

fn f(v: &Value, k: &str) -> f64 {
    v[k].as_f64()
        .unwrap_or_else(|| panic!("{k} is not a number in {v}"))
}

/// Scaling every length by s keeps every angle (α_eq, λ = U′/|Q_h| with both ∝ s⁴), multiplies the
/// masses by s³, U′ and U″ by s⁴ and M by s⁵, so p_eq² = √(U′² + U″²)/M ∝ 1/s and
/// F_H(s) = F_H(1)/√s at the same θm/α_eq. α_eq and p_eq come from U″ by central differences in θ
/// (scale-free), so the formula columns obey the law to round-off: tolerance 1e-9. The engine's
/// free fall is the same motion on the time scale √s, but its error control (rtol 1e-10,
/// atol 1e-12 on θ and θ̇, with θ̇ ∝ 1/√s) does not scale exactly: tolerance 1e-8, a hundred
/// times the integrator's rtol (measured: below 1e-10). Returns the unscaled row.
fn assert_scaling(sweep: &Value, scales: &[f64], mass1: f64, height1: f64) -> Value {
    let rows = sweep["rows"].as_array().unwrap();
    assert_eq!(rows.len(), scales.len());
    let one = rows
        .iter()
        .find(|r| f(r, "scale") == 1.0)
        .expect("the sweep holds s = 1")
        .clone();
    for (r, &s) in rows.iter().zip(scales) {
        assert!((f(r, "scale") - s).abs() < 1e-15, "{r}");
        let m = f(r, "mass");
        assert!(
            (m - mass1 * s.powi(3)).abs() <= 1e-12 * m,
            "mass {m} at s = {s}"
        );
        let h = f(r, "height");
        assert!(
            (h - height1 * s).abs() <= 1e-12 * h,
            "height {h} at s = {s}"
        );
        for k in ["alpha_eq", "lambda", "epsilon"] {
            assert!(
                (f(r, k) - f(&one, k)).abs() <= 1e-9 * f(&one, k),
                "{k} at s = {s}"
            );
        }
        let chi = f(r, "chi") * s;
        assert!((chi - f(&one, "chi")).abs() <= 1e-9 * chi, "χ s at s = {s}");
        for k in ["p_eq", "housner_hz"] {
            let scaled = f(r, k) * s.sqrt();
            assert!(
                (scaled - f(&one, k)).abs() <= 1e-9 * f(&one, k),
                "{k} √s at s = {s}: {scaled} against {}",
                f(&one, k)
            );
        }
        let scaled = f(r, "engine_hz") * s.sqrt();
        let e1 = f(&one, "engine_hz");
        eprintln!(
            "{} s = {s}: engine √s relative deviation {:.2e}",
            sweep["model"],
            (scaled - e1).abs() / e1
        );
        assert!(
            (scaled - e1).abs() <= 1e-8 * e1,
            "engine √s at s = {s}: {scaled} against {e1}"
        );
    }
    one
}

/// The single block 0.4 × 0.4 × 2 m (ρ = 2500, 800 kg): besides the scaling law, the unscaled row
/// is Housner's block, p² = 3g/4R, α = atan(b/h), and F_H(s) at θm = α/2 is
/// √(3g/(4Rs)) / (4 arccosh 2) (p² from U″ by differences: 1e-6 as in `cli_check`).
#[test]
fn single_block_frequency_scales_as_one_over_root_size() {
    let v = json(&[
        "check",
        "examples/models/single_block.toml",
        "--json",
        "--size-sweep",
        "0.5:2:4",
    ]);
    // The check report itself is unchanged: an object with the mechanism, plus the sweep.
    assert_eq!(v["mobility"]["dof2"], 1);
    let sweep = &v["size_sweep"];
    assert_eq!(sweep["amplitude_ratio"], 0.5);
    assert_eq!(sweep["coordinate"], "base");
    let one = assert_scaling(sweep, &[0.5, 1.0, 1.5, 2.0], 800.0, 2.0);
    let (b, h, g): (f64, f64, f64) = (0.2, 1.0, 9.81);
    let r = b.hypot(h);
    assert!((f(&one, "alpha_eq") - (b / h).atan()).abs() < 1e-9);
    assert!((f(&one, "lambda") - b / h).abs() < 1e-9);
    // The sweep's unscaled row is the check report's mechanism.
    assert!((f(&one, "p_eq") - f(&v["mechanism"], "p_eq")).abs() < 1e-12);
    for row in sweep["rows"].as_array().unwrap() {
        let s = f(row, "scale");
        let fh = (3.0 * g / (4.0 * r * s)).sqrt() / (4.0 * 2f64.acosh());
        assert!((f(row, "housner_hz") - fh).abs() < 1e-6 * fh, "{row}");
        assert!((f(row, "theta_m") - 0.5 * (b / h).atan()).abs() < 1e-9);
    }
}

/// Several models: one JSON array, each report with its sweep; the scaling law holds for the
/// trilithon (7625 kg, 4.6 m high) and the arch (2.5 m high) (a closed chain with no closed form; total mass from the
/// annular sectors: 2200 × π (2.5² − 2²)/2 × 1 m); `--plot` draws one housner figure, one
/// size_sweep figure and each model's levels under its own name.
#[test]
fn several_models_share_the_figures_and_obey_the_scaling() {
    let dir = scratch("size_sweep_models");
    let v = json(&[
        "check",
        "examples/models/trilithon.toml",
        "examples/models/arch.toml",
        "--json",
        "--size-sweep",
        "1:4:3",
        "--amplitude-ratio",
        "0.3",
        "--plot",
        dir.to_str().unwrap(),
    ]);
    let a = v.as_array().expect("an array of reports");
    assert_eq!(a.len(), 2);
    assert_eq!(a[0]["model"], "trilithon");
    assert_eq!(a[1]["model"], "arch");
    let arch_mass = 2200.0 * std::f64::consts::PI * (2.5f64.powi(2) - 4.0) / 2.0;
    // Heights: columns 4 m + architrave 0.6 m; the arch's extrados crown 2.5 m above the springings.
    for (r, mass, height) in [(&a[0], 7625.0, 4.6), (&a[1], arch_mass, 2.5)] {
        assert_eq!(r["size_sweep"]["amplitude_ratio"], 0.3);
        assert_scaling(&r["size_sweep"], &[1.0, 2.5, 4.0], mass, height);
    }
    for file in [
        "housner.png",
        "housner.svg",
        "size_sweep.png",
        "size_sweep.svg",
        "trilithon_levels.png",
        "trilithon_levels.csv",
        "arch_levels.svg",
        "arch_levels.csv",
    ] {
        let len = std::fs::metadata(dir.join(file))
            .unwrap_or_else(|e| panic!("{file}: {e}"))
            .len();
        assert!(len > 10_000, "{file}: {len} bytes");
    }
    let svg = std::fs::read_to_string(dir.join("housner.svg")).unwrap();
    assert!(svg.contains("trilithon") && svg.contains("arch"));
    let svg = std::fs::read_to_string(dir.join("size_sweep.svg")).unwrap();
    assert!(
        svg.contains("trilithon")
            && svg.contains("arch")
            && svg.contains("height of the structure")
    );
}

/// Without the new options a single model's JSON stays one object with no sweep.
#[test]
fn single_model_output_is_unchanged() {
    let v = json(&["check", "examples/models/single_block.toml", "--json"]);
    assert!(v.is_object());
    assert!(v.get("size_sweep").is_none());
    let o = crr(&["check", "examples/models/single_block.toml"]);
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(!text.contains("versus size"));
}

/// Bad values: exit 2, a message naming the option, no panic; a model that is not a one-DOF
/// mechanism cannot be swept.
#[test]
fn bad_sweeps_are_input_errors() {
    let model = "examples/models/single_block.toml";
    for (args, option) in [
        (vec!["--size-sweep", "0:2:3"], "--size-sweep"),
        (vec!["--size-sweep", "-1:2:3"], "--size-sweep"),
        (vec!["--size-sweep", "1:2:0"], "--size-sweep"),
        (vec!["--size-sweep", "nan:2:3"], "--size-sweep"),
        (vec!["--size-sweep", "1:inf:3"], "--size-sweep"),
        (vec!["--size-sweep", "1:2"], "--size-sweep"),
        (vec!["--size-sweep", "a:2:3"], "--size-sweep"),
        (vec!["--size-sweep", "1:2:1000000"], "--size-sweep"),
        (vec!["--size-sweep", "1e-300:1e-300:1"], "--size-sweep"),
        (
            vec!["--size-sweep", "1:2:2", "--amplitude-ratio", "1"],
            "--amplitude-ratio",
        ),
        (
            vec!["--size-sweep", "1:2:2", "--amplitude-ratio", "NaN"],
            "--amplitude-ratio",
        ),
        (
            vec!["--size-sweep", "1:2:2", "--amplitude-ratio", "-0.5"],
            "--amplitude-ratio",
        ),
        (vec!["--amplitude-ratio", "0.5"], "--size-sweep"),
    ] {
        let mut all = vec!["check", model];
        all.extend(&args);
        let o = crr(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(option), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    let o = crr(&[
        "check",
        "examples/models/two_block_stack.toml",
        "--size-sweep",
        "1:2:2",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--size-sweep") && err.contains("DOF(2) = 2"),
        "{err}"
    );
}

/// `scale_structure` scales every kind of input length: on the bundled models (boxes, annular
/// sectors, hinges with point and segment pivots, rocking bases) and on a polyhedron and a prism
/// given by its mass (the examples of docs/model-format.md), the scaled model built by
/// `Model::from_spec` (exact mass properties from the shapes) has every mass × s³, density kept,
/// centre × s, inertia tensor × s⁵, pivot points and corners × s and the same axes, and the
/// structure's height × s, to round-off (1e-12 relative).
#[test]
fn scaling_multiplies_every_length() {
    use crr::analysis::size_sweep::scale_structure;
    use crr::input::model_file::parse_model_file;
    use crr::kinematics::{InterfaceKind, Model};
    let frustum = r#"
name = "frustum"
[[body]]
name = "stele"
density = 2400.0
polyhedron = { vertices = [
  [-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0],
  [-0.3, -0.3, 1.5], [0.3, -0.3, 1.5], [0.3, 0.3, 1.5], [-0.3, 0.3, 1.5],
] }
[[interface]]
name = "base"
parent = "ground"
child = "stele"
axis = [0.0, 1.0, 0.0]
pivot_positive = [[0.5, -0.5, 0.0], [0.5, 0.5, 0.0]]
pivot_negative = [[-0.5, -0.5, 0.0], [-0.5, 0.5, 0.0]]
"#;
    let wall = r#"
name = "tapered_wall"
[[body]]
name = "wall"
mass = 3000.0
prism = { polygon = [[-0.3, -1.0, 0.0], [0.3, -1.0, 0.0], [0.2, -1.0, 2.0], [-0.2, -1.0, 2.0]], extrude = [0.0, 2.0, 0.0] }
[[interface]]
name = "toe"
parent = "ground"
child = "wall"
axis = [0.0, 1.0, 0.0]
pivot_positive = [0.3, 0.0, 0.0]
pivot_negative = [-0.3, 0.0, 0.0]
"#;
    let mut files = vec![
        parse_model_file(Path::new("frustum.toml"), frustum).unwrap(),
        parse_model_file(Path::new("wall.toml"), wall).unwrap(),
    ];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models");
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            files.push(crr::load_model(&p).unwrap().0);
        }
    }
    assert!(files.len() >= 10);
    // Heights from the shapes: the frustum 1.5 m, the wall 2 m.
    let height =
        |i: usize| crr::analysis::size_sweep::structure_height(&files[i].structure()).unwrap();
    assert!((height(0) - 1.5).abs() < 1e-15 && (height(1) - 2.0).abs() < 1e-15);
    let s = 2.5f64;
    let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-12 * scale;
    for file in &files {
        let spec = file.structure();
        let m1 = Model::from_spec(&spec).unwrap();
        let ms = Model::from_spec(&scale_structure(&spec, s)).unwrap();
        let l = m1.size * s;
        let (h1, hs) = (
            crr::analysis::size_sweep::structure_height(&spec).unwrap(),
            crr::analysis::size_sweep::structure_height(&scale_structure(&spec, s)).unwrap(),
        );
        assert!((hs - h1 * s).abs() <= 1e-12 * hs, "{}: height", spec.name);
        for (a, b) in m1.bodies.iter().zip(&ms.bodies) {
            assert!(close(b.mass, a.mass * s.powi(3), b.mass), "{}", a.name);
            assert!(close(b.density, a.density, a.density), "{}", a.name);
            assert!((b.com - a.com * s).amax() <= 1e-12 * l, "{}", a.name);
            let i = a.inertia.norm() * s.powi(5);
            assert!(
                (b.inertia - a.inertia * s.powi(5)).amax() <= 1e-12 * i,
                "{}",
                a.name
            );
        }
        for (a, b) in m1.interfaces.iter().zip(&ms.interfaces) {
            match (&a.kind, &b.kind) {
                (
                    InterfaceKind::Hinge {
                        axis: a0,
                        pivot_positive: a1,
                        pivot_negative: a2,
                        ..
                    },
                    InterfaceKind::Hinge {
                        axis: b0,
                        pivot_positive: b1,
                        pivot_negative: b2,
                        ..
                    },
                ) => {
                    assert!((b0 - a0).amax() <= 1e-15, "{}", a.name);
                    assert!((b1 - a1 * s).amax() <= 1e-12 * l, "{}", a.name);
                    assert!((b2 - a2 * s).amax() <= 1e-12 * l, "{}", a.name);
                }
                (
                    InterfaceKind::RockingBase { corners: ca, .. },
                    InterfaceKind::RockingBase { corners: cb, .. },
                ) => {
                    for (p, q) in ca.iter().zip(cb) {
                        assert!((q - p * s).amax() <= 1e-12 * l, "{}", a.name);
                    }
                }
                _ => panic!("{}: the interface kind changed", a.name),
            }
        }
    }
}

/// The sweep reads the mechanism on the side `crr check` reports, whatever the sense the file
/// gives the coordinate: a leaning block (parallelogram section whose centroid lies 0.05 m off
/// its base's centre, 1 m up) written with its hinge in both senses has α_eq = atan 0.15 (its
/// weak side, λ = 0.15) in the report and in the sweep's row at s = 1, and the engine's frequency
/// of that row is the same in both (the sweep read the other side, α_eq atan 0.25, in one).
#[test]
fn the_sweep_reads_the_side_the_report_gives() {
    let block = crate::common::leaning_block;
    let mut engine = Vec::new();
    for (tag, text) in [
        ("sweep_leaning_plus", block(1.0, 0.2, -0.2)),
        ("sweep_leaning_minus", block(-1.0, -0.2, 0.2)),
    ] {
        let path = crate::common::write_model(tag, &text);
        let v = json(&[
            "check",
            path.to_str().unwrap(),
            "--json",
            "--size-sweep",
            "1:2:2",
        ]);
        let report = &v["mechanism"];
        let row = &v["size_sweep"]["rows"][0];
        assert_eq!(f(row, "scale"), 1.0);
        assert!(
            (f(report, "alpha_eq") - 0.15f64.atan()).abs() < 1e-6,
            "{report}"
        );
        assert!(
            (f(row, "alpha_eq") - f(report, "alpha_eq")).abs() < 1e-12,
            "{row}"
        );
        assert!((f(row, "lambda") - 0.15).abs() < 1e-9, "{row}");
        engine.push(f(row, "engine_hz"));
    }
    assert!(
        (engine[0] - engine[1]).abs() < 1e-9 * engine[0],
        "{engine:?}"
    );
}
