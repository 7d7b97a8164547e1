//! The input layer: model files (TOML or JSON) read into validated models, the blocks of
//! Wavefront OBJ files for assemblies, and the reproducible
//! synthetic record. Everything here reads; nothing runs an analysis or writes a result.

pub mod model_file;
pub mod obj;
pub mod synthetic;
