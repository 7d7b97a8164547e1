//! `crr inspect` on the bundled single block reports the closed forms: m = ρ·2b·2b·2h, centre
//! (0, 0, h), I_c = m/12 diag(w²+h², …), M(0) = I₀ = (4/3) m R², U = m g h, and −∂U/∂q at θ equal
//! to −m g R sin(α − θ); errors go to stderr with exit code 2.

use crate::common::crr;

fn json(args: &[&str]) -> serde_json::Value {
    let out = crr(args);
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

#[test]
fn single_block_matches_closed_forms() {
    let r = json(&["inspect", "examples/models/single_block.toml", "--json"]);
    let (b, h, rho, g) = (0.2f64, 1.0f64, 2500.0, 9.81);
    let m = rho * (2.0 * b) * (2.0 * b) * (2.0 * h);
    let body = &r["bodies"][0];
    // Mass properties of a box are exact up to a few ulps.
    assert!(close(body["mass"].as_f64().unwrap(), m, 1e-14));
    let c: Vec<f64> = body["center_at_rest"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!(c[0].abs() < 1e-15 && c[1].abs() < 1e-15 && close(c[2], h, 1e-15));
    let i = &body["inertia"];
    let ixx = m * ((2.0 * b).powi(2) + (2.0 * h).powi(2)) / 12.0;
    let izz = m * 2.0 * (2.0 * b).powi(2) / 12.0;
    assert!(close(i[0][0].as_f64().unwrap(), ixx, 1e-13));
    assert!(close(i[1][1].as_f64().unwrap(), ixx, 1e-13));
    assert!(close(i[2][2].as_f64().unwrap(), izz, 1e-13));
    assert!(i[0][1].as_f64().unwrap().abs() < 1e-12 * ixx);
    // M(0) = I₀ = (4/3) m R² about the pivot edge.
    let i0 = 4.0 / 3.0 * m * (b * b + h * h);
    assert!(close(r["mass_matrix"][0][0].as_f64().unwrap(), i0, 1e-13));
    assert!(close(
        r["potential_energy"].as_f64().unwrap(),
        m * g * h,
        1e-14
    ));
    assert_eq!(r["dof"], 1);
    assert_eq!(r["coordinates"][0]["name"], "base");
}

#[test]
fn gravity_moment_at_an_angle() {
    let theta = 0.1;
    let r = json(&[
        "inspect",
        "examples/models/single_block.toml",
        "--json",
        "--q",
        "base=0.1",
    ]);
    let (b, h, g) = (0.2f64, 1.0f64, 9.81);
    let m = 2500.0 * 0.4 * 0.4 * 2.0;
    let (rr, alpha) = ((b * b + h * h).sqrt(), (b / h).atan());
    let expected = -m * g * rr * (alpha - theta).sin();
    assert!(close(
        r["generalized_gravity"][0].as_f64().unwrap(),
        expected,
        1e-12
    ));
    // M(θ) is constant for a single block about a fixed pivot.
    assert!(close(
        r["mass_matrix"][0][0].as_f64().unwrap(),
        4.0 / 3.0 * m * rr * rr,
        1e-13
    ));
    assert_eq!(r["coordinates"][0]["pivot"], "+");
}

#[test]
fn errors_name_the_file_and_item_with_exit_code_2() {
    let out = crr(&["inspect", "examples/models/no_such_model.toml"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no_such_model.toml") && err.contains("cannot read"),
        "{err}"
    );

    let out = crr(&[
        "inspect",
        "examples/models/single_block.toml",
        "--q",
        "bse=0.1",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bse") && err.contains("base"), "{err}");

    let out = crr(&[
        "inspect",
        "examples/models/single_block.toml",
        "--q",
        "base=abc",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a finite number"));

    let dir = std::env::temp_dir().join(format!("crr-inspect-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\n[[body]]\nname = \"a\"\ndensity = 1.0\nbox = { center = [0, 0, 1], size = [1, 1] }\n").unwrap();
    let out = crr(&["inspect", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.toml") && err.contains("line 5"),
        "parse errors give the line: {err}"
    );
    assert!(!err.contains("panicked"));

    let unsafe_model = dir.join("swapped.toml");
    std::fs::write(
        &unsafe_model,
        std::fs::read_to_string("examples/models/single_block.toml")
            .unwrap()
            .replace("axis = [0.0, 1.0, 0.0]", "axis = [0.0, -1.0, 0.0]"),
    )
    .unwrap();
    let out = crr(&["inspect", unsafe_model.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("swapped.toml")
            && err.contains("interface \"base\"")
            && err.contains("pivots swapped"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn json_model_files_are_accepted() {
    let dir = std::env::temp_dir().join(format!("crr-inspect-json-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/models/single_block.toml"
    ))
    .unwrap();
    let spec: crr::input::model_file::ModelFile = toml::from_str(&text).unwrap();
    let path = dir.join("block.json");
    std::fs::write(&path, serde_json::to_string(&spec).unwrap()).unwrap();
    let a = json(&["inspect", path.to_str().unwrap(), "--json"]);
    let b = json(&["inspect", "examples/models/single_block.toml", "--json"]);
    assert_eq!(
        a, b,
        "the same structure from JSON and TOML gives the same report"
    );
    std::fs::remove_dir_all(&dir).ok();
}
