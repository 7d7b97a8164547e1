//! Exact mass properties (volume, centroid, second moment) of the body shapes.
//!
//! All geometry is given in world coordinates of the structure at rest, in SI
//! units (m), with z up. Every result is exact up to floating-point round-off:
//! closed forms or exact polynomial integration, never sampling.
//!
//! Shapes:
//! * [`BoxShape`]: a rectangular block, optionally rotated about its centre;
//! * [`PolyhedronShape`]: the convex hull of a point cloud;
//! * [`PrismShape`]: a planar simple polygon (convex or not) swept along a vector;
//! * [`AnnularSectorShape`]: a voussoir / arch-ring piece.

use nalgebra::{Matrix3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

mod hull;
mod surface;
#[cfg(test)]
mod tests;

pub use hull::{
    HULL_REL_TOL, convex_hull_faces, convex_hull_triangles, polyhedron_properties_divergence,
    polyhedron_properties_tetrahedra,
};
pub use surface::{SECTOR_MIN_SEGMENTS, SECTOR_SEGMENTS_PER_TURN, Surface, sector_segments};

/// Relative tolerance (w.r.t. the polygon's bounding-box diagonal) on the
/// distance of a prism polygon vertex from the plane through its first three
/// vertices (or, if these are nearly collinear, vertices 0, 1 and the first
/// vertex well off the line through them).
pub const PLANARITY_REL_TOL: f64 = 1e-6;

/// Relative tolerance used for "parallel" tests of direction vectors
/// (extrusion in the polygon plane, start direction along the axis).
const PARALLEL_REL_TOL: f64 = 1e-9;

/// Volume properties of a solid of unit density.
#[derive(Clone, Debug, PartialEq)]
pub struct MassProperties {
    /// Volume (m³), strictly positive.
    pub volume: f64,
    /// Centroid (m), world coordinates.
    pub centroid: Vector3<f64>,
    /// Second moment of volume about the centroid, world axes (m⁵):
    /// `S = ∫ (x - c)(x - c)ᵀ dV`.
    pub second_moment: Matrix3<f64>,
}

impl MassProperties {
    /// Inertia tensor about the centroid, world axes (kg·m²), for a uniform
    /// density `density` (kg/m³): `ρ (tr(S) I - S)`.
    pub fn inertia(&self, density: f64) -> Matrix3<f64> {
        let s = &self.second_moment;
        (Matrix3::identity() * s.trace() - s) * density
    }

    /// Mass (kg) for a uniform density `density` (kg/m³).
    pub fn mass(&self, density: f64) -> f64 {
        density * self.volume
    }

    /// Properties of the union of disjoint solids (parallel-axis theorem).
    ///
    /// Returns `None` for an empty slice.
    pub fn combine(parts: &[MassProperties]) -> Option<MassProperties> {
        if parts.is_empty() {
            return None;
        }
        let volume: f64 = parts.iter().map(|p| p.volume).sum();
        let centroid = parts
            .iter()
            .fold(Vector3::zeros(), |acc, p| acc + p.centroid * p.volume)
            / volume;
        let second_moment = parts.iter().fold(Matrix3::zeros(), |acc, p| {
            let r = p.centroid - centroid;
            acc + p.second_moment + r * r.transpose() * p.volume
        });
        Some(MassProperties {
            volume,
            centroid,
            second_moment,
        })
    }

    /// Properties of the solid moved by the rigid motion `x ↦ R x + t`
    /// (`rotation` R proper orthogonal, `translation` t in m).
    pub fn transformed(&self, rotation: &Matrix3<f64>, translation: &Vector3<f64>) -> Self {
        MassProperties {
            volume: self.volume,
            centroid: rotation * self.centroid + translation,
            second_moment: rotation * self.second_moment * rotation.transpose(),
        }
    }
}

/// The largest angle a box's `rotation` may have, rad (about 16 turns): a turn is 2π, so this
/// admits any orientation written with a few turns to spare.
pub const MAX_ROTATION_ANGLE: f64 = 100.0;

/// Invalid shape input. Messages are meant for the structural engineer who
/// wrote the model file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// A compound shape with no part.
    #[error("a compound body needs at least one part")]
    NoParts,
    /// A NaN or infinite number was found in the named input field.
    #[error("non-finite number in {field}")]
    NonFinite {
        /// Name of the offending field.
        field: &'static str,
    },
    /// A box rotation of more turns than any model needs.
    #[error(
        "rotation is {angle:e} rad about its axis, more than {MAX_ROTATION_ANGLE} rad (the \
         axis-angle vector's length is the angle in radians: degrees given for radians?)"
    )]
    RotationAngle {
        /// The rotation's angle, the vector's length (rad).
        angle: f64,
    },
    /// A box side is zero or negative.
    #[error(
        "box size must be positive in all three directions, got {}",
        fmt_vec(.size)
    )]
    BoxSize {
        /// The given size (m).
        size: [f64; 3],
    },
    /// Not enough points to define the shape.
    #[error("{what} needs at least {required} points, got {found}")]
    TooFewPoints {
        /// What the points describe (e.g. "polyhedron", "prism polygon").
        what: &'static str,
        /// Minimum number of points.
        required: usize,
        /// Number of points given.
        found: usize,
    },
    /// More points than the convex hull's brute force handles in reasonable time.
    #[error(
        "polyhedron has {found} vertices, more than the {limit} its convex hull is computed for (by \
         brute force, O(n³) to O(n⁴): 1 s for 500 points, 15 s for 1 000, minutes for 3 000); give the \
         hull's own vertices, or a decimated point cloud"
    )]
    TooManyPoints {
        /// Number of points given.
        found: usize,
        /// The largest number accepted.
        limit: usize,
    },
    /// All polyhedron vertices lie in one plane (or on one line / point).
    #[error("polyhedron vertices are coplanar: zero volume")]
    Coplanar,
    /// A prism polygon vertex is too far from the polygon's plane.
    #[error(
        "prism polygon is not planar: vertex {vertex} is {} m off the plane through vertices {}, {} and {}",
        fmt_num(.distance),
        .plane[0],
        .plane[1],
        .plane[2]
    )]
    PolygonNotPlanar {
        /// Index of the first vertex off the plane.
        vertex: usize,
        /// Its distance from the plane (m).
        distance: f64,
        /// The three vertices defining the reference plane.
        plane: [usize; 3],
    },
    /// The prism polygon encloses no area.
    #[error("prism polygon has zero area: its vertices are collinear")]
    PolygonZeroArea,
    /// Two consecutive prism polygon vertices coincide.
    #[error("prism polygon vertex {vertex} repeats the previous vertex")]
    PolygonRepeatedVertex {
        /// Index of the repeated vertex.
        vertex: usize,
    },
    /// The prism polygon boundary crosses or touches itself.
    #[error(
        "prism polygon is not simple: edge {first} and edge {second} cross or touch \
         (edge k joins vertex k to vertex k+1)"
    )]
    PolygonNotSimple {
        /// First offending edge.
        first: usize,
        /// Second offending edge.
        second: usize,
    },
    /// A direction vector is zero.
    #[error("{field} must be non-zero")]
    ZeroVector {
        /// Name of the offending field.
        field: &'static str,
    },
    /// The prism extrusion lies in the polygon plane.
    #[error("prism extrusion is parallel to the polygon plane: zero volume")]
    ExtrusionParallel,
    /// Negative inner radius of an annular sector.
    #[error("inner_radius must not be negative, got {}", fmt_num(.inner))]
    NegativeRadius {
        /// The given inner radius (m).
        inner: f64,
    },
    /// Inner radius not smaller than outer radius.
    #[error(
        "inner_radius {} must be smaller than outer_radius {}",
        fmt_num(.inner),
        fmt_num(.outer)
    )]
    RadiusOrder {
        /// Inner radius (m).
        inner: f64,
        /// Outer radius (m).
        outer: f64,
    },
    /// The start direction of an annular sector is along its axis.
    #[error("start direction is parallel to the axis")]
    StartParallel,
    /// The angular range of an annular sector is empty or reversed.
    #[error(
        "to_angle {} must exceed from_angle {}",
        fmt_num(.to_angle),
        fmt_num(.from_angle)
    )]
    AngleOrder {
        /// Start angle (rad).
        from_angle: f64,
        /// End angle (rad).
        to_angle: f64,
    },
    /// The angular span of an annular sector is more than a full turn.
    #[error(
        "angle span to_angle - from_angle = {} rad exceeds a full turn (2π)",
        fmt_num(.span)
    )]
    AngleSpan {
        /// The span (rad).
        span: f64,
    },
    /// Non-positive thickness of an annular sector.
    #[error("thickness must be positive, got {}", fmt_num(.thickness))]
    Thickness {
        /// The given thickness (m).
        thickness: f64,
    },
}

/// Formats a number with at most 6 significant digits, without exponent noise.
fn fmt_num(x: &f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    let rounded: f64 = format!("{x:.5e}").parse().unwrap_or(*x);
    format!("{rounded}")
}

fn fmt_vec(v: &[f64; 3]) -> String {
    format!(
        "[{}, {}, {}]",
        fmt_num(&v[0]),
        fmt_num(&v[1]),
        fmt_num(&v[2])
    )
}

fn check_finite(values: &[f64], field: &'static str) -> Result<(), ShapeError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(ShapeError::NonFinite { field })
    }
}

fn v3(a: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// Rectangular block.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxShape {
    /// Centre of the box (m), world.
    pub center: [f64; 3],
    /// Edge lengths (m) along the box's own axes (world x, y, z before rotation).
    pub size: [f64; 3],
    /// Optional rotation of the box about its centre, as an axis-angle vector
    /// (rad): direction = axis, norm = angle (right-handed).
    #[serde(default)]
    pub rotation: Option<[f64; 3]>,
}

impl BoxShape {
    /// Rotation matrix of the box axes (identity when `rotation` is `None`).
    pub fn rotation_matrix(&self) -> Matrix3<f64> {
        match self.rotation {
            Some(r) => *Rotation3::new(v3(&r)).matrix(),
            None => Matrix3::identity(),
        }
    }

    /// Exact mass properties.
    pub fn mass_properties(&self) -> Result<MassProperties, ShapeError> {
        check_finite(&self.center, "center")?;
        check_finite(&self.size, "size")?;
        if let Some(r) = &self.rotation {
            check_finite(r, "rotation")?;
            // An angle of many turns is a typo (degrees for radians, a stray exponent); beyond
            // about 1e16 rad it has no digits left, and 1e300 made the inertia NaN.
            let v = v3(r);
            let largest = v.amax();
            // Scaled by its largest component: the squares of 1e300 overflow.
            let angle = if largest > 0.0 {
                largest * (v / largest).norm()
            } else {
                0.0
            };
            if angle.is_nan() || angle > MAX_ROTATION_ANGLE {
                return Err(ShapeError::RotationAngle { angle });
            }
        }
        if self.size.iter().any(|&s| s <= 0.0) {
            return Err(ShapeError::BoxSize { size: self.size });
        }
        let [a, b, c] = self.size;
        let volume = a * b * c;
        let s0 = Matrix3::from_diagonal(&Vector3::new(a * a, b * b, c * c)) * (volume / 12.0);
        let r = self.rotation_matrix();
        Ok(MassProperties {
            volume,
            centroid: v3(&self.center),
            second_moment: r * s0 * r.transpose(),
        })
    }
}

/// Convex polyhedron: the convex hull of the given points (interior and
/// duplicate points are ignored).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolyhedronShape {
    /// Points (m), world; at least 4, not coplanar.
    pub vertices: Vec<[f64; 3]>,
}

impl PolyhedronShape {
    /// Exact mass properties (tetrahedra route, see
    /// [`polyhedron_properties_tetrahedra`]).
    pub fn mass_properties(&self) -> Result<MassProperties, ShapeError> {
        let pts: Vec<Vector3<f64>> = self.vertices.iter().map(v3).collect();
        polyhedron_properties_tetrahedra(&pts)
    }
}

/// Prism: a planar simple polygon swept along a vector.
///
/// The solid is `{p + t d : p in polygon, t in [0, 1]}` with `d = extrude`,
/// which may be oblique to the polygon plane. The polygon may be convex or
/// not, in any orientation and either winding; a closing vertex equal to the
/// first one is accepted and ignored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PrismShape {
    /// Polygon vertices in order (m), world; at least 3, planar within
    /// [`PLANARITY_REL_TOL`] times the polygon size.
    pub polygon: Vec<[f64; 3]>,
    /// Extrusion vector (m), world; not parallel to the polygon plane.
    pub extrude: [f64; 3],
}

impl PrismShape {
    /// Exact mass properties from the polygon area moments and the sweep.
    pub fn mass_properties(&self) -> Result<MassProperties, ShapeError> {
        for p in &self.polygon {
            check_finite(p, "polygon")?;
        }
        check_finite(&self.extrude, "extrude")?;
        let mut pts: Vec<Vector3<f64>> = self.polygon.iter().map(v3).collect();
        let too_few = |found| ShapeError::TooFewPoints {
            what: "prism polygon",
            required: 3,
            found,
        };
        if pts.len() < 3 {
            return Err(too_few(pts.len()));
        }
        let scale = bbox_diagonal(&pts);
        if scale == 0.0 {
            return Err(ShapeError::PolygonZeroArea);
        }
        let tol = 1e-9 * scale;
        if (pts[pts.len() - 1] - pts[0]).norm() <= tol {
            pts.pop();
            if pts.len() < 3 {
                return Err(too_few(pts.len()));
            }
        }
        let n = pts.len();
        for i in 1..n {
            if (pts[i] - pts[i - 1]).norm() <= tol {
                return Err(ShapeError::PolygonRepeatedVertex { vertex: i });
            }
        }
        // Work relative to the vertex mean for conditioning.
        let origin = pts.iter().sum::<Vector3<f64>>() / n as f64;
        let r: Vec<Vector3<f64>> = pts.iter().map(|p| p - origin).collect();
        // Planarity: distances from the plane through vertices 0, 1 and the
        // first vertex k at least half as far from the line (0, 1) as the
        // farthest one (the first three vertices unless they are nearly
        // collinear).
        let e01 = r[1] - r[0];
        let off_line: Vec<f64> = r.iter().map(|ri| e01.cross(&(ri - r[0])).norm()).collect();
        let max_off = off_line.iter().copied().fold(0.0, f64::max);
        if max_off <= tol * e01.norm() {
            return Err(ShapeError::PolygonZeroArea);
        }
        let k = (2..n).find(|&k| off_line[k] >= 0.5 * max_off).unwrap_or(2);
        let pn = e01.cross(&(r[k] - r[0])).normalize();
        for (i, ri) in r.iter().enumerate() {
            let distance = pn.dot(&(ri - r[0])).abs();
            if distance > PLANARITY_REL_TOL * scale {
                return Err(ShapeError::PolygonNotPlanar {
                    vertex: i,
                    distance,
                    plane: [0, 1, k],
                });
            }
        }
        // Simplicity in 2D plane coordinates.
        let e1 = any_perpendicular(&pn);
        let e2 = pn.cross(&e1);
        let uv: Vec<[f64; 2]> = r.iter().map(|ri| [e1.dot(ri), e2.dot(ri)]).collect();
        check_simple(&uv, tol)?;
        // Newell area vector.
        let area_vec = (0..n).fold(Vector3::zeros(), |acc, i| {
            acc + r[i].cross(&r[(i + 1) % n]) * 0.5
        });
        let area_norm = area_vec.norm();
        if area_norm <= 1e-12 * scale * scale {
            return Err(ShapeError::PolygonZeroArea);
        }
        let normal = area_vec / area_norm;

        let d = v3(&self.extrude);
        let dn = d.norm();
        if dn <= 1e-12 * scale {
            return Err(ShapeError::ZeroVector { field: "extrude" });
        }
        let h = normal.dot(&d).abs();
        if h <= PARALLEL_REL_TOL * dn {
            return Err(ShapeError::ExtrusionParallel);
        }

        // Area moments by a signed triangle fan from the origin (vertex mean):
        // for a triangle (0, a, b): ∫ y dA = A (a + b)/3,
        // ∫ y yᵀ dA = A/12 (a aᵀ + b bᵀ + (a + b)(a + b)ᵀ).
        let mut area = 0.0;
        let mut first = Vector3::zeros();
        let mut second = Matrix3::zeros();
        for i in 0..n {
            let a = r[i];
            let b = r[(i + 1) % n];
            let s = 0.5 * normal.dot(&a.cross(&b));
            let ab = a + b;
            area += s;
            first += ab * (s / 3.0);
            second += (a * a.transpose() + b * b.transpose() + ab * ab.transpose()) * (s / 12.0);
        }
        let yc = first / area;
        let sp = second - yc * yc.transpose() * area;
        // Sweep: q = y + t d, dV = h dA dt; about the centroid the cross terms
        // vanish and ∫₀¹ (t - 1/2)² dt = 1/12.
        let volume = area * h;
        let second_moment = sp * h + d * d.transpose() * (volume / 12.0);
        Ok(MassProperties {
            volume,
            centroid: origin + yc + d * 0.5,
            second_moment,
        })
    }
}

/// Annular sector (voussoir, arch-ring piece).
///
/// Points `center + ρ (cos θ e_s + sin θ e_t) + ζ w` with `w = axis/|axis|`,
/// `e_s` = `start` projected perpendicular to `w` and normalised,
/// `e_t = w × e_s`, `ρ ∈ [inner_radius, outer_radius]`,
/// `θ ∈ [from_angle, to_angle]` (right-handed about `w`),
/// `ζ ∈ [-thickness/2, thickness/2]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnnularSectorShape {
    /// Centre of the rings (m), world; mid-plane of the thickness.
    pub center: [f64; 3],
    /// Axis of the rings (any length, non-zero), world.
    pub axis: [f64; 3],
    /// Inner radius (m), `>= 0`.
    pub inner_radius: f64,
    /// Outer radius (m), `> inner_radius`.
    pub outer_radius: f64,
    /// Direction of angle zero (any length, not parallel to `axis`), world.
    pub start: [f64; 3],
    /// Start angle (rad).
    pub from_angle: f64,
    /// End angle (rad), `from_angle < to_angle <= from_angle + 2π`.
    pub to_angle: f64,
    /// Thickness along the axis (m), `> 0`.
    pub thickness: f64,
}

impl AnnularSectorShape {
    /// Orthonormal frame `(e_s, e_t, w)` as the columns of a rotation matrix.
    pub fn frame(&self) -> Result<Matrix3<f64>, ShapeError> {
        check_finite(&self.axis, "axis")?;
        check_finite(&self.start, "start")?;
        let axis = v3(&self.axis);
        let an = axis.norm();
        if an == 0.0 {
            return Err(ShapeError::ZeroVector { field: "axis" });
        }
        let w = axis / an;
        let start = v3(&self.start);
        let sn = start.norm();
        if sn == 0.0 {
            return Err(ShapeError::ZeroVector { field: "start" });
        }
        let sp = start - w * w.dot(&start);
        let spn = sp.norm();
        if spn <= PARALLEL_REL_TOL * sn {
            return Err(ShapeError::StartParallel);
        }
        let es = sp / spn;
        let et = w.cross(&es);
        Ok(Matrix3::from_columns(&[es, et, w]))
    }

    /// Exact mass properties (closed form).
    pub fn mass_properties(&self) -> Result<MassProperties, ShapeError> {
        check_finite(&self.center, "center")?;
        check_finite(&[self.inner_radius], "inner_radius")?;
        check_finite(&[self.outer_radius], "outer_radius")?;
        check_finite(&[self.from_angle], "from_angle")?;
        check_finite(&[self.to_angle], "to_angle")?;
        check_finite(&[self.thickness], "thickness")?;
        let frame = self.frame()?;
        let (a, b) = (self.inner_radius, self.outer_radius);
        if a < 0.0 {
            return Err(ShapeError::NegativeRadius { inner: a });
        }
        if a >= b {
            return Err(ShapeError::RadiusOrder { inner: a, outer: b });
        }
        if self.thickness <= 0.0 {
            return Err(ShapeError::Thickness {
                thickness: self.thickness,
            });
        }
        let span = self.to_angle - self.from_angle;
        if span <= 0.0 {
            return Err(ShapeError::AngleOrder {
                from_angle: self.from_angle,
                to_angle: self.to_angle,
            });
        }
        if span > std::f64::consts::TAU * (1.0 + 1e-12) {
            return Err(ShapeError::AngleSpan { span });
        }
        let t = self.thickness;
        // Bisector frame: x along the bisector, y tangential, z along the axis;
        // φ ∈ [-α, α]. Radii as mid radius m ± half width h.
        let alpha = 0.5 * span;
        let m = 0.5 * (a + b);
        let h = 0.5 * (b - a);
        let (sa, ca) = alpha.sin_cos();
        let sin2_over_alpha = sa * sa / alpha;
        // ∫cos²φ dφ over [-α, α].
        let c2 = alpha + sa * ca;
        let q = h / m;
        let volume = 4.0 * t * h * m * alpha;
        let cx = (m + h * q / 3.0) * sa / alpha;
        // S_xx = ∫x² - V cx² with ∫ρ³dρ = 2hm³(1 + q²), ∫ρ²dρ = 2hm²(1 + q²/3),
        // ∫ρ dρ = 2hm; the O(α) parts cancel exactly and are summed in
        // `cos2_defect` = α + sinα cosα - 2 sin²α/α.
        let sxx = t
            * 2.0
            * h
            * m.powi(3)
            * (cos2_defect(alpha) + q * q * (c2 - 4.0 / 3.0 * sin2_over_alpha)
                - q.powi(4) * (2.0 / 9.0) * sin2_over_alpha);
        // S_yy = ∫ρ³dρ ∫sin²φ dφ.
        let syy = t * 2.0 * h * m.powi(3) * (1.0 + q * q) * sin2_integral(alpha);
        let szz = volume * t * t / 12.0;
        let s_local = Matrix3::from_diagonal(&Vector3::new(sxx, syy, szz));
        let mid = self.from_angle + alpha;
        let (sm, cm) = mid.sin_cos();
        // Local (bisector) frame in world axes.
        let es = frame.column(0).into_owned();
        let et = frame.column(1).into_owned();
        let w = frame.column(2).into_owned();
        let eb = es * cm + et * sm;
        let en = w.cross(&eb);
        let rot = Matrix3::from_columns(&[eb, en, w]);
        Ok(MassProperties {
            volume,
            centroid: v3(&self.center) + eb * cx,
            second_moment: rot * s_local * rot.transpose(),
        })
    }
}

/// `α + sinα cosα - 2 sin²α / α`, accurate also for small α (≈ 2α⁵/45).
fn cos2_defect(alpha: f64) -> f64 {
    if alpha < 2.0 {
        // Σ_{k≥2} (-1)^k 4^k α^{2k+1} (2k-2)/(2k+2)!
        let a2 = alpha * alpha;
        let mut sum = 0.0;
        // term_k without the (2k-2) factor: (-1)^k 4^k α^{2k+1}/(2k+2)!
        let mut term = 16.0 * a2 * a2 * alpha / 720.0; // k = 2
        for k in 2..40 {
            let contrib = term * (2 * k - 2) as f64;
            sum += contrib;
            if contrib.abs() <= 1e-18 * sum.abs() {
                break;
            }
            let kf = k as f64;
            term *= -4.0 * a2 / ((2.0 * kf + 3.0) * (2.0 * kf + 4.0));
        }
        sum
    } else {
        let (s, c) = alpha.sin_cos();
        alpha + s * c - 2.0 * s * s / alpha
    }
}

/// `∫ sin²φ dφ` over `[-α, α]` = `α - sinα cosα`, accurate for small α (≈ 2α³/3).
fn sin2_integral(alpha: f64) -> f64 {
    if alpha < 1.0 {
        // Σ_{k≥1} (-1)^{k+1} (2α)^{2k+1} / (2 (2k+1)!)
        let x = 2.0 * alpha;
        let x2 = x * x;
        let mut term = x2 * x / 12.0; // k = 1
        let mut sum = 0.0;
        for k in 1..40 {
            sum += term;
            if term.abs() <= 1e-18 * sum.abs() {
                break;
            }
            let kf = k as f64;
            term *= -x2 / ((2.0 * kf + 2.0) * (2.0 * kf + 3.0));
        }
        sum
    } else {
        let (s, c) = alpha.sin_cos();
        alpha - s * c
    }
}

/// A body shape.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Rectangular block.
    Box(BoxShape),
    /// Convex hull of points.
    Polyhedron(PolyhedronShape),
    /// Polygon swept along a vector.
    Prism(PrismShape),
    /// Voussoir / arch-ring piece.
    AnnularSector(AnnularSectorShape),
    /// A rigid domain of several disjoint parts (a compound body), each a simple shape.
    Compound(Vec<Shape>),
}

impl Shape {
    /// The same shape moved by `d` (m): every point given plus d, every direction, size and
    /// angle as it is.
    pub fn translated(&self, d: &Vector3<f64>) -> Shape {
        let moved = |p: &[f64; 3]| [p[0] + d.x, p[1] + d.y, p[2] + d.z];
        match self {
            Shape::Box(s) => Shape::Box(BoxShape {
                center: moved(&s.center),
                ..s.clone()
            }),
            Shape::Polyhedron(s) => Shape::Polyhedron(PolyhedronShape {
                vertices: s.vertices.iter().map(moved).collect(),
            }),
            Shape::Prism(s) => Shape::Prism(PrismShape {
                polygon: s.polygon.iter().map(moved).collect(),
                ..s.clone()
            }),
            Shape::AnnularSector(s) => Shape::AnnularSector(AnnularSectorShape {
                center: moved(&s.center),
                ..s.clone()
            }),
            Shape::Compound(parts) => {
                Shape::Compound(parts.iter().map(|p| p.translated(d)).collect())
            }
        }
    }

    /// Exact mass properties (unit density), validating the input.
    pub fn mass_properties(&self) -> Result<MassProperties, ShapeError> {
        match self {
            Shape::Box(s) => s.mass_properties(),
            Shape::Polyhedron(s) => s.mass_properties(),
            Shape::Prism(s) => s.mass_properties(),
            Shape::AnnularSector(s) => s.mass_properties(),
            Shape::Compound(parts) => {
                let props = parts
                    .iter()
                    .map(Shape::mass_properties)
                    .collect::<Result<Vec<_>, _>>()?;
                MassProperties::combine(&props).ok_or(ShapeError::NoParts)
            }
        }
    }

    /// Short name of the shape kind: `"box"`, `"polyhedron"`, `"prism"`, `"annular_sector"` or
    /// `"compound"`.
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Box(_) => "box",
            Shape::Polyhedron(_) => "polyhedron",
            Shape::Prism(_) => "prism",
            Shape::AnnularSector(_) => "annular_sector",
            Shape::Compound(_) => "compound",
        }
    }
}

/// Diagonal of the axis-aligned bounding box of the points (m).
fn bbox_diagonal(pts: &[Vector3<f64>]) -> f64 {
    let mut lo = pts[0];
    let mut hi = pts[0];
    for p in pts {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (hi - lo).norm()
}

/// A unit vector perpendicular to the unit vector `n`.
pub(crate) fn any_perpendicular(n: &Vector3<f64>) -> Vector3<f64> {
    let trial = if n.x.abs() <= n.y.abs() && n.x.abs() <= n.z.abs() {
        Vector3::x()
    } else if n.y.abs() <= n.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let p = trial - n * n.dot(&trial);
    p / p.norm()
}

fn sub2(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn dot2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Distance from point `p` to segment `[a, b]` in 2D.
fn point_segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let ab = sub2(b, a);
    let ap = sub2(p, a);
    let len2 = dot2(ab, ab);
    let t = if len2 > 0.0 {
        (dot2(ap, ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let d = [ap[0] - t * ab[0], ap[1] - t * ab[1]];
    dot2(d, d).sqrt()
}

/// Distance between segments `[a, b]` and `[c, d]` in 2D (0 if they cross).
fn segment_distance(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> f64 {
    let o1 = cross2(sub2(b, a), sub2(c, a));
    let o2 = cross2(sub2(b, a), sub2(d, a));
    let o3 = cross2(sub2(d, c), sub2(a, c));
    let o4 = cross2(sub2(d, c), sub2(b, c));
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return 0.0;
    }
    point_segment_distance(a, c, d)
        .min(point_segment_distance(b, c, d))
        .min(point_segment_distance(c, a, b))
        .min(point_segment_distance(d, a, b))
}

/// Checks that the closed polygon is simple: non-adjacent edges are farther
/// apart than `tol`, and adjacent edges do not fold back onto each other.
/// O(n²).
fn check_simple(uv: &[[f64; 2]], tol: f64) -> Result<(), ShapeError> {
    let n = uv.len();
    for i in 0..n {
        let (a, b) = (uv[i], uv[(i + 1) % n]);
        // Adjacent edge (i, i+1): the far end must not lie on the other edge.
        let j = (i + 1) % n;
        let c = uv[(j + 1) % n];
        if point_segment_distance(c, a, b) <= tol || point_segment_distance(a, b, c) <= tol {
            return Err(ShapeError::PolygonNotSimple {
                first: i,
                second: j,
            });
        }
        for j in (i + 2)..n {
            if i == 0 && j == n - 1 {
                continue; // adjacent through the closing vertex
            }
            let (c, d) = (uv[j], uv[(j + 1) % n]);
            if segment_distance(a, b, c, d) <= tol {
                return Err(ShapeError::PolygonNotSimple {
                    first: i,
                    second: j,
                });
            }
        }
    }
    Ok(())
}
