//! The event-driven simulation: rocking, impacts, seating, uplift and collapse.
//!
//! Every interface angle slot is **seated** (φ = 0 held by a constraint row) or **rocking** about
//! P⁺ or P⁻ (its side in the dynamic chain). Between events the constrained equations of motion are
//! integrated with DOP853 (or the method chosen), never stepping across a breakpoint of the ground
//! motion. Events, located on the dense output and then reached by a real step:
//! - a rocking angle crossing 0: an **impact** (all rocking angles within
//!   [`Parameters::simultaneity`] of 0 and moving towards it impact together, as the four hinges of
//!   an arch); the pivots switch and the interface's impact law maps q̇⁻ to q̇⁺;
//! - **uplift** of seated interfaces, when keeping them seated would need tension (see
//!   [`opening_mode`]);
//! - **collapse**: the potential energy falls below its value at rest by more than
//!   [`Parameters::collapse_drop`]·W·L (W the weight, L the model size) while the rotations grow
//!   (q·q̇ > 0): the structure is past its point of no return (for a block, beyond θ = 2α); the run
//!   stops with the time and the body whose centre has dropped most. Also a collapse, naming
//!   the body: a rocking contact turned to π/2 (a body laid on its support's plane, its own
//!   event), and the flight of bodies already fallen past their point of no return on their
//!   support (`Simulation::fallen_in_flight`).
//!
//! **Seating** (the Zeno limit of free rocking, infinitely many impacts in finite time): after an
//! impact, an interface whose rate is below [`Parameters::seat_rate`], or that impacted less than
//! [`Parameters::min_impact_interval`] before, is seated with a plastic impulse on that angle alone
//! (its rate set to 0, the other generalized momenta kept); the run continues seated until uplift.

use std::sync::Arc;

use nalgebra::DVector;
use serde::Serialize;

use crr_dynamics::eom::{Dynamics, GeneralizedForce, slot_row};
use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::integrator::{
    DenseStep, Direction, EventFunctions, Method, Options, SolveError, Solver, StepEnds, Stop,
};
use crr_dynamics::roots::sign_change;
use crr_dynamics::{ConstrainedSystem, InitialState};
use crr_kinematics::short_copy::{assign, copy_short, extend_short};
use crr_kinematics::spec::ImpactLaw;
use crr_kinematics::velocity::point_bias_acceleration;
use crr_kinematics::{
    ActivePivots, Data, InterfaceKind, Model, Side, closure_angles, forward_kinematics,
    potential_energy,
};

use crate::laws::{
    ImpactError, LawWorkspace, RegularisedSlot, dirac_law_holding, dirac_regularised_force,
    momentum_law_projected, restitution_law_holding,
};

mod certificate_audit;
mod events;
mod hops;
mod impact_releases;
mod impacts;
mod landing_check;
mod open_loops;
mod opening_qp;
mod output;
mod samples;
mod seating;
mod slots;
mod uplift_from_rest;

pub use certificate_audit::{CertificateAudit, CertificateDisagreement};
use events::*;
pub use hops::Hop;
use impacts::*;
use open_loops::OpenLoops;
pub use open_loops::body_offsets;
pub use opening_qp::{
    IMPULSE_OPENING_TOLERANCE, OpeningDecision, OpeningQpError, QP_OPENING_TOLERANCE, impulse_qp,
    offers_both_pivots, opening_qp, opening_qp_holding,
};
pub use samples::{FaceOpening, Iter as SampleIter, Sample, Samples};
pub(crate) use seating::other_pivot_rest;
pub use seating::{
    CERTIFIED_CLOSURE_RESIDUAL, DOUBTFUL_CHECK_RESIDUAL, opening_mode, openings_slide_nowhere,
};
use seating::{UndecidedRow, opening_mode_in};
pub use slots::check_initial_state;
pub(crate) use slots::slot_interface;
use slots::*;
use uplift_from_rest::{RestCache, opening_from_rest};

/// Largest step while joints are seated and the ground moves (s): the time resolution of the
/// uplift test (exact location then by bisection on the release test).
pub const SEATED_MAX_STEP: f64 = 1e-3;

/// Samples per shortest period of the ground motion on the seated grid: the grid step is
/// min([`SEATED_MAX_STEP`], period / this), so that no sine or pulse is sampled at its zeros only
/// (a 1 ms grid under a 500 Hz sine) and the sampled peak is within 1 − cos(π/32) = 0.5 % of the
/// true one.
pub const SEATED_SAMPLES_PER_PERIOD: f64 = 32.0;

/// The grid step of the uplift test while joints are seated under `ground`.
pub(crate) fn seated_step(ground: &GroundMotion) -> f64 {
    ground.time_scale().map_or(SEATED_MAX_STEP, |t| {
        SEATED_MAX_STEP.min(t / SEATED_SAMPLES_PER_PERIOD)
    })
}

/// Tunable parameters of a simulation, with documented defaults.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Parameters {
    /// End time of the run (s).
    pub duration: f64,
    /// Interval between output samples (s). Default 0.01.
    pub output_interval: f64,
    /// Integration method. Default DOP853.
    #[serde(skip)]
    pub method: Method,
    /// Integrator tolerances. Default rtol 1e-10, atol 1e-12.
    pub options: Options,
    /// An interface whose rate after an impact is below this seats (rad/s). Default 1e-4.
    pub seat_rate: f64,
    /// An interface impacting again within this time seats (s). Default 1e-6.
    pub min_impact_interval: f64,
    /// Rocking angles within this of 0 at an impact impact together (rad). Default 1e-8.
    pub simultaneity: f64,
    /// Largest number of impacts before the run stops with an error. Default 1 000 000.
    pub max_impacts: usize,
    /// Friction coefficient μ of every contact for the hypotheses monitor (None: not checked).
    pub friction: Option<f64>,
    /// Collapse is declared when U falls below its rest value by this fraction of W·L (total
    /// weight times the model size) while the rotations grow. Default 1e-3.
    pub collapse_drop: f64,
    /// Keep every seated joint seated through a momentum-law impact even where that pulls
    /// (recorded as `impulse_tension`) instead of opening them by Moreau's impact
    /// (`simulation::impact_releases`). Default false.
    pub hold_seated_at_impacts: bool,
    /// A pull at a pivot where a segment starts whose hop opens, lands and departs from the
    /// chain's motion by no more than this (m) is not a violation (module `hops`). Default 0:
    /// every such pull is one.
    pub hop_tolerance: f64,
    /// End the run at the first violation of the rigid-contact hypotheses
    /// ([`Trajectory::violation`]): at the end of the first step that starts after it with no
    /// pull at a pivot being measured (module `hops`: a pull found just after an impact is
    /// measured to its end, and its hop completes the record). What follows is outside the
    /// model. Default false: the run goes on to its duration.
    pub stop_at_violation: bool,
}

impl Default for Parameters {
    /// The defaults of `[analysis]` ([`crr_dynamics::AnalysisSpec::default`], their one owner)
    /// with a duration of 10 s.
    fn default() -> Self {
        Self::from_analysis(&crr_dynamics::AnalysisSpec::default(), 10.0)
            .expect("the default analysis settings are valid")
    }
}

impl Parameters {
    /// Parameters from a model file's `[analysis]` table; `default_duration` applies when it gives
    /// none. Errors name the bad field.
    pub fn from_analysis(
        a: &crr_dynamics::AnalysisSpec,
        default_duration: f64,
    ) -> Result<Self, String> {
        let (method, options) = a.solver()?;
        Ok(Self {
            duration: a.duration.unwrap_or(default_duration),
            output_interval: a.output_interval,
            method,
            options,
            seat_rate: a.seat_rate,
            min_impact_interval: a.min_impact_interval,
            simultaneity: a.simultaneity,
            max_impacts: a.max_impacts,
            friction: a.friction,
            collapse_drop: a.collapse_drop,
            hold_seated_at_impacts: a.hold_seated_at_impacts,
            hop_tolerance: a.hop_tolerance,
            stop_at_violation: a.stop_at_violation,
        })
    }
}

/// The state of one angle slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum SlotState {
    /// Held at φ = 0.
    Seated,
    /// Rocking about P⁺.
    Positive,
    /// Rocking about P⁻.
    Negative,
    /// The whole face lifted off: no pivot, the interface out of the dynamic chain until a
    /// point of its face lands (docs/simulation.md, "Faces that open").
    Open,
}

impl SlotState {
    /// `seated`, `+`, `-` or `open` (the history file's codes).
    pub fn code(self) -> &'static str {
        match self {
            SlotState::Seated => "seated",
            SlotState::Positive => "+",
            SlotState::Negative => "-",
            SlotState::Open => "open",
        }
    }
}

/// One impact.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImpactRecord {
    /// Time (s).
    pub t: f64,
    /// Names of the impacting interfaces.
    pub interfaces: Vec<String>,
    /// The impacting angle slots.
    pub slots: Vec<usize>,
    /// Their rates before (rad/s).
    pub rates_before: Vec<f64>,
    /// Their rates after (rad/s).
    pub rates_after: Vec<f64>,
    /// T⁻ − T⁺ (J), including the seating of interfaces that came to rest.
    pub energy_lost: f64,
    /// The law would have raised the kinetic energy.
    pub energy_gain: bool,
    /// Slots seated at this impact.
    pub seated: Vec<usize>,
    /// Seated slots this impact opened (a momentum-law impact that would otherwise pull at
    /// them: Moreau's impact, `simulation::impact_releases`), now rocking on the pivot of
    /// their state after it.
    pub released: Vec<usize>,
}

/// A local extremum of a rocking coordinate (q̇ = 0), located on the dense output.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Peak {
    /// Time (s).
    pub t: f64,
    /// Coordinate index.
    pub coordinate: usize,
    /// Its value (rad).
    pub value: f64,
}

/// A collapse.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Collapse {
    /// Time (s).
    pub t: f64,
    /// The body whose centre has dropped most below its rest height; for a body that toppled
    /// (a contact turned to π/2) or fell off its support (a flight past its point of no return),
    /// that body.
    pub body: String,
}

/// Why [`Simulation::step`] returned.
#[derive(Clone, Debug, PartialEq)]
pub enum StopReason {
    /// A breakpoint of the ground motion was reached; nothing else happened.
    Breakpoint(f64),
    /// An impact (index into [`Simulation::impacts`]).
    Impact(usize),
    /// Seated interfaces uplifted: (slot, side), slots in the file's numbering and sides as the
    /// slot states report them ([`Simulation::states`]).
    Uplift(f64, Vec<(usize, Side)>),
    /// The structure collapsed.
    Collapse(Collapse),
    /// The end time was reached.
    End(f64),
}

/// A failure of a simulation (the results computed so far stay available).
#[derive(Debug, thiserror::Error)]
pub enum SimulationError {
    /// The integrator failed.
    #[error("integration failed: {0}")]
    Solve(#[from] SolveError),
    /// An impact law failed.
    #[error("impact at t = {t}: {source}")]
    Impact {
        /// Time (s).
        t: f64,
        /// The law's error.
        source: ImpactError,
    },
    /// The equations of motion failed (e.g. a singular mass matrix).
    #[error("equations of motion at t = {t}: {source}")]
    Dynamics {
        /// Time (s).
        t: f64,
        /// The failure.
        source: crr_dynamics::DynamicsError,
    },
    /// Too many impacts.
    #[error("more than {0} impacts: raise analysis.max_impacts or check the seating parameters")]
    TooManyImpacts(usize),
    /// Impacts chatter: the last [`CHATTER_IMPACTS`] impacts came less than
    /// `min_impact_interval` apart on average, among at most a tenth as many interfaces. Single
    /// impacts in sequence that do not settle (a block landing on one support and then on the other, each
    /// landing lifting it off the first again) are a simultaneous contact the event-driven model
    /// does not resolve; the run stops instead of spending hours of impacts on microseconds.
    #[error(
        "at t = {t} s the last {count} impacts came within {span:.3e} s, among {}: single impacts in sequence that do not settle (a body landing on its supports in turn); outside what the event-driven model resolves (docs/simulation.md, \"Limitations\")",
        interfaces.join(", ")
    )]
    Chatter {
        /// Time (s).
        t: f64,
        /// The impacts counted.
        count: usize,
        /// Time from the first of them to the last (s).
        span: f64,
        /// The interfaces they involve.
        interfaces: Vec<String>,
    },
    /// A joint an impact seats keeps turning after the plastic impulse that seats it: its rate
    /// row is dependent on the loops' (and the other seated joints') within the rank threshold,
    /// so the impulse cannot act on it alone. The loop is near a singular configuration of its
    /// angles (pivots nearly in line, as two columns rocking about collinear edges under one
    /// beam), where holding the seat would take an impulse beyond the rigid model's resolution;
    /// left seated, the joint reopened on the side the contacts chose while it still turned the
    /// other way, and re-impacted at once (a 3D trilithon: 200 impacts within 7e-7 s).
    #[error(
        "at t = {t} s the seat of {interface} cannot be held: the plastic impulse that seats it leaves it turning at {rate:.3e} rad/s, its rate dependent on the loops' within the rank threshold (a loop near a singular configuration, e.g. pivots nearly in line); outside what the chain's angles resolve (docs/simulation.md, \"Limitations\")"
    )]
    UnheldSeat {
        /// Time (s).
        t: f64,
        /// The interface whose seat cannot be held.
        interface: String,
        /// Its rate after the seating impulse (rad/s).
        rate: f64,
    },
    /// The uplift test keeps finding that the seated state cannot hold while no release is
    /// confirmed: [`UNDECIDED_UPLIFTS`] uplift events in a row released nothing, each within
    /// [`UNDECIDED_GAP`] of the one before (a step of round-off length, with no release or impact
    /// between them). Where the contact program lifts faces off that the chain without them
    /// drives into their supports, and the chain with them finds no motion of its own, the
    /// engine cannot decide the state, and the run stops instead of stepping by 1e-13 s for
    /// ever.
    #[error(
        "at t = {t} s the uplift test fired {events} times within {span:.3e} s without a release: {}; the engine cannot decide this state (docs/simulation.md, \"Limitations\")",
        if interfaces.is_empty() {
            "the seated state cannot hold, but no release is confirmed by the chain's own equations".to_string()
        } else {
            format!("the contact program lifts {} off a support, the chain without them drives one into it, and the chain with them confirms none of the program's other releases", interfaces.join(", "))
        }
    )]
    Undecided {
        /// Time (s).
        t: f64,
        /// The uplift events counted.
        events: u32,
        /// Time from the first of them to the last (s).
        span: f64,
        /// The faces the contact program lifted off and the chain contradicted during these
        /// events (empty when none did).
        interfaces: Vec<String>,
    },
    /// More output samples in memory than the caller allows.
    #[error(
        "more than {max} output samples in memory at t = {t} s: raise output_interval, or the \
         sample limit if the memory allows, or stream the history to a file (crr simulate); \
         the results until then are kept"
    )]
    TooManySamples {
        /// The limit.
        max: usize,
        /// Time reached (s).
        t: f64,
    },
    /// The caller asked the run to stop (Ctrl-C, SIGTERM, a cancellation flag).
    #[error("interrupted at t = {t} s: the results until then are kept")]
    Cancelled {
        /// Time reached (s).
        t: f64,
    },
    /// A bad parameter.
    #[error("{0}")]
    Parameter(String),
    /// The run's invariant failed (a rocking angle past its pivot, loops open): the message says
    /// which angle, when, and what to change.
    #[error("{0}")]
    Invariant(String),
    /// The contact program finds that blocks lift off a support (at rest: the mechanism the load
    /// opens; in motion: the motion of least Gauss function), or a face rocking on a pivot that
    /// alone carries the bodies above it (on an open chain, or a block hanging on one face of a
    /// structure with loops) would pull on it, and the chain cannot go on without those
    /// interfaces: a body left with no support (a flight), or no spanning tree left that the CRR
    /// model can integrate (docs/simulation.md, "Faces that open").
    #[error(
        "at t = {t} s the contacts' decision finds a motion in which {} lift(s) off a support: {reason}; outside the CRR model, which keeps every interface on a pivot",
        interfaces.join(", ")
    )]
    LiftOff {
        /// Time (s).
        t: f64,
        /// The interfaces that open entirely.
        interfaces: Vec<String>,
        /// The bodies left with no path to the ground through the contacts that stay closed: a
        /// flight. Empty when every body keeps a support.
        in_flight: Vec<String>,
        /// Why the run cannot follow it, in words.
        reason: String,
    },
}

/// Snaps (seated joints set to exactly 0, loops closed again) that moved more than this
/// fraction of the energy the impacts (and the regularised Dirac forces, whose pivot switches
/// are elastic) dissipated, over the part of the run inside the model, are
/// a warning (`crr simulate`): the energy booked as dissipated is then partly the
/// idealisation's, not the impact laws'.
pub const SNAP_ENERGY_FRACTION: f64 = 1e-2;

/// The snaps' Σ|ΔT + ΔU| and the impacts' Σ`energy_lost` until a time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SnapsAndLosses {
    /// Time (s): the monitor's first violation, or the end of the run.
    pub t: f64,
    /// Σ|ΔT + ΔU| of the snaps until then (J).
    pub snaps: f64,
    /// Σ of the impacts' `energy_lost` until then, plus what the regularised Dirac forces
    /// dissipated (J): a `dirac_regularised` law's pivot switch is elastic and its force does
    /// the dissipation, which a comparison with the impacts alone left out (the single block
    /// under it was warned that snaps of 1.6e-8 J outweighed the impacts' 2e-15 J).
    pub lost: f64,
}

/// The words of [`SimulationError::LiftOff`] on the bodies it leaves without support.
pub(crate) fn flight_words(in_flight: &[String]) -> String {
    format!("{} lose(s) every support: a flight", in_flight.join(", "))
}

/// The bodies with no path to the ground through the interfaces other than `lifting` (each
/// interface joins its parent and its child), in the model's order: the bodies that would fly
/// if those interfaces opened.
pub fn bodies_without_support(model: &Model, lifting: &[String]) -> Vec<String> {
    let removed: Vec<bool> = model
        .interfaces
        .iter()
        .map(|f| lifting.contains(&f.name))
        .collect();
    model
        .bodies_off_ground(&removed)
        .into_iter()
        .map(|b| model.bodies[b].name.clone())
        .collect()
}

/// A run that failed part-way: the error and everything computed before it.
#[derive(Debug)]
pub struct Interrupted {
    /// What went wrong.
    pub error: SimulationError,
    /// The results up to the failure.
    pub partial: Trajectory,
}

/// The most output samples one [`Simulation::step`] produces.
const MAX_SAMPLES_PER_STEP: usize = 4096;

/// Impact records a run has room for from the start (a rocking run has tens to hundreds).
const INITIAL_IMPACT_ROOM: usize = 256;

/// An event-driven simulation of one structure under one ground motion.
pub struct Simulation<'a> {
    /// The dynamic chain integrated now: the file's model without the interfaces whose faces
    /// lifted off ([`Model::with_open_interfaces`]), its tree grown again where one of
    /// them was in it.
    model: Arc<Model>,
    /// The file's model, moved near the origin where it lies far from it
    /// ([`Model::moved_near_origin`]): the outputs' slots (samples, impacts) are numbered as its
    /// slots.
    original: Arc<Model>,
    /// The faces open: which interfaces of `original` are open, the slots' maps between the
    /// two models and the open faces watched for a corner touching again.
    open: OpenLoops,
    /// q and q̇ of the sample being taken in the file's coordinates, when the chain's tree is
    /// not the file's (`OpenLoops::files_tree`).
    file_q: Vec<f64>,
    file_qdot: Vec<f64>,
    /// Counts the changes of chain: a workspace taken before a call that may change it is
    /// given back only if the chain is still the same.
    chain_changes: u64,
    /// The rest statics' axis multipliers of the chains met so far, by their interfaces.
    axis_memory: crate::statics::AxisMemory,
    ground: &'a GroundMotion,
    params: Parameters,
    dynamics: Dynamics,
    solver: Solver,
    regularised: Option<Regularised>,
    out_kin: Data,
    /// Workspaces reused by every segment and sample: the events' kinematics, the uplift test's
    /// dynamics and the monitor's dynamics (the run allocates them once, not per step).
    spare: Workspaces,
    /// The model's connected parts (the uplift test batches its releases over them).
    parts: crr_kinematics::Parts,
    /// Per slot of the chain integrated, whether it is a rocking contact, not a pin
    /// ([`slots::contact_slots`]).
    contact_slots: Vec<bool>,
    /// State [q, q̇, W, D] at the current time.
    y: Vec<f64>,
    t: f64,
    seated: Vec<bool>,
    last_impact: Vec<f64>,
    dissipated_at_impacts: f64,
    /// Σ of the impacts' `energy_lost`, summed as each impact is appended ([`Self::push_impact`])
    /// in the order `Iterator::sum` adds them (from −0.0), so that a sample does not add up the
    /// whole list again: a long run's cost stays linear in its impacts. Every impact appended
    /// counts, also those a caller has since removed from `impacts` (a Poincaré section clears
    /// the list as it goes).
    lost_at_impacts: f64,
    /// Σ|ΔT + ΔU| of the snaps booked in `dissipated_at_impacts` ([`Trajectory::energy_at_snaps`]).
    energy_at_snaps: f64,
    /// The first sample of the last instant samples were taken at: its time, the chain's
    /// coordinates by name and their values. Taken before that instant's events (an impact, a
    /// landing) switch the state: what their snaps moved ([`Self::angle_before_events`]).
    pre_event: (f64, Vec<(String, f64)>, Vec<Side>),
    /// The snaps and the impacts' losses when the monitor first found a hypothesis failing.
    snaps_at_violation: Option<SnapsAndLosses>,
    /// Uplift events in a row that released nothing ([`SimulationError::Undecided`]).
    undecided: UndecidedRow,
    u_rest: f64,
    energy_start: f64,
    next_sample: usize,
    /// The instant of the last uplift event whose samples were deferred to the motion after its
    /// release (−∞ before any): such a sample, at its grid instant up to the event's bracket
    /// before it, is judged under the load the release was decided with (at a jump, the load
    /// after it; [`Self::sample_under_load_at`]).
    deferred_to: f64,
    finished: bool,
    /// Running over every sample recorded (also those drained): peak |q| per coordinate, the
    /// largest |T + U − W + D − E(0)|, the time of the last sample.
    peak_abs: Vec<f64>,
    balance_error: f64,
    last_sample_t: f64,
    /// Output samples at the output interval, plus the instants just before and after impacts,
    /// since the last [`Simulation::drain_samples`].
    pub samples: Samples,
    /// Every impact, in time order.
    pub impacts: Vec<ImpactRecord>,
    /// Local extrema of the rocking coordinates.
    pub peaks: Vec<Peak>,
    /// First uplift from a seated state.
    pub uplift_time: Option<f64>,
    /// The collapse, if the structure collapsed.
    pub collapse: Option<Collapse>,
    /// First failure of the no-flight (compressive contact) or no-slip hypothesis, checked at
    /// every output sample and impact instant.
    pub violation: Option<crate::monitor::Violation>,
    /// The largest opening of the loops at acceleration level left by the monitor's solves.
    loop_residual: LoopResidual,
    /// The first decision that rested on a solve left with the loops open.
    doubtful_check: Option<DoubtfulCheck>,
    /// The first instant at rest held on a multiplier that is not exhaustive.
    held_on_search: Option<HeldOnSearch>,
    /// The pulls at pivots where segments start, measured (module `hops`).
    hops: hops::Hops,
}

/// The largest opening of the loops at acceleration level (Φ_q q̈ + Φ̇_q q̇ of a closure row,
/// [`Dynamics::loop_residual`]) left by the closed-chain solves at the output samples, until the
/// monitor's first violation. Round-off (7e-15 to 1.4e-11 m/s² on the bundled models) where the
/// loops are independent or exactly dependent; near a hyperstatic seat the solve takes rows dependent to
/// less than its rank rule as dependent and leaves them open by this much, and decisions whose
/// rates lie below it are within the solve's error (docs/simulation.md, Limitations).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LoopResidual {
    /// The largest residual (m/s²).
    pub largest: f64,
    /// The sample's time (s).
    pub t: f64,
}

/// A decision of the uplift test that rests on a closed-chain solve the run does not trust: the
/// contact program found that joints open, and the chain's solve that checks each release (it
/// must open on its side) left the loops open at acceleration level by more than
/// [`DOUBTFUL_CHECK_RESIDUAL`] g (rows nearly dependent near a hyperstatic seat, taken
/// as dependent: docs/simulation.md, Limitations) and sent some back to their seats. The
/// joints then stay seated on that solve's word alone.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DoubtfulCheck {
    /// The instant of the decision (s).
    pub t: f64,
    /// The loops' opening left by the checking solve, Φ_q q̈ + Φ̇_q q̇ (m/s²).
    pub residual: f64,
    /// The interfaces whose releases were sent back.
    pub interfaces: Vec<String>,
}

/// An instant at which the structure at rest was held on a static multiplier that is not
/// exhaustive ([`crate::statics::RestStatics::held_on_search`]): along that load's direction
/// the structure has more sets of joints that may open and slide than the rest statics try, and
/// the search for them found none below the load, but a lower mechanism may exist
/// (docs/simulation.md, "The exhaustive pass").
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HeldOnSearch {
    /// The instant (s).
    pub t: f64,
    /// The ground acceleration held (m/s²).
    pub load: [f64; 3],
}

/// The buffers of one integration segment ([`Simulation::step`]): the events' state and pivots,
/// the watched slots and the output's scratch.
#[derive(Clone, Debug, Default)]
struct SegmentBuffers {
    rocking: Vec<(usize, Side)>,
    seats: Vec<f64>,
    rocking_coords: Vec<usize>,
    pivots: ActivePivots,
    angles: Vec<f64>,
    q: DVector<f64>,
    qdot: DVector<f64>,
    y: Vec<f64>,
    peaks: Vec<Peak>,
}

/// The buffers of the test for joints coming to rest: q, q̇, the slot angles and rates, the
/// slots near φ = 0.
#[derive(Clone, Debug, Default)]
struct SettleBuffers {
    q: DVector<f64>,
    qdot: DVector<f64>,
    angles: Vec<f64>,
    rates: Vec<f64>,
    candidates: Vec<usize>,
    /// A slot's rate row aᵀ (n entries).
    row: DVector<f64>,
}

/// Workspaces of a simulation reused from segment to segment (taken by a segment's events and
/// given back after it).
#[derive(Clone, Debug)]
struct Workspaces {
    /// Boxed, so that taking and giving back a workspace moves a pointer, not the structure
    /// (a `memcpy` of its size otherwise, at every step or segment).
    events_kin: Option<Box<Data>>,
    trial: Option<Box<Dynamics>>,
    /// The dynamics of the pivot events ([`SegmentEvents::pressing_trial`]),
    /// loaded with the current pivots and seats by each segment that watches a pivot.
    pressing: Option<Box<Dynamics>>,
    /// The buffers of a segment's events and output, taken by each segment and given back.
    segment: Option<Box<SegmentBuffers>>,
    /// The buffers of the test for joints coming to rest ([`Simulation::step`]'s first task).
    settle: Option<Box<SettleBuffers>>,
    monitor: Dynamics,
    /// q, q̇ and the slot states of the sample being taken.
    sample_q: DVector<f64>,
    sample_qdot: DVector<f64>,
    sample_states: Vec<SlotState>,
    /// The open faces' offsets of the sample being taken.
    sample_openings: Vec<FaceOpening>,
    /// The output samples a segment's steps pass, [t, y…] each, taken after the segment.
    pending: Vec<f64>,
    /// Buffers of the monitor's contact forces.
    forces: crate::monitor::ForceWork,
    /// The monitor's distribution on the faces carried across samples at rest.
    faces: crate::face_forces::RestFaces,
    /// The q and q̇ buffers of the segments' right-hand sides ([`ConstrainedSystem::with_buffers`]).
    system: (DVector<f64>, DVector<f64>),
    /// The uplift test's factorisations at rest ([`RestCache`]).
    rest: RestCache,
    /// Scratch of the impacts.
    impact: ImpactBuffers,
    /// The impact laws' buffers.
    laws: crate::laws::LawWorkspace,
    /// The slot angles, q and the closure rows' scale of the invariant's check (no allocation
    /// per step).
    invariant_angles: Vec<f64>,
    invariant_q: DVector<f64>,
    constraint_scale: DVector<f64>,
}

impl Workspaces {
    /// Fresh workspaces of a run on `model` (`trial` a copy of its dynamics).
    fn new(model: &Model, trial: Dynamics, pivots: &ActivePivots) -> Self {
        Self {
            events_kin: Some(Box::new(Data::new(model))),
            trial: Some(Box::new(trial)),
            pressing: None,
            segment: None,
            settle: None,
            monitor: Dynamics::new(model, pivots.clone()),
            sample_q: DVector::zeros(model.dof()),
            sample_qdot: DVector::zeros(model.dof()),
            sample_states: Vec::with_capacity(model.slot_count),
            sample_openings: Vec::new(),
            pending: Vec::new(),
            forces: Default::default(),
            faces: Default::default(),
            rest: RestCache::default(),
            system: Default::default(),
            impact: ImpactBuffers::default(),
            laws: Default::default(),
            invariant_angles: Vec::with_capacity(model.slot_count),
            invariant_q: DVector::zeros(model.dof()),
            constraint_scale: crr_dynamics::eom::constraint_row_scale(model),
        }
    }
}

/// Largest `seat_rate` as a fraction of the structure's rate scale √(g/L): a joint rocking at a
/// tenth of it still swings by a visible angle, and seating it stops real motion.
pub const SEAT_RATE_MAX: f64 = 0.1;

/// Largest `min_impact_interval` as a fraction of the structure's time scale √(L/g): impacts a
/// hundredth of it apart are the Zeno limit of a joint coming to rest, farther apart they are
/// rocking.
pub const MIN_IMPACT_INTERVAL_MAX: f64 = 0.01;

/// Impacts that, coming less than `min_impact_interval` apart on average among at most a tenth
/// as many interfaces, stop a run as [`SimulationError::Chatter`]: the Zeno sequences of rocking
/// (a joint's impacts closer and closer until it seats) seat a joint after its first impact
/// within the interval, so a sequence of hundreds on the same few joints is no rocking.
pub const CHATTER_IMPACTS: usize = 200;

/// Uplift events in a row that release nothing, each within [`UNDECIDED_GAP`] of the one before,
/// that stop a run as [`SimulationError::Undecided`].
pub const UNDECIDED_UPLIFTS: u32 = 100;

/// The gap (s, relative to max(1, t)) within which an uplift event that releases nothing follows
/// the one before as a stall: event times are located to 1e-13·max(1, t) (the integrator's
/// events and the rest scan's bisection), and after such an event the next came 5.8e-14 s later
/// on a 5 × 5 wall; an event that the motion itself brings back comes a step of the motion
/// later. A hundred times the location's precision, so that it scales with t as the steps of a
/// stall do.
pub const UNDECIDED_GAP: f64 = 1e-11;

/// Largest `collapse_drop` (a fraction of weight × model size): a structure whose potential
/// energy has dropped by half its weight times its size has fallen.
pub const COLLAPSE_DROP_MAX: f64 = 0.5;

/// The width of an event's located bracket at time `t` (s): the root finder's tolerance
/// 1e-13 max(|t|, 1) and its round-off 4 ε |t| (`crr_dynamics::integrator`, Brent's method).
fn event_bracket(t: f64) -> f64 {
    1e-13 * t.abs().max(1.0) + 4.0 * f64::EPSILON * t.abs()
}

/// Settings that would change the physics rather than the numerics are refused, with the reason:
/// a seat rate or impact interval as large as the motion's own scales seats joints that rock
/// (turning a collapse into survival), a collapse drop beyond a fall lets a block pass through the
/// ground unreported.
pub fn check_physical_bounds(model: &Model, params: &Parameters) -> Result<(), SimulationError> {
    let rate_scale = (model.gravity / model.size).sqrt();
    let time_scale = 1.0 / rate_scale;
    if params.seat_rate > SEAT_RATE_MAX * rate_scale {
        return Err(SimulationError::Parameter(format!(
            "seat_rate = {} rad/s is not small against the structure's rate scale √(g/L) = {rate_scale:.4} rad/s: \
             joints that rock would be seated (at most {SEAT_RATE_MAX} of it; default 1e-4)",
            params.seat_rate
        )));
    }
    if !(params.min_impact_interval.is_finite()
        && params.min_impact_interval <= MIN_IMPACT_INTERVAL_MAX * time_scale)
    {
        return Err(SimulationError::Parameter(format!(
            "min_impact_interval = {} s is not small against the structure's time scale √(L/g) = {time_scale:.4} s: \
             joints that rock would be seated (at most {MIN_IMPACT_INTERVAL_MAX} of it; default 1e-6)",
            params.min_impact_interval
        )));
    }
    if !(params.collapse_drop.is_finite() && params.collapse_drop <= COLLAPSE_DROP_MAX) {
        return Err(SimulationError::Parameter(format!(
            "collapse_drop = {} is more than {COLLAPSE_DROP_MAX} (of weight × model size): a structure \
             that has lost that much potential energy has fallen, and a larger drop lets it pass through \
             the ground unreported (default 1e-3)",
            params.collapse_drop
        )));
    }
    if params.duration.is_nan() || params.duration > LONGEST_DURATION * time_scale {
        return Err(SimulationError::Parameter(format!(
            "duration = {:e} s is more than {LONGEST_DURATION:e} times the structure's time scale \
             √(L/g) = {time_scale:.4} s (the duration is `[analysis] duration`, or the ground \
             motion's end where that gives none): an instant t is located to 1e-13 t, beyond that coarser than the \
             impacts' own spacing near rest (min_impact_interval, default 1e-6 s); a record \
             whose time step or times are in the wrong unit gives such a duration",
            params.duration
        )));
    }
    // The simulation computes a structure far from the origin moved near it
    // (`Model::moved_near_origin`); its input coordinates themselves resolve its geometry to
    // ε D only, 2e-7 of its size at the bound (the geometry's own tolerance is 1e-6 of the size).
    let farthest = model
        .bodies
        .iter()
        .max_by(|a, b| a.com.norm().total_cmp(&b.com.norm()));
    if let Some(body) = farthest
        && body.com.norm() > FARTHEST_FROM_ORIGIN * model.size
    {
        let ratio = body.com.norm() / model.size;
        return Err(SimulationError::Parameter(format!(
            "body \"{}\" lies {:.4e} m from the world origin, {ratio:.3e} times the model's size \
             L = {:.4} m (at most {FARTHEST_FROM_ORIGIN:e}): its coordinates resolve its geometry \
             to {:.1e} of its size only; translate the model nearer the origin",
            body.name,
            body.com.norm(),
            model.size,
            f64::EPSILON * ratio
        )));
    }
    Ok(())
}

/// The longest run, in the structure's time scale √(L/g) ([`check_physical_bounds`]): events
/// are located to 1e-13 of their instant (the event bracket), 1e-6 √(L/g) at this bound, which
/// for structures of a metre to ten (√(L/g) = 0.3 to 1 s) is the order of the default spacing of
/// the impacts of a joint coming to rest (`min_impact_interval`, 1e-6 s). Rocking dies out
/// within some hundreds of time units; a run of a million (the Python interrupt test's 1e6 s of a
/// 2 m block) is far inside it.
pub const LONGEST_DURATION: f64 = 1e7;

/// The farthest a body's centre may lie from the world origin, in model sizes
/// ([`check_physical_bounds`]): beyond, the coordinates of the input resolve the geometry to less
/// than ε × 1e9 ≈ 2e-7 of the model's size, near its geometric tolerance (1e-6 of the size).
pub const FARTHEST_FROM_ORIGIN: f64 = 1e9;

/// Sets the tree coordinates `seated(k)` of q and q̇ to exactly 0 and closes the loops again by
/// the least change of the other coordinates, positions then velocities (Φ = 0, Φ_q q̇ = 0):
/// what the integrator's projection does after its next step, done where the caller can book
/// the change of T + U. The coordinates `keep(k)` (tree coordinates that must stay where they
/// are, e.g. at exactly 0 on a new pivot) are held too, unless the loops cannot be closed
/// without them. Seated closure angles (not rows of Φ) go to 0 with their rates too, as rows of
/// the projections beside Φ, where that is well conditioned ([`snap_holding_closures`]);
/// otherwise they take their share of the least change. On a heavy structure moving little the
/// change is not negligible: residual
/// angles of 1e-8 rad under the bundled temple's entablature move U by millijoules, the order
/// of its impact losses. Returns (T, U) of the state reached ([`state_energies`]).
pub(super) fn snap_to_seats(
    model: &Model,
    kin: &mut Data,
    pivots: &ActivePivots,
    q: &mut DVector<f64>,
    qdot: &mut DVector<f64>,
    seated: impl Fn(usize) -> bool,
    keep: impl Fn(usize) -> bool,
) -> Result<(f64, f64), crr_dynamics::DynamicsError> {
    use crr_dynamics::closed_chain::{project_positions, project_velocities};
    let n = model.dof();
    for k in (0..n).filter(|&k| seated(k)) {
        q[k] = 0.0;
        qdot[k] = 0.0;
    }
    if model.constraint_rows > 0 {
        let (start_q, start_qdot) = (q.clone(), qdot.clone());
        // The least change of the free coordinates that closes Φ, the kept ones moving only if
        // the loops cannot close without them.
        let mut free: Vec<usize> = (0..n).filter(|&k| !seated(k) && !keep(k)).collect();
        let least_closure = match project_positions(model, kin, pivots, q, Some(&free)) {
            Ok(norm) => norm,
            Err(_) => {
                q.copy_from(&start_q);
                free = (0..n).filter(|&k| !seated(k)).collect();
                project_positions(model, kin, pivots, q, Some(&free))?
            }
        };
        project_velocities(model, kin, pivots, q, qdot, Some(&free));
        let seated_closures: Vec<usize> = (n..model.slot_count).filter(|&s| seated(s)).collect();
        if !seated_closures.is_empty()
            && let Some((held_q, held_qdot)) = snap_holding_closures(
                model,
                kin,
                pivots,
                (&start_q, &start_qdot),
                (q, qdot, least_closure),
                &free,
                &seated_closures,
            )
        {
            q.copy_from(&held_q);
            qdot.copy_from(&held_qdot);
        }
    }
    Ok(state_energies(model, kin, pivots, q, qdot))
}

/// [`snap_to_seats`] with the seated closure angles `closures` (not rows of Φ) set to 0 and their
/// rates to 0 as the seated tree coordinates are, as rows of the projections beside Φ, from the
/// state (q, q̇) `start`; or None when the loops do not close so (Φ and the rows to the closure
/// tolerance, their rates to round-off), or when it is ill-conditioned: its move of q or of q̇
/// more than a thousand times that of the least change with Φ alone (`least`) plus the residuals
/// it removes (the seated angles for q; the rows' rates and Φ_q q̇ for q̇). A row well conditioned removes a residual r by
/// a move of order r; one the loop all but locks, by r/σ ≫ r (the bundled temple's entablature
/// seats under the default `simultaneity`: q moved by 1.4e-4 rad to remove 1e-10, and q̇ thrown
/// to 8.6 rad/s). Without these rows the least change turns a seated closing joint like a free
/// one: on a 9-voussoir arch under a pulse one was left 1.1e-6 rad past its seat.
fn snap_holding_closures(
    model: &Model,
    kin: &mut Data,
    pivots: &ActivePivots,
    (start_q, start_qdot): (&DVector<f64>, &DVector<f64>),
    (least_q, least_qdot, least_closure): (&DVector<f64>, &DVector<f64>, f64),
    free: &[usize],
    closures: &[usize],
) -> Option<(DVector<f64>, DVector<f64>)> {
    use crr_dynamics::closed_chain::{
        CLOSURE_TOLERANCE, held_at, project_positions_holding, project_velocities_holding,
    };
    // Moves below this are round-off (rad, rad/s).
    const FLOOR: f64 = 1e-12;
    // The largest move per residual removed: measured, up to 1e2 on voussoir arches (whose
    // three-hinge sub-loops near the closed configuration are near-singular, as are their
    // seated tree coordinates'), from 3e4 up on the temple's entablature seats.
    const AMPLIFICATION: f64 = 1e3;
    let at_seat: Vec<(usize, f64)> = closures.iter().map(|&s| (s, 0.0)).collect();
    let residual = held_at(model, kin, start_q, pivots, closures)
        .iter()
        .fold(0.0_f64, |m, &(_, psi)| m.max(psi.abs()));
    let mut q = start_q.clone();
    let closed =
        project_positions_holding(model, kin, pivots, &mut q, Some(free), &at_seat).ok()?;
    // Newton may stall on a least-squares compromise when a row is all but dependent on Φ over
    // the free coordinates: only a solve to the closure tolerance (or as far as the least
    // change's went) stands.
    if closed > CLOSURE_TOLERANCE.max(least_closure)
        || (&q - start_q).amax() > AMPLIFICATION * ((least_q - start_q).amax() + residual) + FLOOR
    {
        return None;
    }
    let mut qdot = start_qdot.clone();
    let (rate_residual, left) =
        project_velocities_holding(model, kin, pivots, &q, &mut qdot, Some(free), closures);
    let least_rate = (least_qdot - start_qdot).amax();
    // What the (single, rank-truncated) solve leaves outside the range of the free columns
    // stays: then the least change stands.
    if left > FLOOR * (1.0 + start_qdot.amax())
        || (&qdot - start_qdot).amax() > AMPLIFICATION * (least_rate + rate_residual) + FLOOR
    {
        return None;
    }
    Some((q, qdot))
}

/// (T, U) at (q, q̇) on `pivots`, T from the bodies' velocities, leaving `kin` evaluated there.
pub(super) fn state_energies(
    model: &Model,
    kin: &mut Data,
    pivots: &ActivePivots,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> (f64, f64) {
    forward_kinematics(model, kin, q, pivots);
    crr_kinematics::velocities(model, kin, qdot);
    (
        crr_kinematics::body_kinetic_energy(model, kin),
        potential_energy(model, kin),
    )
}

impl<'a> Simulation<'a> {
    /// Builds a simulation from a consistent initial state. Slots whose angle and rate are both 0
    /// start seated; the others rock on the side of their angle (or of their rate when the angle
    /// is 0).
    pub fn new(
        model: &'a Model,
        ground: &'a GroundMotion,
        initial: &InitialState,
        params: Parameters,
    ) -> Result<Self, SimulationError> {
        for (name, v) in [
            ("duration", params.duration),
            ("output_interval", params.output_interval),
            ("seat_rate", params.seat_rate),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(SimulationError::Parameter(format!(
                    "{name} must be a positive number, got {v}"
                )));
            }
        }
        check_physical_bounds(model, &params)?;
        // Far from the origin the dynamics would lose digits to round-off: moved near it.
        let placed = Arc::new(model.moved_near_origin().unwrap_or_else(|| model.clone()));
        let model = &*placed;
        let n = model.dof();
        let mut pivots = initial.pivots.clone();
        let mut kin = Data::new(model);
        let mut angles = vec![0.0; model.slot_count];
        slot_angles(model, &mut kin, &initial.q, &pivots, &mut angles);
        crr_kinematics::velocities(model, &mut kin, &initial.qdot);
        let mut rates = vec![0.0; model.slot_count];
        slot_rates(model, &kin, &initial.qdot, &mut rates);
        check_initial_state(model, initial).map_err(SimulationError::Parameter)?;
        let tiny = 1e-14;
        let mut seated = vec![false; model.slot_count];
        for s in 0..model.slot_count {
            if angles[s].abs() <= tiny && rates[s].abs() <= tiny {
                seated[s] = true;
            } else if angles[s].abs() > tiny {
                pivots.sides[s] = Side::of(angles[s], pivots.sides[s]);
            } else {
                pivots.sides[s] = Side::of(rates[s], pivots.sides[s]);
            }
        }
        let mut dynamics = Dynamics::new(model, pivots);
        // The integration and the uplift test need q̈ only; the monitor has its own workspace
        // with the minimum-norm multipliers.
        dynamics.min_norm_multipliers = false;
        dynamics.seated = (0..model.slot_count).filter(|&s| seated[s]).collect();
        let regularised = Regularised::of(model);
        let mut solver = Solver::new(params.method, params.options, 2 * n + 2)?;
        let y = ConstrainedSystem::pack(&initial.q, &initial.qdot, 0.0, 0.0);
        solver.reset(0.0, &y);
        let u_rest = crr_dynamics::energy::rest_potential(model);
        let trial = dynamics.clone();
        // Room for the regular samples of the whole run, up to one step's worth (a longer run
        // grows by doubling, or is drained by a caller streaming it), and for the two samples
        // of an impact every eighth output interval (more impacts grow the vectors once).
        let regular_samples = (params.duration / params.output_interval) as usize + 2;
        let sample_room = regular_samples + regular_samples / 4;
        let impact_room = params.max_impacts.min(INITIAL_IMPACT_ROOM);
        let mut sim = Self {
            model: Arc::clone(&placed),
            original: Arc::clone(&placed),
            open: OpenLoops::none(model),
            file_q: vec![0.0; model.dof()],
            file_qdot: vec![0.0; model.dof()],
            chain_changes: 0,
            axis_memory: Default::default(),
            ground,
            params,
            dynamics,
            solver,
            regularised,
            out_kin: Data::new(model),
            spare: Workspaces::new(model, trial, &initial.pivots),
            parts: model.parts(),
            contact_slots: slots::contact_slots(model),
            y,
            t: 0.0,
            seated,
            last_impact: vec![f64::NEG_INFINITY; model.slot_count],
            dissipated_at_impacts: 0.0,
            lost_at_impacts: -0.0,
            energy_at_snaps: 0.0,
            snaps_at_violation: None,
            undecided: UndecidedRow::default(),
            deferred_to: f64::NEG_INFINITY,
            u_rest,
            energy_start: 0.0,
            next_sample: 0,
            finished: false,
            peak_abs: vec![0.0; n],
            balance_error: 0.0,
            last_sample_t: f64::NEG_INFINITY,
            pre_event: (f64::NAN, Vec::new(), Vec::new()),
            samples: Samples::with_capacity(
                n,
                model.slot_count,
                sample_room.min(MAX_SAMPLES_PER_STEP),
            ),
            impacts: Vec::with_capacity(impact_room),
            peaks: Vec::new(),
            uplift_time: None,
            collapse: None,
            violation: None,
            loop_residual: LoopResidual::default(),
            doubtful_check: None,
            held_on_search: None,
            hops: hops::Hops::default(),
        };
        // Released beyond the point of no return (its potential energy already below the rest
        // level by the collapse margin, e.g. a block tilted past 2α): collapsed at t = 0. The
        // event only sees U falling through the threshold, which such a start never does.
        let energy_scale = model.total_mass() * model.gravity * model.size;
        let q0 = sim.chain_q();
        forward_kinematics(model, &mut sim.out_kin, &q0, &sim.dynamics.pivots);
        let u0 = potential_energy(model, &sim.out_kin) - sim.u_rest;
        let collapsed = u0 < -sim.params.collapse_drop * energy_scale;
        // A seated structure that cannot hold at t = 0 uplifts at once, before the first
        // sample: the monitor judges the contacts the motion starts on (a load that starts
        // above the threshold, as a one-cosine pulse does, would find the seated structure
        // pulling).
        if !collapsed {
            sim.release_if_opening()?;
        }
        let y = std::mem::take(&mut sim.y);
        let first = sim.sample_at(0.0, &y);
        sim.y = y;
        // The energy the run starts with, before the release: a release that snaps a loop
        // closed (a twisting seat's flip) books its change of T + U as dissipated.
        sim.energy_start = first.kinetic + first.potential - first.work_in + first.dissipated;
        sim.record_sample(first);
        sim.next_sample = 1;
        if collapsed {
            let c = sim.collapse_record();
            sim.collapse = Some(c);
            sim.finished = true;
            return Ok(sim);
        }
        Ok(sim)
    }

    /// Current time (s).
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Current q, in the file's coordinates (docs/simulation.md, "Faces that open": a
    /// coordinate whose face is open is the angle of its bodies' relative rotation).
    pub fn q(&self) -> DVector<f64> {
        self.file_state().0
    }

    /// Current q̇, in the file's coordinates (as [`Self::q`]).
    pub fn qdot(&self) -> DVector<f64> {
        self.file_state().1
    }

    /// The model integrated now: the file's, or the file's without the faces that are open
    /// (its spanning tree grown again where one of them was in it).
    pub fn chain(&self) -> &Model {
        &self.model
    }

    /// q of [`Self::chain`].
    pub fn chain_q(&self) -> DVector<f64> {
        DVector::from_column_slice(&self.y[..self.model.dof()])
    }

    /// q̇ of [`Self::chain`].
    pub fn chain_qdot(&self) -> DVector<f64> {
        let n = self.model.dof();
        DVector::from_column_slice(&self.y[n..2 * n])
    }

    /// Current state of every slot of the file's model.
    pub fn states(&self) -> Vec<SlotState> {
        (0..self.original.slot_count)
            .map(|s| self.slot_state(s))
            .collect()
    }

    /// The chain's releases `mode` with their slots in the file's numbering.
    fn file_slots(&self, mode: Vec<(usize, Side)>) -> Vec<(usize, Side)> {
        mode.into_iter()
            .map(|(k, side)| (self.open.original_slot(k), side))
            .collect()
    }

    /// The state of slot `s` of the file's model.
    fn slot_state(&self, s: usize) -> SlotState {
        let Some(s) = self.open.active_slot(s) else {
            return SlotState::Open;
        };
        if self.seated[s] {
            SlotState::Seated
        } else if self.dynamics.pivots.sides[s] == Side::Positive {
            SlotState::Positive
        } else {
            SlotState::Negative
        }
    }

    /// The current dynamic chain: the active pivot of every slot of [`Self::chain`].
    pub fn pivots(&self) -> &ActivePivots {
        &self.dynamics.pivots
    }

    /// T + U − W + D − E(0): the energy-balance error (J), zero up to the integration tolerance.
    pub fn energy_balance_error(&self) -> f64 {
        self.balance_error
    }

    /// Takes the samples recorded since the last call, so that a long run can stream them to a
    /// file and keep its memory flat; the peaks and the energy balance still cover every sample.
    pub fn drain_samples(&mut self) -> Samples {
        let empty = Samples::new(self.original.dof(), self.original.slot_count);
        std::mem::replace(&mut self.samples, empty)
    }

    /// Books a snap's change of T + U (before − after) in D and tallies it
    /// ([`Trajectory::energy_at_snaps`]).
    pub(super) fn book_snap(&mut self, change: f64) {
        self.dissipated_at_impacts += change;
        self.energy_at_snaps += change.abs();
    }

    /// Σ of the `energy_lost` of every impact appended so far (J), also those a caller has
    /// since removed from `impacts`.
    pub(super) fn lost_at_impacts(&self) -> f64 {
        self.lost_at_impacts
    }

    /// The energy the regularised Dirac forces (`dirac_regularised`) have dissipated so far (J):
    /// the state's last entry, integrated with the motion (0 without such a law).
    pub(super) fn dissipated_by_forces(&self) -> f64 {
        self.y.get(2 * self.model.dof() + 1).copied().unwrap_or(0.0)
    }

    /// Seats (`true`) or releases (`false`) slots. The seated set is held twice, as the mask
    /// the events read and as the list the dynamics solves with; this is the one place either
    /// changes after the start, and both change together.
    pub(super) fn set_seated(&mut self, changes: impl IntoIterator<Item = (usize, bool)>) {
        for (s, seated) in changes {
            self.seated[s] = seated;
        }
        self.dynamics.seated.clear();
        let seated = &self.seated;
        self.dynamics
            .seated
            .extend((0..self.model.slot_count).filter(|&s| seated[s]));
    }

    /// A flag the run reads inside its steps: once set, [`Self::step`] stops with
    /// [`SimulationError::Cancelled`] within one integration step (or, at rest, one grid
    /// interval of the uplift test) of the request, at a state of the motion (the end of an
    /// accepted step, or an instant known to hold at rest), with the samples up to there
    /// recorded and a last one at that instant ([`Self::record_final_sample`]). Each step still
    /// advances at least once, so a caller that reads the flag between steps too stops after the
    /// first. Without it a step runs to its event, breakpoint or end, which may take long (a
    /// quiet stretch of a large structure, a stalled step of many short steps).
    pub fn set_interrupt(&mut self, cancel: Option<crr_dynamics::Cancel>) {
        self.solver.set_interrupt(cancel);
    }

    fn reset_solver(&mut self) {
        self.solver.reset(self.t, &self.y);
        // Every segment rebuilds its event list: an index from the last one means nothing now.
        self.solver.forget_last_event();
    }

    /// Audits the faces' certificate from now on: wherever it decides that nothing opens, the
    /// contact program is solved too and its answer recorded ([`CertificateAudit`]; the run's
    /// motion is unchanged, each certified step end costs one program more).
    pub fn audit_certificate(&mut self) {
        self.spare.rest.audit.get_or_insert_with(Default::default);
    }

    /// What the audit found so far (None: not audited).
    pub fn certificate_audit(&self) -> Option<&CertificateAudit> {
        self.spare.rest.audit.as_ref()
    }

    /// Integrates to the next event, breakpoint or the end.
    ///
    /// Every step ends with the run's invariant checked ([`Self::check_invariant`]): each rocking
    /// angle lies on the side of its active pivot and the loops are closed; a state that breaks
    /// it stops the run with [`SimulationError::Invariant`] instead of going on from a wrong
    /// state.
    pub fn step(&mut self) -> Result<StopReason, SimulationError> {
        let start = self.t;
        let stop = self.step_unchecked();
        self.collect_doubtful_checks();
        self.collect_sliding_unloaded();
        self.collect_held_on_search();
        let mut stop = stop?;
        // The first violation is final once a step has started after it with no pull being
        // measured: whatever is recorded later is at or after that start.
        if self.params.stop_at_violation
            && self.violation.as_ref().is_some_and(|v| v.t < start)
            && self.hops.settled()
            && !matches!(stop, StopReason::End(_) | StopReason::Collapse(_))
        {
            // The results keep the state the step reached; nothing after it is integrated.
            self.finished = true;
            self.record_final_sample();
            stop = StopReason::End(self.t);
        }
        if let Err(e) = self.check_invariant() {
            // A collapse declared from a state outside the model is no collapse: the run stops
            // with the error alone.
            if matches!(stop, StopReason::Collapse(_)) {
                self.collapse = None;
            }
            return Err(e);
        }
        Ok(stop)
    }

    /// Keeps the first doubtful check ([`DoubtfulCheck`]) on the run's trajectory: the checks
    /// made up to the time reached (those of the root location past an event are not on it).
    fn collect_doubtful_checks(&mut self) {
        let checks = std::mem::take(&mut self.spare.rest.doubtful);
        if self.doubtful_check.is_none() {
            self.doubtful_check = self.first_reached(checks, |c| c.t);
        }
    }

    /// Keeps the first instant on the run's trajectory at which the structure at rest was held on
    /// a multiplier that is not exhaustive ([`HeldOnSearch`]).
    fn collect_held_on_search(&mut self) {
        let held = std::mem::take(&mut self.spare.rest.held_on_search);
        if self.held_on_search.is_none() {
            self.held_on_search = self.first_reached(held, |h| h.t);
        }
    }

    /// The earliest of `records` (instant `t`) made up to the time reached: those of a root
    /// location past an event are not on the trajectory.
    fn first_reached<T>(&self, records: Vec<T>, t: impl Fn(&T) -> f64) -> Option<T> {
        let reached = self.t + 1e-12 * self.t.abs().max(1.0);
        records
            .into_iter()
            .filter(|r| t(r) <= reached)
            .min_by(|a, b| t(a).total_cmp(&t(b)))
    }

    /// Records the first instant on the run's trajectory at which the structure at rest was held
    /// against a load beyond a mechanism whose joints slide while keeping contact
    /// (`seating::followable_collapse`) as a violation of kind `sliding_unloaded` (the first
    /// joint by name; no force is computed: N = 0, |F_t|/N infinite, shear with no
    /// compression), unless one came before.
    fn collect_sliding_unloaded(&mut self) {
        let held = std::mem::take(&mut self.spare.rest.sliding_unloaded);
        let reached = self.t + 1e-12 * self.t.abs().max(1.0);
        let Some((t, interfaces)) = held
            .into_iter()
            .filter(|(t, _)| *t <= reached)
            .min_by(|a, b| a.0.total_cmp(&b.0))
        else {
            return;
        };
        let Some(first) = interfaces.into_iter().next() else {
            return;
        };
        // At rest nothing moves between that instant and now: the energies are those of now.
        let snaps = SnapsAndLosses {
            t,
            snaps: self.energy_at_snaps,
            lost: self.lost_at_impacts() + self.dissipated_by_forces(),
        };
        self.record_violation(
            crate::monitor::Violation {
                t,
                interface: first,
                kind: "sliding_unloaded".to_string(),
                normal: 0.0,
                friction_demand: f64::INFINITY,
                hop: None,
            },
            snaps,
        );
    }

    /// The run's invariant, in every build: every slot that rocks has its angle on the side of
    /// its active pivot (σψ ≥ −tol; tol = 100 × `simultaneity` within [1e-5, 1e-3] rad: 1e-5 rad
    /// by default, above the event location's overshoot of a crossing and the band in which a
    /// joint coming to rest waits to be seated), every seated slot is within tol of 0 (a seated
    /// closure angle is held by its rows only, and a projection that turned it would leave it
    /// off its seat unseen), and the loops are closed (|Φ| ≤ 1e-6 on the row-scaled closures). A
    /// rocking angle past its pivot means an impact was missed (a step too long for the
    /// tolerances); the run's results from there on would be wrong.
    pub fn check_invariant(&mut self) -> Result<(), SimulationError> {
        let model = Arc::clone(&self.model);
        let model = &*model;
        let n = model.dof();
        let tol = (100.0 * self.params.simultaneity).clamp(1e-5, 1e-3);
        let mut angles = std::mem::take(&mut self.spare.invariant_angles);
        angles.clear();
        angles.extend_from_slice(&self.y[..n]);
        angles.resize(model.slot_count, 0.0);
        if model.constraint_rows > 0 {
            let q = &mut self.spare.invariant_q;
            assign(q, &self.y[..n]);
            forward_kinematics(model, &mut self.out_kin, q, &self.dynamics.pivots);
            closure_angles(model, &self.out_kin, &mut angles[n..]);
            crr_kinematics::constraint_residual(model, &mut self.out_kin, &self.dynamics.pivots, q);
            let residual = self
                .out_kin
                .phi
                .iter()
                .zip(self.spare.constraint_scale.iter())
                .map(|(r, s)| (r * s).abs())
                .fold(0.0, f64::max);
            // NaN counts as open.
            if residual.is_nan() || residual > 1e-6 {
                self.spare.invariant_angles = angles;
                return Err(SimulationError::Invariant(format!(
                    "at t = {} s the loops are open by {residual:.3e} (row-scaled |Φ|): the state has left the closed chain; {}",
                    self.t,
                    self.remedy_without_slot()
                )));
            }
        }
        let deepest = if self.open.faces.is_empty() {
            None
        } else {
            self.deepest_open_point(&DVector::from_column_slice(&self.y[..n]))
        };
        if let Some((gap, name)) = deepest
            && (gap.is_nan() || gap < -open_loops::GAP_TOLERANCE * model.size)
        {
            self.spare.invariant_angles = angles;
            return Err(SimulationError::Invariant(format!(
                "at t = {} s a corner of the open face of \"{name}\" is {:.3e} m inside its support: its landing was missed; {}",
                self.t,
                -gap,
                self.remedy_without_slot()
            )));
        }
        let mut broken = None;
        for s in 0..model.slot_count {
            if self.seated[s] {
                // A seated joint is held at 0 (a closure angle keeps at most the residual it
                // was seated with, within `simultaneity`).
                let angle = angles[s];
                if angle.is_nan() || angle.abs() > tol {
                    self.spare.invariant_angles = angles;
                    let remedy = self.remedy((s, angle), |x| x.is_nan() || x.abs() > tol);
                    return Err(SimulationError::Invariant(format!(
                        "at t = {} s the angle \"{}\" is {angle:.6} rad while it is seated: the state has left its seat; {remedy}",
                        self.t,
                        model.slot_name(s),
                    )));
                }
                continue;
            }
            let side = self.dynamics.pivots.sides[s];
            let angle = angles[s];
            let past = side.sign() * angle;
            if past.is_nan() || past < -tol {
                broken = Some((s, side, angle));
                break;
            }
        }
        self.spare.invariant_angles = angles;
        if let Some((s, side, angle)) = broken {
            let remedy = self.remedy((s, angle), |x| x.is_nan() || side.sign() * x < -tol);
            return Err(SimulationError::Invariant(format!(
                "at t = {} s the angle \"{}\" is {angle:.6} rad while it rocks on its {} pivot: the state is on the wrong side of its pivot (an impact was missed); {remedy}",
                self.t,
                model.slot_name(s),
                match side {
                    Side::Positive => "+",
                    Side::Negative => "-",
                },
            )));
        }
        Ok(())
    }

    /// What to change when the invariant fails: the step of RK4, the tolerance otherwise. Where
    /// an impact or a landing set the state at this very instant, its snap (the least change
    /// that closes the loops on the new pivots) may be what moved it, which no tolerance
    /// changes: the message says so (on the bundled wall under a pulse of 12 m/s², as of commit
    /// 6ac4261, a landing's snap put a rocking angle 7.9e-5 rad past its pivot, the same with
    /// rtol 1e-10 and 1e-12).
    fn remedy_without_slot(&self) -> String {
        let names = self.event_names();
        self.remedy_with(&names, String::new())
    }

    /// The interfaces of every impact or landing record of this instant (landings that push
    /// other faces in come in a cascade).
    fn event_names(&self) -> Vec<String> {
        self.impacts
            .iter()
            .rev()
            .take_while(|i| i.t == self.t)
            .flat_map(|i| i.interfaces.iter().cloned())
            .collect()
    }

    /// [`Self::remedy_without_slot`] for the failing slot s at its angle now, `wrong` telling
    /// an angle outside the model (past its pivot, or off its seat): how the events of this
    /// instant moved it, and whether it was already wrong before them (then the integration
    /// missed an impact, which the tolerance does change).
    fn remedy(&mut self, (s, now): (usize, f64), wrong: impl Fn(f64) -> bool) -> String {
        let names = self.event_names();
        let before = if names.is_empty() {
            None
        } else {
            self.angle_before_events(s)
        };
        let name = self.model.slot_name(s);
        // On the same pivot before the events as now (an impact switches its own).
        let same_side = self.pre_event.2.get(s) == self.dynamics.pivots.sides.get(s);
        match before {
            Some(before) if same_side && wrong(before) => format!(
                "{} (\"{name}\" was already at {before:.3e} rad before the impact or landing \
                 of {} at this instant: the integration passed an impact)",
                self.remedy_with(&[], String::new()),
                names.join(", ")
            ),
            Some(before) if (now - before).abs() > 0.0 => self.remedy_with(
                &names,
                format!(
                    " (the events moved \"{name}\" from {before:.3e} to {now:.3e} rad: a snap \
                     closes the loops on the new pivots, and bodies that meet away from the \
                     points their pivots had at rest, after a flight or a rattle, are brought \
                     back to them)"
                ),
            ),
            _ => self.remedy_with(&names, String::new()),
        }
    }

    fn remedy_with(&self, names: &[String], moved: String) -> String {
        let integration = match self.params.method {
            Method::Rk4 { step } => format!("shorten analysis.rk4_step (now {step:e} s)"),
            _ => format!(
                "tighten analysis.rtol (now {:e}) or set analysis.max_step",
                self.params.options.rtol
            ),
        };
        if names.is_empty() {
            return integration;
        }
        format!(
            "{integration}; the state at this instant was set by the impact or landing of {} and \
             its snap{moved}, which a tolerance does not change: if the failure comes back at \
             the same instant, the contacts rattle beyond what the event-driven model resolves",
            names.join(", ")
        )
    }

    /// Slot `s`'s angle before the events of this instant (an impact, a landing), from the
    /// sample taken just before the first of them: a coordinate's value, or a closure angle
    /// from the bodies' rotations then (which the pivots do not change). An impact law changes
    /// the rates only, so what moved an angle at this instant is the events' snaps (impacting
    /// angles to 0, seats, loops closed on the new pivots). None where no event sample was
    /// taken at this instant, or the chain's tree has changed since (a re-rooted chain may turn
    /// an interface round, whose angles then change sign).
    fn angle_before_events(&mut self, s: usize) -> Option<f64> {
        let (t, before, _) = &self.pre_event;
        let model = Arc::clone(&self.model);
        let coords = &model.coords;
        if *t != self.t
            || before.len() != coords.len()
            || before
                .iter()
                .zip(coords)
                .any(|((name, _), c)| *name != c.name)
        {
            return None;
        }
        let n = coords.len();
        if s < n {
            return Some(before[s].1);
        }
        let q = DVector::from_iterator(n, before.iter().map(|(_, x)| *x));
        forward_kinematics(&model, &mut self.out_kin, &q, &self.dynamics.pivots);
        let mut angles = vec![0.0; model.slot_count - n];
        closure_angles(&model, &self.out_kin, &mut angles);
        angles.get(s - n).copied()
    }

    fn step_unchecked(&mut self) -> Result<StopReason, SimulationError> {
        if self.finished {
            return Ok(StopReason::End(self.t));
        }
        let lift_off = self.settle_resting_joints()?;
        loop {
            let settled = self.settled_open_faces();
            if settled.is_empty() {
                break;
            }
            self.recontact(&settled)?;
        }
        let model = Arc::clone(&self.model);
        let model = &*model;
        let n = model.dof();
        let t_stop = self.segment_end(lift_off);
        if lift_off.is_none()
            && let Some(stop) = self.rest_until_uplift(t_stop)?
        {
            return Ok(stop);
        }
        let h_max = self.step_cap();
        // The pivots of the faces rocking on a pivot that alone carry the bodies above them,
        // each watched for the instant its normal force falls through 0 (a flight). One that
        // pulls already where the segment starts has no event (it would start below its zero)
        // and is left to the monitor (`tension`): such pulls start at an impact and end at the
        // next (the bundled drum column after `bed_2`'s impact at 0.42250 s: the bodies above
        // `bed_3` pull with 0.8 % of their weight for 0.11 ms, by Newton's second law on the
        // samples, `crates/crr-impact/tests/flights.rs`), and a flight there would end runs in
        // the chatter that follows impacts. Except a face held on its pivot for this event
        // after the contact program found it lifting (a flight): there the flight is now.
        let pressing = self.pressing_faces_now();
        if let Some(k) = self.held_face_pulling(&pressing) {
            return self.fall_or_flight(k);
        }
        self.hops_at_segment_start(&pressing);
        let mut hop_log = std::mem::take(&mut self.hops.log);
        hop_log.clear();
        let hop_logging = self.hops.logging();
        let mut seg = self.spare.segment.take().unwrap_or_default();
        seg.rocking.clear();
        seg.rocking.extend(
            (0..model.slot_count)
                .filter(|&s| !self.seated[s])
                .map(|s| (s, self.dynamics.pivots.sides[s])),
        );
        seg.pivots.clone_from(&self.dynamics.pivots);
        seg.angles.clear();
        seg.angles.resize(model.slot_count, 0.0);
        if seg.q.len() != n {
            seg.q = DVector::zeros(n);
            seg.qdot = DVector::zeros(n);
        }
        // The rocking angles at the start, for their seats (the closure angles from the poses).
        let mut seats = std::mem::take(&mut seg.seats);
        if seg.rocking.iter().any(|&(s, _)| s >= n) {
            assign(&mut seg.q, &self.y[..n]);
            slot_angles(
                model,
                &mut self.out_kin,
                &seg.q,
                &self.dynamics.pivots,
                &mut seg.angles,
            );
        } else {
            seg.angles[..n].copy_from_slice(&self.y[..n]);
        }
        // A slot of a regularised law is integrated through its zone: its seat stays at 0.
        let regularised = |slot: usize| {
            self.regularised
                .as_ref()
                .is_some_and(|r| r.slots.iter().any(|z| z.slot == slot))
        };
        rocking_seats(&seg.rocking, &seg.angles, regularised, &mut seats);
        let gap_seats = self.gap_seats();
        let pressing_trial = (!pressing.is_empty()).then(|| self.take_pressing_trial());
        let mut events = SegmentEvents {
            model,
            ground: self.ground,
            rocking: std::mem::take(&mut seg.rocking),
            seats,
            kin: self
                .spare
                .events_kin
                .take()
                .unwrap_or_else(|| Box::new(Data::new(model))),
            pivots: std::mem::take(&mut seg.pivots),
            angles: std::mem::take(&mut seg.angles),
            uplift: (!self.dynamics.seated.is_empty()).then(|| Box::new(self.dynamics.clone())),
            trial: self.take_trial(),
            rest: std::mem::take(&mut self.spare.rest),
            slot_part: &self.parts.of_slot,
            contacts: &self.contact_slots,
            q: std::mem::take(&mut seg.q),
            qdot: std::mem::take(&mut seg.qdot),
            u_rest: self.u_rest,
            energy_scale: model.total_mass() * model.gravity * model.size,
            collapse_drop: self.params.collapse_drop,
            zones: self
                .regularised
                .as_ref()
                .map(|r| {
                    r.slots
                        .iter()
                        .filter(|z| !self.seated[z.slot])
                        .map(|z| (z.slot, 0.5 * z.width))
                        .collect()
                })
                .unwrap_or_default(),
            open_faces: &self.open.faces,
            gap_seats,
            pressing,
            pressing_trial,
        };
        // Dense-output sampling and peak detection, on copies so that the system can borrow the
        // dynamics.
        let dt = self.params.output_interval;
        let next_sample = self.next_sample;
        let mut pending = std::mem::take(&mut self.spare.pending);
        pending.clear();
        // Each pending sample: its grid instant, the instant of its state (the step's end where
        // the grid instant lies past it within round-off), then q, q̇, W and D.
        let stride = 2 * n + 4;
        let mut peaks = std::mem::take(&mut seg.peaks);
        peaks.clear();
        let mut rocking_coords = std::mem::take(&mut seg.rocking_coords);
        rocking_coords.clear();
        rocking_coords.extend((0..n).filter(|&k| !self.seated[k]));
        let mut buf = std::mem::take(&mut seg.y);
        buf.clear();
        buf.resize(2 * n + 2, 0.0);
        // The dense output is computed only for the steps that read it: a hop being measured, a
        // sample inside the step, or a rate changing sign across it (a peak). Both closures
        // read the next sample's index, which the second advances.
        let next_sample = std::cell::Cell::new(next_sample);
        let duration = self.params.duration;
        let sample_in = |t1: f64| {
            let next = next_sample.get() as f64 * dt;
            next <= t1 + 1e-12 * dt && next <= duration + 1e-12 * dt
        };
        // A peak may lie in the step: q̇ₖ nonzero at its start and, at its end, of the other sign
        // or within 1e-6 of its change over the step (the step's own states). The test below
        // reads the interpolant at the ends, as it always did; its value at t1 can differ from
        // the step's state there by the rounding of (t1 − t0)/h times the change of q̇ₖ, about
        // ulp(t1)/h of that change: the margin covers it for steps longer than 1e8 ulp(t1), and
        // shorter steps always compute the interpolant.
        let turns = |ends: &StepEnds, k: usize| {
            let (a, b) = (ends.y0[n + k], ends.y1[n + k]);
            let short = ends.t1 - ends.t0 <= 1e8 * f64::EPSILON * ends.t1.abs();
            a != 0.0 && (short || a.signum() != b.signum() || b.abs() <= 1e-6 * (b - a).abs())
        };
        let mut wants_dense = |ends: &StepEnds| {
            hop_logging || sample_in(ends.t1) || rocking_coords.iter().any(|&k| turns(ends, k))
        };
        let mut on_step = |_: &StepEnds, step: Option<&DenseStep>| {
            let Some(step) = step else {
                return;
            };
            // The states where an open hop's face is read: eight per step (module `hops`).
            if hop_logging {
                for i in 1..=hops::READINGS_PER_STEP {
                    let f = i as f64 / hops::READINGS_PER_STEP as f64;
                    let ts = if i == hops::READINGS_PER_STEP {
                        step.t1()
                    } else {
                        step.t0() + f * (step.t1() - step.t0())
                    };
                    step.eval(ts, &mut buf);
                    hop_log.push(ts);
                    extend_short(&mut hop_log, &buf[..2 * n]);
                }
            }
            while sample_in(step.t1()) {
                let next = next_sample.get();
                let ts = (next as f64 * dt).min(step.t1());
                step.eval(ts, &mut buf);
                pending.push(next as f64 * dt);
                pending.push(ts);
                extend_short(&mut pending, &buf);
                next_sample.set(next + 1);
            }
            for &k in &rocking_coords {
                let rate = step.component(n + k);
                let (a, b) = (rate.eval(step.t0()), rate.eval(step.t1()));
                if a != 0.0 && b != 0.0 && a.signum() != b.signum() {
                    // The sign change of q̇ₖ(t) of the dense output, to adjacent doubles.
                    let (lo, hi) = sign_change(|t| rate.eval(t), step.t0(), a, step.t1(), b);
                    let tp = 0.5 * (lo + hi);
                    peaks.push(Peak {
                        t: tp,
                        coordinate: k,
                        value: step.eval_component(tp, k),
                    });
                }
            }
        };
        self.solver.set_h_max(h_max);
        let buffers = std::mem::take(&mut self.spare.system);
        let mut sys =
            ConstrainedSystem::with_buffers(model, self.ground, &mut self.dynamics, buffers);
        if let Some(r) = self.regularised.as_mut() {
            sys.extra = Some(r);
        }
        let stop = self.solver.advance_lazily(
            &mut sys,
            t_stop,
            &mut events,
            &mut wants_dense,
            &mut on_step,
        );
        self.spare.system = sys.into_buffers();
        let (collapse_index, toppling_index, first_zone_index) = (
            events.collapse_index(),
            events.toppling_index(),
            events.first_zone_index(),
        );
        let rocking_len = events.rocking.len();
        // An uplift event: the seated chain cannot hold from here (a load that jumps past its
        // threshold jumps at the event's instant).
        let uplift_at = match &stop {
            Ok(Stop::Event { index, .. })
                if events.uplift.is_some() && *index == events.uplift_index() =>
            {
                Some(self.solver.t())
            }
            _ => None,
        };
        let event_slot = match &stop {
            Ok(Stop::Event { index, .. }) => events.rocking.get(*index).map(|r| r.0),
            _ => None,
        };
        let landing = match &stop {
            Ok(Stop::Event { index, .. })
                if *index >= events.first_gap_index() && *index < events.first_pressing_index() =>
            {
                Some(events.gap_point(index - events.first_gap_index()))
            }
            _ => None,
        };
        let pulling = match &stop {
            Ok(Stop::Event { index, .. }) if *index >= events.first_pressing_index() => {
                Some(events.pressing[index - events.first_pressing_index()])
            }
            _ => None,
        };
        let SegmentEvents {
            kin: events_kin,
            trial,
            pressing_trial,
            rest,
            rocking,
            seats,
            pivots,
            angles,
            q,
            qdot,
            ..
        } = events;
        seg.seats = seats;
        self.spare.events_kin = Some(events_kin);
        self.spare.trial = Some(trial);
        if pressing_trial.is_some() {
            self.spare.pressing = pressing_trial;
        }
        self.spare.rest = rest;
        self.next_sample = next_sample.get();
        // In the file's coordinates (a coordinate of a re-rooted chain that closes a loop of
        // the file has no peak to report).
        let file_dof = self.original.dof();
        self.peaks.extend(peaks.iter().filter_map(|p| {
            let k = self.open.original_slot(p.coordinate);
            (k < file_dof).then_some(Peak {
                coordinate: k,
                ..*p
            })
        }));
        (seg.rocking, seg.pivots, seg.angles, seg.q, seg.qdot) = (rocking, pivots, angles, q, qdot);
        (seg.peaks, seg.rocking_coords, seg.y) = (peaks, rocking_coords, buf);
        self.spare.segment = Some(seg);
        // The hops first: the monitor's samples within an episode that ended in this segment
        // are that pull's (module `hops`).
        self.hops.log = hop_log;
        self.hops_read_log();
        // A sample at an uplift event's instant (within its location's bracket) belongs to the
        // motion after the release, as at rest (`rest_until_uplift`): taken here, it would
        // judge the seated chain under a load that may already be past the threshold (a pulse
        // that starts at a sample's instant) and report the joints that open as pulling.
        let deferred = uplift_at.map_or(0, |te| {
            pending
                .chunks_exact(stride)
                .filter(|sample| sample[0] >= te - event_bracket(te))
                .count()
        });
        let taken = pending.len() / stride - deferred;
        for sample in pending.chunks_exact(stride).take(taken) {
            let s = self.sample_under_load_at(sample[0], sample[1], &sample[2..]);
            self.record_sample(s);
        }
        self.next_sample -= deferred;
        if deferred > 0
            && let Some(te) = uplift_at
        {
            self.deferred_to = te;
        }
        self.spare.pending = pending;
        self.attach_hop();
        if let Err(SolveError::Interrupted { t }) = stop {
            // The end of an accepted step, its samples recorded above: the run stops there.
            self.t = t;
            copy_short(&mut self.y, self.solver.y());
            self.record_final_sample();
            return Err(SimulationError::Cancelled { t });
        }
        let stop = stop?;
        self.t = self.solver.t();
        copy_short(&mut self.y, self.solver.y());
        if let Some(k) = pulling {
            return self.fall_or_flight(k);
        }
        if let Some((face, point)) = landing {
            let mut landings = vec![(face, point)];
            landings.extend(self.open_faces_touching(Some(face))?);
            return self.recontact(&landings).map(StopReason::Impact);
        }
        // A rocking joint's impact with open faces touching at the same instant: the faces land
        // first (their loops close with a plastic impulse, which may stop the joint: a wedge
        // landing on its whole crack stops at its toe too); the joint's impact follows at once
        // if it still moves into its seat.
        if let Some(slot) = event_slot {
            let touching = self.open_faces_touching(None)?;
            if !touching.is_empty() {
                let file_slot = self.open.original_slot(slot);
                let landed = self.recontact(&touching)?;
                return match self.open.active_slot(file_slot) {
                    Some(s) if !self.seated[s] && self.moves_into_its_seat(s) => {
                        self.impact(s).map(StopReason::Impact)
                    }
                    _ => Ok(StopReason::Impact(landed)),
                };
            }
        }
        self.stop_reason(
            stop,
            event_slot,
            collapse_index,
            toppling_index,
            first_zone_index,
            rocking_len,
        )
    }

    /// The bodies carried by tree slot k lose their only support now (its pivot would pull,
    /// [`pressing_faces`]): a collapse where they have already fallen past their point of no
    /// return ([`Self::fallen_in_flight`]), otherwise a flight, an error of the run.
    fn fall_or_flight(&mut self, k: usize) -> Result<StopReason, SimulationError> {
        match self.fallen_in_flight(k) {
            Some(c) => Ok(self.finish_with_collapse(c)),
            None => Err(self.flight_of(k)),
        }
    }

    /// Ends the run with the collapse `c`, its state the last sample.
    fn finish_with_collapse(&mut self, c: Collapse) -> StopReason {
        self.collapse = Some(c.clone());
        self.finished = true;
        self.record_final_sample();
        StopReason::Collapse(c)
    }

    /// The collapse of the bodies carried by tree slot k when they leave their support past
    /// their point of no return: their centre of mass below its rest height by `collapse_drop`
    /// of the model size (their potential energy below rest by collapse_drop·W_k·L, the
    /// collapse criterion on them alone) while the joint turns away from its seat, measured
    /// with their support at rest (every coordinate that does not carry them at 0: a support
    /// tilted by its own rocking lowers or raises them without their falling). A body
    /// toppling off a support loses its contact on the way down (its centre's acceleration
    /// towards the pivot outgrows gravity): that flight is the end of a fall, reported as a
    /// collapse naming the joint's body (a 0.5 m finial on a pier flies at 1.2 to 1.5 rad, its
    /// centre 0.07 to 0.14 m below its rest height). None for bodies above their rest height (a
    /// block leaving its corner under a fast signal).
    fn fallen_in_flight(&mut self, k: usize) -> Option<Collapse> {
        let model = Arc::clone(&self.model);
        let (mut q, qdot) = (self.chain_q(), self.chain_qdot());
        for j in 0..model.dof() {
            if !model.carries(k, Some(j)) {
                q[j] = 0.0;
            }
        }
        forward_kinematics(&model, &mut self.out_kin, &q, &self.dynamics.pivots);
        let (mass, drop) = (0..model.bodies.len())
            .filter(|&b| model.carries(k, Some(model.body_coord[b])))
            .fold((0.0, 0.0), |(m, d), b| {
                let body = &model.bodies[b];
                (
                    m + body.mass,
                    d + body.mass * (self.out_kin.com[b].z - body.com.z),
                )
            });
        let turning_away = self.dynamics.pivots.sides[k].sign() * qdot[k] > 0.0;
        let child = model.interfaces[model.coords[k].interface].child;
        (turning_away && drop < -self.params.collapse_drop * mass * model.size).then(|| Collapse {
            t: self.t,
            body: model.bodies[child].name.clone(),
        })
    }

    /// The flight of the bodies carried by tree slot k, whose pivot would pull now
    /// ([`pressing_faces`]): its face lifts off their only support.
    fn flight_of(&mut self, k: usize) -> SimulationError {
        let model = Arc::clone(&self.model);
        self.record_final_sample();
        let iface = &model.interfaces[model.coords[k].interface];
        let in_flight: Vec<String> = (0..model.bodies.len())
            .filter(|&b| model.carries(k, Some(model.body_coord[b])))
            .map(|b| model.bodies[b].name.clone())
            .collect();
        SimulationError::LiftOff {
            t: self.t,
            interfaces: vec![iface.name.clone()],
            reason: format!(
                "its pivot's normal force falls to zero, {}",
                flight_words(&in_flight)
            ),
            in_flight,
        }
    }

    /// Whether slot `s` turns into its seat (against its side) faster than round-off, 1e-12 of
    /// the rate scale √(g/L).
    fn moves_into_its_seat(&mut self, s: usize) -> bool {
        let model = Arc::clone(&self.model);
        let (q, qdot) = (self.chain_q(), self.chain_qdot());
        forward_kinematics(&model, &mut self.out_kin, &q, &self.dynamics.pivots);
        crr_kinematics::velocities(&model, &mut self.out_kin, &qdot);
        let mut rates = vec![0.0; model.slot_count];
        slot_rates(&model, &self.out_kin, &qdot, &mut rates);
        let rate_scale = (model.gravity / model.size).sqrt();
        self.dynamics.pivots.sides[s].sign() * rates[s] < -1e-12 * rate_scale
    }

    /// Where this segment ends at the latest: the duration, the ground motion's next breakpoint,
    /// the estimated turning point of a joint leaving its seat, and the samples one step may
    /// hold.
    fn segment_end(&self, lift_off: Option<f64>) -> f64 {
        let mut t_stop = self
            .ground
            .next_breakpoint(self.t)
            .map_or(self.params.duration, |b| b.min(self.params.duration));
        // A joint leaving φ = 0 against its acceleration (every rebound) ends its segment at the
        // estimated turning point τ/2: every step of the segment is then shorter than the flight, so
        // the zero-start probe at 10⁻³h lies on the outward half and the return is a plain sign
        // change at a later step end. No further step cap is needed: within the segment the error
        // control sets the steps (a cap at τ/8 had doubled the steps of free rocking without
        // changing any result).
        if let Some(c) = lift_off {
            t_stop = t_stop.min(self.t + c);
        }
        // A step returns after at most this many output samples, so that a caller streaming
        // them (Simulation::drain_samples) keeps its memory flat through long quiet segments.
        let segment_end = self.t + MAX_SAMPLES_PER_STEP as f64 * self.params.output_interval;
        if segment_end > self.t {
            t_stop = t_stop.min(segment_end);
        }
        t_stop
    }

    /// The longest step of this segment: the user's `max_step`, capped while joints are seated
    /// under a ground motion and inside a regularised δ zone.
    fn step_cap(&mut self) -> f64 {
        let model = Arc::clone(&self.model);
        let model = &*model;
        // Inside a regularised δ zone the step is limited to an eighth of the zone's crossing time,
        // so that the bump is resolved by the steps and their dense output.
        let mut h_max = self.params.options.h_max;
        // While joints are seated the state barely changes and steps would grow up to the next
        // breakpoint; the uplift test runs at step ends, so a short excursion of the ground motion
        // above the threshold could be stepped over. Cap the step at `SEATED_MAX_STEP`.
        if !self.dynamics.seated.is_empty()
            && !self.ground.is_none()
            && self.t < self.ground.duration()
        {
            h_max = h_max.min(seated_step(self.ground));
        }
        if let Some(r) = &self.regularised {
            let mut angles = vec![0.0; model.slot_count];
            let (q, qdot) = (self.chain_q(), self.chain_qdot());
            slot_angles(
                model,
                &mut self.out_kin,
                &q,
                &self.dynamics.pivots,
                &mut angles,
            );
            crr_kinematics::velocities(model, &mut self.out_kin, &qdot);
            let mut rates = vec![0.0; model.slot_count];
            slot_rates(model, &self.out_kin, &qdot, &mut rates);
            for z in &r.slots {
                let (s, width) = (z.slot, z.width);
                if !self.seated[s] && angles[s].abs() < 0.5 * width * (1.0 + 1e-9) {
                    h_max = h_max.min(width / (8.0 * rates[s].abs().max(1e-12)));
                }
            }
        }
        h_max
    }

    /// What the segment's end means: the end of the run, a breakpoint, an impact, a collapse, a
    /// δ zone entered or left, or an uplift.
    fn stop_reason(
        &mut self,
        stop: Stop,
        event_slot: Option<usize>,
        collapse_index: usize,
        toppling_index: usize,
        first_zone_index: usize,
        rocking_len: usize,
    ) -> Result<StopReason, SimulationError> {
        match stop {
            Stop::Reached => {
                if self.t >= self.params.duration {
                    self.finished = true;
                    if self.last_sample_t < self.t {
                        self.record_current_sample(self.t);
                    }
                    return Ok(StopReason::End(self.t));
                }
                Ok(StopReason::Breakpoint(self.t))
            }
            Stop::Event { index, .. } => {
                if let Some(slot) = event_slot {
                    debug_assert!(index < rocking_len);
                    self.impact(slot).map(StopReason::Impact)
                } else if index == toppling_index {
                    // The toppling event (`events`): a rocking contact turned to π/2.
                    let q = self.chain_q();
                    match self.toppled_body(&q) {
                        Some(body) => Ok(self.finish_with_collapse(Collapse { t: self.t, body })),
                        None => {
                            self.reset_solver();
                            Ok(StopReason::Breakpoint(self.t))
                        }
                    }
                } else if index == collapse_index {
                    let (q, qdot) = (self.chain_q(), self.chain_qdot());
                    if q.dot(&qdot) > 0.0 {
                        let c = self.collapse_record();
                        Ok(self.finish_with_collapse(c))
                    } else {
                        self.reset_solver();
                        Ok(StopReason::Breakpoint(self.t))
                    }
                } else if index >= first_zone_index {
                    // Entering or leaving a regularised δ zone: restart with a fresh step size.
                    self.reset_solver();
                    Ok(StopReason::Breakpoint(self.t))
                } else {
                    let mode = self.release_at_uplift_event()?;
                    Ok(match mode {
                        Some(m) => StopReason::Uplift(self.t, self.file_slots(m)),
                        None => {
                            self.reset_solver();
                            StopReason::Breakpoint(self.t)
                        }
                    })
                }
            }
        }
    }

    /// The body of a rocking contact turned to π/2 on its pivot's side at `q` (within 1e-9
    /// rad, the toppling event's location; of several, the farthest turned, so that the body
    /// named does not depend on the order of the slots): it lies on its support's plane,
    /// toppled (the toppling function, `events`): the interface's child, or on a chain grown
    /// again around open faces, where the interface was turned round, the file's child, its
    /// parent here. None when no contact is there.
    fn toppled_body(&mut self, q: &DVector<f64>) -> Option<String> {
        let model = Arc::clone(&self.model);
        let mut angles = vec![0.0; model.slot_count];
        slot_angles(
            &model,
            &mut self.out_kin,
            q,
            &self.dynamics.pivots,
            &mut angles,
        );
        let (seated, contacts) = (&self.seated, &self.contact_slots);
        let past_seat = |s: usize| self.dynamics.pivots.sides[s].sign() * angles[s];
        let s = (0..model.slot_count)
            .filter(|&s| !seated[s] && contacts[s])
            .filter(|&s| past_seat(s) >= std::f64::consts::FRAC_PI_2 - 1e-9)
            .max_by(|&a, &b| past_seat(a).total_cmp(&past_seat(b)))?;
        let i = slot_interface(&model, s);
        let iface = &model.interfaces[i];
        let body = match iface.parent {
            crr_kinematics::Parent::Body(b) if self.open.turned(i) => b,
            _ => iface.child,
        };
        Some(model.bodies[body].name.clone())
    }

    fn collapse_record(&mut self) -> Collapse {
        let q = self.chain_q();
        forward_kinematics(&self.model, &mut self.out_kin, &q, &self.dynamics.pivots);
        let (b, _) = self
            .model
            .bodies
            .iter()
            .enumerate()
            .map(|(b, body)| (b, self.out_kin.com[b].z - body.com.z))
            .fold(
                (0, f64::INFINITY),
                |acc, x| if x.1 < acc.1 { x } else { acc },
            );
        Collapse {
            t: self.t,
            body: self.model.bodies[b].name.clone(),
        }
    }

    /// Runs to the end (or collapse) and returns the trajectory; on failure, the error with the
    /// results computed until then.
    pub fn run(mut self) -> Result<Trajectory, Box<Interrupted>> {
        loop {
            match self.step() {
                Ok(StopReason::End(_)) | Ok(StopReason::Collapse(_)) => {
                    return Ok(self.into_trajectory());
                }
                Ok(_) => {}
                Err(error) => {
                    return Err(Box::new(Interrupted {
                        error,
                        partial: self.into_trajectory(),
                    }));
                }
            }
        }
    }

    /// The results so far.
    pub fn into_trajectory(mut self) -> Trajectory {
        // A pull still being measured ends here, with what it reached.
        self.finish_hops();
        let mut peak_abs = self.peak_abs.clone();
        for p in &self.peaks {
            peak_abs[p.coordinate] = peak_abs[p.coordinate].max(p.value.abs());
        }
        let balance = self.energy_balance_error();
        let snaps_and_losses = self.snaps_at_violation.unwrap_or(SnapsAndLosses {
            t: self.t,
            snaps: self.energy_at_snaps,
            lost: self.lost_at_impacts() + self.dissipated_by_forces(),
        });
        Trajectory {
            coordinates: self
                .original
                .coords
                .iter()
                .map(|c| c.name.clone())
                .collect(),
            samples: self.samples,
            impacts: self.impacts,
            peaks: self.peaks,
            peak_abs,
            uplift_time: self.uplift_time,
            collapse: self.collapse,
            violation: self.violation,
            energy_balance_error: balance,
            energy_at_snaps: self.energy_at_snaps,
            snaps_and_losses,
            end_time: self.t,
            solver_stats: self.solver.stats(),
            loop_residual: self.loop_residual,
            doubtful_check: self.doubtful_check.clone(),
            held_on_search: self.held_on_search.clone(),
            hops: self.hops.done,
        }
    }
}

/// The results of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Trajectory {
    /// Coordinate names in the order of q.
    pub coordinates: Vec<String>,
    /// Output samples (and the instants just before and after each impact).
    pub samples: Samples,
    /// Impact log.
    pub impacts: Vec<ImpactRecord>,
    /// Local extrema of the rocking coordinates.
    pub peaks: Vec<Peak>,
    /// Peak |φ| per coordinate (rad).
    pub peak_abs: Vec<f64>,
    /// First uplift from a seated state (s).
    pub uplift_time: Option<f64>,
    /// Collapse, if any.
    pub collapse: Option<Collapse>,
    /// First failure of a hypothesis (no flight, no sliding), if any.
    pub violation: Option<crate::monitor::Violation>,
    /// Largest |T + U − W + D − E(0)| over the samples (J).
    pub energy_balance_error: f64,
    /// Σ|ΔT + ΔU| of the snaps booked in D (J): seated joints set to exactly 0 and the loops
    /// closed again at impacts and at seating, and a twisting seat's loop closed on its new
    /// corner. Not a physical loss: a measure of what the idealisation moved, to compare with D.
    pub energy_at_snaps: f64,
    /// The snaps against the impacts' losses over the part of the run inside the model: until
    /// the monitor's first violation, or the end.
    pub snaps_and_losses: SnapsAndLosses,
    /// Time reached (s).
    pub end_time: f64,
    /// Integrator work over the whole run: steps, rejections, right-hand side evaluations.
    pub solver_stats: crr_dynamics::integrator::Stats,
    /// How far the closed-chain solves left the loops open at acceleration level.
    pub loop_residual: LoopResidual,
    /// The first decision of the uplift test that rested on a solve left with the loops open
    /// ([`DoubtfulCheck`]); None where there was none.
    pub doubtful_check: Option<DoubtfulCheck>,
    /// The first instant at rest held on a static multiplier that is not exhaustive
    /// ([`HeldOnSearch`]); None where there was none.
    pub held_on_search: Option<HeldOnSearch>,
    /// Every pull at a pivot where a segment started, with the bound on how far its face would
    /// open (module `hops`), in the order they ended.
    pub hops: Vec<Hop>,
}

impl Trajectory {
    /// The results of a run that integrated nothing: no samples, impacts or peaks, at t = 0.
    pub fn empty(model: &Model) -> Self {
        Trajectory {
            coordinates: model.coords.iter().map(|c| c.name.clone()).collect(),
            samples: Samples::new(model.dof(), model.slot_count),
            impacts: Vec::new(),
            peaks: Vec::new(),
            peak_abs: vec![0.0; model.dof()],
            uplift_time: None,
            collapse: None,
            violation: None,
            energy_balance_error: 0.0,
            energy_at_snaps: 0.0,
            snaps_and_losses: SnapsAndLosses::default(),
            end_time: 0.0,
            solver_stats: Default::default(),
            loop_residual: LoopResidual::default(),
            doubtful_check: None,
            held_on_search: None,
            hops: Vec::new(),
        }
    }
}

#[cfg(test)]
mod invariant_tests {
    //! The invariant's check on states made by hand: an angle past its active pivot and loops
    //! pulled open are refused with the angle's name; the states a run reaches pass.
    use std::collections::BTreeMap;

    use crr_dynamics::ground_motion::GroundMotion;
    use crr_dynamics::{InitialSpec, solve_initial};
    use crr_kinematics::Model;
    use crr_kinematics::fixtures::{single_block, trilithon};

    use super::{Parameters, Simulation, SimulationError};

    fn released(model: &Model, name: &str, angle: f64) -> crr_dynamics::InitialState {
        solve_initial(
            model,
            &InitialSpec {
                angles: BTreeMap::from([(name.to_string(), angle)]),
                ..Default::default()
            },
        )
        .unwrap()
    }

    #[test]
    fn an_angle_past_its_pivot_is_refused() {
        let model = Model::from_spec(&single_block(0.2, 1.0, 2500.0)).unwrap();
        let initial = released(&model, "base", 0.05);
        let ground = GroundMotion::none();
        let mut sim = Simulation::new(&model, &ground, &initial, Parameters::default()).unwrap();
        assert!(sim.check_invariant().is_ok());
        // On its + pivot (started at +0.05); within the tolerance (1e-5 rad) it passes.
        sim.y[0] = -0.5e-5;
        assert!(sim.check_invariant().is_ok());
        sim.y[0] = -0.01;
        match sim.check_invariant() {
            Err(SimulationError::Invariant(m)) => {
                assert!(m.contains("\"base\" is -0.010000 rad"), "{m}");
                assert!(m.contains("+ pivot"), "{m}");
                assert!(m.contains("tighten analysis.rtol"), "{m}");
                assert!(!m.contains("set by the impact"), "{m}");
            }
            other => panic!("{other:?}"),
        }
        // The same state set by an impact at this instant: its snap is named as what a
        // tolerance does not change.
        sim.impacts.push(super::ImpactRecord {
            t: sim.t,
            interfaces: vec!["base".into()],
            slots: vec![0],
            rates_before: vec![-1.0],
            rates_after: vec![0.5],
            energy_lost: 1.0,
            energy_gain: false,
            seated: Vec::new(),
            released: Vec::new(),
        });
        match sim.check_invariant() {
            Err(SimulationError::Invariant(m)) => {
                assert!(m.contains("tighten analysis.rtol"), "{m}");
                assert!(m.contains("set by the impact or landing of base"), "{m}");
            }
            other => panic!("{other:?}"),
        }
        // A run keeps it: 3 s of free rocking, checked after every step.
        let sim = Simulation::new(&model, &ground, &initial, Parameters::default()).unwrap();
        assert!(sim.run().is_ok());
    }

    /// A closed state of the trilithon's mechanism (its columns turned by 0.05 rad) with every
    /// joint flagged seated: the closure angle and the tree angles are off their seats, which
    /// the invariant refuses, naming a seated angle; the same state rocking passes.
    #[test]
    fn a_seated_angle_off_its_seat_is_refused() {
        let model = Model::from_spec(&trilithon(0.25, 2.0, 2.0, 0.5, 1.0)).unwrap();
        let initial = released(&model, &model.coords[0].name, 0.05);
        let ground = GroundMotion::none();
        let mut sim = Simulation::new(&model, &ground, &initial, Parameters::default()).unwrap();
        assert!(sim.check_invariant().is_ok());
        sim.set_seated((0..model.slot_count).map(|s| (s, true)));
        match sim.check_invariant() {
            Err(SimulationError::Invariant(m)) => {
                assert!(m.contains("while it is seated"), "{m}");
                assert!(m.contains("rad"), "{m}");
            }
            other => panic!("{other:?}"),
        }
        // Within the tolerance (1e-5 rad by default) a seated angle passes: the same closed
        // mechanism turned by 0.5e-5 rad.
        let small = released(&model, &model.coords[0].name, 0.5e-5);
        let mut sim = Simulation::new(&model, &ground, &small, Parameters::default()).unwrap();
        sim.set_seated((0..model.slot_count).map(|s| (s, true)));
        assert!(sim.check_invariant().is_ok());
    }

    #[test]
    fn open_loops_are_refused() {
        let model = Model::from_spec(&trilithon(0.25, 2.0, 2.0, 0.5, 1.0)).unwrap();
        let initial = released(&model, &model.coords[0].name, 0.05);
        let ground = GroundMotion::none();
        let mut sim = Simulation::new(&model, &ground, &initial, Parameters::default()).unwrap();
        assert!(sim.check_invariant().is_ok());
        // Turn one column alone by 1e-3 rad: the beam no longer closes the loop.
        sim.y[1] += 1e-3;
        match sim.check_invariant() {
            Err(SimulationError::Invariant(m)) => assert!(m.contains("loops are open"), "{m}"),
            other => panic!("{other:?}"),
        }
    }
}

#[cfg(test)]
mod parameter_tests {
    use super::Parameters;
    use crr_dynamics::integrator::Method;

    #[test]
    fn the_default_parameters_are_the_documented_defaults_of_analysis() {
        // docs/model-format.md, `[analysis]`: each default as the documentation states it.
        let p = Parameters::default();
        assert_eq!(p.duration, 10.0);
        assert_eq!(p.output_interval, 0.01);
        assert!(matches!(p.method, Method::Dop853));
        assert_eq!((p.options.rtol, p.options.atol), (1e-10, 1e-12));
        assert_eq!(p.options.h_max, f64::INFINITY);
        assert_eq!(p.seat_rate, 1e-4);
        assert_eq!(p.min_impact_interval, 1e-6);
        assert_eq!(p.simultaneity, 1e-8);
        assert_eq!(p.max_impacts, 1_000_000);
        assert_eq!(p.friction, None);
        assert_eq!(p.collapse_drop, 1e-3);
    }
}

#[cfg(test)]
mod flight_tests {
    //! Which bodies a lift-off leaves without support, on a trilithon (two columns on the
    //! ground, an architrave on both; its right top closes the loop) and a stack of three drums.
    use crr_kinematics::Model;
    use crr_kinematics::fixtures::{serial_chain, trilithon};

    use super::bodies_without_support;

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn a_body_flies_only_when_no_closed_contact_joins_it_to_the_ground() {
        let model = Model::from_spec(&trilithon(0.2, 1.5, 1.2, 0.4, 1.0)).unwrap();
        // The architrave leaving one column keeps the other, through the tree or the loop.
        for one in ["top_left", "top_right"] {
            assert!(
                bodies_without_support(&model, &names(&[one])).is_empty(),
                "{one}"
            );
        }
        // Leaving both, it flies; a column leaving the ground still touches the architrave,
        // which stands on the other column.
        assert_eq!(
            bodies_without_support(&model, &names(&["top_left", "top_right"])),
            names(&["architrave"])
        );
        assert!(bodies_without_support(&model, &names(&["base_left"])).is_empty());
        // Both bases: the whole frame flies.
        assert_eq!(
            bodies_without_support(&model, &names(&["base_left", "base_right"])).len(),
            3
        );
        // A serial chain: a joint that opens carries everything above it away.
        let chain = Model::from_spec(&serial_chain(3)).unwrap();
        let second = chain.interfaces[1].name.clone();
        let above: Vec<String> = chain.bodies[1..].iter().map(|b| b.name.clone()).collect();
        assert_eq!(bodies_without_support(&chain, &[second]), above);
    }
}

#[cfg(test)]
mod chatter_tests {
    //! The stop on impacts that chatter, on a record of impacts written by hand into a run of a
    //! single block: 200 impacts less than `min_impact_interval` apart on average on two
    //! interfaces stop it, naming them; as many on 200 interfaces (joints ending their rocking
    //! together), the Zeno sequence of a rocking block (intervals shrinking geometrically to the
    //! interval) and a steady sequence just above the interval do not.
    use crr_dynamics::ground_motion::GroundMotion;
    use crr_dynamics::{InitialSpec, solve_initial};
    use crr_kinematics::Model;
    use crr_kinematics::fixtures::single_block;

    use super::{CHATTER_IMPACTS, ImpactRecord, Parameters, Simulation, SimulationError};

    fn record(t: f64, interface: &str) -> ImpactRecord {
        ImpactRecord {
            t,
            interfaces: vec![interface.to_string()],
            slots: vec![0],
            rates_before: vec![1e-6],
            rates_after: vec![0.0],
            energy_lost: 0.0,
            energy_gain: false,
            seated: vec![],
            released: vec![],
        }
    }

    #[test]
    fn impacts_closer_than_the_interval_on_average_stop_the_run() {
        let model = Model::from_spec(&single_block(0.2, 1.0, 2500.0)).unwrap();
        let initial = solve_initial(&model, &InitialSpec::default()).unwrap();
        let ground = GroundMotion::none();
        let params = Parameters::default();
        let interval = params.min_impact_interval;
        let mut sim = Simulation::new(&model, &ground, &initial, params).unwrap();
        // Two supports landing in turn every 0.88 interval (the 10 × 10 wall's 0.88 µs).
        let names = ["left_seat", "right_seat"];
        for i in 0..CHATTER_IMPACTS {
            sim.impacts
                .push(record(0.5 + 0.44 * interval * i as f64, names[i % 2]));
        }
        sim.t = 0.5 + 0.44 * interval * CHATTER_IMPACTS as f64;
        match sim.check_impact_room() {
            Err(SimulationError::Chatter {
                count, interfaces, ..
            }) => {
                assert_eq!(count, CHATTER_IMPACTS);
                assert_eq!(interfaces, names);
            }
            other => panic!("{other:?}"),
        }
        // One impact fewer: not yet.
        sim.impacts.remove(0);
        assert!(sim.check_impact_room().is_ok());
        // The same times on 200 interfaces: many joints, no chatter.
        sim.impacts.insert(0, record(0.5, "left_seat"));
        for (i, r) in sim.impacts.iter_mut().enumerate() {
            r.interfaces = vec![format!("joint_{i}")];
        }
        assert!(sim.check_impact_room().is_ok());
        // A rocking block's Zeno sequence: intervals shrinking by r² = 0.81 from 1 ms down to
        // 1.01 intervals (the seating rule would end it at the first below the interval), 400
        // impacts, so that the last 200 are all at the smallest interval.
        sim.impacts.clear();
        let (mut t, mut gap): (f64, f64) = (0.0, 1e-3);
        for _ in 0..2 * CHATTER_IMPACTS {
            sim.impacts.push(record(t, "base"));
            t += gap.max(1.01 * interval);
            gap *= 0.81;
        }
        sim.t = t;
        assert!(sim.check_impact_room().is_ok());
        // Just below the interval on average, the same sequence stops.
        for (i, r) in sim.impacts.iter_mut().enumerate() {
            r.t = 0.99 * interval * i as f64;
        }
        sim.t = 0.99 * interval * (2 * CHATTER_IMPACTS) as f64;
        assert!(matches!(
            sim.check_impact_room(),
            Err(SimulationError::Chatter { .. })
        ));
    }
}

#[cfg(test)]
mod lost_at_impacts_tests {
    //! The impacts' losses kept as a running sum: after every impact of a long rocking run the
    //! sum equals the list's to the bit, and Housner's kinetic energies about the pivot,
    //! ½ I_O (θ̇⁻² − θ̇⁺²), summed over the impacts, to round-off.
    use crr_dynamics::ground_motion::{Axis, ComponentSpec, GroundMotion, SignalSpec, SineSpec};
    use crr_dynamics::{InitialSpec, solve_initial};
    use crr_kinematics::Model;
    use crr_kinematics::fixtures::single_block;

    use super::{Parameters, Simulation, StopReason};

    #[test]
    fn the_running_sum_of_the_losses_is_the_sum_over_every_impact() {
        let (b, h, density) = (0.2, 1.0, 2500.0);
        let model = Model::from_spec(&single_block(b, h, density)).unwrap();
        let sine = ComponentSpec::new(SignalSpec::Sine(SineSpec {
            amplitude: 4.0,
            period: None,
            frequency: Some(2.0),
            phase: 0.0,
            cycles: None,
            start: 0.0,
        }));
        let ground = GroundMotion::none()
            .with_component(Axis::X, &sine, std::path::Path::new("."))
            .unwrap();
        let initial = solve_initial(&model, &InitialSpec::default()).unwrap();
        let params = Parameters {
            duration: 40.0,
            ..Parameters::default()
        };
        let mut sim = Simulation::new(&model, &ground, &initial, params).unwrap();
        // I_O = (4/3) m R² of the 2b × 2b × 2h box about a base edge (its depth is 2b).
        let mass = density * (2.0 * b) * (2.0 * b) * (2.0 * h);
        let i_o = 4.0 / 3.0 * mass * (b * b + h * h);
        let (mut housner, mut impacts) = (0.0, 0);
        loop {
            match sim.step().unwrap() {
                StopReason::Impact(k) => {
                    let record = &sim.impacts[k];
                    let (before, after) = (record.rates_before[0], record.rates_after[0]);
                    housner += 0.5 * i_o * (before * before - after * after);
                    impacts += 1;
                    let listed: f64 = sim.impacts.iter().map(|i| i.energy_lost).sum();
                    assert_eq!(sim.lost_at_impacts().to_bits(), listed.to_bits());
                    // Each term is about ½ I_O θ̇² ≈ 10² J and carries the rates' round-off
                    // (about 1e-15 relative); 1e-9 of the running total leaves room for the
                    // sum's own rounding over the run's impacts, far below a missed impact.
                    let scale = 1e-9 * housner.abs().max(1.0);
                    assert!(
                        (sim.lost_at_impacts() - housner).abs() <= scale,
                        "impact {impacts}: {} J booked, {housner} J by Housner's energies",
                        sim.lost_at_impacts()
                    );
                }
                StopReason::End(_) => break,
                StopReason::Collapse(c) => panic!("the block collapsed: {c:?}"),
                _ => {}
            }
        }
        // Four impacts a second once the rocking is steady.
        assert!(impacts > 100, "{impacts} impacts");
    }
}
