//! The static multiplier of a planar model (every interface a hinge about y) along directions
//! with a part along y, which its hinges carry bilaterally: `out_of_plane` gives that part
//! |d̂·ŷ|, λ answers for the in-plane part only (λ(d)·|d̂ₓ| = λ(+x): the y load is held by the
//! hinges for any λ, so only the x part can open a mechanism), and `crr check` says that ±y is
//! not answered rather than "holds up to 10". Models with rocking bases answer every direction
//! (`out_of_plane` = 0).
//!
//! Tolerances: `out_of_plane` is a dot product of unit vectors (1e-12); λ agrees to 1e-8
//! relative, the linear program's accuracy (docs/check.md).

use nalgebra::Vector3;

use crate::common::{bundled_model as bundled, bundled_path, crr};
use crr::analysis::static_multiplier::{static_multiplier, static_multipliers};

#[test]
fn planar_models_answer_in_their_plane_only() {
    for name in ["wall", "trilithon", "arch", "drum_column", "single_block"] {
        let model = bundled(name);
        let all = static_multipliers(&model).unwrap();
        let plus_x = all[0]
            .lambda
            .expect("every bundled planar model has λ along +x");
        for m in &all {
            let expected = m.direction[1].abs();
            assert!(
                (m.out_of_plane - expected).abs() < 1e-12,
                "{name} {:?}: out_of_plane {}",
                m.direction,
                m.out_of_plane
            );
        }
        // 30° from x towards y: the x part is cos 30°, the y part sin 30° = 1/2.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let m = static_multiplier(&model, Vector3::new(c, s, 0.0)).unwrap();
        assert!(
            (m.out_of_plane - s).abs() < 1e-12,
            "{name}: {}",
            m.out_of_plane
        );
        let lambda = m.lambda.expect("the x part opens a mechanism");
        assert!(
            (lambda * c - plus_x).abs() <= 1e-8 * plus_x,
            "{name}: λ(30°) cos 30° = {} against λ(+x) = {plus_x}",
            lambda * c
        );
    }
}

#[test]
fn models_with_rocking_bases_answer_every_direction() {
    for name in ["arch_3d", "baldachin", "temple"] {
        for m in static_multipliers(&bundled(name)).unwrap() {
            assert_eq!(m.out_of_plane, 0.0, "{name} {:?}", m.direction);
        }
    }
}

#[test]
fn check_says_what_a_planar_model_does_not_answer() {
    let wall = bundled_path("wall");
    let o = crr(&["check", wall.to_str().unwrap()]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for dir in ["+y", "−y"] {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("d = {dir}:")))
            .unwrap_or_else(|| panic!("no line for {dir}:\n{text}"));
        assert!(
            line.contains("not answered") && !line.contains("holds up to"),
            "{line}"
        );
    }
    assert!(text.contains("d = +x: λ = 0.636364"), "{text}");
    let o = crr(&["check", wall.to_str().unwrap(), "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let parts: Vec<f64> = json["static_multipliers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["out_of_plane"].as_f64().unwrap())
        .collect();
    assert_eq!(parts, [0.0, 0.0, 1.0, 1.0]);
}
