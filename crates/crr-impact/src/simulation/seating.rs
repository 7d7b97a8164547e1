//! Seating and uplift: the opening mode of seated joints (a small complementarity problem solved
//! by single releases and an active set), releasing them, and seating joints that come to rest.

use super::open_loops::FaceRelease;
use super::*;
use crr_kinematics::kinematics::frame_point;
use crr_kinematics::{ContactFace, Interface};
use nalgebra::{Matrix3, Vector3};

/// Finds the interfaces that open from a seated state at (t, q, q̇): releasing a seated slot on a
/// side must give it an opening acceleration on that side. First every single release is tried
/// (the strongest opening wins); if none opens and the structure has loops, all seated slots are
/// released together and their sides adjusted to the signs of their accelerations (an active-set
/// iteration that finds one-DOF mechanisms such as a trilithon's or an arch's). Returns the slots
/// to release with their sides, or None when the seated state holds.
pub fn opening_mode(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Option<Vec<(usize, Side)>> {
    let mut trial = template.clone();
    let parts = model.parts();
    opening_mode_in(
        model,
        ground,
        template,
        &mut trial,
        &mut RestCache::default(),
        &parts.of_slot,
        t,
        q,
        qdot,
    )
}

/// [`opening_mode`] with a workspace: `trial` is any [`Dynamics`] of the same model (its pivots
/// and seated slots are overwritten), so that the uplift test at every step allocates no
/// workspace of the dynamics; `rest` keeps the factorisations of the test at rest from one
/// instant to the next; `slot_part` is [`crr_kinematics::Parts::of_slot`] of the model.
///
/// On open chains the single releases are batched over the model's connected parts: the
/// accelerations of one part do not depend on another part's pivots or seated slots (M is
/// block-diagonal over the parts, the articulated-body recursions never combine two trees), so
/// one solve releasing one slot in each of several parts gives each of them the opening
/// acceleration of its release alone. Round r releases the r-th seated slot of every part, and
/// the test costs 2·(most seated slots in one part) solves of O(DOF(1)) instead of 2·|seated|:
/// O(DOF(1)) for a structure of independent blocks. A round whose solve fails (a singular part)
/// is redone slot by slot, so every release keeps the result it has alone.
///
/// A structure at rest with every joint seated is also tested globally: where the search finds
/// no opening, the contact faces' linear program ([`crate::statics::RestStatics`]) decides
/// whether the load exceeds the collapse multiplier along its direction, and its mechanism gives
/// the joints that open and their sides. A mechanism in which blocks lift off a support is
/// recorded in `rest.lift_off` (the run stops with [`super::SimulationError::LiftOff`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn opening_mode_in(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &mut Dynamics,
    rest: &mut RestCache,
    slot_part: &[usize],
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Option<Vec<(usize, Side)>> {
    let rate_scale = (model.gravity / model.size).sqrt();
    let at_rest = qdot.amax() <= 1e-12 * rate_scale;
    // A load along the ground's normal that pulls every body off it: a flight, whatever the
    // chain could release (every motion from rest pulls at the ground too, `free_fall`).
    if at_rest && let Some(thrown) = free_fall(model, ground, t).filter(|f| f.along) {
        rest.lift_off = Some(thrown.faces);
        rest.thrown_off = true;
        rest.grazing.clear();
        return Some(Vec::new());
    }
    let decided = opening_mode_decided(model, ground, template, trial, rest, slot_part, t, q, qdot);
    // Another load that pulls every body off the ground, where the motion decided (the
    // current one when nothing opens) pulls at the ground as well: a flight.
    if at_rest
        && let Some(faces) = thrown_off(
            model,
            ground,
            template,
            decided.as_deref().unwrap_or(&[]),
            (t, q, qdot),
        )
    {
        rest.lift_off = Some(faces);
        rest.thrown_off = true;
        rest.grazing.clear();
        return Some(Vec::new());
    }
    decided
}

/// The interfaces on the ground (their names) where the structure at rest in `template`, with
/// the releases `mode` made, is thrown off the ground: [`free_fall`] finds g_eff pulling every
/// body off it, and the ground's total force along its normal n in that motion,
/// M (a_cm − g_eff) · n (the bodies' momentum rates less their loads: every contact between
/// bodies cancels), pulls beyond 1e-9 W. Then no motion the model offers keeps the ground's
/// contacts pressing, and free fall meets every contact condition. Along n every motion pulls
/// there ([`free_fall`]); across it a body leaning far may press, which this asks of the motion
/// itself. None otherwise, or where the motion cannot be solved (the decision stands).
pub(super) fn thrown_off(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    mode: &[(usize, Side)],
    (t, q, qdot): (f64, &DVector<f64>, &DVector<f64>),
) -> Option<Vec<String>> {
    let thrown = free_fall(model, ground, t)?;
    if thrown.along {
        return Some(thrown.faces);
    }
    let mut d = template.clone();
    for &(k, side) in mode {
        d.pivots.sides[k] = side;
        d.seated.retain(|&s| s != k);
    }
    d.accelerations(model, ground, t, q, qdot).ok()?;
    crr_kinematics::jacobians(model, &mut d.kin);
    // At rest the bodies' centres accelerate by J_c q̈ (no velocity terms).
    let a = &d.kin.com_jacobian * &d.qddot;
    let mut momentum_rate = Vector3::zeros();
    for (b, body) in model.bodies.iter().enumerate() {
        momentum_rate += body.mass * a.fixed_rows::<3>(3 * b);
    }
    let mass = model.total_mass();
    let normal_force = (momentum_rate - mass * d.effective_gravity()).dot(&thrown.normal);
    (normal_force < -1e-9 * mass * model.gravity).then_some(thrown.faces)
}

/// [`opening_mode_in`] but for a structure thrown off the ground.
#[allow(clippy::too_many_arguments)]
fn opening_mode_decided(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &mut Dynamics,
    rest: &mut RestCache,
    slot_part: &[usize],
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Option<Vec<(usize, Side)>> {
    let rate_scale = (model.gravity / model.size).sqrt();
    // On open chains the single releases are exact: every mechanism of a tree of one-support
    // joints is a positive combination of single-joint openings, and a ratio of two linear
    // forms (the loads' and the weight's power) is least at an extreme ray; a block cannot lift
    // off its only support under less than g. The global test is for loops.
    if model.constraint_rows == 0
        || template.seated.len() < model.slot_count
        || qdot.amax() > 1e-12 * rate_scale
    {
        return opening_mode_local(
            model, ground, template, trial, rest, slot_part, t, q, qdot, true,
        );
    }
    let a = ground.acceleration(t);
    // The linear program decides first: a load inside the collapse set holds (static theorem: a
    // compressive equilibrium exists, so no mechanism of the CRR model, each one admissible on
    // the contact faces, has positive power), and then no local search is needed; most instants
    // at rest cost no solve at all (the load inside the cached octahedron of the six axis
    // multipliers). A failed program leaves the decision to the local test. A load beyond a
    // mechanism found before is exceeded (kinematic theorem), and the local test's opening,
    // when it finds one, is the answer with or without the program along a's direction (below):
    // the program runs only if the local test finds none (in the bisection of an uplift
    // instant, most probes beyond the multiplier).
    let local_first = rest.global.beyond_a_known_mechanism(model, &a);
    if local_first
        && let Some(local) = opening_mode_local(
            model, ground, template, trial, rest, slot_part, t, q, qdot, true,
        )
    {
        return Some(local);
    }
    // (A local test already run found no opening; it would find none again.)
    let collapse = match rest.global.exceeded(model, &a) {
        Ok(None) => {
            if rest.global.held_on_search() {
                rest.held_on_search.push(super::HeldOnSearch {
                    t,
                    load: [a.x, a.y, a.z],
                });
            }
            return None;
        }
        Ok(Some(collapse)) => collapse.clone(),
        Err(_) if local_first => return None,
        Err(_) => {
            return opening_mode_local(
                model, ground, template, trial, rest, slot_part, t, q, qdot, true,
            );
        }
    };
    // Beyond the multiplier the local test gives the opening accelerations' own mode when it
    // finds one; the mechanism's sides open otherwise.
    if !local_first
        && let Some(local) = opening_mode_local(
            model, ground, template, trial, rest, slot_part, t, q, qdot, true,
        )
    {
        return Some(local);
    }
    // (None: held, the chain cannot follow the mechanism.)
    let (collapse, grazing) = followable_collapse(model, rest, collapse, &a, t, q)?;
    let mut lifting: Vec<String> = collapse.lifting_off().map(|i| i.name.clone()).collect();
    lifting.extend(grazing);
    let sides: Vec<(usize, Side)> = collapse
        .interfaces
        .iter()
        .flat_map(|i| i.sides.iter().copied())
        .collect();
    if !lifting.is_empty() {
        rest.lift_off = Some(lifting);
        return Some(sides);
    }
    // Gauss' principle from the mechanism's sides gives the opening accelerations' own mode
    // when they exceed its threshold; at the crossing itself (a load 1e-9 above λ_c) they do
    // not, and the mechanism's sides open.
    let mut start = template.clone();
    for &(slot, side) in &sides {
        start.pivots.sides[slot] = side;
    }
    opening_mode_local(
        model, ground, &start, trial, rest, slot_part, t, q, qdot, true,
    )
    .or(Some(sides))
}

/// The collapse exceeded by the load `a` at rest in `q` that the CRR chain can follow, with the
/// joints it slides while keeping contact that open entirely (below), or None where it holds.
///
/// A mechanism of the search for joints that open and slide may have joints that slide while
/// keeping contact, carrying nothing (a block against a pier turning about its far foot, its
/// lowest edge sliding up the pier; a corner wedge whose half block slides up its head joint;
/// part of a 3D wall turning out of its plane, its head joints sliding past their neighbours).
/// The chain's joints do not slide, and its own local test has found no opening. Up to the
/// convex program's λ along the load (no sliding anywhere, the chain's own mechanisms included):
/// - those joints are offered as faces that open entirely, with the faces the mechanism lifts
///   off (the caller's `rest.lift_off`): the chain without them moves, and where its motion
///   takes every point of those faces off its support, at second order in the displacement
///   where the first leaves them grazing (`Simulation::faces_separate`: the block's lowest
///   edge rises along the pier and leaves it by w(1 − cos θ)), they open and the structure
///   leaves rest;
/// - where it does not (two equal blocks side by side, tipping together, press their common
///   face at second order: the motion needs that face to slide under compression), the chain
///   holds by shear across those joints with no compression, which no friction gives: the
///   instant and the joints are recorded in `rest.sliding_unloaded` (the run's
///   `sliding_unloaded` violation) and the structure stays at rest; the set is then held at
///   that state without asking again (`rest.grazing_refused`).
///
/// Beyond the convex λ, the convex program's collapse along the load decides, as for a
/// structure without such a mechanism. Releasing the sliding mechanism's sides, as before
/// 2026-12-05, moved nothing (rates of 1e-17 rad/s) and reported an uplift; lifting its faces
/// off before 2026-12-08 landed them at once, for ever (a `Chatter` stop at t = 0), because a
/// face's gap was measured from its parent's plane extended past the edge the tipping block
/// had lifted (`OpenFace::gap`).
fn followable_collapse(
    model: &Model,
    rest: &mut RestCache,
    collapse: crate::statics::Collapse,
    a: &Vector3<f64>,
    t: f64,
    q: &DVector<f64>,
) -> Option<(crate::statics::Collapse, Vec<String>)> {
    let mut sliding: Vec<String> = collapse
        .sliding_in_contact()
        .map(|i| i.name.clone())
        .collect();
    if sliding.is_empty() {
        return Some((collapse, Vec::new()));
    }
    let beyond_convex = collapse
        .convex_lambda
        .is_some_and(|l| a.norm() > l * model.gravity * (1.0 + 1e-9));
    if !beyond_convex {
        // In name order: the same record whatever order the file lists the joints in.
        sliding.sort_unstable();
        let state = grazing_key(q, a);
        if rest
            .grazing_refused
            .iter()
            .any(|(set, at)| *set == sliding && *at == state)
        {
            rest.sliding_unloaded.push((t, sliding));
            return None;
        }
        rest.grazing.clone_from(&sliding);
        return Some((collapse, sliding));
    }
    let convex = crate::statics::StaticsOptions {
        sliding_lift_off: false,
        ..Default::default()
    };
    crate::statics::collapse_multiplier(model, a.normalize(), &convex)
        .ok()
        .filter(|c| c.lambda.is_some())
        .map(|c| (c, Vec::new()))
}

/// Most sets of joints sliding in contact a run keeps as refused ([`RestCache::grazing_refused`]);
/// the oldest is dropped beyond.
const GRAZING_REFUSALS: usize = 16;

/// The key of a refused set of joints sliding in contact ([`RestCache::grazing_refused`]): the
/// state q as bits (exact) and the load's direction to 1e-3 (the motion that decided depends on
/// it; a record's load turning keeps asking).
pub(super) fn grazing_key(q: &DVector<f64>, a: &Vector3<f64>) -> Vec<u64> {
    let norm = a.norm();
    let direction = if norm > 0.0 { a / norm } else { *a };
    q.iter()
        .map(|x| x.to_bits())
        .chain(direction.iter().map(|x| (x * 1e3).round() as i64 as u64))
        .collect()
}

/// The faces on the ground where the effective gravity g_eff(t) pulls a structure at rest off
/// the ground: every face on the ground has the same normal n (into the bodies; the ground does
/// not turn), g_eff · n > 1e-9 g, and none of them is a pin (which holds any force). None
/// otherwise.
///
/// Held as it is, the structure needs from the ground the force −M g_eff, whose part along n,
/// −M g_eff · n, is the sum of the faces' normal forces: one of them pulls. The motion in which
/// every body falls freely (each with g_eff relative to the ground, no contact force anywhere,
/// the contacts between bodies at rest relative to each other, every point on the ground moving
/// off its face) meets every contact condition: the bodies leave the ground, outside the model.
/// On a horizontal ground, a vertical ground acceleration below −g.
///
/// Where g_eff lies along n ([`Thrown::along`]), every motion of the model from rest pulls at
/// the ground too. At q̇ = 0 the constrained accelerations are the M-orthogonal projection of
/// free fall's q̈_f (every body accelerating with g_eff) onto the motions the contacts allow, so
/// q̈ᵀMq̈_f = q̈ᵀMq̈ ≤ q̈_fᵀMq̈_f, that is M a_cm · g_eff ≤ M |g_eff|²: with g_eff = ε n the
/// ground's total normal force M (a_cm − g_eff) · n = M (a_cm · g_eff − ε²)/ε is at most 0,
/// whatever opens. (For one body turning about a pivot, its centre at r from it, it is
/// m ε (m wᵀI_P⁻¹w/ε² − 1) with w = r × g_eff, and I_P ⪰ m(|r|²I − r rᵀ) bounds it by
/// m ε (sin²θ − 1), θ between r and g_eff.) Across n the model's no-slip contacts may keep the
/// ground pressing (a body leaning far under a large horizontal part): [`thrown_off`] asks the
/// motion decided.
fn free_fall(model: &Model, ground: &GroundMotion, t: f64) -> Option<Thrown> {
    let g_eff = crr_dynamics::eom::effective_gravity(model, ground, t);
    let mut faces = Vec::new();
    let mut normal: Option<Vector3<f64>> = None;
    for (index, iface) in model.interfaces.iter().enumerate() {
        if !matches!(iface.parent, crr_kinematics::Parent::Ground) {
            continue;
        }
        let face = ContactFace::of_interface(model, index);
        let common = *normal.get_or_insert(face.normal);
        if face.pin
            || (face.normal - common).norm() > 1e-9
            || g_eff.dot(&face.normal) <= 1e-9 * model.gravity
        {
            return None;
        }
        faces.push(iface.name.clone());
    }
    let normal = normal?;
    let along = (g_eff - normal * g_eff.dot(&normal)).norm() <= 1e-9 * g_eff.dot(&normal);
    Some(Thrown {
        faces,
        normal,
        along,
    })
}

/// A structure thrown off the ground ([`free_fall`]).
struct Thrown {
    /// The interfaces on the ground.
    faces: Vec<String>,
    /// Their common normal n (into the bodies).
    normal: Vector3<f64>,
    /// Whether g_eff lies along n (its part across n within 1e-9 of its part along it).
    along: bool,
}

/// The local test of [`opening_mode_in`]: single releases, the active set, and Gauss' principle
/// over the sides at rest; on loops the contact program first when `with_program`. Without it,
/// the chain's own decision with every closed face kept closed (for a lift-off of the program
/// that the chain without the face does not confirm, [`Simulation::release_once`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn opening_mode_local(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &mut Dynamics,
    rest: &mut RestCache,
    slot_part: &[usize],
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    with_program: bool,
) -> Option<Vec<(usize, Side)>> {
    let seated = template.seated.clone();
    if seated.is_empty() {
        return None;
    }
    let tol = 1e-9 * model.gravity / model.size;
    // A structure with loops at rest: the contact program decides (loop_opening, below), and
    // where it cannot, Gauss' principle over the seated slots' sides (uplift_from_rest.rs). Both
    // find the mechanisms of several joints in hyperstatic loops (an arch that rocks out of its
    // plane) that single releases and the active set below miss. In motion the search over
    // sides picked modes that later needed tension (the 3D arch under its record), so single
    // releases and the active set keep that case.
    let rate_scale = (model.gravity / model.size).sqrt();
    let at_rest = model.constraint_rows > 0 && qdot.amax() <= 1e-12 * rate_scale;
    if at_rest {
        trial.pivots.clone_from(&template.pivots);
        trial.seated.clone_from(&seated);
        trial.evaluate(model, ground, t, q, qdot);
        if let Some(mode) = with_program
            .then(|| loop_opening(model, ground, template, trial, rest, t, q, qdot, tol))
            .flatten()
        {
            return mode;
        }
        if let Some(mode) = opening_from_rest(model, ground, template, trial, rest, t, q, qdot, tol)
        {
            return mode;
        }
    }
    // The current sides: one evaluation of the state (M, h …) serves every solve, unless the
    // articulated-body algorithm solves (it does not use M, and its solve is as cheap as the
    // evaluation).
    trial.pivots.clone_from(&template.pivots);
    trial.seated.clone_from(&seated);
    let evaluated = !trial.articulated_body_applies(model);
    if evaluated {
        trial.evaluate(model, ground, t, q, qdot);
    }
    // Releases that cannot open are known from one solve with every seated slot locked.
    let may_open = releases_that_may_open(model, ground, template, trial, t, q, qdot);
    // Every seated slot held on both of its pivots: no release opens, and no set of releases
    // either. The power of the held structure's constraint forces on any opening motion is
    // Σ αₖσₖrₖ(sₖ) over the slots it opens (αₖ ≥ 0), positive when every σₖrₖ(sₖ) is, so the
    // held motion is the minimum of the Gauss function over the cone of openings (convex), and
    // the active set below could only end where it starts.
    // The faces rocking on one pivot must press on it too, or the program decides whether they
    // lift off.
    if model.constraint_rows > 0
        && may_open.as_ref().is_some_and(|m| m.iter().all(|&o| !o))
        && !rocking_face_may_lift(model, template, trial, &rest.held_faces)
    {
        return None;
    }
    // With loops, one convex program over the seated faces decides (opening_qp.rs); the single
    // releases and the active set below remain for open chains (where single releases are
    // exact) and for a program that fails. At rest it has run above, on the same state.
    if with_program && model.constraint_rows > 0 && !at_rest {
        // A compressive distribution of the locked motion's forces: the program's minimum is
        // that motion (most step ends in motion: the locked solve's own reactions are one split
        // among many on hyperstatic loops and seldom certify). Only where the program would be
        // the whole problem: a restricted one leaves the decision to the local test below, and
        // so does the certificate.
        let certificate =
            may_open.is_some() && openings_slide_nowhere(model) && offers_both_pivots(model, trial);
        if may_open.is_none() {
            trial.evaluate(model, ground, t, q, qdot);
        } else if certificate
            && let Some(residual) = closed_loops_residual(model, trial)
            && pressing_carried(model, trial, rest)
        {
            let state = (t, q, qdot);
            audit_certified(model, ground, template, trial, rest, state, residual, tol);
            return None;
        }
        if let Some(mode) = loop_opening(model, ground, template, trial, rest, t, q, qdot, tol) {
            if certificate && mode.is_none() {
                // Nothing opens: the faces' program finds a distribution to carry to the next
                // states (where something opens it finds none, at twice the contact program's
                // cost).
                rest.pressing.refresh_paced();
            }
            return mode;
        }
    }
    let opening = single_release_openings(
        model,
        ground,
        template,
        trial,
        &seated,
        slot_part,
        may_open.as_deref(),
        evaluated,
        t,
        q,
        qdot,
    );
    if let Some((k, side)) = strongest_opening(&seated, &opening, tol) {
        return Some(vec![(k, side)]);
    }
    if model.constraint_rows == 0 || seated.len() < 2 {
        return None;
    }
    active_set_opening(model, ground, template, trial, &seated, t, q, qdot, tol)
}

/// Whether every opening the contact program offers moves the touching points it leaves along
/// the normal the faces pose their forces on, so that the faces' distributions (free tangential
/// forces at every touching point) price exactly the program's motions, and a compressive one
/// certifies that nothing opens (`pressing_carried`, asked by the uplift test in motion only
/// where this holds). A hinge turns about a pivot line in its face's plane; a rocking base with
/// both tilts seated about an edge of the seat, and one with its first tilt seated and its
/// second turned about the parent's e₁, both in the parent's face plane; a lift translates
/// along that normal. A rocking base with its first tilt turned and its second seated turns
/// about R(e₁, θ₁)e₂, in the child's face plane: the certificate poses that face's forces on
/// the child's axes (`face_forces`, `leaves_along_child_normal`; on the parent's, the 3D arch
/// had 66 step ends certified where the program, confirmed by the chain's own solve, released a
/// joint). A seat that may twist is a rocking base for this rule: its twist turns the child's
/// axes about the face's normal, within the face's plane. (Both were kept out from 2026-11-30
/// until the cause of the temple's disagreements was found: the closed-chain solve's residual
/// near its seats, [`CERTIFIED_CLOSURE_RESIDUAL`].) A hinge whose two pivot lines (nearly)
/// coincide is a pin for the faces (free normal forces, any moment) but keeps a lift in the
/// program, whose dual bounds its moment: such a face "held" lifts that the program makes (an
/// independent review, with pivots 1e-7 m apart). Those decide by the program.
pub fn openings_slide_nowhere(model: &Model) -> bool {
    (0..model.interfaces.len()).all(|index| !ContactFace::is_pin(model, index))
}

/// The largest closure residual Φ_q q̈ + Φ̇_q q̇ of the locked solve (in g) at which the faces'
/// certificate may decide. The certificate proves that the locked motion is the contact
/// program's minimum, and that motion is the one with every loop closed; near a hyperstatic
/// seat the closed-chain solve takes rows dependent below its rank rule as dependent and leaves
/// them open (docs/simulation.md, Limitations), and what it certifies there is another motion.
/// Round-off is 1.5e-14 m/s² or less on the bundled 3D arch and on walls, and up to 2e-11 m/s²
/// on the bundled temple's certified states; the temple near its seats reaches 1.3e-3 m/s²
/// (with rigid seats) and 7e-7 m/s² (as bundled, at 0.8 of its record). Without this bound the
/// audit found 7 749 and 140 step ends there at which the certificate held and the program,
/// confirmed by the chain's own solve, released a joint; with it, none
/// (`tests/engine/certificate_audit.rs`, 2026-11-30).
pub const CERTIFIED_CLOSURE_RESIDUAL: f64 = 1e-11;

/// The loops' opening at acceleration level (g) above which the closed-chain solve that checks
/// the contact program's releases (each must open on its side) is not trusted to send one back to
/// its seat: such a check is recorded ([`super::DoubtfulCheck`]) and the run warns of it. The
/// level of the output samples' warning (1e-6 g); round-off is 1e-11 g or less on the bundled
/// models.
pub const DOUBTFUL_CHECK_RESIDUAL: f64 = 1e-6;

/// The locked solve's closure residual (m/s², [`Dynamics::loop_residual`]) where it keeps every
/// loop closed at acceleration level to [`CERTIFIED_CLOSURE_RESIDUAL`] g; None where it does not.
fn closed_loops_residual(model: &Model, trial: &Dynamics) -> Option<f64> {
    let residual = trial.loop_residual(model);
    (residual <= CERTIFIED_CLOSURE_RESIDUAL * model.gravity).then_some(residual)
}

/// Whether the locked motion solved in `trial` (every seated slot held, every rocking face on its
/// pivot) is certified by a compressive distribution of its contact forces on the faces, the last
/// one found carried to this state ([`crate::face_forces::PressingCertificate::carries`]): then
/// it is the contact program's minimum, and nothing opens. False where the carried distribution
/// does not press everywhere or cannot be computed (the program decides).
fn pressing_carried(model: &Model, trial: &Dynamics, rest: &mut RestCache) -> bool {
    crate::monitor::body_loads_into(model, trial, trial.effective_gravity(), &mut rest.loads);
    rest.pressing
        .carries(model, trial, &rest.loads)
        .unwrap_or(false)
}

/// With the run audited ([`super::Simulation::audit_certificate`]), the contact program's answer
/// at a state the certificate decided, recorded: the uplift test's own [`loop_opening`] (the
/// program, its releases confirmed by the chain's exact solve) on a copy of `trial`, with the
/// lift-off it may name taken back, so that the run goes on as unaudited. `residual` is the
/// locked solve's closure residual ([`closed_loops_residual`]), recorded with the answer.
#[allow(clippy::too_many_arguments)]
fn audit_certified(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &Dynamics,
    rest: &mut RestCache,
    (t, q, qdot): (f64, &DVector<f64>, &DVector<f64>),
    residual: f64,
    tol: f64,
) {
    let Some(mut audit) = rest.audit.take() else {
        return;
    };
    let mut scratch = trial.clone();
    let kept = rest.lift_off.take();
    let answer = loop_opening(model, ground, template, &mut scratch, rest, t, q, qdot, tol);
    let lifting_off = std::mem::replace(&mut rest.lift_off, kept).unwrap_or_default();
    match answer {
        Some(releases) => audit.record(
            model,
            t,
            &releases.unwrap_or_default(),
            lifting_off,
            residual,
        ),
        None => audit.unsolved += 1,
    }
    rest.audit = Some(audit);
}

/// The contact program's decision on a structure with loops (`trial` evaluated at the state
/// with the template's pivots and seated slots), checked by the chain's exact solve: the
/// releases it names are solved together and every one must open on its side by more than
/// `tol`; one that does not (the program's round-off near a threshold) goes back to its seat and
/// the rest are solved again. Faces that lift off are recorded in `rest.lift_off` when every
/// seated slot was offered both pivots ([`OpeningDecision::complete`]). None when the program
/// fails or finds a lift-off in a restricted program (the caller falls back to single releases
/// and the active set); Some(None) when nothing opens.
#[allow(clippy::too_many_arguments)]
fn loop_opening(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &mut Dynamics,
    rest: &mut RestCache,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    tol: f64,
) -> Option<Option<Vec<(usize, Side)>>> {
    // A program with some slot held to its current side (a flip that would move a free slot's
    // axis) is not the whole problem: the local test decides then, as before the program.
    if !offers_both_pivots(model, trial) {
        return None;
    }
    let decision = opening_qp_holding(model, trial, &rest.held_faces).ok()?;
    if !decision.lifting_off.is_empty() {
        rest.lift_off = Some(
            decision
                .lifting_off
                .iter()
                .map(|&i| model.interfaces[i].name.clone())
                .collect(),
        );
        return Some(Some(decision.releases));
    }
    confirmed_releases(
        model,
        ground,
        template,
        trial,
        decision.releases,
        t,
        q,
        qdot,
        tol,
        &mut rest.doubtful,
    )
}

/// The releases `releases` (the contact program's) checked by the chain's exact solve: they are
/// solved together and every one must open on its side by more than `tol`; one that does not
/// (the program's round-off near a threshold, or a release that came with a lift-off the chain
/// does not confirm) goes back to its seat and the rest are solved again. Some(None) when
/// nothing opens; None when a solve fails. A solve that sends releases back while it leaves the
/// loops open by more than [`DOUBTFUL_CHECK_RESIDUAL`] g is recorded in `doubtful`.
#[allow(clippy::too_many_arguments)]
pub(super) fn confirmed_releases(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &mut Dynamics,
    mut releases: Vec<(usize, Side)>,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    tol: f64,
    doubtful: &mut Vec<super::DoubtfulCheck>,
) -> Option<Option<Vec<(usize, Side)>>> {
    let mut row = DVector::zeros(model.dof());
    while !releases.is_empty() {
        trial.pivots.clone_from(&template.pivots);
        for &(k, side) in &releases {
            trial.pivots.sides[k] = side;
        }
        trial.seated.clear();
        trial.seated.extend(
            template
                .seated
                .iter()
                .copied()
                .filter(|s| !releases.iter().any(|r| r.0 == *s)),
        );
        trial.accelerations(model, ground, t, q, qdot).ok()?;
        let opens: Vec<bool> = releases
            .iter()
            .map(|&(k, side)| {
                let bias = slot_row(model, &trial.kin, k, &mut row);
                side.sign() * (row.dot(&trial.qddot) + bias) > tol
            })
            .collect();
        if opens.iter().all(|&o| o) {
            return Some(Some(releases));
        }
        // Near a hyperstatic seat the solve takes nearly dependent rows as dependent and leaves
        // the loops open; its accelerations are then not the chain's, and the releases it sends
        // back are sent back on its word alone (the rigid-seated temple at 2.0395 s: the
        // program's necks and seats, open by 3.7e-3 m/s², all sent back).
        let residual = trial.loop_residual(model);
        if residual > DOUBTFUL_CHECK_RESIDUAL * model.gravity {
            // Each interface once (a rocking base's two tilts), in the releases' order.
            let mut interfaces: Vec<String> = Vec::new();
            for (&(k, _), _) in releases.iter().zip(&opens).filter(|(_, o)| !**o) {
                let name = &model.interfaces[slot_interface(model, k)].name;
                if !interfaces.contains(name) {
                    interfaces.push(name.clone());
                }
            }
            doubtful.push(super::DoubtfulCheck {
                t,
                residual,
                interfaces,
            });
        }
        let mut kept = opens.iter();
        releases.retain(|_| *kept.next().unwrap_or(&false));
    }
    Some(None)
}

/// Release (slot, side) is indexed 2i on the positive side of slot `seated[i]`, 2i + 1 on the
/// negative.
fn side_index(side: Side) -> usize {
    usize::from(side == Side::Negative)
}

/// The opening acceleration of every single release of the seated slots that may open (see
/// [`side_index`]; None: not tried, or its solve failed). The releases on the slots' current
/// sides share the template's chain (evaluated once in `trial` when `evaluated`); a release on
/// the other side changes the chain and is evaluated anew. Releases are batched in rounds: on
/// open chains slot i goes to round (its rank among the seated slots of its part); with loops
/// every release is a round of its own (the rank threshold of the closed-chain solve is taken
/// over the whole Jacobian, which couples the parts' round-off).
#[allow(clippy::too_many_arguments)]
fn single_release_openings(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &mut Dynamics,
    seated: &[usize],
    slot_part: &[usize],
    may_open: Option<&[bool]>,
    evaluated: bool,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Vec<Option<f64>> {
    let mut row = DVector::zeros(model.dof());
    let n = model.dof();
    // The opening acceleration of slot k in the last solve (a tree coordinate's is q̈ₖ).
    let slot_accel = |trial: &Dynamics, row: &mut DVector<f64>, k: usize| -> f64 {
        if k < n {
            trial.qddot[k]
        } else {
            let bias = slot_row(model, &trial.kin, k, row);
            row.dot(&trial.qddot) + bias
        }
    };
    let mut opening: Vec<Option<f64>> = vec![None; 2 * seated.len()];
    let mut round = vec![0; seated.len()];
    let rounds = if model.constraint_rows == 0 {
        let mut count = vec![0usize; slot_part.iter().max().map_or(0, |&p| p + 1)];
        for (i, &k) in seated.iter().enumerate() {
            round[i] = count[slot_part[k]];
            count[slot_part[k]] += 1;
        }
        count.into_iter().max().unwrap_or(0)
    } else {
        for (i, r) in round.iter_mut().enumerate() {
            *r = i;
        }
        seated.len()
    };
    // Solves with the slots of `batch` (indices into `seated`) released, on their current sides
    // (the template's chain, already evaluated in `trial` when `evaluated`) or flipped; returns
    // their opening accelerations with their indices into `opening`, None if the solve failed.
    let mut in_batch = vec![false; seated.len()];
    let mut release = |trial: &mut Dynamics, batch: &[usize], flip: bool, evaluated: bool| {
        for &i in batch {
            in_batch[i] = true;
        }
        trial.seated.clear();
        trial.seated.extend(
            seated
                .iter()
                .zip(&in_batch)
                .filter(|&(_, &released)| !released)
                .map(|(&s, _)| s),
        );
        for &i in batch {
            in_batch[i] = false;
        }
        let ok = if flip {
            trial.pivots.clone_from(&template.pivots);
            for &i in batch {
                let k = seated[i];
                trial.pivots.sides[k] = trial.pivots.sides[k].flipped();
            }
            trial.accelerations(model, ground, t, q, qdot).is_ok()
        } else if evaluated {
            trial.solve_evaluated(model, t, q, qdot, None).is_ok()
        } else {
            trial.accelerations(model, ground, t, q, qdot).is_ok()
        };
        ok.then(|| {
            batch
                .iter()
                .map(|&i| {
                    let k = seated[i];
                    let side = trial.pivots.sides[k];
                    (
                        2 * i + side_index(side),
                        side.sign() * slot_accel(trial, &mut row, k),
                    )
                })
                .collect::<Vec<_>>()
        })
    };
    let mut batch = Vec::with_capacity(seated.len());
    for flip in [false, true] {
        for r in 0..rounds {
            batch.clear();
            batch.extend((0..seated.len()).filter(|&i| {
                let side = if flip {
                    template.pivots.sides[seated[i]].flipped()
                } else {
                    template.pivots.sides[seated[i]]
                };
                round[i] == r && may_open.is_none_or(|m| m[2 * i + side_index(side)])
            }));
            if batch.is_empty() {
                continue;
            }
            let results = match release(trial, &batch, flip, evaluated) {
                Some(results) => results,
                None if batch.len() > 1 => batch
                    .iter()
                    .filter_map(|&i| release(trial, &[i], flip, evaluated))
                    .flatten()
                    .collect(),
                None => Vec::new(),
            };
            for (j, a) in results {
                opening[j] = Some(a);
            }
        }
    }
    opening
}

/// The single release that opens fastest, above `tol`.
fn strongest_opening(seated: &[usize], opening: &[Option<f64>], tol: f64) -> Option<(usize, Side)> {
    let mut best: Option<(usize, Side, f64)> = None;
    for (i, &k) in seated.iter().enumerate() {
        for side in [Side::Positive, Side::Negative] {
            if let Some(o) = opening[2 * i + side_index(side)]
                && o > tol
                && best.is_none_or(|b| o > b.2)
            {
                best = Some((k, side, o));
            }
        }
    }
    best.map(|(k, side, _)| (k, side))
}

/// The active set over the seated slots released together (loops with several seated slots,
/// when no single release opens).
#[allow(clippy::too_many_arguments)]
fn active_set_opening(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &mut Dynamics,
    seated: &[usize],
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    tol: f64,
) -> Option<Vec<(usize, Side)>> {
    let mut row = DVector::zeros(model.dof());
    // Active set over the seated slots released together: a slot closing on its side is tried
    // once on the other side; closing on both, it stays seated (the tilts of a loop of rocking
    // bases that the excitation does not drive: under x only, the y tilts). Whenever a slot
    // goes back to its seat the mechanism changes, so the others get their second try again.
    // Each return to a seat shrinks the set, and between two of them each slot flips at most
    // once: the iteration ends within (|seated| + 1)² evaluations.
    let mut released: Vec<(usize, Side, bool)> = seated
        .iter()
        .map(|&s| (s, template.pivots.sides[s], false))
        .collect();
    let bound = (seated.len() + 1) * (seated.len() + 1);
    for _ in 0..bound {
        trial.seated = seated
            .iter()
            .copied()
            .filter(|s| !released.iter().any(|r| r.0 == *s))
            .collect();
        trial.pivots.clone_from(&template.pivots);
        for &(s, side, _) in &released {
            trial.pivots.sides[s] = side;
        }
        trial.accelerations(model, ground, t, q, qdot).ok()?;
        let mut next = Vec::with_capacity(released.len());
        let mut reseated = false;
        for &(s, side, tried) in &released {
            let bias = slot_row(model, &trial.kin, s, &mut row);
            let a = row.dot(&trial.qddot) + bias;
            if side.sign() * a > tol {
                next.push((s, side, tried));
            } else if !tried && a.abs() > tol {
                next.push((s, side.flipped(), true));
            } else {
                reseated = true;
            }
        }
        if next.len() == released.len() && next.iter().zip(&released).all(|(a, b)| a.1 == b.1) {
            return Some(released.into_iter().map(|(s, side, _)| (s, side)).collect());
        }
        if next.is_empty() {
            return None;
        }
        if reseated {
            for r in &mut next {
                r.2 = false;
            }
        }
        released = next;
    }
    None
}

/// Which single releases of `template`'s seated slots may open, indexed like `opening_mode_in`'s
/// `opening` (2i: slot `seated[i]` on the positive side, 2i + 1: negative), from one solve with
/// every seated slot locked; None when the test does not apply (loops, or a solve not by the
/// articulated-body algorithm), and then every release is solved.
///
/// Releasing seated slot k alone on its current pivot changes q̈ by −(M̃⁻¹)eₖrₖ, M̃ the mass
/// matrix over the free coordinates and k, so that its opening acceleration is
/// q̈ₖ = −rₖ (M̃⁻¹)ₖₖ with (M̃⁻¹)ₖₖ > 0: the release opens on side σ only if −σ rₖ > 0, rₖ the
/// seat reaction of the locked solve. On the other pivot the locked motion is the same (at
/// qₖ = q̇ₖ = 0 the pivot moves no frame, and a locked joint is a weld whatever its axis), so
/// that the reaction there is the joint force's moment about the other axis,
/// rₖ′ = rₖ + (sₖ′ − sₖ)ᵀfₖ = rₖ + ((pₖ′ − pₖ) × wₖ)·fₖ — unless the flip also moves the pivot of
/// a free coordinate (the other tilt of a rocking base) or qₖ, q̇ₖ are not 0 to round-off, and
/// the release is then solved. Skipped
/// releases are exactly those whose solve would give σq̈ₖ ≤ 0, below the opening threshold:
/// the uplift test's answer is unchanged, and a seated state that holds costs one solve.
fn releases_that_may_open(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &mut Dynamics,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Option<Vec<bool>> {
    let n = model.dof();
    let seated = &template.seated;
    if model.constraint_rows != 0 {
        return loop_releases_that_may_open(model, ground, template, trial, t, q, qdot);
    }
    if seated.iter().any(|&k| k >= n) {
        return None;
    }
    // Seated coordinates sit at q = 0, q̇ = 0 up to round-off (the projections leave ~1e-16):
    // there the other pivot's reaction is off by some 1e-12 W·L at most, 1e-3 of the opening
    // threshold (1e-9 g/size on an inertia of order m·size²), so no release that opens is skipped.
    let rate_scale = (model.gravity / model.size).sqrt();
    let at_seat = |k: usize| q[k].abs() <= 1e-12 && qdot[k].abs() <= 1e-12 * rate_scale;
    trial.pivots.clone_from(&template.pivots);
    trial.seated.clone_from(seated);
    if !trial.articulated_body_applies(model) {
        return None;
    }
    trial.accelerations(model, ground, t, q, qdot).ok()?;
    let mut is_seated = vec![false; model.slot_count];
    for &k in seated {
        is_seated[k] = true;
    }
    let mut may_open = vec![true; 2 * seated.len()];
    for (i, &k) in seated.iter().enumerate() {
        let f = trial.joint_force(k)?;
        let r = trial.seat_reactions[i];
        let side = template.pivots.sides[k];
        let index = |s: Side| 2 * i + usize::from(s == Side::Negative);
        may_open[index(side)] = -side.sign() * r > 0.0;
        // The other pivot, where the flip moves no free coordinate's pivot.
        let coord = &model.coords[k];
        let iface = &model.interfaces[coord.interface];
        let moves_free = iface.slots.clone().any(|s| s != k && !is_seated[s]);
        if moves_free || !at_seat(k) {
            continue;
        }
        let other = side.flipped();
        let pivot = frame_point(
            &trial.kin,
            coord.parent,
            &other_pivot_rest(iface, &template.pivots, k),
        );
        let arm = (pivot - trial.kin.pivot[k]).cross(&trial.kin.axis[k]);
        let r_other = r + arm.dot(&f.fixed_rows::<3>(3));
        may_open[index(other)] = -other.sign() * r_other > 0.0;
    }
    Some(may_open)
}

/// Whether a face rocking on one pivot may lift off, from the locked solve in `trial` (that of
/// [`loop_releases_that_may_open`]): its pivot's normal force, read as the reaction r′ about its
/// other pivot P′ (on the parent) of a joint that carries no moment about P (r = 0), as for a
/// seated slot's other side; it may lift where −σ′r′ > −(margin + round-off), σ′ the other side.
/// Any equilibrium distribution that presses on every pivot certifies that none lifts (the held
/// structure's forces do positive power on every lift), so the locked solve's own λ serves.
/// True where the solve gives no λ (the articulated-body path) or a face's reaction is not
/// known (a seat that may twist): the program decides then.
fn rocking_face_may_lift(
    model: &Model,
    template: &Dynamics,
    trial: &Dynamics,
    held: &[usize],
) -> bool {
    let mut is_seated = vec![false; model.slot_count];
    for &k in &template.seated {
        is_seated[k] = true;
    }
    let mut faces = super::opening_qp::rocking_faces(model, trial, &is_seated, held).peekable();
    if faces.peek().is_none() {
        return false;
    }
    if trial.used_articulated_body() {
        return true;
    }
    let margin = 1e-9 * trial.seat_reactions.amax();
    let loads = SubtreeLoads::new(model, trial);
    for (_, k, _) in faces {
        let (r_other, round_off) = if k < model.dof() {
            loads.other_side_reaction(model, trial, &template.pivots, k, 0.0)
        } else {
            match closure_other_side_reaction(model, trial, &template.pivots, k, 0.0) {
                Some(x) => x,
                None => return true,
            }
        };
        let other = template.pivots.sides[k].flipped();
        if -other.sign() * r_other > -(margin + round_off) {
            return true;
        }
    }
    false
}

/// [`releases_that_may_open`] on a structure with loops.
///
/// **Current sides.** With every seated slot held, the seated rows and the closure rows B carry
/// multipliers with M q̈ = Q + Bᵀλ. Releasing seated slot k alone removes its row bₖ. If bₖ is in
/// the span of the other rows the motion does not change and the release cannot open. Otherwise
/// every λ that solves the locked problem has the same component λₖ (a self-stress state ν,
/// Bᵀν = 0, has νₖ = 0, or bₖ would be a combination of the others), and the release changes q̈
/// along the one new direction d of the admissible accelerations, d the part of M⁻¹bₖ
/// M-orthogonal to the other rows' span, so that the released slot's acceleration is
/// bₖ·Δq̈ = −λₖ (bₖ·d) with bₖ·d > 0: it opens on its side σ only if −σλₖ > 0, whichever solution
/// of the locked problem gave λ.
///
/// **Other sides.** Gauss' principle says the same in body space: releasing k adds one direction
/// d′ to the admissible accelerations, and the release opens along d′ only if the locked
/// structure's constraint forces R = M_b a − f do negative power on it (the Gauss function's
/// gradient at the locked motion is R, which does no power on the locked directions, so any d′
/// with the same opening rate gives the same power). A tree coordinate k at its seat (qₖ = q̇ₖ = 0)
/// turned about the other pivot P′ moves its subtree as a rotation about P plus the translation
/// t = u × (P − P′) per unit rate, so that its reaction there is rₖ′ = rₖ + t·fₖ, fₖ the force the
/// joint passes to its subtree: the subtree's Σ mᵢ(aᵢ − g_eff) less the closure forces λ on its
/// point rows (a loop's point row moves with the translation when one of its two frames is in
/// the subtree; angle rows, seated slot rows and symmetry rows do not). The release on P′ opens
/// only if −σ′rₖ′ > 0. As in the open-chain test this is skipped, and the release solved, where
/// the flip also moves a free coordinate's pivot, or qₖ, q̇ₖ are not at the seat, or the slot is
/// a closure angle. Reactions within 1e-9 of the largest of the closing sign are solved all the
/// same (round-off of a near-dependent row), so no release that opens is skipped.
fn loop_releases_that_may_open(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &mut Dynamics,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Option<Vec<bool>> {
    let seated = &template.seated;
    trial.pivots.clone_from(&template.pivots);
    trial.seated.clone_from(seated);
    trial.accelerations(model, ground, t, q, qdot).ok()?;
    let margin = 1e-9 * trial.seat_reactions.amax();
    let mut may_open = vec![true; 2 * seated.len()];
    for (i, &k) in seated.iter().enumerate() {
        let side = template.pivots.sides[k];
        let r = trial.seat_reactions[i];
        may_open[2 * i + usize::from(side == Side::Negative)] = -side.sign() * r > -margin;
    }
    if !trial.used_articulated_body() {
        other_side_releases(model, template, trial, q, qdot, margin, &mut may_open);
    }
    Some(may_open)
}

/// The other-side part of [`loop_releases_that_may_open`]: marks in `may_open` the releases on
/// the other pivot that cannot open, from the locked solve in `trial`.
fn other_side_releases(
    model: &Model,
    template: &Dynamics,
    trial: &Dynamics,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    margin: f64,
    may_open: &mut [bool],
) {
    let rate_scale = (model.gravity / model.size).sqrt();
    let mut is_seated = vec![false; model.slot_count];
    for &k in &template.seated {
        is_seated[k] = true;
    }
    let loads = SubtreeLoads::new(model, trial);
    for (i, &k) in template.seated.iter().enumerate() {
        if flip_moves_a_free_axis(model, trial, &template.pivots, &is_seated, k) {
            continue;
        }
        let r = trial.seat_reactions[i];
        let (r_other, round_off) = if k < model.dof() {
            if q[k].abs() > 1e-12 || qdot[k].abs() > 1e-12 * rate_scale {
                continue;
            }
            loads.other_side_reaction(model, trial, &template.pivots, k, r)
        } else {
            match closure_other_side_reaction(model, trial, &template.pivots, k, r) {
                Some(x) => x,
                None => continue,
            }
        };
        let other = template.pivots.sides[k].flipped();
        may_open[2 * i + usize::from(other == Side::Negative)] =
            -other.sign() * r_other > -(margin + round_off);
    }
}

/// The reaction of a seated closure angle k (≥ DOF(1)) on its other pivot, from its reaction `r`
/// (the multiplier of its angle row) on the current one; None for a rocking base that may twist.
///
/// The tree does not change: only the closure's point rows move from P to P′. A release on P′
/// turns the child relative to the parent about the slot's axis w through P′ at the rate σ′, so
/// the point rows at P see the relative velocity −σ′ w × (P − P′) and the held forces do the
/// power σ′(r − λ_P·(w × (P − P′))), λ_P the multipliers of the point rows (the angle rows of
/// the interface and every other row see no motion). Also returns the round-off of the correction.
pub(super) fn closure_other_side_reaction(
    model: &Model,
    trial: &Dynamics,
    pivots: &ActivePivots,
    k: usize,
    r: f64,
) -> Option<(f64, f64)> {
    let kin = &trial.kin;
    let (index, iface) = model
        .interfaces
        .iter()
        .enumerate()
        .find(|(_, i)| i.slots.contains(&k))?;
    let closure = model.closures.iter().find(|c| c.interface == index)?;
    let parent = model.frame_of(iface.parent);
    let child = Some(model.body_coord[iface.child]);
    let frame_rot = |f: Option<usize>| f.map_or_else(Matrix3::identity, |f| kin.rot_ops[f]);
    let component = k - iface.slots.start;
    // The slot's world axis, as in `slot_row`: on the parent, a rocking base's second tilt on
    // the child.
    let w = match &iface.kind {
        InterfaceKind::Hinge { axis, .. } => frame_rot(parent) * axis,
        InterfaceKind::RockingBase { twist: true, .. } => return None,
        InterfaceKind::RockingBase { e1, e2, .. } => {
            if component == 0 {
                frame_rot(parent) * e1
            } else {
                frame_rot(child) * e2
            }
        }
    };
    let p = frame_point(
        kin,
        parent,
        &iface.kind.pivot(pivots.of_interface(model, index)),
    );
    let p_other = frame_point(kin, parent, &other_pivot_rest(iface, pivots, k));
    let lambda = trial.lambda.fixed_rows::<3>(closure.first_row);
    let arm = w.cross(&(p - p_other));
    Some((r - lambda.dot(&arm), 1e-9 * lambda.norm() * arm.norm()))
}

/// Whether slot `k` is a tilt of a loop-closing seat that may twist.
pub(super) fn is_twisting_closure_slot(model: &Model, k: usize) -> bool {
    k >= model.dof()
        && matches!(
            model.interfaces[slot_interface(model, k)].kind,
            InterfaceKind::RockingBase { twist: true, .. }
        )
}

/// The rest position (in the coordinates of the frame that carries it) of interface `iface`'s
/// pivot with its slot `k` on the other side, its other slots as in `pivots`.
pub(crate) fn other_pivot_rest(iface: &Interface, pivots: &ActivePivots, k: usize) -> Vector3<f64> {
    // An interface has one slot (a hinge) or two (a rocking base's tilts).
    let current = &pivots.sides[iface.slots.clone()];
    let mut sides = [Side::Positive; 2];
    sides[..current.len()].copy_from_slice(current);
    let local = k - iface.slots.start;
    sides[local] = sides[local].flipped();
    iface.kind.pivot(&sides[..current.len()])
}

/// Whether turning seated slot k to its other pivot moves the axis line of a free
/// coordinate of the same interface (then the released chain's other columns change, and the
/// reaction formula does not hold). A rocking base's pivot is a corner shared by its two tilts:
/// flipping one tilt moves the corner along the other tilt's axis, which leaves that axis line,
/// and the other tilt's column at every instant, as it was; only a free closure slot, or a
/// displacement across a free axis, stops the filter.
pub(super) fn flip_moves_a_free_axis(
    model: &Model,
    trial: &Dynamics,
    pivots: &ActivePivots,
    is_seated: &[bool],
    k: usize,
) -> bool {
    let kin = &trial.kin;
    let Some(iface) = model.interfaces.iter().find(|i| i.slots.contains(&k)) else {
        return true;
    };
    let p_rest = other_pivot_rest(iface, pivots, k);
    iface.slots.clone().any(|j| {
        if j == k || is_seated[j] {
            return false;
        }
        if j >= model.dof() {
            return true;
        }
        let moved = frame_point(kin, model.coords[j].parent, &p_rest);
        kin.axis[j].cross(&(kin.pivot[j] - moved)).norm() > 1e-12 * model.size
    })
}

/// mᵢ(aᵢ − g_eff) of every body i at the solve in `trial`, aᵢ its centre of mass' acceleration
/// Σⱼ (uⱼ × (cᵢ − pⱼ)) q̈ⱼ over the coordinates carrying it plus the bias acceleration of cᵢ (N).
pub(super) fn body_forces(model: &Model, trial: &Dynamics) -> Vec<Vector3<f64>> {
    let kin = &trial.kin;
    let g_eff = trial.effective_gravity();
    (0..model.bodies.len())
        .map(|b| {
            let frame = model.body_coord[b];
            let c = kin.com[b];
            let mut a = point_bias_acceleration(kin, Some(frame), &c);
            let mut j = Some(frame);
            while let Some(jj) = j {
                a += kin.axis[jj].cross(&(c - kin.pivot[jj])) * trial.qddot[jj];
                j = model.coords[jj].parent;
            }
            model.bodies[b].mass * (a - g_eff)
        })
        .collect()
}

/// The forces of a locked solve that each tree joint passes to its subtree.
pub(super) struct SubtreeLoads {
    /// fₖ of every tree coordinate k: the Σ mᵢ(aᵢ − g_eff) of the bodies it carries less the
    /// closure forces λ on its subtree's side of each loop's point rows (N).
    subtree: Vec<Vector3<f64>>,
}

impl SubtreeLoads {
    /// From the solve in `trial` (q̈, λ and the kinematics of its state, its velocities and
    /// bias accelerations included, which the articulated-body path fills as well).
    pub(super) fn new(model: &Model, trial: &Dynamics) -> Self {
        // Every fₖ at once: each body's load added along its frame's path to the ground, each
        // loop's point force λ along its two frames' paths (−λ on the parent's side, +λ on the
        // child's; the common part cancels), O((bodies + loops) × depth).
        let mut subtree = vec![Vector3::zeros(); model.dof()];
        let mut add_along = |frame: Option<usize>, v: Vector3<f64>| {
            let mut j = frame;
            while let Some(jj) = j {
                subtree[jj] += v;
                j = model.coords[jj].parent;
            }
        };
        for (b, f) in body_forces(model, trial).iter().enumerate() {
            add_along(Some(model.body_coord[b]), *f);
        }
        for cl in &model.closures {
            let closing = &model.interfaces[cl.interface];
            let lambda: Vector3<f64> = trial.lambda.fixed_rows::<3>(cl.first_row).into_owned();
            add_along(model.frame_of(closing.parent), -lambda);
            add_along(Some(model.body_coord[closing.child]), lambda);
        }
        Self { subtree }
    }

    /// Tree coordinate k's reaction rₖ′ on its other pivot P′, from its reaction `r` on the
    /// current one (0 for a joint that rocks): rₖ′ = rₖ + t·fₖ, t = u × (P − P′). Also returns
    /// the round-off of the correction (1e-9 |t| |fₖ|).
    pub(super) fn other_side_reaction(
        &self,
        model: &Model,
        trial: &Dynamics,
        pivots: &ActivePivots,
        k: usize,
        r: f64,
    ) -> (f64, f64) {
        let kin = &trial.kin;
        let force = &self.subtree[k];
        let coord = &model.coords[k];
        let iface = &model.interfaces[coord.interface];
        let pivot = frame_point(kin, coord.parent, &other_pivot_rest(iface, pivots, k));
        let shift = kin.axis[k].cross(&(kin.pivot[k] - pivot));
        (r + shift.dot(force), 1e-9 * shift.norm() * force.norm())
    }
}

impl Simulation<'_> {
    /// The uplift test's workspace (give it back to `spare.trial` after use).
    pub(super) fn take_trial(&mut self) -> Box<Dynamics> {
        self.spare
            .trial
            .take()
            .unwrap_or_else(|| Box::new(self.dynamics.clone()))
    }

    /// Releases seated slots if the seated state cannot hold now. On open chains a decision
    /// releases the strongest single opening of each part, and a release changes the loads on
    /// the joints left seated (a drum column whose third bed opens at an impact can need the
    /// fourth to open too, on its other pivot), so the test is repeated on what remains until
    /// it holds (at most once per slot). On loops the decision is taken for all the seated
    /// slots together (the contact program, or the active set) and is not repeated: releasing
    /// one slot at a time there cascades through joints that the joint decision keeps seated.
    /// Returns every slot released, with its side.
    pub(super) fn release_if_opening(
        &mut self,
    ) -> Result<Option<Vec<(usize, Side)>>, SimulationError> {
        let mut released: Option<Vec<(usize, Side)>> = None;
        for _ in 0..self.model.slot_count {
            match self.release_once()? {
                Some(mode) => released.get_or_insert_with(Vec::new).extend(mode),
                None => break,
            }
            if !self.model.closures.is_empty() {
                break;
            }
        }
        Ok(released)
    }

    /// The faces among `lifting` (names of the chain's interfaces) that carry the bodies
    /// `in_flight`, when the flight the contact program finds comes early: each body in flight
    /// is carried by one of them, each of them is a face whose pivot's normal force is watched
    /// by an event ([`pressing_faces`]), and that force, from the chain's solve at the current
    /// state, still presses beyond the event's zero and its own round-off. In motion only (at
    /// rest the program's mechanism stands). The program reads which contacts hold from its
    /// interior point's forces and accelerations, and a force below about √(its tolerance) of
    /// the structure's weight is zero to it: a block on one pivot was found flying 65 µs early
    /// on the bundled wall, with 5.6e-5 of its weight still pressing by Newton's second law.
    pub(super) fn early_flight(
        &mut self,
        lifting: &[String],
        in_flight: &[String],
    ) -> Option<Vec<String>> {
        if self.at_rest() {
            return None;
        }
        let model = Arc::clone(&self.model);
        let pressing = self.pressing_faces_now();
        let watched: Vec<usize> = pressing
            .iter()
            .copied()
            .filter(|&k| lifting.contains(&model.interfaces[model.coords[k].interface].name))
            .collect();
        // Every watched lifting face that carries a body in flight (all of them, so that the
        // answer does not depend on the order the faces are listed in), and each body carried
        // by one.
        let flying: Vec<usize> = in_flight
            .iter()
            .map(|name| model.body_index(name))
            .collect::<Option<_>>()?;
        let carries = |k: usize, b: usize| model.carries(k, Some(model.body_coord[b]));
        let slots: Vec<usize> = watched
            .iter()
            .copied()
            .filter(|&k| flying.iter().any(|&b| carries(k, b)))
            .collect();
        if !flying.iter().all(|&b| slots.iter().any(|&k| carries(k, b))) {
            return None;
        }
        if slots.is_empty() || !self.pressing_now(&slots)?.iter().all(|&p| p) {
            return None;
        }
        Some(
            slots
                .iter()
                .map(|&k| model.interfaces[model.coords[k].interface].name.clone())
                .collect(),
        )
    }

    /// The dynamics the pivots' normal forces are solved with ([`pressing_forces`]): the spare
    /// one kept between uses, loaded with the current pivots and seats, solved as the run's own
    /// dynamics are (on open chains by the articulated-body algorithm, without forming M; give
    /// it back to `spare.pressing` after use).
    pub(super) fn take_pressing_trial(&mut self) -> Box<Dynamics> {
        match self.spare.pressing.take() {
            Some(mut d) => {
                d.pivots.clone_from(&self.dynamics.pivots);
                d.seated.clone_from(&self.dynamics.seated);
                d
            }
            None => Box::new(self.dynamics.clone()),
        }
    }

    /// The faces whose pivots' normal forces are watched now ([`pressing_faces`]).
    pub(super) fn pressing_faces_now(&self) -> Vec<usize> {
        let watched = self.original.symmetries.is_empty() && self.regularised.is_none();
        let (pivots, seated) = (&self.dynamics.pivots, &self.seated);
        pressing_faces(&self.model, pivots, seated, &self.open.turned, watched)
    }

    /// Whether the pivot of each face of `slots` ([`pressing_faces`]) presses at the current
    /// state, beyond the event's zero ([`crr_dynamics::integrator::EVENT_ZERO_TOL`]) and the
    /// round-off of its normal force; None where the chain's solve fails.
    pub(super) fn pressing_now(&mut self, slots: &[usize]) -> Option<Vec<bool>> {
        let model = Arc::clone(&self.model);
        let (q, qdot) = (self.chain_q(), self.chain_qdot());
        let mut trial = self.take_pressing_trial();
        let (mut forces, mut roundoff) = (vec![0.0; slots.len()], vec![0.0; slots.len()]);
        let state = (self.t, &q, &qdot);
        let pivots = &self.dynamics.pivots;
        let solved = pressing_forces(
            &model,
            self.ground,
            &mut trial,
            pivots,
            slots,
            state,
            &mut forces,
            Some(&mut roundoff),
        );
        self.spare.pressing = Some(trial);
        let zero = crr_dynamics::integrator::EVENT_ZERO_TOL;
        solved.then(|| {
            forces
                .iter()
                .zip(&roundoff)
                .map(|(&f, &e)| f > zero + e)
                .collect()
        })
    }

    /// A face held on its pivot for its flight event ([`Self::early_flight`]) whose pivot
    /// no longer presses where a segment starts (the program's other releases, made with the
    /// face held, changed its load): its flight is now (its event, starting at or below its
    /// zero, would never fire). Among `pressing`, the faces watched in that segment.
    pub(super) fn held_face_pulling(&mut self, pressing: &[usize]) -> Option<usize> {
        let held: Vec<usize> = pressing
            .iter()
            .copied()
            .filter(|&k| {
                self.spare
                    .rest
                    .held_faces
                    .contains(&self.model.coords[k].interface)
            })
            .collect();
        if held.is_empty() {
            return None;
        }
        let pressed = self.pressing_now(&held)?;
        // The first by name among those pulling: the same face whatever the file's order.
        let name = |k: usize| &self.model.interfaces[self.model.coords[k].interface].name;
        held.iter()
            .zip(pressed)
            .filter(|(_, p)| !p)
            .map(|(&k, _)| k)
            .min_by(|&a, &b| name(a).cmp(name(b)))
    }

    /// Keeps the faces `names` (the chain's interfaces) on their pivots in the contact program
    /// until the next impact or landing.
    fn hold_faces(&mut self, names: &[String]) {
        for name in names {
            if let Some(k) = self.model.interface_index(name)
                && !self.spare.rest.held_faces.contains(&k)
            {
                self.spare.rest.held_faces.push(k);
            }
        }
    }

    /// One round of [`Self::release_if_opening`].
    fn release_once(&mut self) -> Result<Option<Vec<(usize, Side)>>, SimulationError> {
        if self.dynamics.seated.is_empty() {
            // Nothing to release; but a structure at rest on its pivots alone (let go from a
            // tilt) may be thrown off the ground, its motion pulling there (`thrown_off`).
            let (q, qdot) = (self.chain_q(), self.chain_qdot());
            let rate_scale = (self.model.gravity / self.model.size).sqrt();
            if qdot.amax() <= 1e-12 * rate_scale
                && let Some(interfaces) = thrown_off(
                    &self.model,
                    self.ground,
                    &self.dynamics,
                    &[],
                    (self.t, &q, &qdot),
                )
            {
                let in_flight = bodies_without_support(&self.model, &interfaces);
                return Err(SimulationError::LiftOff {
                    t: self.t,
                    reason: super::flight_words(&in_flight),
                    in_flight,
                    interfaces,
                });
            }
            return Ok(None);
        }
        let (q, qdot) = (self.chain_q(), self.chain_qdot());
        let mut trial = self.take_trial();
        self.spare.rest.lift_off = None;
        self.spare.rest.thrown_off = false;
        self.spare.rest.grazing.clear();
        let mode = opening_mode_in(
            &self.model,
            self.ground,
            &self.dynamics,
            &mut trial,
            &mut self.spare.rest,
            &self.parts.of_slot,
            self.t,
            &q,
            &qdot,
        );
        self.spare.trial = Some(trial);
        let mut mode = mode;
        if let Some(interfaces) = self.spare.rest.lift_off.take() {
            let in_flight = bodies_without_support(&self.model, &interfaces);
            // Joints that slide in contact in the mechanism, offered as faces that open
            // (`followable_collapse`): held at rest unless the chain without them opens them.
            let grazing = std::mem::take(&mut self.spare.rest.grazing);
            if !grazing.is_empty() && !in_flight.is_empty() {
                return Ok(self.hold_on_grazing(grazing, &q));
            }
            // Thrown off the ground: every body flies, no face is held for a pivot event.
            let thrown = std::mem::take(&mut self.spare.rest.thrown_off);
            // The proposal's other joints and sides, by the file's slots (the chain changes).
            let proposal: Vec<(usize, Side)> = mode
                .iter()
                .flatten()
                .map(|&(s, side)| (self.open.original_slot(s), side))
                .collect();
            let from_rest = self.at_rest();
            // The faces open and the chain without them (its tree grown again where needed)
            // decides again; a body left without support is outside the model.
            let mut contradicted = false;
            let reason = if in_flight.is_empty() {
                let offered: &[(usize, Side)] = if grazing.is_empty() { &[] } else { &proposal };
                match self.release_faces(&interfaces, offered) {
                    FaceRelease::Released => {
                        let released = self.release_once()?;
                        if released.is_some() || !from_rest {
                            return Ok(released);
                        }
                        return self.release_mechanism(&proposal);
                    }
                    _ if !grazing.is_empty() => return Ok(self.hold_on_grazing(grazing, &q)),
                    FaceRelease::Impossible(why) => Some(format!(
                        "every body keeps a support through other contacts, but no chain of \
                         the CRR model is left without them ({why})"
                    )),
                    release @ (FaceRelease::Contradicted | FaceRelease::Ties) => {
                        // Faces that do not move stay closed without a record: no point would
                        // leave or be driven in, no hypothesis is at stake.
                        contradicted = matches!(release, FaceRelease::Contradicted);
                        // A face rocking on one pivot stays on it, and a face that ties stays
                        // seated: the program leaves its lift out until the next impact or
                        // landing (else its answer would stay "opens" and the uplift event
                        // could not fire again for the other joints).
                        for name in &interfaces {
                            if let Some(k) = self.model.interface_index(name)
                                && (!contradicted
                                    || !self.model.interfaces[k]
                                        .slots
                                        .clone()
                                        .any(|s| self.seated[s]))
                                && !self.spare.rest.held_faces.contains(&k)
                            {
                                self.spare.rest.held_faces.push(k);
                            }
                        }
                        None
                    }
                    FaceRelease::Unsolved => None,
                }
            } else if !thrown && let Some(carrying) = self.early_flight(&interfaces, &in_flight) {
                // The faces carrying the bodies in flight, whose pivots' normal forces the
                // chain's exact solve still finds pressing, stay on their pivots: their events
                // locate the flight where those forces reach zero. With other faces lifting
                // too, the decision is taken again with those held (in motion).
                self.hold_faces(&carrying);
                if carrying.len() < interfaces.len() {
                    return self.release_once();
                }
                None
            } else {
                Some(super::flight_words(&in_flight))
            };
            if let Some(reason) = reason {
                return Err(SimulationError::LiftOff {
                    t: self.t,
                    in_flight,
                    interfaces,
                    reason,
                });
            }
            // The faces stay closed. The program's other releases belong to the motion in which
            // they lift off (its lifted faces still hold their slip rows, module `opening_qp`):
            // with the faces closed they stand only where the chain's exact solve opens them.
            let model = Arc::clone(&self.model);
            let lifting = |s: usize| {
                interfaces
                    .iter()
                    .any(|name| model.interfaces[slot_interface(&model, s)].name == *name)
            };
            let others: Vec<(usize, Side)> = mode
                .unwrap_or_default()
                .into_iter()
                .filter(|&(s, _)| !lifting(s))
                .collect();
            // Where none does, the chain decides alone with the faces closed (single releases
            // and the active set; at rest Gauss' principle over the sides), the faces' own
            // slots held: without a release nothing would ask again while the program keeps its
            // answer (the uplift event stays on).
            let tol = 1e-9 * model.gravity / model.size;
            let mut trial = self.take_trial();
            mode = confirmed_releases(
                &model,
                self.ground,
                &self.dynamics,
                &mut trial,
                others,
                self.t,
                &q,
                &qdot,
                tol,
                &mut self.spare.rest.doubtful,
            )
            .flatten()
            .or_else(|| {
                let with_program = false;
                opening_mode_local(
                    &model,
                    self.ground,
                    &self.dynamics,
                    &mut trial,
                    &mut self.spare.rest,
                    &self.parts.of_slot,
                    self.t,
                    &q,
                    &qdot,
                    with_program,
                )
                .map(|m| {
                    m.into_iter()
                        .filter(|&(s, _)| !lifting(s))
                        .collect::<Vec<_>>()
                })
                .filter(|m| !m.is_empty())
            });
            self.spare.trial = Some(trial);
            if mode.is_none() && contradicted {
                self.record_undecided_lift_off(&interfaces);
            }
        }
        if let Some(mode) = &mode {
            self.apply_release(mode)?;
        }
        Ok(mode)
    }

    /// A structure at rest in `q` held on the joints `grazing` of a mechanism, which slide in
    /// contact carrying nothing and which the chain without them does not open
    /// ([`followable_collapse`]): the instant is recorded as `sliding_unloaded`, the set held at
    /// that state without asking again, and nothing is released.
    fn hold_on_grazing(
        &mut self,
        grazing: Vec<String>,
        q: &DVector<f64>,
    ) -> Option<Vec<(usize, Side)>> {
        let refused = &mut self.spare.rest.grazing_refused;
        if refused.len() >= GRAZING_REFUSALS {
            refused.remove(0);
        }
        let a = self.ground.acceleration(self.t);
        refused.push((grazing.clone(), grazing_key(q, &a)));
        self.spare.rest.sliding_unloaded.push((self.t, grazing));
        None
    }

    /// The releases of an uplift event ([`Self::release_if_opening`]): one ends the row of
    /// events without a release; none extends it, and the run stops with
    /// [`SimulationError::Undecided`] at the [`super::UNDECIDED_UPLIFTS`]th (the test would fire
    /// again at once, one step of round-off later, for ever).
    pub(super) fn release_at_uplift_event(
        &mut self,
    ) -> Result<Option<Vec<(usize, Side)>>, SimulationError> {
        let mode = self.release_if_opening()?;
        if mode.is_some() {
            self.undecided.end();
            return Ok(mode);
        }
        let Some(error) = self.undecided.extend(self.t) else {
            return Ok(None);
        };
        self.record_final_sample();
        Err(error)
    }

    /// Every slot seated and every rate within 1e-12 of the rate scale √(g/L): the structure
    /// at rest.
    pub(super) fn at_rest(&self) -> bool {
        let n = self.model.dof();
        let rate_scale = (self.model.gravity / self.model.size).sqrt();
        self.seated.iter().all(|&s| s)
            && self.y[n..2 * n]
                .iter()
                .all(|v| v.abs() <= 1e-12 * rate_scale)
    }

    /// Faces that lifted off from rest where the chain without them finds no opening of its own:
    /// at the crossing of the collapse multiplier the load is 1e-9 of λ_c above the structure's
    /// multiplier, and the chain's own test (the same mechanism, its multiplier equal to the
    /// structure's to round-off) keeps the threshold's margin. The mechanism's other joints
    /// (`proposal`, by the file's slots) open on their sides where the chain's exact solve opens
    /// them by any positive acceleration, as they do at the crossing without a lift-off
    /// ([`opening_mode_in`]); otherwise nothing moves, the faces rest on their supports, close
    /// again, and lift off again at the same instant, over and over.
    fn release_mechanism(
        &mut self,
        proposal: &[(usize, Side)],
    ) -> Result<Option<Vec<(usize, Side)>>, SimulationError> {
        let proposed: Vec<(usize, Side)> = proposal
            .iter()
            .filter_map(|&(file_slot, side)| Some((self.open.active_slot(file_slot)?, side)))
            .filter(|&(s, _)| self.seated[s])
            .collect();
        // Checked by the chain's exact solve without the margin: each must open on its side
        // (by any positive acceleration); one that the chain holds goes back to its seat.
        let (q, qdot) = (self.chain_q(), self.chain_qdot());
        let mut trial = self.take_trial();
        let mode = confirmed_releases(
            &self.model,
            self.ground,
            &self.dynamics,
            &mut trial,
            proposed,
            self.t,
            &q,
            &qdot,
            0.0,
            &mut self.spare.rest.doubtful,
        )
        .flatten();
        self.spare.trial = Some(trial);
        let Some(mode) = mode else {
            return Ok(None);
        };
        self.apply_release(&mode)?;
        Ok(Some(mode))
    }

    /// Releases the slots of `mode` on their sides (see [`Self::release_once`]).
    fn apply_release(&mut self, mode: &[(usize, Side)]) -> Result<(), SimulationError> {
        // The structure leaves rest only when every joint was seated: a joint seated at an
        // impact and released at once while others rock (the end of free rocking) is no
        // uplift of the structure (`uplift_time` stays null for a run released from rest
        // angles).
        let from_rest = self.seated.iter().all(|&s| s);
        let n = self.model.dof();
        let twisting_flip = mode.iter().any(|&(s, side)| {
            side != self.dynamics.pivots.sides[s] && is_twisting_closure_slot(&self.model, s)
        });
        for &(s, side) in mode {
            self.dynamics.pivots.sides[s] = side;
            // A seated angle leaves its seat from exactly 0: the state can still carry the
            // round-off of the step that seated it (−1.9e-9 rad on the drum column), which
            // on the other pivot would be the wrong side of it.
            if s < n {
                self.y[s] = 0.0;
                self.y[n + s] = 0.0;
            }
        }
        self.set_seated(mode.iter().map(|&(s, _)| (s, false)));
        if twisting_flip {
            let released: Vec<usize> = mode.iter().map(|&(s, _)| s).collect();
            self.close_loops_after_a_twisting_flip(&released)?;
        }
        if from_rest {
            self.uplift_time.get_or_insert(self.t);
        }
        self.reset_solver();
        Ok(())
    }

    /// The contact program lifts `interfaces` off, the chain without them drives them back into
    /// their supports, and with them closed no release the engine tries opens (the program's
    /// others, the chain's single releases and active set): the engine finds no motion that
    /// keeps every contact compressive, and the program's own needs the faces to slide along
    /// their supports while they lift. The run goes on with the faces closed, as after a
    /// hypotheses monitor's violation, and this is recorded as its first violation if none came
    /// before (kind `lift_off`, the face first by name; no force is computed: N = 0, |F_t|/N undefined,
    /// infinite as for a tension). The faces and the time are kept for
    /// [`SimulationError::Undecided`] in any case.
    fn record_undecided_lift_off(&mut self, interfaces: &[String]) {
        self.undecided.contradicted(self.t, interfaces);
        if self.violation.is_some() {
            return;
        }
        // The first name in alphabetical order: the same face whatever order the file lists
        // the lifting faces in.
        let Some(first) = interfaces.iter().min() else {
            return;
        };
        self.violation = Some(crate::monitor::Violation {
            t: self.t,
            interface: first.clone(),
            kind: "lift_off".to_string(),
            normal: 0.0,
            friction_demand: f64::INFINITY,
            hop: None,
        });
        self.snaps_at_violation = Some(super::SnapsAndLosses {
            t: self.t,
            snaps: self.energy_at_snaps,
            lost: self.lost_at_impacts() + self.dissipated_by_forces(),
        });
    }

    /// A seat that may twist, turned to its other pivot corner: the child's face has turned
    /// about the normal on the old corner by its twist τ, so its new corner lies |P′ − P|·τ from
    /// the parent's (a second-order offset: τ is of the order of the product of the tilts).
    /// The loop is closed again on the new corner here, positions then velocities (least
    /// change, the seated tree coordinates and the ones just `released` held: they leave their
    /// seats from exactly 0), and the change of T + U that this costs is booked as dissipated,
    /// as the snaps at impacts are: otherwise the integrator's projection after its next step
    /// makes the same correction unbooked (on the bundled temple, 2e-9 rad and 1.7 mJ of the
    /// energy balance per flip).
    fn close_loops_after_a_twisting_flip(
        &mut self,
        released: &[usize],
    ) -> Result<(), SimulationError> {
        let model = Arc::clone(&self.model);
        let model = &*model;
        let n = model.dof();
        let (mut q, mut qdot) = (self.chain_q(), self.chain_qdot());
        let seated = self.seated.clone();
        let mut kin = self
            .spare
            .events_kin
            .take()
            .unwrap_or_else(|| Box::new(Data::new(model)));
        let pivots = &self.dynamics.pivots;
        let (t_before, u_before) = state_energies(model, &mut kin, pivots, &q, &qdot);
        let snapped = snap_to_seats(
            model,
            &mut kin,
            pivots,
            &mut q,
            &mut qdot,
            |k| seated[k],
            |k| released.contains(&k),
        );
        self.spare.events_kin = Some(kin);
        let (t_after, u_after) = snapped.map_err(|e| SimulationError::Dynamics {
            t: self.t,
            source: e,
        })?;
        self.book_snap(t_before + u_before - t_after - u_after);
        self.y[..n].copy_from_slice(q.as_slice());
        self.y[n..2 * n].copy_from_slice(qdot.as_slice());
        Ok(())
    }

    /// At rest with every tree coordinate seated nothing moves (q = 0 on the seated angles,
    /// q̇ = 0, hence Ẇ = 0) until the seated state cannot hold: instead of integrating a
    /// constant state, the uplift test is evaluated on a time grid up to `t_stop` and its first
    /// failure located by bisection to 1e-13·max(1, t), the precision of the integrator's event
    /// location. The grid is the integrator's step cap while seated ([`SEATED_MAX_STEP`]), or
    /// the whole interval when the test cannot change inside it: after the ground motion ends,
    /// and while the ground motion is affine in t (records between samples). On open chains each
    /// single release's opening acceleration at rest is linear in g_eff(t) and, once past its
    /// threshold inside the interval, stays past it to the end. With loops, the loads a
    /// structure at rest carries form a convex set (static theorem: an equilibrium with
    /// compressive contacts exists, a convex condition on the load), so a structure that holds
    /// at both ends of a segment of g_eff holds along it. Output samples of the
    /// interval are recorded. Returns None (nothing done) unless every tree coordinate is seated.
    pub(super) fn rest_until_uplift(
        &mut self,
        t_stop: f64,
    ) -> Result<Option<StopReason>, SimulationError> {
        let model = Arc::clone(&self.model);
        let model = &*model;
        let n = model.dof();
        if !self.seated[..n].iter().all(|&s| s) || self.t >= t_stop {
            return Ok(None);
        }
        // Seated coordinates are held at exactly 0 with rate 0 (projection after every step).
        for k in 0..n {
            self.y[k] = 0.0;
            self.y[n + k] = 0.0;
        }
        let (q, qdot) = (self.chain_q(), self.chain_qdot());
        let mut trial = self.take_trial();
        let mut rest = std::mem::take(&mut self.spare.rest);
        let (ground, template, parts) = (self.ground, &self.dynamics, &self.parts.of_slot);
        let mut opens = |t: f64| {
            opening_mode_in(
                model, ground, template, &mut trial, &mut rest, parts, t, &q, &qdot,
            )
            .is_some()
        };
        let mut found = None;
        let mut t0 = self.t;
        // An interrupt read after each grid interval (the first always runs) ends the rest at
        // the last instant known to hold.
        let mut interrupted_at = None;
        while t0 < t_stop {
            if t0 > self.t && self.solver.interrupted() {
                interrupted_at = Some(t0);
                break;
            }
            let whole = ground.duration() <= t0 || ground.is_affine_on(t0, t_stop);
            let t1 = if whole {
                t_stop
            } else {
                (t0 + seated_step(ground)).min(t_stop)
            };
            if opens(t1) {
                let (mut lo, mut hi) = (t0, t1);
                while hi - lo > 1e-13 * hi.abs().max(1.0) {
                    let mid = 0.5 * (lo + hi);
                    if opens(mid) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                found = Some((lo, hi));
                break;
            }
            t0 = t1;
        }
        self.spare.trial = Some(trial);
        self.spare.rest = rest;
        let t_end = interrupted_at.unwrap_or(found.map_or(t_stop, |(_, hi)| hi));
        let dt = self.params.output_interval;
        let y = self.y.clone();
        // The samples at rest: up to the last instant known to hold where the structure
        // uplifts. A sample in the uplift's bracket is left to the motion that follows: the
        // load there may already be past the threshold (a pulse that starts at a sample's
        // instant), where the seated structure would be judged pulling.
        let at_rest = |ts: f64| match found {
            Some((lo, _)) => ts <= lo,
            None => ts <= t_end + 1e-12 * dt,
        };
        while at_rest((self.next_sample as f64) * dt)
            && (self.next_sample as f64) * dt <= self.params.duration + 1e-12 * dt
        {
            // A grid instant up to round-off past the segment's end (a breakpoint, where the
            // load may jump) is judged under the load at that end.
            let ts = self.next_sample as f64 * dt;
            let s = self.sample_under_load_at(ts, ts.min(t_end), &y);
            self.record_sample(s);
            self.next_sample += 1;
        }
        self.t = t_end;
        self.reset_solver();
        if let Some(t) = interrupted_at {
            self.record_final_sample();
            return Err(SimulationError::Cancelled { t });
        }
        if found.is_some()
            && let Some(mode) = self.release_at_uplift_event()?
        {
            return Ok(Some(StopReason::Uplift(self.t, self.file_slots(mode))));
        }
        if self.t >= self.params.duration {
            self.finished = true;
            if self.last_sample_t < self.t {
                let s = self.sample_at(self.t, &y);
                self.record_sample(s);
            }
            return Ok(Some(StopReason::End(self.t)));
        }
        Ok(Some(StopReason::Breakpoint(self.t)))
    }

    /// Seats rocking joints that sit at φ ≈ 0 with a negligible rate while their acceleration
    /// points into their closed side (they cannot open on that side; left alone they would slip
    /// through the contact without a crossing to detect). They may then uplift on the other side.
    pub(super) fn settle_resting_joints(&mut self) -> Result<Option<f64>, SimulationError> {
        // The run's workspaces (given back whatever the outcome).
        let mut kin = self
            .spare
            .events_kin
            .take()
            .unwrap_or_else(|| Box::new(Data::new(&self.model)));
        let mut d = self.take_trial();
        let mut buffers = self.spare.settle.take().unwrap_or_default();
        let chain = self.chain_changes;
        let result = self.settle_resting_joints_in(&mut d, &mut kin, &mut buffers);
        // A face that opened in there changed the chain and its workspaces.
        if self.chain_changes == chain {
            self.spare.events_kin = Some(kin);
            self.spare.trial = Some(d);
            self.spare.settle = Some(buffers);
        }
        result
    }

    /// [`Self::settle_resting_joints`] with the workspaces `d` (its pivots and seated slots are
    /// set here), `kin` and `buffers`.
    fn settle_resting_joints_in(
        &mut self,
        d: &mut Dynamics,
        kin: &mut Data,
        buffers: &mut SettleBuffers,
    ) -> Result<Option<f64>, SimulationError> {
        let model = Arc::clone(&self.model);
        let model = &*model;
        let n = model.dof();
        let SettleBuffers {
            q,
            qdot,
            angles,
            rates,
            candidates,
            row,
        } = buffers;
        if q.len() != n {
            *q = DVector::zeros(n);
            *qdot = DVector::zeros(n);
            *row = DVector::zeros(n);
        }
        copy_short(q.as_mut_slice(), &self.y[..n]);
        copy_short(qdot.as_mut_slice(), &self.y[n..2 * n]);
        let (q, qdot) = (&*q, &*qdot);
        angles.clear();
        angles.resize(model.slot_count, 0.0);
        slot_angles(model, kin, q, &self.dynamics.pivots, angles);
        candidates.clear();
        candidates.extend(
            (0..model.slot_count)
                .filter(|&s| !self.seated[s] && angles[s].abs() <= self.params.simultaneity),
        );
        if candidates.is_empty() {
            return Ok(None);
        }
        d.pivots.clone_from(&self.dynamics.pivots);
        d.seated.clone_from(&self.dynamics.seated);
        d.accelerations(model, self.ground, self.t, q, qdot)
            .map_err(|e| SimulationError::Dynamics {
                t: self.t,
                source: e,
            })?;
        rates.clear();
        rates.resize(model.slot_count, 0.0);
        slot_rates(model, &d.kin, qdot, rates);
        // A joint leaving φ = 0 against its acceleration returns after τ = 2|φ̇|/|φ̈|: the
        // segment is capped at τ/2 (the turning point) so the return is a plain sign change.
        let mut cap: Option<f64> = None;
        for &s in candidates.iter() {
            let bias = slot_row(model, &d.kin, s, row);
            let acc = row.dot(&d.qddot) + bias;
            let side = self.dynamics.pivots.sides[s].sign();
            if side * rates[s] > 0.0 && side * acc < 0.0 {
                let tau = 2.0 * rates[s].abs() / acc.abs();
                cap = Some(cap.map_or(0.5 * tau, |c: f64| c.min(0.5 * tau)));
            }
        }
        let closing: Vec<usize> = candidates
            .iter()
            .copied()
            .filter(|&s| {
                let bias = slot_row(model, &d.kin, s, row);
                let acc = row.dot(&d.qddot) + bias;
                let side = self.dynamics.pivots.sides[s].sign();
                rates[s].abs() < self.params.seat_rate
                    && side * rates[s] <= 1e-12
                    && side * acc <= 0.0
            })
            .collect();
        if closing.is_empty() {
            return Ok(cap);
        }
        let held: Vec<usize> = (0..model.slot_count)
            .filter(|&s| self.seated[s] || closing.contains(&s))
            .collect();
        // Seating is rare: its projection gets a workspace of its own.
        let (qd, kinetic) = plastic_projection(
            model,
            &mut self.dynamics.clone(),
            self.ground,
            self.t,
            q,
            qdot,
            &self.dynamics.pivots,
            &held,
        )?;
        d.ensure_mass_matrix(model);
        let before = 0.5 * qdot.dot(&(&d.kin.mass_matrix * qdot));
        let u_before = potential_energy(model, &d.kin);
        // Seating removes the kinetic energy of the stopped joints (booked as dissipated); the
        // snap of their residual angles (below `simultaneity`) to exactly 0, with the loops
        // closed again, positions then velocities, changes T + U further: booked too, and
        // tallied as a snap.
        let (mut q_new, mut qd_new) = (self.chain_q(), qd);
        let seated = &self.seated;
        let (t_after, u_after) = snap_to_seats(
            model,
            kin,
            &self.dynamics.pivots,
            &mut q_new,
            &mut qd_new,
            |k| seated[k] || closing.contains(&k),
            |_| false,
        )
        .map_err(|source| SimulationError::Dynamics { t: self.t, source })?;
        self.dissipated_at_impacts += before - kinetic;
        self.book_snap(kinetic - t_after + u_before - u_after);
        let n = model.dof();
        self.y[..n].copy_from_slice(q_new.as_slice());
        self.y[n..2 * n].copy_from_slice(qd_new.as_slice());
        self.set_seated(closing.iter().map(|&s| (s, true)));
        self.reset_solver();
        self.release_if_opening()?;
        Ok(None)
    }
}

/// Uplift events in a row that released nothing ([`SimulationError::Undecided`]), each within
/// [`super::UNDECIDED_GAP`]·max(1, t) of the one before; a release or an impact ends the row.
#[derive(Clone, Debug)]
pub(super) struct UndecidedRow {
    /// Events in the row (0: no row).
    count: u32,
    /// Time of the row's first event and of its last (s).
    first: f64,
    last: f64,
    /// Time of the last contradicted lift-off and its faces, by name in alphabetical order.
    contradicted: (f64, Vec<String>),
}

impl Default for UndecidedRow {
    fn default() -> Self {
        UndecidedRow {
            count: 0,
            first: f64::NEG_INFINITY,
            last: f64::NEG_INFINITY,
            contradicted: (f64::NEG_INFINITY, Vec::new()),
        }
    }
}

impl UndecidedRow {
    /// A release or an impact: the row ends.
    pub(super) fn end(&mut self) {
        self.count = 0;
    }

    /// A lift-off of `faces` contradicted at `t`, named in the error if the row reaches its
    /// limit (sorted, so that the message does not depend on the order of the file).
    pub(super) fn contradicted(&mut self, t: f64, faces: &[String]) {
        let mut faces = faces.to_vec();
        faces.sort();
        self.contradicted = (t, faces);
    }

    /// An event without a release at `t`: it continues the row when it follows the last within
    /// the gap, else starts one; the error once the row counts [`super::UNDECIDED_UPLIFTS`].
    fn extend(&mut self, t: f64) -> Option<SimulationError> {
        if self.count == 0 || t - self.last > super::UNDECIDED_GAP * t.abs().max(1.0) {
            (self.count, self.first) = (0, t);
        }
        self.count += 1;
        self.last = t;
        (self.count >= super::UNDECIDED_UPLIFTS).then(|| SimulationError::Undecided {
            t,
            events: self.count,
            span: t - self.first,
            // The faces of a lift-off contradicted during these events, not an earlier one.
            interfaces: if self.contradicted.0 >= self.first {
                self.contradicted.1.clone()
            } else {
                Vec::new()
            },
        })
    }
}

#[cfg(test)]
mod other_side_tests {
    //! The reaction of a seated joint on its other pivot, rₖ′ = rₖ + t·fₖ (subtree forces), against
    //! the flipped chain's own equations of motion: its kinematics, M′, h′, Q′ and Φ′_q evaluated
    //! anew, and row k of M′q̈ + h′ − Q′ − Φ′_qᵀλ − Σ ρₛ row′ₛ with the locked solve's q̈, λ and
    //! seat reactions ρ (any consistent set of multipliers gives the same value).
    use nalgebra::DVector;

    use crr_dynamics::eom::{Dynamics, slot_row};
    use crr_dynamics::ground_motion::GroundMotion;
    use crr_kinematics::fixtures::{
        SplitMix, colonnade, four_hinge_arch, random_chain, skew_four_hinge_loop, trilithon,
    };
    use crr_kinematics::{ActivePivots, Model, Side};

    use super::SubtreeLoads;

    /// Row k of the equations of motion of `d` (evaluated) at q̈, λ and the seat reactions of
    /// `locked` (seated closure slots only: tree coordinates' rows are unit rows).
    fn generalized_reaction(model: &Model, d: &Dynamics, locked: &Dynamics, k: usize) -> f64 {
        let n = model.dof();
        let m = &d.kin.mass_matrix;
        let mut r: f64 = (0..n).map(|j| m[(k, j)] * locked.qddot[j]).sum::<f64>()
            + d.kin.velocity_product[k]
            - d.load[k];
        for row in 0..model.constraint_rows {
            r -= d.kin.phi_q[(row, k)] * locked.lambda[row];
        }
        let mut row = DVector::zeros(n);
        for (i, &s) in locked.seated.iter().enumerate() {
            if s >= n {
                slot_row(model, &d.kin, s, &mut row);
                r -= row[k] * locked.seat_reactions[i];
            }
        }
        r
    }

    /// Every slot on a random side.
    fn random_pivots(model: &Model, rng: &mut SplitMix) -> ActivePivots {
        let mut pivots = ActivePivots::uniform(model, Side::Positive);
        for s in pivots.sides.iter_mut() {
            *s = if rng.uniform(0.0, 1.0) < 0.5 {
                Side::Positive
            } else {
                Side::Negative
            };
        }
        pivots
    }

    /// Compares every seated reaction the filter computes; returns how many, and how many of
    /// them had another slot of their interface free.
    fn check(model: &Model, seed: u64) -> (usize, usize) {
        let n = model.dof();
        let mut rng = SplitMix(seed);
        let ground = GroundMotion::none();
        let pivots = random_pivots(model, &mut rng);
        // Seat whole interfaces (every slot of a rocking base), or one tilt of a rocking base
        // while the other rocks, about half of them.
        let mut seated = Vec::new();
        for iface in &model.interfaces {
            let u = rng.uniform(0.0, 1.0);
            if u < 0.4 {
                seated.extend(iface.slots.clone());
            } else if u < 0.7 {
                seated.push(iface.slots.start + rng.below(iface.slots.len()));
            }
        }
        // Free tree coordinates tilted (the loops then close only approximately, which the
        // identity does not need), and rates that keep the loops closed to first order and the
        // seated slots at rest: a random combination of the null space of [Φ_q; seated rows].
        let q = DVector::from_fn(n, |k, _| {
            if seated.contains(&k) {
                0.0
            } else {
                rng.uniform(-0.05, 0.05)
            }
        });
        let mut at_rest = Dynamics::new(model, pivots.clone());
        at_rest.evaluate(model, &ground, 0.0, &q, &DVector::zeros(n));
        let mut is_seated = vec![false; model.slot_count];
        for &s in &seated {
            is_seated[s] = true;
        }
        let mut rows: Vec<DVector<f64>> = (0..model.constraint_rows)
            .map(|r| at_rest.kin.phi_q.row(r).transpose())
            .collect();
        for &s in &seated {
            let mut row = DVector::zeros(n);
            slot_row(model, &at_rest.kin, s, &mut row);
            rows.push(row);
        }
        let mut qdot = DVector::zeros(n);
        if rows.is_empty() {
            qdot = DVector::from_fn(n, |_, _| rng.uniform(-0.3, 0.3));
        } else {
            let b = nalgebra::DMatrix::from_rows(
                &rows.iter().map(|r| r.transpose()).collect::<Vec<_>>(),
            );
            let full = b.transpose() * &b;
            let eig = full.symmetric_eigen();
            let top = eig.eigenvalues.amax().max(1e-300);
            for (i, &l) in eig.eigenvalues.iter().enumerate() {
                if l <= 1e-12 * top {
                    qdot += eig.eigenvectors.column(i) * rng.uniform(-0.3, 0.3);
                }
            }
        }
        let mut locked = Dynamics::new(model, pivots.clone());
        locked.seated = seated.clone();
        if locked
            .accelerations(model, &ground, 0.0, &q, &qdot)
            .is_err()
        {
            return (0, 0);
        }
        let scale = locked.seat_reactions.amax().max(1.0);
        // The seated slots are held (q̈ₖ = 0), which the identity needs.
        for &k in seated.iter().filter(|&&k| k < n) {
            assert!(
                locked.qddot[k].abs() <= 1e-9,
                "{}: q̈ = {}",
                model.slot_name(k),
                locked.qddot[k]
            );
        }
        let loads = SubtreeLoads::new(model, &locked);
        let (mut checked, mut partial) = (0, 0);
        for (i, &k) in seated.iter().enumerate() {
            if k >= n || super::flip_moves_a_free_axis(model, &locked, &pivots, &is_seated, k) {
                continue;
            }
            // The generalized route on the current chain gives the solve's own reaction.
            let mut same = Dynamics::new(model, pivots.clone());
            same.evaluate(model, &ground, 0.0, &q, &qdot);
            if iface_partly_seated(model, &is_seated, k) {
                partial += 1;
            }
            let r_same = generalized_reaction(model, &same, &locked, k);
            assert!(
                (r_same - locked.seat_reactions[i]).abs() <= 1e-9 * scale,
                "{}: {r_same} against the solve's {}",
                model.slot_name(k),
                locked.seat_reactions[i]
            );
            let mut flipped_pivots = pivots.clone();
            flipped_pivots.sides[k] = pivots.sides[k].flipped();
            let mut flipped = Dynamics::new(model, flipped_pivots);
            flipped.evaluate(model, &ground, 0.0, &q, &qdot);
            let expected = generalized_reaction(model, &flipped, &locked, k);
            let (r_other, _) =
                loads.other_side_reaction(model, &locked, &pivots, k, locked.seat_reactions[i]);
            assert!(
                (r_other - expected).abs() <= 1e-9 * scale,
                "{}: subtree forces give {r_other}, the flipped chain {expected}",
                model.slot_name(k)
            );
            checked += 1;
        }
        (checked, partial)
    }

    fn iface_partly_seated(model: &Model, is_seated: &[bool], k: usize) -> bool {
        let iface = &model.interfaces[model.coords[k].interface];
        iface.slots.clone().any(|s| !is_seated[s])
    }

    /// A seated closure angle's reaction on its other pivot against the power of the held
    /// solve's generalized constraint force τ = M q̈ + h − Q on the motion that releases it there:
    /// δq from the flipped closure's own rows (point rows at P′, the other rows as they are) with
    /// a unit rate of the released angle, by least squares; cases where the release adds no
    /// motion (the rows inconsistent) are skipped. Returns how many were compared.
    fn check_closure_slots(model: &Model, seed: u64) -> usize {
        let n = model.dof();
        let mut rng = SplitMix(seed);
        let ground = GroundMotion::none();
        let pivots = random_pivots(model, &mut rng);
        let mut seated: Vec<usize> = Vec::new();
        for iface in &model.interfaces {
            if iface.slots.start >= n || rng.uniform(0.0, 1.0) < 0.15 {
                seated.extend(iface.slots.clone());
            }
        }
        let q = DVector::zeros(n);
        let mut locked = Dynamics::new(model, pivots.clone());
        locked.seated = seated.clone();
        if locked.accelerations(model, &ground, 0.0, &q, &q).is_err() {
            return 0;
        }
        let m = &locked.kin.mass_matrix;
        let tau = m * &locked.qddot + &locked.kin.velocity_product - &locked.load;
        let mut compared = 0;
        for (i, &k) in seated.iter().enumerate() {
            if k < n {
                continue;
            }
            let Some((r_other, _)) = super::closure_other_side_reaction(
                model,
                &locked,
                &pivots,
                k,
                locked.seat_reactions[i],
            ) else {
                continue;
            };
            let mut flipped_pivots = pivots.clone();
            flipped_pivots.sides[k] = pivots.sides[k].flipped();
            let mut flipped = Dynamics::new(model, flipped_pivots);
            flipped.evaluate(model, &ground, 0.0, &q, &q);
            let mut rows: Vec<DVector<f64>> = (0..model.constraint_rows)
                .map(|r| flipped.kin.phi_q.row(r).transpose())
                .collect();
            let mut row = DVector::zeros(n);
            for &s in seated.iter().filter(|&&s| s != k) {
                slot_row(model, &flipped.kin, s, &mut row);
                rows.push(row.clone());
            }
            slot_row(model, &flipped.kin, k, &mut row);
            rows.push(row.clone());
            let a = nalgebra::DMatrix::from_rows(
                &rows.iter().map(|r| r.transpose()).collect::<Vec<_>>(),
            );
            let mut b = DVector::zeros(rows.len());
            b[rows.len() - 1] = 1.0;
            let dq = a.clone().svd(true, true).solve(&b, 1e-10).unwrap();
            if (&a * &dq - &b).amax() > 1e-8 {
                continue;
            }
            let expected = dq.dot(&tau);
            let scale = locked
                .seat_reactions
                .amax()
                .max(locked.lambda.amax() * model.size);
            assert!(
                (r_other - expected).abs() <= 1e-8 * scale,
                "{}: the formula gives {r_other}, the power on the released motion {expected}",
                model.slot_name(k)
            );
            compared += 1;
        }
        compared
    }

    #[test]
    fn closure_angle_reaction_is_the_power_on_the_released_motion() {
        // Loops that move when a closure angle is released (random closed chains are mostly
        // locked): the trilithon, four-hinge arches, a skew four-hinge loop, the colonnade.
        let models = [
            trilithon(0.3, 2.0, 3.0, 0.5, 1.0),
            four_hinge_arch(3.0, 3.6, 1.0, false),
            four_hinge_arch(3.0, 3.6, 1.0, true),
            skew_four_hinge_loop(),
            colonnade(0.3, 2.0, 1.5, 0.4),
        ];
        let mut compared = 0;
        for spec in &models {
            let model = Model::from_spec(spec).unwrap();
            for seed in 0..20 {
                compared += check_closure_slots(&model, seed);
            }
        }
        assert!(compared > 30, "only {compared} closure angles compared");
    }

    #[test]
    fn other_pivot_reaction_matches_the_flipped_chain() {
        let (mut checked, mut partial) = (0, 0);
        for seed in 0..40 {
            let model = Model::from_spec(&random_chain(seed, 6, 2)).unwrap();
            let (c, p) = check(&model, 1000 + seed);
            checked += c;
            partial += p;
        }
        let model = Model::from_spec(&colonnade(0.3, 2.0, 1.5, 0.4)).unwrap();
        for seed in 0..10 {
            let (c, p) = check(&model, seed);
            checked += c;
            partial += p;
        }
        assert!(checked > 100, "only {checked} reactions compared");
        assert!(partial > 20, "only {partial} with the other tilt free");
    }

    /// The subtree forces of every tree coordinate, summed at once along the paths to the
    /// ground, equal their definition summed here per coordinate over subtree membership (the
    /// bodies it carries, less λ on the point rows of each loop with one side in its subtree),
    /// on random chains with loops and the colonnade at tilted, moving states, to 1e-12 of the
    /// largest.
    #[test]
    fn subtree_forces_at_once_match_the_per_coordinate_sums() {
        let mut compared = 0;
        let models: Vec<Model> = (0..12)
            .map(|seed| Model::from_spec(&random_chain(seed, 6, 2)).unwrap())
            .chain(std::iter::once(
                Model::from_spec(&colonnade(0.3, 2.0, 1.5, 0.4)).unwrap(),
            ))
            .collect();
        for (i, model) in models.iter().enumerate() {
            let n = model.dof();
            let mut rng = SplitMix(77 + i as u64);
            let pivots = random_pivots(model, &mut rng);
            let q = DVector::from_fn(n, |_, _| rng.uniform(-0.05, 0.05));
            let qdot = DVector::from_fn(n, |_, _| rng.uniform(-0.3, 0.3));
            let mut d = Dynamics::new(model, pivots.clone());
            if d.accelerations(model, &GroundMotion::none(), 0.0, &q, &qdot)
                .is_err()
                || d.used_articulated_body()
            {
                continue;
            }
            let loads = SubtreeLoads::new(model, &d);
            let body_force = super::body_forces(model, &d);
            let per_coordinate: Vec<nalgebra::Vector3<f64>> = (0..n)
                .map(|k| {
                    let in_subtree = |frame: Option<usize>| model.carries(k, frame);
                    let mut force = nalgebra::Vector3::zeros();
                    for (b, f) in body_force.iter().enumerate() {
                        if in_subtree(Some(model.body_coord[b])) {
                            force += f;
                        }
                    }
                    for cl in &model.closures {
                        let closing = &model.interfaces[cl.interface];
                        let a_side = in_subtree(model.frame_of(closing.parent));
                        let b_side = in_subtree(Some(model.body_coord[closing.child]));
                        let share = f64::from(u8::from(a_side)) - f64::from(u8::from(b_side));
                        force -= share * d.lambda.fixed_rows::<3>(cl.first_row);
                    }
                    force
                })
                .collect();
            let largest = per_coordinate
                .iter()
                .map(|f| f.norm())
                .fold(1e-300, f64::max);
            for k in 0..n {
                assert!(
                    (per_coordinate[k] - loads.subtree[k]).norm() <= 1e-12 * largest,
                    "model {i}, coordinate {k}: {} against {}",
                    per_coordinate[k],
                    loads.subtree[k]
                );
                compared += 1;
            }
        }
        assert!(compared > 60, "only {compared} coordinates compared");
    }
}
