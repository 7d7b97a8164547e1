//! `crr check MODEL --size-sweep s0:s1:n`: the model scaled geometrically by n factors from s0 to
//! s1 (every length: shapes, centres, pivots, contact corners; densities kept, so masses scale as
//! s³; a body given by its `mass` gets mass × s³), and for each scaled model the generalized
//! Housner frequency (paper eq 6, χ = p_eq², ε = 1/α_eq of that model) beside the engine's
//! free-rocking frequency at a fixed amplitude θ_m = ratio · α_eq (the paper's Fig. 10 against
//! size). Documented in `docs/outputs.md`.

use nalgebra::Vector3;
use serde::Serialize;

use crr_dynamics::{horizontal_direction, reported_side};
use crr_kinematics::shapes::Shape;
use crr_kinematics::spec::PivotSpec;
use crr_kinematics::{Model, StructureSpec};

use crate::Error;
use crate::analysis::check::{first_fall_time, housner_frequency};

/// Largest number of scale factors of a sweep.
pub const MAX_SIZES: usize = 200;

/// Default θ_m/α_eq of the sweep's frequencies.
pub const DEFAULT_AMPLITUDE_RATIO: f64 = 0.5;

/// The scale factors of `--size-sweep s0:s1:n`: n values evenly spaced from s0 to s1 (s0 alone
/// when n = 1). Errors name the option.
pub fn parse_sweep(text: &str) -> Result<Vec<f64>, Error> {
    let bad = |why: String| {
        Error::Argument(format!(
            "--size-sweep: {why} (expected s0:s1:n, e.g. 0.5:2:7: n scale factors from s0 to s1, \
             both positive)"
        ))
    };
    let parts: Vec<&str> = text.split(':').collect();
    if parts.len() != 3 {
        return Err(bad(format!("\"{text}\" does not have three fields")));
    }
    let factor = |s: &str, name: &str| -> Result<f64, Error> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| bad(format!("{name} = \"{s}\" is not a number")))?;
        if !v.is_finite() || v <= 0.0 {
            return Err(bad(format!(
                "{name} must be a finite positive factor, got {s}"
            )));
        }
        Ok(v)
    };
    let s0 = factor(parts[0], "s0")?;
    let s1 = factor(parts[1], "s1")?;
    let n: usize = parts[2]
        .trim()
        .parse()
        .map_err(|_| bad(format!("n = \"{}\" is not a whole number", parts[2])))?;
    if n == 0 || n > MAX_SIZES {
        return Err(bad(format!("n must be from 1 to {MAX_SIZES}, got {n}")));
    }
    if n == 1 {
        return Ok(vec![s0]);
    }
    Ok((0..n)
        .map(|i| s0 + (s1 - s0) * i as f64 / (n - 1) as f64)
        .collect())
}

/// Checks `--amplitude-ratio`: θ_m/α_eq in (0, 1).
pub fn check_amplitude_ratio(r: f64) -> Result<f64, Error> {
    if r.is_finite() && r > 0.0 && r < 1.0 {
        Ok(r)
    } else {
        Err(Error::Argument(format!(
            "--amplitude-ratio must be a number between 0 and 1 (θm/α_eq, exclusive), got {r}"
        )))
    }
}

fn scale3(p: &mut [f64; 3], s: f64) {
    for x in p.iter_mut() {
        *x *= s;
    }
}

/// The structure scaled by `s` about the origin: every length multiplied by s, densities kept
/// (given masses multiplied by s³), directions, angles, gravity and impact laws unchanged.
pub fn scale_structure(spec: &StructureSpec, s: f64) -> StructureSpec {
    let mut out = spec.clone();
    for b in &mut out.body {
        if let Some(m) = b.mass.as_mut() {
            *m *= s * s * s;
        }
        // The body's own shape and each part of a compound body.
        for fields in b.shape_fields_mut() {
            if let Some(x) = fields.box_shape.as_mut() {
                scale3(&mut x.center, s);
                scale3(&mut x.size, s);
            }
            if let Some(x) = fields.polyhedron.as_mut() {
                x.vertices.iter_mut().for_each(|v| scale3(v, s));
            }
            if let Some(x) = fields.prism.as_mut() {
                x.polygon.iter_mut().for_each(|v| scale3(v, s));
                scale3(&mut x.extrude, s);
            }
            if let Some(x) = fields.annular_sector.as_mut() {
                scale3(&mut x.center, s);
                x.inner_radius *= s;
                x.outer_radius *= s;
                x.thickness *= s;
            }
        }
    }
    for i in &mut out.interface {
        for p in [i.pivot_positive.as_mut(), i.pivot_negative.as_mut()]
            .into_iter()
            .flatten()
        {
            match p {
                PivotSpec::Point(x) => scale3(x, s),
                PivotSpec::Segment(seg) => seg.iter_mut().for_each(|x| scale3(x, s)),
            }
        }
        if let Some(rb) = i.rocking_base.as_mut() {
            rb.corners.iter_mut().for_each(|c| scale3(c, s));
        }
    }
    out
}

/// The height of the structure at rest (m): the highest point of its shapes minus the lowest one
/// (exact for every shape kind and every part of a compound body: box corners, polyhedron
/// vertices, prism vertices, and the extreme heights of an annular sector's arcs). `None` when a shape is degenerate (the model would not
/// build either).
pub fn structure_height(spec: &StructureSpec) -> Option<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut add = |z: f64| {
        lo = lo.min(z);
        hi = hi.max(z);
    };
    let v = |p: &[f64; 3]| Vector3::new(p[0], p[1], p[2]);
    let shapes = spec.body.iter().flat_map(|b| {
        let parts = b.blocks.iter().flat_map(|p| p.shapes());
        b.own_shapes().into_iter().chain(parts)
    });
    for shape in shapes {
        if let Shape::Box(x) = &shape {
            let r = x.rotation_matrix();
            for i in 0..8 {
                let sgn = |k: usize| if i & (1 << k) == 0 { -0.5 } else { 0.5 };
                let local =
                    Vector3::new(sgn(0) * x.size[0], sgn(1) * x.size[1], sgn(2) * x.size[2]);
                add((v(&x.center) + r * local).z);
            }
        }
        if let Shape::Polyhedron(x) = &shape {
            x.vertices.iter().for_each(|p| add(p[2]));
        }
        if let Shape::Prism(x) = &shape {
            x.polygon.iter().for_each(|p| {
                add(p[2]);
                add(p[2] + x.extrude[2]);
            });
        }
        if let Shape::AnnularSector(x) = &shape {
            let f = x.frame().ok()?;
            let (es, et, w) = (f.column(0), f.column(1), f.column(2));
            // z(θ) = c + ρ (A cos θ + B sin θ) + ζ w_z: extremes at the ends of the arc and where
            // tan θ = B/A (θ* and θ* + π) if inside it.
            let (a, bb) = (es.z, et.z);
            let star = bb.atan2(a);
            let two_pi = std::f64::consts::TAU;
            let mut angles = vec![x.from_angle, x.to_angle];
            for c in [star, star + std::f64::consts::PI] {
                let shifted = x.from_angle + (c - x.from_angle).rem_euclid(two_pi);
                if shifted <= x.to_angle {
                    angles.push(shifted);
                }
            }
            for t in angles {
                for rho in [x.inner_radius, x.outer_radius] {
                    for zeta in [-0.5 * x.thickness, 0.5 * x.thickness] {
                        add(x.center[2] + rho * (a * t.cos() + bb * t.sin()) + zeta * w.z);
                    }
                }
            }
        }
    }
    (hi - lo).is_finite().then_some(hi - lo)
}

/// One scaled model of the sweep.
#[derive(Clone, Debug, Serialize)]
pub struct SizeRow {
    /// Scale factor s.
    pub scale: f64,
    /// The scaled model's length scale (`Model::size`: largest extent of the centres and pivots, m).
    pub size: f64,
    /// Height of the scaled structure at rest (m): its highest point minus its lowest
    /// ([`structure_height`]); `None` if it cannot be computed.
    pub height: Option<f64>,
    /// Total mass (kg): s³ times the unscaled one.
    pub mass: f64,
    /// λ (g).
    pub lambda: f64,
    /// α_eq (rad).
    pub alpha_eq: f64,
    /// p_eq (rad/s).
    pub p_eq: f64,
    /// χ of eq 6: p_eq² (1/s²).
    pub chi: f64,
    /// ε of eq 6: 1/α_eq (1/rad).
    pub epsilon: f64,
    /// θ_m = ratio · α_eq (rad).
    pub theta_m: f64,
    /// F_H of eq 6 with χ = p_eq², ε = 1/α_eq (Hz).
    pub housner_hz: f64,
    /// 1/(4τ), τ the engine's first fall from θ_m (Hz), `None` if it did not return.
    pub engine_hz: Option<f64>,
    /// engine_hz / housner_hz.
    pub ratio: Option<f64>,
}

/// The sweep of one model.
#[derive(Clone, Debug, Serialize)]
pub struct SizeSweep {
    /// Model name.
    pub model: String,
    /// The mechanism coordinate θ.
    pub coordinate: String,
    /// θ_m/α_eq of every row.
    pub amplitude_ratio: f64,
    /// One row per scale factor, in the order given.
    pub rows: Vec<SizeRow>,
}

/// Runs the sweep. Errors (as text) when a scaled model is invalid or not a one-DOF mechanism.
pub fn size_sweep(spec: &StructureSpec, scales: &[f64], ratio: f64) -> Result<SizeSweep, String> {
    let mut rows = Vec::with_capacity(scales.len());
    let mut coordinate = String::new();
    for &s in scales {
        let at = if (1e-3..1e4).contains(&s) {
            format!("scaled by {s}")
        } else {
            format!("scaled by {s:e}")
        };
        let scaled = scale_structure(spec, s);
        let model = Model::from_spec(&scaled).map_err(|e| format!("{at}: {e}"))?;
        coordinate = model
            .coords
            .first()
            .map(|c| c.name.clone())
            .unwrap_or_default();
        // The side `crr check` reports (reported_side), read in its opening angle.
        let (side, _, eq) = reported_side(&model, 0, &horizontal_direction(&model, 0))
            .map_err(|e| format!("{at}: {e}"))?;
        let (p, alpha) = (eq.p_squared.sqrt(), eq.alpha);
        if !(p.is_finite() && p > 0.0 && alpha.is_finite() && alpha > 0.0) {
            return Err(format!(
                "{at}: no equivalent block (p_eq² = {}, α_eq = {alpha})",
                eq.p_squared
            ));
        }
        let theta_m = side.sign() * ratio * alpha;
        let fh = housner_frequency(p, alpha, theta_m.abs());
        let limit = 2.0 / fh + 1.0;
        let engine =
            first_fall_time(&model, &coordinate, theta_m, limit).map(|tau| 1.0 / (4.0 * tau));
        rows.push(SizeRow {
            scale: s,
            size: model.size,
            height: structure_height(&scaled),
            mass: model.total_mass(),
            lambda: eq.lambda,
            alpha_eq: alpha,
            p_eq: p,
            chi: p * p,
            epsilon: 1.0 / alpha,
            theta_m,
            housner_hz: fh,
            engine_hz: engine,
            ratio: engine.map(|e| e / fh),
        });
    }
    Ok(SizeSweep {
        model: spec.name.clone(),
        coordinate,
        amplitude_ratio: ratio,
        rows,
    })
}

/// The sweep as a text table.
pub fn to_text(sw: &SizeSweep) -> String {
    let mut s = format!(
        "\nfree-rocking frequency versus size ({}, θm/α_eq = {})\n",
        sw.model, sw.amplitude_ratio
    );
    s += "scale   height (m)  mass (kg)      α_eq (rad)  p_eq (rad/s)  F_H Housner (Hz)  engine (Hz)  engine/F_H\n";
    for r in &sw.rows {
        let (e, q) = match (r.engine_hz, r.ratio) {
            (Some(e), Some(q)) => (format!("{e:.6}"), format!("{q:.5}")),
            _ => ("–".to_string(), "–".to_string()),
        };
        s += &format!(
            "{:<7.4} {:<11} {:<14.6e} {:<11.6} {:<13.6} {:<17.6} {:<12} {}\n",
            r.scale,
            r.height.map_or("–".to_string(), |h| format!("{h:.4}")),
            r.mass,
            r.alpha_eq,
            r.p_eq,
            r.housner_hz,
            e,
            q
        );
    }
    s
}
