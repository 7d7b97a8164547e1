//! Rocking bases that may twist (`twist = true`, loop closures only): the child keeps its pivot
//! corner and its face plane on the parent but may turn about the contact normal. Checked here:
//! the tilt angles are those of the face normal (exact decomposition R(e₁,θ₁)R(e₂,θ₂)R(n,τ)), the
//! slot rows and biases are their first and second time derivatives (central differences along a
//! path), the closure has 3 rows, a tree interface cannot twist, and a temple bay of multi-drum
//! columns under architraves, whose loops move only to first order with rigid contacts (a column
//! tilting about x at one bed and about y at another twists its capital at second order), moves at
//! finite amplitude with twisting closures.
use crate::common;

use nalgebra::{DVector, Rotation3, Unit, Vector3};

use crr::dynamics::eom::{Dynamics, slot_row};
use crr::dynamics::ground_motion::GroundMotion;
use crr::dynamics::{mobility, mobility_after_step};
use crr::kinematics::{ActivePivots, InterfaceKind, Model, Side, closure_angles, relative_angles};

/// The bundled baldachin's text with its three loop-closing tops allowed to twist.
pub(crate) fn twisting_text() -> String {
    let text = common::bundled_text("baldachin");
    let mut out = String::new();
    let mut in_closing_top = false;
    for line in text.lines() {
        if line.starts_with("name = \"top_") {
            in_closing_top = line != "name = \"top_1\"";
        }
        if in_closing_top && line.starts_with("rocking_base") {
            // `rocking_base = { corners = [[…], …] }`: the table's closing brace gains the key.
            out += &line.replace("]] }", "]], twist = true }");
        } else {
            out += line;
        }
        out += "\n";
    }
    out
}

/// The bundled baldachin with its three loop-closing tops allowed to twist, written to a file of
/// its own per test (`tag`): the tests of this file run in parallel.
fn twisting_baldachin(tag: &str) -> Model {
    let path = common::write_model(&format!("baldachin_twist_{tag}"), &twisting_text());
    crr::load_model(&path).unwrap().1
}

#[test]
fn the_tilts_of_a_twisting_base_are_those_of_its_face_normal() {
    let m = twisting_baldachin("angles");
    let k = m.interfaces.iter().position(|i| i.name == "top_2").unwrap();
    let kind = &m.interfaces[k].kind;
    let InterfaceKind::RockingBase {
        normal,
        e1,
        e2,
        twist: true,
        ..
    } = kind
    else {
        panic!("top_2 twists");
    };
    let rot =
        |axis: &Vector3<f64>, a: f64| Rotation3::from_axis_angle(&Unit::new_normalize(*axis), a);
    for (t1, t2, tau) in [
        (0.1, -0.2, 0.3),
        (-0.4, 0.05, -1.2),
        (0.0, 0.0, 0.7),
        (0.3, 0.3, 0.0),
    ] {
        let rel = (rot(e1, t1) * rot(e2, t2) * rot(normal, tau)).into_inner();
        let mut out = [0.0; 2];
        relative_angles(kind, &rel, &mut out);
        assert!(
            (out[0] - t1).abs() < 1e-14 && (out[1] - t2).abs() < 1e-14,
            "{out:?} against ({t1}, {t2}) with twist {tau}"
        );
    }
    // 3 rows per twisting closure instead of 4: 1 rigid closure left (none: top_1 is in the tree).
    assert_eq!(m.closure_rows, 3 * 3);
}

/// ψ(t) along q(t) = q₀ + t q̇ + ½t² q̈: (ψ(h) − ψ(−h))/2h = row·q̇ and
/// (ψ(h) − 2ψ(0) + ψ(−h))/h² = row·q̈ + bias, to the differences' truncation (h² ψ‴/6, h² ψ⁗/12
/// with derivatives of order 1 here: 1e-8 at h = 1e-4) plus round-off (1e-16/h² = 1e-8 for the
/// second difference). The largest errors over these cases are 5.9e-9 (rate) and 3.1e-8
/// (acceleration); the tolerances are 2e-8 and 1e-7, about three times those.
#[test]
fn slot_rows_are_the_derivatives_of_the_twisting_tilts() {
    let m = twisting_baldachin("rows");
    let n = m.dof();
    let ground = GroundMotion::none();
    let mut rng = 0x2545F4914F6CDD1Du64;
    let mut uniform = |lo: f64, hi: f64| {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        lo + (hi - lo) * ((rng >> 11) as f64 / (1u64 << 53) as f64)
    };
    for trial in 0..5 {
        let q0 = DVector::from_fn(n, |_, _| uniform(-0.2, 0.2));
        let qd = DVector::from_fn(n, |_, _| uniform(-1.0, 1.0));
        let qdd = DVector::from_fn(n, |_, _| uniform(-1.0, 1.0));
        let pivots = ActivePivots {
            sides: (0..m.slot_count)
                .map(|s| {
                    if (s + trial) % 3 == 0 {
                        Side::Negative
                    } else {
                        Side::Positive
                    }
                })
                .collect(),
        };
        let angles_at = |t: f64| {
            let q = &q0 + &qd * t + &qdd * (0.5 * t * t);
            let mut d = Dynamics::new(&m, pivots.clone());
            d.evaluate(&m, &ground, 0.0, &q, &(&qd + &qdd * t));
            let mut out = vec![0.0; m.slot_count - n];
            closure_angles(&m, &d.kin, &mut out);
            out
        };
        let h = 1e-4;
        let (ap, a0, am) = (angles_at(h), angles_at(0.0), angles_at(-h));
        let mut d = Dynamics::new(&m, pivots.clone());
        d.evaluate(&m, &ground, 0.0, &q0, &qd);
        let mut row = DVector::zeros(n);
        let mut checked = 0;
        // The twisting closures' slots (the rigid closures' rows are derivatives of their angles
        // only on the closure manifold, and these configurations are random).
        for s in n..m.slot_count {
            let k = m
                .interfaces
                .iter()
                .position(|i| i.slots.contains(&s))
                .unwrap();
            if !matches!(
                m.interfaces[k].kind,
                InterfaceKind::RockingBase { twist: true, .. }
            ) {
                continue;
            }
            let bias = slot_row(&m, &d.kin, s, &mut row);
            checked += 1;
            let i = s - n;
            let rate = (ap[i] - am[i]) / (2.0 * h);
            let accel = (ap[i] - 2.0 * a0[i] + am[i]) / (h * h);
            assert!(
                (row.dot(&qd) - rate).abs() < 2e-8,
                "slot {s}: rate {} against {rate}",
                row.dot(&qd)
            );
            assert!(
                (row.dot(&qdd) + bias - accel).abs() < 1e-7,
                "slot {s}: acceleration {} against {accel}",
                row.dot(&qdd) + bias
            );
        }
        assert_eq!(checked, 6, "the three twisting tops' two tilts");
    }
}

#[test]
fn a_tree_interface_cannot_twist() {
    let text = common::bundled_text("single_block")
        .replace("axis = [0.0, 1.0, 0.0]\n", "")
        .replace(
            "pivot_positive = [[0.2, -0.2, 0.0], [0.2, 0.2, 0.0]]\npivot_negative = [[-0.2, -0.2, 0.0], [-0.2, 0.2, 0.0]]",
            "rocking_base = { corners = [[-0.2, -0.2, 0.0], [0.2, -0.2, 0.0], [0.2, 0.2, 0.0], [-0.2, 0.2, 0.0]], twist = true }",
        );
    assert!(text.contains("twist = true"), "{text}");
    let path = common::write_model("block_twist", &text);
    let e = crr::load_model(&path).unwrap_err().to_string();
    assert!(
        e.contains("interface \"base\"") && e.contains("only on an interface that closes a loop"),
        "{e}"
    );
}

/// The twisting baldachin keeps the parallelogram mechanism (DOF(2) = 2: the slab cannot twist,
/// being held by the rigid top of column 1) at rest and after a finite step, and under its
/// bundled diagonal pulse it moves exactly as the rigid baldachin: no motion of the bundled run
/// needs a twist, so the 3-row closures must give the same run as the 4-row ones (same impacts,
/// peaks to 1e-9 rad, energy dissipated to 1e-9 relative) — a check of the twisting closures'
/// constraints, angles and slot rows inside the whole simulation.
#[test]
fn the_twisting_baldachin_moves_as_the_rigid_one() {
    let m = twisting_baldachin("finite");
    let zero = DVector::zeros(m.dof());
    let rest = mobility(&m, &zero, &ActivePivots::uniform(&m, Side::Positive));
    let finite = mobility_after_step(&m, 0.01).unwrap();
    assert_eq!((rest.dof2, finite.dof2), (2, 2));
    let rigid_text = common::bundled_text("baldachin");
    let (_, rigid) = common::run_model_text("baldachin_rigid", &rigid_text, None);
    let twist_path = common::write_model("baldachin_twist_run", &twisting_text());
    let opts = crr::RunOptions::default();
    let p = crr::analysis::simulation::prepare(&crr::ModelInput::read(&twist_path).unwrap(), &opts)
        .unwrap();
    let twisting = p.run().trajectory;
    assert_eq!(rigid.impacts.len(), twisting.impacts.len());
    assert!(rigid.impacts.len() >= 4);
    for (a, b) in rigid.peak_abs.iter().zip(&twisting.peak_abs) {
        assert!((a - b).abs() < 1e-9, "peak {a} against {b}");
    }
    let lost = |t: &crr::impact::Trajectory| t.impacts.iter().map(|i| i.energy_lost).sum::<f64>();
    let (lr, lt) = (lost(&rigid), lost(&twisting));
    assert!((lr - lt).abs() <= 1e-9 * lr.abs(), "{lr} against {lt}");
    assert!(
        twisting.energy_balance_error < 1e-6,
        "{}",
        twisting.energy_balance_error
    );
}

/// A frame of two columns of two drums under a beam (one loop; feet along x first, heads along y
/// first, as docs/model-format.md advises). With rigid contacts a column tilting about x at one
/// bed and about y at the other turns its top by R_x R_y or R_y R_x, which differ by a twist at
/// second order that the head cannot take: 7 first-order motions at rest, 6 after a finite step.
/// With the closing head allowed to twist, all 7 continue.
#[test]
fn a_twisting_head_lets_a_frame_of_drum_columns_move_at_finite_amplitude() {
    let rect = |cx: f64, z: f64, x_first: bool| {
        let (a, b) = (cx - 0.2, cx + 0.2);
        if x_first {
            format!("[[{a}, -0.2, {z}], [{b}, -0.2, {z}], [{b}, 0.2, {z}], [{a}, 0.2, {z}]]")
        } else {
            format!("[[{a}, -0.2, {z}], [{a}, 0.2, {z}], [{b}, 0.2, {z}], [{b}, -0.2, {z}]]")
        }
    };
    for (twist, finite) in [(false, 6), (true, 7)] {
        let mut s = String::from("name = \"drum_frame\"\n");
        for (side, x) in [("l", -1.0), ("r", 1.0)] {
            for k in 1..=2 {
                s += &format!(
                    "[[body]]\nname = \"d{side}{k}\"\ndensity = 2500.0\nbox = {{ center = [{x}, 0.0, {}], size = [0.4, 0.4, 1.0] }}\n",
                    k as f64 - 0.5
                );
            }
        }
        s += "[[body]]\nname = \"beam\"\ndensity = 2500.0\nbox = { center = [0.0, 0.0, 2.2], size = [2.8, 0.4, 0.4] }\n";
        for (side, x) in [("l", -1.0), ("r", 1.0)] {
            s += &format!(
                "[[interface]]\nname = \"bed_{side}1\"\nparent = \"ground\"\nchild = \"d{side}1\"\nrocking_base = {{ corners = {} }}\n",
                rect(x, 0.0, true)
            );
            s += &format!(
                "[[interface]]\nname = \"bed_{side}2\"\nparent = \"d{side}1\"\nchild = \"d{side}2\"\nrocking_base = {{ corners = {} }}\n",
                rect(x, 1.0, true)
            );
        }
        let tw = if twist { ", twist = true" } else { "" };
        s += &format!(
            "[[interface]]\nname = \"head_l\"\nparent = \"dl2\"\nchild = \"beam\"\nrocking_base = {{ corners = {} }}\n",
            rect(-1.0, 2.0, false)
        );
        s += &format!(
            "[[interface]]\nname = \"head_r\"\nparent = \"dr2\"\nchild = \"beam\"\nrocking_base = {{ corners = {}{tw} }}\n",
            rect(1.0, 2.0, false)
        );
        let path = common::write_model(&format!("drum_frame_{twist}"), &s);
        let m = crr::load_model(&path).unwrap().1;
        assert_eq!(m.closure_rows, if twist { 3 } else { 4 });
        let zero = DVector::zeros(m.dof());
        let rest = mobility(&m, &zero, &ActivePivots::uniform(&m, Side::Positive));
        let after = mobility_after_step(&m, 0.01).unwrap();
        assert_eq!((rest.dof2, after.dof2), (7, finite), "twist = {twist}");
    }
}
