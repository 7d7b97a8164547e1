//! `crr check`: mobility of the bundled models; for the one-DOF ones λ, the equivalent block and r
//! against closed forms, and the engine's free-rocking frequencies against Housner's.

use std::process::Command;

fn check(model: &str) -> serde_json::Value {
    let o = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(["check", model, "--json"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("crr runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn single_block_is_housners_block() {
    let r = check("examples/models/single_block.toml");
    assert_eq!(r["mobility"]["dof1"], 1);
    assert_eq!(r["mobility"]["dof2"], 1);
    let m = &r["mechanism"];
    let (b, h, g): (f64, f64, f64) = (0.2, 1.0, 9.81);
    let alpha = (b / h).atan();
    let f = |k: &str| m[k].as_f64().unwrap();
    assert!((f("lambda") - b / h).abs() < 1e-9);
    assert!((f("alpha_eq") - alpha).abs() < 1e-6);
    assert!((f("p_squared") - 3.0 * g / (4.0 * b.hypot(h))).abs() < 1e-6);
    assert!((f("r") - (1.0 - 1.5 * alpha.sin().powi(2))).abs() < 1e-12);
    let rows = m["frequencies"].as_array().unwrap();
    assert_eq!(rows.len(), 9);
    for row in rows {
        // The exact nonlinear frequency is within 1% of the linearised formula for this block.
        let q = row["ratio"].as_f64().unwrap();
        assert!((q - 1.0).abs() < 0.01, "{row}");
    }
}

#[test]
fn trilithon_is_makris_vassiliou() {
    let r = check("examples/models/trilithon.toml");
    assert_eq!(r["mobility"]["dof1"], 3);
    assert_eq!(r["mobility"]["closures"], 1);
    assert_eq!(r["mobility"]["dof2"], 1);
    let m = &r["mechanism"];
    let (b, h, g): (f64, f64, f64) = (0.25, 2.0, 9.81);
    let alpha = (b / h).atan();
    let gamma = (3.5 * 0.5 * 0.6) / (2.0 * 0.5 * 0.5 * 4.0);
    let p2 = 3.0 * g / (4.0 * b.hypot(h)) * (1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma);
    let rr =
        (1.0 - 1.5 * alpha.sin().powi(2) + 3.0 * gamma * (2.0 * alpha).cos()) / (1.0 + 3.0 * gamma);
    let f = |k: &str| m[k].as_f64().unwrap();
    assert!((f("lambda") - b / h).abs() < 1e-8);
    assert!((f("p_squared") - p2).abs() < 1e-5 * p2);
    assert!((f("r") - rr).abs() < 1e-10);
}

#[test]
fn multi_dof_models_report_mobility_only() {
    let r = check("examples/models/two_block_stack.toml");
    assert_eq!(r["mobility"]["dof2"], 2);
    assert!(r["mechanism"].is_null());
    assert!(r["note"].as_str().unwrap().contains("DOF(2) = 2"));
    // An open chain has no finite-mobility check.
    assert!(r["finite_mobility"].is_null());
    let a = check("examples/models/arch.toml");
    assert_eq!(a["mobility"]["dof2"], 1);
    assert_eq!(a["mobility"]["rank"], 2);
    assert_eq!(a["finite_mobility"]["dof2"], 1);
    // The baldachin's loops close for finite tilts: still two DOF away from rest.
    let b = check("examples/models/baldachin.toml");
    assert_eq!(b["mobility"]["dof2"], 2);
    assert_eq!(b["mobility"]["redundant"], 4);
    assert_eq!(b["finite_mobility"]["dof2"], 2);
    assert!(b["finite_mobility"]["residual"].as_f64().unwrap() < 1e-12);
}

#[test]
fn text_output_has_the_table() {
    let o = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(["check", "examples/models/single_block.toml"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let s = String::from_utf8(o.stdout).unwrap();
    assert!(s.contains("DOF(2) = 1"));
    assert!(s.contains("activation multiplier λ = 0.200000"));
    assert!(s.contains("F_H Housner (Hz)"));
}
