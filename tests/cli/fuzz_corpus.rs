//! Replays the fuzz corpus (`fuzz/corpus/<target>/`: the seeds and every input a fuzzing run
//! found to crash, once fixed) through the fuzz targets' entry points: each must return, never
//! panic. The fuzzing itself runs with `cargo +nightly fuzz run <target>` (see fuzz/README.md).

use std::path::Path;

fn replay(target: &str, run: fn(&[u8])) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "{}: empty corpus", dir.display());
    for f in &files {
        let data = std::fs::read(f).unwrap();
        let outcome = std::panic::catch_unwind(|| run(&data));
        assert!(outcome.is_ok(), "{}: panicked", f.display());
    }
    eprintln!("{target}: {} inputs replayed", files.len());
}

#[test]
fn model_file_corpus() {
    replay("model_file", crr::fuzzing::model_file);
}

#[test]
fn records_corpus() {
    replay("records", crr::fuzzing::records);
}

#[test]
fn results_corpus() {
    replay("results", crr::fuzzing::results);
}
