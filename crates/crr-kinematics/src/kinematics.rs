//! Forward kinematics along the dynamic chain (eq 1) and the body Jacobians.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use crate::data::Data;
use crate::model::{Model, Parent};
use crate::pivots::ActivePivots;
use crate::rotation::axis_angle;

/// Fills Γᵏ, tᵏ, wₖ, Pₖ, pₖ and the centres of mass for the configuration q with the active pivots
/// given (eq 1): a point X of a body whose frame is k is at
/// r = P₁ + Γ¹(P₂ − P₁) + … + Γᵏ(X − Pₖ), with Γᵏ = R₁…Rₖ and Rⱼ the rotation by qⱼ about the
/// rest axis uⱼ. Coordinates are in topological order, so one forward pass suffices.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &DVector<f64>, pivots: &ActivePivots) {
    debug_assert_eq!(q.len(), model.dof());
    for (k, c) in model.coords.iter().enumerate() {
        let iface = &model.interfaces[c.interface];
        let p_rest = iface.kind.pivot(&pivots.sides[iface.slots.clone()]);
        let own = axis_angle(&c.axis, q[k]);
        // A root coordinate's parent frame is the world: no products with the identity.
        let (rot, pivot, axis) = match c.parent {
            Some(p) => {
                let parent_rot = data.rot_ops[p];
                (
                    parent_rot * own,
                    parent_rot * p_rest + data.frame_translation[p],
                    parent_rot * c.axis,
                )
            }
            None => (own, p_rest, c.axis),
        };
        data.axis[k] = axis;
        data.pivot_rest[k] = p_rest;
        data.pivot[k] = pivot;
        data.rot_ops[k] = rot;
        data.frame_translation[k] = pivot - rot * p_rest;
    }
    for (b, body) in model.bodies.iter().enumerate() {
        data.com[b] = body_point(model, data, b, &body.com);
    }
}

/// Rotation of body `b` from rest (its Γ), after [`forward_kinematics`].
pub fn body_rotation(model: &Model, data: &Data, b: usize) -> Matrix3<f64> {
    data.rot_ops[model.body_coord[b]]
}

/// Rotation of a parent (identity for the ground), after [`forward_kinematics`].
pub fn parent_rotation(model: &Model, data: &Data, p: Parent) -> Matrix3<f64> {
    match model.frame_of(p) {
        Some(k) => data.rot_ops[k],
        None => Matrix3::identity(),
    }
}

/// World position of the point of body `b` that is at `x_rest` at rest, after
/// [`forward_kinematics`].
pub fn body_point(model: &Model, data: &Data, b: usize, x_rest: &Vector3<f64>) -> Vector3<f64> {
    frame_point(data, Some(model.body_coord[b]), x_rest)
}

/// World positions of the points of body `b` that are at `rest` at rest (e.g. the vertices of
/// its [`crate::shapes::Surface`]), after [`forward_kinematics`]: `out[i] = Γ rest[i] + t` with Γ
/// and t the body's frame. `out` is cleared first.
pub fn body_points(
    model: &Model,
    data: &Data,
    b: usize,
    rest: &[Vector3<f64>],
    out: &mut Vec<Vector3<f64>>,
) {
    let k = model.body_coord[b];
    let (rot, trans) = (data.rot_ops[k], data.frame_translation[k]);
    out.clear();
    out.extend(rest.iter().map(|x| rot * x + trans));
}

/// World position of a point attached to frame `k` (None: the ground).
pub fn frame_point(data: &Data, k: Option<usize>, x_rest: &Vector3<f64>) -> Vector3<f64> {
    match k {
        Some(k) => data.rot_ops[k] * x_rest + data.frame_translation[k],
        None => *x_rest,
    }
}

/// Fills the centre-of-mass and angular-velocity Jacobians J_c and J_ω of every body (ċ = J_c q̇,
/// ω = J_ω q̇), after [`forward_kinematics`].
pub fn jacobians(model: &Model, data: &mut Data) {
    let shape = (3 * model.bodies.len(), model.dof());
    if data.com_jacobian.shape() != shape {
        data.com_jacobian = DMatrix::zeros(shape.0, shape.1);
        data.angular_jacobian = DMatrix::zeros(shape.0, shape.1);
    }
    data.com_jacobian.fill(0.0);
    data.angular_jacobian.fill(0.0);
    for b in 0..model.bodies.len() {
        let c = data.com[b];
        let mut j = Some(model.body_coord[b]);
        while let Some(jj) = j {
            let w = data.axis[jj];
            let lin = w.cross(&(c - data.pivot[jj]));
            for r in 0..3 {
                data.com_jacobian[(3 * b + r, jj)] = lin[r];
                data.angular_jacobian[(3 * b + r, jj)] = w[r];
            }
            j = model.coords[jj].parent;
        }
    }
}
