//! # crr — coupled rocking rotations
//!
//! A Rust engine for the dynamics of rigid-block structures (free-standing blocks, columns of
//! drums, trilithons and colonnades, four-hinged arches, walls) under earthquakes, after the
//! theory of coupled rocking rotations (CRR).
//!
//! One call runs a simulation: [`run`] takes a model (a file, or one already read) and
//! [`RunOptions`], and returns a [`Run`] (the history, the impacts and a typed [`Summary`]); every
//! failure is one [`Error`]. `docs/embedding.md` shows it in a program. [`prelude`] imports what
//! an embedding needs.
//!
//! The crate is layered, each layer calling only the ones below it:
//! - [`input`]: model files with errors naming the file, item and problem; synthetic records.
//! - [`analysis`]: simulation, the `crr check` report and static multiplier, energy levels, size
//!   sweeps, Poincaré sections, studies; all in memory.
//! - [`output`]: results folders (CSV, JSON, plots, animations) and the folder convention.
//! - the command line `crr` (`src/bin/crr/`), one file per command, over the three.
//!
//! Below them are the engine's crates, re-exported: [`kinematics`] (`crr-kinematics`: the model,
//! rotation operators Γ, γ, Jacobians, M(q), U(q), loop closures Φ(q)), [`dynamics`]
//! (`crr-dynamics`: equations of motion, ground motion, integrators) and [`impact`]
//! (`crr-impact`: impact laws, the event-driven simulation, contact statics).
//! [`fuzzing`] holds the entry points of the fuzz targets in `fuzz/` and of their corpus replay.

pub use crr_dynamics as dynamics;
pub use crr_impact as impact;
pub use crr_kinematics as kinematics;

pub mod analysis;
pub mod error;
pub mod fuzzing;
pub mod input;
pub mod output;

pub use analysis::simulation::{
    Cancel, RecordFile, RecordSamples, Run, RunOptions, run, run_streaming,
};
pub use analysis::summary::Summary;
pub use error::{Error, PlotError};
pub use input::model_file::load_model;
pub use input::model_file::{ModelFile, ModelInput};

/// What a program embedding crr needs: `use crr::prelude::*;`.
pub mod prelude {
    pub use crate::dynamics::ground_motion::{Axis, Record, RecordFormat, Units};
    pub use crate::{
        Cancel, Error, ModelFile, ModelInput, RecordFile, RecordSamples, Run, RunOptions, Summary,
        run, run_streaming,
    };
}

// The examples of docs/embedding.md are compiled and run as doc tests.
#[cfg(doctest)]
#[doc = include_str!("../docs/embedding.md")]
struct EmbeddingDoc;
