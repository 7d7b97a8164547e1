//! Ground motion: the ground acceleration `a_g(t) = (a_x, a_y, a_z)` in m/s² (world z up).
//!
//! The engine uses it as an effective gravity `(−a_x, −a_y, −g − a_z)`.
//!
//! * [`GroundMotionSpec`] is the serde description found under `[ground_motion]` in a
//!   model file: per component one signal (`sine`, `one_sine_pulse`, `one_cosine_pulse`,
//!   `ricker`, `rectangular_pulse`, `constant`, `record`) and an optional `scale`.
//! * [`GroundMotion`] is the built, validated motion used at run time: acceleration,
//!   exact ground velocity, breakpoints for the integrator, duration, PGA.
//! * [`read_at2`], [`read_table`] and [`read_record`] read accelerograms into a [`Record`].
//!
//! The user documentation is `docs/ground-motion.md` at the workspace root.

mod analytic;
pub mod record;
pub mod spec;

use std::path::Path;

use nalgebra::Vector3;

use analytic::Signal;
pub use record::{
    Record, TableOptions, parse_at2, parse_fortran_float, parse_table, read_at2, read_record,
    read_table,
};
pub use spec::{
    Axis, ComponentSpec, ConstantSpec, GroundMotionSpec, PulseSpec, RecordFormat, RecordSpec,
    RectangularPulseSpec, RickerSpec, STANDARD_GRAVITY, SignalSpec, SineSpec, Units,
};

/// Errors when building a ground motion or reading a record.
///
/// Messages name the model-file location (`ground_motion.x.sine`) or the file (path as
/// given, after joining with the base directory) and the 1-based line number.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GroundMotionError {
    /// A parameter of the specification is invalid, e.g.
    /// `ground_motion.x.sine: period must be positive, got 0`.
    #[error("{context}: {message}")]
    InvalidSpec {
        /// Where in the model file, e.g. `ground_motion.x.sine`.
        context: String,
        /// What is wrong.
        message: String,
    },
    /// The file could not be read.
    #[error("{path}: cannot read file: {error}")]
    Io {
        /// The file.
        path: String,
        /// The underlying I/O error.
        error: std::io::Error,
    },
    /// A problem at a given line of a record file.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong (e.g. the offending token).
        message: String,
    },
    /// A problem with a record file as a whole (no header, too few samples, ...).
    #[error("{path}: {message}")]
    Format {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// Invalid data given to [`Record::uniform`] / [`Record::from_samples`].
    #[error("invalid record: {message}")]
    InvalidRecord {
        /// What is wrong.
        message: String,
    },
    /// An error while building one component (adds the model-file location).
    #[error("{context}: {error}")]
    InComponent {
        /// Where in the model file, e.g. `ground_motion.y.record`.
        context: String,
        /// The underlying error.
        error: Box<GroundMotionError>,
    },
}

/// Side of a one-sided limit, for [`GroundMotion::acceleration_limit`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    /// Limit from the left, `lim_{τ↑t} a(τ)`: the value on a step that ends at `t`.
    Before,
    /// Limit from the right, `lim_{τ↓t} a(τ)`: the value on a step that starts at `t`.
    After,
}

#[derive(Debug, Clone, PartialEq)]
struct Component {
    signal: Signal,
    scale: f64,
    /// `signal.primitive(0)`, so that `velocity(t) = scale (F(t) − F(0))`.
    primitive_at_zero: f64,
}

impl Component {
    fn new(signal: Signal, scale: f64) -> Self {
        let primitive_at_zero = signal.primitive(0.0);
        Component {
            signal,
            scale,
            primitive_at_zero,
        }
    }
}

/// A built ground motion: three optional components (absent = 0), scale applied.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GroundMotion {
    components: [Option<Component>; 3],
}

fn spec_error(context: &str, message: String) -> GroundMotionError {
    GroundMotionError::InvalidSpec {
        context: context.to_string(),
        message,
    }
}

fn finite(context: &str, field: &str, value: f64) -> Result<f64, GroundMotionError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(spec_error(
            context,
            format!("{field} must be finite, got {value}"),
        ))
    }
}

/// Largest peak ground acceleration a component may have, m/s² (about 1e5 g, five orders
/// above the strongest records): finite accelerations beyond it overflow the forces they drive
/// (a constant 1e308 m/s² made every generalized force infinite, and the uplift test, comparing
/// NaN, left the block at rest).
pub const MAX_GROUND_ACCELERATION: f64 = 1e6;

/// The component `signal` × `scale`, refused where its peak is not finite or beyond
/// [`MAX_GROUND_ACCELERATION`].
fn bounded(context: &str, signal: Signal, scale: f64) -> Result<Component, GroundMotionError> {
    let peak = scale.abs() * signal.peak();
    if peak.is_nan() || peak > MAX_GROUND_ACCELERATION {
        return Err(spec_error(
            context,
            format!(
                "its peak acceleration |scale| × peak = {peak:e} m/s² is beyond any ground motion \
                 (at most {MAX_GROUND_ACCELERATION:e} m/s², about 1e5 g)"
            ),
        ));
    }
    Ok(Component::new(signal, scale))
}

fn positive(context: &str, field: &str, value: f64) -> Result<f64, GroundMotionError> {
    let value = finite(context, field, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(spec_error(
            context,
            format!("{field} must be positive, got {value}"),
        ))
    }
}

fn build_signal(
    spec: &SignalSpec,
    context: &str,
    base_dir: &Path,
) -> Result<Signal, GroundMotionError> {
    Ok(match spec {
        SignalSpec::Sine(s) => {
            let amplitude = finite(context, "amplitude", s.amplitude)?;
            let period = match (s.period, s.frequency) {
                (Some(p), None) => positive(context, "period", p)?,
                (None, Some(f)) => 1.0 / positive(context, "frequency", f)?,
                (Some(_), Some(_)) => {
                    return Err(spec_error(
                        context,
                        "give either period or frequency, not both".to_string(),
                    ));
                }
                (None, None) => {
                    return Err(spec_error(
                        context,
                        "period (s) or frequency (Hz) is required".to_string(),
                    ));
                }
            };
            let phase = finite(context, "phase", s.phase)?;
            let start = finite(context, "start", s.start)?;
            let end = match s.cycles {
                Some(c) => Some(start + positive(context, "cycles", c)? * period),
                None => None,
            };
            if let Some(e) = end
                && !e.is_finite()
            {
                return Err(spec_error(
                    context,
                    format!("start + cycles·period overflows ({e})"),
                ));
            }
            Signal::Sine {
                amplitude,
                period,
                phase,
                start,
                end,
            }
        }
        SignalSpec::OneSinePulse(p) | SignalSpec::OneCosinePulse(p) => {
            let amplitude = finite(context, "amplitude", p.amplitude)?;
            let period = positive(context, "period", p.period)?;
            let start = finite(context, "start", p.start)?;
            finite(context, "start + period", start + period)?;
            if matches!(spec, SignalSpec::OneSinePulse(_)) {
                Signal::Sine {
                    amplitude,
                    period,
                    phase: 0.0,
                    start,
                    end: Some(start + period),
                }
            } else {
                Signal::CosinePulse {
                    amplitude,
                    period,
                    start,
                }
            }
        }
        SignalSpec::Ricker(r) => Signal::Ricker {
            amplitude: finite(context, "amplitude", r.amplitude)?,
            frequency: positive(context, "frequency", r.frequency)?,
            center: finite(context, "center", r.center)?,
        },
        SignalSpec::RectangularPulse(r) => {
            let amplitude = finite(context, "amplitude", r.amplitude)?;
            let duration = positive(context, "duration", r.duration)?;
            let start = finite(context, "start", r.start)?;
            finite(context, "start + duration", start + duration)?;
            Signal::Rectangular {
                amplitude,
                start,
                duration,
            }
        }
        SignalSpec::Constant(c) => Signal::Constant {
            value: finite(context, "value", c.value)?,
        },
        SignalSpec::Record(r) => Signal::Record(load_record(r, base_dir)?),
    })
}

fn load_record(spec: &RecordSpec, base_dir: &Path) -> Result<Record, GroundMotionError> {
    let path = if spec.file.is_absolute() {
        spec.file.clone()
    } else {
        base_dir.join(&spec.file)
    };
    let source = path.display().to_string();
    match spec.format {
        RecordFormat::PeerAt2 => {
            record::check_at2_units(&source, spec.units)?;
            let given: Vec<&str> = [
                spec.time_column.map(|_| "time_column"),
                spec.accel_column.map(|_| "accel_column"),
                spec.skip_rows.map(|_| "skip_rows"),
            ]
            .into_iter()
            .flatten()
            .collect();
            if !given.is_empty() {
                return Err(GroundMotionError::Format {
                    path: source,
                    message: format!("{} only apply to csv/text records", given.join(", ")),
                });
            }
            read_at2(&path)
        }
        RecordFormat::Csv | RecordFormat::Text => {
            let units = spec.units.ok_or_else(|| GroundMotionError::Format {
                path: source.clone(),
                message: format!(
                    "units are required for {} records (g, m/s2 or cm/s2)",
                    spec.format
                ),
            })?;
            let mut options = TableOptions::new(spec.format, units);
            options.time_column = spec.time_column.unwrap_or(0);
            options.accel_column = spec.accel_column.unwrap_or(1);
            options.skip_rows = spec.skip_rows.unwrap_or(0);
            read_table(&path, &options)
        }
    }
}

impl GroundMotion {
    /// No ground motion: all components 0.
    pub fn none() -> Self {
        GroundMotion::default()
    }

    /// The shortest time over which any component changes shape (the smallest period of its
    /// sines and pulses, 1/f of its Ricker wavelets); `None` when every component is constant or
    /// affine between breakpoints. A test of the motion on a time grid must sample finer than
    /// this: a 1 ms grid under a 500 Hz sine samples only its zeros.
    pub fn time_scale(&self) -> Option<f64> {
        self.components
            .iter()
            .flatten()
            .filter_map(|c| c.signal.time_scale())
            .reduce(f64::min)
    }

    /// True if no component is set.
    pub fn is_none(&self) -> bool {
        self.components.iter().all(Option::is_none)
    }

    /// Builds the motion described by `spec`; record files with relative paths are read
    /// relative to `base_dir` (the folder of the model file).
    pub fn from_spec(spec: &GroundMotionSpec, base_dir: &Path) -> Result<Self, GroundMotionError> {
        let mut motion = GroundMotion::none();
        for axis in Axis::ALL {
            if let Some(c) = spec.component(axis) {
                motion = motion.with_component(axis, c, base_dir)?;
            }
        }
        Ok(motion)
    }

    /// Sets (replaces) one component from its specification.
    pub fn with_component(
        mut self,
        axis: Axis,
        spec: &ComponentSpec,
        base_dir: &Path,
    ) -> Result<Self, GroundMotionError> {
        let component_ctx = format!("ground_motion.{axis}");
        let scale = finite(&component_ctx, "scale", spec.scale)?;
        let context = format!("{component_ctx}.{}", spec.signal.key());
        let signal = build_signal(&spec.signal, &context, base_dir).map_err(|e| match e {
            e @ GroundMotionError::InvalidSpec { .. } => e,
            other => GroundMotionError::InComponent {
                context: context.clone(),
                error: Box::new(other),
            },
        })?;
        self.components[axis.index()] = Some(bounded(&component_ctx, signal, scale)?);
        Ok(self)
    }

    /// A motion with a single recorded component (e.g. from the command line
    /// `--record FILE --format … --units … --component x --scale S`).
    pub fn from_record(axis: Axis, record: Record, scale: f64) -> Result<Self, GroundMotionError> {
        GroundMotion::none().with_record(axis, record, scale)
    }

    /// Sets (replaces) one component by a record times `scale` (finite).
    pub fn with_record(
        mut self,
        axis: Axis,
        record: Record,
        scale: f64,
    ) -> Result<Self, GroundMotionError> {
        let context = format!("ground_motion.{axis}");
        finite(&context, "scale", scale)?;
        self.components[axis.index()] = Some(bounded(&context, Signal::Record(record), scale)?);
        Ok(self)
    }

    /// The record driving a component, if that component is a record.
    pub fn record(&self, axis: Axis) -> Option<&Record> {
        match &self.components[axis.index()] {
            Some(Component {
                signal: Signal::Record(r),
                ..
            }) => Some(r),
            _ => None,
        }
    }

    fn map(&self, f: impl Fn(&Component) -> f64) -> Vector3<f64> {
        Vector3::from_fn(|i, _| self.components[i].as_ref().map_or(0.0, &f))
    }

    /// Ground acceleration at `t`, m/s², scale applied. Windows are closed: at a pulse's
    /// start and end, and at a record's first and last sample, the in-window value is
    /// returned. Use [`acceleration_limit`](Self::acceleration_limit) for one-sided limits.
    pub fn acceleration(&self, t: f64) -> Vector3<f64> {
        self.map(|c| c.scale * c.signal.value(t, None))
    }

    /// One-sided limit of the ground acceleration at `t` (m/s²): `Side::Before` for a
    /// step ending at `t`, `Side::After` for a step starting at `t`. Equal to
    /// [`acceleration`](Self::acceleration) except at jumps.
    pub fn acceleration_limit(&self, t: f64, side: Side) -> Vector3<f64> {
        self.map(|c| c.scale * c.signal.value(t, Some(side)))
    }

    /// Ground velocity `∫_0^t a_g dτ`, m/s (negative integral for `t < 0`), exact for
    /// the closed-form signals and the piecewise-linear records.
    pub fn velocity(&self, t: f64) -> Vector3<f64> {
        self.map(|c| c.scale * (c.signal.primitive(t) - c.primitive_at_zero))
    }

    /// The first time strictly greater than `t` at which some component has a kink or a
    /// jump: record sample times, pulse and sine starts/ends. `None` if there is none.
    /// O(log n) for records.
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        self.components
            .iter()
            .flatten()
            .filter_map(|c| c.signal.next_breakpoint(t))
            .reduce(f64::min)
    }

    /// True if every component is affine in t on [t0, t1] (an interval inside which
    /// [`Self::next_breakpoint`] finds no breakpoint): then a quantity linear in the ground
    /// acceleration that is positive at t1 and crossed 0 inside the interval stays positive up to
    /// t1, so testing the interval's end detects it.
    pub fn is_affine_on(&self, t0: f64, t1: f64) -> bool {
        self.components
            .iter()
            .flatten()
            .all(|c| c.signal.is_affine_on(t0, t1))
    }

    /// Time (≥ 0) after which every component is 0 forever: the end of the last record or
    /// pulse; `f64::INFINITY` for an endless sine or a constant. A Ricker wavelet counts
    /// as over at `center + 3/frequency` (beyond it `|a| < 1e-35·|A|`). 0 for no motion.
    pub fn duration(&self) -> f64 {
        self.components
            .iter()
            .flatten()
            .map(|c| c.signal.end_time())
            .fold(0.0, f64::max)
    }

    /// The warnings of the records read (e.g. extra values ignored), each prefixed with its
    /// component.
    pub fn record_warnings(&self) -> Vec<String> {
        Axis::ALL
            .iter()
            .filter_map(|&axis| match &self.components[axis.index()] {
                Some(Component {
                    signal: Signal::Record(r),
                    ..
                }) => Some((axis, r)),
                _ => None,
            })
            .flat_map(|(axis, r)| {
                r.warnings()
                    .iter()
                    .map(move |w| format!("ground motion {}: {w}", axis.name()))
            })
            .collect()
    }

    /// The shortest sample interval of the records (s), or None without a uniformly sampled
    /// record.
    pub fn record_sample_interval(&self) -> Option<f64> {
        self.components
            .iter()
            .flatten()
            .filter_map(|c| match &c.signal {
                Signal::Record(r) => r.dt(),
                _ => None,
            })
            .reduce(f64::min)
    }

    /// Peak ground acceleration per component, m/s² (|scale| applied): exact for the
    /// analytic signals, the largest |sample| for records.
    pub fn pga(&self) -> Vector3<f64> {
        self.map(|c| c.scale.abs() * c.signal.peak())
    }
}

#[cfg(test)]
mod tests;
