//! The validated, immutable model: bodies with exact mass properties, interfaces, and the chain
//! (a spanning tree from the ground giving the coordinates, DOF(1), plus the loop closures).

use std::collections::{HashMap, VecDeque};
use std::ops::Range;

use nalgebra::{Matrix3, Vector3};

use crate::disjoint_sets::DisjointSets;
use crate::error::ModelError;
use crate::shapes::{MassProperties, Shape};
use crate::spec::{BodySpec, ImpactLaw, InterfaceSpec, PivotSpec, StructureSpec};

/// Relative tolerance for geometric checks (parallel edges, planarity), times the model's size.
pub const GEOMETRY_TOLERANCE: f64 = 1e-6;

/// One rigid body with its exact mass properties (world coordinates at rest).
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Name from the model file.
    pub name: String,
    /// The shape it was built from.
    pub shape: Shape,
    /// Mass Mⁿ (kg).
    pub mass: f64,
    /// Density used (kg/m³): the given one, or mass / volume when a mass is given.
    pub density: f64,
    /// Volume Vₙ (m³).
    pub volume: f64,
    /// Centre of mass at rest (m, world).
    pub com: Vector3<f64>,
    /// Inertia tensor about the centre of mass, world axes at rest (kg m²).
    pub inertia: Matrix3<f64>,
    /// Second moment ∫ρ (x − c)(x − c)ᵀ dV about the centre of mass (kg m²).
    pub second_moment: Matrix3<f64>,
}

/// The parent side of an interface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parent {
    /// The ground (moves with the ground motion; fixed in the ground frame).
    Ground,
    /// A body, by index into [`Model::bodies`].
    Body(usize),
}

/// Which of an angle's two pivots is active: P⁺ (for φ > 0) or P⁻ (for φ < 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Side {
    /// P⁺, the pivot active for a positive angle.
    Positive,
    /// P⁻, the pivot active for a negative angle.
    Negative,
}

impl Side {
    /// The side selected by the sign of an angle; `tie` when it is exactly zero.
    pub fn of(angle: f64, tie: Side) -> Side {
        if angle > 0.0 {
            Side::Positive
        } else if angle < 0.0 {
            Side::Negative
        } else {
            tie
        }
    }
    /// +1 or −1.
    pub fn sign(self) -> f64 {
        match self {
            Side::Positive => 1.0,
            Side::Negative => -1.0,
        }
    }
    /// The other side.
    pub fn flipped(self) -> Side {
        match self {
            Side::Positive => Side::Negative,
            Side::Negative => Side::Positive,
        }
    }
}

/// The geometry of an interface.
#[derive(Clone, Debug, PartialEq)]
pub enum InterfaceKind {
    /// One rotation coordinate φ about `axis`, pivoting on P⁺ (φ > 0) or P⁻ (φ < 0).
    Hinge {
        /// Unit axis u (world, at rest).
        axis: Vector3<f64>,
        /// A point of the pivot line P⁺ (m, world at rest).
        pivot_positive: Vector3<f64>,
        /// A point of the pivot line P⁻ (m, world at rest).
        pivot_negative: Vector3<f64>,
    },
    /// Two tilts of the child on a rectangular contact: `.1` about e₁ (the direction of the first
    /// edge, corner 0 → corner 1), then `.2` about e₂ = n × e₁, n the unit normal pointing to the
    /// child. The pivot is the corner selected by the two signs.
    RockingBase {
        /// The four corners (m, world at rest), in the order given.
        corners: [Vector3<f64>; 4],
        /// Unit normal n of the contact plane, pointing to the child's side.
        normal: Vector3<f64>,
        /// Unit e₁, along the edge corner 0 → corner 1: axis of the first tilt.
        e1: Vector3<f64>,
        /// Unit e₂ = n × e₁: axis of the second tilt.
        e2: Vector3<f64>,
        /// The child may also twist about n on its pivot corner (loop closures only): the tilts
        /// are then those of the child's face normal, Γ_AᵀΓ_B n = R(e₁, θ₁)R(e₂, θ₂) n, and the
        /// closure has no orientation row.
        twist: bool,
    },
}

impl InterfaceKind {
    /// Number of angles the interface carries: 1 (hinge) or 2 (rocking base).
    pub fn angle_count(&self) -> usize {
        match self {
            InterfaceKind::Hinge { .. } => 1,
            InterfaceKind::RockingBase { .. } => 2,
        }
    }

    /// Rest-frame axis of angle `component` (u for a hinge; e₁ or e₂ for a rocking base).
    pub fn axis(&self, component: usize) -> Vector3<f64> {
        match self {
            InterfaceKind::Hinge { axis, .. } => *axis,
            InterfaceKind::RockingBase { e1, e2, .. } => {
                if component == 0 {
                    *e1
                } else {
                    *e2
                }
            }
        }
    }

    /// The active pivot point (world at rest) for the given sides of this interface's angles.
    ///
    /// Rocking base: a positive tilt about e₁ pivots on the corner edge of least e₂·x, a negative
    /// one on the greatest; a positive tilt about e₂ pivots on the edge of greatest e₁·x, a negative
    /// one on the least (so that the rest of the base lifts towards n).
    pub fn pivot(&self, sides: &[Side]) -> Vector3<f64> {
        match self {
            InterfaceKind::Hinge {
                pivot_positive,
                pivot_negative,
                ..
            } => match sides[0] {
                Side::Positive => *pivot_positive,
                Side::Negative => *pivot_negative,
            },
            InterfaceKind::RockingBase {
                corners, e1, e2, ..
            } => {
                let score =
                    |c: &Vector3<f64>| -sides[0].sign() * e2.dot(c) + sides[1].sign() * e1.dot(c);
                let mut best = corners[0];
                for c in &corners[1..] {
                    if score(c) > score(&best) {
                        best = *c;
                    }
                }
                best
            }
        }
    }
}

/// Whether an interface is a coordinate of the spanning tree or a loop closure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// In the spanning tree: its angles are the coordinates `first_coord ..`.
    Tree {
        /// Index of its first coordinate in q.
        first_coord: usize,
    },
    /// A loop closure: index into [`Model::closures`].
    Closure {
        /// Index into [`Model::closures`].
        index: usize,
    },
}

/// One interface, validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Interface {
    /// Name from the model file.
    pub name: String,
    /// Parent body or ground.
    pub parent: Parent,
    /// Child body index.
    pub child: usize,
    /// Hinge or rocking base geometry.
    pub kind: InterfaceKind,
    /// Impact law for the impact stage.
    pub impact: ImpactLaw,
    /// Tree coordinate(s) or loop closure.
    pub role: Role,
    /// The interface's pivot-side slots in an [`crate::ActivePivots`] (one per angle).
    pub slots: Range<usize>,
}

/// One generalized coordinate qₖ (a tree angle), in the order of q.
#[derive(Clone, Debug, PartialEq)]
pub struct Coordinate {
    /// `<interface>` for a hinge, `<interface>.1` / `<interface>.2` for a rocking base.
    pub name: String,
    /// Interface index.
    pub interface: usize,
    /// 0, or 1 for the second tilt of a rocking base.
    pub component: usize,
    /// Unit axis uₖ in the rest frame.
    pub axis: Vector3<f64>,
    /// The coordinate whose frame this one rotates relative to (None: the ground).
    /// Always smaller than this coordinate's index (topological order).
    pub parent: Option<usize>,
}

/// One loop closure: an interface not in the tree, imposing Φ(q) = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Closure {
    /// Interface index.
    pub interface: usize,
    /// Its first row in Φ.
    pub first_row: usize,
    /// Number of rows: 5 for a hinge (point coincidence 3 + axis alignment 2), 4 for a rocking base
    /// (point coincidence 3 + the two tilt axes staying perpendicular 1).
    pub rows: usize,
}

/// A validated structure: immutable once built.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// Name of the structure.
    pub name: String,
    /// g (m/s²).
    pub gravity: f64,
    /// Bodies in file order.
    pub bodies: Vec<Body>,
    /// Interfaces in file order.
    pub interfaces: Vec<Interface>,
    /// Generalized coordinates q in order (DOF(1) = `coords.len()`).
    pub coords: Vec<Coordinate>,
    /// Loop closures.
    pub closures: Vec<Closure>,
    /// For each body, the coordinate whose frame it moves with (the last angle of the tree interface
    /// whose child it is).
    pub body_coord: Vec<usize>,
    /// User/symmetry constraints φₐ − s φ_b = 0 as (a, b, s), rows after the closures' in Φ.
    pub symmetries: Vec<(usize, usize, f64)>,
    /// Rows of Φ from the loop closures (the symmetry rows follow them).
    pub closure_rows: usize,
    /// Total rows of Φ: closures, then symmetries.
    pub constraint_rows: usize,
    /// Total pivot-side slots: one per tree coordinate (slot k = coordinate k), then one per closure
    /// angle.
    pub slot_count: usize,
    /// A length scale of the model (largest extent of the bodies' centres and pivots, m, ≥ 1e-3),
    /// used to scale tolerances.
    pub size: f64,
}

fn finite3(v: &[f64; 3], item: &str, field: &str) -> Result<Vector3<f64>, ModelError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(Vector3::from(*v))
    } else {
        Err(ModelError::new(
            item,
            format!("{field} has a NaN or infinite value: {v:?}"),
        ))
    }
}

/// A pivot farther from its child's centre than this many times the child's size (the cube root
/// of its volume) is refused.
const PIVOT_REACH: f64 = 100.0;

/// Why a body or interface name cannot be used: it becomes a column of the CSV outputs
/// (`base`, `base_rate`, `base_state`) and an entry of their `;`-joined lists, so separators,
/// quotes and control characters would break them.
fn unusable_name(name: &str) -> Option<&'static str> {
    name.chars()
        .any(|c| c.is_control() || matches!(c, ',' | ';' | '"'))
        .then_some("the name holds a comma, a semicolon, a quote or a control character (a line break, a tab), which the CSV outputs cannot carry")
}

fn quoted(kind: &str, name: &str) -> String {
    format!("{kind} \"{name}\"")
}

/// The mass properties at unit density of each part of a body (its one shape, or each block of
/// a compound body), with the block's own density when it gives one; every block must give
/// exactly one shape.
fn body_parts(
    spec: &BodySpec,
    item: &str,
) -> Result<Vec<(MassProperties, Option<f64>)>, ModelError> {
    let exactly_one = |shapes: Vec<Shape>, what: &str| match shapes.len() {
        1 => Ok(shapes.into_iter().next().expect("one shape")),
        0 => Err(ModelError::new(
            item,
            format!("{what} no shape: give one of box, polyhedron, prism, annular_sector"),
        )),
        _ => {
            let kinds: Vec<_> = shapes.iter().map(|s| s.kind()).collect();
            Err(ModelError::new(
                item,
                format!(
                    "{what} {} shapes ({}): give exactly one",
                    kinds.len(),
                    kinds.join(", ")
                ),
            ))
        }
    };
    let props = |shape: &Shape, label: String| {
        shape
            .mass_properties()
            .map_err(|e| ModelError::new(format!("{item} ({label})"), e.to_string()))
    };
    if !spec.is_compound() {
        let shape = exactly_one(spec.own_shapes(), "has")?;
        return Ok(vec![(props(&shape, shape.kind().to_string())?, None)]);
    }
    let own = spec.own_shapes();
    if !own.is_empty() {
        let kinds: Vec<_> = own.iter().map(|s| s.kind()).collect();
        return Err(ModelError::new(
            item,
            format!(
                "has blocks and a shape of its own ({}): a compound body's shapes are all in its \
                 blocks",
                kinds.join(", ")
            ),
        ));
    }
    spec.blocks
        .iter()
        .enumerate()
        .map(|(k, part)| {
            let shape = exactly_one(part.shapes(), &format!("has in block {}", k + 1))?;
            let label = format!("block {}, {}", k + 1, shape.kind());
            Ok((props(&shape, label)?, part.density))
        })
        .collect()
}

fn build_body(spec: &BodySpec) -> Result<Body, ModelError> {
    let item = quoted("body", &spec.name);
    let parts = body_parts(spec, &item)?;
    let positive = |what: String, x: f64, unit: &str| {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(ModelError::new(
                item.clone(),
                format!("{what} must be a positive number of {unit}, got {x}"),
            ))
        }
    };
    if let Some(m) = spec.mass {
        positive("mass".into(), m, "kg")?;
    }
    if let Some(d) = spec.density {
        positive("density".into(), d, "kg/m³")?;
    }
    for (k, part) in spec.blocks.iter().enumerate() {
        if let Some(d) = part.density {
            positive(format!("the density of block {}", k + 1), d, "kg/m³")?;
            if spec.mass.is_some() {
                return Err(ModelError::new(
                    item,
                    format!(
                        "gives a mass and block {} a density: give the blocks' densities, or \
                         the body's mass (spread at one density over its blocks)",
                        k + 1
                    ),
                ));
            }
        }
    }
    let volume: f64 = parts.iter().map(|(p, _)| p.volume).sum();
    // Each part's density: its own, else the body's, else the body's mass over its volume.
    let mut densities = Vec::with_capacity(parts.len());
    for (k, (_, own)) in parts.iter().enumerate() {
        densities.push(match (own, spec.mass, spec.density) {
            (Some(d), _, _) => *d,
            (None, Some(m), _) => m / volume,
            (None, None, Some(d)) => d,
            (None, None, None) if spec.is_compound() => {
                return Err(ModelError::new(
                    item,
                    format!(
                        "block {} needs a density (kg/m³): give it, or the body's density or mass",
                        k + 1
                    ),
                ));
            }
            (None, None, None) => {
                return Err(ModelError::new(
                    item,
                    "needs a density (kg/m³) or a mass (kg)",
                ));
            }
        });
    }
    let (low, high) = DENSITY_RANGE;
    for (k, d) in densities.iter().enumerate() {
        if !(low..=high).contains(d) {
            let which = if spec.is_compound() {
                format!("block {}'s density", k + 1)
            } else if spec.mass.is_some() {
                "density (its mass over its volume)".to_string()
            } else {
                "density".to_string()
            };
            return Err(ModelError::new(
                item,
                format!(
                    "its {which} {d:e} kg/m³ is outside {low:e}…{high:e} kg/m³ (stone is about \
                     2500; check the units: kg, m, kg/m³)"
                ),
            ));
        }
    }
    // Sums over the parts (parallel-axis theorem): m = Σ ρₖVₖ, c = Σ ρₖVₖcₖ / m,
    // S = Σ ρₖ (Sₖ + Vₖ (cₖ − c)(cₖ − c)ᵀ).
    let mass: f64 = parts
        .iter()
        .zip(&densities)
        .map(|((p, _), d)| d * p.volume)
        .sum();
    let com = parts
        .iter()
        .zip(&densities)
        .fold(Vector3::zeros(), |acc, ((p, _), d)| {
            acc + p.centroid * (d * p.volume)
        })
        / mass;
    let second_moment = parts
        .iter()
        .zip(&densities)
        .fold(Matrix3::zeros(), |acc, ((p, _), d)| {
            let r = p.centroid - com;
            acc + (p.second_moment + r * r.transpose() * p.volume) * *d
        });
    let shape = if spec.is_compound() {
        Shape::Compound(spec.blocks.iter().flat_map(|p| p.shapes()).collect())
    } else {
        spec.own_shapes()
            .pop()
            .expect("one shape, checked by body_parts")
    };
    let body = Body {
        name: spec.name.clone(),
        mass,
        density: mass / volume,
        volume,
        com,
        inertia: Matrix3::identity() * second_moment.trace() - second_moment,
        second_moment,
        shape,
    };
    // Sizes or densities far outside engineering ranges overflow (or underflow) the mass
    // properties; say so here rather than let a later check misread the infinities.
    let finite = body.mass.is_finite()
        && body.mass > 0.0
        && body.com.iter().all(|x| x.is_finite())
        && body.inertia.iter().all(|x| x.is_finite())
        && body.second_moment.iter().all(|x| x.is_finite());
    if !finite {
        return Err(ModelError::new(
            item,
            format!(
                "its mass properties are not finite numbers (volume {:e} m³, mass {:e} kg): \
                 the sizes or the density are out of range (check the units: metres, kg/m³)",
                body.volume, body.mass
            ),
        ));
    }
    Ok(body)
}

/// A pivot given as a point or an edge: returns a point on the line, checking an edge is parallel
/// to the axis.
fn pivot_point(
    p: &PivotSpec,
    axis: &Vector3<f64>,
    item: &str,
    field: &str,
    size: f64,
) -> Result<Vector3<f64>, ModelError> {
    match p {
        PivotSpec::Point(x) => finite3(x, item, field),
        PivotSpec::Segment([a, b]) => {
            let a = finite3(a, item, field)?;
            let b = finite3(b, item, field)?;
            let d = b - a;
            if d.norm() <= GEOMETRY_TOLERANCE * size {
                return Err(ModelError::new(
                    format!("{item} ({field})"),
                    "the two end points of the pivot edge coincide",
                ));
            }
            let sin = d.normalize().cross(axis).norm();
            if sin > GEOMETRY_TOLERANCE {
                return Err(ModelError::new(
                    format!("{item} ({field})"),
                    format!(
                        "the pivot edge is not parallel to the axis: they differ by {:.4}°",
                        sin.asin().to_degrees()
                    ),
                ));
            }
            Ok(a)
        }
    }
}

/// Which side of a joint face is its child's: the side of a point (its centre of mass, or the
/// centroid of the part of a compound body the face lies on, [`side_point`]), or the side the
/// interface's `normal` points to.
enum ChildSide {
    Point(Vector3<f64>),
    Normal(Vector3<f64>),
}

/// How far (rad) an interface's `normal` may be from its joint face's own normal: it only says
/// which side of the face is the child's, and a face written with rounded coordinates (accepted
/// to 1e-6 of the model's size) has a normal off the exact one.
const NORMAL_SLACK: f64 = 0.01745; // 1°

/// The unit direction of an interface's `normal` (finite, not zero), refused otherwise; for a
/// convex child (a box or a polyhedron) it must point to its centre's side, where the whole
/// body lies.
fn given_normal(
    n: &[f64; 3],
    child: &Body,
    face: &[[f64; 3]],
    item: &str,
) -> Result<Vector3<f64>, ModelError> {
    let item_n = format!("{item} (normal)");
    let n = finite3(n, &item_n, "normal")?;
    let largest = n.amax();
    if largest == 0.0 {
        return Err(ModelError::new(item_n, "the normal is the zero vector"));
    }
    let n = (n / largest).normalize();
    let convex = matches!(child.shape, Shape::Box(_) | Shape::Polyhedron(_));
    let on_face = face.first().map_or(child.com, |x| Vector3::from(*x));
    if convex && n.dot(&(child.com - on_face)) < 0.0 {
        return Err(ModelError::new(
            item_n,
            format!(
                "[{:.6}, {:.6}, {:.6}] points away from the centre of mass of its child, a \
                 convex body that lies wholly on its centre's side of any face it touches: \
                 reverse it (or leave it out)",
                n.x, n.y, n.z
            ),
        ));
    }
    Ok(n)
}

/// The side of `face_normal` (unit, a joint face's own) the child is on: +1 or −1, or an error
/// where it cannot be told (the child's point in the face's plane, within `tolerance` m) or the
/// interface's normal is not the face's (beyond [`NORMAL_SLACK`]). `what` names the face's
/// normal in the message.
fn side_of(
    child: &ChildSide,
    face_normal: &Vector3<f64>,
    on_face: &Vector3<f64>,
    tolerance: f64,
    item: &str,
    what: &str,
) -> Result<f64, ModelError> {
    match child {
        ChildSide::Point(p) => {
            let side = face_normal.dot(&(p - on_face));
            if side.abs() <= tolerance {
                return Err(ModelError::new(
                    item,
                    format!(
                        "the child's centre of mass lies in {what}: cannot tell which side is \
                         the child's (give the interface's `normal`)"
                    ),
                ));
            }
            Ok(side.signum())
        }
        ChildSide::Normal(n) => {
            let cos = n.dot(face_normal);
            if cos.abs() < NORMAL_SLACK.cos() {
                return Err(ModelError::new(
                    format!("{item} (normal)"),
                    format!(
                        "[{:.6}, {:.6}, {:.6}] is not the normal of {what}: it is {:.4}° from \
                         it (at most {:.0}°)",
                        n.x,
                        n.y,
                        n.z,
                        cos.abs().min(1.0).acos().to_degrees(),
                        NORMAL_SLACK.to_degrees()
                    ),
                ));
            }
            Ok(cos.signum())
        }
    }
}

/// The point [`Model::from_spec`] takes for the child's side of an interface with no `normal`,
/// whose points are `face`, on the body of `spec` ([`side_point`]); None for a body it refuses.
pub(crate) fn default_side_point(spec: &BodySpec, face: &[[f64; 3]]) -> Option<Vector3<f64>> {
    build_body(spec).ok().map(|body| side_point(&body, face))
}

/// A point on the child's side of an interface whose points are `face`: its centre of mass, or
/// for a compound body (a rigid domain of several blocks, not convex) the centroid of the part
/// the face lies on: the part on whose surface most of the face's points lie; among equals, the
/// one of least excess of the face's centre beyond the planes of its faces, then the nearest
/// centroid. The domain's centre of mass may lie beyond the plane of a face on its other side
/// (a corner wedge of a wall, whose head joints face its own centre).
///
/// The face's points, not its centre alone, name the part: `crr assemble` writes the coplanar
/// faces of two domains as one interface on the convex hull of their corners, whose centre may
/// lie between the parts that touch (the two legs of a bridge-shaped domain), even on a part of
/// the child across the face's plane; each of the hull's corners is a corner of a face that
/// touches, so it lies on a part on the child's side.
fn side_point(body: &Body, face: &[[f64; 3]]) -> Vector3<f64> {
    let Shape::Compound(parts) = &body.shape else {
        return body.com;
    };
    if face.is_empty() {
        return body.com;
    }
    let points: Vec<Vector3<f64>> = face.iter().map(|x| Vector3::from(*x)).collect();
    let centre = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    let scale = body.volume.cbrt();
    // How far x lies beyond the planes of the part's faces, in units of the geometry's
    // tolerance, rounded: 0 on or in the part, so that parts touching x compare as equals.
    let excess = |surface: &crate::shapes::Surface, x: &Vector3<f64>| {
        let beyond = (0..surface.face_count())
            .map(|f| {
                let on = surface.vertices[surface.faces[f][0]];
                surface.face_normal(f).dot(&(x - on))
            })
            .fold(f64::NEG_INFINITY, f64::max);
        (beyond / (GEOMETRY_TOLERANCE * scale)).round().max(0.0)
    };
    parts
        .iter()
        .filter_map(|part| {
            let surface = part.surface().ok()?;
            let centroid = part.mass_properties().ok()?.centroid;
            let touching = points.iter().filter(|x| excess(&surface, x) == 0.0).count();
            Some((
                touching,
                excess(&surface, &centre),
                (centroid - centre).norm(),
                centroid,
            ))
        })
        .min_by(|a, b| {
            b.0.cmp(&a.0)
                .then(a.1.total_cmp(&b.1))
                .then(a.2.total_cmp(&b.2))
        })
        .map_or(body.com, |(_, _, _, centroid)| centroid)
}

fn hinge_kind(
    spec: &InterfaceSpec,
    child: &ChildSide,
    item: &str,
    size: f64,
) -> Result<InterfaceKind, ModelError> {
    let axis = spec
        .axis
        .ok_or_else(|| ModelError::new(item, "a hinge needs an axis (or give a rocking_base)"))?;
    let axis = finite3(&axis, item, "axis")?;
    // Divided by its largest component first: the norm of [0, 1e160, 0] overflows and that of
    // [0, 1e-200, 0] underflows, while any non-zero length is a direction.
    let largest = axis.amax();
    if largest == 0.0 {
        return Err(ModelError::new(
            format!("{item} (axis)"),
            "the axis is the zero vector",
        ));
    }
    let axis = (axis / largest).normalize();
    let pp = spec
        .pivot_positive
        .as_ref()
        .ok_or_else(|| ModelError::new(item, "a hinge needs pivot_positive"))?;
    let pn = spec.pivot_negative.as_ref().ok_or_else(|| {
        ModelError::new(
            item,
            "a hinge needs pivot_negative (equal to pivot_positive for a plain hinge)",
        )
    })?;
    let pp = pivot_point(pp, &axis, item, "pivot_positive", size)?;
    let pn = pivot_point(pn, &axis, item, "pivot_negative", size)?;
    // A given normal lies across the axis (the joint face contains it).
    if let ChildSide::Normal(n) = child
        && n.dot(&axis).abs() > NORMAL_SLACK.sin()
    {
        return Err(ModelError::new(
            format!("{item} (normal)"),
            format!(
                "[{:.6}, {:.6}, {:.6}] is not perpendicular to the axis: it makes {:.4}° with \
                 it, not within {:.0}° of 90° (the joint face contains the axis)",
                n.x,
                n.y,
                n.z,
                n.dot(&axis).abs().min(1.0).acos().to_degrees(),
                NORMAL_SLACK.to_degrees()
            ),
        ));
    }
    // Offset between the two pivot lines, perpendicular to the axis.
    let offset = (pn - pp) - axis * axis.dot(&(pn - pp));
    if offset.norm() > GEOMETRY_TOLERANCE * size {
        // A small positive rotation about P⁺ moves P⁻ with velocity u × (P⁻ − P⁺): it must go
        // towards the child's side of the joint face, i.e. the side of the child's centre.
        let lift = axis.cross(&offset).normalize();
        let side = side_of(
            child,
            &lift,
            &pp,
            GEOMETRY_TOLERANCE * size,
            item,
            "the joint face through the two pivots",
        )?;
        if side < 0.0 {
            let away = match child {
                ChildSide::Point(_) => "away from the child's centre of mass",
                ChildSide::Normal(_) => "against the interface's normal",
            };
            return Err(ModelError::new(
                item,
                format!(
                    "pivots swapped: a small positive rotation about pivot_positive moves pivot_negative into the parent \
                     ({away}). With a right-handed angle about the axis, pivot_positive must be \
                     the edge the child rocks on when the angle is positive; exchange pivot_positive and pivot_negative, or reverse the axis"
                ),
            ));
        }
    }
    Ok(InterfaceKind::Hinge {
        axis,
        pivot_positive: pp,
        pivot_negative: pn,
    })
}

fn rocking_base_kind(
    corners: &[[f64; 3]],
    twist: bool,
    child: &ChildSide,
    item: &str,
    size: f64,
) -> Result<InterfaceKind, ModelError> {
    let item_c = format!("{item} (rocking_base.corners)");
    if corners.len() != 4 {
        return Err(ModelError::new(
            item_c,
            format!("needs exactly 4 corners, got {}", corners.len()),
        ));
    }
    let mut c = [Vector3::zeros(); 4];
    for (k, x) in corners.iter().enumerate() {
        c[k] = finite3(x, &item_c, &format!("corner {k}"))?;
    }
    let tol = GEOMETRY_TOLERANCE * size;
    let edges: Vec<Vector3<f64>> = (0..4).map(|k| c[(k + 1) % 4] - c[k]).collect();
    if let Some(k) = edges.iter().position(|e| e.norm() <= tol) {
        return Err(ModelError::new(
            item_c,
            format!("corners {k} and {} coincide", (k + 1) % 4),
        ));
    }
    let mut normal = edges[0].cross(&edges[1]).normalize();
    let off_plane = normal.dot(&(c[3] - c[0]));
    if off_plane.abs() > tol {
        return Err(ModelError::new(
            item_c,
            format!(
                "the corners are not coplanar: corner 3 is {off_plane:.3e} m off the plane of the first three"
            ),
        ));
    }
    for k in 0..4 {
        let cos = edges[k].normalize().dot(&edges[(k + 1) % 4].normalize());
        if cos.abs() > GEOMETRY_TOLERANCE {
            return Err(ModelError::new(
                item_c,
                format!(
                    "not a rectangle: the angle at corner {} is {:.4}°, not 90° (are the corners in order around it?)",
                    (k + 1) % 4,
                    cos.clamp(-1.0, 1.0).acos().to_degrees()
                ),
            ));
        }
    }
    if side_of(child, &normal, &c[0], tol, &item_c, "the contact plane")? < 0.0 {
        normal = -normal;
    }
    let e1 = edges[0].normalize();
    let e2 = normal.cross(&e1);
    Ok(InterfaceKind::RockingBase {
        corners: c,
        normal,
        e1,
        e2,
        twist,
    })
}

/// The largest DOF(1) a model may have: the equations of motion, the impact laws and the
/// workspaces are dense (n × n matrices, Cholesky and rank-revealing factorisations), so a larger
/// model would allocate gigabytes (20 000 coordinates: 3.2 GB per matrix) and take minutes per
/// evaluation. Refused by [`Model::from_spec`] before anything of that size is allocated.
pub const MAX_COORDINATES: usize = 2048;

/// The error of a model over [`MAX_COORDINATES`] (`n` coordinates, or `at_least` n).
fn too_many_coordinates(name: &str, n: usize, at_least: &str) -> ModelError {
    let gb = (n * n * 8) as f64 / 1e9;
    ModelError::new(
        quoted("model", name),
        format!(
            "has DOF(1) = {at_least}{n} coordinates, more than the {MAX_COORDINATES} that crr's \
             dense equations of motion handle (one n × n mass matrix alone would take {gb:.1} GB, \
             and its factorisation O(n³) work at every evaluation); simulate the structure's \
             independent parts as separate models"
        ),
    )
}

/// Farther than this many model sizes from the world origin, a structure is computed moved so
/// that its bodies' mean centre is near the origin ([`Model::moved_near_origin`]): the dynamics
/// sums spatial quantities about the origin (a body's inertia there, I_c − m \[c\]×², less its
/// share about its centre), so a body at D carries D²/L² times its own inertia and round-off
/// takes ε D²/L² of M(q). Placed in survey coordinates (5e5 m away, 2.5e5 times its size), a
/// single block's rocking lost its energy balance and a stack stalled the integrator (an
/// independent review), before such models were moved. Within 10 sizes (every bundled model)
/// the model is used as given.
pub const MOVED_BEYOND: f64 = 10.0;

/// The point a structure of size `size` (m) whose points' mean is `mean` is moved to the origin
/// from: `mean` rounded to a multiple of u, the power of two at or above `size`. A coordinate x
/// with |x| ≥ u is a multiple of its own ulp, which divides u, and lies within size + u/2 ≤ 1.5 u
/// of the point, so x minus the point is a multiple of ulp(x) below 2⁵³ ulp(x) and is computed
/// exactly (smaller coordinates, of a structure near the origin, move to the round-off of u).
/// The mean's own round-off (the order the points are listed in) changes the point only where
/// the mean sits at a rounding boundary, and the moves are exact then too.
pub fn exact_reference(mean: &Vector3<f64>, size: f64) -> Vector3<f64> {
    let unit = size.log2().ceil().exp2();
    (mean / unit).map(f64::round) * unit
}

impl Model {
    /// The same structure moved by `d` (m): every body's centre and shape, every pivot line's
    /// point and every corner plus d; axes, normals, mass properties about the centres, the
    /// tree, the loops and the size as they are. Gravity and the ground's motion are the same
    /// everywhere, so the moved structure has the same motion in its angles, the same energies
    /// relative to rest and the same contact forces. (The dynamics sums spatial quantities about
    /// the world origin, whose round-off grows as the square of a body's distance from it: a
    /// structure given far from the origin is computed moved near it.)
    pub fn translated(&self, d: &Vector3<f64>) -> Model {
        let mut moved = self.clone();
        for body in &mut moved.bodies {
            body.com += d;
            body.shape = body.shape.translated(d);
        }
        for interface in &mut moved.interfaces {
            match &mut interface.kind {
                InterfaceKind::Hinge {
                    pivot_positive,
                    pivot_negative,
                    ..
                } => {
                    *pivot_positive += d;
                    *pivot_negative += d;
                }
                InterfaceKind::RockingBase { corners, .. } => {
                    for c in corners.iter_mut() {
                        *c += d;
                    }
                }
            }
        }
        moved
    }

    /// This model moved so that its bodies' mean centre is near the origin, when a body's
    /// centre lies farther than [`MOVED_BEYOND`] model sizes from it; None otherwise (the model
    /// is used as it is). Angles, the mass matrix M(q), the generalized forces, energies relative
    /// to rest and contact forces are the same for both, up to the round-off the move avoids.
    ///
    /// The move is the mean centre rounded to a multiple of u, the power of two at or above the
    /// model's size ([`exact_reference`]): each moved coordinate is computed exactly. The moved
    /// model is the given one to the bit, and the order in which the bodies are listed (which
    /// changes the mean by round-off) does not change the move.
    pub fn moved_near_origin(&self) -> Option<Model> {
        let far = self
            .bodies
            .iter()
            .any(|b| b.com.norm() > MOVED_BEYOND * self.size);
        if !far {
            return None;
        }
        let mean =
            self.bodies.iter().map(|b| b.com).sum::<Vector3<f64>>() / self.bodies.len() as f64;
        Some(self.translated(&-exact_reference(&mean, self.size)))
    }

    /// Validates a description and builds the model: mass properties, interface geometry, the
    /// spanning tree from the ground (coordinates in breadth-first order, interfaces in file order)
    /// and the loop closures.
    pub fn from_spec(spec: &StructureSpec) -> Result<Model, ModelError> {
        check_structure(spec)?;
        let (bodies, body_index) = build_bodies(spec)?;
        let size = length_scale(spec, &bodies);
        let ends = build_interfaces(spec, &bodies, &body_index, size)?;
        let (order, in_tree) = spanning_tree(&ends, &bodies)?;
        check_twist_closes_a_loop(spec, &ends, &order)?;
        let TreeCoordinates {
            coords,
            body_coord,
            mut roles,
            mut slots,
        } = tree_coordinates(
            |k, comp| coordinate_name(&spec.interface[k].name, ends[k].2.angle_count(), comp),
            &ends,
            &order,
            bodies.len(),
        );
        let (closures, row, slot) =
            loop_closures(&ends, &in_tree, &mut roles, &mut slots, coords.len());
        let symmetries = symmetry_rows(spec, &coords)?;
        let closure_rows = row;
        let row = row + symmetries.len();
        if coords.len() > MAX_COORDINATES {
            return Err(too_many_coordinates(&spec.name, coords.len(), ""));
        }
        let interfaces = ends
            .into_iter()
            .enumerate()
            .map(|(k, (parent, child, kind))| Interface {
                name: spec.interface[k].name.clone(),
                parent,
                child,
                kind,
                impact: spec.interface[k].impact,
                role: roles[k],
                slots: slots[k].clone(),
            })
            .collect();
        Ok(Model {
            name: spec.name.clone(),
            gravity: spec.gravity,
            bodies,
            interfaces,
            coords,
            closures,
            body_coord,
            symmetries,
            closure_rows,
            constraint_rows: row,
            slot_count: slot,
            size,
        })
    }

    /// The chain left when the loop-closing interfaces `open` (indices into
    /// [`Model::interfaces`]) lift off: the same bodies, tree and coordinates q, without those
    /// interfaces, their closure rows and their slots. The interfaces kept are renumbered in
    /// their order (so are the closures, their rows and the closure slots after the tree's);
    /// tree slots and coordinates keep their indices, so a state q, q̇ of this model is one of
    /// `self` and the other way round. A tree interface cannot be dropped this way (the chain
    /// would have to be re-rooted): that is an error naming it.
    pub fn without_loop_closures(&self, open: &[usize]) -> Result<Model, ModelError> {
        if let Some(&k) = open.iter().find(|&&k| {
            self.interfaces
                .get(k)
                .is_none_or(|i| !matches!(i.role, Role::Closure { .. }))
        }) {
            let name = self
                .interfaces
                .get(k)
                .map_or_else(|| format!("#{k}"), |i| i.name.clone());
            return Err(ModelError::new(
                quoted("interface", &name),
                "is not a loop closure of the model: opening it would need the chain re-rooted",
            ));
        }
        // With only loop closures open the file's tree still reaches every body, so the
        // general construction keeps it (and turns nothing round).
        Ok(self.with_open_interfaces(open, &[])?.0)
    }

    /// The chain left when the interfaces `open` (indices into [`Model::interfaces`], of a
    /// model built from a file) lift off, whichever they are: the same bodies, the interfaces
    /// kept (renumbered in their order), and a spanning tree grown again from the ground: the
    /// file's tree where it still reaches every body, and otherwise
    /// interfaces turned round ([`reversed_kind`]) to reach the bodies that hung from an open
    /// one (a capital left on the entablature when its column's neck opens). An interface
    /// turned round carries the file's names; a rocking base's tilts swap (its first coordinate
    /// is the file's `<name>.2`). Symmetry rows between two coordinates still in the tree are
    /// kept, the others dropped. Interfaces in `last_resort` enter the tree only where the
    /// others cannot reach a body (a face that has just landed stays a loop closure, so that
    /// its landing is an impulse on the loop's rows). Also returns, per interface kept, whether
    /// it was turned round. Errors: a body left with no support (a flight), or a twisting seat
    /// that would have to enter the tree.
    pub fn with_open_interfaces(
        &self,
        open: &[usize],
        last_resort: &[usize],
    ) -> Result<(Model, Vec<bool>), ModelError> {
        let kept: Vec<usize> = (0..self.interfaces.len())
            .filter(|k| !open.contains(k))
            .collect();
        let names: Vec<String> = kept
            .iter()
            .map(|&k| self.interfaces[k].name.clone())
            .collect();
        let mut ends: Vec<InterfaceEnds> = kept
            .iter()
            .map(|&k| {
                let i = &self.interfaces[k];
                (i.parent, i.child, i.kind.clone())
            })
            .collect();
        let last: Vec<bool> = kept.iter().map(|k| last_resort.contains(k)).collect();
        let (order, in_tree, turned) = rooted_tree(&mut ends, &self.bodies, &names, &last)?;
        let TreeCoordinates {
            coords,
            body_coord,
            mut roles,
            mut slots,
        } = tree_coordinates(
            |k, comp| {
                let count = ends[k].2.angle_count();
                let file_comp = if turned[k] { count - 1 - comp } else { comp };
                coordinate_name(&names[k], count, file_comp)
            },
            &ends,
            &order,
            self.bodies.len(),
        );
        let (closures, row, slot) =
            loop_closures(&ends, &in_tree, &mut roles, &mut slots, coords.len());
        let find = |name: &str| coords.iter().position(|c| c.name == name);
        let symmetries: Vec<(usize, usize, f64)> = self
            .symmetries
            .iter()
            .filter_map(|&(a, b, sign)| {
                Some((
                    find(&self.coords[a].name)?,
                    find(&self.coords[b].name)?,
                    sign,
                ))
            })
            .collect();
        let interfaces = ends
            .into_iter()
            .enumerate()
            .map(|(j, (parent, child, kind))| Interface {
                name: names[j].clone(),
                parent,
                child,
                kind,
                impact: self.interfaces[kept[j]].impact,
                role: roles[j],
                slots: slots[j].clone(),
            })
            .collect();
        let model = Model {
            name: self.name.clone(),
            gravity: self.gravity,
            bodies: self.bodies.clone(),
            interfaces,
            coords,
            closures,
            body_coord,
            closure_rows: row,
            constraint_rows: row + symmetries.len(),
            symmetries,
            slot_count: slot,
            size: self.size,
        };
        Ok((model, turned))
    }

    /// DOF(1): the number of tree coordinates.
    pub fn dof(&self) -> usize {
        self.coords.len()
    }

    /// The common axis a of a planar model: every interface a hinge, their axes parallel (the
    /// sines of their angles to the first below 1e-9). Every body then turns about axes along a
    /// and moves in planes normal to it, and the hinges carry any load along a bilaterally (a
    /// hinge's pivot lines are lines, not contacts that can open across them): the model answers
    /// for the ground motion's part normal to a only. Unit, with the first hinge's sense; None
    /// for a model with a rocking base, with hinges about different axes or without interfaces.
    pub fn planar_axis(&self) -> Option<Vector3<f64>> {
        let mut axes = self.interfaces.iter().map(|i| match &i.kind {
            InterfaceKind::Hinge { axis, .. } => Some(axis.normalize()),
            InterfaceKind::RockingBase { .. } => None,
        });
        let first = axes.next()??;
        for axis in axes {
            if axis?.cross(&first).norm() > 1e-9 {
                return None;
            }
        }
        Some(first)
    }

    /// The name of a pivot slot: its interface's name, with `.1`/`.2` for the tilts of a rocking
    /// base (the names of `crr inspect`; a closure's slots are named like a tree interface's).
    pub fn slot_name(&self, slot: usize) -> String {
        self.interfaces
            .iter()
            .find(|i| i.slots.contains(&slot))
            .map(|i| {
                if i.slots.len() > 1 {
                    format!("{}.{}", i.name, slot - i.slots.start + 1)
                } else {
                    i.name.clone()
                }
            })
            .unwrap_or_else(|| format!("slot {slot}"))
    }

    /// Index of a coordinate by name.
    pub fn coord_index(&self, name: &str) -> Option<usize> {
        self.coords.iter().position(|c| c.name == name)
    }

    /// Index of a body by name.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Index of an interface by name.
    pub fn interface_index(&self, name: &str) -> Option<usize> {
        self.interfaces.iter().position(|i| i.name == name)
    }

    /// Total mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }

    /// The frame coordinate of a parent (None for the ground).
    pub fn frame_of(&self, p: Parent) -> Option<usize> {
        match p {
            Parent::Ground => None,
            Parent::Body(b) => Some(self.body_coord[b]),
        }
    }

    /// Whether coordinate `coordinate` carries frame `frame`: it lies on the frame's path to the
    /// ground (a frame carries itself; the ground, None, is carried by nothing).
    pub fn carries(&self, coordinate: usize, frame: Option<usize>) -> bool {
        let mut j = frame;
        while let Some(jj) = j {
            if jj == coordinate {
                return true;
            }
            j = self.coords[jj].parent;
        }
        false
    }

    /// The bodies (indices, in order) with no path to the ground through the interfaces not
    /// `removed` (each interface joins its parent and its child): those that would fly if the
    /// removed interfaces opened.
    pub fn bodies_off_ground(&self, removed: &[bool]) -> Vec<usize> {
        let n = self.bodies.len();
        // The ground is index n.
        let mut sets = DisjointSets::new(n + 1);
        for (i, interface) in self.interfaces.iter().enumerate() {
            if !removed[i] {
                let parent = match interface.parent {
                    Parent::Ground => n,
                    Parent::Body(b) => b,
                };
                sets.union(parent, interface.child);
            }
        }
        (0..n).filter(|&b| !sets.joined(b, n)).collect()
    }

    /// The partition of the structure into its connected parts: the coordinates joined by
    /// parent links (one tree rooted at the ground each), by loop closures between bodies
    /// (a closure to the ground joins nothing) and by symmetry rows. The equations of motion of
    /// different parts do not couple (M is block-diagonal over them, each constraint row lies in
    /// one part), so a quantity of one part depends on that part's state alone.
    pub fn parts(&self) -> Parts {
        let n = self.dof();
        // The smaller index names a set, so a part's root is its first coordinate.
        let mut sets = DisjointSets::new(n);
        for (k, c) in self.coords.iter().enumerate() {
            if let Some(p) = c.parent {
                sets.union(p, k);
            }
        }
        for cl in &self.closures {
            let iface = &self.interfaces[cl.interface];
            if let Some(a) = self.frame_of(iface.parent) {
                sets.union(a, self.body_coord[iface.child]);
            }
        }
        for &(a, b, _) in &self.symmetries {
            sets.union(a, b);
        }
        let mut index = vec![usize::MAX; n];
        let mut of_coord = vec![0; n];
        let mut coords: Vec<Vec<usize>> = Vec::new();
        for k in 0..n {
            let r = sets.find(k);
            if index[r] == usize::MAX {
                index[r] = coords.len();
                coords.push(Vec::new());
            }
            of_coord[k] = index[r];
            coords[index[r]].push(k);
        }
        let mut bodies = vec![Vec::new(); coords.len()];
        for (b, &k) in self.body_coord.iter().enumerate() {
            bodies[of_coord[k]].push(b);
        }
        let mut of_slot = vec![0; self.slot_count];
        of_slot[..n].copy_from_slice(&of_coord);
        for iface in &self.interfaces {
            if let Role::Closure { .. } = iface.role {
                for s in iface.slots.clone() {
                    of_slot[s] = of_coord[self.body_coord[iface.child]];
                }
            }
        }
        Parts {
            of_coord,
            of_slot,
            coords,
            bodies,
        }
    }
}

/// The connected parts of a [`Model`] ([`Model::parts`]), numbered in the order of their first
/// coordinate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Parts {
    /// The part of each coordinate.
    pub of_coord: Vec<usize>,
    /// The part of each pivot-side slot (a closure angle's is its interface's part).
    pub of_slot: Vec<usize>,
    /// The coordinates of each part, in increasing order (closed under parents).
    pub coords: Vec<Vec<usize>>,
    /// The bodies of each part, in increasing order.
    pub bodies: Vec<Vec<usize>>,
}

impl Parts {
    /// The number of parts.
    pub fn len(&self) -> usize {
        self.coords.len()
    }

    /// True for a model without coordinates.
    pub fn is_empty(&self) -> bool {
        self.coords.is_empty()
    }
}

/// The narrowest zone ε of a regularised Dirac force (`dirac_regularised.width`, rad): the
/// run's smallest angle tolerance (the pivot-side check, 1e-5 rad; docs/simulation.md). Narrower
/// zones were stepped over: at 1e-12 the block's angle went 5e-3 rad past its pivot in one step,
/// and at 1e-6 to 1e-8 a run needed more than a million steps.
pub const MIN_DIRAC_WIDTH: f64 = 1e-5;

fn check_impact_law(law: &ImpactLaw, item: &str) -> Result<(), ModelError> {
    let bad_r = |r: f64| !(r.is_finite() && r > 0.0 && r <= 1.0);
    let bad_pos = |x: f64| !(x.is_finite() && x > 0.0);
    let problem = match *law {
        ImpactLaw::Momentum => None,
        ImpactLaw::Restitution(r) if bad_r(r) => {
            Some(format!("restitution r must be in (0, 1], got {r}"))
        }
        ImpactLaw::Dirac { r, .. } | ImpactLaw::DiracRegularised { r, .. } if bad_r(r) => {
            Some(format!("r must be in (0, 1], got {r}"))
        }
        ImpactLaw::Dirac { c, .. } | ImpactLaw::DiracRegularised { c, .. } if bad_pos(c) => {
            Some(format!("c must be positive, got {c}"))
        }
        ImpactLaw::DiracRegularised { width, .. }
            if !(width.is_finite() && width >= MIN_DIRAC_WIDTH) =>
        {
            Some(format!(
                "width must be a finite number of at least {MIN_DIRAC_WIDTH:e} rad, got {width}: \
                 a narrower zone lies within the angle tolerance of the run's events and pivot \
                 checks (1e-5 rad), so the integrator steps over it; for the impulsive limit give \
                 `dirac = {{ r, c }}`"
            ))
        }
        _ => None,
    };
    match problem {
        Some(p) => Err(ModelError::new(format!("{item} (impact)"), p)),
        None => Ok(()),
    }
}

/// Gravities a model may have, m/s²: every planet's and moon's surface gravity with margin on
/// both sides. Far outside, the run's tolerances, set against the time scale √(L/g), blame
/// settings the user never gave (1e-6 m/s² was reported as a `seat_rate` too large).
pub const GRAVITY_RANGE: (f64, f64) = (1e-2, 1e3);

/// Densities a body or block may have, kg/m³: far beyond every material on both sides (osmium
/// is 22 590; a nearly massless member, as in a test of a limit, stays allowed), while the
/// weight, the inertia and their products stay far from overflow and underflow in the equations
/// of motion (1e308 kg/m³ gave U = inf where the mass was still a finite number, and 1e-320 a
/// NaN frequency).
pub const DENSITY_RANGE: (f64, f64) = (1e-12, 1e9);

/// An interface's two ends and its kind, before the chain is built.
type InterfaceEnds = (Parent, usize, InterfaceKind);

/// Gravity, and at least one but not too many bodies.
fn check_structure(spec: &StructureSpec) -> Result<(), ModelError> {
    if !(spec.gravity.is_finite() && spec.gravity > 0.0) {
        return Err(ModelError::new(
            "gravity",
            format!("must be a positive number of m/s², got {}", spec.gravity),
        ));
    }
    let (low, high) = GRAVITY_RANGE;
    if !(low..=high).contains(&spec.gravity) {
        return Err(ModelError::new(
            "gravity",
            format!(
                "{:e} m/s² is outside {low:e}…{high:e} m/s² (Earth's is 9.81; check the units: \
                 m/s²)",
                spec.gravity
            ),
        ));
    }
    if spec.body.is_empty() {
        return Err(ModelError::new(
            quoted("model", &spec.name),
            "has no bodies",
        ));
    }
    // Every body moves with at least one coordinate of its own: more bodies than
    // MAX_COORDINATES are refused before any per-body work.
    if spec.body.len() > MAX_COORDINATES {
        return Err(too_many_coordinates(
            &spec.name,
            spec.body.len(),
            "at least ",
        ));
    }
    Ok(())
}

/// The bodies with their mass properties, and the index of each name; names are checked.
fn build_bodies(spec: &StructureSpec) -> Result<(Vec<Body>, HashMap<String, usize>), ModelError> {
    let mut body_index = HashMap::new();
    let mut bodies = Vec::with_capacity(spec.body.len());
    for (k, b) in spec.body.iter().enumerate() {
        if b.name.trim().is_empty() {
            return Err(ModelError::new(
                format!("body #{}", k + 1),
                "has an empty name",
            ));
        }
        if let Some(why) = unusable_name(&b.name) {
            return Err(ModelError::new(quoted("body", &b.name), why));
        }
        if b.name == "ground" {
            return Err(ModelError::new(
                quoted("body", &b.name),
                "\"ground\" is reserved for the ground",
            ));
        }
        if body_index.insert(b.name.clone(), k).is_some() {
            return Err(ModelError::new(
                quoted("body", &b.name),
                "the name is used by two bodies",
            ));
        }
        bodies.push(build_body(b)?);
    }
    Ok((bodies, body_index))
}

/// A length scale for tolerances: the extent of the centres and of every given point (at least
/// the size of the largest body, and 1 mm).
fn length_scale(spec: &StructureSpec, bodies: &[Body]) -> f64 {
    let mut pts: Vec<Vector3<f64>> = bodies.iter().map(|b| b.com).collect();
    for i in &spec.interface {
        for p in [&i.pivot_positive, &i.pivot_negative].into_iter().flatten() {
            match p {
                PivotSpec::Point(x) => pts.push(Vector3::from(*x)),
                PivotSpec::Segment(s) => pts.extend(s.iter().map(|x| Vector3::from(*x))),
            }
        }
        if let Some(rb) = &i.rocking_base {
            pts.extend(rb.corners.iter().map(|x| Vector3::from(*x)));
        }
    }
    let pts: Vec<_> = pts
        .into_iter()
        .filter(|p| p.iter().all(|x| x.is_finite()))
        .collect();
    let mut size: f64 = bodies.iter().map(|b| b.volume.cbrt()).fold(1e-3, f64::max);
    for a in &pts {
        for b in &pts {
            size = size.max((a - b).norm());
        }
    }

    size
}

/// Every interface's ends and kind (hinge or rocking base), its names, pivots and impact law
/// checked.
fn build_interfaces(
    spec: &StructureSpec,
    bodies: &[Body],
    body_index: &HashMap<String, usize>,
    size: f64,
) -> Result<Vec<InterfaceEnds>, ModelError> {
    let mut names = HashMap::new();
    let mut ends = Vec::with_capacity(spec.interface.len());
    for (k, i) in spec.interface.iter().enumerate() {
        let item = quoted("interface", &i.name);
        if i.name.trim().is_empty() {
            return Err(ModelError::new(
                format!("interface #{}", k + 1),
                "has an empty name",
            ));
        }
        if let Some(why) = unusable_name(&i.name) {
            return Err(ModelError::new(item, why));
        }
        if names.insert(i.name.clone(), k).is_some() {
            return Err(ModelError::new(item, "the name is used by two interfaces"));
        }
        let parent = if i.parent == "ground" {
            Parent::Ground
        } else {
            Parent::Body(*body_index.get(&i.parent).ok_or_else(|| {
                ModelError::new(
                    format!("{item} (parent)"),
                    format!("no body is named \"{}\"", i.parent),
                )
            })?)
        };
        if i.child == "ground" {
            return Err(ModelError::new(
                format!("{item} (child)"),
                "the child must be a body: to join a body to the ground make \"ground\" the parent",
            ));
        }
        let child = *body_index.get(&i.child).ok_or_else(|| {
            ModelError::new(
                format!("{item} (child)"),
                format!("no body is named \"{}\"", i.child),
            )
        })?;
        if parent == Parent::Body(child) {
            return Err(ModelError::new(
                item,
                format!("joins body \"{}\" to itself", i.child),
            ));
        }
        let child_com = bodies[child].com;
        // A contact lies on the child: a pivot far outside it is a typing or unit mistake
        // (millimetres for metres). 100 times the child's size leaves room for any real
        // joint and catches those.
        let reach = PIVOT_REACH * bodies[child].volume.cbrt();
        let given = i.face_points();
        if let Some(far) = given
            .iter()
            .map(|x| (Vector3::from(*x) - child_com).norm())
            .find(|d| *d > reach)
        {
            return Err(ModelError::new(
                item,
                format!(
                    "a pivot lies {far:.4e} m from the centre of body \"{}\", more than {PIVOT_REACH} times its size ({:.4e} m): pivots must lie on the child (check the units: metres)",
                    i.child,
                    bodies[child].volume.cbrt()
                ),
            ));
        }
        let child_side = match i.normal {
            None => ChildSide::Point(side_point(&bodies[child], &given)),
            Some(n) => ChildSide::Normal(given_normal(&n, &bodies[child], &given, &item)?),
        };
        let kind = match &i.rocking_base {
            Some(rb) => {
                if i.axis.is_some() || i.pivot_positive.is_some() || i.pivot_negative.is_some() {
                    return Err(ModelError::new(
                        item,
                        "a rocking_base defines its own axes and pivots: remove axis, pivot_positive and pivot_negative",
                    ));
                }
                rocking_base_kind(&rb.corners, rb.twist, &child_side, &item, size)?
            }
            None => hinge_kind(i, &child_side, &item, size)?,
        };
        check_impact_law(&i.impact, &item)?;
        ends.push((parent, child, kind));
    }
    check_history_columns(spec, &ends)?;
    Ok(ends)
}

/// The columns of the history (docs/outputs.md) and of the Poincaré sections and sweeps
/// (docs/poincare.md) besides the interfaces' own.
const FIXED_COLUMNS: [&str; 9] = [
    "t",
    "kinetic",
    "potential",
    "work_in",
    "dissipated",
    "k",
    "case",
    "amplitude",
    "frequency",
];

/// The history's columns must be distinct: each interface takes its coordinates (its name, or
/// `<name>.1` and `<name>.2`), their rates `<coordinate>_rate` and its state `<name>_state`
/// (whether it closes a loop or not, so that no choice of the chain makes two columns one).
/// Names that collide (a hinge `x.1` beside a rocking base `x`, an interface `kinetic`, or
/// `base_rate` beside `base`) would make two coordinates one name for `[initial]` and two
/// columns one for whatever reads the file.
fn check_history_columns(spec: &StructureSpec, ends: &[InterfaceEnds]) -> Result<(), ModelError> {
    let mut owner: HashMap<String, Option<usize>> = FIXED_COLUMNS
        .iter()
        .map(|c| (c.to_string(), None))
        .collect();
    for (k, (i, (_, _, kind))) in spec.interface.iter().zip(ends).enumerate() {
        let count = kind.angle_count();
        let coordinates: Vec<String> = (0..count)
            .map(|comp| coordinate_name(&i.name, count, comp))
            .collect();
        let columns = coordinates
            .iter()
            .cloned()
            .chain(coordinates.iter().map(|c| format!("{c}_rate")))
            .chain(std::iter::once(format!("{}_state", i.name)));
        for column in columns {
            if let Some(previous) = owner.insert(column.clone(), Some(k)) {
                let other = match previous {
                    Some(j) => format!("interface \"{}\"'s", spec.interface[j].name),
                    None => "a column of the outputs of their own".to_string(),
                };
                return Err(ModelError::new(
                    quoted("interface", &i.name),
                    format!(
                        "its output column \"{column}\" is also {other}: rename one (the \
                         history's columns are t, each coordinate, its _rate, kinetic, potential, \
                         work_in, dissipated and each interface's _state; the Poincaré sections' \
                         add k, case, amplitude and frequency)"
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The spanning tree, breadth first from the ground along parent → child: the tree interfaces
/// in coordinate order, and which interfaces are in the tree. Every body must be reached.
fn spanning_tree(
    ends: &[InterfaceEnds],
    bodies: &[Body],
) -> Result<(Vec<usize>, Vec<bool>), ModelError> {
    let n_i = ends.len();
    let mut in_tree = vec![false; n_i];
    let mut reached = vec![false; bodies.len()];
    let mut order = Vec::new(); // tree interfaces in coordinate order
    let mut queue = VecDeque::from([Parent::Ground]);
    while let Some(node) = queue.pop_front() {
        for (k, (p, c, _)) in ends.iter().enumerate() {
            if *p == node && !reached[*c] {
                reached[*c] = true;
                in_tree[k] = true;
                order.push(k);
                queue.push_back(Parent::Body(*c));
            }
        }
    }
    if let Some(b) = reached.iter().position(|r| !r) {
        return Err(ModelError::new(
            quoted("body", &bodies[b].name),
            "has no path from the ground: every body must be reached from \"ground\" through interfaces, \
             following each interface from parent to child",
        ));
    }

    Ok((order, in_tree))
}

/// A twisting rocking base must close a loop: in the tree it would need a third coordinate.
fn check_twist_closes_a_loop(
    spec: &StructureSpec,
    ends: &[InterfaceEnds],
    order: &[usize],
) -> Result<(), ModelError> {
    if let Some(&k) = order
        .iter()
        .find(|&&k| matches!(ends[k].2, InterfaceKind::RockingBase { twist: true, .. }))
    {
        return Err(ModelError::new(
            quoted("interface", &spec.interface[k].name),
            "`twist = true` is allowed only on an interface that closes a loop (its child is \
             reached through another interface first, following the interfaces from the \
             ground in file order); here the child is reached through this interface, which \
             would need a third coordinate. List the other interface of the child first",
        ));
    }
    Ok(())
}

/// The coordinates of the tree interfaces, each with its parent coordinate.
struct TreeCoordinates {
    coords: Vec<Coordinate>,
    body_coord: Vec<usize>,
    roles: Vec<Role>,
    slots: Vec<std::ops::Range<usize>>,
}

/// The tree's coordinates in the order of `order` (one per hinge, two per rocking base), the
/// coordinate each body moves with, and the tree interfaces' roles and slots.
fn tree_coordinates(
    name: impl Fn(usize, usize) -> String,
    ends: &[InterfaceEnds],
    order: &[usize],
    n_bodies: usize,
) -> TreeCoordinates {
    let n_i = ends.len();
    let mut coords = Vec::new();
    let mut body_coord = vec![usize::MAX; n_bodies];
    let mut roles = vec![Role::Closure { index: 0 }; n_i];
    let mut slots = vec![0..0; n_i];
    for &k in order {
        let (p, c, kind) = &ends[k];
        let first = coords.len();
        let mut parent = match p {
            Parent::Ground => None,
            Parent::Body(b) => Some(body_coord[*b]),
        };
        let n = kind.angle_count();
        for comp in 0..n {
            coords.push(Coordinate {
                name: name(k, comp),
                interface: k,
                component: comp,
                axis: kind.axis(comp),
                parent,
            });
            parent = Some(coords.len() - 1);
        }
        body_coord[*c] = coords.len() - 1;
        roles[k] = Role::Tree { first_coord: first };
        slots[k] = first..first + n;
    }
    TreeCoordinates {
        coords,
        body_coord,
        roles,
        slots,
    }
}

/// The name of component `comp` of an interface `name` with `count` angles: the interface's
/// name for a hinge, `<name>.1` / `<name>.2` for a rocking base's tilts.
fn coordinate_name(name: &str, count: usize, comp: usize) -> String {
    if count == 1 {
        name.to_string()
    } else {
        format!("{name}.{}", comp + 1)
    }
}

/// An interface turned round: its child becomes its parent. The relative motion of the file's
/// parent seen from its child is the inverse rotation about the same pivots: a hinge R(u, φ)
/// about P becomes R(−u, φ) about P; a rocking base R(e₁, θ₁)R(e₂, θ₂) becomes
/// R(−e₂, θ₂)R(−e₁, θ₁), so its first tilt is the file's second about −e₂ and its second the
/// file's first about −e₁; the normal, into the new child, is −n. Angles and pivot sides keep
/// their values (a positive tilt about −e₂ pivots on the edge of greatest e₁·x, as a positive
/// tilt about e₂ did).
pub fn reversed_kind(kind: &InterfaceKind) -> InterfaceKind {
    match kind {
        InterfaceKind::Hinge {
            axis,
            pivot_positive,
            pivot_negative,
        } => InterfaceKind::Hinge {
            axis: -axis,
            pivot_positive: *pivot_positive,
            pivot_negative: *pivot_negative,
        },
        InterfaceKind::RockingBase {
            corners,
            normal,
            e1,
            e2,
            twist,
        } => InterfaceKind::RockingBase {
            corners: *corners,
            normal: -normal,
            e1: -e2,
            e2: -e1,
            twist: *twist,
        },
    }
}

/// A spanning tree: the tree interfaces in coordinate order, which interfaces are in it, and
/// which were turned round.
type RootedTree = (Vec<usize>, Vec<bool>, Vec<bool>);

/// The spanning tree of [`spanning_tree`] when some bodies can only be reached through an
/// interface from its child to its parent: the tree grows from the ground along interfaces from
/// parent to child (file order, breadth first, as the file's own tree); when bodies remain, the
/// first interface (file order) from a body reached to an unreached parent is turned round
/// ([`reversed_kind`]) and the growth goes on from there. Interfaces marked `last_resort` enter
/// the tree only when the others cannot reach every body; a seat that may twist never does
/// (it would need a third coordinate). With every body reachable from parent to child it is
/// the file's tree. Returns the order, the tree flags and which interfaces were turned round
/// (their `ends` are turned in place).
fn rooted_tree(
    ends: &mut [InterfaceEnds],
    bodies: &[Body],
    names: &[String],
    last_resort: &[bool],
) -> Result<RootedTree, ModelError> {
    let n_i = ends.len();
    let twists =
        |kind: &InterfaceKind| matches!(kind, InterfaceKind::RockingBase { twist: true, .. });
    let mut in_tree = vec![false; n_i];
    let mut turned = vec![false; n_i];
    let mut reached = vec![false; bodies.len()];
    let mut order = Vec::new();
    let mut queue = VecDeque::from([Parent::Ground]);
    let mut tier = 0;
    loop {
        let usable =
            |k: usize, ends: &[InterfaceEnds]| !twists(&ends[k].2) && (tier > 0 || !last_resort[k]);
        while let Some(node) = queue.pop_front() {
            for k in 0..n_i {
                let (p, c, _) = &ends[k];
                if *p == node && !reached[*c] && usable(k, ends) {
                    let c = *c;
                    reached[c] = true;
                    in_tree[k] = true;
                    order.push(k);
                    queue.push_back(Parent::Body(c));
                }
            }
        }
        if reached.iter().all(|&r| r) {
            break;
        }
        let turn = (0..n_i).find(|&k| match ends[k].0 {
            Parent::Body(b) => reached[ends[k].1] && !reached[b] && usable(k, ends),
            Parent::Ground => false,
        });
        let Some(k) = turn else {
            if tier == 0 {
                // The interfaces kept for last: grow again from every body reached.
                tier = 1;
                queue.push_back(Parent::Ground);
                queue.extend((0..bodies.len()).filter(|&b| reached[b]).map(Parent::Body));
                continue;
            }
            let b = reached.iter().position(|r| !r).expect("a body not reached");
            if let Some(k) = (0..n_i).find(|&k| {
                let parent_reached = match ends[k].0 {
                    Parent::Ground => true,
                    Parent::Body(p) => reached[p],
                };
                twists(&ends[k].2) && reached[ends[k].1] != parent_reached
            }) {
                return Err(ModelError::new(
                    quoted("interface", &names[k]),
                    "may twist (`twist = true`) and would have to enter the spanning tree to \
                     support a body, which needs a third coordinate",
                ));
            }
            return Err(ModelError::new(
                quoted("body", &bodies[b].name),
                "has no support left: no interface that stays closed joins it to the ground",
            ));
        };
        let (p, c, kind) = &ends[k];
        let Parent::Body(b) = *p else {
            unreachable!("the ground is never turned round")
        };
        ends[k] = (Parent::Body(*c), b, reversed_kind(kind));
        turned[k] = true;
        reached[b] = true;
        in_tree[k] = true;
        order.push(k);
        queue.push_back(Parent::Body(b));
    }
    Ok((order, in_tree, turned))
}

/// The loop closures of the interfaces outside the tree (5 rows for a hinge, 4 for a rocking
/// base, 3 for a twisting one), their roles and slots after the tree's; returns the closures,
/// their rows and the slot count.
fn loop_closures(
    ends: &[InterfaceEnds],
    in_tree: &[bool],
    roles: &mut [Role],
    slots: &mut [std::ops::Range<usize>],
    tree_slots: usize,
) -> (Vec<Closure>, usize, usize) {
    let n_i = ends.len();
    let mut closures = Vec::new();
    let mut slot = tree_slots;
    let mut row = 0;
    for k in (0..n_i).filter(|&k| !in_tree[k]) {
        let kind = &ends[k].2;
        let rows = match kind {
            InterfaceKind::Hinge { .. } => 5,
            InterfaceKind::RockingBase { twist: false, .. } => 4,
            InterfaceKind::RockingBase { twist: true, .. } => 3,
        };
        roles[k] = Role::Closure {
            index: closures.len(),
        };
        slots[k] = slot..slot + kind.angle_count();
        slot += kind.angle_count();
        closures.push(Closure {
            interface: k,
            first_row: row,
            rows,
        });
        row += rows;
    }
    (closures, row, slot)
}

/// The symmetry rows (DOF(3)): pairs of coordinates equal or opposite.
fn symmetry_rows(
    spec: &StructureSpec,
    coords: &[Coordinate],
) -> Result<Vec<(usize, usize, f64)>, ModelError> {
    let mut symmetries = Vec::new();
    for (k, sy) in spec.symmetry.iter().enumerate() {
        let item = format!(
            "symmetry #{} ({} = {}{})",
            k + 1,
            sy.coordinates[0],
            if sy.relation == crate::spec::SymmetryRelation::Opposite {
                "−"
            } else {
                ""
            },
            sy.coordinates[1]
        );
        let find = |name: &str| {
            coords
                .iter()
                .position(|c: &Coordinate| c.name == name)
                .ok_or_else(|| {
                    let names: Vec<_> = coords.iter().map(|c| c.name.as_str()).collect();
                    ModelError::new(
                        item.clone(),
                        format!(
                            "no coordinate named \"{name}\"; coordinates are: {}",
                            names.join(", ")
                        ),
                    )
                })
        };
        let (a, b) = (find(&sy.coordinates[0])?, find(&sy.coordinates[1])?);
        if a == b {
            return Err(ModelError::new(item, "relates a coordinate to itself"));
        }
        let sign = match sy.relation {
            crate::spec::SymmetryRelation::Equal => 1.0,
            crate::spec::SymmetryRelation::Opposite => -1.0,
        };
        symmetries.push((a, b, sign));
    }
    Ok(symmetries)
}
