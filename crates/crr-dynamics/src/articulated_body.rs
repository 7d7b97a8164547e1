//! Forward dynamics of an open (tree) chain in O(DOF(1)) by Featherstone's articulated-body
//! algorithm (ABA; R. Featherstone, *Rigid Body Dynamics Algorithms*, Springer 2008, §7.3, Table
//! 7.1), written in world-frame Plücker coordinates.
//!
//! Every CRR coordinate k is a revolute rotation about the world axis wₖ through the active pivot
//! pₖ, so its joint motion subspace is the spatial axis sₖ = [wₖ; pₖ × wₖ]
//! ([`spatial_axis`]). All spatial quantities are expressed in world axes about the world origin
//! (motion vectors [ω; v₀], forces [n₀; f], as in [`crr_kinematics::velocity`]), so the
//! coordinate transforms ˡXₖ of the textbook are identities and the three passes read:
//!
//! 1. outwards: Vₖ = V_λ(k) + sₖq̇ₖ, cₖ = Vₖ ×ₘ sₖq̇ₖ (the velocity-product acceleration,
//!    ṡₖq̇ₖ), Iᴬₖ = Σₙ Iₙ and pᴬₖ = Σₙ Vₖ ×_f IₙVₖ over the bodies n moving with k (Iₙ the spatial
//!    inertia of body n about the origin);
//! 2. inwards: Uₖ = Iᴬₖsₖ, Dₖ = sₖᵀUₖ, uₖ = τₖ − sₖᵀpᴬₖ, and the parent λ(k) receives
//!    Iᵃ = Iᴬₖ − UₖUₖᵀ/Dₖ and pᵃ = pᴬₖ + Iᵃcₖ + Uₖuₖ/Dₖ;
//! 3. outwards: a′ = a_λ(k) + cₖ, q̈ₖ = (uₖ − Uₖᵀa′)/Dₖ, aₖ = a′ + sₖq̈ₖ, from the base
//!    acceleration a₀ = [0; −g_eff]: a uniform field g_eff on every body is the same as the
//!    ground accelerating by −g_eff (Featherstone §5.3), which gives the generalized load
//!    Q = Σₙ Mⁿ J_cₙᵀ g_eff of [`crate::eom`].
//!
//! **Locked coordinates** (seated tree coordinates, q̈ₖ = 0 held by a reaction rₖ) are welds for
//! the dynamics: in pass 2 the joint passes its full articulated inertia to its parent,
//! Iᵃ = Iᴬₖ and pᵃ = pᴬₖ + Iᴬₖcₖ (no projection), and in pass 3 q̈ₖ = 0, aₖ = a′. The spatial
//! force transmitted across the joint is fₖ = Iᴬₖaₖ + pᴬₖ, and the joint's generalized equation
//! sₖᵀfₖ = τₖ + rₖ gives the reaction rₖ = sₖᵀ(Iᴬₖaₖ + pᴬₖ) − τₖ: the Lagrange multiplier of the
//! row q̇ₖ = 0 in M q̈ + h = Q + τ + Σ eₖrₖ, the sign of [`crate::Dynamics::seat_reactions`].
//!
//! The workspace is allocated once ([`ArticulatedBody::new`]); [`ArticulatedBody::solve`] does
//! not allocate.

use nalgebra::{DVector, Matrix3, Matrix6, Vector3, Vector6};

use crr_kinematics::mass_matrix::{spatial_axis, world_inertia};
use crr_kinematics::velocity::{cross_force, cross_motion};
use crr_kinematics::{Data, Model};

/// Workspace and intermediate results of the articulated-body algorithm for one model.
#[derive(Clone, Debug)]
pub struct ArticulatedBody {
    /// sₖ = [wₖ; pₖ × wₖ]: spatial axis of each coordinate.
    pub axis: Vec<Vector6<f64>>,
    /// cₖ = Vₖ ×ₘ sₖq̇ₖ: velocity-product acceleration of each coordinate's joint (rad/s², m/s²).
    pub velocity_product: Vec<Vector6<f64>>,
    /// Iᴬₖ: articulated inertia of the subtree of each coordinate about the origin, after pass 2.
    pub inertia: Vec<Matrix6<f64>>,
    /// pᴬₖ: articulated bias force of the subtree of each coordinate (N m; N), after pass 2.
    pub bias_force: Vec<Vector6<f64>>,
    /// aₖ: spatial acceleration of each coordinate's frame, after pass 3 (including −g_eff).
    pub acceleration: Vec<Vector6<f64>>,
    /// Uₖ = Iᴬₖsₖ.
    u_vec: Vec<Vector6<f64>>,
    /// Dₖ = sₖᵀIᴬₖsₖ.
    d: Vec<f64>,
    /// uₖ = τₖ − sₖᵀpᴬₖ.
    u: Vec<f64>,
    /// Whether each coordinate is locked.
    locked: Vec<bool>,
    /// The bodies moving with coordinate k: `bodies[body_start[k]..body_start[k + 1]]`.
    body_start: Vec<usize>,
    bodies: Vec<usize>,
}

impl ArticulatedBody {
    /// Allocates the workspace for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.dof();
        let mut body_start = vec![0; n + 1];
        for &k in &model.body_coord {
            body_start[k + 1] += 1;
        }
        for k in 0..n {
            body_start[k + 1] += body_start[k];
        }
        let mut bodies = vec![0; model.bodies.len()];
        let mut next = body_start.clone();
        for (b, &k) in model.body_coord.iter().enumerate() {
            bodies[next[k]] = b;
            next[k] += 1;
        }
        Self {
            axis: vec![Vector6::zeros(); n],
            velocity_product: vec![Vector6::zeros(); n],
            inertia: vec![Matrix6::zeros(); n],
            bias_force: vec![Vector6::zeros(); n],
            acceleration: vec![Vector6::zeros(); n],
            u_vec: vec![Vector6::zeros(); n],
            d: vec![0.0; n],
            u: vec![0.0; n],
            locked: vec![false; n],
            body_start,
            bodies,
        }
    }

    /// Solves the forward dynamics M q̈ + h = Q(g_eff) + τ + Σ eₖrₖ with q̈ₖ = 0 for the
    /// coordinates k in `locked`, writing q̈ to `qddot` and the reactions rₖ (N m, in the order of
    /// `locked`) to `reactions`. Requires [`crr_kinematics::forward_kinematics`] in `data`; fills
    /// `data.spatial_velocity` and `data.bias_acceleration` as [`crr_kinematics::velocities`]
    /// does. The model must be an open chain (closure rows are ignored). Returns the first
    /// coordinate (in pass-2 order) whose articulated inertia about its axis Dₖ is not positive,
    /// i.e. a singular mass matrix.
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &mut self,
        model: &Model,
        data: &mut Data,
        qdot: &DVector<f64>,
        g_eff: &Vector3<f64>,
        tau: &DVector<f64>,
        locked: &[usize],
        qddot: &mut DVector<f64>,
        reactions: &mut [f64],
    ) -> Result<(), usize> {
        let n = model.dof();
        debug_assert_eq!(qdot.len(), n);
        debug_assert_eq!(tau.len(), n);
        debug_assert_eq!(qddot.len(), n);
        debug_assert_eq!(reactions.len(), locked.len());
        self.locked.fill(false);
        for &k in locked {
            self.locked[k] = true;
        }
        // Pass 1 (outwards): velocities, velocity-product accelerations; the inertias and bias
        // forces of the bodies moving with each coordinate start its articulated quantities.
        for (k, coord) in model.coords.iter().enumerate() {
            let s = spatial_axis(data, k);
            let sq = s * qdot[k];
            let (vp, ap) = match coord.parent {
                Some(p) => (data.spatial_velocity[p], data.bias_acceleration[p]),
                None => (Vector6::zeros(), Vector6::zeros()),
            };
            let v = vp + sq;
            let c = cross_motion(&v, &sq);
            data.spatial_velocity[k] = v;
            data.bias_acceleration[k] = ap + c;
            self.axis[k] = s;
            self.velocity_product[k] = c;
            // Summed in place (the same operations as into a zero matrix moved there after).
            let inertia = &mut self.inertia[k];
            inertia.fill(0.0);
            let mut momentum = Vector6::zeros();
            for &b in &self.bodies[self.body_start[k]..self.body_start[k + 1]] {
                let body = &model.bodies[b];
                let i_w = world_inertia(body, &data.rot_ops[k]);
                let i_b = body_spatial_inertia(body.mass, &data.com[b], &i_w);
                momentum += i_b * v;
                add_assign(inertia, &i_b);
            }
            self.bias_force[k] = cross_force(&v, &momentum);
        }
        // Pass 2 (inwards): articulated inertias and bias forces. The parent receives
        // Iᵃ = Iᴬ − UUᵀ/D and pᵃ = pᴬ + Iᵃc + Uu/D = pᴬ + Iᴬc + U(u − Uᵀc)/D.
        for k in (0..n).rev() {
            let (head, tail) = self.inertia.split_at_mut(k);
            let ia = &tail[0];
            let c = self.velocity_product[k];
            let ia_c = ia * c;
            let parent = model.coords[k].parent;
            if self.locked[k] {
                if let Some(p) = parent {
                    add_assign(&mut head[p], ia);
                    let f = self.bias_force[k] + ia_c;
                    self.bias_force[p] += f;
                }
                continue;
            }
            let s = self.axis[k];
            let u_vec = ia * s;
            let d = s.dot(&u_vec);
            if !(d > 0.0 && d.is_finite()) {
                return Err(k);
            }
            let u = tau[k] - s.dot(&self.bias_force[k]);
            self.u_vec[k] = u_vec;
            self.d[k] = d;
            self.u[k] = u;
            if let Some(p) = parent {
                let parent_inertia = &mut head[p];
                add_assign(parent_inertia, ia);
                parent_inertia.ger(-1.0 / d, &u_vec, &u_vec, 1.0);
                let f = self.bias_force[k] + ia_c + u_vec * ((u - u_vec.dot(&c)) / d);
                self.bias_force[p] += f;
            }
        }
        // Pass 3 (outwards): accelerations from the base's a₀ = [0; −g_eff].
        let a0 = Vector6::new(0.0, 0.0, 0.0, -g_eff.x, -g_eff.y, -g_eff.z);
        for (k, coord) in model.coords.iter().enumerate() {
            let ap = coord.parent.map_or(a0, |p| self.acceleration[p]);
            let a = ap + self.velocity_product[k];
            if self.locked[k] {
                qddot[k] = 0.0;
                self.acceleration[k] = a;
            } else {
                let qdd = (self.u[k] - self.u_vec[k].dot(&a)) / self.d[k];
                qddot[k] = qdd;
                self.acceleration[k] = a + self.axis[k] * qdd;
            }
        }
        for (r, &k) in reactions.iter_mut().zip(locked) {
            let f = self.inertia[k] * self.acceleration[k] + self.bias_force[k];
            *r = self.axis[k].dot(&f) - tau[k];
        }
        Ok(())
    }
}

/// a += b, element by element (a plain loop over the 36 entries, which the compiler vectorises).
#[inline(always)]
fn add_assign(a: &mut Matrix6<f64>, b: &Matrix6<f64>) {
    for (x, y) in a.as_mut_slice().iter_mut().zip(b.as_slice()) {
        *x += *y;
    }
}

/// Spatial inertia about the world origin of a body of mass m, world centre c and world inertia
/// I_c about its centre: [[I_c + m(|c|²1 − ccᵀ), m[c]×], [−m[c]×, m1]] (the same matrix as
/// [`crr_kinematics::mass_matrix::spatial_inertia`], with −[c]×² = |c|²1 − ccᵀ written out).
#[inline]
fn body_spatial_inertia(mass: f64, c: &Vector3<f64>, i_c: &Matrix3<f64>) -> Matrix6<f64> {
    let mc = c * mass;
    let c2 = c.dot(&mc);
    let mut s = Matrix6::zeros();
    for j in 0..3 {
        for i in 0..3 {
            s[(i, j)] = i_c[(i, j)] - mc[i] * c[j];
        }
        s[(j, j)] += c2;
        s[(j + 3, j + 3)] = mass;
    }
    // m[c]× (upper right) and its transpose −m[c]× (lower left).
    let (x, y, z) = (mc.x, mc.y, mc.z);
    s[(0, 4)] = -z;
    s[(0, 5)] = y;
    s[(1, 3)] = z;
    s[(1, 5)] = -x;
    s[(2, 3)] = -y;
    s[(2, 4)] = x;
    s[(4, 0)] = -z;
    s[(5, 0)] = y;
    s[(3, 1)] = z;
    s[(5, 1)] = -x;
    s[(3, 2)] = -y;
    s[(4, 2)] = x;
    s
}
