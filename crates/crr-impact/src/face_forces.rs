//! The contact forces of a structure in motion, posed on its contact faces: the most compressive
//! distribution of a hyperstatic structure's contact forces as one linear program (the hypotheses
//! monitor's question when the least-norm forces show a tension).
//!
//! **Loads.** At a state whose accelerations are solved, body b needs from its contacts the net
//! force Fᵦ = mᵦ(a_b − g_eff) (its centre's acceleration a_b, the effective gravity g_eff of the
//! ground's frame) and the net moment about its centre of mass Mᵦ = I_b α_b + ω_b × I_b ω_b
//! (Euler; I_b = R I_rest Rᵀ in world axes). The loops and seated joints of a hyperstatic
//! structure hold it more times than its motion needs, so these loads fix a family of contact
//! forces, not one.
//!
//! **Contacts.** Each interface touches on the points of its face ([`crr_kinematics::ContactFace`])
//! that its state keeps closed: a seated angle offers both of its pivots, a rocking one only its
//! current pivot. So a seated hinge touches on its two pivot lines, a rocking hinge on one; a
//! rocking base on one corner (both tilts free), on an edge (one tilt seated) or on its four
//! corners. Each touching point carries f = fₙn + f₁t₁ + f₂t₂ from the parent on the child (the
//! face's axes turned with the parent), unilateral: fₙ ≥ s. A hinge also carries its bilateral
//! couples about n and t₁ (it is a line); a rocking base on one corner the couple about n that its
//! two tilts leave no freedom for (the CRR base does not twist); a seat that may twist carries no
//! torsion, so only its current pivot takes tangential forces. A plain hinge (one pivot line) is
//! a pin: its force is free.
//!
//! **Program.** max s subject to every body's equilibrium Σ f = Fᵦ, Σ (p − c_b) × f + couples = Mᵦ,
//! fₙ ≥ s at every unilateral point, s ≤ 0 (with a small proximal term on the forces,
//! [`PROXIMAL`]). Its optimum s* is the largest smallest normal force
//! any distribution reaches: s* = 0 when a compressive one exists, and s* < 0 is the least tension
//! the motion needs somewhere. One linear program with one global answer, whatever the order of
//! the bodies, interfaces and corners; solved by `clarabel`'s interior point, on the sparse
//! equilibrium of the bodies (six rows each, a few columns per contact point) rather than on the
//! dense self-stress states of the tree coordinates.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::{Matrix3, Vector3};

use crr_dynamics::eom::Dynamics;
use crr_kinematics::kinematics::frame_point;
use crr_kinematics::{ContactFace, InterfaceKind, Model, Parent, Role, Side};

use crate::monitor::ForceWork;

/// Weight ε of the proximal term ½ε‖f‖² added to the program (forces in units of the weight W).
/// It makes the program strictly convex in the forces, so that among the optimal distributions
/// it takes the least-norm one and the interior point's systems stay well conditioned on
/// degenerate optima: without it `clarabel` stopped with a numerical error on the temple near its
/// stop, where the optimal distributions form a wide face. It lowers s* by at most ½ε‖f₀‖² W
/// (f₀ the least-norm optimal forces, ‖f₀‖² of order one in these units): about 1e-7 W, far
/// below the monitor's tolerance of 5e-4 W.
pub const PROXIMAL: f64 = 1e-7;

/// The answer of the program at one state.
#[derive(Clone, Debug, PartialEq)]
pub struct MostCompressive {
    /// s*, the largest smallest normal force at a touching point that any distribution in
    /// equilibrium reaches (N); 0 when a compressive distribution exists.
    pub min_normal: f64,
    /// The interface whose point holds s* with the largest dual price (the contact that limits
    /// it; the lowest index among equals), None when no point is unilateral.
    pub limiting: Option<usize>,
    /// The normal force of every interface under that distribution (N, the sum over its
    /// touching points), in interface order.
    pub normals: Vec<f64>,
}

/// A column of the program: a force along `direction` at `point`, or a couple.
struct Unknown {
    interface: usize,
    /// The point (world, current), None for a couple.
    point: Option<Vector3<f64>>,
    /// Direction (world, current).
    direction: Vector3<f64>,
}

/// The most compressive distribution of the contact forces at the state solved in `dynamics`
/// (its kinematics, seated slots and pivots) with the bodies' accelerations in `work` (from
/// [`crate::monitor::contact_forces_into`] at the same state, general path). None when the
/// program does not solve (the caller then judges the least-norm forces).
pub fn most_compressive(
    model: &Model,
    dynamics: &Dynamics,
    work: &ForceWork,
) -> Option<MostCompressive> {
    if work.acc.len() != model.dof() || work.body_force.len() != model.bodies.len() {
        return None;
    }
    let weight = model.total_mass() * model.gravity;
    let size = model.size;
    let mut is_seated = vec![false; model.slot_count];
    for &k in &dynamics.seated {
        is_seated[k] = true;
    }
    // Columns: 0 is s, then the unknowns; the unilateral points' normal columns listed apart.
    let mut unknowns = Vec::new();
    let mut unilateral = Vec::new();
    for (index, iface) in model.interfaces.iter().enumerate() {
        let face = ContactFace::of_interface(model, index);
        let frame = model.frame_of(iface.parent);
        let rot = frame.map_or_else(Matrix3::identity, |k| dynamics.kin.rot_ops[k]);
        let axes = [
            rot * face.normal,
            rot * face.tangents[0],
            rot * face.tangents[1],
        ];
        let points = touching_points(
            &iface.kind,
            &is_seated[iface.slots.clone()],
            dynamics.pivots.of_interface(model, index),
        );
        let twist = matches!(iface.kind, InterfaceKind::RockingBase { twist: true, .. });
        for (p, rest) in points.iter().enumerate() {
            let point = frame_point(&dynamics.kin, frame, rest);
            let along = if twist && p > 0 {
                &axes[..1]
            } else {
                &axes[..]
            };
            for (k, &direction) in along.iter().enumerate() {
                if k == 0 && !face.pin {
                    unilateral.push(1 + unknowns.len());
                }
                unknowns.push(Unknown {
                    interface: index,
                    point: Some(point),
                    direction,
                });
            }
        }
        let mut couples: Vec<Vector3<f64>> =
            face.bilateral_couples.iter().map(|c| rot * c).collect();
        if !twist && points.len() == 1 && matches!(iface.kind, InterfaceKind::RockingBase { .. }) {
            couples.push(torsion_axis(model, &dynamics.kin, index));
        }
        unknowns.extend(couples.into_iter().map(|direction| Unknown {
            interface: index,
            point: None,
            direction,
        }));
    }
    // Equilibrium: six rows per body (force / W, moment about the centre / W·size).
    let (mut ri, mut ci, mut vi) = (Vec::new(), Vec::new(), Vec::new());
    let mut push = |r: usize, c: usize, v: f64| {
        if v != 0.0 {
            ri.push(r);
            ci.push(c);
            vi.push(v);
        }
    };
    for (j, u) in unknowns.iter().enumerate() {
        let iface = &model.interfaces[u.interface];
        let mut on = |body: usize, sign: f64| {
            let row = 6 * body;
            match u.point {
                Some(p) => {
                    let arm = (p - dynamics.kin.com[body]).cross(&u.direction) / size;
                    for k in 0..3 {
                        push(row + k, 1 + j, sign * u.direction[k]);
                        push(row + 3 + k, 1 + j, sign * arm[k]);
                    }
                }
                None => {
                    for k in 0..3 {
                        push(row + 3 + k, 1 + j, sign * u.direction[k] / size);
                    }
                }
            }
        };
        on(iface.child, 1.0);
        if let Parent::Body(parent) = iface.parent {
            on(parent, -1.0);
        }
    }
    let bodies = model.bodies.len();
    let mut b = vec![0.0; 6 * bodies];
    for (n, body) in model.bodies.iter().enumerate() {
        let k = model.body_coord[n];
        let rot = dynamics.kin.rot_ops[k];
        let inertia = rot * body.inertia * rot.transpose();
        let omega = top(&dynamics.kin.spatial_velocity[k]);
        let alpha = top(&work.acc[k]);
        let moment = inertia * alpha + omega.cross(&(inertia * omega));
        for i in 0..3 {
            b[6 * n + i] = work.body_force[n][i] / weight;
            b[6 * n + 3 + i] = moment[i] / (weight * size);
        }
    }
    // fₙ ≥ s at every unilateral point (s − fₙ ≤ 0), and s ≤ 0.
    let mut row = 6 * bodies;
    for &c in &unilateral {
        push(row, 0, 1.0);
        push(row, c, -1.0);
        row += 1;
    }
    push(row, 0, 1.0);
    row += 1;
    b.resize(row, 0.0);
    let columns = 1 + unknowns.len();
    let a = CscMatrix::new_from_triplets(row, columns, ri, ci, vi);
    let p = CscMatrix::new_from_triplets(
        columns,
        columns,
        (1..columns).collect(),
        (1..columns).collect(),
        vec![PROXIMAL; columns - 1],
    );
    let mut q = vec![0.0; columns];
    q[0] = -1.0;
    let cones = [
        SupportedConeT::ZeroConeT(6 * bodies),
        SupportedConeT::NonnegativeConeT(row - 6 * bodies),
    ];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(200)
        .build()
        .ok()?;
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings).ok()?;
    solver.solve();
    let solution = &solver.solution;
    if !matches!(
        solution.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    ) {
        return None;
    }
    let mut normals = vec![0.0; model.interfaces.len()];
    for &c in &unilateral {
        normals[unknowns[c - 1].interface] += solution.x[c] * weight;
    }
    // The limiting contact: the point row with the largest dual price (ties: lowest interface).
    let mut limiting: Option<(usize, f64)> = None;
    for (r, &c) in unilateral.iter().enumerate() {
        let price = solution.z[6 * bodies + r];
        let interface = unknowns[c - 1].interface;
        if limiting.is_none_or(|(i, best)| price > best || (price == best && interface < i)) {
            limiting = Some((interface, price));
        }
    }
    Some(MostCompressive {
        min_normal: solution.x[0] * weight,
        limiting: limiting.map(|(i, _)| i),
        normals,
    })
}

/// The axis of the couple a rocking base on one corner transmits: the one its two tilts leave no
/// rotation about, w₁ × w₂ of the tilts' world axes (the parent's e₁ turned with the parent, e₂
/// turned with the child: the face's normal only while the first tilt is 0).
fn torsion_axis(model: &Model, kin: &crr_kinematics::Data, index: usize) -> Vector3<f64> {
    let iface = &model.interfaces[index];
    let (w1, w2) = match iface.role {
        Role::Tree { first_coord } => (kin.axis[first_coord], kin.axis[first_coord + 1]),
        Role::Closure { .. } => {
            let rot = |k: Option<usize>| k.map_or_else(Matrix3::identity, |k| kin.rot_ops[k]);
            let child = rot(Some(model.body_coord[iface.child]));
            (
                rot(model.frame_of(iface.parent)) * iface.kind.axis(0),
                child * iface.kind.axis(1),
            )
        }
    };
    w1.cross(&w2).normalize()
}

/// The points (world at rest) on which interface `kind` touches with its slots seated as
/// `seated` and on the pivot sides `sides`: the pivots of every side choice that keeps the free
/// slots' current side (a seated slot offers both), each once.
fn touching_points(kind: &InterfaceKind, seated: &[bool], sides: &[Side]) -> Vec<Vector3<f64>> {
    let choices = |k: usize| {
        if seated[k] {
            vec![Side::Positive, Side::Negative]
        } else {
            vec![sides[k]]
        }
    };
    let mut points: Vec<Vector3<f64>> = Vec::new();
    let mut add = |p: Vector3<f64>| {
        if !points.contains(&p) {
            points.push(p);
        }
    };
    match kind {
        InterfaceKind::Hinge { .. } => {
            for s in choices(0) {
                add(kind.pivot(&[s]));
            }
        }
        InterfaceKind::RockingBase { .. } => {
            // The current pivot first (a twisting seat's tangential forces act there).
            add(kind.pivot(sides));
            for s0 in choices(0) {
                for s1 in choices(1) {
                    add(kind.pivot(&[s0, s1]));
                }
            }
        }
    }
    points
}

fn top(v: &nalgebra::Vector6<f64>) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}
