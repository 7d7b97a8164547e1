//! The constraint row of an angle slot (a tree coordinate, a closure angle, the tilt of a
//! twisting rocking base) and its bias.

use super::*;

/// The constraint row of an angle slot: the generalized direction a with φ̇ = aᵀq̇ (eₖ for a tree
/// coordinate; for a closure angle the relative angular velocity of child and parent frames along
/// the angle's world axis), and its bias ȧᵀq̇. Requires kinematics and velocities in `kin`.
pub fn slot_row(model: &Model, kin: &Data, slot: usize, row: &mut DVector<f64>) -> f64 {
    row.fill(0.0);
    if slot < model.dof() {
        row[slot] = 1.0;
        return 0.0;
    }
    let (iface, component) = model
        .interfaces
        .iter()
        .find_map(|i| i.slots.clone().position(|s| s == slot).map(|c| (i, c)))
        .expect("slot of a closure interface");
    let (a, b) = (
        model.frame_of(iface.parent),
        Some(model.body_coord[iface.child]),
    );
    let rot = |k: Option<usize>| frame_rotation(kin, k);
    let ang = |k: Option<usize>, part: usize| frame_angular(kin, k, part);
    if let crr_kinematics::InterfaceKind::RockingBase {
        normal,
        e1,
        e2,
        twist: true,
        ..
    } = &iface.kind
    {
        return twisting_tilt_row(model, kin, (a, b), (normal, e1, e2), component, row);
    }
    // The axis is attached to the parent, except a rocking base's second tilt (child).
    let (w, on_child) = match &iface.kind {
        crr_kinematics::InterfaceKind::Hinge { axis, .. } => (rot(a) * axis, false),
        crr_kinematics::InterfaceKind::RockingBase { e1, e2, .. } => {
            if component == 0 {
                (rot(a) * e1, false)
            } else {
                (rot(b) * e2, true)
            }
        }
    };
    for (frame, sign) in [(b, 1.0), (a, -1.0)] {
        let mut j = frame;
        while let Some(jj) = j {
            row[jj] += sign * w.dot(&kin.axis[jj]);
            j = model.coords[jj].parent;
        }
    }
    let (wa, wb) = (ang(a, 0), ang(b, 0));
    let w_dot = if on_child { wb.cross(&w) } else { wa.cross(&w) };
    w.dot(&(ang(b, 1) - ang(a, 1))) + (wb - wa).dot(&w_dot)
}

/// The rotation Γ of frame `k` (the identity for the ground, `None`).
fn frame_rotation(kin: &Data, k: Option<usize>) -> nalgebra::Matrix3<f64> {
    k.map_or_else(nalgebra::Matrix3::identity, |k| kin.rot_ops[k])
}

/// The angular part of frame `k`'s spatial velocity (`part` 0) or bias acceleration (`part` 1),
/// world axes; zero for the ground (`None`).
fn frame_angular(kin: &Data, k: Option<usize>, part: usize) -> Vector3<f64> {
    k.map_or_else(Vector3::zeros, |k| {
        let v = if part == 0 {
            &kin.spatial_velocity[k]
        } else {
            &kin.bias_acceleration[k]
        };
        Vector3::new(v[0], v[1], v[2])
    })
}

/// [`slot_row`] of a closure tilt of a rocking base that may twist: the tilts are those of the
/// child's face normal m = Γ_B n seen from the parent, θ₁ = atan2(u, v) with u = −(Γ_A e₂)·m,
/// v = (Γ_A n)·m, and θ₂ = asin((Γ_A e₁)·m). With Ω = ω_B − ω_A (world), ṁ = ω_B × m and the
/// parent's axes turning with ω_A: θ̇₂ = Ω·(m × Γ_A e₁)/cos θ₂ and
/// θ̇₁ = Ω·(−v (m × Γ_A e₂) − u (m × Γ_A n))/(u² + v²). So θ̇ = wᵀΩ, whose row over q̇ is built
/// like a plain axis's, and the bias of θ̈ is wᵀ(Ω̇'s bias) + ẇᵀΩ.
fn twisting_tilt_row(
    model: &Model,
    kin: &Data,
    (a, b): (Option<usize>, Option<usize>),
    (normal, e1, e2): (&Vector3<f64>, &Vector3<f64>, &Vector3<f64>),
    component: usize,
    row: &mut DVector<f64>,
) -> f64 {
    let rot = |k: Option<usize>| frame_rotation(kin, k);
    let ang = |k: Option<usize>, part: usize| frame_angular(kin, k, part);
    let (ra, rb) = (rot(a), rot(b));
    let (wa, wb) = (ang(a, 0), ang(b, 0));
    let m = rb * normal;
    let m_dot = wb.cross(&m);
    let (w, w_dot) = if component == 0 {
        let (e2a, na) = (ra * e2, ra * normal);
        let (e2a_dot, na_dot) = (wa.cross(&e2a), wa.cross(&na));
        let (u, v) = (-e2a.dot(&m), na.dot(&m));
        let (u_dot, v_dot) = (
            -(e2a_dot.dot(&m) + e2a.dot(&m_dot)),
            na_dot.dot(&m) + na.dot(&m_dot),
        );
        let d = u * u + v * v;
        let d_dot = 2.0 * (u * u_dot + v * v_dot);
        let p = -m.cross(&e2a) * v - m.cross(&na) * u;
        let p_dot = -m.cross(&e2a) * v_dot
            - (m_dot.cross(&e2a) + m.cross(&e2a_dot)) * v
            - m.cross(&na) * u_dot
            - (m_dot.cross(&na) + m.cross(&na_dot)) * u;
        (p / d, p_dot / d - p * (d_dot / (d * d)))
    } else {
        let e1a = ra * e1;
        let e1a_dot = wa.cross(&e1a);
        let s = e1a.dot(&m);
        let s_dot = e1a_dot.dot(&m) + e1a.dot(&m_dot);
        let c = (1.0 - s * s).max(0.0).sqrt();
        let c_dot = -s * s_dot / c;
        let p = m.cross(&e1a);
        let p_dot = m_dot.cross(&e1a) + m.cross(&e1a_dot);
        (p / c, p_dot / c - p * (c_dot / (c * c)))
    };
    row.fill(0.0);
    for (frame, sign) in [(b, 1.0), (a, -1.0)] {
        let mut j = frame;
        while let Some(jj) = j {
            row[jj] += sign * w.dot(&kin.axis[jj]);
            j = model.coords[jj].parent;
        }
    }
    w.dot(&(ang(b, 1) - ang(a, 1))) + (wb - wa).dot(&w_dot)
}
