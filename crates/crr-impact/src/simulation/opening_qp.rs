//! Which seated joints open, to which side, or lift off: Gauss' principle over the contact
//! faces of the seated joints as one convex quadratic program, at any state (in motion too).
//!
//! **Variables.** q̈ (every tree coordinate on the current pivot sides, seated ones included) and,
//! for each seated slot k whose other pivot can be offered, a lift ℓₖ ≥ 0. A seated slot k on
//! side σₖ with axis w through its pivot P, other pivot P′, opens by a rotation about P at the
//! rate αₖ⁺ ≥ 0 (in its sense σₖ) and about P′ at αₖ⁻ ≥ 0 (in the sense −σₖ). At the seat
//! (ψₖ = ψ̇ₖ = 0) a rotation about P′ is the rotation about P plus the translation w × (P − P′)
//! of everything beyond the joint, so the two read
//!
//!   ψ̈ₖ = σₖ(αₖ⁺ − αₖ⁻),  ℓₖ = αₖ⁻,  with the translation τₖℓₖ, τₖ = σₖ w × (P′ − P)
//!
//! (τₖ lies along the face normal, into the child). The constraints αₖ⁺ = σₖψ̈ₖ + ℓₖ ≥ 0 and
//! ℓₖ ≥ 0 are the face's unilateral contacts: on a hinge the cone of its two pivot lines, on a
//! rocking base (two tilts, two lifts) the cone of rotations about its four edges, and every
//! positive combination of both pivots of one slot lifts its face off (both corners open).
//!
//! A face **rocking on one pivot** P (no slot of its interface seated) has one lift ℓ ≥ 0 too,
//! with the translation τ = σ w × (P′ − P) of its first slot (P′ its other pivot, carried by the
//! parent): it turns freely about P, so a rotation about P′ adds only that translation, along the
//! parent's face normal, at any angle. Its row is ℓ ≥ 0 alone; its dual is the pivot's normal
//! force, and the face lifts off where the pivot would have to pull ([`rocking_faces`]).
//!
//! **Objective.** Gauss' function of the bodies' accelerations (Gibbs–Appell): with the tree's
//! part ½q̈ᵀMq̈ − q̈ᵀ(Q − h), plus the lifts' translations of the bodies beyond each seated tree
//! coordinate: Σ_b m_b(a_b − g_eff)·Σ_{k∋b} τₖℓₖ + ½Σ_b m_b |Σ_{k∋b} τₖℓₖ|². A lift of a seated
//! closure angle moves no body: it only relaxes its loop's point rows.
//!
//! **Equalities.** The loops' rows Φ_q q̈ + Φ̇_q q̇ = 0, whose point rows x_A(P) − x_B(P) see each
//! lift: +τₖℓₖ when the closure's parent side is beyond a seated tree coordinate k, −τₖℓₖ for its
//! child side, +τₖℓₖ for the closure's own seated angle (the child turning about P′).
//!
//! The program is convex (a positive semidefinite metric over a polyhedral cone), so its minimum
//! is global and does not depend on how the model is written: no search over sides, and the
//! mechanisms of hyperstatic loops (where held reactions are one split among many) come out of
//! one solve. It is solved by `clarabel`'s interior point; the decision it gives is checked with
//! the chain's own exact solve before it is used ([`super::seating`]).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use crr_dynamics::eom::{Dynamics, slot_row};
use crr_kinematics::kinematics::frame_point;
use crr_kinematics::velocity::point_bias_acceleration;
use crr_kinematics::{InterfaceKind, Model, Side};

use super::seating::other_pivot_rest;

/// Relative size (of g / size) below which an opening rate counts as zero in the program's
/// answer. A rate above it opens only when it also exceeds its contact's force (module
/// `solve`): with the product of the two of the order of the solver's tolerance, the rates
/// that open are in effect above max(1e-7, √(sᵢzᵢ)), some 1e-7 to 1e-6 g / size. A true opening
/// below that grows with the load and is found a moment later, and the answer is checked by the
/// chain's exact solve anyway.
pub const QP_OPENING_TOLERANCE: f64 = 1e-7;

/// Relative size (of the largest rate before an impulse) below which a rate the impulse program
/// gives counts as zero. At an impact most contacts neither carry an impulse nor open (both
/// members of their complementary pair vanish), and there the interior point leaves both of the
/// order of the square root of its tolerance: where the velocities before the impulse already
/// satisfy every contact, the program's answer differs from them by 1e-6 to 1e-4 of the largest
/// rate (the landings of the walls of `examples/wall_pulse.rs`, 2026-11-29).
pub const IMPULSE_OPENING_TOLERANCE: f64 = 1e-3;

/// What the contact program decides at a state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OpeningDecision {
    /// Seated slots that open, with the side of the pivot they turn on.
    pub releases: Vec<(usize, Side)>,
    /// Interfaces whose face opens entirely (every corner leaves its seat): a block lifting off a
    /// support, outside the CRR chain.
    pub lifting_off: Vec<usize>,
    /// The opening rates (αₖ⁺, αₖ⁻) of every seated slot, in the order of `Dynamics::seated`
    /// (rad/s²; αₖ⁻ = 0 where the other pivot is not offered).
    pub rates: Vec<(f64, f64)>,
    /// q̈ of the program's minimum (rad/s²).
    pub qddot: DVector<f64>,
    /// Every seated slot was offered both pivots. When false (a flip that would move a free
    /// slot's axis) the program is the exact one restricted to the
    /// current side of those slots: its "holds" and its releases stand (checked by the chain),
    /// but a lift-off it finds may be an artefact of the restriction.
    pub complete: bool,
}

/// Why the program gave no answer.
#[derive(Clone, Debug, PartialEq)]
pub struct OpeningQpError(pub String);

/// The lift of one seated slot, or of a face rocking on one pivot: its translation τₖ and what
/// it moves.
struct Lift {
    /// Index into `Dynamics::seated`; None for a rocking face's lift.
    seated_index: Option<usize>,
    /// The interface whose face lifts.
    interface: usize,
    /// τₖ = σₖ w × (P′ − P) (m per rad/s² of ℓₖ).
    tau: Vector3<f64>,
    /// A tree coordinate (its subtree translates) or a closure (its point rows relax).
    moves: LiftMoves,
}

enum LiftMoves {
    /// The subtree of this tree coordinate translates.
    Subtree(usize),
    /// The point rows of this closure interface relax.
    Closure(usize),
}

/// Whether the program at the state evaluated in `d` offers every seated slot both of its
/// pivots ([`OpeningDecision::complete`]), known before it is solved.
pub fn offers_both_pivots(model: &Model, d: &Dynamics) -> bool {
    let mut is_seated = vec![false; model.slot_count];
    for &k in &d.seated {
        is_seated[k] = true;
    }
    lifts(model, d, &is_seated).len() == d.seated.len()
}

/// Solves the contact program at the state evaluated in `d` ([`Dynamics::evaluate`] with the
/// current pivots and seated slots: M, h, Q, Φ_q, Φ̇_q q̇, the frames and velocities).
pub fn opening_qp(model: &Model, d: &Dynamics) -> Result<OpeningDecision, OpeningQpError> {
    opening_qp_holding(model, d, &[])
}

/// [`opening_qp`] with the faces listed in `held` (interfaces) kept on their pivots: their lifts
/// are left out (a lift-off the chain without the face contradicted, a face that ties, or a
/// flight the chain's exact solve finds early, which the simulation keeps closed until the next
/// impact, landing or change of chain).
pub fn opening_qp_holding(
    model: &Model,
    d: &Dynamics,
    held: &[usize],
) -> Result<OpeningDecision, OpeningQpError> {
    program(model, d, held, Level::Acceleration)
}

/// The same program one level down, for an impulse: over q̇⁺ and the lifts' rates, Gauss'
/// principle of impulsive motion ½(V⁺ − V⁻)ᵀ𝓜(V⁺ − V⁻) over the bodies (Moreau's perfectly
/// inelastic impact), with the loops' rows Φ_q q̇⁺ = 0 and every seated slot's and rocking
/// face's contacts unilateral (αₖ⁺ ≥ 0, ℓₖ ≥ 0, now rates; no bias terms). `d` is evaluated at
/// the impulse's positions (its pivots and the slots the impulse holds seated); `qdot_minus`
/// are the velocities before it on the same chain (an impulse that switches no pivot, as a
/// landing's: across a pivot switch the momentum before is J⁺ᵀ𝕄J⁻q̇⁻, not M q̇⁻). Its releases
/// and lift-offs are contacts that leave at the impulse: where it finds any, no distribution
/// of compressive impulses over the contacts (without sliding) gives the plastic impulse that
/// holds them all, which then pulls somewhere. The simulation sizes that tension with the
/// contact points' linear program (`simulation::landing_check`), whose verdict agrees with this
/// one (its unit test).
pub fn impulse_qp(
    model: &Model,
    d: &Dynamics,
    qdot_minus: &DVector<f64>,
) -> Result<OpeningDecision, OpeningQpError> {
    program(model, d, &[], Level::Velocity(qdot_minus))
}

/// What the contact program is posed on.
#[derive(Clone, Copy)]
enum Level<'a> {
    /// q̈ at the state evaluated (loads, velocity products and bias terms).
    Acceleration,
    /// q̇⁺ after an impulse, from these velocities before it.
    Velocity(&'a DVector<f64>),
}

/// The contact program at `level` ([`opening_qp_holding`], [`impulse_qp`]).
fn program(
    model: &Model,
    d: &Dynamics,
    held: &[usize],
    level: Level,
) -> Result<OpeningDecision, OpeningQpError> {
    let n = model.dof();
    let kin = &d.kin;
    let mut is_seated = vec![false; model.slot_count];
    for &k in &d.seated {
        is_seated[k] = true;
    }
    let mut lifts = lifts(model, d, &is_seated);
    let complete = lifts.len() == d.seated.len();
    lifts.extend(rocking_lifts(model, d, &is_seated, held));
    let nv = n + lifts.len();
    let scale = Scale::of(model, level);
    let momentum = match level {
        Level::Acceleration => None,
        Level::Velocity(v) => Some(&kin.mass_matrix * v),
    };

    // Objective ½xᵀPx + cᵀx (upper triangle of P).
    let mut p = DMatrix::<f64>::zeros(nv, nv);
    let mut c = DVector::<f64>::zeros(nv);
    for i in 0..n {
        for j in i..n {
            p[(i, j)] = kin.mass_matrix[(i, j)];
        }
        c[i] = match &momentum {
            None => kin.velocity_product[i] - d.load[i],
            Some(m) => -m[i],
        };
    }
    add_lift_metric(model, d, &lifts, level, &mut p, &mut c);
    let biased = matches!(level, Level::Acceleration);

    // Rows: Ax + s = b, s in the zero cone (loops) then the non-negative cone (openings).
    let rows = model.constraint_rows;
    let mut a = DMatrix::<f64>::zeros(rows + d.seated.len() + lifts.len(), nv);
    let mut b = DVector::<f64>::zeros(a.nrows());
    let row_scale = d.row_scale();
    for r in 0..rows {
        for j in 0..n {
            a[(r, j)] = row_scale[r] * kin.phi_q[(r, j)];
        }
        if biased {
            b[r] = -row_scale[r] * kin.phi_bias[r];
        }
    }
    for (l, lift) in lifts.iter().enumerate() {
        for cl in &model.closures {
            let share = match lift.moves {
                LiftMoves::Subtree(k) => {
                    let closing = &model.interfaces[cl.interface];
                    let beyond = |f: Option<usize>| f64::from(u8::from(model.carries(k, f)));
                    beyond(model.frame_of(closing.parent))
                        - beyond(Some(model.body_coord[closing.child]))
                }
                LiftMoves::Closure(i) => f64::from(u8::from(i == cl.interface)),
            };
            for r in 0..3 {
                a[(cl.first_row + r, n + l)] = row_scale[cl.first_row + r] * share * lift.tau[r];
            }
        }
    }
    // αₖ⁺ = σₖ(rowₖ·q̈ + biasₖ) + ℓₖ ≥ 0, then ℓₖ ≥ 0.
    let mut slot = DVector::zeros(n);
    let mut rate_rows = Vec::with_capacity(d.seated.len());
    for (i, &k) in d.seated.iter().enumerate() {
        let bias = slot_row(model, kin, k, &mut slot);
        let bias = if biased { bias } else { 0.0 };
        let sigma = d.pivots.sides[k].sign();
        let r = rows + i;
        for j in 0..n {
            a[(r, j)] = -sigma * slot[j];
        }
        b[r] = sigma * bias;
        rate_rows.push((slot.clone(), bias));
    }
    for (l, lift) in lifts.iter().enumerate() {
        if let Some(i) = lift.seated_index {
            a[(rows + i, n + l)] = -1.0;
        }
        a[(rows + d.seated.len() + l, n + l)] = -1.0;
    }

    let solution = solve(
        &scale.apply(p, c, a, b),
        rows,
        d.seated.len() + lifts.len(),
        &scale,
    )?;
    let mut decision = decide(model, d, &lifts, &rate_rows, &solution, &scale, held);
    decision.complete = complete;
    Ok(decision)
}

/// The units of the program: rates in g / size, Gauss' function in m_total g² size⁰.
struct Scale {
    /// g / size (rad/s²).
    rate: f64,
    /// Σ m size² (kg m²).
    inertia: f64,
    /// The rate above which a contact opens (rad/s² or rad/s).
    opening: f64,
}

/// The scaled program's matrices.
struct Scaled {
    p: DMatrix<f64>,
    c: DVector<f64>,
    a: DMatrix<f64>,
    b: DVector<f64>,
}

impl Scale {
    /// Accelerations in g / size; velocities in the largest rate before the impulse.
    fn of(model: &Model, level: Level) -> Self {
        let mass: f64 = model.bodies.iter().map(|b| b.mass).sum();
        let natural = model.gravity / model.size;
        let (rate, opening) = match level {
            Level::Acceleration => (natural, QP_OPENING_TOLERANCE * natural),
            Level::Velocity(v) => {
                let rate = v.amax().max(1e-9 * natural.sqrt());
                (rate, IMPULSE_OPENING_TOLERANCE * rate)
            }
        };
        Self {
            rate,
            opening,
            inertia: mass * model.size * model.size,
        }
    }

    /// x = rate·x̂: ½x̂ᵀ(P/I)x̂ + (c/(I·rate))ᵀx̂ over Ax̂ + ŝ = b/rate.
    fn apply(&self, p: DMatrix<f64>, c: DVector<f64>, a: DMatrix<f64>, b: DVector<f64>) -> Scaled {
        Scaled {
            p: p / self.inertia,
            c: c / (self.inertia * self.rate),
            a,
            b: b / self.rate,
        }
    }
}

/// The lifts offered: every seated slot at its seat whose other pivot turns no free
/// coordinate's axis (a rocking base's other tilt moves its corner along that tilt's axis,
/// which is fine), twisting seats included.
fn lifts(model: &Model, d: &Dynamics, is_seated: &[bool]) -> Vec<Lift> {
    let mut lifts = Vec::new();
    for (i, &k) in d.seated.iter().enumerate() {
        let Some(index) = model.interfaces.iter().position(|f| f.slots.contains(&k)) else {
            continue;
        };
        let iface = &model.interfaces[index];
        let sigma = d.pivots.sides[k].sign();
        let Some(moves) = lift_moves(model, index, k) else {
            continue;
        };
        let w = world_axis(model, d, index, k);
        let (pivot, other) = pivot_pair(model, d, index, k);
        // The other pivot must lie on the axis line of every free slot of the interface (a
        // rocking base's other tilt: flipping one tilt moves the corner along the other's
        // axis), or the flip would change that slot's motion too.
        let moves_free = iface.slots.clone().any(|j| {
            j != k
                && !is_seated[j]
                && world_axis(model, d, index, j)
                    .cross(&(other - pivot))
                    .norm()
                    > 1e-12 * model.size
        });
        if moves_free {
            continue;
        }
        lifts.push(Lift {
            seated_index: Some(i),
            interface: index,
            tau: sigma * w.cross(&(other - pivot)),
            moves,
        });
    }
    lifts
}

/// The lifts of the faces that rock on one pivot (every slot of the interface free, none
/// seated): one per face, along its normal. A face rocking on P turns freely about P, so a
/// rotation about its other pivot P′ (on the parent) adds only the translation
/// τ = σ w × (P′ − P) of the child side (slot k the interface's first, w its axis, σ its side):
/// the face leaving P along the parent's normal, at any angle, as at the seat. Its contact holds
/// while the pivot's normal force is compressive; the program lifts it off where that force
/// would have to pull. Plain hinges (one pivot line, τ = 0) have no lift.
fn rocking_lifts(model: &Model, d: &Dynamics, is_seated: &[bool], held: &[usize]) -> Vec<Lift> {
    rocking_faces(model, d, is_seated, held)
        .filter_map(|(index, k, tau)| {
            Some(Lift {
                seated_index: None,
                interface: index,
                tau,
                moves: lift_moves(model, index, k)?,
            })
        })
        .collect()
}

/// What a lift of slot k of interface `index` moves: the subtree of a tree coordinate, or the
/// point rows of a loop closure; None for neither.
fn lift_moves(model: &Model, index: usize, k: usize) -> Option<LiftMoves> {
    if k < model.dof() {
        Some(LiftMoves::Subtree(k))
    } else if model.closures.iter().any(|c| c.interface == index) {
        Some(LiftMoves::Closure(index))
    } else {
        None
    }
}

/// The current pivot P of interface `index` and its other pivot P′ with slot k flipped, both
/// carried by the parent (world).
fn pivot_pair(model: &Model, d: &Dynamics, index: usize, k: usize) -> (Vector3<f64>, Vector3<f64>) {
    let iface = &model.interfaces[index];
    let parent = model.frame_of(iface.parent);
    let pivot = frame_point(
        &d.kin,
        parent,
        &iface.kind.pivot(d.pivots.of_interface(model, index)),
    );
    let other = frame_point(&d.kin, parent, &other_pivot_rest(iface, &d.pivots, k));
    (pivot, other)
}

/// The faces that rock on one pivot and can lift ([`rocking_lifts`]), but those in `held`:
/// (interface, its first slot k, τ = σ w × (P′ − P)).
pub(super) fn rocking_faces<'m>(
    model: &'m Model,
    d: &'m Dynamics,
    is_seated: &'m [bool],
    held: &'m [usize],
) -> impl Iterator<Item = (usize, usize, Vector3<f64>)> + 'm {
    model
        .interfaces
        .iter()
        .enumerate()
        .filter_map(move |(index, iface)| {
            if iface.slots.is_empty()
                || iface.slots.clone().any(|k| is_seated[k])
                || held.contains(&index)
            {
                return None;
            }
            let k = iface.slots.start;
            lift_moves(model, index, k)?;
            let (pivot, other) = pivot_pair(model, d, index, k);
            let tau =
                d.pivots.sides[k].sign() * world_axis(model, d, index, k).cross(&(other - pivot));
            (tau.norm() > 1e-9 * model.size).then_some((index, k, tau))
        })
}

/// Adds the lifts' terms of Gauss' function: per body b, a_b = Σⱼ (wⱼ × (c_b − pⱼ)) q̈ⱼ + bias_b
/// plus the translations τₖℓₖ of the lifted tree coordinates k that carry it (seated slots, and
/// the first slots of faces rocking on one pivot).
fn add_lift_metric(
    model: &Model,
    d: &Dynamics,
    lifts: &[Lift],
    level: Level,
    p: &mut DMatrix<f64>,
    c: &mut DVector<f64>,
) {
    let kin = &d.kin;
    let n = model.dof();
    let g_eff = d.effective_gravity();
    let mut carrying = Vec::with_capacity(lifts.len());
    for (b, body) in model.bodies.iter().enumerate() {
        let frame = model.body_coord[b];
        carrying.clear();
        carrying.extend(
            lifts
                .iter()
                .enumerate()
                .filter_map(|(l, lift)| match lift.moves {
                    LiftMoves::Subtree(k) if model.carries(k, Some(frame)) => Some(l),
                    _ => None,
                }),
        );
        if carrying.is_empty() {
            continue;
        }
        let m = body.mass;
        let com = kin.com[b];
        // What the lifts' translations are measured against: the acceleration the body would
        // have from the load and the motion alone, or its velocity before the impulse.
        let free = match level {
            Level::Acceleration => g_eff - point_bias_acceleration(kin, Some(frame), &com),
            Level::Velocity(v) => {
                let mut velocity = Vector3::zeros();
                let mut j = Some(frame);
                while let Some(jj) = j {
                    velocity += kin.axis[jj].cross(&(com - kin.pivot[jj])) * v[jj];
                    j = model.coords[jj].parent;
                }
                velocity
            }
        };
        for (x, &l) in carrying.iter().enumerate() {
            let tau = lifts[l].tau;
            c[n + l] -= m * tau.dot(&free);
            for &l2 in &carrying[x..] {
                let (lo, hi) = (l.min(l2), l.max(l2));
                p[(n + lo, n + hi)] += m * tau.dot(&lifts[l2].tau);
            }
            let mut j = Some(frame);
            while let Some(jj) = j {
                p[(jj, n + l)] += m * tau.dot(&kin.axis[jj].cross(&(com - kin.pivot[jj])));
                j = model.coords[jj].parent;
            }
        }
    }
}

/// The interior point's tolerance on the gap and the residuals of the scaled program. At its
/// end every complementary pair has sᵢzᵢ of the order of the gap over the rows. On the 6 × 6
/// wall under its pulse (`examples/wall_pulse.rs 6 1.5`), pairs with both members above 1e-7:
/// 1105 with 1e-9 (1417 solves, all Solved); 429 with 1e-11 (all Solved, one or two
/// iterations more); with 1e-12 clarabel stopped short (AlmostSolved) in 29 of 1336 solves.
const SOLVER_TOLERANCE: f64 = 1e-11;

/// The program's minimum: x (unscaled, rad/s²) and, for each inequality row (the seated slots'
/// αₖ⁺ rows, then the lifts' ℓₖ rows), whether the interior point holds it.
struct Solution {
    x: DVector<f64>,
    held: Vec<bool>,
}

/// The interior point on the scaled program.
///
/// Which contacts hold is read from the complementary pairs (slack sᵢ, the row's rate in g/size;
/// dual zᵢ, its contact's moment in W·size). The interior point ends with sᵢzᵢ of the order of
/// its tolerance on every row, so a contact that carries a force keeps a small slack rate: with
/// a tolerance of 1e-9, the 6 × 6 wall under its pulse had 583 rows with rates above
/// `QP_OPENING_TOLERANCE` whose forces were 1e-4 to 1e-6 W (products sᵢzᵢ from 3e-13 to 6e-10).
/// Read against the tolerance alone, such rows opened joints and lifted faces that the static
/// theorem holds (the faces' program proved margins of 6e-4 W there). A row holds when
/// zᵢ ≥ sᵢ, the indicator of the active set of interior points (El-Bakry, Tapia and Zhang
/// 1994): both are of order one in these units, and the converged member of a pair is the
/// larger.
fn solve(
    s: &Scaled,
    equalities: usize,
    inequalities: usize,
    scale: &Scale,
) -> Result<Solution, OpeningQpError> {
    let nv = s.p.ncols();
    let p = dense_to_csc(&s.p, true);
    let a = dense_to_csc(&s.a, false);
    let mut cones = Vec::with_capacity(2);
    if equalities > 0 {
        cones.push(SupportedConeT::ZeroConeT(equalities));
    }
    if inequalities > 0 {
        cones.push(SupportedConeT::NonnegativeConeT(inequalities));
    }
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .tol_gap_abs(SOLVER_TOLERANCE)
        .tol_gap_rel(SOLVER_TOLERANCE)
        .tol_feas(SOLVER_TOLERANCE)
        .tol_ktratio(1e-7)
        .max_iter(200)
        .build()
        .map_err(|e| OpeningQpError(format!("{e:?}")))?;
    let b: Vec<f64> = s.b.iter().copied().collect();
    let c: Vec<f64> = s.c.iter().copied().collect();
    let mut solver = DefaultSolver::new(&p, &c, &a, &b, &cones, settings)
        .map_err(|e| OpeningQpError(format!("{e:?}")))?;
    solver.solve();
    match solver.solution.status {
        status @ (SolverStatus::Solved | SolverStatus::AlmostSolved) => {
            let (slack, dual) = (&solver.solution.s, &solver.solution.z);
            // An answer only almost solved (clarabel's reduced tolerances, a gap up to 5e-5)
            // leaves pairs whose product is too large to read: its rates decide alone.
            let solved = status == SolverStatus::Solved;
            Ok(Solution {
                x: DVector::from_iterator(nv, solver.solution.x.iter().map(|x| x * scale.rate)),
                held: (equalities..equalities + inequalities)
                    .map(|r| solved && dual[r] >= slack[r])
                    .collect(),
            })
        }
        other => Err(OpeningQpError(format!("{other:?}"))),
    }
}

/// A dense matrix as clarabel's compressed columns (its upper triangle when `upper`).
fn dense_to_csc(m: &DMatrix<f64>, upper: bool) -> CscMatrix<f64> {
    let (mut rows, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..m.ncols() {
        let last = if upper { j + 1 } else { m.nrows() };
        for i in 0..last {
            if m[(i, j)] != 0.0 {
                rows.push(i);
                cols.push(j);
                vals.push(m[(i, j)]);
            }
        }
    }
    CscMatrix::new_from_triplets(m.nrows(), m.ncols(), rows, cols, vals)
}

/// Reads the program's minimum: each seated slot's (αₖ⁺, αₖ⁻), and from them, interface by
/// interface, what opens. A face with one seated slot opens on the side whose rate is positive,
/// and lifts off when both are; a rocking base with both tilts seated is read from the normal
/// accelerations of its four pivot corners (its two lifts are parallel translations, so their
/// split is not unique): the corners that stay down name the pivot (two: an edge, the tilt
/// across it turns; one: both tilts; none: the base lifts off). A seated face in `held_faces`
/// (one whose lift-off tied: its blocks did not move without it, docs/simulation.md, "Faces
/// that open") does not lift off: it holds, so that the answer can turn back to "holds" and
/// the uplift event fire again for the other joints.
fn decide(
    model: &Model,
    d: &Dynamics,
    lifts: &[Lift],
    rate_rows: &[(DVector<f64>, f64)],
    solution: &Solution,
    scale: &Scale,
    held_faces: &[usize],
) -> OpeningDecision {
    let n = model.dof();
    let x = &solution.x;
    let qddot = x.rows(0, n).into_owned();
    let mut lift_of = vec![0.0; d.seated.len()];
    // Whether the interior point holds each seated slot's pivot (αₖ⁺) and other pivot (ℓₖ; held
    // where it is not offered).
    let mut held: Vec<(bool, bool)> = solution.held[..d.seated.len()]
        .iter()
        .map(|&h| (h, true))
        .collect();
    // A rocking face lifts off where its lift is not held and exceeds the tolerance.
    let mut rocking_off = Vec::new();
    for (l, lift) in lifts.iter().enumerate() {
        let held_here = solution.held[d.seated.len() + l];
        match lift.seated_index {
            Some(i) => {
                lift_of[i] = x[n + l].max(0.0);
                held[i].1 = held_here;
            }
            None => {
                if !held_here && x[n + l] > scale.opening {
                    rocking_off.push(lift.interface);
                }
            }
        }
    }
    let rates: Vec<(f64, f64)> = d
        .seated
        .iter()
        .enumerate()
        .map(|(i, &k)| {
            let (row, bias) = &rate_rows[i];
            let psi = row.dot(&qddot) + bias;
            (d.pivots.sides[k].sign() * psi + lift_of[i], lift_of[i])
        })
        .collect();
    let tol = scale.opening;
    let mut decision = OpeningDecision {
        rates: rates.clone(),
        qddot,
        lifting_off: rocking_off,
        ..OpeningDecision::default()
    };
    // The rates as read: a held row's rate is the interior point's round-off, read as 0.
    let opening = |i: usize| {
        let plus = if held[i].0 { 0.0 } else { rates[i].0 };
        let minus = if held[i].1 { 0.0 } else { rates[i].1 };
        (plus, minus)
    };
    for (index, iface) in model.interfaces.iter().enumerate() {
        let seated: Vec<usize> = d
            .seated
            .iter()
            .enumerate()
            .filter(|(_, k)| iface.slots.contains(k))
            .map(|(i, _)| i)
            .collect();
        match seated[..] {
            [] => {}
            [i] => {
                let k = d.seated[i];
                let side = d.pivots.sides[k];
                let (plus, minus) = opening(i);
                match (plus > tol, minus > tol) {
                    (true, true) if held_faces.contains(&index) => {}
                    (true, true) => decision.lifting_off.push(index),
                    (true, false) => decision.releases.push((k, side)),
                    (false, true) => decision.releases.push((k, side.flipped())),
                    (false, false) => {}
                }
            }
            // A base whose every row is held has every corner down: it holds.
            _ => match base_decision(model, d, index, &seated, opening, tol) {
                BaseMotion::LiftsOff if held_faces.contains(&index) => {}
                motion => motion.apply(index, &mut decision),
            },
        }
    }
    decision.lifting_off.sort_unstable();
    decision
}

/// What a rocking base with both tilts seated does.
enum BaseMotion {
    Holds,
    Turns(Vec<(usize, Side)>),
    LiftsOff,
}

impl BaseMotion {
    fn apply(self, index: usize, decision: &mut OpeningDecision) {
        match self {
            BaseMotion::Holds => {}
            BaseMotion::Turns(r) => decision.releases.extend(r),
            BaseMotion::LiftsOff => decision.lifting_off.push(index),
        }
    }
}

/// The normal accelerations of a seated base's four pivot corners under the program's motion
/// (the child's relative to the parent: Σ ψ̈ⱼ wⱼ × (C − P) + Σ τₗℓₗ, along the face normal), and the
/// corners that stay down. `opening(i)` is the seated slot i's (αᵢ⁺, αᵢ⁻) as read (a held row's
/// rate as 0), from which ψ̈ᵢ = σᵢ(αᵢ⁺ − αᵢ⁻) and ℓᵢ = αᵢ⁻.
fn base_decision(
    model: &Model,
    d: &Dynamics,
    index: usize,
    seated: &[usize],
    opening: impl Fn(usize) -> (f64, f64),
    tol: f64,
) -> BaseMotion {
    let kin = &d.kin;
    let iface = &model.interfaces[index];
    let InterfaceKind::RockingBase { normal, .. } = &iface.kind else {
        return BaseMotion::Holds;
    };
    let parent = model.frame_of(iface.parent);
    let rot = parent.map_or_else(Matrix3::identity, |f| kin.rot_ops[f]);
    let n_world = rot * normal;
    let current = d.pivots.of_interface(model, index).to_vec();
    let pivot = frame_point(kin, parent, &iface.kind.pivot(&current));
    let mut turn = Vector3::zeros();
    let mut lift = Vector3::zeros();
    for &i in seated {
        let k = d.seated[i];
        let sigma = d.pivots.sides[k].sign();
        let (plus, minus) = opening(i);
        let w = world_axis(model, d, index, k);
        turn += w * (sigma * (plus - minus));
        let other = frame_point(kin, parent, &other_pivot_rest(iface, &d.pivots, k));
        lift += sigma * w.cross(&(other - pivot)) * minus;
    }
    let down: Vec<[Side; 2]> = [Side::Positive, Side::Negative]
        .into_iter()
        .flat_map(|a| [Side::Positive, Side::Negative].map(|b| [a, b]))
        .filter(|sides| {
            let corner = frame_point(kin, parent, &iface.kind.pivot(sides));
            n_world.dot(&(turn.cross(&(corner - pivot)) + lift)) <= tol * model.size
        })
        .collect();
    let (k1, k2) = (iface.slots.start, iface.slots.start + 1);
    match down[..] {
        [] => BaseMotion::LiftsOff,
        [[s1, s2]] => BaseMotion::Turns(vec![(k1, s1), (k2, s2)]),
        // An edge: the corners share one tilt's side, and the other tilt's axis runs along it.
        [[a1, a2], [b1, b2]] if a2 == b2 && a1 != b1 => BaseMotion::Turns(vec![(k2, a2)]),
        [[a1, a2], [b1, b2]] if a1 == b1 && a2 != b2 => BaseMotion::Turns(vec![(k1, a1)]),
        _ => BaseMotion::Holds,
    }
}

/// The world axis of slot k of interface `index`: a tree coordinate's own; a closure's first tilt
/// (or hinge axis) on the parent; its second tilt about R(e₁, θ₁)e₂ = n_B × e₁.
fn world_axis(model: &Model, d: &Dynamics, index: usize, k: usize) -> Vector3<f64> {
    let kin = &d.kin;
    if k < model.dof() {
        return kin.axis[k];
    }
    let iface = &model.interfaces[index];
    let rot = |f: Option<usize>| f.map_or_else(Matrix3::identity, |f| kin.rot_ops[f]);
    match &iface.kind {
        InterfaceKind::Hinge { axis, .. } => rot(model.frame_of(iface.parent)) * axis,
        InterfaceKind::RockingBase { e1, normal, .. } => {
            let e1 = rot(model.frame_of(iface.parent)) * e1;
            if k == iface.slots.start {
                e1
            } else {
                // The second tilt turns about R(e₁, θ₁)e₂, perpendicular to e₁ and to the
                // child's face normal: n_B × e₁ (the child's own e₂ only without a twist).
                (rot(Some(model.body_coord[iface.child])) * normal)
                    .cross(&e1)
                    .normalize()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crr_dynamics::ground_motion::GroundMotion;
    use crr_kinematics::closure::relative_angles;
    use crr_kinematics::fixtures::colonnade_with_top_order;
    use crr_kinematics::{ActivePivots, Parent};
    use nalgebra::Rotation3;

    /// The tilt angles (θ₁, θ₂) after turning the child by ε about `w` (world) through any point.
    fn tilts_after(
        kind: &InterfaceKind,
        ra: &Matrix3<f64>,
        rb: &Matrix3<f64>,
        w: &Vector3<f64>,
        eps: f64,
    ) -> [f64; 2] {
        let turn = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(*w), eps);
        let rel = ra.transpose() * turn.matrix() * rb;
        let mut out = [0.0; 2];
        relative_angles(kind, &rel, &mut out);
        out
    }

    /// The axis the program gives a seat's tilt is the one about which turning the child changes
    /// that tilt alone (central differences of the angles measured from the poses), also on a
    /// seat that has twisted: a colonnade whose tops tilt in the same order as its bases twists
    /// its slab on them (second order in the columns' tilts), and there the child's own e₂ is
    /// not the second tilt's axis (it changes θ₁ by about the twist per radian).
    #[test]
    fn a_twisting_seats_tilt_axes_change_one_tilt_each() {
        let mut spec = colonnade_with_top_order(0.2, 1.5, 1.2, 0.4, false);
        let mut closing = 0;
        for iface in spec.interface.iter_mut().filter(|i| i.child == "slab") {
            closing += 1;
            if closing > 1 {
                iface.rocking_base.as_mut().unwrap().twist = true;
            }
        }
        let model = Model::from_spec(&spec).unwrap();
        let n = model.dof();
        // Every column tilted about x and y, the slab's own tilts chosen to leave it twisted.
        let mut q = DVector::zeros(n);
        for k in 0..n {
            q[k] = 0.03 * (1.0 + 0.37 * k as f64).sin();
        }
        let mut d = Dynamics::new(&model, ActivePivots::uniform(&model, Side::Positive));
        d.evaluate(&model, &GroundMotion::none(), 0.0, &q, &DVector::zeros(n));
        let kin = &d.kin;
        let rot = |f: Option<usize>| f.map_or_else(Matrix3::identity, |f| kin.rot_ops[f]);
        let mut largest_twist_error: f64 = 0.0;
        let mut checked = 0;
        for cl in &model.closures {
            let iface = &model.interfaces[cl.interface];
            if !matches!(iface.kind, InterfaceKind::RockingBase { twist: true, .. }) {
                continue;
            }
            let parent = match iface.parent {
                Parent::Ground => None,
                Parent::Body(b) => Some(model.body_coord[b]),
            };
            let (ra, rb) = (rot(parent), rot(Some(model.body_coord[iface.child])));
            let eps = 1e-6;
            for (local, k) in iface.slots.clone().enumerate() {
                let w = world_axis(&model, &d, cl.interface, k);
                let plus = tilts_after(&iface.kind, &ra, &rb, &w, eps);
                let minus = tilts_after(&iface.kind, &ra, &rb, &w, -eps);
                for j in 0..2 {
                    let rate = (plus[j] - minus[j]) / (2.0 * eps);
                    let expected = if j == local { 1.0 } else { 0.0 };
                    assert!(
                        (rate - expected).abs() < 1e-8,
                        "{} slot {local}: dθ{j}/dε = {rate}",
                        iface.name
                    );
                }
                checked += 1;
            }
            // The child's own e₂ is off by the twist.
            let e2_child = rb * iface.kind.axis(1);
            let plus = tilts_after(&iface.kind, &ra, &rb, &e2_child, 1e-6);
            let minus = tilts_after(&iface.kind, &ra, &rb, &e2_child, -1e-6);
            largest_twist_error = largest_twist_error.max(((plus[0] - minus[0]) / 2e-6).abs());
        }
        assert_eq!(checked, 6, "three twisting seats, two tilts each");
        assert!(
            largest_twist_error > 1e-5,
            "the seats have not twisted ({largest_twist_error}): the check would not discriminate"
        );
    }
}
