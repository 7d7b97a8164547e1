//! The model description a person writes (TOML) or a program produces (JSON).
//!
//! These are plain serde structures, checked by [`crate::Model::from_spec`], which turns them into
//! a validated [`crate::Model`]. Every field is documented with its units in `docs/model-format.md`.

use serde::{Deserialize, Serialize};

use crate::shapes::{AnnularSectorShape, BoxShape, PolyhedronShape, PrismShape, Shape};

/// Standard value of g used when a model does not give one (m/s²).
pub const DEFAULT_GRAVITY: f64 = 9.81;

fn default_gravity() -> f64 {
    DEFAULT_GRAVITY
}

/// A structure: bodies and the interfaces (hinges, rocking bases) that join them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureSpec {
    /// Name of the structure (used for the results folder).
    pub name: String,
    /// Acceleration of gravity g (m/s², positive, acting along −z). Default 9.81.
    #[serde(default = "default_gravity")]
    pub gravity: f64,
    /// The rigid bodies (`[[body]]` tables).
    #[serde(default)]
    pub body: Vec<BodySpec>,
    /// The interfaces (`[[interface]]` tables).
    #[serde(default)]
    pub interface: Vec<InterfaceSpec>,
    /// User or symmetry constraints between coordinates (`[[symmetry]]` tables), giving DOF(3).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub symmetry: Vec<SymmetrySpec>,
}

/// A user constraint between two coordinates: φₐ = φ_b (`"equal"`) or φₐ = −φ_b (`"opposite"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SymmetrySpec {
    /// The two coordinate names [a, b].
    pub coordinates: [String; 2],
    /// `"equal"` (φₐ = φ_b) or `"opposite"` (φₐ = −φ_b).
    pub relation: SymmetryRelation,
}

/// The relation of a [`SymmetrySpec`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SymmetryRelation {
    /// φₐ = φ_b.
    Equal,
    /// φₐ = −φ_b.
    Opposite,
}

/// One rigid body: a name, its density or mass, and exactly one shape in world coordinates at rest,
/// or (a compound body, a rigid domain of several blocks) no shape of its own and its `block`s.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Unique name (not `"ground"`).
    pub name: String,
    /// Density ρ (kg/m³).
    #[serde(default)]
    pub density: Option<f64>,
    /// Mass (kg); overrides the density-derived mass (the inertia is scaled with it).
    #[serde(default)]
    pub mass: Option<f64>,
    /// A rectangular box.
    #[serde(default, rename = "box")]
    pub box_shape: Option<BoxShape>,
    /// The convex hull of a set of points.
    #[serde(default)]
    pub polyhedron: Option<PolyhedronShape>,
    /// A planar polygon swept along a vector.
    #[serde(default)]
    pub prism: Option<PrismShape>,
    /// An annular sector (voussoir, arch ring piece).
    #[serde(default)]
    pub annular_sector: Option<AnnularSectorShape>,
    /// The blocks of a compound body (`[[body.block]]` tables), each with one shape: the body
    /// moves as one rigid domain and its mass properties are the exact sums of its blocks'. A
    /// compound body gives no shape of its own.
    #[serde(default, rename = "block", skip_serializing_if = "Vec::is_empty")]
    pub blocks: Vec<BlockSpec>,
}

/// One block of a compound body: exactly one shape, and its density when it differs from the
/// body's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockSpec {
    /// The block's name (for reports); optional.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Density ρ (kg/m³); the body's when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// A rectangular box.
    #[serde(default, rename = "box", skip_serializing_if = "Option::is_none")]
    pub box_shape: Option<BoxShape>,
    /// The convex hull of a set of points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polyhedron: Option<PolyhedronShape>,
    /// A planar polygon swept along a vector.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prism: Option<PrismShape>,
    /// An annular sector.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub annular_sector: Option<AnnularSectorShape>,
}

/// The shapes given in the four shape fields of a body or a block, in the fields' order.
fn listed_shapes(
    box_shape: &Option<BoxShape>,
    polyhedron: &Option<PolyhedronShape>,
    prism: &Option<PrismShape>,
    annular_sector: &Option<AnnularSectorShape>,
) -> Vec<Shape> {
    [
        box_shape.clone().map(Shape::Box),
        polyhedron.clone().map(Shape::Polyhedron),
        prism.clone().map(Shape::Prism),
        annular_sector.clone().map(Shape::AnnularSector),
    ]
    .into_iter()
    .flatten()
    .collect()
}

impl BodySpec {
    /// A body of one shape, with its density.
    pub fn simple(name: &str, density: f64, shape: Shape) -> BodySpec {
        let mut b = BodySpec {
            name: name.to_string(),
            density: Some(density),
            mass: None,
            box_shape: None,
            polyhedron: None,
            prism: None,
            annular_sector: None,
            blocks: Vec::new(),
        };
        match shape {
            Shape::Box(s) => b.box_shape = Some(s),
            Shape::Polyhedron(s) => b.polyhedron = Some(s),
            Shape::Prism(s) => b.prism = Some(s),
            Shape::AnnularSector(s) => b.annular_sector = Some(s),
            compound @ Shape::Compound(_) => b.blocks = BlockSpec::all_of(None, None, compound),
        }
        b
    }

    /// The shapes given in the body's own shape fields (exactly one for a valid simple body, none
    /// for a compound one).
    pub fn own_shapes(&self) -> Vec<Shape> {
        listed_shapes(
            &self.box_shape,
            &self.polyhedron,
            &self.prism,
            &self.annular_sector,
        )
    }

    /// Whether the body is compound (has `block`s).
    pub fn is_compound(&self) -> bool {
        !self.blocks.is_empty()
    }

    /// Every shape field of the body and of its blocks, to be transformed in place (scaling).
    pub fn shape_fields_mut(&mut self) -> Vec<ShapeFieldsMut<'_>> {
        let mut out = vec![ShapeFieldsMut {
            box_shape: &mut self.box_shape,
            polyhedron: &mut self.polyhedron,
            prism: &mut self.prism,
            annular_sector: &mut self.annular_sector,
        }];
        out.extend(self.blocks.iter_mut().map(|p| ShapeFieldsMut {
            box_shape: &mut p.box_shape,
            polyhedron: &mut p.polyhedron,
            prism: &mut p.prism,
            annular_sector: &mut p.annular_sector,
        }));
        out
    }
}

/// The four shape fields of a body or of a block, borrowed mutably.
pub struct ShapeFieldsMut<'a> {
    /// A rectangular box.
    pub box_shape: &'a mut Option<BoxShape>,
    /// The convex hull of a set of points.
    pub polyhedron: &'a mut Option<PolyhedronShape>,
    /// A planar polygon swept along a vector.
    pub prism: &'a mut Option<PrismShape>,
    /// An annular sector.
    pub annular_sector: &'a mut Option<AnnularSectorShape>,
}

impl BlockSpec {
    /// The blocks of a shape, each with the given name and density: one for a simple shape, one
    /// per (flattened) part of a compound shape.
    pub fn all_of(name: Option<String>, density: Option<f64>, shape: Shape) -> Vec<BlockSpec> {
        let mut p = BlockSpec {
            name: name.clone(),
            density,
            box_shape: None,
            polyhedron: None,
            prism: None,
            annular_sector: None,
        };
        match shape {
            Shape::Box(s) => p.box_shape = Some(s),
            Shape::Polyhedron(s) => p.polyhedron = Some(s),
            Shape::Prism(s) => p.prism = Some(s),
            Shape::AnnularSector(s) => p.annular_sector = Some(s),
            Shape::Compound(parts) => {
                return parts
                    .into_iter()
                    .flat_map(|s| BlockSpec::all_of(name.clone(), density, s))
                    .collect();
            }
        }
        vec![p]
    }

    /// The shapes given in the block's fields (exactly one for a valid block).
    pub fn shapes(&self) -> Vec<Shape> {
        listed_shapes(
            &self.box_shape,
            &self.polyhedron,
            &self.prism,
            &self.annular_sector,
        )
    }
}

/// A pivot line, given by one point on it or by two points of the contact edge.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "expected a point [x, y, z] or an edge of two points [[x, y, z], [x, y, z]] (m)"
)]
pub enum PivotSpec {
    /// A point on the pivot line (m); the line runs along the interface axis.
    Point([f64; 3]),
    /// The two end points of the contact edge (m); it must be parallel to the interface axis.
    Segment([[f64; 3]; 2]),
}

/// A rectangular rocking base: the contact rectangle between parent and child.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RockingBaseSpec {
    /// The four corners of the contact rectangle, in order around it (m).
    pub corners: Vec<[f64; 3]>,
    /// The child may also turn about the contact normal (twist) on its pivot corner: the contact
    /// keeps the corner and the face plane, not the direction of the edges. Allowed on a loop
    /// closure only (3 rows of Φ instead of 4); default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub twist: bool,
}

impl InterfaceSpec {
    /// The points the interface gives on its joint face: a rocking base's corners, a hinge's
    /// pivot points (both ends of a pivot given as an edge).
    pub fn face_points(&self) -> Vec<[f64; 3]> {
        match (
            &self.rocking_base,
            &self.pivot_positive,
            &self.pivot_negative,
        ) {
            (Some(rb), _, _) => rb.corners.clone(),
            (None, p, n) => [p, n]
                .into_iter()
                .flatten()
                .flat_map(|x| match x {
                    PivotSpec::Point(a) => vec![*a],
                    PivotSpec::Segment(s) => s.to_vec(),
                })
                .collect(),
        }
    }
}

/// How an impact at this interface dissipates energy (used by the impact stage).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ImpactLaw {
    /// Generalized Housner law: plastic impact at the new pivots, momentum projected on the new
    /// chain. Needs no coefficient.
    #[default]
    Momentum,
    /// Classical restitution: the impacting coordinate's rate is multiplied by `r` (a ratio of
    /// angular velocities, 0 < r ≤ 1) in the energy norm of the impact mode (its kinetic energy
    /// becomes r² times its value; exactly φ̇⁺ = r φ̇⁻ on one block); the momentum of every motion
    /// that leaves the impacting rates unchanged is conserved, from the bodies' real velocities.
    Restitution(f64),
    /// The paper's eq (5), F = C ln(r) φ̇|φ̇| δ(φ), integrated exactly across φ = 0: restitution
    /// with r^C (an elastic pivot switch, then the impulsive force).
    Dirac {
        /// Restitution-like ratio r of angular velocities, 0 < r ≤ 1.
        r: f64,
        /// The coefficient C (> 0; C = 1 gives φ̇⁺ = r φ̇⁻).
        c: f64,
    },
    /// Eq (5) with δ replaced by a unit-area function of the given width, integrated straight
    /// through with no impact event.
    DiracRegularised {
        /// Restitution-like ratio r, 0 < r ≤ 1.
        r: f64,
        /// The coefficient C (> 0).
        c: f64,
        /// Width ε of the regularised δ (rad, at least `MIN_DIRAC_WIDTH` = 1e-5).
        width: f64,
    },
}

/// One interface: a hinge (one rotation coordinate) or a rocking base (two tilts) joining a parent
/// (a body or the ground) to a child body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InterfaceSpec {
    /// Unique name; it names the interface's coordinate(s).
    pub name: String,
    /// A body name or `"ground"`.
    pub parent: String,
    /// A body name.
    pub child: String,
    /// Hinge axis direction (normalised by the engine).
    #[serde(default)]
    pub axis: Option<[f64; 3]>,
    /// Pivot line active when the angle is positive.
    #[serde(default)]
    pub pivot_positive: Option<PivotSpec>,
    /// Pivot line active when the angle is negative.
    #[serde(default)]
    pub pivot_negative: Option<PivotSpec>,
    /// A rocking base instead of a hinge (no axis or pivots then).
    #[serde(default)]
    pub rocking_base: Option<RockingBaseSpec>,
    /// The normal of the joint face, pointing into the child: which side of the face is the
    /// child's. Default: the side of the child's centre of mass, which a stone that is not
    /// convex may lie across (a joggled or hooked stone resting on a ledge above its centre);
    /// `crr assemble` writes it there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// Impact law at this interface (default `"momentum"`).
    #[serde(default)]
    pub impact: ImpactLaw,
}
