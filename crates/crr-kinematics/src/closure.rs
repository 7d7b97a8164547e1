//! Loop closures: residuals Φ(q), their Jacobian Φ_q, and the closure angles.
//!
//! A hinge closure between frames A (parent) and B (child) with axis u and active pivot P imposes
//! x_A(P) − x_B(P) = 0 (3 rows) and (Γ_A v₁)·(Γ_B u) = (Γ_A v₂)·(Γ_B u) = 0 (2 rows), v₁, v₂ ⊥ u:
//! 5 rows (only 2 independent in a planar structure). A rocking-base closure imposes the corner
//! coincidence and (Γ_A e₁)·(Γ_B e₂) = 0, the condition of two tilts in series (a Hooke joint):
//! 4 rows.

use nalgebra::{DVector, Matrix3, UnitQuaternion, Vector3};

use crate::data::Data;
use crate::kinematics::frame_point;
use crate::model::{InterfaceKind, Model};
use crate::pivots::ActivePivots;

/// A unit vector perpendicular to `u` (deterministic).
pub fn perpendicular(u: &Vector3<f64>) -> Vector3<f64> {
    let e = if u.x.abs() <= u.y.abs() && u.x.abs() <= u.z.abs() {
        Vector3::x()
    } else if u.y.abs() <= u.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    u.cross(&e).normalize()
}

pub(crate) fn frame_rot(data: &Data, k: Option<usize>) -> Matrix3<f64> {
    k.map_or_else(Matrix3::identity, |k| data.rot_ops[k])
}

/// Frames (parent, child) of a closure interface.
fn closure_frames(model: &Model, interface: usize) -> (Option<usize>, Option<usize>) {
    let i = &model.interfaces[interface];
    (model.frame_of(i.parent), Some(model.body_coord[i.child]))
}

/// A pair (a on frame A, b on frame B) whose dot product (Γ_A a)·(Γ_B b) is one orientation row.
pub(crate) type OrientationPair = (Vector3<f64>, Vector3<f64>);

/// The pairs whose dot products are the orientation rows of a closure, and how many rows there
/// are (2 for a hinge, 1 for a rocking base).
pub(crate) fn orientation_pairs(kind: &InterfaceKind) -> ([OrientationPair; 2], usize) {
    match kind {
        InterfaceKind::Hinge { axis, .. } => {
            let v1 = perpendicular(axis);
            let v2 = axis.cross(&v1);
            ([(v1, *axis), (v2, *axis)], 2)
        }
        InterfaceKind::RockingBase { e1, e2, twist, .. } => {
            ([(*e1, *e2), (*e1, *e2)], if *twist { 0 } else { 1 })
        }
    }
}

/// Fills `data.phi` with Φ(q): closure rows, then symmetry rows qₐ − s q_b.
/// Requires [`crate::forward_kinematics`].
pub fn constraint_residual(
    model: &Model,
    data: &mut Data,
    pivots: &ActivePivots,
    q: &DVector<f64>,
) {
    for (k, &(a, b, s)) in model.symmetries.iter().enumerate() {
        data.phi[model.closure_rows + k] = q[a] - s * q[b];
    }
    for cl in &model.closures {
        let iface = &model.interfaces[cl.interface];
        let (a, b) = closure_frames(model, cl.interface);
        let p = iface.kind.pivot(pivots.of_interface(model, cl.interface));
        let d = frame_point(data, a, &p) - frame_point(data, b, &p);
        let r0 = cl.first_row;
        data.phi.fixed_rows_mut::<3>(r0).copy_from(&d);
        let (ra, rb) = (frame_rot(data, a), frame_rot(data, b));
        let (pairs, count) = orientation_pairs(&iface.kind);
        for (r, (va, vb)) in pairs.iter().take(count).enumerate() {
            data.phi[r0 + 3 + r] = (ra * va).dot(&(rb * vb));
        }
    }
}

/// Fills `data.phi_q` with Φ_q = ∂Φ/∂q. Requires [`crate::forward_kinematics`].
pub fn constraint_jacobian(model: &Model, data: &mut Data, pivots: &ActivePivots) {
    // Only the entries written below are ever nonzero (`Data::new` starts from zeros and nothing
    // else writes Φ_q): a closure's rows depend on the coordinates of its two frames' paths to
    // the ground alone. Zeroing those, not the whole rows × DOF(1) matrix, keeps the cost with
    // the loops' depth rather than the structure's size.
    for (k, &(a, b, _)) in model.symmetries.iter().enumerate() {
        data.phi_q[(model.closure_rows + k, a)] = 0.0;
        data.phi_q[(model.closure_rows + k, b)] = 0.0;
    }
    for cl in &model.closures {
        let (a, b) = closure_frames(model, cl.interface);
        let rows = 3 + orientation_pairs(&model.interfaces[cl.interface].kind).1;
        for frame in [a, b] {
            let mut j = frame;
            while let Some(jj) = j {
                for r in 0..rows {
                    data.phi_q[(cl.first_row + r, jj)] = 0.0;
                }
                j = model.coords[jj].parent;
            }
        }
    }
    for (k, &(a, b, s)) in model.symmetries.iter().enumerate() {
        data.phi_q[(model.closure_rows + k, a)] = 1.0;
        data.phi_q[(model.closure_rows + k, b)] -= s;
    }
    for cl in &model.closures {
        let iface = &model.interfaces[cl.interface];
        let (a, b) = closure_frames(model, cl.interface);
        let p = iface.kind.pivot(pivots.of_interface(model, cl.interface));
        let r0 = cl.first_row;
        let (xa, xb) = (frame_point(data, a, &p), frame_point(data, b, &p));
        for (frame, x, sign) in [(a, xa, 1.0), (b, xb, -1.0)] {
            let mut j = frame;
            while let Some(jj) = j {
                let c = data.axis[jj].cross(&(x - data.pivot[jj]));
                for r in 0..3 {
                    data.phi_q[(r0 + r, jj)] += sign * c[r];
                }
                j = model.coords[jj].parent;
            }
        }
        // d/dt (Γ_A a)·(Γ_B b) = (ω_A − ω_B)·((Γ_A a) × (Γ_B b)).
        let (ra, rb) = (frame_rot(data, a), frame_rot(data, b));
        let (pairs, count) = orientation_pairs(&iface.kind);
        for (r, (va, vb)) in pairs.iter().take(count).enumerate() {
            let nrm = (ra * va).cross(&(rb * vb));
            for (frame, s) in [(a, 1.0), (b, -1.0)] {
                let mut j = frame;
                while let Some(jj) = j {
                    data.phi_q[(r0 + 3 + r, jj)] += s * data.axis[jj].dot(&nrm);
                    j = model.coords[jj].parent;
                }
            }
        }
    }
}

/// The relative angles of every closure slot (in slot order, `slot_count − DOF(1)` values) from
/// the relative rotation Γ_Aᵀ Γ_B ([`relative_angles`]). Requires [`crate::forward_kinematics`].
pub fn closure_angles(model: &Model, data: &Data, out: &mut [f64]) {
    let base = model.dof();
    for cl in &model.closures {
        let iface = &model.interfaces[cl.interface];
        let (a, b) = closure_frames(model, cl.interface);
        let rel = frame_rot(data, a).transpose() * frame_rot(data, b);
        let s0 = iface.slots.start - base;
        relative_angles(&iface.kind, &rel, &mut out[s0..s0 + iface.slots.len()]);
    }
}

/// The angles of an interface from the relative rotation Γ_Aᵀ Γ_B of its child to its parent:
/// for a hinge the twist angle about u (swing–twist decomposition); for a rocking base the tilts
/// θ₁ about e₁ and θ₂ about e₂ with Γ_AᵀΓ_B = R(e₁, θ₁)R(e₂, θ₂). For a tree interface these are
/// its coordinates; for a closure, its closure angles.
pub fn relative_angles(kind: &InterfaceKind, rel: &Matrix3<f64>, out: &mut [f64]) {
    match kind {
        InterfaceKind::Hinge { axis, .. } => {
            // Twist of the swing–twist decomposition: 2 atan2(v·u, w) of the quaternion
            // (w, v) of Γ_AᵀΓ_B, independent of any reference direction.
            let quat = UnitQuaternion::from_matrix(rel);
            let mut t = 2.0 * quat.imag().dot(axis).atan2(quat.w);
            if t > std::f64::consts::PI {
                t -= 2.0 * std::f64::consts::PI;
            } else if t <= -std::f64::consts::PI {
                t += 2.0 * std::f64::consts::PI;
            }
            out[0] = t;
        }
        InterfaceKind::RockingBase {
            normal,
            e1,
            e2,
            twist: true,
            ..
        } => {
            // Γ_AᵀΓ_B n = R(e₁, θ₁)R(e₂, θ₂) n = e₁ sin θ₂ + cos θ₂ (n cos θ₁ − e₂ sin θ₁): the
            // twist about n leaves n where it is.
            let rn = rel * normal;
            out[0] = (-e2.dot(&rn)).atan2(normal.dot(&rn));
            out[1] = e1.dot(&rn).clamp(-1.0, 1.0).asin();
        }
        InterfaceKind::RockingBase { normal, e1, e2, .. } => {
            let r2 = rel * e2;
            out[0] = normal.dot(&r2).atan2(e2.dot(&r2));
            let r1 = rel.transpose() * e1;
            out[1] = normal.dot(&r1).atan2(e1.dot(&r1));
        }
    }
}

/// Every slot's angle (`slot_count` values: the coordinates q, then the closure angles) measured
/// from the bodies' rotations alone, `rotations[b]` the rotation of body b from rest, e.g. poses
/// from another engine.
pub fn interface_angles(model: &Model, rotations: &[Matrix3<f64>], out: &mut [f64]) {
    for iface in &model.interfaces {
        let ra = match iface.parent {
            crate::model::Parent::Ground => Matrix3::identity(),
            crate::model::Parent::Body(p) => rotations[p],
        };
        let rel = ra.transpose() * rotations[iface.child];
        relative_angles(&iface.kind, &rel, &mut out[iface.slots.clone()]);
    }
}
