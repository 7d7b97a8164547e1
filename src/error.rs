//! `crr::Error`: every failure of the library, from reading an input to writing a result, as
//! one enum whose messages name the file, the item and what is wrong.

use std::path::PathBuf;

use crr_kinematics::ModelError;

/// Any failure of a library call: an input that cannot be read or understood, a value that is
/// not valid for the model, results that cannot be written or drawn. A simulation that stops
/// part-way is not an error: its partial results come back with the reason (see [`crate::Run`]).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The file could not be read.
    #[error("{file}: cannot read the file: {source}")]
    Io {
        /// The path as given.
        file: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// A file that an input names (a model's record, say) could not be read: the input and the
    /// item that names it are given.
    #[error("{input}: {item}: {file}: cannot read file: {source}")]
    NamedFile {
        /// The input (model or study file) that names it.
        input: PathBuf,
        /// The item naming it, e.g. `ground_motion.x.record`.
        item: String,
        /// The file as named (joined with the input's folder).
        file: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// The text is not valid TOML/JSON or does not fit the model format (line and column given).
    #[error("{file}: {message}")]
    Parse {
        /// The path as given.
        file: PathBuf,
        /// The parser's message, with line and column.
        message: String,
    },
    /// The description is well-formed but not a valid structure.
    #[error("{file}: {source}")]
    Model {
        /// The path as given.
        file: PathBuf,
        /// Which item is wrong and why.
        source: ModelError,
    },
    /// The results could not be written.
    #[error("{dir}: cannot write the results: {source}")]
    Output {
        /// The output folder.
        dir: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// A value given (an option, an override) is not valid for this model.
    #[error("{0}")]
    Argument(String),
    /// Results could not be read back or drawn.
    #[error(transparent)]
    Plot(#[from] PlotError),
}

/// A failure to read the results or to draw a plot.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The results folder does not exist.
    #[error("{0}: no such results folder (run `crr simulate MODEL --out DIR` first)")]
    MissingDir(PathBuf),
    /// A results file is missing or cannot be understood.
    #[error("{file}: {message}")]
    Read {
        /// The file.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// `crr check --plot` on a model that is not a one-DOF mechanism.
    #[error("no frequency plot: {0}")]
    NoMechanism(String),
    /// `crr check --plot`: the energy levels of the mechanism cannot be followed.
    #[error("no energy levels: {0}")]
    NoLevels(String),
    /// An image could not be drawn or written.
    #[error("{file}: cannot draw the plot: {message}")]
    Draw {
        /// The image file.
        file: PathBuf,
        /// The backend's reason.
        message: String,
    },
}
