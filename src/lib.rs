//! # crr — coupled rocking rotations
//!
//! A Rust engine for the dynamics of rigid-block structures (free-standing blocks, columns of
//! drums, trilithons and colonnades, four-hinged arches, walls) under earthquakes, after the
//! theory of coupled rocking rotations (CRR).
//!
//! This facade re-exports the engine's crates and reads model files:
//! - [`kinematics`] (crate `crr-kinematics`): the model, rotation operators Γ, γ, Jacobians,
//!   M(q), U(q), loop closures Φ(q).
//! - [`model_file`]: TOML/JSON model files with errors naming the file, item and problem.
//! - [`inspect`]: the report of `crr inspect`.
//! - [`simulate`]: `crr simulate` (history, impacts and summary files, `docs/outputs.md`).
//! - [`check`]: `crr check` (mobility, activation multiplier, equivalent block, frequencies).
//! - [`synthetic`]: the reproducible synthetic accelerogram `examples/records/synthetic.AT2`.
//! - [`levels`]: energy levels of any one-DOF mechanism from the engine's M(θ) and U(θ).
//! - [`size_sweep`]: `crr check --size-sweep`, the frequencies of geometrically scaled models.
//! - [`plot`]: PNG and SVG plots of the results (`crr plot`, `--plot`).
//! - [`study`]: `crr study` (many cases of one model in parallel: maps, fragility studies).
//! - [`poincare`]: `crr poincare`, Poincaré sections under harmonic ground motion, bifurcation
//!   diagrams and basins (`docs/poincare.md`); [`poincare_plot`] draws them.
//! - [`animate`]: `crr animate`, the motion as a ParaView series and an animated GIF
//!   (`docs/animation.md`).
//! - [`fuzzing`]: the entry points of the fuzz targets in `fuzz/` and of their corpus replay.

pub use crr_dynamics as dynamics;
pub use crr_impact as impact;
pub use crr_kinematics as kinematics;

pub mod animate;
pub mod check;
pub mod folder_lock;
pub mod fuzzing;
pub mod inspect;
pub mod levels;
pub mod model_file;
pub mod plot;
pub mod poincare;
pub mod poincare_plot;
pub mod simulate;
pub mod size_sweep;
pub mod static_multiplier;
pub mod study;
pub mod synthetic;

pub use model_file::{InputError, load_model};
