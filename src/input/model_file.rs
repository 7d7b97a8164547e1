//! Reading a model file (TOML written by people, or JSON) into a validated model, with errors that
//! name the file, the item and the problem.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crr_dynamics::ground_motion::GroundMotionSpec;
use crr_dynamics::{AnalysisSpec, InitialSpec};
use crr_kinematics::spec::{BodySpec, DEFAULT_GRAVITY, InterfaceSpec, SymmetrySpec};
use crr_kinematics::{Model, StructureSpec};

use crate::Error;

fn default_gravity() -> f64 {
    DEFAULT_GRAVITY
}

/// A whole model file: the structure (`name`, `gravity`, `[[body]]`, `[[interface]]`, documented in
/// `docs/model-format.md`) and the optional `[ground_motion]` (`docs/ground-motion.md`),
/// `[initial]` and `[analysis]` tables.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// Name of the structure.
    pub name: String,
    /// g (m/s²), default 9.81.
    #[serde(default = "default_gravity")]
    pub gravity: f64,
    /// Bodies.
    #[serde(default)]
    pub body: Vec<BodySpec>,
    /// Interfaces.
    #[serde(default)]
    pub interface: Vec<InterfaceSpec>,
    /// User or symmetry constraints (DOF(3)).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub symmetry: Vec<SymmetrySpec>,
    /// Ground motion, per component.
    #[serde(default)]
    pub ground_motion: Option<GroundMotionSpec>,
    /// Initial angles and rates by coordinate name.
    #[serde(default)]
    pub initial: Option<InitialSpec>,
    /// Duration, output interval, integrator settings.
    #[serde(default)]
    pub analysis: Option<AnalysisSpec>,
    /// Blocks from Wavefront OBJ files (assemblies only: `crr assemble` turns them into bodies).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obj: Vec<crate::input::obj::ObjSpec>,
    /// The blocks that are part of the ground (assemblies only): abutments, foundations, the
    /// rock of a stepped site, by name. `crr assemble` makes the faces on them ground contacts
    /// and leaves them out of the model.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed: Vec<String>,
}

impl ModelFile {
    /// The structure part.
    pub fn structure(&self) -> StructureSpec {
        StructureSpec {
            name: self.name.clone(),
            gravity: self.gravity,
            body: self.body.clone(),
            interface: self.interface.clone(),
            symmetry: self.symmetry.clone(),
        }
    }
}

/// Parses the text of a model file; JSON when the file name ends in `.json`, TOML otherwise.
pub fn parse_model_file(path: &Path, text: &str) -> Result<ModelFile, Error> {
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    parse_model_text(path, text, is_json)
}

/// Parses the text of a model (JSON when `is_json`, else TOML) that need not come from a file:
/// `label` names it in the errors as a file path would (e.g. `<string>` for a model given as
/// text by an embedding program).
pub fn parse_model_text(label: &Path, text: &str, is_json: bool) -> Result<ModelFile, Error> {
    let path = label;
    let parsed = if is_json {
        // With the key path of the error: a model given as a dict in Python has no lines to
        // point at (its JSON is one line).
        let mut de = serde_json::Deserializer::from_str(text);
        serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            if path == "." {
                inner.to_string()
            } else {
                format!("{path}: {inner}")
            }
        })
    } else {
        toml::from_str(text).map_err(|e| e.to_string().trim_end().to_string())
    };
    let file: ModelFile = parsed.map_err(|message| Error::Parse {
        file: path.to_path_buf(),
        message,
    })?;
    // The typed reading takes the first N values of a longer array and drops the rest: check
    // the lengths on the generic tree.
    let tree: Result<serde_json::Value, String> = if is_json {
        serde_json::from_str(text).map_err(|e| e.to_string())
    } else {
        toml::from_str(text).map_err(|e| e.to_string())
    };
    if let Ok(tree) = tree
        && let Some(message) = array_length_error(&tree, "")
    {
        return Err(Error::Parse {
            file: path.to_path_buf(),
            message,
        });
    }
    Ok(file)
}

/// Keys whose value is a point or vector (3 numbers), or a list of them.
const VECTOR_KEYS: [&str; 11] = [
    "center",
    "size",
    "rotation",
    "extrude",
    "axis",
    "start",
    "pivot_positive",
    "pivot_negative",
    "corners",
    "vertices",
    "polygon",
];

/// The first array of the wrong length in the model tree: a vector of `VECTOR_KEYS` must have
/// 3 numbers (a pivot may also be a segment of two points), a symmetry's `coordinates` 2 names.
/// The message gives the item's path (e.g. `body[0].box.size`).
fn array_length_error(v: &serde_json::Value, at: &str) -> Option<String> {
    use serde_json::Value;
    let is_vector = |x: &Value| x.as_array().is_some_and(|a| a.iter().all(Value::is_number));
    let bad = |what: &str, n: usize, expected: &str| {
        Some(format!("{what} has {n} values, {expected} expected"))
    };
    match v {
        Value::Object(map) => map.iter().find_map(|(k, x)| {
            let here = if at.is_empty() {
                k.clone()
            } else {
                format!("{at}.{k}")
            };
            let items = x.as_array();
            match (k.as_str(), items) {
                ("coordinates", Some(a)) if at.starts_with("symmetry") && a.len() != 2 => {
                    bad(&here, a.len(), "2")
                }
                // An empty list of points is left to the shape's or face's own check, which
                // says how many points it needs (it read as a vector of 0 values, "3 expected").
                ("corners" | "vertices" | "polygon", Some(a)) if a.is_empty() => None,
                (key, Some(a)) if VECTOR_KEYS.contains(&key) => {
                    if is_vector(x) {
                        (a.len() != 3).then(|| bad(&here, a.len(), "3")).flatten()
                    } else {
                        // A list of points (corners, a pivot segment): each of 3 numbers.
                        a.iter().enumerate().find_map(|(i, p)| match p.as_array() {
                            Some(pa) if pa.len() != 3 => {
                                bad(&format!("{here}[{i}]"), pa.len(), "3")
                            }
                            _ => None,
                        })
                    }
                }
                _ => array_length_error(x, &here),
            }
        }),
        Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, x)| array_length_error(x, &format!("{at}[{i}]"))),
        _ => None,
    }
}

/// Reads and parses a model file (TOML, or JSON when it ends in .json), without validating the
/// structure.
pub fn read_model_file(path: &Path) -> Result<ModelFile, Error> {
    let limit = crr_dynamics::input::MODEL_FILE_LIMIT;
    let text = crr_dynamics::input::read_regular_text(path, limit).map_err(|source| Error::Io {
        file: path.to_path_buf(),
        source,
    })?;
    parse_model_file(path, &text)
}

/// Reads, parses and validates a model file (the structure; the other tables are checked where
/// they are used).
pub fn load_model(path: &Path) -> Result<(ModelFile, Model), Error> {
    build_model(path, read_model_file(path)?)
}

/// Validates the structure of a parsed model file into a model; errors name `path` (the file,
/// or the label of a model given as text) and the item.
pub fn build_model(path: &Path, file: ModelFile) -> Result<(ModelFile, Model), Error> {
    if !file.obj.is_empty() {
        return Err(Error::Argument(format!(
            "{}: [[obj]] lists blocks of an assembly: turn it into a model with `crr assemble` \
             (docs/assembly.md)",
            path.display()
        )));
    }
    if !file.fixed.is_empty() {
        return Err(Error::Argument(format!(
            "{}: `fixed` names blocks of an assembly that are part of the ground: turn it into \
             a model with `crr assemble` (docs/assembly.md)",
            path.display()
        )));
    }
    let model = Model::from_spec(&file.structure()).map_err(|source| Error::Model {
        file: path.to_path_buf(),
        source,
    })?;
    Ok((file, model))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_model_given_as_text_reads_as_the_same_file_and_errors_name_its_label() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
        let text = std::fs::read_to_string(&path).unwrap();
        let (from_file, _) = load_model(&path).unwrap();
        let label = Path::new("<string>");
        let (from_text, model) =
            build_model(label, parse_model_text(label, &text, false).unwrap()).unwrap();
        assert_eq!(from_file, from_text);
        assert_eq!(model.dof(), 1);
        let json = serde_json::to_string(&from_file).unwrap();
        assert_eq!(parse_model_text(label, &json, true).unwrap(), from_file);
        let err = parse_model_text(label, "name = 1", false).unwrap_err();
        assert!(err.to_string().starts_with("<string>: "), "{err}");
    }
}

/// A model read and validated, ready to run: the file as read, the structure built from it, the
/// path its errors name and the folder its relative record files are found in.
#[derive(Clone, Debug)]
pub struct ModelInput {
    /// The path (or label) that names the model in errors and in `summary.json`.
    pub path: PathBuf,
    /// The folder relative record paths of `[ground_motion]` are resolved against.
    pub base_dir: PathBuf,
    /// The file as read.
    pub file: ModelFile,
    /// The validated structure.
    pub model: Model,
}

impl ModelInput {
    /// Reads and validates the model file at `path` (TOML, or JSON when it ends in `.json`).
    pub fn read(path: impl AsRef<Path>) -> Result<Self, Error> {
        let path = path.as_ref();
        let (file, model) = load_model(path)?;
        Ok(Self::with_folder(path, file, model))
    }

    /// A model given as text (JSON when `is_json`, else TOML), named `label` in errors; its
    /// relative record paths are found from `label`'s folder.
    pub fn parse(label: impl AsRef<Path>, text: &str, is_json: bool) -> Result<Self, Error> {
        let label = label.as_ref();
        let file = parse_model_text(label, text, is_json)?;
        Self::from_file(label, file)
    }

    /// A model file already in memory (built by a program), named `label` in errors.
    pub fn from_file(label: impl AsRef<Path>, file: ModelFile) -> Result<Self, Error> {
        let label = label.as_ref();
        let (file, model) = build_model(label, file)?;
        Ok(Self::with_folder(label, file, model))
    }

    fn with_folder(path: &Path, file: ModelFile, model: Model) -> Self {
        ModelInput {
            path: path.to_path_buf(),
            base_dir: path.parent().unwrap_or(Path::new(".")).to_path_buf(),
            file,
            model,
        }
    }
}
