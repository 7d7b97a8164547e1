//! Reading a model file (TOML written by people, or JSON) into a validated model, with errors that
//! name the file, the item and the problem.

use std::path::{Path, PathBuf};

use crr_kinematics::{Model, ModelError, StructureSpec};

/// Any failure to read or understand an input file.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The file could not be read.
    #[error("{file}: cannot read the file: {source}")]
    Io {
        /// The path as given.
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
    /// A value given on the command line is not valid for this model.
    #[error("{0}")]
    Argument(String),
}

/// Parses the text of a model file; JSON when the file name ends in `.json`, TOML otherwise.
pub fn parse_structure(path: &Path, text: &str) -> Result<StructureSpec, InputError> {
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let parsed = if is_json {
        serde_json::from_str(text).map_err(|e| e.to_string())
    } else {
        toml::from_str(text).map_err(|e| e.to_string().trim_end().to_string())
    };
    parsed.map_err(|message| InputError::Parse {
        file: path.to_path_buf(),
        message,
    })
}

/// Reads, parses and validates a model file.
pub fn load_model(path: &Path) -> Result<(StructureSpec, Model), InputError> {
    let text = std::fs::read_to_string(path).map_err(|source| InputError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    let spec = parse_structure(path, &text)?;
    let model = Model::from_spec(&spec).map_err(|source| InputError::Model {
        file: path.to_path_buf(),
        source,
    })?;
    Ok((spec, model))
}
