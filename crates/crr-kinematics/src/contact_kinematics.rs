//! Face-level contact geometry in a configuration q: the gaps and slips of every contact point of
//! every interface, their Jacobians with respect to q and their bias accelerations.
//!
//! Interface i joins a parent A (a body, or the ground) to a child B. Every point X of its
//! [`ContactFace`] (world, at rest) is a material point of both bodies, coincident at rest. In a
//! configuration q (with the active pivots of [`crate::forward_kinematics`]) the two copies are
//!
//!   x_B = Γ_B X + t_B,  x_A = Γ_A X + t_A  (ground: Γ_A = I, t_A = 0, x_A = X),
//!
//! with Γ, t the frames of the bodies (`Data::rot_ops`, `Data::frame_translation`). The face's
//! frame turns with the parent: n(q) = Γ_A n, t_k(q) = Γ_A t_k (n, t₁, t₂ the rest normal, into the
//! child, and tangents of the face). With d = x_B − x_A the separation,
//!
//!   g = n(q)·d  (normal gap: > 0 open, < 0 interpenetrating),  s_k = t_k(q)·d  (slips),
//!
//! which are the components of the child's point in the parent's rest frame,
//! g = n·(Γ_Aᵀ(x_B − t_A) − X). Hence, with V = [ω; v₀] the spatial velocities and
//! v_F(x) = v₀_F + ω_F × x the velocity of the point of frame F currently at x:
//!
//! - **Rates.** ġ = n(q)·u and ṡ_k = t_k(q)·u with u = v_B(x_B) − v_A(x_B), the velocity of the
//!   child's copy relative to the parent's frame, taken at the child's copy. This is
//!   ṅ·d + n·ḋ: the term ṅ·d = (ω_A × n)·d of the turning normal is included (it vanishes at
//!   contact, d = 0, but not in general).
//! - **Jacobians.** ġ = G q̇ with, for coordinate j (world axis wⱼ, world pivot pⱼ),
//!   Gⱼ = ±n(q)·(wⱼ × (x_B − pⱼ)): + when j is on the tree path of B only, − when on that of A
//!   only, 0 otherwise (a common ancestor moves both copies and the face rigidly). The rows of the
//!   slips are the same with t_k(q) for n(q).
//! - **Biases.** With a_F(x) = J_F(x) q̈ + b_F(x) the acceleration of the point of frame F at x
//!   (b_F(x) = α₀ + α × x + ω × v_F(x) from the bias accelerations Aₖ = J̇q̇ of
//!   [`crate::velocities`]), differentiating ġ = n·u once more gives
//!
//!   g̈ = G q̈ + n(q)·(b_B(x_B) − b_A(x_B) − 2 ω_A × u),
//!
//!   the last term the Coriolis acceleration of the relative motion in the parent's turning
//!   frame. The bias β = n(q)·(b_B(x_B) − b_A(x_B) − 2 ω_A × u) is g̈ at q̈ = 0, so a contact that
//!   must not open or close at acceleration level reads G q̈ + β ≥ 0 (or = 0). Slips likewise with
//!   t_k(q).
//!
//! The points are numbered over all interfaces in the order of [`Model::interfaces`], each
//! face's points in the order of [`ContactFace::points`]
//! ([`ContactKinematics::point_range`]). At q = 0 every gap and slip is 0; when a tree interface's
//! child rocks on the active pivot P the gap of P stays 0 and the others open (a positive angle
//! rotates about P⁺ and lifts P⁻ along n).

use std::ops::Range;

use nalgebra::{DMatrix, DVector, Vector3};

use crate::contact_face::{ContactFace, contact_faces};
use crate::data::Data;
use crate::model::Model;
use crate::velocity::{point_bias_acceleration, point_velocity};

/// Workspace of the contact geometry of a model: allocated once by [`ContactKinematics::new`],
/// filled by [`contact_geometry`] (positions, gaps, slips, Jacobians) and [`contact_bias`] (rates
/// and biases) without allocating. m is the number of contact points over all interfaces, n =
/// DOF(1); slip rows are 2p + k for tangent k of point p.
#[derive(Clone, Debug)]
pub struct ContactKinematics {
    /// The contact faces at rest, one per interface, in the order of [`Model::interfaces`].
    pub faces: Vec<ContactFace>,
    /// First point of each interface, and the point count at the end (length interfaces + 1).
    pub first_point: Vec<usize>,
    /// The interface of each point.
    pub interface_of_point: Vec<usize>,

    // --- filled by `contact_geometry` ---
    /// x_B: world position of the child's copy of each point (m).
    pub child_point: Vec<Vector3<f64>>,
    /// x_A: world position of the parent's copy of each point (m; the rest point on the ground).
    pub parent_point: Vec<Vector3<f64>>,
    /// n(q) = Γ_A n: current normal of each interface's face (into the child).
    pub normal: Vec<Vector3<f64>>,
    /// t_k(q) = Γ_A t_k: current tangents of each interface's face.
    pub tangents: Vec<[Vector3<f64>; 2]>,
    /// g = n(q)·(x_B − x_A): normal gap of each point (m), length m.
    pub gap: DVector<f64>,
    /// s_k = t_k(q)·(x_B − x_A): slips (m), row 2p + k, length 2m.
    pub slip: DVector<f64>,
    /// G: ġ = G q̇, m × n (m/rad).
    pub gap_jacobian: DMatrix<f64>,
    /// S: ṡ = S q̇, 2m × n (m/rad), row 2p + k.
    pub slip_jacobian: DMatrix<f64>,

    // --- filled by `contact_bias` ---
    /// ġ = n(q)·(v_B(x_B) − v_A(x_B)) (m/s), length m.
    pub gap_rate: DVector<f64>,
    /// ṡ_k = t_k(q)·(v_B(x_B) − v_A(x_B)) (m/s), length 2m.
    pub slip_rate: DVector<f64>,
    /// β: g̈ = G q̈ + β, the gap's acceleration at q̈ = 0 (m/s²), length m.
    pub gap_bias: DVector<f64>,
    /// The slips' accelerations at q̈ = 0, s̈ = S q̈ + bias (m/s²), length 2m.
    pub slip_bias: DVector<f64>,
}

impl ContactKinematics {
    /// Allocates the workspace for `model` (its contact faces from [`contact_faces`]).
    pub fn new(model: &Model) -> Self {
        let faces = contact_faces(model);
        let mut first_point = Vec::with_capacity(faces.len() + 1);
        let mut interface_of_point = Vec::new();
        for (i, face) in faces.iter().enumerate() {
            first_point.push(interface_of_point.len());
            interface_of_point.extend(std::iter::repeat_n(i, face.points.len()));
        }
        let m = interface_of_point.len();
        first_point.push(m);
        let n = model.dof();
        Self {
            child_point: faces
                .iter()
                .flat_map(|f| f.points.iter().copied())
                .collect(),
            parent_point: faces
                .iter()
                .flat_map(|f| f.points.iter().copied())
                .collect(),
            normal: faces.iter().map(|f| f.normal).collect(),
            tangents: faces.iter().map(|f| f.tangents).collect(),
            faces,
            first_point,
            interface_of_point,
            gap: DVector::zeros(m),
            slip: DVector::zeros(2 * m),
            gap_jacobian: DMatrix::zeros(m, n),
            slip_jacobian: DMatrix::zeros(2 * m, n),
            gap_rate: DVector::zeros(m),
            slip_rate: DVector::zeros(2 * m),
            gap_bias: DVector::zeros(m),
            slip_bias: DVector::zeros(2 * m),
        }
    }

    /// Number of contact points m over all interfaces.
    pub fn point_count(&self) -> usize {
        self.interface_of_point.len()
    }

    /// The points of interface `interface` (indices into the per-point buffers).
    pub fn point_range(&self, interface: usize) -> Range<usize> {
        self.first_point[interface]..self.first_point[interface + 1]
    }
}

/// Fills the positions of both copies of every contact point, the faces' current normals and
/// tangents, the gaps g, slips s and their Jacobians G, S (see the module's documentation).
/// Requires [`crate::forward_kinematics`] for the configuration (it reads Γ, t, wⱼ and pⱼ; not
/// [`crate::jacobians`]). Does not allocate.
pub fn contact_geometry(model: &Model, data: &Data, contacts: &mut ContactKinematics) {
    contacts.gap_jacobian.fill(0.0);
    contacts.slip_jacobian.fill(0.0);
    for (i, iface) in model.interfaces.iter().enumerate() {
        let a = model.frame_of(iface.parent);
        let b = model.body_coord[iface.child];
        let face = &contacts.faces[i];
        let (n, t) = match a {
            Some(k) => {
                let r = &data.rot_ops[k];
                (
                    r * face.normal,
                    [r * face.tangents[0], r * face.tangents[1]],
                )
            }
            None => (face.normal, face.tangents),
        };
        contacts.normal[i] = n;
        contacts.tangents[i] = t;
        let first = contacts.first_point[i];
        for (j, x_rest) in face.points.iter().enumerate() {
            let p = first + j;
            let xb = data.rot_ops[b] * x_rest + data.frame_translation[b];
            let xa = match a {
                Some(k) => data.rot_ops[k] * x_rest + data.frame_translation[k],
                None => *x_rest,
            };
            let d = xb - xa;
            contacts.child_point[p] = xb;
            contacts.parent_point[p] = xa;
            contacts.gap[p] = n.dot(&d);
            contacts.slip[2 * p] = t[0].dot(&d);
            contacts.slip[2 * p + 1] = t[1].dot(&d);
            // Walk both tree paths up to their common ancestor: coordinates are in topological
            // order (a parent's index is smaller), and None (the ground) is below every Some.
            let (mut ja, mut jb) = (a, Some(b));
            while ja != jb {
                let (k, sign) = if jb > ja {
                    let k = jb.expect("jb > ja, so jb is a coordinate");
                    jb = model.coords[k].parent;
                    (k, 1.0)
                } else {
                    let k = ja.expect("ja > jb, so ja is a coordinate");
                    ja = model.coords[k].parent;
                    (k, -1.0)
                };
                let c = data.axis[k].cross(&(xb - data.pivot[k])) * sign;
                contacts.gap_jacobian[(p, k)] = n.dot(&c);
                contacts.slip_jacobian[(2 * p, k)] = t[0].dot(&c);
                contacts.slip_jacobian[(2 * p + 1, k)] = t[1].dot(&c);
            }
        }
    }
}

/// Fills the rates ġ, ṡ and the biases (g̈, s̈ at q̈ = 0) of every contact point: with
/// u = v_B(x_B) − v_A(x_B), ġ = n(q)·u and β = n(q)·(b_B(x_B) − b_A(x_B) − 2 ω_A × u), so that
/// g̈ = G q̈ + β (slips likewise with t_k(q)). The rates q̇ enter through the spatial velocities and
/// bias accelerations of [`crate::velocities`]`(model, data, qdot)`, which must have been called
/// for the same configuration, after [`contact_geometry`]. Does not allocate.
pub fn contact_bias(model: &Model, data: &Data, contacts: &mut ContactKinematics) {
    for (i, iface) in model.interfaces.iter().enumerate() {
        let a = model.frame_of(iface.parent);
        let b = Some(model.body_coord[iface.child]);
        let (n, t) = (contacts.normal[i], contacts.tangents[i]);
        let omega_a = a.map_or_else(Vector3::zeros, |k| {
            data.spatial_velocity[k].fixed_rows::<3>(0).into_owned()
        });
        for p in contacts.point_range(i) {
            let xb = contacts.child_point[p];
            let u = point_velocity(data, b, &xb) - point_velocity(data, a, &xb);
            let acc = point_bias_acceleration(data, b, &xb)
                - point_bias_acceleration(data, a, &xb)
                - 2.0 * omega_a.cross(&u);
            contacts.gap_rate[p] = n.dot(&u);
            contacts.slip_rate[2 * p] = t[0].dot(&u);
            contacts.slip_rate[2 * p + 1] = t[1].dot(&u);
            contacts.gap_bias[p] = n.dot(&acc);
            contacts.slip_bias[2 * p] = t[0].dot(&acc);
            contacts.slip_bias[2 * p + 1] = t[1].dot(&acc);
        }
    }
}
