//! `crr study`: results that do not depend on how the work is split (threads, shards, an
//! interruption), failing cases as rows, intensity scaling, and clear errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use crate::common::{crr, scratch};

/// A 6 × 6 map of Housner's block under one-sine pulses (36 cases, 4 s each), written into `dir`.
fn small_map(dir: &Path) -> PathBuf {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models");
    let text = format!(
        "name = \"small_map\"\nmodel = \"{}\"\nduration = 4.0\n\n[pulses]\nkind = \"one_sine_pulse\"\n\
         amplitude_ratios = {{ from = 1.5, to = 6.0, count = 6 }}\n\
         frequency_ratios = {{ from = 1.0, to = 8.0, count = 6 }}\n",
        models.join("single_block.toml").display()
    );
    let path = dir.join("small_map.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn run_ok(args: &[&str]) -> String {
    let out = crr(args);
    assert!(
        out.status.success(),
        "crr {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

#[test]
fn threads_shards_and_merge_give_the_same_cases() {
    let dir = scratch("study_split");
    let study = small_map(&dir);
    let s = study.to_str().unwrap();
    let one = dir.join("one");
    let two = dir.join("two");
    run_ok(&[
        "study",
        s,
        "--jobs",
        "1",
        "--quiet",
        "--out",
        one.to_str().unwrap(),
    ]);
    run_ok(&[
        "study",
        s,
        "--jobs",
        "2",
        "--quiet",
        "--out",
        two.to_str().unwrap(),
    ]);
    let reference = read(&one.join("cases.csv"));
    assert_eq!(reference.lines().count(), 37, "header and 36 cases");
    assert_eq!(reference, read(&two.join("cases.csv")), "1 and 2 threads");
    // The block rocks or overturns in some cases and not in others: the map is not trivial.
    let collapsed = reference
        .lines()
        .skip(1)
        .filter(|l| l.contains(",ok,1,"))
        .count();
    assert!(
        collapsed > 0 && collapsed < 36,
        "{collapsed} of 36 collapsed"
    );
    let mut parts = Vec::new();
    for i in 1..=3 {
        let d = dir.join(format!("shard{i}"));
        run_ok(&[
            "study",
            s,
            "--shard",
            &format!("{i}/3"),
            "--jobs",
            "2",
            "--quiet",
            "--out",
            d.to_str().unwrap(),
        ]);
        assert_eq!(read(&d.join("cases.csv")).lines().count(), 13, "shard {i}");
        parts.push(d.to_str().unwrap().to_string());
    }
    let merged = dir.join("merged");
    let mut args = vec!["study", "merge"];
    args.extend(parts.iter().map(String::as_str));
    args.extend(["--out", merged.to_str().unwrap()]);
    run_ok(&args);
    assert_eq!(read(&merged.join("cases.csv")), reference, "merged shards");
}

#[test]
fn an_interrupted_run_resumes_without_losing_or_repeating_a_case() {
    let dir = scratch("study_resume");
    let study = small_map(&dir);
    let s = study.to_str().unwrap();
    let full = dir.join("full");
    run_ok(&["study", s, "--quiet", "--out", full.to_str().unwrap()]);
    let reference = read(&full.join("cases.csv"));
    // A run cut while writing: the header, 10 finished rows (not in id order, as threads finish
    // them) and half of an eleventh.
    let rows: Vec<&str> = reference.lines().collect();
    let cut = dir.join("cut");
    std::fs::create_dir_all(&cut).unwrap();
    let mut text = format!("{}\n", rows[0]);
    for k in [7, 3, 12, 1, 30, 2, 25, 9, 18, 36] {
        text += rows[k];
        text.push('\n');
    }
    text += &rows[20][..rows[20].len() / 2];
    std::fs::write(cut.join("cases.csv"), text).unwrap();
    // The cut run had written which study it computes before its first row.
    std::fs::copy(
        full.join("study.fingerprint"),
        cut.join("study.fingerprint"),
    )
    .unwrap();
    let said = run_ok(&["study", s, "--quiet", "--out", cut.to_str().unwrap()]);
    let _ = said;
    assert_eq!(read(&cut.join("cases.csv")), reference);
    let json: serde_json::Value = serde_json::from_str(&read(&cut.join("study.json"))).unwrap();
    assert_eq!(json["cases_skipped"], 10);
    assert_eq!(json["cases_run"], 26);

    // A real kill: stop a run after some rows are out, then resume into the same folder.
    let killed = dir.join("killed");
    let mut child = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(["study", s, "--jobs", "1", "--quiet", "--out"])
        .arg(&killed)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    for _ in 0..200 {
        let rows = std::fs::read_to_string(killed.join("cases.csv"))
            .map(|t| t.lines().count())
            .unwrap_or(0);
        if rows > 3 || child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let _ = child.kill();
    let _ = child.wait();
    run_ok(&["study", s, "--quiet", "--out", killed.to_str().unwrap()]);
    assert_eq!(read(&killed.join("cases.csv")), reference);
}

#[test]
fn records_scale_to_their_levels_and_a_bad_record_is_a_row() {
    let dir = scratch("study_records");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = format!(
        "model = \"{}\"\nduration = 6.0\n\n[records]\nfiles = [\"{}\", \"missing.AT2\"]\nformat = \"peer-at2\"\n\n\
         [intensity]\npga = [0.1, 0.3]\n",
        root.join("examples/models/single_block.toml").display(),
        root.join("examples/records/synthetic.AT2").display()
    );
    let study = dir.join("records.toml");
    std::fs::write(&study, text).unwrap();
    let out = dir.join("out");
    run_ok(&[
        "study",
        study.to_str().unwrap(),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let csv = read(&out.join("cases.csv"));
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 4);
    // The synthetic record's PGA is 0.25 g (examples/records/README.md): factors 0.4 and 1.2.
    let factor = |row: &str| -> f64 { row.split(',').nth(3).unwrap().parse().unwrap() };
    assert!((factor(rows[0]) - 0.1 / 0.25).abs() < 1e-9, "{}", rows[0]);
    assert!((factor(rows[1]) - 0.3 / 0.25).abs() < 1e-9, "{}", rows[1]);
    // At 0.1 g < tan α = 0.2 the block never uplifts; at 0.3 g it rocks.
    assert!(rows[0].contains(",ok,0,,0,0,0,"), "{}", rows[0]);
    assert!(rows[1].contains(",ok,"), "{}", rows[1]);
    for r in &rows[2..] {
        assert!(r.contains(",error,") && r.contains("missing.AT2"), "{r}");
    }
}

#[test]
fn bad_study_input_is_a_clear_error() {
    let dir = scratch("study_errors");
    let study = small_map(&dir);
    let s = study.to_str().unwrap();
    let out = crr(&["study", s, "--shard", "4/3"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--shard"));
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, read(&study).replace("kind =", "knid =")).unwrap();
    let out = crr(&["study", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.toml") && err.contains("knid"), "{err}");
    let both = dir.join("both.toml");
    std::fs::write(
        &both,
        read(&study) + "\n[records]\nfiles = [\"a.AT2\"]\nformat = \"peer-at2\"\n",
    )
    .unwrap();
    let out = crr(&["study", both.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("exactly one of [pulses] and [records]"));
}

/// The library's in-memory route (what the Python package and its Dask workers call): the study
/// given as text, its cases run in chunks, the rows joined in any order give the command line's
/// `cases.csv` byte for byte.
#[test]
fn case_rows_joined_in_any_order_equal_the_command_line_file() {
    use crr::analysis::study::{Study, StudySpec};
    use crr::output::study::{case_rows, cases_csv, folder::header};
    let dir = scratch("study_rows");
    let study_file = small_map(&dir);
    let out = dir.join("cli");
    run_ok(&[
        "study",
        study_file.to_str().unwrap(),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let text = read(&study_file);
    let study =
        Study::from_spec(StudySpec::parse(&study_file, &text).unwrap(), &study_file).unwrap();
    assert_eq!(study.cases.len(), 36);
    let cases: Vec<_> = study.cases.iter().collect();
    let mut rows = Vec::new();
    for chunk in cases.chunks(10).rev() {
        rows.extend(case_rows(&study, chunk, Some(1)).unwrap());
    }
    let joined = cases_csv(&header(&study), rows.iter().map(String::as_str));
    assert_eq!(joined, read(&out.join("cases.csv")));
    let err = case_rows(&study, &cases[..1], Some(0)).unwrap_err();
    assert_eq!(err.to_string(), "--jobs must be at least 1");
}

/// A study whose `duration` ends its cases before their records do says so before any case
/// runs (stderr, with `--quiet` too, and `study.json`): 1.5 × the bundled 20 s record overturns
/// the block at 6.93 s, and a study cut at 5 s wrote `collapse` 0. A `factors` study has one
/// `factor` column (its level is the factor applied; the header had `factor` twice), and its
/// failed cases are a warning with `--quiet` too.
#[test]
fn a_study_cut_short_warns_and_a_factors_study_has_one_factor_column() {
    let dir = scratch("study_cut_short");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let study = |name: &str, duration: &str| {
        let text = format!(
            "model = \"{}\"\n{duration}\n[records]\nfiles = [\"{}\", \"missing.AT2\"]\nformat = \"peer-at2\"\n\n\
             [intensity]\nfactors = [1.5]\n",
            root.join("examples/models/block_record.toml").display(),
            root.join("examples/records/synthetic.AT2").display()
        );
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        path
    };
    let run = |path: &Path, out: &str| {
        let out = dir.join(out);
        let o = crr(&[
            "study",
            path.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let json: serde_json::Value = serde_json::from_str(&read(&out.join("study.json"))).unwrap();
        (
            read(&out.join("cases.csv")),
            json,
            String::from_utf8_lossy(&o.stderr).to_string(),
        )
    };
    let (cut_csv, cut_json, cut_err) = run(&study("cut", "duration = 5.0\n"), "cut");
    let (full_csv, full_json, full_err) = run(&study("full", ""), "full");
    let warning = "duration = 5 s ends 1 of the 2 case(s) before their ground motion does (the \
                   latest ends at t = 20 s)";
    assert!(
        cut_err.contains(&format!("crr: warning: {}", dir.join("cut.toml").display())),
        "{cut_err}"
    );
    assert!(cut_err.contains(warning), "{cut_err}");
    assert_eq!(cut_json["warnings"].as_array().unwrap().len(), 1);
    assert!(
        cut_json["warnings"][0]
            .as_str()
            .unwrap()
            .starts_with(warning)
    );
    assert!(
        !full_err.contains("before their ground motion"),
        "{full_err}"
    );
    assert_eq!(full_json["warnings"].as_array().unwrap().len(), 0);
    // One factor column; the missing record's row keeps its level.
    for csv in [&cut_csv, &full_csv] {
        let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        assert_eq!(header[..4], ["id", "record", "factor", "status"]);
        let rows: Vec<Vec<&str>> = csv
            .lines()
            .skip(1)
            .map(|r| r.split(',').collect())
            .collect();
        assert_eq!(rows.len(), 2);
        assert!(rows.iter().all(|r| r[2] == "1.5"), "{csv}");
    }
    // Cut at 5 s the block stands; run to the record's end + 5 s it overturns after 5 s.
    let collapse = |csv: &str| -> (String, String) {
        let row: Vec<String> = csv
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .map(String::from)
            .collect();
        (row[3].clone(), row[4].clone()) // status, collapse
    };
    assert_eq!(collapse(&cut_csv), ("ok".into(), "0".into()));
    assert_eq!(collapse(&full_csv), ("ok".into(), "1".into()));
    let time: f64 = full_csv
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(5)
        .unwrap()
        .parse()
        .unwrap();
    assert!(time > 5.0 && time < 20.0, "{time}");
    // The missing record's case failed: said with --quiet.
    for err in [&cut_err, &full_err] {
        assert!(
            err.contains("crr: warning: 1 of the 2 case(s) of this part stopped with an error"),
            "{err}"
        );
    }
}

/// The bundled studies' durations cover their motions: no warning before they run.
#[test]
fn the_bundled_studies_cut_no_motion_short() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in ["housner_map", "block_spectrum", "drum_fragility"] {
        let study =
            crr::analysis::study::Study::load(&root.join(format!("examples/studies/{name}.toml")))
                .unwrap();
        assert!(study.warnings.is_empty(), "{name}: {:?}", study.warnings);
    }
}

/// The warnings found before a study's cases run stay with its folder through `crr study
/// merge`: two shards of the study cut at 5 s merge into a study.json that still says so.
#[test]
fn a_merged_study_keeps_its_warnings() {
    let dir = scratch("study_merge_warnings");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = format!(
        "model = \"{}\"\nduration = 5.0\n[records]\nfiles = [\"{}\"]\nformat = \"peer-at2\"\n\n\
         [intensity]\nfactors = [0.5, 1.0]\n",
        root.join("examples/models/block_record.toml").display(),
        root.join("examples/records/synthetic.AT2").display()
    );
    let study = dir.join("cut.toml");
    std::fs::write(&study, text).unwrap();
    let s = study.to_str().unwrap();
    let mut folders = Vec::new();
    for shard in ["1/2", "2/2"] {
        let out = dir.join(shard.replace('/', "_of_"));
        run_ok(&[
            "study",
            s,
            "--shard",
            shard,
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        folders.push(out);
    }
    let merged = dir.join("merged");
    let mut args = vec!["study", "merge"];
    args.extend(folders.iter().map(|f| f.to_str().unwrap()));
    args.extend(["--out", merged.to_str().unwrap()]);
    run_ok(&args);
    let json: serde_json::Value = serde_json::from_str(&read(&merged.join("study.json"))).unwrap();
    let warnings = json["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{json}");
    assert!(
        warnings[0]
            .as_str()
            .unwrap()
            .starts_with("duration = 5 s ends 2 of the 2 case(s) before their ground motion does"),
        "{json}"
    );
}
