//! The static multiplier (`crr::analysis::static_multiplier`, `crr check`'s `static_multipliers`): the
//! static theorem's linear program on the contact faces (`crr_impact::statics`), against the
//! limit-analysis closed forms of the bundled structures (kinematic theorem: the horizontal load
//! λ m g at each centroid against the weight, in the virtual motion of the mechanism) and the
//! one-DOF mechanism reports (λ = U′(0)/|Q_h(0)|, a different computation).
//!
//! Tolerance 1e-8 relative: the interior-point solver stops at a duality gap of 1e-12 (in units
//! of the structure's weight), and its λ agrees with the closed forms to a few 1e-11.
use crate::common;

use nalgebra::Vector3;

use crate::common::bundled_model as bundled;
use crr::analysis::check::check;
use crr::analysis::static_multiplier::{static_multiplier, static_multipliers};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-8 * b.abs()
}

/// Rigid rocking of a stack of boxes (centre heights zᵢ, volumes Vᵢ, one density) about a base
/// edge at distance b from the centre line: λ = b ΣVᵢ / ΣVᵢzᵢ.
fn stack_lambda(b: f64, boxes: &[(f64, f64)]) -> f64 {
    let v: f64 = boxes.iter().map(|(v, _)| v).sum();
    let vz: f64 = boxes.iter().map(|(v, z)| v * z).sum();
    b * v / vz
}

#[test]
fn closed_forms_of_the_bundled_structures() {
    // Housner's block 0.4 × 2 m: tan α = b/h = 0.2.
    let single = 0.2;
    // Two blocks (0.6 × 0.6 × 1.5 under 0.4 × 0.4 × 1.6): the stack rocks as one body on its base
    // (0.2403) before the upper block rocks on the lower (b/h = 0.2/0.8 = 0.25).
    let stack = stack_lambda(0.3, &[(0.6 * 0.6 * 1.5, 0.75), (0.4 * 0.4 * 1.6, 2.3)]);
    // Eight drums 0.6 × 0.6 × 0.5 and a capital 1 × 1 × 0.4 at 4.2 m: the column as one body.
    let mut drums: Vec<(f64, f64)> = (0..8).map(|i| (0.18, 0.25 + 0.5 * i as f64)).collect();
    drums.push((0.4, 4.2));
    let column = stack_lambda(0.3, &drums);
    // Baldachin and trilithon: a frame of equal columns rocks at tan α of a column whatever its
    // cap (Makris & Vassiliou 2013): b/h = 0.2/1.5 and the trilithon's 0.125.
    for (name, lambda, along_y) in [
        ("single_block", single, None),
        ("two_block_stack", stack, None),
        ("drum_column", column, None),
        ("baldachin", 0.2 / 1.5, Some(0.2 / 1.5)),
        ("trilithon", 0.125, None),
        // The bundled wall's corner wedge by hand (examples/models/wall.toml): 7/11.
        ("wall", 7.0 / 11.0, None),
    ] {
        let all = static_multipliers(&bundled(name)).unwrap();
        assert_eq!(all.len(), 4);
        for s in &all {
            let expected = if s.direction[0] != 0.0 {
                Some(lambda)
            } else {
                along_y
            };
            match (s.lambda, expected) {
                (Some(l), Some(e)) => {
                    assert!(close(l, e), "{name} {:?}: {l} against {e}", s.direction)
                }
                // Planar hinges about y: no motion across the plane at any load.
                (None, None) => assert!(s.opening.is_empty()),
                (l, e) => panic!("{name} {:?}: {l:?} against {e:?}", s.direction),
            }
        }
    }
}

/// Every one-DOF bundled mechanism: λ along its mechanism direction equals the equivalent block's
/// λ = U′(0)/|Q_h(0)| of `crr check`, in both senses (the arch is not symmetric about a pivot
/// switch, but its λ is the same both ways by its mirror symmetry).
#[test]
fn one_dof_mechanisms_agree_with_the_equivalent_block() {
    for name in ["single_block", "trilithon", "arch", "two_block_stack"] {
        let report = check(&bundled(name));
        let Some(m) = report.mechanism.as_ref() else {
            continue;
        };
        let d = Vector3::from(m.direction);
        for sense in [1.0, -1.0] {
            let s = static_multiplier(&bundled(name), d * sense).unwrap();
            let l = s.lambda.unwrap();
            assert!(
                close(l, m.lambda),
                "{name} {sense}: {l} against {}",
                m.lambda
            );
        }
    }
}

/// A direction with a vertical part: the ground accelerating along d = (dₓ, 0, d_z) loads the block
/// with −λ g dₓ across and changes its weight to m g (1 + λ d_z); it rocks when
/// λ dₓ = (1 + λ d_z) tan α, λ = tan α / (dₓ − d_z tan α) (both senses of x, d_z kept). Bad
/// directions are refused with the reason.
#[test]
fn a_direction_with_a_vertical_part_and_bad_directions() {
    let m = bundled("single_block");
    let tan_alpha: f64 = 0.2;
    for sense in [1.0, -1.0] {
        let d = Vector3::<f64>::new(sense, 0.0, 0.5);
        let unit = d.normalize();
        let expected = tan_alpha / (unit.x.abs() - unit.z * tan_alpha);
        let l = static_multiplier(&m, d).unwrap().lambda.unwrap();
        assert!(close(l, expected), "{sense}: {l} against {expected}");
    }
    let e = static_multiplier(&m, Vector3::zeros()).unwrap_err();
    assert!(e.contains("non-zero"), "{e}");
    let e = static_multiplier(&m, Vector3::new(f64::NAN, 0.0, 0.0)).unwrap_err();
    assert!(e.contains("non-zero finite"), "{e}");
}

/// `crr check --json` carries the four multipliers; the text names them.
#[test]
fn check_reports_the_multipliers() {
    let o = common::crr(&["check", "examples/models/arch_3d.toml", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let all = v["static_multipliers"].as_array().unwrap();
    assert_eq!(all.len(), 4);
    for s in all {
        let l = s["lambda"].as_f64().unwrap();
        assert!(l > 0.3 && l < 0.4, "{s}");
        assert!(!s["opening"].as_object().unwrap().is_empty(), "{s}");
    }
    let o = common::crr(&["check", "examples/models/arch_3d.toml"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("d = +y: λ = 0.347635"), "{text}");
}
