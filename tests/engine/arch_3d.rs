//! The 3D arch (`examples/models/arch_3d.toml`): the ring of the planar four-hinge arch with
//! rectangular contact faces (rocking bases) at its four joints.
//!
//! - Under a purely in-plane motion it is the planar arch (`arch.toml`): same mechanism, same
//!   static multiplier, same response, the out-of-plane tilts never leaving their seats.
//! - Out of plane it rocks as a whole on its springings' edges; its static multiplier is the
//!   limit-analysis (kinematic theorem) value of that mechanism, derived in `out_of_plane_lambda`.
//! - Under the bundled record at 45° to its plane it hinges in plane and rocks out of plane, with
//!   an energy balance closed to 1e-6 of the energy dissipated.
use crate::common;

use std::f64::consts::PI;

use nalgebra::Vector3;

use crate::common::bundled_model as bundled;
use crr::analysis::check::check;
use crr::analysis::static_multiplier::static_multiplier;
use crr::impact::Trajectory;

/// The bundled model `name` with everything from its first `[ground_motion]` or `[initial]`
/// table on replaced by `tail`.
fn with_tail(name: &str, tail: &str) -> String {
    let text = common::bundled_text(name);
    let cut = ["[initial]", "[ground_motion]"]
        .iter()
        .filter_map(|t| text.find(t))
        .min()
        .unwrap();
    format!("{}{tail}\n", &text[..cut])
}

/// Ring of inner radius 2 m, outer radius 2.5 m, depth t = 1 m.
const R_I: f64 = 2.0;
const R_O: f64 = 2.5;
const DEPTH: f64 = 1.0;

/// The out-of-plane multiplier of the ring rocking as one rigid body about the line through its
/// springings' edges (y = ±t/2, z = 0), by the kinematic theorem of limit analysis (Heyman, "The
/// stone skeleton", Int. J. Solids Struct. 2, 1966): in a virtual rotation δψ about that line the
/// horizontal load λ m g acting at the centroid (height z̄) does work λ m g z̄ δψ, and the weight
/// rises by (t/2) δψ at the centroid, so λ = (t/2)/z̄ — Housner's tan α = b/h of a block, with
/// b = t/2 and h = z̄. The centroid of a half annulus is at z̄ = 4(R_o³ − R_i³)/(3π(R_o² − R_i²))
/// above its diameter (centroid of a circular sector of angle π, integrated over the radius).
/// A first-order check of the other out-of-plane motion (the voussoirs folding about their joint
/// edges) gives the same λ for any mix of the two, since every voussoir's work terms share the
/// factor; it continues as no finite motion (the model file says why).
fn out_of_plane_lambda() -> f64 {
    let z_bar = 4.0 * (R_O.powi(3) - R_I.powi(3)) / (3.0 * PI * (R_O.powi(2) - R_I.powi(2)));
    (DEPTH / 2.0) / z_bar
}

#[test]
fn mobility_in_plane_hinges_and_out_of_plane_tilts() {
    let report = check(&bundled("arch_3d"));
    let m = &report.mobility;
    assert_eq!(m.dof1, 6);
    assert_eq!(m.constraint_rows, 4);
    // In plane the four-hinge mechanism (1); out of plane the rigid rocking and the first-order
    // folding of the flat spherical chain (2); after a finite step the folding is gone.
    assert_eq!(m.dof2, 3);
    assert_eq!(report.finite_mobility.as_ref().unwrap().dof2, 2);
}

/// λ along x equals the planar arch's λ = U′(0)/|Q_h(0)| of its one-DOF mechanism (a different
/// computation: the equivalent block of `crr check` against the uplift test bisected here), with
/// the same four joints opening on the same sides; λ along y equals the closed form. Tolerance:
/// the bisection stops at 1e-12 relative, but a joint counts as opening only above an angular
/// acceleration of 1e-9 g/size (4e-9 rad/s² here), which the ring rocking out of plane reaches
/// (ψ̈ ≈ 2.6 (λ − λ_c) rad/s²) some 1.5e-9 above λ_c: 4e-9 relative. So 1e-8.
#[test]
fn static_multipliers_in_and_out_of_plane() {
    let planar = check(&bundled("arch"));
    let lambda_planar = planar.mechanism.as_ref().unwrap().lambda;
    let arch = bundled("arch_3d");
    for (d, sides) in [(1.0, ["-", "+", "-", "-"]), (-1.0, ["+", "-", "+", "+"])] {
        let s = static_multiplier(&arch, Vector3::new(d, 0.0, 0.0)).unwrap();
        let l = s.lambda.unwrap();
        assert!(
            (l - lambda_planar).abs() <= 1e-8 * lambda_planar,
            "λ_x = {l} against the planar arch's {lambda_planar}"
        );
        let names = [
            "joint_120.2",
            "joint_60.2",
            "springing_left.2",
            "springing_right.2",
        ];
        assert_eq!(s.opening.len(), 4, "{:?}", s.opening);
        for (name, side) in names.iter().zip(sides) {
            assert_eq!(
                s.opening.get(*name).map(String::as_str),
                Some(side),
                "{:?}",
                s.opening
            );
        }
    }
    let expected = out_of_plane_lambda();
    assert!((expected - 0.347635).abs() < 1e-6, "closed form {expected}");
    for (d, side) in [(1.0, "+"), (-1.0, "-")] {
        let s = static_multiplier(&arch, Vector3::new(0.0, d, 0.0)).unwrap();
        let l = s.lambda.unwrap();
        assert!(
            (l - expected).abs() <= 1e-8 * expected,
            "λ_y = {l} against (t/2)/z̄ = {expected}"
        );
        // The ring rocks on both springings' edges together; the in-plane tilts stay seated.
        // The folding motion has the same λ at first order and may join in (a joint's `.1`).
        assert_eq!(s.opening["springing_right.1"], side, "{:?}", s.opening);
        assert_eq!(s.opening["springing_left.1"], side, "{:?}", s.opening);
        assert!(
            s.opening.keys().all(|k| k.ends_with(".1")),
            "{:?}",
            s.opening
        );
    }
}

/// A constant out-of-plane ground acceleration just below λ_y g leaves the arch at rest; just
/// above, it rocks out of plane, on its springings only. (Before Gauss' principle decided the
/// uplift of structures at rest, the arch stayed at rest up to 0.64 g.)
#[test]
fn out_of_plane_uplift_at_the_static_multiplier() {
    let g = 9.81;
    let lambda = out_of_plane_lambda();
    for (factor, uplifts) in [(0.999, false), (1.001, true)] {
        let a = factor * lambda * g;
        let text = with_tail(
            "arch_3d",
            &format!("[ground_motion]\ny = {{ constant = {{ value = {a} }} }}"),
        );
        let (model, traj) =
            common::run_model_text(&format!("arch_3d_y_{factor}"), &text, Some(0.3));
        assert_eq!(traj.uplift_time.is_some(), uplifts, "a = {factor} λ g");
        let k = |name: &str| model.coord_index(name).unwrap();
        let last = traj.samples.last().unwrap();
        if uplifts {
            assert_eq!(traj.uplift_time, Some(0.0));
            // ψ̈ ≈ 2.6 × 0.001 λ rad/s² for 0.3 s: ψ ≈ 4e-5 rad (7.9e-5 from the engine, the
            // acceleration growing with the tilt).
            assert!(last.q[k("springing_right.1")] > 2e-5, "{:?}", last.q);
            assert!(
                (last.q[k("springing_right.1")] - last.q[k("springing_left.1")]).abs() < 1e-9,
                "the ring rocks as one body: {:?}",
                last.q
            );
            for name in [
                "springing_right.2",
                "springing_left.2",
                "joint_60.1",
                "joint_60.2",
            ] {
                assert!(last.q[k(name)].abs() < 1e-12, "{name}: {:?}", last.q);
            }
        } else {
            assert!(last.q.iter().all(|&v| v == 0.0), "{:?}", last.q);
        }
    }
}

/// The regular output samples (t a multiple of 0.01 s, the first row of each time).
fn regular(traj: &Trajectory) -> Vec<crr::impact::simulation::Sample<'_>> {
    let mut out: Vec<crr::impact::simulation::Sample<'_>> = Vec::new();
    for s in &traj.samples {
        let k = (s.t / 0.01).round();
        if (s.t - k * 0.01).abs() < 1e-9 && out.last().is_none_or(|l| l.t != s.t) {
            out.push(s);
        }
    }
    out
}

/// Under a one-sine pulse along x (in the arch's plane) the 3D arch moves as the planar arch:
/// every in-plane tilt `.2` follows the planar hinge of the same name at every sample, the
/// impacts come at the same times, and the out-of-plane tilts stay exactly at 0. The two runs
/// integrate different systems (6 and 3 coordinates, a 4-row and a 5-row closure), so they agree
/// to the integrators' accuracy (rtol 1e-10) amplified through the impacts: 1e-7 rad.
#[test]
fn in_plane_motion_reproduces_the_planar_arch() {
    let tail = "[ground_motion]\nx = { one_sine_pulse = { amplitude = 4.5, period = 0.6 } }";
    let (planar, p) =
        common::run_model_text("arch_planar_pulse", &with_tail("arch", tail), Some(3.0));
    let (arch3d, a) =
        common::run_model_text("arch_3d_pulse", &with_tail("arch_3d", tail), Some(3.0));
    assert!(
        p.uplift_time.is_some() && !p.impacts.is_empty(),
        "the planar arch rocks"
    );
    assert!(p.collapse.is_none() && a.collapse.is_none());
    assert_eq!(p.impacts.len(), a.impacts.len());
    for (i, j) in p.impacts.iter().zip(&a.impacts) {
        assert!(
            (i.t - j.t).abs() < 1e-7,
            "impact at {} against {}",
            i.t,
            j.t
        );
    }
    let (ps, as_) = (regular(&p), regular(&a));
    assert_eq!(ps.len(), as_.len());
    let mut largest: f64 = 0.0;
    for (x, y) in ps.iter().zip(&as_) {
        assert_eq!(x.t, y.t);
        for (k, c) in planar.coords.iter().enumerate() {
            let k3 = arch3d.coord_index(&format!("{}.2", c.name)).unwrap();
            let o3 = arch3d.coord_index(&format!("{}.1", c.name)).unwrap();
            largest = largest.max(x.q[k].abs());
            assert!(
                (x.q[k] - y.q[k3]).abs() < 1e-7,
                "t = {}: {} = {} against {}",
                x.t,
                c.name,
                x.q[k],
                y.q[k3]
            );
            assert_eq!(y.q[o3], 0.0, "t = {}: {}.1 left its seat", x.t, c.name);
        }
    }
    assert!(largest > 0.01, "the arch rocked: peak {largest} rad");
}

/// The bundled run: the record at 45° to the plane. It uplifts, rocks out of plane and hinges in
/// plane, does not collapse, and closes its energy balance T + U − W + D = E(0) to 1e-6 of the
/// energy D dissipated at its impacts.
#[test]
fn the_record_at_45_degrees_rocks_in_and_out_of_plane() {
    let text = common::bundled_text_with_records("arch_3d");
    let (model, traj) = common::run_model_text("arch_3d_record", &text, None);
    assert!(traj.collapse.is_none());
    assert!(traj.impacts.len() > 10, "{} impacts", traj.impacts.len());
    let dissipated: f64 = -traj.impacts.iter().map(|i| i.energy_lost).sum::<f64>();
    let dissipated = dissipated.abs();
    assert!(dissipated > 100.0, "D = {dissipated} J");
    assert!(
        traj.energy_balance_error < 1e-6 * dissipated,
        "energy-balance error {} J against D = {dissipated} J",
        traj.energy_balance_error
    );
    let peak = |name: &str| traj.peak_abs[model.coord_index(name).unwrap()];
    assert!(
        peak("springing_right.1") > 1e-3,
        "out of plane {}",
        peak("springing_right.1")
    );
    assert!(
        peak("springing_right.2") > 1e-4,
        "in plane {}",
        peak("springing_right.2")
    );
}
