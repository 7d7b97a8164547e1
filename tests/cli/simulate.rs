//! `crr simulate` on the bundled models: the files, their columns, the summary keys documented in
//! docs/outputs.md, the free-rocking closed forms of the single block, and every error path.

use crate::common::{crr, scratch};
use std::path::Path;

fn simulate(model: &str, out: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["simulate", model, "--out", out.to_str().unwrap(), "--quiet"];
    args.extend_from_slice(extra);
    let o = crr(&args);
    assert!(
        o.status.success(),
        "{model}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Top-level keys of summary.json listed in docs/outputs.md (rows "| `key` |" of its section).
fn documented_summary_keys() -> Vec<String> {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/outputs.md"))
            .unwrap();
    let section = doc
        .split("## summary.json")
        .nth(1)
        .expect("a summary.json section")
        .split("\n## ")
        .next()
        .unwrap();
    let mut keys: Vec<String> = section
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .map(|l| l.split('`').next().unwrap().to_string())
        .filter(|k| !k.contains('.'))
        .collect();
    keys.sort();
    keys
}

#[test]
fn single_block_files_columns_and_closed_forms() {
    let out = scratch("single_block");
    let s = simulate(
        "examples/models/single_block.toml",
        &out,
        &["--duration", "5"],
    );
    // Keys as documented.
    let mut keys: Vec<String> = s.as_object().unwrap().keys().cloned().collect();
    keys.sort();
    assert_eq!(keys, documented_summary_keys());
    assert_eq!(s["completed"], true);
    assert_eq!(s["crr_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(s["model"]["gravity"], 9.81);
    // history.csv header.
    let hist = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert_eq!(
        hist.lines().next().unwrap(),
        "t,base,base_rate,kinetic,potential,work_in,dissipated,base_state"
    );
    for line in hist.lines().skip(1) {
        assert_eq!(line.split(',').count(), 8, "{line}");
    }
    let imp = std::fs::read_to_string(out.join("impacts.csv")).unwrap();
    assert_eq!(
        imp.lines().next().unwrap(),
        "t,interfaces,rates_before,rates_after,energy_lost,opened"
    );
    // Closed forms: θ̈ = −p² sin(α − θ) for θ > 0; a quarter cycle from θm takes
    // τ = ∫₀^θm dθ / √(2p²(cos(α − θm) − cos(α − θ))); at each impact θ̇⁺ = r θ̇⁻ with
    // r = 1 − 1.5 sin²α, so cos(α − θₙ₊₁) − cos α = r²(cos(α − θₙ) − cos α).
    let (b, h, g): (f64, f64, f64) = (0.2, 1.0, 9.81);
    let alpha = (b / h).atan();
    let p2 = 3.0 * g / (4.0 * b.hypot(h));
    let r = 1.0 - 1.5 * alpha.sin().powi(2);
    let tau = |tm: f64| {
        // θ = θm − u²: the integrand 2u/√(…) is smooth; Simpson with 2000 intervals.
        let f = |u: f64| {
            let th = tm - u * u;
            let d = 2.0 * p2 * ((alpha - tm).cos() - (alpha - th).cos());
            if u == 0.0 {
                2.0 / (2.0 * p2 * (alpha - tm).sin()).sqrt()
            } else {
                2.0 * u / d.sqrt()
            }
        };
        let (a, z, n) = (0.0, tm.sqrt(), 2000);
        let hh = (z - a) / n as f64;
        let mut sum = f(a) + f(z);
        for i in 1..n {
            sum += f(a + i as f64 * hh) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        sum * hh / 3.0
    };
    let mut theta = 0.1;
    let mut t = tau(theta);
    let mut times = Vec::new();
    while t < 5.0 {
        times.push(t);
        let c = (alpha.cos() + r * r * ((alpha - theta).cos() - alpha.cos())).acos();
        theta = alpha - c;
        t += 2.0 * tau(theta);
    }
    let engine: Vec<f64> = imp
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(s["impacts"], times.len());
    assert_eq!(engine.len(), times.len());
    for (e, c) in engine.iter().zip(&times) {
        // Integration tolerance 1e-10 and Simpson's rule: 1e-6 s is generous.
        assert!((e - c).abs() < 1e-6, "impact at {e} vs closed form {c}");
    }
    let peak = s["coordinates"][0]["peak_abs"].as_f64().unwrap();
    assert!((peak - 0.1).abs() < 1e-12);
    let ratio = s["coordinates"][0]["peak_over_alpha"].as_f64().unwrap();
    assert!((ratio - 0.1 / alpha).abs() < 1e-12);
    assert!(s["collapse"]["collapsed"] == false);
    assert!(s["energy_balance_error"].as_f64().unwrap() < 1e-4);
}

/// The bundled baldachin: four identical columns under a rigid slab form a spatial parallelogram
/// mechanism. Every column carries the same tilts, the slab translates without rotating (its
/// tilts on column 1 undo the column's: top_1.1 = −base_1.2, top_1.2 = base_1.1), the columns
/// uplift on their corners at the closed-form instant, every impact involves all eight contacts
/// and dissipates, and the energy balance closes.
#[test]
fn baldachin_is_a_translating_parallelogram_mechanism() {
    let out = scratch("baldachin_full");
    let s = simulate("examples/models/baldachin.toml", &out, &[]);
    assert_eq!(s["completed"], true);
    assert_eq!(s["collapse"]["collapsed"], false);
    // Uplift: each component's one-sine pulse A sin(ωt) reaches g tan α = g b/h (for a corner,
    // tan α_diag = b√2/h against the diagonal acceleration A√2 sin(ωt): the same instant).
    let (a, period, g, b, h): (f64, f64, f64, f64, f64) = (2.0, 0.8, 9.81, 0.2, 1.5);
    let t_uplift = (g * b / (a * h)).asin() / (2.0 * std::f64::consts::PI / period);
    let t_engine = s["uplift_time"].as_f64().unwrap();
    // Uplift is located by the integrator's event search (tolerance 1e-10 relative).
    assert!(
        (t_engine - t_uplift).abs() < 1e-8,
        "{t_engine} vs {t_uplift}"
    );
    let hist = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let header: Vec<&str> = hist.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let mut peak: f64 = 0.0;
    let mut rows = 0;
    for line in hist.lines().skip(1) {
        let v: Vec<f64> = line
            .split(',')
            .take(21)
            .map(|x| x.parse().unwrap())
            .collect();
        let (p1, p2) = (v[col("base_1.1")], v[col("base_1.2")]);
        peak = peak.max(p1.abs()).max(p2.abs());
        // Projection tolerance 1e-13 on closures of 3 m lever arms: 1e-10 rad is generous.
        for k in 2..=4 {
            assert!(
                (v[col(&format!("base_{k}.1"))] - p1).abs() < 1e-10,
                "{line}"
            );
            assert!(
                (v[col(&format!("base_{k}.2"))] - p2).abs() < 1e-10,
                "{line}"
            );
        }
        assert!((v[col("top_1.1")] + p2).abs() < 1e-10, "{line}");
        assert!((v[col("top_1.2")] - p1).abs() < 1e-10, "{line}");
        rows += 1;
    }
    assert!(rows > 400);
    // It rocks (well beyond the uplift) but stays below α = 0.1326.
    assert!(peak > 0.02 && peak < 0.1326, "peak {peak}");
    let imp = std::fs::read_to_string(out.join("impacts.csv")).unwrap();
    let mut impacts = 0;
    for line in imp.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f[1].split(';').count(), 8, "{line}");
        assert!(f[4].parse::<f64>().unwrap() > 0.0, "{line}");
        impacts += 1;
    }
    assert!(impacts >= 4, "{impacts} impacts");
    // Balance: integration tolerance 1e-10 relative on energies of order 1e3 J.
    let balance = s["energy_balance_error"].as_f64().unwrap();
    assert!(balance < 1e-5, "balance {balance} J");
}

#[test]
fn bundled_models_write_the_three_files() {
    for (m, d) in [
        ("trilithon", "2"),
        ("arch", "0.5"),
        ("two_block_stack", "1"),
        ("drum_column", "0.3"),
        ("block_record", "3"),
        ("baldachin", "1"),
        ("trilithon_dirac", "2"),
        ("arch_dirac", "0.5"),
    ] {
        let out = scratch(m);
        let s = simulate(
            &format!("examples/models/{m}.toml"),
            &out,
            &["--duration", d],
        );
        assert_eq!(s["completed"], true, "{m}");
        let hist = std::fs::read_to_string(out.join("history.csv")).unwrap();
        let header: Vec<&str> = hist.lines().next().unwrap().split(',').collect();
        let names: Vec<&str> = s["coordinates"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["name"].as_str().unwrap())
            .collect();
        assert_eq!(header[0], "t");
        assert_eq!(&header[1..=names.len()], names.as_slice());
        assert!(header.iter().any(|c| c.ends_with("_state")));
        assert!(out.join("impacts.csv").exists());
        // No temporary files are left.
        for e in std::fs::read_dir(&out).unwrap() {
            let name = e.unwrap().file_name().into_string().unwrap();
            assert!(!name.starts_with(".partial."), "{m}: {name}");
        }
    }
}

#[test]
fn record_on_the_command_line_overrides_a_component() {
    let out = scratch("record");
    let s = simulate(
        "examples/models/single_block.toml",
        &out,
        &[
            "--duration",
            "1",
            "--record",
            "tests/data/accel_cm.csv",
            "--format",
            "csv",
            "--units",
            "cm/s2",
            "--component",
            "x",
            "--scale",
            "2",
        ],
    );
    assert_eq!(s["record"]["component"], "x");
    assert_eq!(s["record"]["scale"], 2.0);
    assert!(s["ground_motion"]["pga"][0].as_f64().unwrap() > 0.0);
}

fn fails(args: &[&str], needle: &str) {
    let o = crr(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.starts_with("crr: error: "), "{err}");
    assert!(err.contains(needle), "{args:?}: {err} lacks {needle}");
    assert!(!err.contains("panicked"));
}

#[test]
fn errors_name_the_file_or_item_and_exit_2() {
    let dir = scratch("errors");
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    fails(
        &["simulate", "no/such/model.toml", "--out", o],
        "no/such/model.toml",
    );
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\n[[body]]\nname = 3\n").unwrap();
    fails(&["simulate", bad.to_str().unwrap(), "--out", o], "line 3");
    let text = std::fs::read_to_string("examples/models/single_block.toml").unwrap();
    let unknown = dir.join("unknown.toml");
    std::fs::write(&unknown, text.replace("base = 0.1", "bsae = 0.1")).unwrap();
    fails(
        &["simulate", unknown.to_str().unwrap(), "--out", o],
        "\"bsae\"",
    );
    let m = "examples/models/single_block.toml";
    fails(
        &[
            "simulate", m, "--out", o, "--record", "nope.AT2", "--format", "peer-at2",
        ],
        "nope.AT2",
    );
    fails(
        &[
            "simulate",
            m,
            "--out",
            o,
            "--record",
            "tests/data/at2_truncated.AT2",
            "--format",
            "peer-at2",
        ],
        "at2_truncated.AT2",
    );
    fails(
        &[
            "simulate",
            m,
            "--out",
            o,
            "--record",
            "tests/data/accel_cm.csv",
            "--format",
            "csv",
            "--units",
            "cm/s2",
            "--component",
            "w",
        ],
        "--component",
    );
    fails(
        &[
            "simulate",
            m,
            "--out",
            o,
            "--record",
            "tests/data/accel_cm.csv",
            "--format",
            "xls",
        ],
        "--format",
    );
    fails(&["simulate", m, "--out", o, "--duration=-1"], "--duration");
    fails(&["check", "no/such/model.toml"], "no/such/model.toml");
    // clap's own usage errors also exit with 2.
    assert_eq!(crr(&["simulate"]).status.code(), Some(2));
}

/// impacts.csv's `opened` column names the seated joints each impact opened: on the bundled
/// drum column the impact of 0.4021 s opens `bed_3`, `bed_4` and `bed_5` (checked by hand from
/// the bodies' momenta in tests/engine/impulse_tension.rs), and every row names exactly the
/// joints of the library's `ImpactRecord::released` (by slot name), empty where none opened.
#[test]
fn the_impacts_file_names_the_joints_an_impact_opened() {
    let out = scratch("drum_column_opened");
    simulate("examples/models/drum_column.toml", &out, &[]);
    let text = std::fs::read_to_string(out.join("impacts.csv")).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let (model, trajectory) = crate::common::run_model_text(
        "drum_column_opened",
        &crate::common::bundled_text_with_records("drum_column"),
        None,
    );
    assert_eq!(rows.len(), trajectory.impacts.len());
    for (row, impact) in rows.iter().zip(&trajectory.impacts) {
        assert_eq!(row.len(), 6, "{row:?}");
        let named: Vec<String> = impact
            .released
            .iter()
            .map(|&k| model.slot_name(k))
            .collect();
        assert_eq!(row[5], named.join(";"), "the impact at {}", row[0]);
    }
    let at = rows
        .iter()
        .find(|r| (r[0].parse::<f64>().unwrap() - 0.4021).abs() < 1e-4)
        .expect("the impact at 0.4021 s");
    assert_eq!(at[5], "bed_3;bed_4;bed_5");
    assert!(rows.iter().filter(|r| r[5].is_empty()).count() > rows.len() / 2);
}
