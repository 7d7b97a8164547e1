//! Cross-checks of crr against rapier, an independent rigid-body engine with contacts and
//! friction between the bodies' real shapes (no pivots, no rocking coordinates, no impact law),
//! and against published closed forms. Never a dependency of crr.

pub mod closed_forms;
pub mod pieces;
pub mod report;
pub mod run;
pub mod scene;
