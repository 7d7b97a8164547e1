//! Explicit Runge–Kutta ODE integrators with dense output and exact event
//! location, tailored to piecewise-smooth rocking dynamics.
//!
//! Three methods are provided (see [`Method`]):
//!
//! * [`Method::Dop853`] — Dormand & Prince 8(5,3) as in Hairer's `dop853.f`,
//!   adaptive, with its 7th-order continuous extension;
//! * [`Method::Dopri5`] — Dormand & Prince 5(4), adaptive, FSAL, with the
//!   4th-order continuous extension of Hairer's `dopri5.f`;
//! * [`Method::Rk4`] — classical fixed-step Runge–Kutta of order 4 with a
//!   cubic Hermite interpolant as dense output.
//!
//! The [`Solver`] keeps its state `(t, y)` between calls of
//! [`Solver::advance`], which integrates until a caller-given end time
//! (landed on *exactly*, so it can serve as a breakpoint of a piecewise
//! forcing) or until the first event of an [`EventFunctions`] set.
//!
//! # Events
//!
//! After each accepted step the event functions `g_i(t, y)` are evaluated at
//! the step end. An event `i` is detected when `g_i` changes sign across the
//! step in the direction allowed by [`EventFunctions::direction`]. Its time
//! is located by Brent's method on `g_i(t, y_dense(t))` to a bracket width
//! `≤ 1e-13·max(1, |t|)`; the earliest located root among all functions
//! wins. The returned time is the end of the final bracket on the
//! *post-crossing* side, so `g_i` has (to interpolation accuracy) already
//! changed sign there.
//!
//! **The state at the event is not taken from the interpolant**: the solver
//! repeats the step from its start `t0` with the step size `t* − t0`, i.e.
//! a genuine step of the method lands exactly on `t*`. The solver state then
//! is `(t*, y(t*))` and the dense output of that *partial* step (not of the
//! full trial step) is the one passed to `on_step`.
//!
//! **The landing step validates the located root** (adaptive methods): it
//! must pass the error control and agree with the interpolant at `t*` to
//! within [`DENSE_TRUST`] tolerances. Otherwise the accepted step had stepped
//! over a narrow feature its stages did not see (e.g. a force confined to a
//! thin band of the state), so its interpolant and the signs of the event
//! functions at its end say nothing about where the roots are: the step is
//! rejected and redone from `t0` with the landing step's (or a smaller) size,
//! and the events are detected again on that step. The state never moves
//! past a root without a step whose ends show the sign change.
//!
//! **No re-firing on restart**: at the start of every [`Solver::advance`]
//! the event functions are evaluated at the current state. A function that
//! is zero there (`|g_i| ≤` [`EVENT_ZERO_TOL`]), or the function that fired
//! the previous event at exactly this time (also across
//! [`Solver::reset`] to the same time), is considered to be *at* its root:
//! it cannot fire at the start and its sign is taken from the first point
//! after the start (the dense solution at `t0 + 10⁻³·h` of the first step,
//! or later points if `g_i` is still zero there).
//!
//! # Modules
//!
//! This file holds the types, the options and [`Solver::advance_lazily`] (the step loop with
//! its error control, breakpoints and event handling; [`Solver::advance`] computes every
//! step's dense output); `stages` computes one step (stage inputs,
//! right-hand sides, error estimate, dense coefficients, the initial step size), `dense` reads
//! a step's interpolant ([`DenseStep`]), `events` locates a root inside a step, and `tableau`
//! holds the methods' coefficients.

mod dense;
mod events;
mod stages;
mod tableau;

use crate::Cancel;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crr_kinematics::short_copy::copy_short;

use dense::dense_eval;
pub use dense::{DenseComponent, DenseStep, StepEnds};
use events::{ZERO_START_PROBE, crosses};
use stages::call_rhs;
use tableau::*;

/// Error returned by a right-hand side evaluation; the message is shown by
/// `Display`.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{0}")]
pub struct RhsError(pub String);

/// A first-order ODE system `y' = f(t, y)`.
pub trait OdeSystem {
    /// Dimension of the state vector.
    fn dim(&self) -> usize;
    /// Evaluates `dydt = f(t, y)`. Both slices have length [`Self::dim`].
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError>;
    /// Called after every accepted step (and after the step that lands on an event) with the new
    /// state; may move it back onto an invariant manifold (e.g. loop closures Φ = 0 and
    /// Φ_q q̇ = 0). Returns whether `y` was changed (then f(t, y) is evaluated again before the
    /// next step). The default does nothing.
    fn project(&mut self, _t: f64, _y: &mut [f64]) -> Result<bool, RhsError> {
        Ok(false)
    }
}

/// Allowed crossing direction of an event function.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Direction {
    /// Both directions trigger the event.
    #[default]
    Any,
    /// Only crossings from negative to non-negative values.
    Rising,
    /// Only crossings from positive to non-positive values.
    Falling,
}

/// A set of event (switching) functions `g_i(t, y)`, `i < count()`.
///
/// Functions should be scaled to `O(1)`: values with magnitude
/// `≤` [`EVENT_ZERO_TOL`] at the start of an advance are treated as zero.
pub trait EventFunctions {
    /// Number of event functions.
    fn count(&self) -> usize;
    /// Evaluates all event functions at `(t, y)` into `g` (length `count()`).
    fn eval(&mut self, t: f64, y: &[f64], g: &mut [f64]);
    /// Evaluates function `i` alone at `(t, y)`; root location calls only this. `g` is scratch
    /// of length `count()`. The default evaluates them all; an implementation whose functions
    /// differ much in cost (one needing a solve of the dynamics) overrides it.
    fn eval_one(&mut self, i: usize, t: f64, y: &[f64], g: &mut [f64]) -> f64 {
        self.eval(t, y, g);
        g[i]
    }
    /// Evaluates the functions again at `(t, y)` after the projection moved the state of an
    /// accepted step by its constraint drift; `g` holds their values before the projection. The
    /// default evaluates them all; an implementation may keep a function whose value is a
    /// decision rather than a distance (a sign that round-off of the state cannot move except
    /// at a threshold, where the next step's end decides as well) and that costs a solve.
    fn eval_after_projection(&mut self, t: f64, y: &[f64], g: &mut [f64]) {
        self.eval(t, y, g);
    }
    /// Allowed crossing direction of function `i`.
    fn direction(&self, i: usize) -> Direction;
    /// Whether function `i` is also read inside each accepted step, not only at its ends: a
    /// distance that can fall through zero and rise back within one step (a rocking joint that
    /// passes its pivot and comes back before the step ends), whose crossing a test of the ends
    /// misses ([`Solver::advance_lazily`], "Crossings inside a step"). Such a function should
    /// be cheap: it is read at [`INSIDE_SAMPLES`] − 1 points of every step. None by default.
    fn checked_inside(&self, _i: usize) -> bool {
        false
    }
    /// Evaluates at `(t, y)` at least the functions [`Self::checked_inside`] into `g` (the
    /// others may be left as they are). The default evaluates them all.
    fn eval_inside(&mut self, t: f64, y: &[f64], g: &mut [f64]) {
        self.eval(t, y, g);
    }
}

/// The functions [`EventFunctions::checked_inside`] are read at the points k·h/`INSIDE_SAMPLES`,
/// k = 1 … `INSIDE_SAMPLES` − 1, of every accepted step of size h: a dip below zero shorter than
/// about h/32 between two of them is not seen. With 8 points, the 9-voussoir arch of
/// `crates/crr-impact/tests/arch_pulses.rs` under 1.1 λ g missed two crossings 2.4 µs apart at
/// 0.5454 s that a run with steps of at most 0.1 ms finds, and its history parted from that run's
/// there (with 32, at 0.5617 s); the bundled temple's 6 s at 0.8 of its record cost 2–3 % more.
pub const INSIDE_SAMPLES: usize = 32;

/// The empty event set.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NoEvents;

impl EventFunctions for NoEvents {
    fn count(&self) -> usize {
        0
    }
    fn eval(&mut self, _t: f64, _y: &[f64], _g: &mut [f64]) {}
    fn direction(&self, _i: usize) -> Direction {
        Direction::Any
    }
}

/// Absolute threshold below which an event function value at the start of
/// an advance counts as exactly zero (no firing at the start).
pub const EVENT_ZERO_TOL: f64 = 1e-14;

/// Integration method.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum Method {
    /// Dormand–Prince 8(5,3), adaptive, 7th-order dense output.
    #[default]
    Dop853,
    /// Dormand–Prince 5(4), adaptive, FSAL, 4th-order dense output.
    Dopri5,
    /// Classical fixed-step RK4 with cubic Hermite dense output.
    Rk4 {
        /// The (fixed) step size; the last step before an end time is
        /// shortened (or stretched by at most 1 %) to land on it.
        step: f64,
    },
}

/// Integration options. Tolerances are ignored by [`Method::Rk4`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Options {
    /// Relative tolerance (default `1e-10`).
    pub rtol: f64,
    /// Absolute tolerance (default `1e-12`).
    pub atol: f64,
    /// Initial step size; `None` (default) selects it by Hairer's
    /// heuristic. Used only while the solver has no step-size history.
    pub h_init: Option<f64>,
    /// Maximum step size (default `+∞`, i.e. unlimited; `inf` in TOML).
    pub h_max: f64,
    /// Maximum number of attempted steps per call of [`Solver::advance`]
    /// (default `1_000_000`).
    pub max_steps: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rtol: 1e-10,
            atol: 1e-12,
            h_init: None,
            h_max: f64::INFINITY,
            max_steps: 1_000_000,
        }
    }
}

impl Options {
    /// Checks that the options are meaningful.
    pub fn validate(&self) -> Result<(), SolveError> {
        let bad = |m: &str| Err(SolveError::InvalidOptions(m.to_string()));
        if !(self.rtol >= 0.0 && self.rtol.is_finite()) {
            return bad("rtol must be finite and >= 0");
        }
        if !(self.atol >= 0.0 && self.atol.is_finite()) {
            return bad("atol must be finite and >= 0");
        }
        if self.rtol == 0.0 && self.atol == 0.0 {
            return bad("rtol and atol must not both be 0");
        }
        if self.h_max.is_nan() || self.h_max <= 0.0 {
            return bad("h_max must be > 0");
        }
        if let Some(h) = self.h_init
            && !(h > 0.0 && h.is_finite())
        {
            return bad("h_init must be finite and > 0");
        }
        if self.max_steps == 0 {
            return bad("max_steps must be > 0");
        }
        Ok(())
    }
}

/// Step statistics accumulated since the solver was created.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stats {
    /// Steps computed (accepted, rejected and event re-steps).
    pub steps: usize,
    /// Steps accepted by the error control (for RK4: all regular steps).
    pub accepted: usize,
    /// Steps rejected by the error control.
    pub rejected: usize,
    /// Right-hand side evaluations.
    pub rhs_evals: usize,
}

/// The step-size control's verdict on a step.
enum StepControl {
    /// Redo the step with this size.
    Rejected {
        /// The size to redo it with.
        retry: f64,
    },
    /// Keep it; the next step's size.
    Accepted {
        /// The proposal for the next step.
        next: f64,
    },
}

/// Why [`Solver::advance`] returned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop {
    /// The end time was reached; `Solver::t() == t_end` exactly.
    Reached,
    /// Event `index` occurred at `t`; the solver state is `(t, y(t))`.
    Event {
        /// Index of the event function.
        index: usize,
        /// Located event time.
        t: f64,
    },
}

/// Integration failure.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolveError {
    /// The right-hand side returned an error.
    #[error("right-hand side failed at t = {t}: {source}")]
    Rhs {
        /// Time of the failing evaluation.
        t: f64,
        /// The error of the system.
        source: RhsError,
    },
    /// The step size fell below the resolution of `t`.
    #[error("step size underflow at t = {t} (h = {h:e})")]
    StepSizeUnderflow {
        /// Current time.
        t: f64,
        /// The too-small step size.
        h: f64,
    },
    /// `max_steps` steps were attempted in one advance.
    #[error("too many steps ({max_steps}) at t = {t}")]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// The limit.
        max_steps: usize,
    },
    /// The new state or the error estimate of a step starting at `t` is NaN
    /// or infinite.
    #[error("non-finite state or error estimate in the step from t = {t} (h = {h:e})")]
    NonFinite {
        /// Start of the failing step.
        t: f64,
        /// Its step size.
        h: f64,
    },
    /// `t_end` is before the current time (backward integration is not
    /// supported).
    #[error("end time {t_end} is before the current time {t}")]
    BackwardEnd {
        /// Current time.
        t: f64,
        /// Requested end.
        t_end: f64,
    },
    /// Invalid [`Options`] or method parameters.
    #[error("invalid integrator options: {0}")]
    InvalidOptions(String),
    /// The interrupt flag ([`Solver::set_interrupt`]) was set: the advance stopped after an
    /// accepted step, the solver's state `(t, y(t))` is that step's end.
    #[error("interrupted at t = {t}")]
    Interrupted {
        /// Time reached: the end of the last accepted step.
        t: f64,
    },
}

/// Largest distance (RMS, in tolerances `atol + rtol·|y|`) between the dense output of a step at
/// a located event time and the genuine step that lands there, for the step to be trusted (see
/// [`Solver::advance`]). The interpolant of an accepted step is accurate to a few tolerances; a
/// step whose stages missed a narrow feature is off by orders of magnitude more.
pub const DENSE_TRUST: f64 = 1e3;

/// An ODE solver holding the current state `(t, y)`.
///
/// All work buffers are allocated in [`Solver::new`]; stepping does not
/// allocate (event buffers are sized on the first advance with a given
/// number of event functions).
#[derive(Debug, Clone)]
pub struct Solver {
    method: Method,
    opts: Options,
    dim: usize,
    t: f64,
    y: Vec<f64>,
    /// `f(t, y)` when `f_valid`.
    f: Vec<f64>,
    f_valid: bool,
    y_new: Vec<f64>,
    y_tmp: Vec<f64>,
    /// The interpolant at a located event time, checked against the landing step.
    y_event: Vec<f64>,
    /// Stage derivatives, `stages × dim`.
    k: Vec<f64>,
    /// Dense-output coefficients of the last computed step, `ncoef × dim`.
    dense: Vec<f64>,
    /// The size of the last finished step whose dense output still lacks DOP853's extra stages
    /// ([`Solver::complete_dense`]); None when complete (or when no step is pending).
    dense_pending: Option<f64>,
    /// Proposed next step size; 0 if unknown.
    h_next: f64,
    facold: f64,
    last_rejected: bool,
    stats: Stats,
    g_prev: Vec<f64>,
    g_new: Vec<f64>,
    g_ref: Vec<f64>,
    g_tmp: Vec<f64>,
    zero_start: Vec<bool>,
    /// The functions checked inside the step being tested whose ends show no crossing, each
    /// with the start of its test (time, value) and whether the cubic interpolant crosses.
    inside: Vec<(usize, f64, f64, bool)>,
    /// Event fired last (index, time).
    fired: Option<(usize, f64)>,
    /// Read after every accepted step that does not end the advance ([`Solver::set_interrupt`]).
    interrupt: Option<Cancel>,
}

impl Solver {
    /// Creates a solver for systems of dimension `dim`, with state
    /// `(0, 0…0)`; call [`Solver::reset`] to set the initial condition.
    pub fn new(method: Method, options: Options, dim: usize) -> Result<Self, SolveError> {
        options.validate()?;
        if let Method::Rk4 { step } = method
            && !(step > 0.0 && step.is_finite())
        {
            return Err(SolveError::InvalidOptions(
                "RK4 step must be finite and > 0".into(),
            ));
        }
        let (stages, ncoef) = match method {
            Method::Dop853 => (DOP853_STAGES, 8),
            Method::Dopri5 => (DOPRI5_STAGES, 5),
            Method::Rk4 { .. } => (5, 4),
        };
        Ok(Self {
            method,
            opts: options,
            dim,
            t: 0.0,
            y: vec![0.0; dim],
            f: vec![0.0; dim],
            f_valid: false,
            y_new: vec![0.0; dim],
            y_tmp: vec![0.0; dim],
            y_event: vec![0.0; dim],
            k: vec![0.0; stages * dim],
            dense: vec![0.0; ncoef * dim],
            dense_pending: None,
            h_next: 0.0,
            facold: 1e-4,
            last_rejected: false,
            stats: Stats::default(),
            g_prev: Vec::new(),
            g_new: Vec::new(),
            g_ref: Vec::new(),
            g_tmp: Vec::new(),
            zero_start: Vec::new(),
            inside: Vec::new(),
            fired: None,
            interrupt: None,
        })
    }

    /// A flag read after every accepted step that does not end the advance (one that reaches
    /// `t_end` or an event returns as usual): once set, [`Self::advance`] (and
    /// [`Self::advance_lazily`]) stop with [`SolveError::Interrupted`] at the end of that step, a
    /// state as good as any other step end. Each advance still takes at least one step, so that a
    /// caller that goes on after an interrupt makes progress. A long advance (a quiet stretch of
    /// many steps, a stalled one of many short steps) is then stopped within one step of the
    /// request instead of at its end.
    pub fn set_interrupt(&mut self, cancel: Option<Cancel>) {
        self.interrupt = cancel;
    }

    /// The request of [`Self::set_interrupt`].
    pub fn interrupt(&self) -> Option<&Cancel> {
        self.interrupt.as_ref()
    }

    /// Whether the request of [`Self::set_interrupt`] was made.
    pub fn interrupted(&self) -> bool {
        self.interrupt.as_ref().is_some_and(Cancel::is_cancelled)
    }

    /// Forgets which event fired last. Call it when the next `advance` uses a different set of
    /// event functions (indices then mean other functions); an event function exactly at zero
    /// (|g| ≤ [`EVENT_ZERO_TOL`]) at the start still cannot fire there.
    pub fn forget_last_event(&mut self) {
        self.fired = None;
    }

    /// Changes the largest step (s), e.g. while a narrow forcing feature is active. Positive or
    /// infinite; other values are ignored.
    pub fn set_h_max(&mut self, h_max: f64) {
        if h_max > 0.0 {
            self.opts.h_max = h_max;
            self.h_next = self.h_next.min(h_max);
        }
    }

    /// Sets the state to `(t0, y0)`, e.g. after an impact. Forgets the FSAL
    /// derivative and the step-size controller history but keeps the last
    /// proposed step size as the initial guess. If `t0` equals the time of
    /// the last event, that event function is still treated as being at its
    /// root (it cannot fire at `t0`).
    ///
    /// # Panics
    /// If `y0.len() != dim`.
    pub fn reset(&mut self, t0: f64, y0: &[f64]) {
        assert_eq!(y0.len(), self.dim, "reset: state has wrong dimension");
        self.t = t0;
        self.y.copy_from_slice(y0);
        self.f_valid = false;
        self.facold = 1e-4;
        self.last_rejected = false;
        if let Some((_, tf)) = self.fired
            && tf != t0
        {
            self.fired = None;
        }
    }

    /// Current time.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Current state.
    pub fn y(&self) -> &[f64] {
        &self.y
    }

    /// State dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The method.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The options.
    pub fn options(&self) -> &Options {
        &self.opts
    }

    /// Step size the controller proposes for the next step (0 if none yet).
    pub fn step_size_guess(&self) -> f64 {
        self.h_next
    }

    /// Accumulated statistics.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Integrates from the current state until `t_end` (landed on exactly)
    /// or until the first event, whichever comes first. `on_step` is called
    /// for every accepted step with its dense output (for an event, the
    /// partial step ending at the event). See the module documentation for
    /// the event semantics. The step repeated to land on an event time is
    /// error-checked and compared with the interpolant; if either test fails,
    /// the step is redone from its start with a smaller size and the events
    /// are detected on that step. Interior double crossings of an event
    /// function within one step (no sign change at the step ends) are not
    /// detected; limit `h_max` if that matters.
    ///
    /// # Panics
    /// If `sys.dim()` differs from the solver dimension.
    pub fn advance(
        &mut self,
        sys: &mut impl OdeSystem,
        t_end: f64,
        events: &mut impl EventFunctions,
        on_step: &mut impl FnMut(&DenseStep),
    ) -> Result<Stop, SolveError> {
        self.advance_lazily(sys, t_end, events, &mut |_| true, &mut |_, dense| {
            if let Some(step) = dense {
                on_step(step);
            }
        })
    }

    /// [`Self::advance`], with each step's dense output computed only where it is read:
    /// `wants_dense` is asked with the exact states at the ends of every accepted step (for an
    /// event, of the partial step ending at it), and `on_step` then receives those ends and the
    /// dense output where it was wanted (None otherwise). DOP853 saves its three extra stages
    /// per step (a fifth of its right-hand sides) on the steps nobody interpolates. Event
    /// location computes the dense output it needs itself. The integration is the same
    /// operations in the same order for a right-hand
    /// side that is a function of (t, y) alone; one that keeps state across calls (a cache)
    /// sees fewer calls. A right-hand side that fails at an extra stage of a step nobody reads
    /// is not evaluated there, so that step does not stop the run.
    pub fn advance_lazily(
        &mut self,
        sys: &mut impl OdeSystem,
        t_end: f64,
        events: &mut impl EventFunctions,
        wants_dense: &mut impl FnMut(&StepEnds) -> bool,
        on_step: &mut impl FnMut(&StepEnds, Option<&DenseStep>),
    ) -> Result<Stop, SolveError> {
        assert_eq!(sys.dim(), self.dim, "advance: system dimension mismatch");
        if t_end < self.t || t_end.is_nan() {
            return Err(SolveError::BackwardEnd { t: self.t, t_end });
        }
        if t_end == self.t {
            return Ok(Stop::Reached);
        }
        if !self.f_valid {
            call_rhs(sys, &mut self.stats, self.t, &self.y, &mut self.f)?;
            self.f_valid = true;
        }

        let ne = self.setup_events(events);
        let adaptive = !matches!(self.method, Method::Rk4 { .. });
        let mut h = self.first_step_size(sys)?;
        let mut steps_here = 0usize;

        loop {
            if steps_here >= self.opts.max_steps {
                return Err(SolveError::TooManySteps {
                    t: self.t,
                    max_steps: self.opts.max_steps,
                });
            }
            steps_here += 1;
            if adaptive {
                h = h.min(self.opts.h_max);
            }
            let h_planned = h;
            let last = self.t + 1.01 * h >= t_end;
            if adaptive && !last && !(h > 10.0 * f64::EPSILON * self.t.abs() && h > 0.0) {
                return Err(SolveError::StepSizeUnderflow { t: self.t, h });
            }
            let t1 = if last {
                h = t_end - self.t;
                t_end
            } else {
                self.t + h
            };

            if !self.f_valid {
                call_rhs(sys, &mut self.stats, self.t, &self.y, &mut self.f)?;
                self.f_valid = true;
            }
            let err = self.rk_step(sys, h, t1)?;
            self.stats.steps += 1;
            if !err.is_finite() || self.y_new.iter().any(|v| !v.is_finite()) {
                return Err(SolveError::NonFinite { t: self.t, h });
            }

            let mut h_new = h;
            if adaptive {
                match self.control_step(err, h) {
                    StepControl::Rejected { retry } => {
                        h = retry;
                        continue;
                    }
                    StepControl::Accepted { next } => h_new = next,
                }
            }
            self.stats.accepted += 1;
            self.finish_step(sys, h, t1)?;

            let found = if ne > 0 {
                self.first_event(sys, events, t1, h)?
            } else {
                None
            };

            if let Some((index, t_star)) = found {
                if t_star != t1 {
                    if let Some(retry) = self.land_on_event(sys, h, t_star, adaptive)? {
                        h = retry;
                        continue;
                    }
                    let h_land = t_star - self.t;
                    self.emit(sys, (wants_dense, on_step), h_land, t_star)?;
                } else {
                    self.emit(sys, (wants_dense, on_step), h, t1)?;
                }
                self.commit(t_star);
                self.project(sys)?;
                self.h_next = h_new;
                self.fired = Some((index, t_star));
                return Ok(Stop::Event { index, t: t_star });
            }

            self.emit(sys, (wants_dense, on_step), h, t1)?;
            self.commit(t1);
            let projected = self.project(sys)?;
            if ne > 0 {
                self.carry_events(events, projected);
            }
            if adaptive {
                // A step shortened to land on `t_end` says little about the
                // step size the solution allows: keep the larger proposal.
                if last {
                    h_new = h_new.max(h_planned);
                }
                self.h_next = h_new;
            }
            h = h_new;
            if last {
                return Ok(Stop::Reached);
            }
            if self.interrupted() {
                return Err(SolveError::Interrupted { t: self.t });
            }
        }
    }

    /// Sizes the event buffers and evaluates the event functions at the start; an event that
    /// just fired here, or is already zero, starts at zero (it fires only after leaving zero).
    /// Returns the number of events.
    fn setup_events(&mut self, events: &mut impl EventFunctions) -> usize {
        let ne = events.count();
        self.g_prev.resize(ne, 0.0);
        self.g_new.resize(ne, 0.0);
        self.g_ref.resize(ne, 0.0);
        self.g_tmp.resize(ne, 0.0);
        self.zero_start.resize(ne, false);
        if ne > 0 {
            events.eval(self.t, &self.y, &mut self.g_prev);
            for i in 0..ne {
                let just_fired = matches!(self.fired, Some((j, tf)) if j == i && tf == self.t);
                self.zero_start[i] = just_fired || self.g_prev[i].abs() <= EVENT_ZERO_TOL;
            }
        }
        ne
    }

    /// The first step of this call: RK4's fixed step, the last call's proposal, the user's, or
    /// the automatic initial step.
    fn first_step_size(&mut self, sys: &mut impl OdeSystem) -> Result<f64, SolveError> {
        Ok(match self.method {
            Method::Rk4 { step } => step,
            _ if self.h_next > 0.0 => self.h_next,
            _ => match self.opts.h_init {
                Some(h0) => h0,
                None => self.initial_step(sys)?,
            },
        })
    }

    /// The step-size control of the adaptive methods (Hairer's, with Lund stabilisation for
    /// DOPRI5) on a step of size `h` with scaled error `err`.
    fn control_step(&mut self, err: f64, h: f64) -> StepControl {
        let (expo, beta, fac_min, fac_max): (f64, f64, f64, f64) = match self.method {
            Method::Dop853 => (1.0 / 8.0, 0.0, 0.333, 6.0),
            _ => (0.2 - 0.04 * 0.75, 0.04, 0.2, 10.0),
        };
        let safe = 0.9;
        let fac11 = err.powf(expo);
        if err > 1.0 {
            self.stats.rejected += 1;
            self.last_rejected = true;
            return StepControl::Rejected {
                retry: h / (1.0 / fac_min).min(fac11 / safe),
            };
        }
        let fac = fac11 / self.facold.powf(beta);
        let fac = (1.0 / fac_max).max((1.0 / fac_min).min(fac / safe));
        let mut next = (h / fac).min(self.opts.h_max);
        if self.last_rejected {
            next = next.min(h);
        }
        self.facold = err.max(1e-4);
        self.last_rejected = false;
        StepControl::Accepted { next }
    }

    /// The earliest event of the step [t, t1] of size `h` (its index and located time): a sign
    /// change in its direction between the step's start (or, for an event starting at zero, the
    /// probe at `ZERO_START_PROBE`·h) and its end.
    fn first_event(
        &mut self,
        sys: &mut impl OdeSystem,
        events: &mut impl EventFunctions,
        t1: f64,
        h: f64,
    ) -> Result<Option<(usize, f64)>, SolveError> {
        let ne = events.count();
        let mut found: Option<(usize, f64)> = None;
        events.eval(t1, &self.y_new, &mut self.g_new);
        let any_zero = self.zero_start.iter().any(|&z| z);
        let t_probe = self.t + ZERO_START_PROBE * h;
        if any_zero {
            self.complete_dense(sys)?;
            dense_eval(&self.dense, self.dim, self.t, h, t_probe, &mut self.y_tmp);
            events.eval(t_probe, &self.y_tmp, &mut self.g_ref);
        }
        for i in 0..ne {
            let gb = self.g_new[i];
            let (ta, ga) = if self.zero_start[i] {
                if self.g_ref[i].abs() > EVENT_ZERO_TOL {
                    (t_probe, self.g_ref[i])
                } else {
                    continue;
                }
            } else {
                (self.t, self.g_prev[i])
            };
            if !crosses(ga, gb, events.direction(i)) {
                continue;
            }
            let tb = match found {
                Some((_, tf)) => tf.min(t1),
                None => t1,
            };
            self.complete_dense(sys)?;
            let root = self.locate(events, i, ta, ga, t1, gb, tb, h);
            if let Some(tr) = root
                && found.is_none_or(|(_, tf)| tr < tf)
            {
                found = Some((i, tr));
            }
        }
        self.first_inside_crossing(sys, events, h, t_probe, found)
    }

    /// Crossings inside a step: the earliest of `found` (the crossings the step's ends show) and
    /// the crossings of the functions checked inside ([`EventFunctions::checked_inside`]) whose
    /// ends show none, the function falling through zero and rising back (or the reverse)
    /// within the step. Each is read first on the step's cubic Hermite interpolant (from the
    /// ends' states and derivatives, no stage beyond the step's own) at the points
    /// k·h/[`INSIDE_SAMPLES`]; where it crosses there, the step's full dense output is read at
    /// the same points, and the first interval where it crosses is the bracket its root is
    /// located in. A crossing the cubic does not show is not seen.
    fn first_inside_crossing(
        &mut self,
        sys: &mut impl OdeSystem,
        events: &mut impl EventFunctions,
        h: f64,
        t_probe: f64,
        mut found: Option<(usize, f64)>,
    ) -> Result<Option<(usize, f64)>, SolveError> {
        self.inside.clear();
        for i in 0..events.count() {
            if !events.checked_inside(i) {
                continue;
            }
            let (ta, ga) = if self.zero_start[i] {
                if self.g_ref[i].abs() > EVENT_ZERO_TOL {
                    (t_probe, self.g_ref[i])
                } else {
                    continue;
                }
            } else {
                (self.t, self.g_prev[i])
            };
            if ga != 0.0 && !crosses(ga, self.g_new[i], events.direction(i)) {
                self.inside.push((i, ta, ga, false));
            }
        }
        if self.inside.is_empty() {
            return Ok(found);
        }
        let (t0, dim) = (self.t, self.dim);
        let point = |k: usize| t0 + h * (k as f64 / INSIDE_SAMPLES as f64);
        for k in 1..INSIDE_SAMPLES {
            let tk = point(k);
            dense_eval(&self.dense[..4 * dim], dim, t0, h, tk, &mut self.y_tmp);
            events.eval_inside(tk, &self.y_tmp, &mut self.g_tmp);
            for entry in &mut self.inside {
                let (i, ta, ga, _) = *entry;
                if tk > ta && crosses(ga, self.g_tmp[i], events.direction(i)) {
                    entry.3 = true;
                }
            }
        }
        for j in 0..self.inside.len() {
            let (i, ta, ga, suspected) = self.inside[j];
            if !suspected {
                continue;
            }
            self.complete_dense(sys)?;
            // The first sample past the crossing on the full interpolant, and the last before.
            let (mut a, mut fa) = (ta, ga);
            let mut bracket = None;
            for k in 1..INSIDE_SAMPLES {
                let tk = point(k);
                if found.is_some_and(|(_, tf)| tf <= a) {
                    break;
                }
                if tk <= ta {
                    continue;
                }
                dense_eval(&self.dense, dim, t0, h, tk, &mut self.y_tmp);
                let gk = events.eval_one(i, tk, &self.y_tmp, &mut self.g_tmp);
                if crosses(ga, gk, events.direction(i)) {
                    bracket = Some((a, fa, tk, gk));
                    break;
                }
                if gk != 0.0 {
                    (a, fa) = (tk, gk);
                }
            }
            let Some((a, fa, b, fb)) = bracket else {
                continue;
            };
            let tb = found.map_or(b, |(_, tf)| tf.min(b));
            let root = self.locate(events, i, a, fa, b, fb, tb, h);
            if let Some(tr) = root
                && found.is_none_or(|(_, tf)| tr < tf)
            {
                found = Some((i, tr));
            }
        }
        Ok(found)
    }

    /// Lands on the event time t* with a genuine step from the step start. The root was located
    /// on the interpolant of a step (size `h`) whose stages may have missed a narrow feature (a
    /// regularised δ zone inside the step): then the landing step fails the error control or
    /// disagrees with the interpolant, and its state may lie past other roots that would never
    /// fire (formerly sub-steps carried the state on to t* without event detection). The long
    /// step is then rejected and the size to redo it with is returned, so events are located
    /// only on steps that resolve them; `None` when the landing step is accepted and finished.
    fn land_on_event(
        &mut self,
        sys: &mut impl OdeSystem,
        h: f64,
        t_star: f64,
        adaptive: bool,
    ) -> Result<Option<f64>, SolveError> {
        let h_land = t_star - self.t;
        if adaptive {
            dense_eval(&self.dense, self.dim, self.t, h, t_star, &mut self.y_event);
        }
        let err = self.rk_step(sys, h_land, t_star)?;
        self.stats.steps += 1;
        if !err.is_finite() || self.y_new.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite {
                t: self.t,
                h: h_land,
            });
        }
        if adaptive {
            let mismatch = self.scaled_distance(&self.y_new, &self.y_event);
            if err > 1.0 || mismatch > DENSE_TRUST {
                self.stats.accepted -= 1;
                self.stats.rejected += 1;
                self.last_rejected = true;
                return Ok(Some(if err > 1.0 {
                    h_land * (0.9 * err.powf(-0.2)).clamp(0.1, 0.9)
                } else {
                    h_land
                }));
            }
        }
        self.finish_step(sys, h_land, t_star)?;
        Ok(None)
    }

    /// After an accepted step without an event: the step end's event values become the next
    /// step's start (re-evaluated when the projection moved the state); an event that started at
    /// zero stays so while it is still zero.
    fn carry_events(&mut self, events: &mut impl EventFunctions, projected: bool) {
        std::mem::swap(&mut self.g_prev, &mut self.g_new);
        if projected {
            events.eval_after_projection(self.t, &self.y, &mut self.g_prev);
        }
        for i in 0..self.zero_start.len() {
            self.zero_start[i] = self.zero_start[i] && self.g_prev[i].abs() <= EVENT_ZERO_TOL;
        }
    }

    /// Hands the step just finished (before its commit: `y` is its start, `y_new` its end) to
    /// `on_step`, with its dense output completed first where `wants_dense` asks for it.
    fn emit(
        &mut self,
        sys: &mut impl OdeSystem,
        (wants_dense, on_step): (
            &mut impl FnMut(&StepEnds) -> bool,
            &mut impl FnMut(&StepEnds, Option<&DenseStep>),
        ),
        h: f64,
        t1: f64,
    ) -> Result<(), SolveError> {
        let wanted = wants_dense(&self.step_ends(t1));
        if wanted {
            self.complete_dense(sys)?;
        }
        let view = DenseStep {
            t0: self.t,
            t1,
            h,
            dim: self.dim,
            coef: &self.dense,
        };
        on_step(&self.step_ends(t1), wanted.then_some(&view));
        Ok(())
    }

    /// The step just finished, from its start to `t1` (before its commit).
    fn step_ends(&self, t1: f64) -> StepEnds<'_> {
        StepEnds {
            t0: self.t,
            t1,
            y0: &self.y,
            y1: &self.y_new,
        }
    }

    /// Accepts `y_new` at `t1`, with the FSAL stage as the new derivative.
    /// Lets the system project the committed state; invalidates f(t, y) when it moved.
    fn project(&mut self, sys: &mut impl OdeSystem) -> Result<bool, SolveError> {
        let t = self.t;
        let moved = sys
            .project(t, &mut self.y)
            .map_err(|source| SolveError::Rhs { t, source })?;
        if moved {
            if self.y.iter().any(|v| !v.is_finite()) {
                return Err(SolveError::NonFinite { t, h: 0.0 });
            }
            self.f_valid = false;
        }
        Ok(moved)
    }

    fn commit(&mut self, t1: f64) {
        let fsal = match self.method {
            Method::Dop853 => DOP853_FSAL,
            Method::Dopri5 => DOPRI5_FSAL,
            Method::Rk4 { .. } => 4,
        };
        let d = self.dim;
        copy_short(&mut self.f, &self.k[fsal * d..(fsal + 1) * d]);
        std::mem::swap(&mut self.y, &mut self.y_new);
        self.t = t1;
        self.f_valid = true;
        // The stages of the step are gone with its start: its dense output can no longer be
        // completed (nothing reads it after the commit).
        self.dense_pending = None;
    }

    /// RMS of `a − b` in units of the tolerance `atol + rtol·max(|a|, |b|)`, the norm of the
    /// error control.
    fn scaled_distance(&self, a: &[f64], b: &[f64]) -> f64 {
        if a.is_empty() {
            return 0.0;
        }
        let (rtol, atol) = (self.opts.rtol, self.opts.atol);
        let sum: f64 = a
            .iter()
            .zip(b)
            .map(|(&x, &y)| ((x - y) / (atol + rtol * x.abs().max(y.abs()))).powi(2))
            .sum();
        (sum / a.len() as f64).sqrt()
    }
}
