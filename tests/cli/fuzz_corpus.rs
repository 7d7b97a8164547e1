//! Replays the fuzz corpus (`fuzz/corpus/<target>/`: the seeds and every input a fuzzing run
//! found to crash, once fixed) through the fuzz targets' entry points: each must return, never
//! panic. The fuzzing itself runs with `cargo +nightly fuzz run <target>` (see fuzz/README.md).
//! The model files also go through `crr simulate`, where an input is refused with an error that
//! names its file, or runs.

use std::path::{Path, PathBuf};

/// The inputs of the corpus of fuzz target `target`, in name order (never empty).
fn corpus(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "{}: empty corpus", dir.display());
    files
}

fn replay(target: &str, run: fn(&[u8])) {
    let files = corpus(target);
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

/// Every model file of the corpus through `crr simulate` for 0.05 s, as a user would meet it:
/// it runs (exit 0, with a summary that ends by 0.05 s), stops (exit 1, with the partial results
/// and one error) or is refused (exit 2, nothing written); an error is one `crr: error:` line that
/// starts with the file's path, never a panic (exit 101) or a signal.
#[test]
fn model_file_corpus_through_the_command_line() {
    let (mut ran, mut refused) = (0, 0);
    for (k, file) in corpus("model_file").iter().enumerate() {
        let out = crate::common::scratch(&format!("fuzz_cli_{k}"));
        let o = crate::common::crr(&[
            "simulate",
            file.to_str().unwrap(),
            "--duration",
            "0.05",
            "--out",
            out.to_str().unwrap(),
            "--force",
            "--quiet",
        ]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        let errors: Vec<&str> = stderr
            .lines()
            .filter(|l| l.starts_with("crr: error:"))
            .collect();
        let named = |errors: &[&str]| {
            errors.len() == 1 && errors[0].starts_with(&format!("crr: error: {}: ", file.display()))
        };
        let summary = || -> serde_json::Value {
            let text = std::fs::read_to_string(out.join("summary.json"))
                .unwrap_or_else(|e| panic!("{}: no summary ({e})", file.display()));
            serde_json::from_str(&text).unwrap()
        };
        match o.status.code() {
            Some(0) => {
                assert!(errors.is_empty(), "{}: {stderr}", file.display());
                let s = summary();
                assert_eq!(s["completed"], true, "{}", file.display());
                let end = s["end_time"].as_f64().unwrap();
                assert!(
                    end > 0.0 && end <= 0.05 + 1e-12,
                    "{}: end {end}",
                    file.display()
                );
                ran += 1;
            }
            Some(1) => {
                assert!(named(&errors), "{}: {stderr}", file.display());
                assert_eq!(summary()["completed"], false, "{}", file.display());
            }
            Some(2) => {
                assert!(named(&errors), "{}: {stderr}", file.display());
                assert!(
                    !out.join("summary.json").exists(),
                    "{}: refused, yet results were written",
                    file.display()
                );
                refused += 1;
            }
            other => panic!("{}: exit {other:?}: {stderr}", file.display()),
        }
    }
    eprintln!("model_file corpus: {ran} ran, {refused} refused");
    assert!(ran >= 10 && refused >= 5, "{ran} ran, {refused} refused");
}
