//! The output layer: results folders and their files. The folder convention (temporary names,
//! replacing an earlier run whole, one writer at a time), the CSV and JSON files, plots and
//! animations. It calls the analysis layer; nothing below calls it.

pub mod animate;
pub mod assemble;
pub mod folder_lock;
pub mod history;
pub mod plot;
pub mod poincare;
pub mod poincare_plot;
pub mod replace_file;
pub mod results_folder;
pub mod simulate;
pub mod study;
pub mod text_lines;
