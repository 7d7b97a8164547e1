//! Velocity-level kinematics: spatial velocities and the bias accelerations J̇q̇ of every frame, the
//! velocity-product forces h(q, q̇) and the constraint bias Φ̇_q q̇.
//!
//! Spatial motion vectors are [ω; v₀] with v₀ the velocity of the frame-fixed point at the world
//! origin; forces are [n₀; f] with n₀ the moment about the origin (Featherstone's convention in
//! world axes). Coordinate k moves along sₖ = [wₖ; pₖ × wₖ]; Vₖ = V_parent + sₖq̇ₖ and the bias
//! acceleration (q̈ = 0) is Aₖ = A_parent + Vₖ ×ₘ sₖq̇ₖ, because ṡₖ = V_parent ×ₘ sₖ.

use nalgebra::{DVector, Vector3, Vector6};

use crate::closure::{frame_rot, orientation_pairs};
use crate::data::Data;
use crate::kinematics::frame_point;
use crate::mass_matrix::{spatial_axis, spatial_inertia, world_inertia};
use crate::model::Model;
use crate::pivots::ActivePivots;

fn top(v: &Vector6<f64>) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}
fn bottom(v: &Vector6<f64>) -> Vector3<f64> {
    Vector3::new(v[3], v[4], v[5])
}
fn join(a: Vector3<f64>, b: Vector3<f64>) -> Vector6<f64> {
    Vector6::new(a.x, a.y, a.z, b.x, b.y, b.z)
}

/// Motion cross product [ω; v] ×ₘ [w; u] = [ω × w; ω × u + v × w].
pub fn cross_motion(a: &Vector6<f64>, b: &Vector6<f64>) -> Vector6<f64> {
    let (w, v, x, u) = (top(a), bottom(a), top(b), bottom(b));
    join(w.cross(&x), w.cross(&u) + v.cross(&x))
}

/// Force cross product [ω; v] ×_f [n; f] = [ω × n + v × f; ω × f].
pub fn cross_force(a: &Vector6<f64>, b: &Vector6<f64>) -> Vector6<f64> {
    let (w, v, n, f) = (top(a), bottom(a), top(b), bottom(b));
    join(w.cross(&n) + v.cross(&f), w.cross(&f))
}

/// Kinetic energy from the bodies' velocities (J): T = Σₙ ½ mₙ|v_c|² + ½ ωᵀIₙω with
/// v_c = v₀ + ω × cₙ from the spatial velocity [ω; v₀] of the body's frame. The same T as
/// ½ q̇ᵀ M q̇ ([`crate::kinetic_energy`]) without forming M: O(bodies). Requires
/// `data.spatial_velocity` of these rates ([`velocities`], or a forward-dynamics solve).
pub fn body_kinetic_energy(model: &Model, data: &Data) -> f64 {
    let mut t = 0.0;
    for (b, body) in model.bodies.iter().enumerate() {
        let k = model.body_coord[b];
        let v = &data.spatial_velocity[k];
        let (w, v0) = (top(v), bottom(v));
        let vc = v0 + w.cross(&data.com[b]);
        // ωᵀ(Γ I Γᵀ)ω = uᵀ I u with u = Γᵀω, the angular velocity in body axes.
        let u = data.rot_ops[k].tr_mul(&w);
        t += 0.5 * (body.mass * vc.norm_squared() + u.dot(&(body.inertia * u)));
    }
    t
}

/// Fills `data.spatial_velocity` and `data.bias_acceleration` for rates q̇.
/// Requires [`crate::forward_kinematics`].
pub fn velocities(model: &Model, data: &mut Data, qdot: &DVector<f64>) {
    for k in 0..model.dof() {
        let s = spatial_axis(data, k) * qdot[k];
        let (vp, ap) = match model.coords[k].parent {
            Some(p) => (data.spatial_velocity[p], data.bias_acceleration[p]),
            None => (Vector6::zeros(), Vector6::zeros()),
        };
        let v = vp + s;
        data.spatial_velocity[k] = v;
        data.bias_acceleration[k] = ap + cross_motion(&v, &s);
    }
}

/// Velocity of the point of frame `k` (None: ground) currently at world position `x`.
pub fn point_velocity(data: &Data, k: Option<usize>, x: &Vector3<f64>) -> Vector3<f64> {
    k.map_or_else(Vector3::zeros, |k| {
        let v = &data.spatial_velocity[k];
        bottom(v) + top(v).cross(x)
    })
}

/// Bias acceleration (the acceleration when q̈ = 0, i.e. J̇q̇) of the point of frame `k` at world
/// position `x`: a = a₀ + α × x + ω × v(x).
pub fn point_bias_acceleration(data: &Data, k: Option<usize>, x: &Vector3<f64>) -> Vector3<f64> {
    k.map_or_else(Vector3::zeros, |k| {
        let a = &data.bias_acceleration[k];
        let w = top(&data.spatial_velocity[k]);
        bottom(a) + top(a).cross(x) + w.cross(&point_velocity(data, Some(k), x))
    })
}

/// Fills `data.velocity_product` with h(q, q̇) = Ṁq̇ − ∂T/∂q (Coriolis and centrifugal terms) by the
/// recursive Newton–Euler algorithm with q̈ = 0 and no gravity: each body's force
/// fₙ = Iₙ Aₙ + Vₙ ×_f Iₙ Vₙ, summed over subtrees, hₖ = sₖᵀ Fₖ. Requires [`velocities`].
pub fn velocity_product(model: &Model, data: &mut Data) {
    for f in data.subtree_force.iter_mut() {
        *f = Vector6::zeros();
    }
    for (b, body) in model.bodies.iter().enumerate() {
        let k = model.body_coord[b];
        let i_w = world_inertia(body, &data.rot_ops[k]);
        let inertia = spatial_inertia(body.mass, &data.com[b], &i_w);
        let v = data.spatial_velocity[k];
        data.subtree_force[k] +=
            inertia * data.bias_acceleration[k] + cross_force(&v, &(inertia * v));
    }
    for k in (0..model.dof()).rev() {
        data.velocity_product[k] = spatial_axis(data, k).dot(&data.subtree_force[k]);
        if let Some(p) = model.coords[k].parent {
            let f = data.subtree_force[k];
            data.subtree_force[p] += f;
        }
    }
}

/// Fills `data.phi_bias` with Φ̇_q q̇, so that the closures hold at acceleration level when
/// Φ_q q̈ + Φ̇_q q̇ = 0. Point rows: difference of the bias accelerations of the two coincident
/// points; orientation rows r = A·B with Ȧ = ω × A: r̈ = Ä·B + 2Ȧ·Ḃ + A·B̈ at q̈ = 0.
/// Requires [`velocities`].
pub fn constraint_bias(model: &Model, data: &mut Data, pivots: &ActivePivots) {
    // Symmetry rows are linear in q: no bias.
    for k in 0..model.symmetries.len() {
        data.phi_bias[model.closure_rows + k] = 0.0;
    }
    for cl in &model.closures {
        let iface = &model.interfaces[cl.interface];
        let (a, b) = (
            model.frame_of(iface.parent),
            Some(model.body_coord[iface.child]),
        );
        let p = iface.kind.pivot(pivots.of_interface(model, cl.interface));
        let (xa, xb) = (frame_point(data, a, &p), frame_point(data, b, &p));
        let d = point_bias_acceleration(data, a, &xa) - point_bias_acceleration(data, b, &xb);
        data.phi_bias
            .fixed_rows_mut::<3>(cl.first_row)
            .copy_from(&d);
        let ang = |k: Option<usize>| -> (Vector3<f64>, Vector3<f64>) {
            k.map_or((Vector3::zeros(), Vector3::zeros()), |k| {
                (
                    top(&data.spatial_velocity[k]),
                    top(&data.bias_acceleration[k]),
                )
            })
        };
        let ((wa, aa), (wb, ab)) = (ang(a), ang(b));
        let (ra, rb) = (frame_rot(data, a), frame_rot(data, b));
        let (pairs, count) = orientation_pairs(&iface.kind);
        for (r, (va, vb)) in pairs.iter().take(count).enumerate() {
            let (x, y) = (ra * va, rb * vb);
            let (xd, yd) = (wa.cross(&x), wb.cross(&y));
            let xdd = aa.cross(&x) + wa.cross(&xd);
            let ydd = ab.cross(&y) + wb.cross(&yd);
            data.phi_bias[cl.first_row + 3 + r] = xdd.dot(&y) + 2.0 * xd.dot(&yd) + x.dot(&ydd);
        }
    }
}
