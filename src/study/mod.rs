//! `crr study`: many runs of one model as one job: an overturning map over a pulse family's
//! amplitude × frequency grid, or a set of records scaled to intensity levels (fragility).
//! Cases run in parallel, stream their rows to `cases.csv`, resume after an interruption and
//! split into shards for a cluster (`docs/studies.md`).
//!
//! - [`spec`]: the study file;
//! - [`cases`]: the study expanded into cases with stable ids;
//! - [`run`]: running the cases, resuming, sharding, merging;
//! - [`fragility`]: lognormal fragility functions fitted by maximum likelihood;
//! - [`zhang_makris`]: the analytic minimum overturning amplitude of a block under one-sine and
//!   one-cosine pulses (the boundary of an overturning map).

pub mod cases;
pub mod fragility;
pub mod products;
pub mod run;
pub mod spec;
pub mod zhang_makris;

pub use cases::{Case, Motion, Study};
pub use run::{Shard, StudyOptions, StudyOutcome, case_rows, cases_csv, merge, run_study};
pub use spec::StudySpec;
