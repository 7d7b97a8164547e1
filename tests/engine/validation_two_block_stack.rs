//! crr against an independent reference for multi-DOF impacts: Psycharis' planar two-block stack,
//! derived on its own with sympy and integrated with scipy (validation/two_block_stack/: the
//! script, its assumptions and how to regenerate the data). Impact by impact the same joint must
//! impact at the same time (≤ 1e-7 s) and the angles agree at every reference sample (≤ 1e-6 rad),
//! up to where the reference stops (an impacting rate below 1e-3 rad/s, close to seating).

use crate::common;

use std::path::Path;

use crr::RunOptions;

fn read_csv(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

/// Runs the bundled stack with the case's law, initial angles and ground motion, then compares.
fn compare(case: &str, law: &str, base: f64, joint: f64, ground: &str) -> (usize, f64, f64) {
    let text = common::bundled_text("two_block_stack");
    let cut = text.find("[ground_motion]").unwrap();
    let model = format!(
        "{}{ground}\n[initial]\nangles = {{ base = {base}, joint = {joint} }}\n\
         [analysis]\nduration = 3.0\nrtol = 1e-12\natol = 1e-14\n",
        text[..cut].replace(
            "[[interface]]\n",
            &format!("[[interface]]\nimpact = {law}\n")
        )
    );
    let dir = std::env::temp_dir().join(format!("crr-validation-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{case}.toml"));
    std::fs::write(&path, model).unwrap();
    let p = crr::analysis::simulation::prepare(
        &crr::ModelInput::read(&path).unwrap(),
        &RunOptions::default(),
    )
    .unwrap();
    let o = p.run();
    assert!(o.summary.error.is_none(), "{case}: {:?}", o.summary.error);
    let traj = o.trajectory;

    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/two_block_stack/data");
    let reference = read_csv(&data.join(format!("{case}_impacts.csv")));
    assert!(
        reference.len() >= 10,
        "{case}: {} reference impacts",
        reference.len()
    );
    let mut worst_t: f64 = 0.0;
    for (i, r) in reference.iter().enumerate() {
        let t: f64 = r[0].parse().unwrap();
        let imp = traj
            .impacts
            .get(i)
            .unwrap_or_else(|| panic!("{case}: crr has only {i} impacts"));
        assert_eq!(
            imp.interfaces,
            vec![r[1].clone()],
            "{case}: impact {i} at {t}"
        );
        worst_t = worst_t.max((imp.t - t).abs());
        assert!(
            (imp.t - t).abs() <= 1e-7,
            "{case}: impact {i}: crr {} vs {t}",
            imp.t
        );
    }
    let rows = read_csv(&data.join(format!("{case}.csv")));
    let mut worst_q: f64 = 0.0;
    for r in &rows {
        let t: f64 = r[0].parse().unwrap();
        // The output samples of crr are at k·0.01 s like the reference's (pre/post-impact samples
        // are in between): the first sample at that time.
        let s = traj
            .samples
            .iter()
            .find(|s| (s.t - t).abs() < 1e-9)
            .unwrap_or_else(|| panic!("{case}: no crr sample at {t}"));
        for k in 0..2 {
            let q: f64 = r[1 + k].parse().unwrap();
            worst_q = worst_q.max((s.q[k] - q).abs());
        }
    }
    assert!(worst_q <= 1e-6, "{case}: angles differ by {worst_q:e} rad");
    eprintln!(
        "{case}: {} impacts, worst impact-time difference {worst_t:.2e} s, {} samples, worst angle difference {worst_q:.2e} rad",
        reference.len(),
        rows.len()
    );
    (reference.len(), worst_t, worst_q)
}

#[test]
fn free_rocking_with_the_momentum_law() {
    compare("free_momentum", "\"momentum\"", 0.02, -0.03, "");
    compare("free_momentum_b", "\"momentum\"", -0.015, -0.04, "");
}

#[test]
fn free_rocking_with_restitution() {
    compare("free_restitution", "{ restitution = 0.9 }", 0.02, -0.03, "");
}

#[test]
fn rocking_under_a_one_sine_pulse_with_the_momentum_law() {
    compare(
        "pulse_momentum",
        "\"momentum\"",
        0.01,
        0.02,
        "[ground_motion]\nx = { one_sine_pulse = { amplitude = 2.0, period = 0.6 } }\n",
    );
}
