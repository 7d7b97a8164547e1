//! Contact faces of the interfaces at rest: where the two bodies of an interface touch, as
//! points, with the face's normal and tangents.
//!
//! The rocking decisions of the CRR model (which joints open, about which edge) are posed on
//! interface angles and their signs. At the level of the faces they are convex: every contact
//! point carries a normal force fₙ ≥ 0 (no tension) and a tangential force, and the statics
//! ([`crate`]'s users: the collapse multiplier by the static theorem) or Gauss' principle become a
//! linear or quadratic program with one global answer.
//!
//! - **Hinge** (planar joint): its two pivot lines P⁺ and P⁻ are the two edges of the face; the
//!   face's normal n = u × (P⁻ − P⁺)/|u × (P⁻ − P⁺)| points into the child (a positive angle
//!   rotates the child about P⁺, lifting P⁻ along n; `Model::from_spec` refuses the other
//!   orientation). Tangents t₁ = u × n (in the plane of motion) and t₂ = u. The hinge is a line:
//!   out of its plane it transmits whatever is needed, so the couples about n and t₁ are
//!   bilateral (the CRR hinge allows no rotation but about u). A plain hinge (P⁺ = P⁻) is a pin:
//!   one point whose force is free in every direction.
//! - **Rocking base**: its four corners, normal n and tangents e₁, e₂ as the model has them.
use nalgebra::Vector3;

use crate::model::{GEOMETRY_TOLERANCE, InterfaceKind, Model};

/// The contact face of one interface, at rest (world coordinates).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactFace {
    /// Index into [`Model::interfaces`].
    pub interface: usize,
    /// Unit normal n, pointing into the child.
    pub normal: Vector3<f64>,
    /// Unit tangents (t₁, t₂), (t₁, t₂, n) right-handed: hinge (u × n, u), rocking base (e₁, e₂)
    /// up to the sign that makes the triad right-handed.
    pub tangents: [Vector3<f64>; 2],
    /// The contact points (m, world at rest): a hinge's P⁺ then P⁻, a rocking base's four corners
    /// in the model's order, a pin's one point.
    pub points: Vec<Vector3<f64>>,
    /// Directions of the couples the interface carries bilaterally, whatever their sign: a
    /// hinge's n and t₁ (it is a line), none for a rocking base.
    pub bilateral_couples: Vec<Vector3<f64>>,
    /// Which tangents friction bounds: a hinge's in-plane t₁ only (its t₂ = u is out of the plane
    /// the planar joint models), both for a rocking base.
    pub friction_tangents: usize,
    /// A pin (plain hinge, P⁺ = P⁻): its point's force is free, no unilateral contact.
    pub pin: bool,
}

impl ContactFace {
    /// Whether interface `index` is a pin ([`Self::pin`]): a hinge whose two pivot lines
    /// coincide within the geometry's tolerance, |u × (P⁻ − P⁺)| ≤ tolerance × model size. Asked
    /// without building the face.
    pub fn is_pin(model: &Model, index: usize) -> bool {
        match &model.interfaces[index].kind {
            InterfaceKind::Hinge {
                axis,
                pivot_positive,
                pivot_negative,
            } => hinge_lift(model, axis, pivot_positive, pivot_negative).is_none(),
            InterfaceKind::RockingBase { .. } => false,
        }
    }

    /// The contact face of interface `index` of `model`.
    pub fn of_interface(model: &Model, index: usize) -> ContactFace {
        match &model.interfaces[index].kind {
            InterfaceKind::Hinge {
                axis,
                pivot_positive,
                pivot_negative,
            } => {
                let lift = hinge_lift(model, axis, pivot_positive, pivot_negative);
                let pin = lift.is_none();
                let normal = lift.map_or_else(|| any_perpendicular(axis), |l| l.normalize());
                let t1 = axis.cross(&normal);
                ContactFace {
                    interface: index,
                    normal,
                    tangents: [t1, *axis],
                    points: if pin {
                        vec![*pivot_positive]
                    } else {
                        vec![*pivot_positive, *pivot_negative]
                    },
                    bilateral_couples: vec![normal, t1],
                    friction_tangents: 1,
                    pin,
                }
            }
            InterfaceKind::RockingBase {
                corners,
                normal,
                e1,
                ..
            } => ContactFace {
                interface: index,
                normal: *normal,
                tangents: [*e1, normal.cross(e1)],
                points: corners.to_vec(),
                bilateral_couples: Vec::new(),
                friction_tangents: 2,
                pin: false,
            },
        }
    }
}

/// The contact faces of every interface of `model`, in the order of [`Model::interfaces`].
pub fn contact_faces(model: &Model) -> Vec<ContactFace> {
    (0..model.interfaces.len())
        .map(|i| ContactFace::of_interface(model, i))
        .collect()
}

/// u × (P⁻ − P⁺) of a hinge with axis u and pivots P⁺, P⁻: the direction P⁻ lifts in when the
/// child turns about P⁺; None for a pin, where it is within the geometry's tolerance (× the model
/// size) of zero.
fn hinge_lift(
    model: &Model,
    axis: &Vector3<f64>,
    pivot_positive: &Vector3<f64>,
    pivot_negative: &Vector3<f64>,
) -> Option<Vector3<f64>> {
    let lift = axis.cross(&(pivot_negative - pivot_positive));
    (lift.norm() > GEOMETRY_TOLERANCE * model.size).then_some(lift)
}

/// A unit vector perpendicular to the unit vector `u`.
fn any_perpendicular(u: &Vector3<f64>) -> Vector3<f64> {
    let other = if u.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    u.cross(&other).normalize()
}
