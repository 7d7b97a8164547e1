//! `study.json`: what a study folder holds, typed ([`StudyInfo`] for a run, [`MergedStudyInfo`]
//! for `crr study merge`), documented in `docs/studies.md`. Written with sorted keys
//! ([`to_json`]), as the file always was.

use serde::{Deserialize, Serialize};

use crate::analysis::study::StudySpec;

/// `study.json` of a run (or of one shard).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyInfo {
    /// The study file as read.
    pub study: StudySpec,
    /// Its path as given.
    pub study_file: String,
    /// The study's name.
    pub name: String,
    /// The version of crr that ran it.
    pub crr_version: String,
    /// The study's fingerprint (`study.fingerprint`): a resume must match it.
    pub fingerprint: String,
    /// The model's name.
    pub model: String,
    /// Cases of the whole study.
    pub cases_in_study: usize,
    /// This folder's part, `i/n`.
    pub shard: String,
    /// Cases of this part.
    pub cases_in_shard: usize,
    /// Cases found done and skipped.
    pub cases_skipped: usize,
    /// Cases run now.
    pub cases_run: usize,
    /// Cases whose row holds an error.
    pub cases_failed: usize,
    /// Cases whose run left crr's model (a hypotheses violation, in the row's `violation_*`
    /// columns).
    #[serde(default)]
    pub cases_outside_model: usize,
    /// What to know before trusting the results, found before any case ran
    /// ([`crate::analysis::study::Study::warnings`]: a `duration` that cuts motions short).
    #[serde(default)]
    pub warnings: Vec<String>,
    /// Worker threads.
    pub threads: usize,
    /// Wall-clock time of the run (s).
    pub wall_time_s: f64,
    /// Static multiplier λ of the model's one-DOF mechanism.
    pub lambda: Option<f64>,
    /// Frequency parameter p of its equivalent block (rad/s).
    pub p_eq_rad_s: Option<f64>,
    /// Slenderness α of its equivalent block (rad).
    pub alpha_eq_rad: Option<f64>,
    /// Per scale of the model: its size, height and mechanism.
    pub scales: Vec<ScaleInfo>,
}

/// One scale of a study's model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScaleInfo {
    /// Factor on the lengths.
    pub scale: f64,
    /// Height of the scaled structure (m).
    pub height_m: Option<f64>,
    /// Its static multiplier λ.
    pub lambda: Option<f64>,
    /// Its p (rad/s).
    pub p_eq_rad_s: Option<f64>,
}

/// `study.json` of a folder merged from shards: what the shards' files say, echoed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MergedStudyInfo {
    /// The study file as the shards read it.
    pub study: Option<serde_json::Value>,
    /// The study's name.
    pub name: Option<serde_json::Value>,
    /// Slenderness α of the equivalent block (rad).
    pub alpha_eq_rad: Option<serde_json::Value>,
    /// The study's fingerprint.
    pub fingerprint: Option<serde_json::Value>,
    /// The shard folders, as given.
    pub merged_from: Vec<String>,
    /// Cases in the merged `cases.csv`.
    pub cases: usize,
    /// Of them, those whose run left crr's model (a hypotheses violation).
    #[serde(default)]
    pub cases_outside_model: usize,
    /// The study's warnings found before its cases ran, as the shards' `study.json` give them
    /// (one study: the first shard's).
    #[serde(default)]
    pub warnings: Vec<String>,
    /// The version of crr that merged them.
    pub crr_version: String,
}

/// The text of a JSON file: pretty-printed, keys in alphabetical order, a final newline.
pub fn to_json<T: Serialize>(value: &T) -> String {
    let value = serde_json::to_value(value).expect("plain data serialises");
    serde_json::to_string_pretty(&value).expect("a JSON value prints") + "\n"
}
