//! Forward dynamics of a structure with one coordinate (DOF(1) = 1): every body turns with θ
//! about one world axis w through the active pivot p, both fixed in the world (the coordinate's
//! parent is the ground). Housner's block, a block on a hinge, a rigid group rocking as one.
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

use nalgebra::Vector6;

use crr_kinematics::mass_matrix::spatial_axis;
use crr_kinematics::{Data, Model};

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
