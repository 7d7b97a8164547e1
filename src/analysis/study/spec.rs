//! The study file (TOML, `docs/studies.md`): the model, the ground motions (a pulse family over an
//! amplitude × period grid, or a set of records scaled to intensity levels) and the run's
//! duration. Unknown keys are errors, as in the model file.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crr_dynamics::ground_motion::{RecordFormat, Units};

use crate::Error;

/// A list of values: explicit (`[0.1, 0.2]`) or evenly spaced (`{ from, to, count }`, both ends
/// included).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged, try_from = "RawValues")]
pub enum Values {
    /// The values as given.
    List(Vec<f64>),
    /// `count` values from `from` to `to` (one value: `from`).
    Range {
        /// First value.
        from: f64,
        /// Last value.
        to: f64,
        /// Number of values (≥ 1).
        count: usize,
    },
}

/// [`Values`] as written, with any number as the count, so that a count that is not a whole
/// number ≥ 1 gets its own error instead of serde's "did not match any variant".
#[derive(Deserialize)]
#[serde(
    untagged,
    expecting = "expected a list of numbers [a, b, …] or a range { from = a, to = b, count = n }"
)]
enum RawValues {
    List(Vec<f64>),
    Range { from: f64, to: f64, count: f64 },
}

impl TryFrom<RawValues> for Values {
    type Error = String;

    fn try_from(raw: RawValues) -> Result<Self, String> {
        match raw {
            RawValues::List(v) => Ok(Values::List(v)),
            RawValues::Range { from, to, count } => {
                if !(count >= 1.0 && count.fract() == 0.0 && count <= usize::MAX as f64) {
                    return Err(format!(
                        "count must be a whole number ≥ 1 in {{ from, to, count }}, got {count}"
                    ));
                }
                Ok(Values::Range {
                    from,
                    to,
                    count: count as usize,
                })
            }
        }
    }
}

/// The most values one axis of a study takes (`{ from, to, count }`): refused above it before
/// anything is allocated.
pub const MAX_AXIS_VALUES: usize = 100_000;

impl Values {
    /// The values, or an error naming `what` when a value is not finite or the list is empty.
    pub fn expand(&self, what: &str) -> Result<Vec<f64>, String> {
        let v = match self {
            Values::List(v) => v.clone(),
            Values::Range { from, to, count } => {
                if *count == 0 {
                    return Err(format!("{what}: count must be at least 1"));
                }
                if *count > MAX_AXIS_VALUES {
                    return Err(format!(
                        "{what}: count must be at most {MAX_AXIS_VALUES}, got {count} (the values \
                         of one axis of a study)"
                    ));
                }
                if *count == 1 {
                    vec![*from]
                } else {
                    (0..*count)
                        .map(|k| from + (to - from) * k as f64 / (*count - 1) as f64)
                        .collect()
                }
            }
        };
        if v.is_empty() {
            return Err(format!("{what}: no values"));
        }
        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
            return Err(format!("{what}: {x} is not a finite number"));
        }
        Ok(v)
    }
}

/// The pulse shapes of a pulse family.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PulseKind {
    /// One full sine cycle a_p sin(ω_p t) on [0, T_p].
    OneSinePulse,
    /// One full cosine cycle a_p cos(ω_p t) on [0, T_p].
    OneCosinePulse,
    /// Ricker wavelet of peak a_p and peak frequency f_p = ω_p/(2π), centred at 1/f_p.
    Ricker,
}

/// `[pulses]`: a pulse family over an amplitude × frequency grid. Amplitudes are given in m/s²
/// (`amplitudes`) or as a_p/(g tan α) (`amplitude_ratios`, with g tan α = λg the model's
/// activation acceleration); the pulse's frequency as a period T_p in s (`periods`) or as ω_p/p
/// (`frequency_ratios`, p the model's frequency parameter p_eq).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PulsesSpec {
    /// Pulse shape.
    pub kind: PulseKind,
    /// a_p in m/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitudes: Option<Values>,
    /// a_p/(g tan α) (dimensionless).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude_ratios: Option<Values>,
    /// T_p = 2π/ω_p in s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub periods: Option<Values>,
    /// ω_p/p (dimensionless).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency_ratios: Option<Values>,
}

/// `[records]`: accelerograms, given as files and/or a folder (every file of the folder with the
/// extension `extension`, in name order).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordsSpec {
    /// Record files (relative to the study file's folder).
    #[serde(default)]
    pub files: Vec<PathBuf>,
    /// A folder of records (relative to the study file's folder).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub folder: Option<PathBuf>,
    /// Extension of the folder's record files (default `AT2`, any case).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extension: Option<String>,
    /// Synthetic records generated by seed (`crate::input::synthetic`), after the files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub synthetic: Option<SyntheticSpec>,
    /// File format: `peer-at2`, `csv` or `text` (needed when files or a folder are given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<RecordFormat>,
    /// Units of csv/text records (`g`, `m/s2`, `cm/s2`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<Units>,
}

/// `[records] synthetic = { seeds = … }`: synthetic accelerograms of `crate::input::synthetic` (20 s,
/// band-limited, enveloped, PGA 0.25 g), one per seed (whole numbers ≥ 0).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SyntheticSpec {
    /// The seeds of the white noise.
    pub seeds: Values,
}

/// `[intensity]`: the levels each record is scaled to; exactly one key.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntensitySpec {
    /// Factors on the record's accelerations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factors: Option<Values>,
    /// Target peak ground acceleration, in g.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pga: Option<Values>,
    /// Target peak ground velocity, in m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pgv: Option<Values>,
    /// Target 5 %-damped pseudo-spectral acceleration Sa(T₁), in g.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sa: Option<SpectralSpec>,
}

/// `sa = { period, damping, levels }`: levels of the pseudo-spectral acceleration
/// Sa(T₁) = ω²max|u| of a linear oscillator of period T₁ and damping ratio ζ (default 0.05).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpectralSpec {
    /// T₁, s (> 0).
    pub period: f64,
    /// ζ (default 0.05, 0 ≤ ζ < 1).
    #[serde(default = "default_damping")]
    pub damping: f64,
    /// Sa(T₁) levels, in g.
    pub levels: Values,
}

fn default_damping() -> f64 {
    0.05
}

/// The whole study file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// Name (default: the file's stem).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The model file (relative to the study file's folder). Its own ground motion is replaced by
    /// the study's; its initial state and `[analysis]` are kept.
    pub model: PathBuf,
    /// The horizontal component driven: `x` (default) or `y`.
    #[serde(default = "default_component")]
    pub component: String,
    /// Replaces the impact law of every interface of the model (as the model file's `impact`
    /// key: `"momentum"`, `{ restitution = r }`, `{ dirac = { r, c } }`, …).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub impact: Option<crr_kinematics::ImpactLaw>,
    /// Replaces the model's `[analysis] hop_tolerance` (m): a pull at a pivot just after an
    /// impact whose motion released departs from crr's by no more than this is not a
    /// violation (docs/simulation.md, "Hops").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hop_tolerance: Option<f64>,
    /// Replaces the model's `[analysis] stop_at_violation`: every case ends at its first
    /// failure of the rigid-contact hypotheses instead of running on outside the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop_at_violation: Option<bool>,
    /// Where every case starts: `"rest"` (default; maps and fragility studies start at rest) or
    /// `"model"` (the model file's `[initial]` state).
    #[serde(default)]
    pub start: Start,
    /// Simulated time of every case, s (default: the motion's duration + 5 s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration: Option<f64>,
    /// A pulse family (or `records`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pulses: Option<PulsesSpec>,
    /// Records (or `pulses`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub records: Option<RecordsSpec>,
    /// Geometric scale factors of the model (every length × s, densities kept): every motion
    /// runs on the model scaled by each factor (default: the model as given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scales: Option<Values>,
    /// Intensity levels of the records (default: factor 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intensity: Option<IntensitySpec>,
}

/// The initial state of the cases.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Start {
    /// At rest (q = 0, q̇ = 0, every joint seated).
    #[default]
    Rest,
    /// The model file's `[initial]` table.
    Model,
}

fn default_component() -> String {
    "x".into()
}

impl StudySpec {
    /// Reads and parses a study file; errors name the file and, for TOML errors, the key.
    pub fn read(path: &Path) -> Result<Self, Error> {
        // A regular file of at most 16 MiB: a FIFO or /dev/zero given as the study is refused
        // at once instead of blocking or filling the memory.
        let text =
            crr_dynamics::input::read_regular_text(path, crr_dynamics::input::MODEL_FILE_LIMIT)
                .map_err(|source| Error::Io {
                    file: path.to_path_buf(),
                    source,
                })?;
        Self::parse(path, &text)
    }

    /// Parses the TOML text of a study file; `path` names it in the errors.
    pub fn parse(path: &Path, text: &str) -> Result<Self, Error> {
        toml::from_str(text).map_err(|e| Error::Parse {
            file: path.to_path_buf(),
            message: e.to_string(),
        })
    }
}
