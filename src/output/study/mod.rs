//! `crr study`'s folder: the cases of a study run in parallel, their rows streamed to
//! `cases.csv`, resumed after an interruption, split into shards and merged ([`folder`]); the
//! products of a finished folder, spectra and fragility tables ([`products`]).

pub mod folder;
pub mod info;
pub mod products;

pub use folder::{
    Shard, StudyOptions, StudyOutcome, case_rows, case_rows_cancellable, cases_csv, merge,
    run_study,
};
pub use info::{MergedStudyInfo, StudyInfo};
