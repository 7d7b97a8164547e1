//! Where `crr simulate` writes: the default folder is `results/<sanitised model name>` (a name can
//! never lead outside `results/`), an earlier run is never overwritten without `--force`, and a
//! forced run replaces the earlier set whole (no stale plots beside new data).

use crate::common;

use std::path::{Path, PathBuf};

use crate::common::{crr_in, scratch};

/// The bundled single block renamed, written into `dir`, run for 1 s.
fn model_named(dir: &Path, name: &str) -> PathBuf {
    let text = common::bundled_text("single_block").replacen(
        "name = \"single_block\"",
        &format!("name = {}", toml_string(name)),
        1,
    );
    let path = dir.join("model.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn toml_string(s: &str) -> String {
    format!(
        "\"{}\"",
        s.replace('\\', "\\\\")
            .replace('"', "\\\"")
            .replace('\n', "\\n")
    )
}

/// Every file below `dir`, relative to it.
fn files_below(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

#[test]
fn model_names_never_lead_outside_results() {
    for (name, folder) in [
        ("../../escaped", "___.._escaped"),
        ("..", "__"),
        (".", "_"),
        ("/tmp/absolute", "_tmp_absolute"),
        ("a,b\nc", "a_b_c"),
        ("", "model"),
        ("temple front-1.2", "temple_front-1.2"),
    ] {
        let work = scratch(&format!("outputs_names_{}", folder.replace('.', "d")));
        let cwd = work.join("cwd");
        std::fs::create_dir_all(&cwd).unwrap();
        let model = model_named(&work, name);
        let o = crr_in(
            &cwd,
            &[
                "simulate",
                model.to_str().unwrap(),
                "--quiet",
                "--duration",
                "1",
            ],
        );
        assert!(
            o.status.success(),
            "{name:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let written = files_below(&cwd);
        let expected: Vec<PathBuf> = [
            "history.csv",
            "hops.csv",
            "impacts.csv",
            "openings.csv",
            "summary.json",
        ]
        .iter()
        .map(|f| Path::new("results").join(folder).join(f))
        .collect();
        assert_eq!(written, expected, "{name:?}");
        // Nothing beside the working folder either.
        let mut around = files_below(&work);
        around.retain(|p| !p.starts_with("cwd"));
        assert_eq!(around, vec![PathBuf::from("model.toml")], "{name:?}");
    }
}

#[test]
fn an_earlier_run_is_replaced_only_with_force_and_whole() {
    let work = scratch("outputs_force");
    let model = model_named(&work, "single_block");
    let out = work.join("out");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "simulate",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        crr_in(&work, &args)
    };
    // First run with plots.
    let o = run(&["--quiet", "--duration", "2", "--plot"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("phase.png").exists());
    let first = std::fs::read_to_string(out.join("summary.json")).unwrap();
    // Again without --force: refused, exit 2, the folder named, nothing touched.
    let o = run(&["--quiet", "--duration", "1"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(out.to_str().unwrap()) && err.contains("--force"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("summary.json")).unwrap(),
        first
    );
    assert!(out.join("phase.png").exists());
    // With --force and no plots: the new data, and no plot of the earlier run left beside it.
    let o = run(&["--quiet", "--duration", "1", "--force"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["end_time"], 1.0);
    assert_eq!(
        files_below(&out),
        [
            "history.csv",
            "hops.csv",
            "impacts.csv",
            "openings.csv",
            "summary.json",
        ]
        .iter()
        .map(PathBuf::from)
        .collect::<Vec<_>>()
    );
    // A folder with other files but no results is written to without --force.
    let other = work.join("other");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("notes.txt"), "mine").unwrap();
    let o = crr_in(
        &work,
        &[
            "simulate",
            model.to_str().unwrap(),
            "--out",
            other.to_str().unwrap(),
            "--quiet",
        ],
    );
    assert!(o.status.success());
    assert_eq!(
        std::fs::read_to_string(other.join("notes.txt")).unwrap(),
        "mine"
    );
}
