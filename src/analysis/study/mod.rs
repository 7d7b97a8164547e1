//! Studies: many runs of one model as one job, an overturning map over a pulse family's
//! amplitude × frequency grid, or a set of records scaled to intensity levels (fragility)
//! (`docs/studies.md`). This is what a study computes; running it into a folder (parallel,
//! resumable, sharded) and its products are [`crate::output::study`]'s.
//!
//! - [`spec`]: the study file;
//! - [`cases`]: the study expanded into cases with stable ids;
//! - [`measures`]: one case run to its measures;
//! - [`fragility`]: lognormal fragility functions fitted by maximum likelihood;
//! - [`zhang_makris`]: the analytic minimum overturning amplitude of a block under one-sine and
//!   one-cosine pulses (the boundary of an overturning map).

pub mod cases;
pub mod fragility;
pub mod measures;
pub mod spec;
pub mod zhang_makris;

pub use cases::{Case, IntensityMeasure, Motion, Study};
pub use measures::{CaseFailure, Measures, run_case, run_case_cancellable};
pub use spec::StudySpec;
