//! The collapse multiplier of a structure at rest by the static theorem of limit analysis, posed
//! on the contact faces as one linear (or second-order cone) program with one global answer.
//!
//! **Load.** Gravity g (along −z) plus a constant ground acceleration λ g d: in the frame of the
//! ground every body n carries its weight Mⁿg and the inertial load −λ Mⁿ g d at its centre of
//! mass. d is any unit direction (horizontal, or with a vertical part).
//!
//! **Statics.** Every interface's contact face ([`crr_kinematics::ContactFace`]) carries at each
//! contact point a force f = fₙn + f₁t₁ + f₂t₂ from the parent on the child, with fₙ ≥ 0 (no
//! tension); a hinge also carries the couples out of its plane (it is a line). Friction is
//! either unlimited (no sliding, the CRR hypothesis), a pyramid |f_k| ≤ μfₙ on each tangent, or
//! the exact cone ‖(f₁, f₂)‖ ≤ μfₙ. The static theorem (Heyman 1966; Livesley 1978 for blocks):
//! the structure holds under λ if an equilibrium of every body with admissible contact forces
//! exists. The admissible (f, λ) form a convex set, so the collapse multiplier
//!
//!   λ_c = max λ subject to  equilibrium of every body,  fₙ ≥ 0,  friction,
//!
//! is a linear program (a second-order cone program with the exact cone), solved by the interior
//! point method of `clarabel` (Goulart & Chen 2024). Its answer does not depend on the order of
//! the bodies, the interfaces or the corners of a face, and mirror-symmetric structures give the
//! same λ in mirrored directions.
//!
//! **Mechanism.** The dual variables of the equilibrium rows are a virtual velocity (v, ω) of
//! every body (the kinematic theorem): at every contact point the gap rate n·(v_child − v_parent)
//! is ≥ 0 and vanishes where the point carries a force, no point slides where friction is
//! unlimited, and the load's virtual power is positive. An interface whose points all keep
//! contact is closed; one that keeps some points rocks about them (its pivot sides are the signs
//! of the relative rotation about its axes, the CRR chain's sides); one that keeps none lifts off,
//! which the CRR chain does not represent.

use nalgebra::Vector3;
use serde::Serialize;

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use crr_dynamics::Cancel;
use crr_kinematics::{ContactFace, InterfaceKind, Model, Parent, Side};

mod closure;
mod precision;
mod unloaded_sets;
mod wedges;

/// Largest multiplier sought by default (a ground acceleration of 10 g): a structure that holds
/// beyond it is reported as holding.
pub const LAMBDA_MAX: f64 = 10.0;

/// Relative size below which a gap rate, slip rate or relative rotation of the mechanism counts
/// as zero (against the mechanism's largest).
pub const MECHANISM_TOLERANCE: f64 = 1e-6;

/// Friction at the contact points.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Friction {
    /// No sliding at any load (the CRR hypothesis: the tangential forces are unlimited).
    NoSliding,
    /// Coulomb friction μ as a pyramid: |f_k| ≤ μ fₙ on each tangent (exact for planar loads).
    Pyramid(f64),
    /// Coulomb friction μ as the exact cone ‖(f₁, f₂)‖ ≤ μ fₙ.
    Cone(f64),
}

/// Most sets of joints that may open and slide that the exhaustive pass tries
/// ([`collapse_multiplier`]; counted before any program, each one to three programs): beyond
/// them the search answers alone, marked as not exhaustive.
pub const EXHAUSTIVE_SETS: usize = 4096;

/// Options of [`collapse_multiplier`].
#[derive(Clone, Debug, PartialEq)]
pub struct StaticsOptions {
    /// Friction at the contact points.
    pub friction: Friction,
    /// The multiplier beyond which the structure is reported as holding.
    pub lambda_max: f64,
    /// Without sliding: also seek mechanisms in which a block lifts off a support while sliding
    /// over it (see [`collapse_multiplier`]). `false` gives the convex program alone.
    pub sliding_lift_off: bool,
    /// With `sliding_lift_off`: the most sets of joints that may open and slide the exhaustive
    /// pass tries; beyond them the search answers alone ([`Collapse::exhaustive`] false).
    pub exhaustive_sets: usize,
    /// A request to stop, polled before every linear program: once set,
    /// [`collapse_multiplier`] returns [`StaticsError::Interrupted`] after the program under
    /// way (the search and the exhaustive pass run hundreds to thousands of them on a wall).
    pub cancel: Option<Cancel>,
}

/// Whether `options` ask to stop.
fn interrupted(options: &StaticsOptions) -> bool {
    options.cancel.as_ref().is_some_and(Cancel::is_cancelled)
}

impl Default for StaticsOptions {
    fn default() -> Self {
        StaticsOptions {
            friction: Friction::NoSliding,
            lambda_max: LAMBDA_MAX,
            sliding_lift_off: true,
            exhaustive_sets: EXHAUSTIVE_SETS,
            cancel: None,
        }
    }
}

/// Friction coefficients of the probes that look for sliding lift-offs (largest first).
const PROBE_FRICTION: [f64; 4] = [2.0, 1.0, 0.5, 0.25];

/// The search for sliding lift-offs tries pairs of the probes' interfaces where no set and no
/// single interface lowers λ, up to this many interfaces (at most 66 programs a round).
const PAIRS_UP_TO: usize = 12;

/// The interior-point solver's settings, tried in turn until one gives a verdict (solved or
/// infeasible): the program's own (gaps and feasibility to 1e-12), then, where the solver stalls
/// in round-off (`NumericalError`), more iterations and refinement steps with tolerances of
/// 1e-10, then 1e-11 without equilibration. The friction the multiplier of an arch of 200
/// voussoirs near its minimum thickness needs asks whether it stands without friction; the
/// program's own settings stopped there with a `NumericalError` and `crr check` gave no
/// multiplier at all; the third settings find it infeasible, as it is (an independent review).
/// Tolerances of 1e-10 lie far below the 1e-7 the multipliers are checked to.
struct SolverAttempt {
    tolerance: f64,
    max_iter: u32,
    refinement_steps: u32,
    equilibrate: bool,
}

/// The solver's attempts at the model's precision ([`Precision::Model`]): its answers are
/// compared at [`EQUILIBRIUM_RESIDUAL`], so gaps of 1e-9 are ample, and its residual bounds set
/// a scale 1e-5 apart from the forces that 1e-12 does not reach.
const SOLVER_ATTEMPTS_AT_PRECISION: [SolverAttempt; 2] = [
    SolverAttempt {
        tolerance: 1e-9,
        max_iter: 400,
        refinement_steps: 10,
        equilibrate: true,
    },
    SolverAttempt {
        tolerance: 1e-8,
        max_iter: 1000,
        refinement_steps: 50,
        equilibrate: false,
    },
];

const SOLVER_ATTEMPTS: [SolverAttempt; 3] = [
    SolverAttempt {
        tolerance: 1e-12,
        max_iter: 400,
        refinement_steps: 10,
        equilibrate: true,
    },
    SolverAttempt {
        tolerance: 1e-10,
        max_iter: 1000,
        refinement_steps: 50,
        equilibrate: true,
    },
    SolverAttempt {
        tolerance: 1e-11,
        max_iter: 1000,
        refinement_steps: 50,
        equilibrate: false,
    },
];

/// Most rounds of the search for sliding lift-offs (each frees at least one interface).
const LIFT_OFF_ROUNDS: usize = 8;

/// What is wrong with a statics question.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StaticsError {
    /// The load direction is not a non-zero finite vector.
    #[error("direction ({0}, {1}, {2}) is not a non-zero finite vector")]
    Direction(f64, f64, f64),
    /// A friction coefficient that is negative or not finite.
    #[error("friction coefficient {0} is not a finite number ≥ 0")]
    Friction(f64),
    /// The structure has no admissible equilibrium under gravity alone.
    #[error(
        "the structure does not hold at rest without ground motion (no equilibrium with compressive contacts{0})"
    )]
    DoesNotHold(String),
    /// The solver did not reach an answer.
    #[error("the linear program of the statics did not solve: {0}")]
    Solver(String),
    /// [`StaticsOptions::cancel`] was set: no answer.
    #[error("interrupted")]
    Interrupted,
}

/// The force of one contact point (N, from the parent on the child).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PointForce {
    /// The point (m, world at rest).
    pub point: [f64; 3],
    /// Normal force fₙ (compression positive; a pin's component along its face's n).
    pub normal: f64,
    /// Tangential components (f₁, f₂) along the face's tangents.
    pub tangential: [f64; 2],
}

/// How an interface moves in the mechanism.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Motion {
    /// Every contact point keeps contact and nothing slides.
    Closed,
    /// It rocks about the points that keep contact.
    Rocks,
    /// Every contact point separates: the child lifts off the parent (outside the CRR chain).
    LiftsOff,
    /// It slides (with finite friction only; outside the CRR chain).
    Slides,
}

/// One interface in the collapse: its forces at λ_c and its motion in the mechanism.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InterfaceCollapse {
    /// Index into [`Model::interfaces`].
    pub interface: usize,
    /// The interface's name.
    pub name: String,
    /// Contact forces at λ_c (N).
    pub forces: Vec<PointForce>,
    /// The couple about the face's normal n (N m, from the parent on the child) that no point
    /// force carries: a rocking base loaded at a single corner that does not turn about n (a
    /// rocking base cannot twist) carries it as that constraint's reaction, with no friction
    /// to do so, so a collapse that relies on it needs unbounded friction. 0 elsewhere (a hinge's
    /// couples are not reported).
    pub twist: f64,
    /// How it moves.
    pub motion: Motion,
    /// The pivot side of each of its angles that opens (by slot index), from the sign of the
    /// relative rotation about the angle's axis; angles that do not turn are absent.
    pub sides: Vec<(usize, Side)>,
    /// Indices (into the face's points) of the points that keep contact while it moves.
    pub pivots: Vec<usize>,
    /// Gap rates n·(v_child − v_parent) of the face's points in the mechanism.
    pub gap_rates: Vec<f64>,
    /// Tangential slip rates |(v_child − v_parent)_t| of the face's points in the mechanism.
    pub slip_rates: Vec<f64>,
    /// Largest of `slip_rates` (0 without sliding).
    pub slip_rate: f64,
    /// Relative angular velocity ω_child − ω_parent in the mechanism (rad/s at unit scale).
    pub rotation: [f64; 3],
}

/// The virtual velocity of one body in the mechanism (at its centre of mass).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BodyMotion {
    /// Velocity of the centre of mass.
    pub velocity: [f64; 3],
    /// Angular velocity.
    pub angular: [f64; 3],
}

/// The answer of [`collapse_multiplier`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Collapse {
    /// Unit direction d of the ground acceleration.
    pub direction: [f64; 3],
    /// λ_c (in g), `None` when the structure holds up to the options' `lambda_max`.
    pub lambda: Option<f64>,
    /// Per interface, in the model's order: forces at λ_c (at `lambda_max` when it holds) and
    /// motion in the mechanism (all closed when it holds).
    pub interfaces: Vec<InterfaceCollapse>,
    /// Virtual velocities of the bodies in the mechanism, scaled so that the largest of |v| and
    /// size·|ω| over the bodies is 1 (all zero when it holds).
    pub bodies: Vec<BodyMotion>,
    /// The convex program's λ (no joint freed to slide where it opens; `None` where it holds up
    /// to `lambda_max`). Where `lambda` lies below it ([`Collapse::from_sliding_search`]),
    /// `lambda` is the search's answer for joints that open and slide: an admissible mechanism
    /// with an equilibrium at its λ on the points it keeps in contact, so the structure does not
    /// hold beyond it, but the search is not exhaustive and a lower one may exist
    /// ([`collapse_multiplier`]).
    pub convex_lambda: Option<f64>,
    /// Whether `lambda` is the least multiplier of every collapse state of the options' contact
    /// model. Always with finite friction (the convex program is that model). Without sliding,
    /// where joints that open may slide (the default): for a tree, whose convex answer is exact,
    /// and where every set of joints that may open and slide was tried (a structure with few
    /// loops); `false` where the budget of programs left the search's answer, an upper bound of
    /// the multiplier (a lower mechanism may exist), and for the convex program alone
    /// (`sliding_lift_off: false`) on a structure with loops. In a 3D model, a face that keeps a
    /// single loaded corner and twists about it is outside both passes.
    pub exhaustive: bool,
    /// Why `exhaustive` is false (`None` where it is true).
    pub unexhausted: Option<Unexhausted>,
}

/// Why a collapse multiplier is not exhaustive ([`Collapse::exhaustive`]): why not every set of
/// joints that may open and slide was tried.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Unexhausted {
    /// The structure has more such sets than the options' `exhaustive_sets`.
    TooManySets,
    /// A program of the exhaustive pass failed to solve (the solver's status).
    SolverFailed(String),
    /// Only the convex program was asked (`sliding_lift_off: false`) on a structure with loops.
    ConvexOnly,
    /// Coulomb friction was asked on a structure with loops: the search for joints that open
    /// and slide runs without a friction limit only, so with friction λ is the convex
    /// program's (an upper bound: a mechanism in which a joint opens while others slide within
    /// the friction may open lower).
    WithFriction,
}

impl Unexhausted {
    fn failed(error: StaticsError) -> Self {
        match error {
            StaticsError::Solver(status) => Unexhausted::SolverFailed(status),
            other => Unexhausted::SolverFailed(other.to_string()),
        }
    }
}

impl Collapse {
    /// Whether λ comes from the search for joints that open and slide (below the convex answer,
    /// or where the convex program holds up to the cap).
    pub fn from_sliding_search(&self) -> bool {
        match (self.lambda, self.convex_lambda) {
            (Some(l), Some(c)) => l < c,
            (Some(_), None) => true,
            (None, _) => false,
        }
    }

    /// The interfaces that lift off in the mechanism.
    pub fn lifting_off(&self) -> impl Iterator<Item = &InterfaceCollapse> {
        self.interfaces
            .iter()
            .filter(|i| i.motion == Motion::LiftsOff)
    }

    /// The interfaces that slide in the mechanism while some of their points keep contact
    /// (carrying nothing: a joint freed by the search for joints that open and slide), which
    /// the CRR chain, whose joints do not slide, cannot follow. Empty for the convex program's
    /// mechanisms without friction (nothing slides in them).
    pub fn sliding_in_contact(&self) -> impl Iterator<Item = &InterfaceCollapse> {
        self.interfaces
            .iter()
            .filter(|i| i.motion != Motion::LiftsOff && i.slip_rate > MECHANISM_TOLERANCE)
    }
}

/// `direction` made unit; an error for a zero or non-finite one. Scaled by its largest component
/// first, so that a direction of tiny or huge components (1e-300, 1e300) is a direction: its
/// norm alone would underflow to 0 or overflow.
fn unit_direction(direction: Vector3<f64>) -> Result<Vector3<f64>, StaticsError> {
    let largest = direction.amax();
    let scaled = direction / largest;
    let norm = scaled.norm();
    if largest.is_finite() && largest > 0.0 && norm.is_finite() {
        Ok(scaled / norm)
    } else {
        Err(StaticsError::Direction(
            direction.x,
            direction.y,
            direction.z,
        ))
    }
}

/// The collapse multiplier of `model` at rest under gravity plus a constant ground acceleration
/// λ g `direction` (see the module's docs).
pub fn collapse_multiplier(
    model: &Model,
    direction: Vector3<f64>,
    options: &StaticsOptions,
) -> Result<Collapse, StaticsError> {
    let answer = collapse_multiplier_uninterrupted(model, direction, options);
    // Once interrupted, every program that follows fails at once and the search and the pass
    // take what they have: an answer computed so is no answer.
    if interrupted(options) {
        return Err(StaticsError::Interrupted);
    }
    answer
}

/// [`collapse_multiplier`] before its answer is checked for an interruption.
fn collapse_multiplier_uninterrupted(
    model: &Model,
    direction: Vector3<f64>,
    options: &StaticsOptions,
) -> Result<Collapse, StaticsError> {
    let d = unit_direction(direction)?;
    if let Friction::Pyramid(mu) | Friction::Cone(mu) = options.friction
        && !(mu.is_finite() && mu >= 0.0)
    {
        return Err(StaticsError::Friction(mu));
    }
    let faces = precision::faces_at_precision(model);
    let mut free = vec![false; faces.len()];
    let convex = solve_program(model, &faces, d, options, &free, &[])?;
    // A tree has no interface that a collapse state may unload: the convex answer is exact.
    let candidates = unloaded_sets::candidates(model, &faces);
    if options.friction != Friction::NoSliding {
        let tree = candidates.is_empty();
        return Ok(Collapse {
            exhaustive: tree,
            unexhausted: (!tree).then_some(Unexhausted::WithFriction),
            ..convex
        });
    }
    if candidates.is_empty() {
        return Ok(Collapse {
            exhaustive: true,
            unexhausted: None,
            ..convex
        });
    }
    if !options.sliding_lift_off {
        return Ok(convex);
    }
    // The search first: its answer bounds the exhaustive pass, which prunes more below a
    // lower bound, and answers where the pass is over its budget.
    let searched = sliding_lift_offs(model, &faces, d, options, &mut free, convex)?;
    let best_lambda = searched.lambda.unwrap_or(options.lambda_max);
    let convex_lambda = searched.convex_lambda;
    Ok(
        match unloaded_sets::least_collapse(
            model,
            &faces,
            &candidates,
            d,
            options,
            searched.clone(),
            best_lambda,
        ) {
            Ok(least) => Collapse {
                convex_lambda,
                exhaustive: true,
                unexhausted: None,
                ..least
            },
            Err(why) => Collapse {
                unexhausted: Some(why),
                ..searched
            },
        },
    )
}

/// Most sets that [`exhaustive_sets_needed`] counts (about 0.04 s of counting; the pass would
/// take about 30 s per direction on them, at 0.3 ms a set on walls of a few courses).
pub const COUNTED_SETS: usize = 100_000;

/// How many sets of joints that may open and slide the exhaustive pass would try for the answer
/// `collapse` (the search's, along its direction), counted without a program: the
/// `exhaustive_sets` that makes it exhaustive (with the default `lambda_max`). `None` beyond
/// `most`, or where the structure has no pass to run (a tree).
pub fn exhaustive_sets_needed(model: &Model, collapse: &Collapse, most: usize) -> Option<usize> {
    let d = unit_direction(Vector3::from(collapse.direction)).ok()?;
    let faces = precision::faces_at_precision(model);
    let candidates = unloaded_sets::candidates(model, &faces);
    // A structure that holds: the pass runs below the cap.
    let lambda = collapse.lambda.unwrap_or(LAMBDA_MAX);
    if candidates.is_empty() {
        return None;
    }
    unloaded_sets::count(
        model,
        &faces,
        &candidates,
        d,
        collapse.clone(),
        lambda,
        most,
    )
}

/// A hinge's load out of its plane at a multiplier: a hinge is a line, which transmits any
/// force along its axis u and any couple not about u, with no geometry to limit them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HingeOutOfPlane {
    /// Index into [`Model::interfaces`].
    pub interface: usize,
    /// The interface's name.
    pub name: String,
    /// |F·u|, the force along the axis (N).
    pub axial: f64,
    /// |M − (M·u)u|, the couple out of the hinge's plane (N m), about its first pivot point.
    pub couple: f64,
}

/// The hinges that every distribution of the contact forces at multiplier `lambda` along
/// `direction` loads out of their plane (above 1e-6 of W or W·L, W the weight, L the model
/// size): the program with λ fixed at lambda·(1 − 1e-7) (inside its feasible interval
/// [0, λ_c]) and ½Σx² of the hinges' out-of-plane unknowns (their bilateral couples and their
/// forces along the axis) minimised, so that a hinge is named only where no
/// distribution spares it, not where the interior point's central answer happens to load it.
/// Each one's load is its wrench about its first pivot point in that distribution. Empty for a
/// model without hinges. Errors as [`collapse_multiplier`]'s.
pub fn hinges_out_of_plane(
    model: &Model,
    direction: Vector3<f64>,
    options: &StaticsOptions,
    lambda: f64,
) -> Result<Vec<HingeOutOfPlane>, StaticsError> {
    let is_hinge = |k: usize| matches!(model.interfaces[k].kind, InterfaceKind::Hinge { .. });
    if !(0..model.interfaces.len()).any(is_hinge) {
        return Ok(Vec::new());
    }
    let d = unit_direction(direction)?;
    let faces = precision::faces_at_precision(model);
    let free = vec![false; faces.len()];
    let program = Program::build(model, &faces, d, options, &free, &[], &[], Precision::Exact);
    let columns: Vec<usize> = program
        .unknowns
        .iter()
        .enumerate()
        .filter(|(_, u)| {
            is_hinge(u.interface)
                && u.at.is_none_or(|_| {
                    let axis = faces[u.interface].tangents[1];
                    u.direction.dot(&axis).abs() > 1.0 - 1e-12
                })
        })
        .map(|(j, _)| j + 1)
        .collect();
    let solution = program.solve_least(lambda.max(0.0) * (1.0 - 1e-7), &columns)?;
    let (weight, size) = (program.weight, model.size);
    let mut loaded = Vec::new();
    for face in faces.iter().filter(|f| is_hinge(f.interface)) {
        let axis = face.tangents[1];
        let origin = face.points[0];
        let (mut force, mut moment) = (Vector3::zeros(), Vector3::zeros());
        for (j, u) in program.unknowns.iter().enumerate() {
            if u.interface != face.interface {
                continue;
            }
            let value = weight * solution.x[j + 1];
            match u.at {
                Some(x) => {
                    let f = u.direction * value;
                    force += f;
                    moment += (x - origin).cross(&f);
                }
                // The couples' rows are M/(W·L) with entries direction/L: x is C/W.
                None => moment += u.direction * value,
            }
        }
        let axial = force.dot(&axis).abs();
        let couple = (moment - axis * moment.dot(&axis)).norm();
        if axial > 1e-6 * weight || couple > 1e-6 * weight * size {
            loaded.push(HingeOutOfPlane {
                interface: face.interface,
                name: model.interfaces[face.interface].name.clone(),
                axial,
                couple,
            });
        }
    }
    Ok(loaded)
}

/// One program: `free` marks the interfaces whose points carry normal forces only (they may
/// slide where they separate); the points `unloaded` ((interface, point)) carry no force at all.
fn solve_program(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    free: &[bool],
    unloaded: &[(usize, usize)],
) -> Result<Collapse, StaticsError> {
    solve_program_at(model, faces, d, options, free, unloaded, Precision::Exact)
}

/// [`solve_program`] as written or at the model's precision ([`Precision`]).
fn solve_program_at(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    free: &[bool],
    unloaded: &[(usize, usize)],
    precision: Precision,
) -> Result<Collapse, StaticsError> {
    solve_built(
        model,
        faces,
        d,
        options,
        &Program::build(model, faces, d, options, free, unloaded, &[], precision),
    )
}

/// [`solve_program`] on a program built.
fn solve_built(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    program: &Program,
) -> Result<Collapse, StaticsError> {
    let solution = program.solve()?;
    answer_of(model, faces, d, options, program, &solution)
}

/// Whether the solver found its program infeasible (its solution is then a certificate).
fn primal_infeasible(status: &SolverStatus) -> bool {
    matches!(
        status,
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible
    )
}

/// A solution of the solver as an answer: `DoesNotHold` where it is a certificate of
/// infeasibility (no equilibrium at any λ).
fn no_certificate(
    solution: clarabel::solver::DefaultSolution<f64>,
) -> Result<clarabel::solver::DefaultSolution<f64>, StaticsError> {
    if primal_infeasible(&solution.status) {
        return Err(StaticsError::DoesNotHold(String::new()));
    }
    Ok(solution)
}

/// The least λ a program's answer may have and still hold: below it, the structure would need
/// the load reversed (a structure balanced exactly on an edge answers λ = 0 within the solver's
/// round-off).
const HOLDS_FROM: f64 = -1e-9;

/// The collapse a program's solution describes, or `DoesNotHold` where its λ is negative.
fn answer_of(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    program: &Program,
    solution: &clarabel::solver::DefaultSolution<f64>,
) -> Result<Collapse, StaticsError> {
    let lambda = solution.x[0];
    if lambda < HOLDS_FROM {
        return Err(StaticsError::DoesNotHold(format!(
            ": it would need a ground acceleration of {:.6} g along ({}, {}, {})",
            -lambda,
            -d.x + 0.0,
            -d.y + 0.0,
            -d.z + 0.0
        )));
    }
    Ok(program.collapse(model, faces, d, options, solution))
}

/// A program of the exhaustive pass solved as written and, where that answer falls short of
/// λ = `needed` (no equilibrium, an error of the solver, or a smaller λ), again at the model's
/// precision ([`Precision::Model`]), unless the dual of the answer as written already shows that
/// the program at the model's precision falls short too ([`Program::reach_at_precision`]): most
/// sets the pass drops have no equilibrium by far more than round-off, and their second program
/// cost 2.6 s of the 8.9 s of CPU of `crr check` on the bundled wall.
#[allow(clippy::too_many_arguments)]
fn solve_to_precision(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    free: &[bool],
    unloaded: &[(usize, usize)],
    twist_reactions: &[usize],
    needed: f64,
) -> Result<Collapse, StaticsError> {
    let build = |precision| {
        Program::build(
            model,
            faces,
            d,
            options,
            free,
            unloaded,
            twist_reactions,
            precision,
        )
    };
    let written = build(Precision::Exact);
    let (answer, reach) = match written.solve_verdict() {
        Ok(solution) => {
            let reach = written.reach_at_precision(&solution);
            let answer = if primal_infeasible(&solution.status) {
                Err(StaticsError::DoesNotHold(String::new()))
            } else {
                answer_of(model, faces, d, options, &written, &solution)
            };
            (answer, reach)
        }
        Err(StaticsError::Interrupted) => return Err(StaticsError::Interrupted),
        Err(e) => (Err(e), f64::INFINITY),
    };
    let reached = answer
        .as_ref()
        .is_ok_and(|c| c.lambda.is_none_or(|l| l >= needed));
    if reached || reach < needed {
        return answer;
    }
    solve_built(model, faces, d, options, &build(Precision::Model))
}

/// The search for mechanisms in which a block lifts off a support while sliding over it.
///
/// Without sliding, the convex program lets a contact carry shear with no compression (the
/// closure of the friction cone as μ → ∞), and its mechanisms separate contacts only along their
/// normal. A real joint that opens carries nothing and may slide: the corner wedge of a wall in
/// running bond (an end half block and the block over it turning about the half block's outer
/// foot, the block over it leaving its other support sideways) opens below the convex answer.
/// This freedom (non-associated: the separated joint's slip does no work against friction) makes
/// the problem non-convex. Its mechanisms are admissible in the convex program with a finite
/// friction μ wherever their separation exceeds μ times their slip, so probes with
/// μ = 2, 1, 0.5, 0.25 find candidates: the interfaces that separate at every point and slide
/// in a probe's mechanism are freed (normal forces only) and the program without sliding is solved
/// again. A candidate is kept when its λ is lower and its mechanism is physical: every point of
/// a freed interface that slides either separates or carries no force in an equilibrium at that
/// λ (a compressed point cannot slide; see [`physical`]). The search also runs where the convex
/// program holds up to the cap: a block against a pier, turning about its far foot, slides up
/// the pier at its lowest edge while the rest of that face opens, and overturns at b/h. Each
/// round first tries rigid wedges ([`wedges`]: on each support, the set of blocks turning as one
/// about a horizontal axis of least kinematic multiplier, found by minimum cuts: exactly where
/// no body falls on its own and the least closure is connected), whose
/// joints open and slide many at once (a running-bond wall's staircase over its end half block
/// of course 1). Then each probe's interfaces are tried freed together, each of the probes' interfaces alone and, where
/// none of those lowers λ, each pair of them; the lowest physical candidate is kept. Rounds
/// repeat until no probe lowers λ. Every answer kept is an admissible mechanism with an
/// equilibrium at its λ (an upper bound of the true multiplier, never above the convex one); the
/// search is not proved to find the lowest.
fn sliding_lift_offs(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    free: &mut Vec<bool>,
    convex: Collapse,
) -> Result<Collapse, StaticsError> {
    // Where the convex program holds up to the cap, a sliding mechanism may still open below
    // it: a block standing against a pier, turning about its far foot, slides up the pier at
    // its lowest edge (which the program without sliding forbids) while the rest of that face
    // opens, and overturns at b/h.
    let mut best_lambda = convex.lambda.unwrap_or(options.lambda_max);
    let convex_lambda = convex.lambda;
    let mut best = convex;
    for _ in 0..LIFT_OFF_ROUNDS {
        // Rigid wedges first (one program each, the search below costs many): a wedge found
        // lowers λ, so fewer probes lower it further.
        let wedge_sets: Vec<Vec<usize>> = wedges::wedges(model, faces, d, free, best_lambda)
            .into_iter()
            .map(|w| w.freed)
            .collect();
        let wedge = lowest_physical(model, faces, d, options, free, best_lambda, &wedge_sets);
        let lowered = wedge.is_some();
        if let Some((lambda, candidate, trial)) = wedge {
            best_lambda = lambda;
            best = Collapse {
                convex_lambda,
                ..candidate
            };
            *free = trial;
        }
        let probes = lowering_probes(model, faces, d, options, free, best_lambda);
        if probes.is_empty() {
            if lowered {
                continue;
            }
            break;
        }
        // The interfaces that separate and slide in some probe's mechanism, in the file's order.
        let mut opened: Vec<usize> = probes.iter().flatten().copied().collect();
        opened.sort_unstable();
        opened.dedup();
        // Each probe's interfaces freed together, then each interface alone, then (where
        // neither lowers λ) each pair: freed together they can fail the physical test (one of
        // them compressed and sliding) where one or two of them are a mechanism, a corner wedge
        // of a wall whose block leaves its other support sideways while the probe's mechanism
        // also opened a joint that must stay closed (an independent review found three-course
        // walls answered up to 44 % above their wedge's multiplier that way).
        let mut sets: Vec<Vec<usize>> = probes.into_iter().filter(|p| p.len() > 1).collect();
        sets.extend(opened.iter().map(|&i| vec![i]));
        let mut found = lowest_physical(model, faces, d, options, free, best_lambda, &sets);
        for set in sets.iter().filter(|set| set.len() > 1) {
            let lowest = found.as_ref().map_or(best_lambda, |f| f.0);
            if let Some(repaired) = repaired_set(model, faces, d, options, free, lowest, set) {
                found = Some(repaired);
            }
        }
        if found.is_none() && opened.len() <= PAIRS_UP_TO {
            let pairs: Vec<Vec<usize>> = (0..opened.len())
                .flat_map(|a| (a + 1..opened.len()).map(move |b| (a, b)))
                .map(|(a, b)| vec![opened[a], opened[b]])
                .collect();
            found = lowest_physical(model, faces, d, options, free, best_lambda, &pairs);
        }
        let Some((lambda, candidate, trial)) = found else {
            if lowered {
                continue;
            }
            break;
        };
        best_lambda = lambda;
        best = Collapse {
            convex_lambda,
            ..candidate
        };
        *free = trial;
    }
    Ok(best)
}

/// The probes with friction that lower λ below `best_lambda`, each as the interfaces its
/// mechanism separates at all their points while sliding (not yet freed, not pins; empty sets
/// left out): a probe's friction makes every point that slides separate too (its flow is
/// associated), so a face that, freed, slides at a point it keeps contact at is among them.
/// λ(μ) grows with μ: the pyramid of a larger μ holds every distribution of a smaller one, with
/// the same freed interfaces, so where the smallest probe does not lower λ, none does, and one
/// program answers for the four.
fn lowering_probes(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    free: &[bool],
    best_lambda: f64,
) -> Vec<Vec<usize>> {
    let probe_options = |mu: f64| StaticsOptions {
        friction: Friction::Pyramid(mu),
        sliding_lift_off: false,
        ..options.clone()
    };
    // (Written as the negation of "holds as high": a NaN λ counts as lowering, as it always has,
    // and goes on to the candidate's own program.)
    let lowers = |probe: &Collapse| !probe.lambda.is_none_or(|l| l >= best_lambda * (1.0 - 1e-6));
    let smallest_mu = PROBE_FRICTION.iter().copied().fold(f64::INFINITY, f64::min);
    let mut smallest = Some(solve_program(
        model,
        faces,
        d,
        &probe_options(smallest_mu),
        free,
        &[],
    ));
    if let Some(Ok(probe)) = &smallest
        && !lowers(probe)
    {
        return Vec::new();
    }
    let mut sets = Vec::new();
    for mu in PROBE_FRICTION {
        let probe = match smallest.take_if(|_| mu == smallest_mu) {
            Some(probe) => probe,
            None => solve_program(model, faces, d, &probe_options(mu), free, &[]),
        };
        let Ok(probe) = probe else {
            continue;
        };
        if !lowers(&probe) {
            continue;
        }
        let opened: Vec<usize> = probe
            .interfaces
            .iter()
            .filter(|i| {
                i.gap_rates.iter().all(|&g| g > MECHANISM_TOLERANCE)
                    && i.slip_rate > MECHANISM_TOLERANCE
                    && !free[i.interface]
                    && !faces[i.interface].pin
            })
            .map(|i| i.interface)
            .collect();
        if !opened.is_empty() {
            sets.push(opened);
        }
    }
    sets
}

/// Of the interface sets `sets`, each freed in addition to `free`, the one whose program
/// without sliding gives the lowest λ below `best_lambda` with a physical mechanism: that λ, its
/// collapse and the freed interfaces. None where no set lowers λ physically.
fn lowest_physical(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    free: &[bool],
    best_lambda: f64,
    sets: &[Vec<usize>],
) -> Option<(f64, Collapse, Vec<bool>)> {
    // Every set's program first, then the physical test (one more program each) from the
    // lowest λ up, until one passes: the test runs once where the lowest candidate is physical.
    let mut candidates: Vec<(f64, Collapse, Vec<bool>)> = Vec::new();
    for set in sets {
        let trial = freed_with(free, set);
        let Ok(candidate) = solve_program(model, faces, d, options, &trial, &[]) else {
            continue;
        };
        let Some(lambda) = candidate.lambda else {
            continue;
        };
        if lambda < best_lambda * (1.0 - 1e-9) {
            candidates.push((lambda, candidate, trial));
        }
    }
    // Stable: of equal λ, the first set in order.
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
    candidates
        .into_iter()
        .find_map(|(lambda, candidate, trial)| {
            physical(model, faces, d, options, &trial, candidate).map(|c| (lambda, c, trial))
        })
}

/// `free` with the interfaces `set` freed as well.
fn freed_with(free: &[bool], set: &[usize]) -> Vec<bool> {
    let mut trial = free.to_vec();
    for &i in set {
        trial[i] = true;
    }
    trial
}

/// Most programs of [`repaired_set`].
const REPAIRS: usize = 4;

/// A probe's interfaces `set` freed together, repaired: where the program's mechanism slides a
/// freed joint that keeps contact at every point (a compressed joint sliding, which no friction
/// allows), that joint is held again and the program solved again, up to [`REPAIRS`] times; the
/// first answer below `best_lambda` that is physical ([`physical`]) is returned. A corner wedge
/// of a running-bond wall needs three joints freed at once (its head joint, the bed it lifts off
/// and the head joint over it), which the sets of one or two joints do not reach.
fn repaired_set(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    free: &[bool],
    best_lambda: f64,
    set: &[usize],
) -> Option<(f64, Collapse, Vec<bool>)> {
    let mut trial = freed_with(free, set);
    for _ in 0..REPAIRS {
        let candidate = solve_program(model, faces, d, options, &trial, &[]).ok()?;
        let lambda = candidate.lambda?;
        let lowers = lambda < best_lambda * (1.0 - 1e-9);
        if !lowers {
            return None;
        }
        let closed_sliding: Vec<usize> = candidate
            .interfaces
            .iter()
            .filter(|i| {
                trial[i.interface]
                    && !free[i.interface]
                    && i.slip_rate > MECHANISM_TOLERANCE
                    && i.gap_rates.iter().all(|&g| g <= MECHANISM_TOLERANCE)
            })
            .map(|i| i.interface)
            .collect();
        if closed_sliding.is_empty() {
            return physical(model, faces, d, options, &trial, candidate)
                .map(|c| (lambda, c, trial));
        }
        for i in closed_sliding {
            trial[i] = false;
        }
    }
    None
}

/// Relative loss of λ within which the points that separate or slide count as unloaded at the
/// multiplier: the model's geometric precision, ten times [`crr_kinematics::GEOMETRY_TOLERANCE`]
/// (faces whose corners lie off their plane by 1e-6 of the model's size are planar to the
/// model), far above the solver's 1e-12. Two programs that differ only in contacts whose
/// geometry agrees to that precision give multipliers that differ by about as much: two blocks
/// of b/h = 2 side by side in an OBJ wall turned 30° with six decimals tip at 1.9999976 and
/// 2.000001, and 8.7e-7 between the programs with their head joint unloaded and freed counted
/// as a proof that no collapse state unloads it (at 1e-8, the exhaustive pass then answered 4,
/// the pair tipping as one, for the multiplier 2 of the same wall unturned).
const UNLOADED_TOLERANCE: f64 = 10.0 * crr_kinematics::GEOMETRY_TOLERANCE;

/// `collapse` (the program's answer with the interfaces `free` freed) as a physical collapse,
/// or None. The program without sliding lets a contact carry shear with no compression, so its
/// forces may put shear across a joint that opens, and a freed joint may slide at a point that
/// keeps contact. A physical collapse has an equilibrium at λ with forces only where the
/// mechanism keeps contact without sliding (a point that separates carries nothing, and so does
/// one that slides: a compressed point cannot). The program with every other point unloaded
/// (pins aside) is solved: where it reaches the same λ, its forces and the mechanism are a
/// primal and a dual optimum of the same program (its feasible set holds the unloaded
/// program's), so they are complementary, and its forces are reported with the mechanism.
/// Where only a freed joint's sliding points were unloaded, the façade of the bundled assemblies
/// answered 1.000484 along +x (1.001462 along −x, though it is symmetric) from a mechanism whose
/// equilibrium relied on shear across opened joints (none exists on the points that hold:
/// `tests/statics/collapse_state.rs`); it answers 65/138 both ways (its corner wedges).
fn physical(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    free: &[bool],
    collapse: Collapse,
) -> Option<Collapse> {
    physical_test(model, faces, d, options, free, collapse, false)
        .ok()
        .flatten()
}

/// [`physical`] that tells a program the solver did not solve (an error) from a collapse that
/// is not physical (None): the exhaustive pass proves that no set lowers λ only with programs
/// that solved. A failed one counted as "not physical" there made the pass answer 4 as
/// exhaustive where 2 was the multiplier (the test's program of two blocks tipping on their
/// edges, whose equilibrium exists at one λ only, stopped in `NumericalError`).
///
/// With `to_precision`, a program that falls short of λ as written is solved again at the
/// model's precision where its dual leaves room ([`solve_to_precision`]): two blocks that tip
/// at one λ written exactly tip at λ some 1e-6 apart once their corners are rounded, and no
/// exact equilibrium has both on their edges.
fn physical_test(
    model: &Model,
    faces: &[ContactFace],
    d: Vector3<f64>,
    options: &StaticsOptions,
    free: &[bool],
    collapse: Collapse,
    to_precision: bool,
) -> Result<Option<Collapse>, StaticsError> {
    let Some(lambda) = collapse.lambda else {
        return Ok(None);
    };
    let unloaded = moving_points(faces, &collapse);
    if unloaded.is_empty() {
        return Ok(Some(collapse));
    }
    let needed = lambda * (1.0 - UNLOADED_TOLERANCE);
    let twists = twist_reactions(faces, &collapse, model.size);
    let spared = if to_precision {
        solve_to_precision(model, faces, d, options, free, &unloaded, &twists, needed)
    } else {
        let program = Program::build(
            model,
            faces,
            d,
            options,
            free,
            &unloaded,
            &twists,
            Precision::Exact,
        );
        solve_built(model, faces, d, options, &program)
    };
    let spared = match spared {
        Ok(spared) => spared,
        Err(StaticsError::DoesNotHold(_)) => return Ok(None),
        Err(e) => return Err(e),
    };
    if !spared.lambda.is_some_and(|l| l >= needed) {
        return Ok(None);
    }
    let mut collapse = collapse;
    for (kept, spared) in collapse.interfaces.iter_mut().zip(spared.interfaces) {
        kept.forces = spared.forces;
        kept.twist = spared.twist;
    }
    Ok(Some(collapse))
}

/// The interfaces whose faces may carry the no-twist reaction at a single loaded corner in the
/// physical test of `collapse` ([`LumpedShear`]): rocking bases that do not turn about their
/// normal in its mechanism (where one does, that couple would do virtual work).
fn twist_reactions(faces: &[ContactFace], collapse: &Collapse, size: f64) -> Vec<usize> {
    collapse
        .interfaces
        .iter()
        .filter(|i| {
            let face = &faces[i.interface];
            let turn = face.normal.dot(&Vector3::from(i.rotation));
            face.bilateral_couples.is_empty()
                && !face.pin
                && size * turn.abs() <= MECHANISM_TOLERANCE
        })
        .map(|i| i.interface)
        .collect()
}

/// The smallest Coulomb friction coefficient (the exact cone, [`Friction::Cone`]) at which the
/// collapse multiplier along `direction` reaches (1 − 1e-6) of `lambda`, its value without
/// sliding ([`collapse_multiplier`]'s answer, which the caller has): the friction the no-sliding
/// answer relies on. 0 when it needs none, infinity beyond μ = 1000. The cone, not the pyramid:
/// a pyramid on a face's own tangents admits μ√2 along its diagonals, so a block turned about
/// the vertical would need less friction than the same block square to the load.
pub fn required_friction(
    model: &Model,
    direction: Vector3<f64>,
    lambda_max: f64,
    lambda: f64,
) -> Result<f64, StaticsError> {
    let target = lambda - 1e-6 * lambda.abs();
    smallest_friction(|mu: f64| -> Result<Option<f64>, StaticsError> {
        let options = StaticsOptions {
            friction: Friction::Cone(mu),
            lambda_max,
            sliding_lift_off: false,
            exhaustive_sets: 0,
            cancel: None,
        };
        match collapse_multiplier(model, direction, &options) {
            Ok(c) => Ok(Some(c.lambda.unwrap_or(lambda_max) - target)),
            Err(StaticsError::DoesNotHold(_)) => Ok(None),
            Err(e) => Err(e),
        }
    })
}

/// The smallest Coulomb friction coefficient (the exact cone) with which the collapse
/// state `collapse` (an answer of [`collapse_multiplier`] with its λ) has an equilibrium at
/// (1 − 1e-6) of its λ with forces only at the points its mechanism keeps in contact without
/// sliding: the friction that state relies on. For an answer of the search for joints that open
/// and slide this is at least [`required_friction`], whose program lets every point carry load
/// (the wall assembly's corner wedge at 2/3: 0.7469 against 0.7134). 0 when it needs none,
/// infinity beyond μ = 1000; `None` for a collapse that holds (no λ).
///
/// With only the holding points loaded the equilibrium does no virtual work, so its program is
/// degenerate (λ is fixed at the mechanism's own), and the solver may stop without converging
/// where an equilibrium exists: such a μ counts as not reaching λ, which can only raise the
/// answer (a bracket of 1e-4 of μ on the wall's wedge, `tests/statics/collapse_state.rs`). Where
/// no μ up to 1000 reaches λ and the solver failed on the way, that failure is returned instead
/// of infinity.
pub fn state_friction(
    model: &Model,
    collapse: &Collapse,
    lambda_max: f64,
) -> Result<Option<f64>, StaticsError> {
    let Some(lambda) = collapse.lambda else {
        return Ok(None);
    };
    let d = unit_direction(Vector3::from(collapse.direction))?;
    let faces = precision::faces_at_precision(model);
    let unloaded = moving_points(&faces, collapse);
    let free = vec![false; faces.len()];
    let target = lambda - 1e-6 * lambda.abs();
    // As written first; where no μ reaches λ that way, at the model's precision (a state the
    // exhaustive pass found there: two blocks on their edges whose round-off leaves them no
    // common exact equilibrium).
    let mut failure = None;
    for precision in [Precision::Exact, Precision::Model] {
        failure = None;
        let mu = smallest_friction(|mu: f64| -> Result<Option<f64>, StaticsError> {
            let options = StaticsOptions {
                friction: Friction::Cone(mu),
                lambda_max,
                sliding_lift_off: false,
                exhaustive_sets: 0,
                cancel: None,
            };
            // With few points loaded and little friction the program may have no equilibrium
            // at any λ ≥ 0, which the solver reports as not converging: that μ does not reach λ.
            match solve_program_at(model, &faces, d, &options, &free, &unloaded, precision) {
                Ok(c) => Ok(Some(c.lambda.unwrap_or(lambda_max) - target)),
                Err(StaticsError::DoesNotHold(_)) => Ok(None),
                Err(StaticsError::Solver(status)) => {
                    failure = Some(status);
                    Ok(None)
                }
                Err(e) => Err(e),
            }
        })?;
        if mu.is_finite() {
            return Ok(Some(mu));
        }
    }
    match failure {
        Some(status) => Err(StaticsError::Solver(status)),
        None => Ok(Some(f64::INFINITY)),
    }
}

/// The points (interface, point) of a collapse's mechanism that open or slide, pins aside: a
/// collapse state loads only the others.
fn moving_points(faces: &[ContactFace], collapse: &Collapse) -> Vec<(usize, usize)> {
    let mut moving = Vec::new();
    for i in &collapse.interfaces {
        if faces[i.interface].pin {
            continue;
        }
        for (p, (&gap, &slip)) in i.gap_rates.iter().zip(&i.slip_rates).enumerate() {
            if gap > MECHANISM_TOLERANCE || slip > MECHANISM_TOLERANCE {
                moving.push((i.interface, p));
            }
        }
    }
    moving
}

/// Relative width of μ's last bracket in [`smallest_friction`] (four significant digits).
const FRICTION_DIGITS: f64 = 1e-4;

/// The μ below which [`smallest_friction`] stops: no joint's friction is measured finer.
const SMALLEST_FRICTION: f64 = 1e-6;

/// The smallest μ ≥ 0 whose multiplier reaches a target, to [`FRICTION_DIGITS`]: 0 where μ = 0
/// reaches, infinity beyond 1000. `excess(μ)` is λ(μ) − target (monotone in μ; it reaches where
/// ≥ 0), or None where the program has no λ (it does not hold, or the solver stopped): that μ
/// does not reach.
///
/// The answer is the upper end of a bracket [low, high] whose lower end does not reach, as a
/// bisection gives, but the steps are taken from the multipliers that fall short: below μ*,
/// λ(μ) is a sliding mechanism's, often linear in μ (a block sliding on its bed: λ = μ), and
/// above it flat (the answer without sliding), so the line through the last two short points
/// estimates μ*. A trial just above the estimate and then one just below close the bracket in
/// two programs where λ is linear there (16 bisections on the temple's 0.1632); where two such
/// steps do not halve the bracket, one bisection does.
fn smallest_friction(
    mut excess: impl FnMut(f64) -> Result<Option<f64>, StaticsError>,
) -> Result<f64, StaticsError> {
    let reaches = |e: Option<f64>| e.is_some_and(|e| e >= 0.0);
    let mut short: Vec<(f64, f64)> = Vec::new();
    let at_zero = excess(0.0)?;
    if reaches(at_zero) {
        return Ok(0.0);
    }
    short.extend(at_zero.map(|e| (0.0, e)));
    let mut low = 0.0;
    let mut high = 0.25;
    loop {
        match excess(high)? {
            e if reaches(e) => break,
            e => short.extend(e.map(|e| (high, e))),
        }
        low = high;
        high *= 2.0;
        if high > 1e3 {
            return Ok(f64::INFINITY);
        }
    }
    let mut aim_below = false;
    let mut stalled = 0;
    let mut halved_at = high - low;
    // (Above an absolute floor: an answer that holds with any friction, by a clamping that
    // the rigid blocks grant, would chase μ down to round-off.)
    while high - low > FRICTION_DIGITS * high && high > SMALLEST_FRICTION {
        let margin = 0.3 * FRICTION_DIGITS * high;
        let estimate = match short[..] {
            [.., (m1, e1), (m2, e2)] if stalled < 2 && e2 > e1 => {
                Some(m2 - e2 * (m2 - m1) / (e2 - e1))
            }
            _ => None,
        }
        .filter(|e| e.is_finite() && *e > low && *e < high);
        let trial = match estimate {
            Some(e) if aim_below => (e - margin).clamp(low + margin, high - margin),
            Some(e) => (e + margin).clamp(low + margin, high - margin),
            None => 0.5 * (low + high),
        };
        let value = excess(trial)?;
        if reaches(value) {
            high = trial;
            // Where the trial above the estimate reached, the next goes just below it.
            aim_below = estimate.is_some() && !aim_below;
        } else {
            low = trial;
            short.extend(value.map(|e| (trial, e)));
            aim_below = false;
        }
        if high - low <= 0.5 * halved_at || estimate.is_none() {
            halved_at = high - low;
            stalled = 0;
        } else {
            stalled += 1;
        }
    }
    Ok(high)
}

/// The multipliers along ±x and ±y without sliding.
pub fn horizontal_multipliers(model: &Model) -> Result<Vec<Collapse>, StaticsError> {
    [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()]
        .into_iter()
        .map(|d| collapse_multiplier(model, d, &StaticsOptions::default()))
        .collect()
}

/// What a variable of the program is: a force or a couple at an interface.
#[derive(Clone, Copy, Debug)]
struct Unknown {
    /// Interface index.
    interface: usize,
    /// Where a force acts (m, world at rest); none for a couple.
    at: Option<Vector3<f64>>,
    /// Its direction (world).
    direction: Vector3<f64>,
}

/// The column of a force the program does not carry: a point's tangential force on a face whose
/// shear is lumped ([`LumpedShear`]), or a force that is zero ([`ZeroForces`]).
const NO_COLUMN: usize = usize::MAX;

/// The forces of one face that a program holds at zero, so that it has no column for them
/// (rather than a column and a row fixing it at 0: the same program, a smaller system): the
/// tangential forces of a freed face's points (normal forces only: they may slide), every force
/// of an unloaded point, and the couples of a hinge unloaded at all its points (a line joint that
/// opens carries nothing). A hinge that keeps one of its lines carries its shear in its plane
/// there: shear along t₁ is the same wrench at either line (they lie apart along t₁), so only the
/// normal force of a line that opens goes. Pins are never unloaded.
struct ZeroForces<'a> {
    face: &'a ContactFace,
    freed: bool,
    unloaded: &'a [(usize, usize)],
    /// Every point unloaded (not a pin): the face has opened.
    opened: bool,
    /// A hinge that has not opened: an unloaded line of it keeps its shear (only its normal
    /// force goes).
    keeps_a_line: bool,
}

impl<'a> ZeroForces<'a> {
    fn of(face: &'a ContactFace, free: &[bool], unloaded: &'a [(usize, usize)]) -> Self {
        let mut zero = ZeroForces {
            face,
            freed: free[face.interface] && !face.pin,
            unloaded,
            opened: false,
            keeps_a_line: false,
        };
        zero.opened = !face.pin
            && !face.points.is_empty()
            && (0..face.points.len()).all(|p| zero.unloaded_point(p));
        zero.keeps_a_line = !face.bilateral_couples.is_empty() && !zero.opened;
        zero
    }

    fn unloaded_point(&self, p: usize) -> bool {
        !self.face.pin && self.unloaded.contains(&(self.face.interface, p))
    }

    /// Whether component k (0: normal, 1: t₁, 2: t₂) of point p's force is zero.
    fn is_zero(&self, p: usize, k: usize) -> bool {
        match (self.unloaded_point(p), self.freed) {
            (true, _) if self.keeps_a_line => k == 0,
            (true, _) => true,
            (false, true) => (1..=self.face.friction_tangents).contains(&k),
            (false, false) => false,
        }
    }
}

/// Without sliding, a face's tangential forces at its loaded points are free, and only their
/// wrench counts: a shear (f₁, f₂) at the loaded points' centroid c and a twist couple T about n
/// (any two distinct points carry it). On a rocking base that is three columns instead of two per
/// point (the temple's faces: 3 instead of 8), the same program (its dual asks the same of the
/// mechanism: no slip at any loaded point). The reported point forces are the least-norm split
/// fᵢ = f/k + T n × (pᵢ − c) / Σ|pⱼ − c|², which sums to the shear and the twist. A hinge (a
/// line joint) carries its couples about n and t₁ bilaterally anyway, so its twist is that couple
/// and its shear is two columns where its two lines had four: its lines lie apart along t₁, so
/// the forces along t₁ at either line are one wrench, and those along u differ by a couple about n
/// (8 unknowns → 6). A hinge keeping one line carries that shear there (its centroid), as the
/// per-line program did (the physical test's rule, [`ZeroForces`]).
///
/// A rocking base loaded at a single corner (the others unloaded: the physical test of a
/// mechanism that keeps only that corner) keeps its twist column where the mechanism does not
/// turn the face about its normal ([`twist_reactions`]). A rocking base cannot turn about n (the
/// CRR interface: two tilts, no twist), and the face carries the reaction of that constraint,
/// as the convex program's closure lets a face carry shear with no compression at its other
/// corners; where the mechanism does not turn it, that couple does no virtual work. No point
/// force carries it: it is reported as [`InterfaceCollapse::twist`], and a state that relies on
/// it needs unbounded friction (the friction programs, point forces only, cannot carry it:
/// "needs μ > 1000"). Without it the physical test rejected such states while the convex
/// program's answer, which rests on the same reactions, stood: an independent review
/// (2026-12-06) found a slab on four columns, loaded obliquely, answered 0.149064 (μ ≥ 476) and
/// marked exhaustive, where the slab lifts off one column and rests on single corners of the
/// other three at 0.140829 (`tests/statics/collapse_state.rs`).
#[derive(Clone, Debug)]
struct LumpedShear {
    /// Columns of f₁, f₂ and T (T not on a hinge), with a loaded point, else [`NO_COLUMN`].
    columns: [usize; 3],
    /// The points that may carry load (not unloaded).
    loaded: Vec<usize>,
    /// Their centroid c.
    centroid: Vector3<f64>,
    /// Σ|pⱼ − c|² over them (m²).
    spread: f64,
}

/// The linear (conic) program: min −λ s.t. A x + s = b, s ∈ K.
struct Program {
    /// Columns 1.. (column 0 is λ).
    unknowns: Vec<Unknown>,
    /// Per interface, per point, the columns of (fₙ, f₁, f₂): [`NO_COLUMN`] for the tangents of
    /// a lumped face and for every force the program holds at zero ([`ZeroForces`]).
    point_columns: Vec<Vec<[usize; 3]>>,
    /// Per interface, its lumped shear ([`LumpedShear`]) where it is lumped.
    shears: Vec<Option<LumpedShear>>,
    rows: usize,
    triplets: (Vec<usize>, Vec<usize>, Vec<f64>),
    b: Vec<f64>,
    cones: Vec<SupportedConeT<f64>>,
    /// Forces are in units of the total weight W; moments in W·size.
    weight: f64,
    /// At the model's precision, the columns of the equilibrium's residuals, 6 per body (none
    /// otherwise): after the forces.
    residuals: usize,
    /// As written or at the model's precision.
    precision: Precision,
    /// Per equilibrium row (6 per body, the program's first rows), the residual the program at
    /// the model's precision allows ([`EQUILIBRIUM_RESIDUAL`] of the body's share of the weight).
    residual_bounds: Vec<f64>,
    /// The options' request to stop.
    cancel: Option<Cancel>,
}

/// Whether a program of the exhaustive pass holds the geometry as written, or only to the
/// model's precision ([`Program::build`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Precision {
    /// Every body in equilibrium exactly.
    Exact,
    /// Every body in equilibrium to [`EQUILIBRIUM_RESIDUAL`] of its weight.
    Model,
}

/// The residual of a body's equilibrium, force and moment (over the model's size), that the
/// programs at the model's precision allow, as a share of its weight. Round-off of the corners by
/// [`crr_kinematics::GEOMETRY_TOLERANCE`] of the model's size moves a centre of mass off the
/// edge it balances on by as much: two blocks that tip at b/h side by side then tip at λ that
/// differ by about 1e-6 and have no common equilibrium on their edges, and an upper block of
/// running bond centred over the joint below no longer balances on either half.
const EQUILIBRIUM_RESIDUAL: f64 = 10.0 * crr_kinematics::GEOMETRY_TOLERANCE;

impl Program {
    fn build(
        model: &Model,
        faces: &[ContactFace],
        d: Vector3<f64>,
        options: &StaticsOptions,
        free: &[bool],
        unloaded: &[(usize, usize)],
        twist_reactions: &[usize],
        precision: Precision,
    ) -> Program {
        let mut unknowns = Vec::new();
        let mut point_columns = Vec::with_capacity(faces.len());
        let mut shears = Vec::with_capacity(faces.len());
        for face in faces {
            // A face without sliding, not freed: its shear is lumped.
            let lumped =
                options.friction == Friction::NoSliding && !face.pin && !free[face.interface];
            let zero = ZeroForces::of(face, free, unloaded);
            let mut columns = Vec::with_capacity(face.points.len());
            for (p, &x) in face.points.iter().enumerate() {
                let mut triple = [NO_COLUMN; 3];
                let directions = [face.normal, face.tangents[0], face.tangents[1]];
                let own = if lumped { 1 } else { 3 };
                for (k, direction) in directions.into_iter().enumerate().take(own) {
                    if zero.is_zero(p, k) {
                        continue;
                    }
                    triple[k] = 1 + unknowns.len();
                    unknowns.push(Unknown {
                        interface: face.interface,
                        at: Some(x),
                        direction,
                    });
                }
                columns.push(triple);
            }
            shears.push(lumped.then(|| {
                let reaction = twist_reactions.contains(&face.interface);
                Self::lumped_shear(face, unloaded, reaction, &mut unknowns)
            }));
            let couples = if zero.opened {
                &[][..]
            } else {
                &face.bilateral_couples[..]
            };
            for &direction in couples {
                unknowns.push(Unknown {
                    interface: face.interface,
                    at: None,
                    direction,
                });
            }
            point_columns.push(columns);
        }
        let total_mass: f64 = model.bodies.iter().map(|b| b.mass).sum();
        let weight = total_mass * model.gravity;
        let size = model.size;
        let residual_bounds = model
            .bodies
            .iter()
            .flat_map(|body| [EQUILIBRIUM_RESIDUAL * body.mass / total_mass; 6])
            .collect();
        let mut program = Program {
            unknowns,
            point_columns,
            shears,
            rows: 0,
            triplets: (Vec::new(), Vec::new(), Vec::new()),
            b: Vec::new(),
            cones: Vec::new(),
            weight,
            residuals: 0,
            precision,
            residual_bounds,
            cancel: options.cancel.clone(),
        };
        program.equilibrium_rows(model, d, total_mass, size);
        program.inequality_rows(faces, options);
        if precision == Precision::Model {
            program.equilibrium_residuals();
        }
        program
    }

    /// At the model's precision: a residual column per equilibrium row (the first 6 per body),
    /// bounded by [`EQUILIBRIUM_RESIDUAL`] of the body's weight.
    fn equilibrium_residuals(&mut self) {
        let first_column = 1 + self.unknowns.len();
        let first = self.rows;
        let count = self.residual_bounds.len();
        for k in 0..count {
            let column = first_column + k;
            let bound = self.residual_bounds[k];
            // The equilibrium rows are the program's first: row k.
            self.push(k, column, -1.0);
            self.push(first + 2 * k, column, 1.0);
            self.push(first + 2 * k + 1, column, -1.0);
            self.b.push(bound);
            self.b.push(bound);
        }
        self.residuals = count;
        self.rows = first + 2 * count;
        self.cones.push(SupportedConeT::NonnegativeConeT(2 * count));
    }

    /// The most λ the same program reaches at the model's precision, bounded from the dual of
    /// its answer as written (`solution`, solved or a certificate of infeasibility); −∞ where
    /// that program has no equilibrium either, +∞ where the dual cannot tell.
    ///
    /// The program at the model's precision is this one with the equilibrium rows' right-hand
    /// side b moved by some δ, |δₖ| ≤ εₖ ([`Self::residual_bounds`]). clarabel's dual z of
    /// min qᵀx s.t. Ax + s = b, s ∈ K, is feasible whatever b is (Aᵀz + q = 0, z ∈ K*), so by
    /// weak duality λ = −qᵀx ≤ (b + δ)ᵀz ≤ bᵀz + Σₖ εₖ|zₖ| for every δ. A certificate of
    /// infeasibility (Aᵀz = 0, z ∈ K*, bᵀz < 0) proves the moved program infeasible as well
    /// where bᵀz + Σₖ εₖ|zₖ| < 0. The solver's z holds its equations to its tolerances only, so
    /// the sum counts twice, and a certificate must hold with half of bᵀz to spare. An answer
    /// at the solver's reduced tolerances (`AlmostSolved`, `AlmostPrimalInfeasible`: dual
    /// residuals up to 5e-5) proves nothing this way (its residual times the forces may exceed
    /// the margin; an independent review), so it leaves the second program to run.
    fn reach_at_precision(&self, solution: &clarabel::solver::DefaultSolution<f64>) -> f64 {
        if !matches!(
            solution.status,
            SolverStatus::Solved | SolverStatus::PrimalInfeasible
        ) {
            return f64::INFINITY;
        }
        let spread: f64 = self
            .residual_bounds
            .iter()
            .zip(&solution.z)
            .map(|(bound, z)| bound * z.abs())
            .sum();
        let bz: f64 = self.b.iter().zip(&solution.z).map(|(b, z)| b * z).sum();
        if !bz.is_finite() || !spread.is_finite() {
            return f64::INFINITY;
        }
        if primal_infeasible(&solution.status) {
            return if bz < 0.0 && 2.0 * spread <= -0.5 * bz {
                f64::NEG_INFINITY
            } else {
                f64::INFINITY
            };
        }
        let lambda = solution.x[0];
        lambda.max(bz) + 2.0 * spread + 1e-9 * (1.0 + lambda.abs())
    }

    /// The lumped shear of `face` ([`LumpedShear`]) and its columns (none where every point is
    /// unloaded).
    fn lumped_shear(
        face: &ContactFace,
        unloaded: &[(usize, usize)],
        twist_reaction: bool,
        unknowns: &mut Vec<Unknown>,
    ) -> LumpedShear {
        let loaded: Vec<usize> = (0..face.points.len())
            .filter(|&p| !unloaded.contains(&(face.interface, p)))
            .collect();
        let centroid = loaded.iter().map(|&p| face.points[p]).sum::<Vector3<f64>>()
            / loaded.len().max(1) as f64;
        let spread: f64 = loaded
            .iter()
            .map(|&p| (face.points[p] - centroid).norm_squared())
            .sum();
        let mut column = |direction: Vector3<f64>, at: Option<Vector3<f64>>| {
            unknowns.push(Unknown {
                interface: face.interface,
                at,
                direction,
            });
            unknowns.len()
        };
        let mut columns = [NO_COLUMN; 3];
        if !loaded.is_empty() {
            columns[0] = column(face.tangents[0], Some(centroid));
            columns[1] = column(face.tangents[1], Some(centroid));
        }
        // A hinge carries its couple about n bilaterally already ([`ContactFace::bilateral_couples`]);
        // a single loaded corner only as the no-twist reaction, where asked ([`LumpedShear`]).
        if (spread > 0.0 || (loaded.len() == 1 && twist_reaction))
            && face.bilateral_couples.is_empty()
        {
            columns[2] = column(face.normal, None);
        }
        LumpedShear {
            columns,
            loaded,
            centroid,
            spread,
        }
    }

    /// Adds `value` at (row, column); nothing for a column that does not exist ([`NO_COLUMN`]).
    fn push(&mut self, row: usize, column: usize, value: f64) {
        if value != 0.0 && column != NO_COLUMN {
            self.triplets.0.push(row);
            self.triplets.1.push(column);
            self.triplets.2.push(value);
        }
    }

    /// Six rows per body: Σ forces + weight − λ·load = 0, Σ moments about the centre of mass /
    /// size = 0 (the zero cone).
    fn equilibrium_rows(&mut self, model: &Model, d: Vector3<f64>, total_mass: f64, size: f64) {
        let bodies = model.bodies.len();
        let first = self.rows;
        for (column, u) in self.unknowns.clone().into_iter().enumerate() {
            let column = column + 1;
            let interface = &model.interfaces[u.interface];
            let add = |body: usize, sign: f64, program: &mut Program| {
                let row = first + 6 * body;
                let com = model.bodies[body].com;
                match u.at {
                    Some(x) => {
                        let arm = (x - com).cross(&u.direction) / size;
                        for k in 0..3 {
                            program.push(row + k, column, sign * u.direction[k]);
                            program.push(row + 3 + k, column, sign * arm[k]);
                        }
                    }
                    None => {
                        for k in 0..3 {
                            program.push(row + 3 + k, column, sign * u.direction[k] / size);
                        }
                    }
                }
            };
            add(interface.child, 1.0, self);
            if let Parent::Body(parent) = interface.parent {
                add(parent, -1.0, self);
            }
        }
        self.b.resize(first + 6 * bodies, 0.0);
        for (n, body) in model.bodies.iter().enumerate() {
            let share = body.mass / total_mass;
            for k in 0..3 {
                // −λ·share·d on the left; the weight share·(−z) moves to the right.
                self.push(first + 6 * n + k, 0, -share * d[k]);
            }
            self.b[first + 6 * n + 2] = share;
        }
        self.rows = first + 6 * bodies;
        self.cones.push(SupportedConeT::ZeroConeT(6 * bodies));
    }

    /// No tension, λ ≤ λ_max, friction.
    fn inequality_rows(&mut self, faces: &[ContactFace], options: &StaticsOptions) {
        let first = self.rows;
        let mut row = first;
        let mut cone_rows = Vec::new();
        for (face, columns) in faces.iter().zip(self.point_columns.clone()) {
            if face.pin {
                continue;
            }
            for [normal, t1, t2] in columns {
                if normal != NO_COLUMN {
                    self.push(row, normal, -1.0);
                    row += 1;
                }
                let tangents = [t1, t2];
                match options.friction {
                    Friction::NoSliding => {}
                    Friction::Cone(mu) if face.friction_tangents == 2 => {
                        if t1 != NO_COLUMN || t2 != NO_COLUMN {
                            cone_rows.push((normal, t1, t2, mu));
                        }
                    }
                    Friction::Pyramid(mu) | Friction::Cone(mu) => {
                        // A hinge's line that opens keeps its t₁ column (its shear is the other
                        // line's): with no normal force there, friction holds it at 0.
                        for &t in tangents[..face.friction_tangents]
                            .iter()
                            .filter(|&&t| t != NO_COLUMN)
                        {
                            for sign in [1.0, -1.0] {
                                self.push(row, t, sign);
                                self.push(row, normal, -mu);
                                row += 1;
                            }
                        }
                    }
                }
            }
        }
        self.push(row, 0, 1.0);
        row += 1;
        self.b.resize(row, 0.0);
        self.b[row - 1] = options.lambda_max;
        self.cones
            .push(SupportedConeT::NonnegativeConeT(row - first));
        for (normal, t1, t2, mu) in cone_rows {
            self.push(row, normal, -mu);
            self.push(row + 1, t1, -1.0);
            self.push(row + 2, t2, -1.0);
            row += 3;
            self.cones.push(SupportedConeT::SecondOrderConeT(3));
        }
        self.b.resize(row, 0.0);
        self.rows = row;
    }

    /// The program with λ fixed at `lambda` (one more zero-cone row) and ½Σx² over `columns`
    /// minimised instead of −λ.
    fn solve_least(
        &self,
        lambda: f64,
        columns: &[usize],
    ) -> Result<clarabel::solver::DefaultSolution<f64>, StaticsError> {
        let n = 1 + self.unknowns.len() + self.residuals;
        let p = CscMatrix::new_from_triplets(
            n,
            n,
            columns.to_vec(),
            columns.to_vec(),
            vec![1.0; columns.len()],
        );
        let q = vec![0.0; n];
        let (mut rows, mut cols, mut values) = self.triplets.clone();
        rows.push(self.rows);
        cols.push(0);
        values.push(1.0);
        let a = CscMatrix::new_from_triplets(self.rows + 1, n, rows, cols, values);
        let mut b = self.b.clone();
        b.push(lambda);
        let mut cones = self.cones.clone();
        cones.push(SupportedConeT::ZeroConeT(1));
        no_certificate(self.run_solver(&p, &q, &a, &b, &cones)?)
    }

    fn solve(&self) -> Result<clarabel::solver::DefaultSolution<f64>, StaticsError> {
        no_certificate(self.solve_verdict()?)
    }

    /// [`Self::solve`] that returns a certificate of infeasibility as a solution (its status
    /// says which): [`Self::reach_at_precision`] reads it.
    fn solve_verdict(&self) -> Result<clarabel::solver::DefaultSolution<f64>, StaticsError> {
        let n = 1 + self.unknowns.len() + self.residuals;
        let p = CscMatrix::zeros((n, n));
        let mut q = vec![0.0; n];
        q[0] = -1.0;
        let a = CscMatrix::new_from_triplets(
            self.rows,
            n,
            self.triplets.0.clone(),
            self.triplets.1.clone(),
            self.triplets.2.clone(),
        );
        self.run_solver(&p, &q, &a, &self.b, &self.cones)
    }

    /// clarabel on min ½xᵀPx + qᵀx s.t. Ax + s = b, s ∈ cones: its solution, or its certificate
    /// of primal infeasibility ([`primal_infeasible`] tells which).
    fn run_solver(
        &self,
        p: &CscMatrix<f64>,
        q: &[f64],
        a: &CscMatrix<f64>,
        b: &[f64],
        cones: &[SupportedConeT<f64>],
    ) -> Result<clarabel::solver::DefaultSolution<f64>, StaticsError> {
        if self.cancel.as_ref().is_some_and(Cancel::is_cancelled) {
            return Err(StaticsError::Interrupted);
        }
        let mut failed = None;
        let attempts: &[SolverAttempt] = match self.precision {
            Precision::Exact => &SOLVER_ATTEMPTS,
            Precision::Model => &SOLVER_ATTEMPTS_AT_PRECISION,
        };
        for attempt in attempts {
            let settings = DefaultSettingsBuilder::default()
                .verbose(false)
                .tol_gap_abs(attempt.tolerance)
                .tol_gap_rel(attempt.tolerance)
                .tol_feas(attempt.tolerance)
                .tol_ktratio(1e-10_f64.max(attempt.tolerance))
                .max_iter(attempt.max_iter)
                .iterative_refinement_max_iter(attempt.refinement_steps)
                .equilibrate_enable(attempt.equilibrate)
                .build()
                .map_err(|e| StaticsError::Solver(format!("{e:?}")))?;
            let mut solver = DefaultSolver::new(p, q, a, b, cones, settings)
                .map_err(|e| StaticsError::Solver(format!("{e:?}")))?;
            solver.solve();
            let solution = solver.solution;
            match solution.status {
                SolverStatus::Solved
                | SolverStatus::AlmostSolved
                | SolverStatus::PrimalInfeasible
                | SolverStatus::AlmostPrimalInfeasible => return Ok(solution),
                other => {
                    failed.get_or_insert(format!("{other:?}"));
                }
            }
        }
        Err(StaticsError::Solver(failed.unwrap_or_default()))
    }

    /// A lumped face's tangential forces (N) per point, the least-norm split of its shear and
    /// twist over its loaded points ([`LumpedShear`]), and the twist no point carries (N m: a
    /// single loaded corner's); none where the face is not lumped.
    fn lumped_split(
        &self,
        face: &ContactFace,
        solution: &clarabel::solver::DefaultSolution<f64>,
    ) -> Option<(Vec<[f64; 2]>, f64)> {
        let lumped = self.shears[face.interface].as_ref()?;
        let value = |c: usize| if c == NO_COLUMN { 0.0 } else { solution.x[c] };
        let [t1, t2] = face.tangents;
        let [f1, f2, twist] = lumped.columns.map(value);
        let shear = (t1 * f1 + t2 * f2) / lumped.loaded.len().max(1) as f64;
        let mut split = vec![[0.0; 2]; face.points.len()];
        for &p in &lumped.loaded {
            let mut f = shear;
            if lumped.spread > 0.0 {
                let arm = face.points[p] - lumped.centroid;
                f += face.normal.cross(&arm) * (twist / lumped.spread);
            }
            split[p] = [self.weight * f.dot(&t1), self.weight * f.dot(&t2)];
        }
        // The couples' rows are M/(W·L) with entries direction/L: T is C/W.
        let unsplit = if lumped.spread > 0.0 {
            0.0
        } else {
            self.weight * twist
        };
        Some((split, unsplit))
    }

    fn collapse(
        &self,
        model: &Model,
        faces: &[ContactFace],
        d: Vector3<f64>,
        options: &StaticsOptions,
        solution: &clarabel::solver::DefaultSolution<f64>,
    ) -> Collapse {
        // A structure balanced exactly on an edge has λ = 0 within the solver's round-off
        // (answers below −1e-9 are refused as not holding): no "λ = −0.000000".
        let lambda = solution.x[0].max(0.0);
        let holds = lambda >= options.lambda_max * (1.0 - 1e-9);
        let size = model.size;
        // Virtual velocities: the duals of the equilibrium rows (forces → v, moments → size·ω).
        let mut bodies: Vec<(Vector3<f64>, Vector3<f64>)> = (0..model.bodies.len())
            .map(|n| {
                let z = &solution.z[6 * n..6 * n + 6];
                (
                    Vector3::new(z[0], z[1], z[2]),
                    Vector3::new(z[3], z[4], z[5]) / size,
                )
            })
            .collect();
        let scale = bodies
            .iter()
            .map(|(v, w)| v.norm().max(size * w.norm()))
            .fold(0.0, f64::max);
        for (v, w) in &mut bodies {
            if holds || scale == 0.0 {
                *v = Vector3::zeros();
                *w = Vector3::zeros();
            } else {
                *v /= scale;
                *w /= scale;
            }
        }
        let point_velocity = |parent: Parent, x: &Vector3<f64>| match parent {
            Parent::Ground => Vector3::zeros(),
            Parent::Body(n) => {
                let (v, w) = &bodies[n];
                v + w.cross(&(x - model.bodies[n].com))
            }
        };
        let interfaces = faces
            .iter()
            .map(|face| {
                let interface = &model.interfaces[face.interface];
                let shear = self.lumped_split(face, solution);
                let forces = self.point_columns[face.interface]
                    .iter()
                    .zip(&face.points)
                    .enumerate()
                    .map(|(p, (&[n, t1, t2], x))| {
                        let value = |c: usize| {
                            if c == NO_COLUMN {
                                0.0
                            } else {
                                self.weight * solution.x[c]
                            }
                        };
                        PointForce {
                            point: [x.x, x.y, x.z],
                            normal: value(n),
                            tangential: match &shear {
                                Some((split, _)) => split[p],
                                None => [value(t1), value(t2)],
                            },
                        }
                    })
                    .collect();
                let mut gap_rates = Vec::with_capacity(face.points.len());
                let mut slip_rates = Vec::with_capacity(face.points.len());
                for x in &face.points {
                    let relative = point_velocity(Parent::Body(interface.child), x)
                        - point_velocity(interface.parent, x);
                    gap_rates.push(face.normal.dot(&relative));
                    slip_rates.push(
                        face.tangents[..face.friction_tangents]
                            .iter()
                            .map(|t| t.dot(&relative).powi(2))
                            .sum::<f64>()
                            .sqrt(),
                    );
                }
                let slip_rate = slip_rates.iter().copied().fold(0.0, f64::max);
                let parent_angular = match interface.parent {
                    Parent::Ground => Vector3::zeros(),
                    Parent::Body(n) => bodies[n].1,
                };
                let rotation = bodies[interface.child].1 - parent_angular;
                let measure = gap_rates
                    .iter()
                    .map(|g| g.abs())
                    .fold(size * rotation.norm(), f64::max)
                    .max(slip_rate);
                let zero = MECHANISM_TOLERANCE;
                let pivots: Vec<usize> = (0..face.points.len())
                    .filter(|&p| gap_rates[p] <= zero)
                    .collect();
                let sliding_friction = options.friction != Friction::NoSliding;
                let motion = if measure <= zero {
                    Motion::Closed
                } else if sliding_friction && slip_rate > zero {
                    Motion::Slides
                } else if pivots.is_empty() && !face.pin {
                    Motion::LiftsOff
                } else {
                    Motion::Rocks
                };
                let sides = if motion == Motion::Closed {
                    Vec::new()
                } else {
                    interface
                        .slots
                        .clone()
                        .enumerate()
                        .filter_map(|(component, slot)| {
                            let turn = rotation.dot(&interface.kind.axis(component));
                            let side = if turn > 0.0 {
                                Side::Positive
                            } else {
                                Side::Negative
                            };
                            (size * turn.abs() > zero).then_some((slot, side))
                        })
                        .collect()
                };
                InterfaceCollapse {
                    interface: face.interface,
                    name: interface.name.clone(),
                    forces,
                    twist: shear.as_ref().map_or(0.0, |(_, twist)| *twist),
                    motion,
                    sides,
                    pivots: if measure <= zero { Vec::new() } else { pivots },
                    gap_rates,
                    slip_rates,
                    slip_rate,
                    rotation: [rotation.x, rotation.y, rotation.z],
                }
            })
            .collect();
        Collapse {
            direction: [d.x + 0.0, d.y + 0.0, d.z + 0.0],
            lambda: (!holds).then_some(lambda),
            convex_lambda: (!holds).then_some(lambda),
            exhaustive: false,
            unexhausted: Some(Unexhausted::ConvexOnly),
            interfaces,
            bodies: bodies
                .iter()
                .map(|(v, w)| BodyMotion {
                    velocity: [v.x, v.y, v.z],
                    angular: [w.x, w.y, w.z],
                })
                .collect(),
        }
    }
}

/// The global test of a structure at rest with every joint seated: does it hold under a ground
/// acceleration a? The loads a structure at rest carries form a convex set containing 0 (static
/// theorem), so it holds under a iff |a| < λ_c(a/|a|)·g. The multipliers along ±x, ±y, ±z are
/// computed when first needed, each once; a load inside their convex hull (the octahedron
/// Σ|a_k|/(λ_k g) < 1, over the axes a has a component along) holds without a program; outside
/// it, the program runs along a's direction (its answers kept by direction, so that a constant
/// load or a one-component record costs one program per sense).
///
/// Whether the structure stands under its own weight is read from both senses of the first axis
/// computed (±x under no load): the loads it holds form a convex set, and where that set does
/// not contain 0 it meets the axis line on one side of 0 only, or not at all, so one sense (or
/// both) has no λ ≥ 0. A structure under a one-component pulse costs two programs, not six.
/// Each chain a run switches to (a face that opens or lands) starts its own, from the axes
/// [`AxisMemory`] kept for the same interfaces.
///
/// Every program's answer is also a point λ(d)·d of the set's boundary (in units of g), and the
/// convex program's set contains the convex hull of 0 and of the points found: a load in the
/// triangle of 0 and two of them (the axes' included) holds without a program. A record in two
/// components (a plane of loads) so needs a program only where its direction and magnitude
/// leave the polygon of the answers so far; before, every new direction outside the octahedron
/// cost one (the bundled temple under 0.8 times its record: 216 programs, 28 % of its run, now
/// 110; 79 with its caller's local test first where [`Self::beyond_a_known_mechanism`]).
///
/// The search for sliding lift-offs ([`collapse_multiplier`]) lowers λ(d) below the convex
/// program's where it finds such a mechanism along d, so the programs' answers need not form a
/// convex set. A mechanism bounds λ along every direction it is driven by (kinematic theorem),
/// so each answer's mechanism is kept as a cut, x·V ≤ λ(d)(d·V) with V = Σ mᵢvᵢ its bodies'
/// momentum: every point kept when a cut is found is pulled in radially onto it (those points
/// then stay within it after the cut's answer is dropped), and a load beyond any cut kept goes
/// to the program, the octahedron's included. An answer kept along the load's exact direction
/// answers for that direction alone, as its program would again. The inference is exact for
/// the convex program; with sliding lift-offs it is as good as the mechanisms found so far (a
/// program along a new direction may find one that none of the answers kept has).
#[derive(Clone, Debug, Default)]
pub struct RestStatics {
    /// λ along +x, −x, +y, −y, +z, −z (capped at [`LAMBDA_MAX`]; 0 for a structure that cannot
    /// stand); `None` until first needed.
    axes: [Option<f64>; 6],
    /// Answers along directions asked before (exact bits of the unit direction).
    by_direction: ByDirection,
    /// The programs' answers as boundary points and cuts (the axes' included).
    known: Vec<KnownAnswer>,
    /// Programs solved (the axes' and the directions').
    programs: usize,
    /// Whether each axis's answer is not exhaustive ([`Collapse::exhaustive`]).
    axes_searched: [bool; 6],
    /// Whether some answer kept is not exhaustive.
    any_searched: bool,
    /// Whether the last load [`Self::exceeded`] found holding was held on an answer that is not
    /// exhaustive (the search for joints that open and slide alone: a lower mechanism may exist).
    held_on_search: bool,
}

/// Most sets of joints that may open and slide the rest statics try exhaustively along an axis.
pub const REST_EXHAUSTIVE_SETS: usize = 256;

/// Most sets the rest statics try exhaustively along any other direction.
pub const REST_DIRECTION_SETS: usize = 32;

/// The options [`RestStatics`] solves its programs with along the unit direction `d`:
/// [`StaticsOptions::default`] with at most [`REST_EXHAUSTIVE_SETS`] sets of joints that may
/// open and slide tried exhaustively along an axis (±x, ±y, ±z), which a run asks for once per
/// chain (the bundled temple's run: 1.3 s without the pass, 2.2 s with it), and at most
/// [`REST_DIRECTION_SETS`] along any other direction: a record in two components asks for many,
/// each its own program, and the pass along each multiplied the temple's run time (62 sets) by
/// nine. Where a load is held on an answer that is not exhaustive,
/// [`RestStatics::held_on_search`] says so.
pub fn rest_options(d: &Vector3<f64>) -> StaticsOptions {
    let on_axis = (0..3).filter(|&k| d[k] != 0.0).count() == 1;
    StaticsOptions {
        exhaustive_sets: if on_axis {
            REST_EXHAUSTIVE_SETS
        } else {
            REST_DIRECTION_SETS
        },
        ..StaticsOptions::default()
    }
}

/// Collapses by the exact bits of their unit direction ([`direction_key`]).
type ByDirection = Vec<([u64; 3], Collapse)>;

/// Most directions a [`RestStatics`] keeps.
const REST_DIRECTIONS: usize = 64;

/// One answer of the rest statics' program: its boundary point and its mechanism's cut.
#[derive(Clone, Debug, PartialEq)]
struct KnownAnswer {
    /// λ(d)·d (units of g; λ capped at [`LAMBDA_MAX`] where the structure holds).
    point: Vector3<f64>,
    /// (V, c): loads x with x·V > c exceed the mechanism's multiplier (none where the structure
    /// holds along d, or the mechanism's momentum has no component along d).
    cut: Option<(Vector3<f64>, f64)>,
}

impl KnownAnswer {
    /// The answer `collapse` along the unit direction `d` on `model`'s bodies.
    fn of(model: &Model, d: &Vector3<f64>, collapse: &Collapse) -> Self {
        let lambda = collapse.lambda;
        let momentum: Vector3<f64> = model
            .bodies
            .iter()
            .zip(&collapse.bodies)
            .map(|(b, m)| b.mass * Vector3::from(m.velocity))
            .sum();
        let along = d.dot(&momentum);
        let cut = lambda.filter(|&l| l > 0.0).and_then(|l| {
            (along.abs() > 1e-12 * momentum.norm())
                .then(|| (along.signum() * momentum, l * along.abs()))
        });
        Self {
            point: lambda.unwrap_or(LAMBDA_MAX) * d,
            cut,
        }
    }
}

impl RestStatics {
    /// `None` when the structure at rest holds under the ground acceleration `a` (m/s²), else
    /// the collapse along a's direction (its mechanism says which joints open, to which side,
    /// and whether a block lifts off). A load exceeds the multiplier only beyond λ_c(1 + 1e-9):
    /// at the threshold itself the dynamics' own test decides.
    pub fn exceeded(
        &mut self,
        model: &Model,
        a: &Vector3<f64>,
    ) -> Result<Option<&Collapse>, StaticsError> {
        let g = model.gravity;
        let magnitude = a.norm();
        // The axes a has a component along (+x under no load): a structure that cannot stand
        // under its own weight has no collapse set to be inside of, even under no load (the
        // caller's local test decides then).
        let needed: Vec<usize> = (0..3)
            .filter(|&k| a[k] != 0.0)
            .map(|k| 2 * k + usize::from(a[k] < 0.0))
            .collect();
        let needed = if needed.is_empty() { vec![0] } else { needed };
        let mut hull = 0.0;
        self.held_on_search = false;
        let mut searched_axes = false;
        for k in needed {
            // Both senses of the axis: the loads a structure holds form a convex set, and one
            // that cannot stand under no load (0 outside the set) meets the axis line on one
            // side of 0 only, or not at all; the other sense (or both) then has no λ ≥ 0.
            for j in [k, k ^ 1] {
                if self.axis(model, j)? <= 0.0 {
                    return Err(StaticsError::DoesNotHold(
                        "the structure does not stand under its own weight".into(),
                    ));
                }
            }
            hull += a[k / 2].abs() / (self.axis(model, k)? * g);
            searched_axes |= self.axes_searched[k];
        }
        if magnitude == 0.0 || !magnitude.is_finite() {
            return Ok(None);
        }
        if hull < 1.0 && !self.beyond_a_cut(&(a / g), 0.0) {
            self.held_on_search = searched_axes;
            return Ok(None);
        }
        let d = a / magnitude;
        let key = direction_key(&d);
        let index = match self
            .by_direction
            .iter()
            .position(|(k, _)| same_direction(k, &key))
        {
            Some(i) => i,
            None => {
                if self.within_known_loads(&(a / g)) {
                    self.held_on_search = self.any_searched;
                    return Ok(None);
                }
                self.programs += 1;
                let c = collapse_multiplier(model, d, &rest_options(&d))?;
                self.any_searched |= !c.exhaustive;
                self.keep_answer(KnownAnswer::of(model, &d, &c));
                self.keep_direction(key, c)
            }
        };
        let collapse = &self.by_direction[index].1;
        Ok(match collapse.lambda {
            Some(l) if magnitude > l * g * (1.0 + 1e-9) => Some(collapse),
            _ => {
                self.held_on_search = !collapse.exhaustive;
                None
            }
        })
    }

    /// Whether the last load [`Self::exceeded`] found holding was held on an answer that is not
    /// exhaustive: the search for joints that open and slide alone, along a direction where the
    /// structure has more sets of such joints than [`rest_options`] tries, so a lower mechanism
    /// may exist and the structure may leave rest under that load.
    pub fn held_on_search(&self) -> bool {
        self.held_on_search
    }

    /// λ along axis `k` (+x, −x, +y, −y, +z, −z), computed once: capped at [`LAMBDA_MAX`], 0
    /// for a structure that cannot stand (kept, so that its program runs once).
    fn axis(&mut self, model: &Model, k: usize) -> Result<f64, StaticsError> {
        if let Some(lambda) = self.axes[k] {
            return Ok(lambda);
        }
        let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        let mut d = Vector3::zeros();
        d[k / 2] = sign;
        self.programs += 1;
        let lambda = match collapse_multiplier(model, d, &rest_options(&d)) {
            Ok(c) => {
                let lambda = c.lambda.unwrap_or(LAMBDA_MAX);
                self.axes_searched[k] = !c.exhaustive;
                self.any_searched |= !c.exhaustive;
                // A structure that cannot stand along this axis (λ ≤ 0) has no boundary point
                // or cut to keep: the standing check stops every test first.
                if lambda > 0.0 {
                    self.keep_answer(KnownAnswer::of(model, &d, &c));
                }
                // A load along the axis itself (a one-component record) asks for this
                // collapse again, by the same direction's bits.
                self.keep_direction(direction_key(&d), c);
                lambda
            }
            Err(StaticsError::DoesNotHold(_)) => 0.0,
            Err(e) => return Err(e),
        };
        self.axes[k] = Some(lambda);
        Ok(lambda)
    }

    /// Whether the ground acceleration `a` (m/s²) drives a mechanism found before beyond its
    /// multiplier by more than 1e-6 (kinematic theorem: the structure does not hold it). Such a
    /// load is one [`Self::exceeded`] calls exceeded wherever its program finds the lowest
    /// mechanism; it lets a caller that needs the collapse only when its own test finds no
    /// opening ask for it then.
    pub fn beyond_a_known_mechanism(&self, model: &Model, a: &Vector3<f64>) -> bool {
        self.beyond_a_cut(&(a / model.gravity), 1e-6)
    }

    /// Whether the load `x` (units of g) lies beyond a kept cut by more than `margin` of it.
    fn beyond_a_cut(&self, x: &Vector3<f64>, margin: f64) -> bool {
        self.known
            .iter()
            .filter_map(|k| k.cut)
            .any(|(momentum, c)| x.dot(&momentum) > c * (1.0 + margin))
    }

    /// Programs this statics has solved (along the axes and along other directions).
    pub fn programs_solved(&self) -> usize {
        self.programs
    }

    /// Whether the load `x` (units of g) lies in a triangle of 0 and two known points (held by
    /// convexity) and within every known mechanism's cut: x = αp + βp′ with α, β ≥ 0,
    /// α + β ≤ 1, to 1e-12 of |x| out of the pair's plane (a load in the plane of the points, as
    /// a record in two components is, has no residual beyond round-off; a load outside every
    /// such plane is left to the program). The program itself calls a load exceeded only beyond
    /// λ(1 + 1e-9), so a load inside the hull of the convex program's answers is never one it
    /// calls exceeded, to its own tolerance.
    fn within_known_loads(&self, x: &Vector3<f64>) -> bool {
        if self.beyond_a_cut(x, 0.0) {
            return false;
        }
        let size = x.norm();
        for (i, first) in self.known.iter().enumerate() {
            let p = &first.point;
            for r in self.known[i + 1..].iter().map(|k| &k.point) {
                let (pp, pr, rr) = (p.dot(p), p.dot(r), r.dot(r));
                // |p × r|² = pp·rr − pr², without the cancellation.
                let det = p.cross(r).norm_squared();
                if det <= 1e-12 * pp * rr {
                    continue;
                }
                let (px, rx) = (p.dot(x), r.dot(x));
                let alpha = (px * rr - rx * pr) / det;
                let beta = (rx * pp - px * pr) / det;
                if alpha >= 0.0
                    && beta >= 0.0
                    && alpha + beta <= 1.0
                    && (x - alpha * p - beta * r).norm() <= 1e-12 * size
                {
                    return true;
                }
            }
        }
        false
    }

    /// Keeps an answer found, dropping the oldest beyond [`REST_DIRECTIONS`].
    fn keep_answer(&mut self, answer: KnownAnswer) {
        keep_known(&mut self.known, answer);
    }

    /// Keeps the collapse along the unit direction of bits `key`, dropping the oldest beyond
    /// [`REST_DIRECTIONS`]; its index.
    fn keep_direction(&mut self, key: [u64; 3], collapse: Collapse) -> usize {
        if self.by_direction.len() >= REST_DIRECTIONS {
            self.by_direction.remove(0);
        }
        self.by_direction.push((key, collapse));
        self.by_direction.len() - 1
    }
}

/// Appends `answer` to `known` unless it is there, dropping the oldest beyond
/// [`REST_DIRECTIONS`], with every point pulled in radially onto every cut (p ← p·min(1,
/// c/(p·V))): the loads along a point's direction up to the point are held by its own program,
/// and the hull of the points then lies within every cut found.
fn keep_known(known: &mut Vec<KnownAnswer>, mut answer: KnownAnswer) {
    if known.contains(&answer) {
        return;
    }
    let cuts: Vec<(Vector3<f64>, f64)> = known
        .iter()
        .chain([&answer])
        .filter_map(|k| k.cut)
        .collect();
    for point in known
        .iter_mut()
        .map(|k| &mut k.point)
        .chain([&mut answer.point])
    {
        for (momentum, c) in &cuts {
            let along = point.dot(momentum);
            if along > *c {
                *point *= c / along;
            }
        }
    }
    if known.len() >= REST_DIRECTIONS {
        known.remove(0);
    }
    known.push(answer);
}

/// Largest difference of the components of two unit directions that [`RestStatics`] takes as
/// one direction. A record in two components scaled from one accelerogram loads the structure
/// along one line, but its unit directions, (s₁a(t), s₂a(t))/|·|, differ from sample to sample
/// by a few units in the last place: each would otherwise cost its program (on a 3D running-bond
/// wall of 88 coordinates under such a record, the search for joints that open and slide, 1.2 s
/// each, nine times along the same line). The collapse set is convex with 0 inside, so λ(d) is
/// Lipschitz in d: directions 1e-12 apart give multipliers within about 1e-12 × (the set's
/// outer over inner radius) of each other relative, far below the 1e-9 margin of a load called
/// exceeded and the solver's own 1e-10.
const SAME_DIRECTION: f64 = 1e-12;

/// Whether the directions of keys `a` and `b` ([`direction_key`]) are one ([`SAME_DIRECTION`]).
fn same_direction(a: &[u64; 3], b: &[u64; 3]) -> bool {
    a.iter()
        .zip(b)
        .all(|(&x, &y)| (f64::from_bits(x) - f64::from_bits(y)).abs() <= SAME_DIRECTION)
}

/// The exact bits of a unit direction, with −0 read as +0 (the key of [`RestStatics`]' answers).
fn direction_key(d: &Vector3<f64>) -> [u64; 3] {
    [
        (d.x + 0.0).to_bits(),
        (d.y + 0.0).to_bits(),
        (d.z + 0.0).to_bits(),
    ]
}

/// The axis multipliers of the structures one run has met, by the set of their interfaces'
/// names, so that a chain the run returns to (a face that lands where it had opened, the whole
/// structure seated again) does not solve its programs again.
///
/// The multipliers depend only on which faces are present: the programs are posed on the
/// faces of the structure at its reference pose (every joint seated, so every block where the
/// file puts it), and two chains over the same interfaces differ only in their tree and loops
/// (which interfaces close loops, which sense a re-rooted interface is written in), not in the
/// faces or the bodies. The answers' boundary points and cuts (the bodies' momentum in the
/// mechanism, a world vector) are kept with them. The collapses themselves (mechanisms written
/// in one chain's interfaces, slots and senses) are kept with the last chain over those
/// interfaces that computed one, and given back only to a chain equal to it: the same chain
/// met again (a wedge that lands whole) does not search its mechanism again.
#[derive(Clone, Debug, Default)]
pub struct AxisMemory {
    entries: Vec<MemoryEntry>,
}

/// What [`AxisMemory`] keeps for one set of interfaces.
#[derive(Clone, Debug)]
struct MemoryEntry {
    /// The interfaces' names, sorted.
    key: Vec<String>,
    /// λ along the axes, as [`RestStatics`] keeps them.
    axes: [Option<f64>; 6],
    /// Whether each axis's answer is not exhaustive.
    axes_searched: [bool; 6],
    /// Whether some answer kept is not exhaustive.
    any_searched: bool,
    /// The answers' boundary points and cuts.
    known: Vec<KnownAnswer>,
    /// The chain that computed `collapses`, and those collapses by direction.
    collapses: Option<(Model, ByDirection)>,
}

/// Most structures an [`AxisMemory`] keeps (the oldest is dropped beyond).
const AXIS_MEMORY: usize = 64;

impl AxisMemory {
    /// The structure's key: its interfaces' names, sorted (a chain's order is its own).
    fn key(model: &Model) -> Vec<String> {
        let mut names: Vec<String> = model.interfaces.iter().map(|i| i.name.clone()).collect();
        names.sort_unstable();
        names
    }

    /// Rest statics for `model` that start from the axes known for its interfaces.
    pub fn statics_for(&self, model: &Model) -> RestStatics {
        let key = Self::key(model);
        let Some(entry) = self.entries.iter().find(|e| e.key == key) else {
            return RestStatics::default();
        };
        let by_direction = match &entry.collapses {
            Some((chain, collapses)) if chain == model => collapses.clone(),
            _ => Vec::new(),
        };
        RestStatics {
            axes: entry.axes,
            by_direction,
            known: entry.known.clone(),
            programs: 0,
            axes_searched: entry.axes_searched,
            any_searched: entry.any_searched,
            held_on_search: false,
        }
    }

    /// Keeps the axes and answers `statics` has computed for `model` (none computed: nothing to
    /// keep).
    pub fn remember(&mut self, model: &Model, statics: &RestStatics) {
        if statics.axes.iter().all(Option::is_none) {
            return;
        }
        let key = Self::key(model);
        let index = match self.entries.iter().position(|e| e.key == key) {
            Some(index) => index,
            None => {
                if self.entries.len() >= AXIS_MEMORY {
                    self.entries.remove(0);
                }
                self.entries.push(MemoryEntry {
                    key,
                    axes: [None; 6],
                    axes_searched: [false; 6],
                    any_searched: false,
                    known: Vec::new(),
                    collapses: None,
                });
                self.entries.len() - 1
            }
        };
        let entry = &mut self.entries[index];
        for k in 0..6 {
            if entry.axes[k].is_none() && statics.axes[k].is_some() {
                entry.axes[k] = statics.axes[k];
                entry.axes_searched[k] = statics.axes_searched[k];
            }
        }
        entry.any_searched |= statics.any_searched;
        for answer in &statics.known {
            keep_known(&mut entry.known, answer.clone());
        }
        if statics.by_direction.is_empty() {
            return;
        }
        // The collapses of this very chain: those kept before (from statics_for, or computed
        // since) and the new ones, each direction once, the newest last.
        match &mut entry.collapses {
            Some((chain, kept)) if chain == model => {
                for (direction, collapse) in &statics.by_direction {
                    if !kept.iter().any(|(k, _)| k == direction) {
                        if kept.len() >= REST_DIRECTIONS {
                            kept.remove(0);
                        }
                        kept.push((*direction, collapse.clone()));
                    }
                }
            }
            _ => entry.collapses = Some((model.clone(), statics.by_direction.clone())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two courses of running bond (three blocks in the upper course, the whole one centred
    /// over the head joint below) with every bed joint's pivots moved `inset` towards each
    /// other: the upper whole block's centre then lies `inset` beyond either of its supports.
    fn running_bond_inset(inset: f64) -> Model {
        let mut spec = crr_kinematics::fixtures::running_bond_wall(2, 2, 1.0, 0.5, 0.3);
        for interface in &mut spec.interface {
            let (
                Some(crr_kinematics::spec::PivotSpec::Point(p)),
                Some(crr_kinematics::spec::PivotSpec::Point(n)),
            ) = (&mut interface.pivot_positive, &mut interface.pivot_negative)
            else {
                panic!("the fixture's joints are hinges with pivot points");
            };
            p[0] -= inset;
            n[0] += inset;
        }
        Model::from_spec(&spec).expect("the wall builds")
    }

    /// [`Program::reach_at_precision`] against the program at the model's precision solved:
    /// every program with a set of joints unloaded, on a wall whose upper block's centre lies
    /// 3e-7 of the model's size beyond its supports (no equilibrium as written where one half
    /// is unloaded; one within the model's precision, 1e-5 of the block's weight). Where the
    /// bound says the program at the model's precision has no equilibrium, it has none; where
    /// it bounds λ, λ at the model's precision is below it. And the bound decides: it rules the
    /// second program out for most sets with no equilibrium, and never for the knife edge.
    #[test]
    fn the_dual_bounds_the_program_at_the_model_s_precision() {
        let model = running_bond_inset(3e-7);
        let faces = precision::faces_at_precision(&model);
        let interfaces = model.interfaces.len();
        let none = vec![false; interfaces];
        // Sets the bound rules out (no equilibrium at λ ≥ 0 at the model's precision, and the
        // bound says so); sets with none as written and one at the model's precision; sets
        // whose λ the model's precision raises.
        let (mut ruled_out, mut knife_edges, mut raised, mut without) = (0, 0, 0, 0);
        for d in [Vector3::x(), -Vector3::x()] {
            let options = StaticsOptions::default();
            for set in 0..1u32 << interfaces {
                let unloaded: Vec<(usize, usize)> = (0..interfaces)
                    .filter(|&i| set & (1 << i) != 0)
                    .flat_map(|i| (0..faces[i].points.len()).map(move |p| (i, p)))
                    .collect();
                let build = |precision| {
                    Program::build(
                        &model,
                        &faces,
                        d,
                        &options,
                        &none,
                        &unloaded,
                        &[],
                        precision,
                    )
                };
                let written = build(Precision::Exact);
                let Ok(solution) = written.solve_verdict() else {
                    continue;
                };
                let reach = written.reach_at_precision(&solution);
                let at_precision = build(Precision::Model).solve().map(|s| s.x[0]);
                let as_written = no_certificate(solution).map(|s| s.x[0]);
                let holds = |answer: &Result<f64, StaticsError>| {
                    answer.as_ref().is_ok_and(|&l| l >= HOLDS_FROM)
                };
                match &at_precision {
                    Ok(lambda) => assert!(
                        *lambda <= reach,
                        "set {set:b} along {d:?}: λ {lambda} at the model's precision beyond \
                         the bound {reach}"
                    ),
                    Err(StaticsError::DoesNotHold(_)) => {}
                    Err(e) => panic!("set {set:b}: {e}"),
                }
                if !holds(&at_precision) {
                    without += 1;
                    ruled_out += usize::from(reach < HOLDS_FROM);
                }
                if holds(&at_precision) && !holds(&as_written) {
                    knife_edges += 1;
                }
                if let (Ok(exact), Ok(lambda)) = (&as_written, &at_precision) {
                    raised += usize::from(*lambda > exact + 1e-7);
                }
            }
        }
        println!(
            "{ruled_out} of {without} without equilibrium ruled out, {knife_edges} knife edges, \
             {raised} raised"
        );
        assert!(
            ruled_out * 10 >= without * 9,
            "{ruled_out} of {without} sets without equilibrium ruled out"
        );
        assert!(
            knife_edges > 0,
            "no knife edge: the test's wall must have one"
        );
        assert!(raised > 0, "no λ raised by the model's precision");
    }

    /// [`smallest_friction`] on closed forms λ(μ): it answers the upper end of a bracket of
    /// [`FRICTION_DIGITS`] around μ*, whatever the shape below μ*, and where λ is linear below
    /// μ* (a block sliding on its bed) in fewer programs than the 16 of a bisection.
    #[test]
    fn the_smallest_friction_brackets_the_closed_form() {
        type Lambda = fn(f64) -> Option<f64>;
        // (name, μ*, λ(μ), most programs; bisection takes 16 on the first)
        let cases: [(&str, f64, Lambda, usize); 4] = [
            // A block of b/h = 0.163 sliding below it: λ = min(μ, 0.163).
            ("linear", 0.163, |mu| Some(mu.min(0.163)), 6),
            // No equilibrium below μ = 0.05, then a curved sliding branch up to 0.4.
            (
                "curved",
                0.4f64.sqrt(),
                |mu| (mu >= 0.05).then(|| (mu * mu).min(0.4)),
                usize::MAX,
            ),
            // Flat short of the answer, then a jump: only bisection can find the step.
            (
                "step",
                3.7,
                |mu| Some(if mu < 3.7 { 0.2 } else { 0.9 }),
                usize::MAX,
            ),
            // Reaches at μ = 0.
            ("none needed", 0.0, |_| Some(0.5), 1),
        ];
        for (name, exact, lambda, most) in cases {
            let target = lambda(1e3).unwrap() * (1.0 - 1e-9);
            let mut calls = 0;
            let mu = smallest_friction(|mu| {
                calls += 1;
                Ok(lambda(mu).map(|l| l - target))
            })
            .unwrap();
            // The answer reaches, and the bracket it closes lies within 1e-4 of it.
            assert!(lambda(mu).is_some_and(|l| l >= target), "{name}: {mu}");
            assert!(mu >= exact * (1.0 - 1e-8), "{name}: {mu} below {exact}");
            assert!(
                mu <= exact * (1.0 + FRICTION_DIGITS) + 1e-12,
                "{name}: {mu}"
            );
            assert!(calls <= most, "{name}: {calls} programs");
        }
        // Beyond μ = 1000: infinity.
        let mu = smallest_friction(|mu| Ok(Some(mu.min(2e3) - 1.5e3))).unwrap();
        assert_eq!(mu, f64::INFINITY);
    }

    fn answer(point: [f64; 3], cut: Option<([f64; 3], f64)>) -> KnownAnswer {
        KnownAnswer {
            point: Vector3::from(point),
            cut: cut.map(|(v, c)| (Vector3::from(v), c)),
        }
    }

    /// The polygon of answers holds a load in a triangle of 0 and two points, in their plane,
    /// and nothing beyond a mechanism's cut: with λ = 1 along x and y, the diagonal load
    /// (0.45, 0.45) lies in the triangle (α + β = 0.9) and holds; a mechanism found along the
    /// diagonal with momentum V = (1, 1, 0) and λ = 0.4·√2 (x·V ≤ 0.8) keeps (0.35, 0.35) and
    /// (0.5, 0.25) (x·V = 0.7 and 0.75) but not (0.45, 0.45) (0.9), nor, once the axes' points
    /// are pulled in onto it (to (0.8, 0, 0) and (0, 0.8, 0)), (0.7, 0.2) after the cut's
    /// answer is dropped: a load the hull of the original points held.
    #[test]
    fn a_load_holds_in_the_polygon_of_answers_and_within_every_cut() {
        let mut statics = RestStatics::default();
        statics.keep_answer(answer([1.0, 0.0, 0.0], None));
        statics.keep_answer(answer([0.0, 1.0, 0.0], None));
        let within = |s: &RestStatics, x: [f64; 3]| s.within_known_loads(&Vector3::from(x));
        assert!(within(&statics, [0.45, 0.45, 0.0]));
        assert!(!within(&statics, [0.55, 0.5, 0.0]), "beyond the chord");
        assert!(!within(&statics, [-0.1, 0.5, 0.0]), "outside the cone");
        assert!(!within(&statics, [0.3, 0.3, 1e-6]), "out of the plane");
        assert!(within(&statics, [0.7, 0.2, 0.0]));
        statics.keep_answer(answer([0.4, 0.4, 0.0], Some(([1.0, 1.0, 0.0], 0.8))));
        assert!(within(&statics, [0.35, 0.35, 0.0]));
        assert!(within(&statics, [0.5, 0.25, 0.0]));
        assert!(!within(&statics, [0.45, 0.45, 0.0]), "beyond the cut");
        assert_eq!(statics.known[0].point, Vector3::new(0.8, 0.0, 0.0));
        let cut = statics.known.pop().expect("the cut's answer");
        assert!(cut.cut.is_some());
        assert!(!within(&statics, [0.7, 0.2, 0.0]), "the cut dropped");
        assert!(within(&statics, [0.35, 0.35, 0.0]));
    }

    /// A mechanism's cut is its kinematic bound along every direction: Housner's block (half
    /// width b, half height h) tips about an edge where the effective gravity g(ẑ + λd) passes
    /// through it, λ(d) = b/(d_x h − b d_z) for d = (d_x, 0, d_z) with a positive denominator;
    /// the cut of the answer along +x passes through λ(d)·d for every such d (1e-9 relative:
    /// the program's duality gap is 1e-12 of the weight).
    #[test]
    fn the_cut_of_housner_s_block_is_its_closed_form_in_every_direction() {
        let (b, h) = (0.2, 1.0);
        let model = Model::from_spec(&crr_kinematics::fixtures::single_block(b, h, 2500.0))
            .expect("the fixture builds");
        let x = Vector3::x();
        let collapse = collapse_multiplier(&model, x, &StaticsOptions::default()).unwrap();
        let (v, c) = KnownAnswer::of(&model, &x, &collapse)
            .cut
            .expect("the block tips along x");
        for phi in [-1.2, -0.6, -0.2, 0.0, 0.3, 0.7, 1.1] {
            let d = Vector3::new(f64::cos(phi), 0.0, f64::sin(phi));
            let lambda = b / (d.x * h - b * d.z);
            assert!(lambda > 0.0);
            let on_cut = (lambda * d).dot(&v) / c;
            assert!((on_cut - 1.0).abs() <= 1e-9, "φ = {phi}: {on_cut}");
        }
    }

    /// The memory gives a collapse back only to the chain that computed it, and what it gives
    /// back is what that chain's program answers: a trilithon loaded at 1.5 λ along x solves
    /// its program once, the same chain met again solves none and gets the collapse computed
    /// afresh, bit for bit; a trilithon over the same interfaces with wider columns (half
    /// width 0.25 instead of 0.2: the same names, other faces) solves its own and gets its own
    /// λ, not the first one's.
    /// A record in two components scaled from one accelerogram loads along one line; its unit
    /// directions differ in their last bits from sample to sample. One program answers for the
    /// line, and its λ is the one a program along each exact direction gives, to 1e-9.
    #[test]
    fn loads_along_one_line_share_one_program() {
        let model = Model::from_spec(&crr_kinematics::fixtures::trilithon(
            0.2, 1.0, 2.0, 0.4, 0.3,
        ))
        .expect("the fixture builds");
        let g = model.gravity;
        let line = Vector3::new(1.5, 0.0, 0.3);
        let mut statics = RestStatics::default();
        let mut answers = Vec::new();
        for r in [0.7, 0.7000001, 0.8, 0.93] {
            let a = line * (r * g);
            answers.push((a, statics.exceeded(&model, &a).unwrap().cloned()));
        }
        let directions: std::collections::BTreeSet<[u64; 3]> = answers
            .iter()
            .map(|(a, _)| direction_key(&a.normalize()))
            .collect();
        assert!(directions.len() > 1, "the directions differ in their bits");
        let solved = statics.programs_solved();
        for (a, answer) in &answers {
            let fresh = collapse_multiplier(&model, a.normalize(), &StaticsOptions::default())
                .unwrap()
                .lambda
                .unwrap();
            let kept = statics.exceeded(&model, a).unwrap().cloned();
            assert_eq!(&kept, answer);
            if let Some(c) = answer {
                assert!((c.lambda.unwrap() - fresh).abs() <= 1e-9 * fresh);
            } else {
                assert!(a.norm() <= fresh * g * (1.0 + 1e-9));
            }
        }
        assert_eq!(statics.programs_solved(), solved, "no program again");
        // The axes (±x and ±z, those the load has components along) and one along the line.
        assert!(solved <= 5, "{solved} programs");
    }

    #[test]
    fn the_memory_gives_a_collapse_back_only_to_an_equal_chain() {
        let build = |b: f64| {
            Model::from_spec(&crr_kinematics::fixtures::trilithon(b, 1.0, 2.0, 0.4, 0.3))
                .expect("the fixture builds")
        };
        let (narrow, wide) = (build(0.2), build(0.25));
        let fresh = |model: &Model| {
            collapse_multiplier(model, Vector3::x(), &StaticsOptions::default()).unwrap()
        };
        let (narrow_collapse, wide_collapse) = (fresh(&narrow), fresh(&wide));
        let lambda = narrow_collapse.lambda.expect("the trilithon collapses");
        assert!(
            wide_collapse
                .lambda
                .is_some_and(|l| (l - lambda).abs() > 1e-6 * lambda)
        );
        let a = Vector3::x() * 1.5 * lambda * narrow.gravity;

        let mut memory = AxisMemory::default();
        let mut statics = memory.statics_for(&narrow);
        let first = statics.exceeded(&narrow, &a).unwrap().cloned();
        assert_eq!(first.as_ref(), Some(&narrow_collapse));
        assert!(statics.programs_solved() >= 1);
        memory.remember(&narrow, &statics);

        let mut again = memory.statics_for(&narrow);
        let second = again.exceeded(&narrow, &a).unwrap().cloned();
        assert_eq!(second.as_ref(), Some(&narrow_collapse));
        assert_eq!(again.programs_solved(), 0);

        let mut other = memory.statics_for(&wide);
        let a_wide = Vector3::x() * 1.5 * wide_collapse.lambda.unwrap() * wide.gravity;
        let third = other.exceeded(&wide, &a_wide).unwrap().cloned();
        assert_eq!(third.as_ref(), Some(&wide_collapse));
        assert!(other.programs_solved() >= 1);
    }
}
