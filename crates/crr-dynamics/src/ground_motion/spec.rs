//! Serde description of a ground motion, as written under `[ground_motion]` in a
//! model file (TOML or JSON).
//!
//! Every table rejects unknown keys (`deny_unknown_fields`). Numbers are SI:
//! accelerations in m/s², times in s, frequencies in Hz, angles in rad.
//! See `docs/ground-motion.md` for the user-facing description.

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// Standard gravity g₀ = 9.80665 m/s², used **only** to convert record values given
/// in units of g (PEER `.AT2` files, `units = "g"`) to m/s². It is independent of
/// the gravity used by the model.
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// One of the three world axes (z is up).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// Horizontal x axis.
    X,
    /// Horizontal y axis.
    Y,
    /// Vertical z axis (up).
    Z,
}

impl Axis {
    /// The three axes in order x, y, z.
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// Index of the axis in a 3-vector (x → 0, y → 1, z → 2).
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }

    /// Lower-case name: `"x"`, `"y"` or `"z"`.
    pub fn name(self) -> &'static str {
        match self {
            Axis::X => "x",
            Axis::Y => "y",
            Axis::Z => "z",
        }
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Axis {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "x" => Ok(Axis::X),
            "y" => Ok(Axis::Y),
            "z" => Ok(Axis::Z),
            other => Err(format!("unknown component `{other}` (expected x, y or z)")),
        }
    }
}

/// The `[ground_motion]` table: one optional [`ComponentSpec`] per world axis.
/// An absent component is identically zero.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundMotionSpec {
    /// Ground acceleration along x (horizontal), m/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<ComponentSpec>,
    /// Ground acceleration along y (horizontal), m/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<ComponentSpec>,
    /// Ground acceleration along z (vertical, up), m/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<ComponentSpec>,
}

impl GroundMotionSpec {
    /// The specification of one component, if given.
    pub fn component(&self, axis: Axis) -> Option<&ComponentSpec> {
        match axis {
            Axis::X => self.x.as_ref(),
            Axis::Y => self.y.as_ref(),
            Axis::Z => self.z.as_ref(),
        }
    }
}

/// One component of the ground acceleration: exactly one signal plus a scale factor.
///
/// In TOML the signal is a key of the component table, next to `scale`:
/// `x = { sine = { amplitude = 2.0, period = 0.5 }, scale = 1.5 }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawComponentSpec", into = "RawComponentSpec")]
pub struct ComponentSpec {
    /// The signal (its values in m/s² before scaling).
    pub signal: SignalSpec,
    /// Dimensionless factor multiplying the signal (default 1). Must be finite.
    pub scale: f64,
}

impl ComponentSpec {
    /// A component with scale 1.
    pub fn new(signal: SignalSpec) -> Self {
        ComponentSpec { signal, scale: 1.0 }
    }
}

/// A ground-acceleration signal (externally tagged: `sine = { ... }`, `record = { ... }`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SignalSpec {
    /// Harmonic acceleration, possibly limited to a number of cycles.
    Sine(SineSpec),
    /// One full sine cycle `A sin(2π(t − start)/T)` on `[start, start + T]`.
    OneSinePulse(PulseSpec),
    /// One full cosine cycle `A cos(2π(t − start)/T)` on `[start, start + T]`.
    OneCosinePulse(PulseSpec),
    /// Ricker wavelet (Mexican hat).
    Ricker(RickerSpec),
    /// Constant acceleration on `[start, start + duration]`.
    RectangularPulse(RectangularPulseSpec),
    /// Constant acceleration at all times.
    Constant(ConstantSpec),
    /// Recorded accelerogram read from a file, linearly interpolated.
    Record(RecordSpec),
}

impl SignalSpec {
    /// The key of the signal in the model file (`"sine"`, `"record"`, ...).
    pub fn key(&self) -> &'static str {
        match self {
            SignalSpec::Sine(_) => "sine",
            SignalSpec::OneSinePulse(_) => "one_sine_pulse",
            SignalSpec::OneCosinePulse(_) => "one_cosine_pulse",
            SignalSpec::Ricker(_) => "ricker",
            SignalSpec::RectangularPulse(_) => "rectangular_pulse",
            SignalSpec::Constant(_) => "constant",
            SignalSpec::Record(_) => "record",
        }
    }
}

/// `sine = { amplitude, period | frequency, phase, cycles, start }`:
/// `a(t) = amplitude · sin(2π (t − start)/T + phase)` for
/// `start ≤ t ≤ start + cycles·T`, and 0 otherwise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SineSpec {
    /// Amplitude A, m/s² (finite; may be negative).
    pub amplitude: f64,
    /// Period T, s (> 0). Give exactly one of `period` and `frequency`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
    /// Frequency f = 1/T, Hz (> 0). Give exactly one of `period` and `frequency`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency: Option<f64>,
    /// Phase φ, rad (default 0).
    #[serde(default)]
    pub phase: f64,
    /// Number of periods (> 0, may be fractional); absent = the sine never stops.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cycles: Option<f64>,
    /// Start time, s (default 0). The signal is 0 before it.
    #[serde(default)]
    pub start: f64,
}

/// `one_sine_pulse` / `one_cosine_pulse = { amplitude, period, start }`: one full cycle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PulseSpec {
    /// Amplitude A, m/s² (finite; may be negative).
    pub amplitude: f64,
    /// Period T (= pulse duration), s (> 0).
    pub period: f64,
    /// Start time, s (default 0).
    #[serde(default)]
    pub start: f64,
}

/// `ricker = { amplitude, frequency, center }`:
/// `a(t) = A (1 − 2π²f²(t − c)²) exp(−π²f²(t − c)²)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RickerSpec {
    /// Peak value A (reached at `t = center`), m/s² (finite; may be negative).
    pub amplitude: f64,
    /// Peak (central) frequency f, Hz (> 0).
    pub frequency: f64,
    /// Time c of the peak, s.
    pub center: f64,
}

/// `rectangular_pulse = { amplitude, duration, start }`: `a(t) = A` on
/// `[start, start + duration]`, 0 otherwise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RectangularPulseSpec {
    /// Value A during the pulse, m/s² (finite; may be negative).
    pub amplitude: f64,
    /// Duration d, s (> 0).
    pub duration: f64,
    /// Start time, s (default 0).
    #[serde(default)]
    pub start: f64,
}

/// `constant = { value }`: `a(t) = value` at all times.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantSpec {
    /// Constant acceleration, m/s² (finite).
    pub value: f64,
}

/// `record = { file, format, units, time_column, accel_column, skip_rows }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordSpec {
    /// Path of the file; a relative path is resolved against the folder of the model file.
    pub file: PathBuf,
    /// File format: `"peer-at2"`, `"csv"` or `"text"`.
    pub format: RecordFormat,
    /// Units of the acceleration column: `"g"`, `"m/s2"` or `"cm/s2"`. Required for
    /// `csv` and `text`; for `peer-at2` the values are in g and only `"g"` (or nothing)
    /// is accepted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<Units>,
    /// 0-based column of the time, s (csv/text only; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_column: Option<usize>,
    /// 0-based column of the acceleration (csv/text only; default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accel_column: Option<usize>,
    /// Number of lines skipped at the top of the file before parsing (csv/text only; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skip_rows: Option<usize>,
}

/// Accepted accelerogram file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum RecordFormat {
    /// PEER NGA `.AT2`: text header with `NPTS` and `DT`, then `NPTS` values in g.
    #[serde(rename = "peer-at2", alias = "at2")]
    PeerAt2,
    /// Comma-separated time/acceleration table (optional header row, `#` comments).
    #[serde(rename = "csv")]
    Csv,
    /// Whitespace-separated time/acceleration table (optional header row, `#` comments).
    #[serde(rename = "text", alias = "txt")]
    Text,
}

impl RecordFormat {
    /// Name as written in a model file.
    pub fn name(self) -> &'static str {
        match self {
            RecordFormat::PeerAt2 => "peer-at2",
            RecordFormat::Csv => "csv",
            RecordFormat::Text => "text",
        }
    }
}

impl fmt::Display for RecordFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RecordFormat {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "peer-at2" | "at2" => Ok(RecordFormat::PeerAt2),
            "csv" => Ok(RecordFormat::Csv),
            "text" | "txt" => Ok(RecordFormat::Text),
            other => Err(format!(
                "unknown record format `{other}` (expected peer-at2, csv or text)"
            )),
        }
    }
}

/// Units of recorded accelerations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Units {
    /// Multiples of standard gravity [`STANDARD_GRAVITY`] = 9.80665 m/s².
    #[serde(rename = "g")]
    G,
    /// m/s².
    #[serde(rename = "m/s2", alias = "m/s^2")]
    MetersPerSecondSquared,
    /// cm/s² (gal); divided by 100.
    #[serde(rename = "cm/s2", alias = "cm/s^2", alias = "gal")]
    CentimetersPerSecondSquared,
}

impl Units {
    /// Converts a value in these units to m/s² (`g`: × 9.80665, `cm/s2`: / 100).
    pub fn to_si(self, value: f64) -> f64 {
        match self {
            Units::G => value * STANDARD_GRAVITY,
            Units::MetersPerSecondSquared => value,
            Units::CentimetersPerSecondSquared => value / 100.0,
        }
    }

    /// Name as written in a model file.
    pub fn name(self) -> &'static str {
        match self {
            Units::G => "g",
            Units::MetersPerSecondSquared => "m/s2",
            Units::CentimetersPerSecondSquared => "cm/s2",
        }
    }
}

impl fmt::Display for Units {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Units {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "g" => Ok(Units::G),
            "m/s2" | "m/s^2" => Ok(Units::MetersPerSecondSquared),
            "cm/s2" | "cm/s^2" | "gal" => Ok(Units::CentimetersPerSecondSquared),
            other => Err(format!(
                "unknown units `{other}` (expected g, m/s2 or cm/s2)"
            )),
        }
    }
}

/// Wire form of [`ComponentSpec`]: every signal key optional, validated on conversion.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawComponentSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    sine: Option<SineSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    one_sine_pulse: Option<PulseSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    one_cosine_pulse: Option<PulseSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    ricker: Option<RickerSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    rectangular_pulse: Option<RectangularPulseSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    constant: Option<ConstantSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    record: Option<RecordSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    scale: Option<f64>,
}

const SIGNAL_KEYS: &str =
    "sine, one_sine_pulse, one_cosine_pulse, ricker, rectangular_pulse, constant or record";

impl TryFrom<RawComponentSpec> for ComponentSpec {
    type Error = String;
    fn try_from(raw: RawComponentSpec) -> Result<Self, Self::Error> {
        let mut signals: Vec<SignalSpec> = Vec::new();
        signals.extend(raw.sine.map(SignalSpec::Sine));
        signals.extend(raw.one_sine_pulse.map(SignalSpec::OneSinePulse));
        signals.extend(raw.one_cosine_pulse.map(SignalSpec::OneCosinePulse));
        signals.extend(raw.ricker.map(SignalSpec::Ricker));
        signals.extend(raw.rectangular_pulse.map(SignalSpec::RectangularPulse));
        signals.extend(raw.constant.map(SignalSpec::Constant));
        signals.extend(raw.record.map(SignalSpec::Record));
        if signals.len() > 1 {
            let keys: Vec<&str> = signals.iter().map(SignalSpec::key).collect();
            return Err(format!(
                "a ground-motion component takes exactly one signal, found {}: {}",
                signals.len(),
                keys.join(", ")
            ));
        }
        match signals.pop() {
            Some(signal) => Ok(ComponentSpec {
                signal,
                scale: raw.scale.unwrap_or(1.0),
            }),
            None => Err(format!(
                "a ground-motion component needs one signal ({SIGNAL_KEYS}), found none"
            )),
        }
    }
}

impl From<ComponentSpec> for RawComponentSpec {
    fn from(spec: ComponentSpec) -> Self {
        let mut raw = RawComponentSpec {
            scale: (spec.scale != 1.0).then_some(spec.scale),
            ..RawComponentSpec::default()
        };
        match spec.signal {
            SignalSpec::Sine(s) => raw.sine = Some(s),
            SignalSpec::OneSinePulse(s) => raw.one_sine_pulse = Some(s),
            SignalSpec::OneCosinePulse(s) => raw.one_cosine_pulse = Some(s),
            SignalSpec::Ricker(s) => raw.ricker = Some(s),
            SignalSpec::RectangularPulse(s) => raw.rectangular_pulse = Some(s),
            SignalSpec::Constant(s) => raw.constant = Some(s),
            SignalSpec::Record(s) => raw.record = Some(s),
        }
        raw
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn component_spec_requires_exactly_one_signal() {
        let none = ComponentSpec::try_from(RawComponentSpec::default()).unwrap_err();
        assert!(none.contains("found none"), "{none}");
        let two = ComponentSpec::try_from(RawComponentSpec {
            sine: Some(SineSpec {
                amplitude: 1.0,
                period: Some(1.0),
                frequency: None,
                phase: 0.0,
                cycles: None,
                start: 0.0,
            }),
            constant: Some(ConstantSpec { value: 1.0 }),
            ..RawComponentSpec::default()
        })
        .unwrap_err();
        assert!(two.contains("found 2: sine, constant"), "{two}");
    }

    #[test]
    fn component_spec_round_trips_through_the_wire_form() {
        let spec = ComponentSpec {
            signal: SignalSpec::Constant(ConstantSpec { value: 2.0 }),
            scale: 1.5,
        };
        let raw = RawComponentSpec::from(spec.clone());
        assert_eq!(raw.scale, Some(1.5));
        assert_eq!(ComponentSpec::try_from(raw), Ok(spec));
        // Scale 1 is omitted on output and restored as the default on input.
        let unit = ComponentSpec::new(SignalSpec::Constant(ConstantSpec { value: 2.0 }));
        let raw = RawComponentSpec::from(unit.clone());
        assert_eq!(raw.scale, None);
        assert_eq!(ComponentSpec::try_from(raw), Ok(unit));
    }
}
