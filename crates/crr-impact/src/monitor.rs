//! The hypotheses monitor: the force every contact transmits, its normal part N (must stay
//! compressive: no flight) and the friction demand |F_t|/N (must stay below μ: no sliding).
//!
//! The force that a tree interface transmits from its parent to the child side is the rate of
//! change of momentum of the child's subtree minus the loads on it (weight and ground-motion
//! pseudo-force, m g_eff) minus the closure forces reaching the subtree from outside:
//! f = Σ m (a_c − g_eff) − Σ f_closure. A closure interface transmits the force of its point
//! multipliers (−λ on the child). N = f·n with n the contact normal (towards the child: for a hinge
//! with two pivot lines n ∝ u × (P⁻ − P⁺); for a rocking base its normal), rotated with the parent.
//! Plain hinges (one pivot line) are joints that can hold tension and are not monitored.
//!
//! A seated slot also carries a moment about its pivot line: its seat reaction r (the
//! generalized force holding it, N m). With the normal force N of its face split between the
//! edge through the current pivot P and the edge through the other pivot P′, the far edge's share
//! is r/s, s = (w × (P′ − P))·n the moment about P's line (axis w) of a unit normal force on P′'s
//! line, and the near edge's N − r/s ([`SeatEdges`]). The contact's resultant lies within its face
//! exactly when both are compressive: a negative far share means the joint should have opened
//! about P, a negative near share that it should rock about P′. The split is exact when the slot's
//! axis lies in the face's plane (a hinge, a rocking base's first tilt, both tilts seated); for a
//! second tilt seated while the first rocks by θ₁ its axis leaves the plane by θ₁, and r also holds
//! sin θ₁ times the face's torsion and the moment of its tangential forces, which the split
//! neglects (an error of order θ₁ in the edge forces).

use nalgebra::{DMatrix, DVector, Matrix3, Vector3, Vector6};
use serde::Serialize;

use crr_dynamics::DynamicsError;
use crr_dynamics::eom::{Dynamics, effective_gravity, slot_row};
use crr_dynamics::ground_motion::GroundMotion;
use crr_kinematics::{InterfaceKind, Model, Role};

/// The force a contact transmits to its child side.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ContactForce {
    /// Force on the child side, world axes (N).
    pub force: [f64; 3],
    /// Normal component N (N); negative is tension.
    pub normal: f64,
    /// Tangential magnitude |F_t| (N).
    pub tangential: f64,
}

impl ContactForce {
    /// The force `force` on the child side split along the unit contact normal `normal`.
    fn new(force: Vector3<f64>, normal: Vector3<f64>) -> Self {
        let nf = force.dot(&normal);
        Self {
            force: force.into(),
            normal: nf,
            tangential: (force - normal * nf).norm(),
        }
    }

    /// |F_t|/N (infinite when N ≤ 0).
    pub fn friction_demand(&self) -> f64 {
        if self.normal > 0.0 {
            self.tangential / self.normal
        } else {
            f64::INFINITY
        }
    }
}

/// The normal force of a seated slot's face split between the edges through its two pivots (the
/// two pivot lines of a hinge; for a rocking base's tilt, the edge through the pivot corner along
/// the tilt's axis and the parallel edge through the other corner).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SeatEdges {
    /// Interface index.
    pub interface: usize,
    /// The slot (a tree coordinate, or a closure angle).
    pub slot: usize,
    /// Normal force on the edge through the current pivot P (N); negative: the joint would need
    /// tension there, it should rock about the other pivot.
    pub near: f64,
    /// Normal force on the edge through the other pivot P′ (N); negative: the joint should have
    /// opened about P.
    pub far: f64,
    /// Its index in `Dynamics::seated`.
    pub seated_index: usize,
    /// The arm s = (w × (P′ − P))·n (m) that splits it.
    pub arm: f64,
}

/// The first failure of a hypothesis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Violation {
    /// Time (s).
    pub t: f64,
    /// Interface name.
    pub interface: String,
    /// `"tension"` (N < 0: flight), `"outside_face"` (a seated joint's resultant beyond an edge of
    /// its face: one of its edges would pull, the joint should rock), `"sliding"` (|F_t| > μN),
    /// `"lift_off"` (recorded by the simulation, not the monitor: a face the contact program
    /// lifts off, that the chain without it drives back into its support, while with it closed
    /// no release the engine tries opens; `normal` is then 0 and `friction_demand` infinite: no
    /// force is computed), or `"impulse_tension"` (recorded by the simulation at a landing whose
    /// plastic impulse needs tension: `normal` is the least normal impulse of the most
    /// compressive distribution, N s, and `friction_demand` infinite), or `"sliding_unloaded"`
    /// (recorded by the simulation at rest: the load exceeds a mechanism in which this joint
    /// slides while keeping contact, carrying nothing, which the CRR chain cannot follow, so it
    /// holds by shear with no compression; `normal` 0, `friction_demand` infinite).
    pub kind: String,
    /// N at that time (N); for `"outside_face"` the normal force of the edge that would pull;
    /// for `"impulse_tension"` an impulse (N s).
    pub normal: f64,
    /// |F_t|/N at that time.
    pub friction_demand: f64,
    /// For a `"tension"` at a face rocking on a pivot that alone carries the bodies above it,
    /// pulling where a segment starts (just after an impact): that pull measured by the motion
    /// with the face released (`simulation::Hop`); None otherwise.
    pub hop: Option<Box<crate::simulation::Hop>>,
}

impl Violation {
    /// Whether this violation is graver than `other` (two found at one instant): a tension
    /// (flight) before a resultant outside a face, that before a slide, and those before the
    /// kinds the simulation records itself (`lift_off`, `impulse_tension`); within a kind the
    /// most negative force (for a slide, the largest friction demand |F_t|/N); then the
    /// interface name that sorts first. The order of the interfaces in the model file plays no
    /// part.
    pub fn graver_than(&self, other: &Violation) -> bool {
        let key = |v: &Violation| match v.kind.as_str() {
            "tension" => (0, v.normal),
            "outside_face" => (1, v.normal),
            "sliding" => (2, -v.friction_demand),
            _ => (3, 0.0),
        };
        let ((rank, severity), (other_rank, other_severity)) = (key(self), key(other));
        rank.cmp(&other_rank)
            .then(severity.total_cmp(&other_severity))
            .then_with(|| self.interface.cmp(&other.interface))
            .is_lt()
    }
}

fn top(v: &Vector6<f64>) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}
fn bottom(v: &Vector6<f64>) -> Vector3<f64> {
    Vector3::new(v[3], v[4], v[5])
}

/// Unit contact normal of an interface at rest (None for a plain hinge).
fn rest_normal(kind: &InterfaceKind, size: f64) -> Option<Vector3<f64>> {
    match kind {
        InterfaceKind::Hinge {
            axis,
            pivot_positive,
            pivot_negative,
        } => {
            let lift = axis.cross(&(pivot_negative - pivot_positive));
            (lift.norm() > 1e-9 * size).then(|| lift.normalize())
        }
        InterfaceKind::RockingBase { normal, .. } => Some(*normal),
    }
}

/// Contact forces of every interface at (t, q, q̇) with the dynamics' pivots and seated slots
/// (None for plain hinges). Solves the accelerations first.
pub fn contact_forces(
    model: &Model,
    dynamics: &mut Dynamics,
    ground: &GroundMotion,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Result<Vec<Option<ContactForce>>, DynamicsError> {
    let mut work = ForceWork::default();
    contact_forces_into(model, dynamics, ground, t, q, qdot, &mut work)?;
    Ok(work.forces)
}

/// Buffers of [`contact_forces_into`], reused from call to call (a simulation samples the contact
/// forces at every output sample).
#[derive(Clone, Debug, Default)]
pub struct ForceWork {
    /// Total spatial acceleration of every coordinate's frame (left empty by the
    /// one-coordinate path).
    pub(crate) acc: Vec<Vector6<f64>>,
    /// Net force of every body beyond its load, m (a_c − g_eff).
    pub(crate) body_force: Vec<Vector3<f64>>,
    /// Point forces of the closures on their two sides: (frame, force on it).
    closure_on: Vec<(Option<usize>, Vector3<f64>)>,
    /// Force and contact normal of every interface (None for plain hinges).
    transmitted: Vec<Option<(Vector3<f64>, Vector3<f64>)>>,
    /// The contact forces of the last call, in interface order.
    pub forces: Vec<Option<ContactForce>>,
    /// The split of the seated slots' normal forces between their edges, in the order of
    /// `Dynamics::seated` (slots of plain hinges left out).
    pub edges: Vec<SeatEdges>,
}

/// [`contact_forces`] into reused buffers: the forces are left in `work.forces`.
pub fn contact_forces_into(
    model: &Model,
    dynamics: &mut Dynamics,
    ground: &GroundMotion,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    work: &mut ForceWork,
) -> Result<(), DynamicsError> {
    // One body on one coordinate: the force in closed form, with θ̈ from the kinematics of the
    // state (Q/I_p, or 0 when the joint is seated; M is not needed).
    if let [_] = q.as_slice()
        && let ([_], [_]) = (&model.bodies[..], &model.interfaces[..])
        && let Some(solved) = dynamics.single_coordinate_accelerations(model, ground, t, q)
    {
        solved?;
        let (g_eff, qddot) = (dynamics.effective_gravity(), dynamics.qddot[0]);
        one_body_force(model, &mut dynamics.kin, g_eff, qddot, qdot[0], work);
        seat_edges(model, dynamics, &work.forces, &mut work.edges);
        return Ok(());
    }
    dynamics.accelerations(model, ground, t, q, qdot)?;
    body_loads_into(model, dynamics, effective_gravity(model, ground, t), work);
    interface_forces(
        model,
        &dynamics.kin,
        &work.body_force,
        &dynamics.lambda,
        &mut work.closure_on,
        &mut work.transmitted,
    );
    work.forces.clear();
    work.forces.extend(
        work.transmitted
            .iter()
            .map(|f| f.map(|(force, normal)| ContactForce::new(force, normal))),
    );
    seat_edges(model, dynamics, &work.forces, &mut work.edges);
    Ok(())
}

/// The loads every body needs from its contacts at the state solved in `dynamics` (its q̈ and
/// kinematics), under the effective gravity `g_eff`: each coordinate frame's total spatial
/// acceleration into `work.acc` and each body's net force beyond its load, m (a_c − g_eff), into
/// `work.body_force` (what [`crate::face_forces`] poses its programs on).
pub fn body_loads_into(
    model: &Model,
    dynamics: &Dynamics,
    g_eff: Vector3<f64>,
    work: &mut ForceWork,
) {
    let kin = &dynamics.kin;
    let n = model.dof();
    // Total spatial accelerations A = A_bias + Σ sⱼ q̈ⱼ along each path.
    let acc = &mut work.acc;
    acc.clear();
    for k in 0..n {
        let s = crr_kinematics::mass_matrix::spatial_axis(kin, k) * dynamics.qddot[k];
        let parent = model.coords[k]
            .parent
            .map_or(Vector6::zeros(), |p| acc[p] - kin.bias_acceleration[p]);
        acc.push(kin.bias_acceleration[k] + parent + s);
    }
    // Net force on each body beyond its load: m (a_c − g_eff).
    work.body_force.clear();
    work.body_force
        .extend(model.bodies.iter().enumerate().map(|(b, body)| {
            let k = model.body_coord[b];
            let (w, v0) = (
                top(&kin.spatial_velocity[k]),
                bottom(&kin.spatial_velocity[k]),
            );
            let (al, a0) = (top(&acc[k]), bottom(&acc[k]));
            let c = kin.com[b];
            let a_c = a0 + al.cross(&c) + w.cross(&(v0 + w.cross(&c)));
            (a_c - g_eff) * body.mass
        }));
}

/// World axis w, current pivot P and other pivot P′ of seated slot `slot` at the state of `kin`,
/// and its interface's index (the axis of `slot_row`: a hinge's and a first tilt's on the parent,
/// a second tilt's on the child; a twisting base's tilts are those of the face normal, whose axes
/// are the parent's e₁, e₂ while the other tilt is 0 and lean by that tilt otherwise: the parent's
/// are taken, within the split's order-θ error, module docs).
fn slot_pivot_lines(
    model: &Model,
    kin: &crr_kinematics::Data,
    pivots: &crr_kinematics::ActivePivots,
    slot: usize,
) -> (usize, Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let index = crate::simulation::slot_interface(model, slot);
    let iface = &model.interfaces[index];
    let other_rest = crate::simulation::other_pivot_rest(iface, pivots, slot);
    if slot < model.dof() {
        let parent = model.coords[slot].parent;
        let other = crr_kinematics::kinematics::frame_point(kin, parent, &other_rest);
        return (index, kin.axis[slot], kin.pivot[slot], other);
    }
    let parent = model.frame_of(iface.parent);
    let rot = |k: Option<usize>| k.map_or_else(Matrix3::identity, |k| kin.rot_ops[k]);
    let component = slot - iface.slots.start;
    let w = match &iface.kind {
        InterfaceKind::Hinge { axis, .. } => rot(parent) * axis,
        InterfaceKind::RockingBase {
            e1,
            e2,
            twist: true,
            ..
        } => rot(parent) * if component == 0 { e1 } else { e2 },
        InterfaceKind::RockingBase { e1, e2, .. } => {
            if component == 0 {
                rot(parent) * e1
            } else {
                rot(Some(model.body_coord[iface.child])) * e2
            }
        }
    };
    let current = iface.kind.pivot(pivots.of_interface(model, index));
    let point = |x: &Vector3<f64>| crr_kinematics::kinematics::frame_point(kin, parent, x);
    (index, w, point(&current), point(&other_rest))
}

/// The split of every seated slot's normal force between the edges through its two pivots
/// ([`SeatEdges`]) from its seat reaction and its interface's contact force, into `edges`.
fn seat_edges(
    model: &Model,
    dynamics: &Dynamics,
    forces: &[Option<ContactForce>],
    edges: &mut Vec<SeatEdges>,
) {
    edges.clear();
    if dynamics.seat_reactions.len() != dynamics.seated.len() {
        return;
    }
    for (i, &slot) in dynamics.seated.iter().enumerate() {
        let Some((interface, arm)) = seat_arm(model, dynamics, slot) else {
            continue;
        };
        let Some(force) = forces[interface] else {
            continue;
        };
        let far = dynamics.seat_reactions[i] / arm;
        edges.push(SeatEdges {
            interface,
            slot,
            near: force.normal - far,
            far,
            seated_index: i,
            arm,
        });
    }
}

/// The interface of seated slot `slot` and its arm s = (w × (P′ − P))·n (m): the moment about
/// the current pivot's line of a unit normal force on the other pivot's line. None for plain
/// hinges (no face) and faces of no width.
fn seat_arm(model: &Model, dynamics: &Dynamics, slot: usize) -> Option<(usize, f64)> {
    let kin = &dynamics.kin;
    let (interface, w, p, p_other) = slot_pivot_lines(model, kin, &dynamics.pivots, slot);
    let iface = &model.interfaces[interface];
    let n_rest = rest_normal(&iface.kind, model.size)?;
    let parent_rot = model
        .frame_of(iface.parent)
        .map_or_else(Matrix3::identity, |k| kin.rot_ops[k]);
    let arm = w.cross(&(p_other - p)).dot(&(parent_rot * n_rest));
    (arm.abs() > 1e-9 * model.size).then_some((interface, arm))
}

/// [`contact_forces_into`] for a structure of one coordinate with θ̈ solved and the frames of
/// the state in `kin`: one body on one interface to the ground (every interface adds a
/// coordinate and there is no closure), turning with ω = θ̇w, α = θ̈w about the pivot line (w, p)
/// fixed in the world. The ground transmits the body's net force beyond its load,
/// F = m (a_c − g_eff) with a_c = α × r + ω × (ω × r), r = c − p: the general assembly's spatial
/// algebra for one body, without its buffers. Also sets the body's spatial velocity
/// V = [w; p × w] θ̇ (as [`crr_kinematics::velocities`] does), which the energies of a sample read.
fn one_body_force(
    model: &Model,
    kin: &mut crr_kinematics::Data,
    g_eff: Vector3<f64>,
    theta_ddot: f64,
    theta_dot: f64,
    work: &mut ForceWork,
) {
    kin.spatial_velocity[0] = crr_kinematics::mass_matrix::spatial_axis(kin, 0) * theta_dot;
    let (body, iface) = (&model.bodies[0], &model.interfaces[0]);
    let (w, r) = (kin.axis[0], kin.com[0] - kin.pivot[0]);
    let a_c = w.cross(&r) * theta_ddot + w.cross(&w.cross(&r)) * (theta_dot * theta_dot);
    let force = (a_c - g_eff) * body.mass;
    work.forces.clear();
    work.forces
        .push(rest_normal(&iface.kind, model.size).map(|normal| ContactForce::new(force, normal)));
}

/// The force each monitored interface transmits to its child side, with its contact normal
/// (world axes), from the bodies' net forces beyond their loads (`body_force`) and the closure
/// multipliers `lambda` (the point force λ of a closure acts on its parent side, −λ on its
/// child side); None for plain hinges. Written to `out`; `closure_on` is a buffer.
fn interface_forces(
    model: &Model,
    kin: &crr_kinematics::Data,
    body_force: &[Vector3<f64>],
    lambda: &DVector<f64>,
    closure_on: &mut Vec<(Option<usize>, Vector3<f64>)>,
    out: &mut Vec<Option<(Vector3<f64>, Vector3<f64>)>>,
) {
    let point_force = |first_row: usize| {
        Vector3::new(
            lambda[first_row],
            lambda[first_row + 1],
            lambda[first_row + 2],
        )
    };
    closure_on.clear();
    for cl in &model.closures {
        let iface = &model.interfaces[cl.interface];
        let lam = point_force(cl.first_row);
        closure_on.push((model.frame_of(iface.parent), lam));
        closure_on.push((Some(model.body_coord[iface.child]), -lam));
    }
    let in_subtree = |frame: Option<usize>, root: usize| model.carries(root, frame);
    out.clear();
    out.extend(model.interfaces.iter().map(|iface| {
        let n_rest = rest_normal(&iface.kind, model.size)?;
        let parent_rot = model
            .frame_of(iface.parent)
            .map_or_else(nalgebra::Matrix3::identity, |k| kin.rot_ops[k]);
        let normal = parent_rot * n_rest;
        let force = match iface.role {
            Role::Tree { first_coord } => {
                let mut f = Vector3::zeros();
                for (b, fb) in body_force.iter().enumerate() {
                    if in_subtree(Some(model.body_coord[b]), first_coord) {
                        f += fb;
                    }
                }
                for (frame, fc) in closure_on.iter() {
                    if in_subtree(*frame, first_coord) {
                        f -= fc;
                    }
                }
                f
            }
            Role::Closure { index } => -point_force(model.closures[index].first_row),
        };
        Some((force, normal))
    }));
}

/// How the monitored normal forces change along the self-stress states of a hyperstatic
/// structure (None when it has none, or no loops): column j holds the change of every
/// interface's normal force (rows in interface order, 0 for plain hinges), then of each seated
/// slot's edge forces (far, near) in the order of `edges` ([`SeatEdges`], from
/// [`contact_forces_into`] at the same state), under the j-th state.
///
/// A structure whose loops and seated joints hold it more times than its motion needs (a bay of
/// columns under one entablature, an arch at rest) has multipliers λ and seat reactions that the
/// motion does not determine: any (λ, r) + K ν with Bᵀ K = 0, B the rows of the closures and the
/// seated slots, gives the same accelerations. The solver returns the least-norm set, one
/// distribution among them; a tension in it is no flight if another distribution is compressive
/// ([`check`]).
pub fn self_stress_normals(
    model: &Model,
    dynamics: &Dynamics,
    edges: &[SeatEdges],
) -> Option<DMatrix<f64>> {
    if model.constraint_rows == 0 {
        return None;
    }
    let kin = &dynamics.kin;
    let n = model.dof();
    let rows = model.constraint_rows + dynamics.seated.len();
    // Rows normalised for the rank decision (B' = S B); λ = S λ' maps the null space back.
    let mut bt = DMatrix::zeros(n, rows);
    let mut scale = vec![0.0; rows];
    let mut row = DVector::zeros(n);
    for i in 0..rows {
        if i < model.constraint_rows {
            row.copy_from(&kin.phi_q.row(i).transpose());
        } else {
            slot_row(
                model,
                kin,
                dynamics.seated[i - model.constraint_rows],
                &mut row,
            );
        }
        let norm = row.norm();
        if norm > 0.0 {
            scale[i] = 1.0 / norm;
            bt.column_mut(i).copy_from(&(&row * scale[i]));
        }
    }
    let states = crr_dynamics::linalg::null_space(&bt);
    if states.ncols() == 0 {
        return None;
    }
    // The arm of every edge split, by slot.
    let zero = vec![Vector3::zeros(); model.bodies.len()];
    let (mut closure_on, mut transmitted) = (Vec::new(), Vec::new());
    let interfaces = model.interfaces.len();
    let mut d = DMatrix::zeros(interfaces + 2 * edges.len(), states.ncols());
    for j in 0..states.ncols() {
        let lambda = DVector::from_fn(model.constraint_rows, |i, _| states[(i, j)] * scale[i]);
        interface_forces(
            model,
            kin,
            &zero,
            &lambda,
            &mut closure_on,
            &mut transmitted,
        );
        for (i, f) in transmitted.iter().enumerate() {
            if let Some((force, normal)) = f {
                d[(i, j)] = force.dot(normal);
            }
        }
        for (e, edge) in edges.iter().enumerate() {
            let r = model.constraint_rows + edge.seated_index;
            let far = states[(r, j)] * scale[r] / edge.arm;
            d[(interfaces + 2 * e, j)] = far;
            d[(interfaces + 2 * e + 1, j)] = d[(edge.interface, j)] - far;
        }
    }
    Some(d)
}

/// A pivot's normal force counts as tension (flight) below −TENSION_TOLERANCE W, W the
/// structure's weight: a tension of a thousandth of the weight is within what the rigid-contact
/// idealisation resolves (the drum column's pivots dip to −2e-4 W at impact instants), and the
/// onset of a real flight grows past it within a sample (the arch under a 2.4 g pulse: −2e-3 W
/// at its first sample beyond with 1 ms samples, −5e-3 W with 10 ms).
pub const TENSION_TOLERANCE: f64 = 1e-3;

/// The gravest violation among the given contact forces and seated edges at time t (`judge`,
/// [`Violation::graver_than`]): tension, then a resultant outside the face, then sliding when μ
/// is given, whatever the order of the interfaces. A tension smaller than `tolerance` (N) is
/// round-off, not flight.
///
/// With `self_stress` ([`self_stress_normals`]) a tension counts only if no distribution of the
/// hyperstatic forces is compressive: the nearest change ν of the least-norm one with every
/// normal force and every edge force N + Dν ≥ −tolerance/2 is sought by least-distance
/// programming, and when it exists the tests read the forces of N + Dν; the sliding test keeps
/// the given tangential forces (the self-stress states' tangential parts are not sought: their
/// friction demand is an estimate, only made when the least-norm forces show a tension).
pub fn check(
    model: &Model,
    forces: &[Option<ContactForce>],
    edges: &[SeatEdges],
    self_stress: Option<&DMatrix<f64>>,
    t: f64,
    friction: Option<f64>,
    tolerance: f64,
) -> Option<Violation> {
    check_from(
        model,
        forces,
        edges,
        self_stress,
        t,
        friction,
        tolerance,
        &mut None,
    )
}

/// [`check`] starting from the self-stress change `correction` of a previous call: when it still
/// makes every force ≥ −3/4 of the tolerance it is kept (no program is solved: a structure at
/// rest, or one whose forces barely changed between samples), otherwise the least-distance
/// program gives the new one, left in `correction` (None when there is none, or when its solver
/// fails: then the least-norm forces are judged, and a failure they show is reported). States
/// with another number of rows than the forces and edges given are not used.
#[allow(clippy::too_many_arguments)]
pub fn check_from(
    model: &Model,
    forces: &[Option<ContactForce>],
    edges: &[SeatEdges],
    self_stress: Option<&DMatrix<f64>>,
    t: f64,
    friction: Option<f64>,
    tolerance: f64,
    correction: &mut Option<DVector<f64>>,
) -> Option<Violation> {
    let tension = forces
        .iter()
        .any(|f| f.is_some_and(|f| f.normal < -tolerance))
        || edges
            .iter()
            .any(|e| e.near < -tolerance || e.far < -tolerance);
    // The forces of the compressive distribution, when one is needed and exists (no buffer when
    // there is no tension: the forces' own are read): every interface's normal force, then
    // (far, near) of each edge split.
    let mut values: Vec<f64> = Vec::new();
    if tension {
        values.extend(forces.iter().map(|f| f.map_or(0.0, |f| f.normal)));
        values.extend(edges.iter().flat_map(|e| [e.far, e.near]));
    }
    if let (Some(d), true) = (self_stress.filter(|d| d.nrows() == values.len()), tension) {
        let monitored: Vec<usize> = (0..forces.len())
            .filter(|&i| forces[i].is_some())
            .chain(forces.len()..values.len())
            .collect();
        let g = DMatrix::from_fn(monitored.len(), d.ncols(), |r, c| d[(monitored[r], c)]);
        let h = DVector::from_fn(monitored.len(), |r, _| {
            -0.5 * tolerance - values[monitored[r]]
        });
        // A previous correction is kept while it leaves every force ≥ −3/4 of the tolerance
        // (the interior point meets its rows only to its accuracy: an active row of the last
        // answer may sit a hair below −tolerance/2).
        let holds =
            |nu: &DVector<f64>| nu.len() == g.ncols() && (&g * nu - &h).min() >= -0.25 * tolerance;
        if !correction.as_ref().is_some_and(holds) {
            *correction = crate::least_distance::least_distance(&g, &h);
        }
        if let Some(nu) = correction.as_ref() {
            let dv = &g * nu;
            for (r, &i) in monitored.iter().enumerate() {
                values[i] += dv[r];
            }
        }
    }
    judge(model, forces, edges, &values, t, friction, tolerance)
}

/// The hypotheses check of a hyperstatic structure at the state solved in `dynamics`, with its
/// least-norm forces and the bodies' accelerations in `work` ([`contact_forces_into`]): a
/// tension counts only if no distribution of the contact forces on the faces in equilibrium with
/// the motion keeps every touching point above −tolerance/2, each point's force measured per
/// edge ([`crate::face_forces::most_compressive`]); it is then reported on the contact that limits
/// the distribution, as `"tension"` when its normal force is negative and `"outside_face"` when
/// only some of its points pull. Sliding is judged on the given tangential forces against μ times
/// the normal forces of the compressive distribution. When the program does not solve, the
/// self-stress states of the tree coordinates decide ([`check`] with [`self_stress_normals`]).
pub fn check_distribution(
    model: &Model,
    dynamics: &Dynamics,
    work: &ForceWork,
    t: f64,
    friction: Option<f64>,
    tolerance: f64,
) -> Option<Violation> {
    let best = crate::face_forces::most_compressive(model, dynamics, work);
    judge_distribution(model, dynamics, work, best, t, friction, tolerance)
}

/// The cap, in tolerances, on the least point force the monitor's program seeks in a run
/// (s ≤ 10 tolerances = 1e-2 W, as the uplift test's certificate,
/// [`crate::face_forces::PRESSING_CAP`]). The cap decides no violation: one needs s* below
/// −tolerance/2, where a cap above 0 is not active. It decides how far a distribution can be
/// carried to the next samples: with tolerance/2 (5e-4 W), the 10 × 10 wall of
/// `examples/wall_pulse.rs` under 1.2 λ g solved 21 programs in 3 s, with distributions whose
/// least force is in fact 8e-4 to 2.5e-3 W; with this cap, 12.
pub const DISTRIBUTION_ROOM: f64 = 10.0;

/// [`check_distribution`] in a simulation: the program's answers at rest are carried from
/// sample to sample in `faces` ([`crate::face_forces::RestFaces`]: the last distribution, moved
/// with the change of the effective gravity `g_eff`, answers while every point keeps more than
/// −tolerance/4 measured per edge, which cannot be a violation); the program keeps a margin of up to
/// [`DISTRIBUTION_ROOM`] times the tolerance where it can, so that its distribution is carried
/// over many samples before it needs the program again.
#[allow(clippy::too_many_arguments)]
pub fn check_distribution_at(
    faces: &mut crate::face_forces::RestFaces,
    model: &Model,
    dynamics: &Dynamics,
    work: &ForceWork,
    (q, qdot): (&DVector<f64>, &DVector<f64>),
    g_eff: Vector3<f64>,
    t: f64,
    friction: Option<f64>,
    tolerance: f64,
) -> Option<Violation> {
    let bounds = (-0.25 * tolerance, DISTRIBUTION_ROOM * tolerance);
    let best = faces.most_compressive(model, dynamics, work, q, qdot, g_eff, bounds);
    judge_distribution(model, dynamics, work, best, t, friction, tolerance)
}

/// The violation [`check_distribution`] reads from the program's answer `best`; when there is
/// none (the program did not solve), the tree-coordinate family decides: the least-norm forces
/// and the self-stress states ([`self_stress_normals`], [`check`]).
fn judge_distribution(
    model: &Model,
    dynamics: &Dynamics,
    work: &ForceWork,
    best: Option<crate::face_forces::MostCompressive>,
    t: f64,
    friction: Option<f64>,
    tolerance: f64,
) -> Option<Violation> {
    let (forces, edges) = (&work.forces, &work.edges);
    let Some(best) = best else {
        let states = self_stress_normals(model, dynamics, edges);
        return check(
            model,
            forces,
            edges,
            states.as_ref(),
            t,
            friction,
            tolerance,
        );
    };
    if best.min_normal < -0.5 * tolerance {
        let i = best.limiting?;
        let normal = best.normals[i];
        let (kind, reported) = if normal < 0.0 {
            ("tension", normal)
        } else {
            ("outside_face", best.min_normal)
        };
        return Some(Violation {
            t,
            interface: model.interfaces[i].name.clone(),
            kind: kind.into(),
            normal: reported,
            friction_demand: forces[i].map_or(f64::INFINITY, |f| f.friction_demand()),
            hop: None,
        });
    }
    // Compressive: every edge split reads as its smallest point force (at most 0).
    let mut values = best.normals;
    values.extend(edges.iter().flat_map(|_| [best.min_normal.min(0.0); 2]));
    judge(model, forces, edges, &values, t, friction, tolerance)
}

/// A `"sliding"` verdict of [`check`] or [`check_distribution_at`] on a structure with loops,
/// settled: there the contact forces are not fixed by the motion, and the verdict read the
/// tangential forces of one distribution (the least-norm one) against the normal forces of
/// another, so it may report a slide that another distribution does not need (an independent
/// review, 2026-12-06: the bundled baldachin at rest with μ = 0.1, "needs friction |F_t|/N =
/// 0.0395 above μ"). One cone program decides ([`crate::face_forces::least_friction`]): None
/// where some compressive distribution keeps every contact within the cone of μ; otherwise the
/// slide at the contact that the least-friction distribution loads most, its `friction_demand`
/// the least μ any distribution needs. Other verdicts, a tree's (its contacts' resultants are
/// the subtrees' own) and a verdict whose program does not solve pass unchanged.
pub fn settle_sliding(
    model: &Model,
    dynamics: &Dynamics,
    work: &ForceWork,
    found: Option<Violation>,
    friction: Option<f64>,
    tolerance: f64,
) -> Option<Violation> {
    let (Some(v), Some(mu)) = (found.as_ref(), friction) else {
        return found;
    };
    if v.kind != "sliding" || model.constraint_rows == 0 {
        return found;
    }
    match crate::face_forces::least_friction(model, dynamics, work, mu, tolerance) {
        Some(crate::face_forces::FrictionNeed::Holds) => None,
        // The contact the least-friction distribution loads most; the first verdict's where
        // none is read (no μ up to the largest tried, or no contact carrying more than the
        // tolerance).
        Some(crate::face_forces::FrictionNeed::Slides { least, limiting }) => {
            let (interface, normal) = limiting.map_or_else(
                || (v.interface.clone(), v.normal),
                |(i, normal, _)| (model.interfaces[i].name.clone(), normal),
            );
            Some(Violation {
                interface,
                normal,
                friction_demand: least,
                ..v.clone()
            })
        }
        None => found,
    }
}

/// The gravest violation among the forces and edges, read from `values` where it has them (every
/// interface's normal force, then (far, near) of each edge split: a distribution other than the
/// given one), from the given forces otherwise. Each contact's own failure is its tension, else
/// a resultant outside its face, else sliding (the given tangential force against μ times the
/// normal force read); of the contacts that fail, the gravest by [`Violation::graver_than`], so
/// that the contact reported does not depend on the order in which the file lists the
/// interfaces.
pub(crate) fn judge(
    model: &Model,
    forces: &[Option<ContactForce>],
    edges: &[SeatEdges],
    values: &[f64],
    t: f64,
    friction: Option<f64>,
    tolerance: f64,
) -> Option<Violation> {
    let value = |i: usize, given: f64| values.get(i).copied().unwrap_or(given);
    let mut gravest: Option<Violation> = None;
    for (i, f) in forces.iter().enumerate() {
        let Some(f) = f else { continue };
        let normal = value(i, f.normal);
        let outside = edges
            .iter()
            .enumerate()
            .filter(|(_, e)| e.interface == i)
            .map(|(e, edge)| {
                let far = value(forces.len() + 2 * e, edge.far);
                let near = value(forces.len() + 2 * e + 1, edge.near);
                far.min(near)
            })
            .fold(f64::INFINITY, f64::min);
        let (kind, reported) = if normal < -tolerance {
            ("tension", normal)
        } else if outside < -tolerance {
            ("outside_face", outside)
        } else if friction.is_some_and(|mu| f.tangential > mu * normal.max(0.0) + tolerance) {
            ("sliding", normal)
        } else {
            continue;
        };
        // A slide's demand is the ratio its test read: the given tangential force over the
        // normal force of the distribution judged (above μ by the test).
        let friction_demand = if kind == "sliding" && normal > 0.0 {
            f.tangential / normal
        } else {
            f.friction_demand()
        };
        let v = Violation {
            t,
            interface: model.interfaces[i].name.clone(),
            kind: kind.into(),
            normal: reported,
            friction_demand,
            hop: None,
        };
        if gravest.as_ref().is_none_or(|g| v.graver_than(g)) {
            gravest = Some(v);
        }
    }
    gravest
}

#[cfg(test)]
mod tests {
    use super::*;
    use crr_kinematics::fixtures::serial_chain;

    fn force(normal: f64, tangential: f64) -> Option<ContactForce> {
        Some(ContactForce {
            force: [tangential, 0.0, normal],
            normal,
            tangential,
        })
    }

    /// Which contact `judge` reports depends on the forces, not on where the interfaces stand:
    /// of the chain's three interfaces j0, j1, j2, each failing set is judged in every one of its
    /// orders (the forces permuted with the names). Two tensions: the more negative (−8 N against
    /// −5 N). A tension against a slide of any size and a resultant outside a face: the tension. A
    /// face outside against a slide: the face. Two slides with μ = 0.5: the larger friction
    /// demand |F_t|/N (3/1 against 9/10). Two equal tensions: the name that sorts first.
    #[test]
    fn the_gravest_failure_is_reported_whatever_the_order() {
        let model = Model::from_spec(&serial_chain(3)).unwrap();
        let names: Vec<String> = model.interfaces.iter().map(|i| i.name.clone()).collect();
        let tolerance = 1e-3;
        // (normal, tangential, least edge force) of three contacts, and what must be reported.
        type Contacts = [(f64, f64, f64); 3];
        let cases: [(Contacts, (usize, &str, f64)); 5] = [
            (
                [(-5.0, 0.0, 1.0), (-8.0, 0.0, 1.0), (10.0, 0.0, 1.0)],
                (1, "tension", -8.0),
            ),
            (
                [(10.0, 90.0, 1.0), (10.0, 0.0, -50.0), (-2.0, 0.0, 1.0)],
                (2, "tension", -2.0),
            ),
            (
                [(10.0, 90.0, 1.0), (10.0, 0.0, -0.5), (10.0, 0.0, 1.0)],
                (1, "outside_face", -0.5),
            ),
            (
                [(1.0, 3.0, 1.0), (10.0, 9.0, 1.0), (10.0, 0.0, 1.0)],
                (0, "sliding", 1.0),
            ),
            (
                [(-4.0, 0.0, 1.0), (10.0, 0.0, 1.0), (-4.0, 0.0, 1.0)],
                (0, "tension", -4.0),
            ),
        ];
        let orders = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        for (contacts, (expected, kind, normal)) in cases {
            for order in orders {
                // Interface i of the model carries contact order[i].
                let forces: Vec<Option<ContactForce>> = order
                    .iter()
                    .map(|&c| force(contacts[c].0, contacts[c].1))
                    .collect();
                let edges: Vec<SeatEdges> = order
                    .iter()
                    .enumerate()
                    .map(|(i, &c)| SeatEdges {
                        interface: i,
                        slot: i,
                        near: contacts[c].2,
                        far: 2.0,
                        seated_index: i,
                        arm: 0.1,
                    })
                    .collect();
                let v = judge(&model, &forces, &edges, &[], 0.0, Some(0.5), tolerance)
                    .expect("a violation");
                // The name that contact `expected` has in this order; equal tensions go to the
                // first name among those that carry them.
                let carriers: Vec<&String> = order
                    .iter()
                    .zip(&names)
                    .filter(|&(&c, _)| contacts[c] == contacts[expected])
                    .map(|(_, name)| name)
                    .collect();
                let first = carriers.iter().min().unwrap();
                assert_eq!(&&v.interface, first, "{kind} in order {order:?}");
                assert_eq!(v.kind, kind, "order {order:?}");
                assert_eq!(v.normal, normal, "order {order:?}");
            }
        }
    }
}
