//! The typed summary of a run: what `summary.json` holds (documented field by field in
//! `docs/outputs.md`), as a struct an embedding program reads without parsing JSON.
//!
//! `summary.json` is written from [`Summary::to_json`], which orders every object's keys
//! alphabetically, as the file always has, whatever the order of the fields here.

use serde::{Deserialize, Serialize};

use crr_dynamics::InitialSpec;

use crate::input::model_file::ModelFile;

/// Everything a run's `summary.json` says about it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// The version of crr that ran it.
    pub crr_version: String,
    /// The run reached its duration or a collapse without an error.
    pub completed: bool,
    /// The error that stopped the run part-way, if any.
    pub error: Option<String>,
    /// The model's path (or label) as given.
    pub model_file: String,
    /// The model file as run: its `[ground_motion]`, `[initial]` and `[analysis]` as replaced
    /// by the run's options, gravity filled in. Records given in memory
    /// (`RunOptions::records`) replace components after this table and are not written into it;
    /// a record file is echoed in `record`.
    pub model: ModelFile,
    /// The record file that replaced one component (`--record`), if any.
    pub record: Option<RecordSummary>,
    /// The ground motion's peaks and duration.
    pub ground_motion: GroundMotionSummary,
    /// The initial state asked for and the consistent one solved from it.
    pub initial: InitialSummary,
    /// The solver settings in force.
    pub solver: SolverSettings,
    /// The integrator's work.
    pub solver_stats: SolverStats,
    /// Time reached (s).
    pub end_time: f64,
    /// Rows of `history.csv`.
    pub samples: usize,
    /// Peak |angle| per coordinate and its ratio to the slenderness α.
    pub coordinates: Vec<CoordinateSummary>,
    /// Number of impacts.
    pub impacts: usize,
    /// Kinetic energy lost at the impacts (J).
    pub energy_lost_at_impacts: f64,
    /// Impacts that raised the kinetic energy (a numerical failure of the impact map).
    pub impacts_with_energy_gain: usize,
    /// What a user must know before trusting the results.
    pub warnings: Vec<String>,
    /// First uplift from a seated state (s).
    pub uplift_time: Option<f64>,
    /// Whether and when a body overturned.
    pub collapse: CollapseSummary,
    /// Largest |T + U − W + D − E(0)| over the samples (J).
    pub energy_balance_error: f64,
    /// Σ|ΔT + ΔU| of the snaps booked in D (J): seated joints set to exactly 0 with the loops
    /// closed again, at impacts and at seating, and a twisting seat's loop closed on its new
    /// corner. Compare with `energy_lost_at_impacts`.
    pub energy_at_snaps: f64,
    /// The first failure of the rigid-contact hypotheses (flight, a resultant outside its face,
    /// sliding), if any.
    pub hypothesis_violation: Option<ViolationSummary>,
    /// The pulls at pivots where a segment started (just after an impact), each measured by the
    /// bound on how far its face would open (docs/simulation.md, "Hops"). Absent from a summary
    /// written before 2026-12-01.
    #[serde(default)]
    pub hops: HopsSummary,
}

/// The hops of a run (`hops` of summary.json; each one in hops.csv).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HopsSummary {
    /// How many.
    pub count: usize,
    /// How many are not within `hop_tolerance` (with the default 0, every one): each is a
    /// violation of the hypotheses, of which `hypothesis_violation` holds the first.
    pub beyond_tolerance: usize,
    /// The largest separation bound (m); None without hops.
    pub largest_separation: Option<f64>,
    /// The largest pull (N); None without hops.
    pub largest_pull: Option<f64>,
}

impl Summary {
    /// The text of `summary.json`: pretty-printed, keys in alphabetical order, a final newline.
    pub fn to_json(&self) -> String {
        // Through a `Value`, whose maps are sorted: the file's key order never depended on the
        // order of the fields.
        let value = serde_json::to_value(self).expect("a summary is plain data");
        serde_json::to_string_pretty(&value).expect("a JSON value prints") + "\n"
    }
}

/// A record file that replaced one component of the ground motion.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordSummary {
    /// The file as given.
    pub file: String,
    /// Its format (`peer-at2`, `csv`, `text`).
    pub format: String,
    /// Units of csv/text records.
    pub units: Option<String>,
    /// The component it drives (`x`, `y`, `z`).
    pub component: String,
    /// Factor on its accelerations.
    pub scale: f64,
}

/// The ground motion's peaks and duration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GroundMotionSummary {
    /// Peak |a| per component x, y, z (m/s²).
    pub pga: [f64; 3],
    /// When the motion ends (s); `None` for one that does not (a sine).
    pub duration: Option<f64>,
}

/// The initial state asked for and the consistent one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InitialSummary {
    /// `[initial]` as given.
    pub spec: InitialSpec,
    /// Consistent angles q(0) (rad), in the order of the coordinates.
    pub q: Vec<f64>,
    /// Consistent rates q̇(0) (rad/s).
    pub qdot: Vec<f64>,
}

/// The solver settings in force (`[analysis]` with its defaults filled in).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolverSettings {
    /// `dop853`, `dopri5` or `rk4`.
    pub method: String,
    /// Duration run (s).
    pub duration: f64,
    /// Interval between history rows (s).
    pub output_interval: f64,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Longest step (s); `None` when unbounded.
    pub max_step: Option<f64>,
    /// RK4's fixed step (s).
    pub rk4_step: f64,
    /// Rate below which a joint reaching its seat stays seated (rad/s).
    pub seat_rate: f64,
    /// Shortest interval between impacts of one joint (s).
    pub min_impact_interval: f64,
    /// Joints closer than this to their seats impact together (rad).
    pub simultaneity: f64,
    /// The run stops after this many impacts.
    pub max_impacts: usize,
    /// A body whose centre dropped by this fraction of its height has collapsed.
    pub collapse_drop: f64,
    /// Friction coefficient μ checked by the monitor, if given.
    pub friction: Option<f64>,
    /// Seated joints held through momentum-law impacts even where that pulls (`[analysis]`
    /// `hold_seated_at_impacts`).
    #[serde(default)]
    pub hold_seated_at_impacts: bool,
    /// `hop_tolerance` (m; read as 0 from a summary written before 2026-12-01).
    #[serde(default)]
    pub hop_tolerance: f64,
    /// The run ended at its first hypotheses violation (`[analysis] stop_at_violation`; read
    /// as false from a summary written before 2026-12-05).
    #[serde(default)]
    pub stop_at_violation: bool,
}

/// The integrator's work over the run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolverStats {
    /// Steps tried.
    pub steps: usize,
    /// Steps accepted.
    pub accepted: usize,
    /// Steps rejected.
    pub rejected: usize,
    /// Evaluations of the equations of motion.
    pub rhs_evaluations: usize,
}

/// One coordinate's peak.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CoordinateSummary {
    /// The coordinate's name.
    pub name: String,
    /// Peak |angle| (rad).
    pub peak_abs: f64,
    /// Slenderness α (rad), for a joint with two pivots.
    pub alpha: Option<f64>,
    /// peak_abs / α.
    pub peak_over_alpha: Option<f64>,
}

/// Whether and when a body overturned.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CollapseSummary {
    /// A body overturned.
    pub collapsed: bool,
    /// When (s).
    pub time: Option<f64>,
    /// Which body.
    pub body: Option<String>,
}

/// The first failure of the rigid-contact hypotheses.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViolationSummary {
    /// When (s).
    pub time: f64,
    /// The interface.
    pub interface: String,
    /// `tension` (flight), `outside_face` (a seated joint that should be rocking), `sliding`,
    /// `lift_off` (a face the contact program lifts off that the model cannot follow; no force
    /// is computed: its normal force is then 0 and its friction demand `None`), or
    /// `impulse_tension` (a landing's impulse that pulls: `normal_force` is then the least
    /// normal impulse, N s, and the friction demand `None`), or `sliding_unloaded` (at rest
    /// under a load beyond a mechanism in which this joint slides unloaded while keeping
    /// contact, which the model cannot follow; normal force 0, friction demand `None`).
    pub kind: String,
    /// Its normal force (N); for `outside_face`, the force of the edge that would pull; for
    /// `impulse_tension`, the least normal impulse (N s).
    pub normal_force: f64,
    /// |F_t|/N needed; `None` when undefined.
    pub friction_demand: Option<f64>,
    /// For a `tension` at a face that pulls on its pivot where a segment starts (just after an
    /// impact): that pull measured by the motion with the face released (docs/simulation.md,
    /// "Hops"); None otherwise.
    #[serde(default)]
    pub hop: Option<crr_impact::simulation::Hop>,
}
