//! Entry points of the fuzz targets (`fuzz/`, run with `cargo +nightly fuzz run TARGET`) and of
//! the regression test that replays their corpus (`tests/cli/fuzz_corpus.rs`). Each takes arbitrary
//! bytes and must return without panicking: bad input is an error value, never a crash.

use std::path::Path;

use crr_dynamics::ground_motion::{RecordFormat, TableOptions, Units, parse_at2, parse_table};
use crr_kinematics::Model;

use crate::input::model_file::parse_model_file;

/// The bytes as text, invalid UTF-8 replaced (the readers get text).
fn text(data: &[u8]) -> String {
    String::from_utf8_lossy(data).into_owned()
}

/// A model file as TOML and as JSON; a model that builds is inspected and its mobility
/// evaluated at rest and after a finite step.
pub fn model_file(data: &[u8]) {
    let text = text(data);
    for name in ["fuzz.toml", "fuzz.json"] {
        let Ok(file) = parse_model_file(Path::new(name), &text) else {
            continue;
        };
        let Ok(model) = Model::from_spec(&file.structure()) else {
            continue;
        };
        let q = nalgebra::DVector::zeros(model.dof());
        let _ = crate::analysis::inspect::inspect(&model, &q);
        let _ = crate::analysis::check::check(&model);
        // What `crr simulate` checks before it runs: the ground motion, the initial state (the
        // continuation from rest on closed chains) and every analysis setting's bounds.
        if let Ok(input) = crate::ModelInput::from_file(Path::new(name), file) {
            let _ = crate::analysis::simulation::prepare(&input, &crate::RunOptions::default());
        }
    }
}

/// An accelerogram as `.AT2`, CSV and text table.
pub fn records(data: &[u8]) {
    let text = text(data);
    let _ = parse_at2(&text, "fuzz.AT2");
    for format in [RecordFormat::Csv, RecordFormat::Text] {
        let _ = parse_table(
            &text,
            "fuzz",
            &TableOptions::new(format, Units::MetersPerSecondSquared),
        );
    }
}

/// A results folder: the input split at the first two NUL bytes into summary.json, history.csv
/// and impacts.csv.
pub fn results(data: &[u8]) {
    let mut parts = data.splitn(3, |b| *b == 0).map(text);
    let (summary, history, impacts) = (
        parts.next().unwrap_or_default(),
        parts.next().unwrap_or_default(),
        parts.next().unwrap_or_default(),
    );
    let _ = crate::output::plot::parse_results(
        Path::new("fuzz"),
        &summary,
        std::io::Cursor::new(history.as_bytes()),
        &impacts,
    );
}
