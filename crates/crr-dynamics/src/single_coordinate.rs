//! Forward dynamics of a structure with one coordinate (DOF(1) = 1): its body turns with θ about
//! one world axis w through the active pivot p, both fixed in the world (the coordinate's parent
//! is the ground). Housner's block, a block on a hinge. (Every body is the child of one tree
//! interface that adds at least one coordinate, so DOF(1) = 1 without closures means one body on
//! a hinge to the ground; the sums below run over the bodies all the same.)
//!
//! The kinetic energy is T = ½ I_p θ̇² with the moment of inertia about the pivot line
//!
//! I_p = Σₙ [ mₙ |w × (cₙ − p)|² + wᵀ Iₙ w ]
//!
//! (cₙ the centre and Iₙ the world inertia about it of body n). A rotation about w changes
//! neither the distance of cₙ from the line nor wᵀIₙw, so I_p does not depend on θ: M = I_p,
//! h = Ṁθ̇ − ½ ∂M/∂θ θ̇² = 0, and the equation of motion is
//!
//! I_p θ̈ = Q + τ,
//!
//! Q = w · Σₙ (cₙ − p) × mₙ g_eff the generalized load ([`crate::eom`]) and τ an extra
//! generalized force. This is what the articulated-body algorithm computes for one coordinate
//! (its pass 1 builds a 6 × 6 inertia, pass 3 projects it on s = [w; p × w]), at a fraction of its
//! cost: the whole right-hand side of a free-rocking block is then the forward kinematics of one
//! rotation. `tests/single_coordinate.rs` checks it against the articulated-body algorithm and
//! against M by composite rigid bodies on random 3D bodies.
//!
//! **The integrator's kernel** ([`Kernel`]). With the parent the ground, the axis u and the pivot
//! p₀ are the rest ones and every centre moves as cₙ = p₀ + R(θ)(cₙ⁰ − p₀), R = I + sin θ \[u\]× +
//! (1 − cos θ)\[u\]×² (Rodrigues, as [`crr_kinematics::rotation::axis_angle`]). With
//! r₀ = Σₙ mₙ(cₙ⁰ − p₀) the first moment about the pivot at rest, the load of a field f is
//!
//! Q_f(θ) = f · (u × R r₀) = f·a₁ + sin θ f·a₂ + (1 − cos θ) f·a₃,
//! a₁ = u × r₀, a₂ = u × a₁, a₃ = u × a₂,
//!
//! so that θ̈ = Q_{g_eff}(θ)/I_p and the ground force Q_{−a_g}(θ) cost one sin/cos and a few
//! products once a₁, a₂, a₃ and I_p are known for the active pivot, without the kinematics
//! workspace.

use nalgebra::{Vector3, Vector6};

use crr_kinematics::mass_matrix::spatial_axis;
use crr_kinematics::{ActivePivots, Data, Model, Side};

/// Whether [`solve`] applies: one coordinate, no closure rows.
pub fn applies(model: &Model) -> bool {
    model.dof() == 1 && model.constraint_rows == 0
}

/// θ̈ = (Q + τ)/I_p for the one coordinate of `model` (see the module docs), from the
/// kinematics in `data` ([`crr_kinematics::forward_kinematics`]) and the generalized force
/// `force` = Q + τ (N m). Also fills `data.spatial_velocity` (V = s θ̇) and
/// `data.bias_acceleration` (V ×ₘ sθ̇ = 0) as [`crr_kinematics::velocities`] does. Returns None
/// when I_p is not positive and finite (a massless coordinate).
pub fn solve(model: &Model, data: &mut Data, theta_dot: f64, force: f64) -> Option<f64> {
    debug_assert!(applies(model));
    let (w, p) = (data.axis[0], data.pivot[0]);
    let mut inertia = 0.0;
    // wᵀ(Γ I Γᵀ)w = uᵀ I u with u = Γᵀw: the inertia in body axes.
    let u = data.rot_ops[0].tr_mul(&w);
    for (b, body) in model.bodies.iter().enumerate() {
        let arm = w.cross(&(data.com[b] - p));
        inertia += body.mass * arm.norm_squared() + u.dot(&(body.inertia * u));
    }
    if !(inertia > 0.0 && inertia.is_finite()) {
        return None;
    }
    data.spatial_velocity[0] = spatial_axis(data, 0) * theta_dot;
    data.bias_acceleration[0] = Vector6::zeros();
    Some(force / inertia)
}

/// The one-coordinate equation of motion for one active pivot, as a function of θ alone (see the
/// module docs): θ̈ = (Q_{g_eff}(θ) + τ)/I_p.
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    /// The sides of the pivot's interface it was built for (they set the pivot).
    sides: Vec<Side>,
    /// The rest pivot p₀ (m).
    pivot: Vector3<f64>,
    /// I_p (kg m²).
    inertia: f64,
    /// a₁ = u × r₀, a₂ = u × a₁, a₃ = u × a₂ (kg m).
    a: [Vector3<f64>; 3],
}

impl Kernel {
    /// The kernel of `model`'s one coordinate on the active pivot of `pivots`. None when
    /// [`applies`] does not hold or I_p is not positive and finite.
    pub fn new(model: &Model, pivots: &ActivePivots) -> Option<Self> {
        if !applies(model) || model.coords[0].parent.is_some() {
            return None;
        }
        let coord = &model.coords[0];
        let iface = &model.interfaces[coord.interface];
        let sides = pivots.sides[iface.slots.clone()].to_vec();
        let pivot = iface.kind.pivot(&sides);
        let u = coord.axis;
        let (mut inertia, mut r0) = (0.0, Vector3::zeros());
        for body in &model.bodies {
            let arm = body.com - pivot;
            inertia += body.mass * u.cross(&arm).norm_squared() + u.dot(&(body.inertia * u));
            r0 += arm * body.mass;
        }
        if !(inertia > 0.0 && inertia.is_finite()) {
            return None;
        }
        let a1 = u.cross(&r0);
        let a2 = u.cross(&a1);
        let a3 = u.cross(&a2);
        Some(Self {
            sides,
            pivot,
            inertia,
            a: [a1, a2, a3],
        })
    }

    /// Whether this kernel, built for `model`, is the one of the active pivot of `pivots`: the
    /// same sides of its interface (the pivot is a function of them). A kernel belongs to one
    /// model (as the [`crate::Dynamics`] holding it does): the geometry is not compared.
    #[inline]
    pub fn is_for(&self, model: &Model, pivots: &ActivePivots) -> bool {
        let iface = &model.interfaces[model.coords[0].interface];
        // Compared side by side: one or two sides, read on every right-hand side.
        pivots.sides.get(iface.slots.clone()).is_some_and(|s| {
            s.len() == self.sides.len() && s.iter().zip(&self.sides).all(|(a, b)| a == b)
        })
    }

    /// I_p (kg m²).
    pub fn inertia(&self) -> f64 {
        self.inertia
    }

    /// The generalized force of a uniform field `field` (m/s², on every body's mass) at θ, from
    /// sin θ and cos θ: Q_f = f·a₁ + sin θ f·a₂ + (1 − cos θ) f·a₃ (N m).
    pub fn load(&self, field: &Vector3<f64>, sin: f64, cos: f64) -> f64 {
        field.dot(&self.a[0]) + sin * field.dot(&self.a[1]) + (1.0 - cos) * field.dot(&self.a[2])
    }
}
