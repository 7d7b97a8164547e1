//! The model description a person writes (TOML) or a program produces (JSON).
//!
//! These are plain serde structures, checked by [`crate::Model::from_spec`], which turns them into
//! a validated [`crate::Model`]. Every field is documented with its units in `docs/model-format.md`.

use serde::{Deserialize, Serialize};

use crate::shapes::{AnnularSectorShape, BoxShape, PolyhedronShape, PrismShape};

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

/// One rigid body: a name, its density or mass, and exactly one shape in world coordinates at rest.
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
}

/// A pivot line, given by one point on it or by two points of the contact edge.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
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
    /// Impact law at this interface (default `"momentum"`).
    #[serde(default)]
    pub impact: ImpactLaw,
}
