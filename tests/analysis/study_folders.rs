//! A study folder belongs to one study and one writer: a resume after the study changed, rows that
//! are not the study's, a merge with a shard missing or unfinished, and two writers in one folder
//! are refused with a message naming the file, where before they mixed results silently.

use std::path::{Path, PathBuf};

use crate::common::{crr, refused, scratch};

/// A 3 × 2 map of Housner's block under one-sine pulses (6 cases) lasting `duration`.
fn map(dir: &Path, duration: f64) -> PathBuf {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models");
    let text = format!(
        "name = \"map\"\nmodel = \"{}\"\nduration = {duration:?}\n\n[pulses]\nkind = \
         \"one_sine_pulse\"\namplitude_ratios = {{ from = 1.5, to = 6.0, count = 3 }}\n\
         frequency_ratios = {{ from = 1.0, to = 8.0, count = 2 }}\n",
        models.join("single_block.toml").display()
    );
    let path = dir.join("map.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn run_ok(args: &[&str]) {
    let out = crr(args);
    assert!(
        out.status.success(),
        "crr {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `crr study STUDY --shard SHARD --out OUT`, which must succeed.
fn run_shard(study: &str, shard: &str, out: &Path) {
    run_ok(&[
        "study",
        study,
        "--quiet",
        "--shard",
        shard,
        "--out",
        out.to_str().unwrap(),
    ]);
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

#[test]
fn a_resume_after_the_study_changed_is_refused_and_leaves_the_rows() {
    let dir = scratch("study_folder_changed");
    let study = map(&dir, 3.0);
    let out = dir.join("out");
    let (s, o) = (study.to_str().unwrap(), out.to_str().unwrap());
    run_ok(&["study", s, "--quiet", "--out", o]);
    let before = read(&out.join("cases.csv"));
    let json: serde_json::Value = serde_json::from_str(&read(&out.join("study.json"))).unwrap();
    assert_eq!(
        json["fingerprint"].as_str().unwrap(),
        read(&out.join("study.fingerprint")).trim()
    );
    // The same study again: every case is already done, nothing is refused.
    run_ok(&["study", s, "--quiet", "--out", o]);
    assert_eq!(read(&out.join("cases.csv")), before);
    // The duration edited: the 6 rows are of another study.
    map(&dir, 4.0);
    refused(
        &["study", s, "--quiet", "--out", o],
        "computed for another version of this study",
    );
    assert_eq!(read(&out.join("cases.csv")), before, "rows untouched");
    // A folder with rows and no fingerprint (written by hand, or by an older crr).
    std::fs::remove_file(out.join("study.fingerprint")).unwrap();
    refused(&["study", s, "--quiet", "--out", o], "study.fingerprint");
}

#[test]
fn rows_that_are_not_the_studys_are_refused_with_their_line() {
    let dir = scratch("study_folder_rows");
    let study = map(&dir, 3.0);
    let s = study.to_str().unwrap();
    let full = dir.join("full");
    run_ok(&["study", s, "--quiet", "--out", full.to_str().unwrap()]);
    let reference = read(&full.join("cases.csv"));
    let lines: Vec<&str> = reference.lines().collect();
    let cases = [
        (
            "garbage",
            format!("{}\n{}\ngarbage,row\n", lines[0], lines[1]),
            "line 3: 2 fields",
        ),
        (
            "truncated",
            format!(
                "{}\n{}\n{}\n",
                lines[0],
                lines[1],
                &lines[2][..lines[2].len() / 2]
            ),
            "line 3",
        ),
        (
            "duplicate",
            format!("{}\n{}\n{}\n", lines[0], lines[1], lines[1]),
            "appears a second time",
        ),
    ];
    // Values crr study never writes in their columns, each in the second row (they were
    // resumed and plotted as they were).
    let header: Vec<&str> = lines[0].split(',').collect();
    let edited = |column: &str, value: &str| {
        let k = header.iter().position(|h| *h == column).unwrap();
        let mut row: Vec<&str> = lines[2].split(',').collect();
        row[k] = value;
        format!("{}\n{}\n{}\n", lines[0], lines[1], row.join(","))
    };
    let mut cases: Vec<(String, String, String)> = cases
        .into_iter()
        .map(|(tag, text, needle)| (tag.to_string(), text, needle.to_string()))
        .collect();
    for (column, value) in [
        ("status", "banana"),
        ("collapse", "7"),
        ("impacts", "-3"),
        ("amplitude_m_s2", "inf"),
        ("residual_rad", "NaN"),
    ] {
        cases.push((
            format!("edited_{column}"),
            edited(column, value),
            format!("line 3: `{column}` holds `{value}`"),
        ));
    }
    for (tag, text, needle) in &cases {
        let (tag, needle) = (tag.as_str(), needle.as_str());
        let out = dir.join(tag);
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(out.join("cases.csv"), text).unwrap();
        std::fs::copy(
            full.join("study.fingerprint"),
            out.join("study.fingerprint"),
        )
        .unwrap();
        refused(
            &["study", s, "--quiet", "--out", out.to_str().unwrap()],
            needle,
        );
        assert_eq!(
            read(&out.join("cases.csv")),
            *text,
            "{tag}: the file is left as it was"
        );
        // `crr plot` reads the same rows: the edited values are refused there too.
        if tag.starts_with("edited_") {
            std::fs::copy(full.join("study.json"), out.join("study.json")).unwrap();
            let o = crr(&["plot", out.to_str().unwrap()]);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{tag}: {err}");
            assert!(err.contains(&needle["line 3: ".len()..]), "{tag}: {err}");
        }
    }
}

#[test]
fn a_shard_s_folder_is_refused_to_another_shard_and_left_as_it_was() {
    let dir = scratch("study_folder_other_shard");
    let study = map(&dir, 3.0);
    let s = study.to_str().unwrap();
    let one = dir.join("one");
    run_shard(s, "1/2", &one);
    let rows = read(&one.join("cases.csv"));
    // Shard 1/2 holds c000000, c000002 and c000004 (index mod 2 = 0); shard 2/2 the others.
    assert_eq!(rows.lines().count(), 4, "{rows}");
    refused(
        &[
            "study",
            s,
            "--quiet",
            "--shard",
            "2/2",
            "--out",
            one.to_str().unwrap(),
        ],
        "case c000000 is not one of this study's cases for shard 2/2",
    );
    assert_eq!(read(&one.join("cases.csv")), rows, "the rows are left");
    // The shard's own resume finds every case done.
    run_shard(s, "1/2", &one);
    assert_eq!(read(&one.join("cases.csv")), rows);
}

#[test]
fn a_merge_needs_every_shard_finished_and_of_one_study() {
    let dir = scratch("study_folder_merge");
    let study = map(&dir, 3.0);
    let s = study.to_str().unwrap();
    let (one, two) = (dir.join("one"), dir.join("two"));
    run_shard(s, "1/2", &one);
    run_shard(s, "2/2", &two);
    let merged = dir.join("merged");
    let (o1, o2, m) = (
        one.to_str().unwrap(),
        two.to_str().unwrap(),
        merged.to_str().unwrap(),
    );
    run_ok(&["study", "merge", o1, o2, "--out", m]);
    assert_eq!(read(&merged.join("cases.csv")).lines().count(), 7);
    // Merging into one of the shards (also written another way) would turn it into a merge:
    // refused, the shard left as it was.
    let shard_rows = read(&one.join("cases.csv"));
    let one_again = format!("{}/../one", two.display());
    for target in [o1, one_again.as_str()] {
        refused(
            &["study", "merge", o1, o2, "--out", target],
            "it is one of the shards being merged",
        );
    }
    assert_eq!(read(&one.join("cases.csv")), shard_rows);
    // A shard left out.
    refused(
        &[
            "study",
            "merge",
            o1,
            "--out",
            dir.join("m1").to_str().unwrap(),
        ],
        "shard(s) 2/2 missing",
    );
    // A shard that did not finish: its last row gone.
    let text = read(&two.join("cases.csv"));
    let cut: Vec<&str> = text.lines().collect();
    std::fs::write(
        two.join("cases.csv"),
        cut[..cut.len() - 1].join("\n") + "\n",
    )
    .unwrap();
    refused(
        &[
            "study",
            "merge",
            o1,
            o2,
            "--out",
            dir.join("m2").to_str().unwrap(),
        ],
        "1 are missing",
    );
    // A row that is not a case.
    std::fs::write(two.join("cases.csv"), text.clone() + "garbage,row\n").unwrap();
    refused(
        &[
            "study",
            "merge",
            o1,
            o2,
            "--out",
            dir.join("m3").to_str().unwrap(),
        ],
        "2 fields",
    );
    // A row whose id is not a case of the study, replacing the last row (the count stays
    // right: this was merged with exit 0, the case it replaced lost) or added.
    let last = cut[cut.len() - 1];
    let foreign = format!("c999999{}", &last[last.find(',').unwrap()..]);
    for (tag, edited) in [
        (
            "m3r",
            cut[..cut.len() - 1].join("\n") + "\n" + &foreign + "\n",
        ),
        ("m3a", text.clone() + &foreign + "\n"),
    ] {
        std::fs::write(two.join("cases.csv"), edited).unwrap();
        refused(
            &[
                "study",
                "merge",
                o1,
                o2,
                "--out",
                dir.join(tag).to_str().unwrap(),
            ],
            "case c999999 is not one of the study's 6 cases (c000000 to c000005)",
        );
        assert!(
            !dir.join(tag).join("cases.csv").exists(),
            "{tag}: nothing merged"
        );
    }
    std::fs::write(two.join("cases.csv"), &text).unwrap();
    // The second shard run again after the study was edited.
    map(&dir, 4.0);
    let three = dir.join("three");
    run_shard(s, "2/2", &three);
    refused(
        &[
            "study",
            "merge",
            o1,
            three.to_str().unwrap(),
            "--out",
            dir.join("m4").to_str().unwrap(),
        ],
        "a different study",
    );
    // The same study file with its model edited between the shards (a denser block): the study
    // file is the same, only the fingerprint tells.
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models");
    let original = read(&models.join("single_block.toml"));
    let model_copy = dir.join("single_block.toml");
    std::fs::write(&model_copy, &original).unwrap();
    let text = read(&study).replace(
        &models.join("single_block.toml").display().to_string(),
        &model_copy.display().to_string(),
    );
    let copied = dir.join("copied.toml");
    std::fs::write(&copied, text).unwrap();
    let c = copied.to_str().unwrap();
    let (five, six) = (dir.join("five"), dir.join("six"));
    run_shard(c, "1/2", &five);
    std::fs::write(
        &model_copy,
        original.replace("density = 2500.0", "density = 2600.0"),
    )
    .unwrap();
    run_shard(c, "2/2", &six);
    refused(
        &[
            "study",
            "merge",
            five.to_str().unwrap(),
            six.to_str().unwrap(),
            "--out",
            dir.join("m5").to_str().unwrap(),
        ],
        "fingerprints differ",
    );
}

#[test]
fn a_folder_another_process_writes_into_is_refused() {
    let dir = scratch("folder_lock_cli");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    // This test's own process holds the folder.
    std::fs::write(out.join(".crr.lock"), format!("{}\n", std::process::id())).unwrap();
    let args = [
        "simulate",
        model.to_str().unwrap(),
        "--quiet",
        "--force",
        "--out",
        out.to_str().unwrap(),
    ];
    refused(&args, "another crr process");
    assert!(!out.join("summary.json").exists());
    let study = map(&dir, 3.0);
    refused(
        &[
            "study",
            study.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ],
        "another crr process",
    );
    refused(
        &[
            "poincare",
            model.to_str().unwrap(),
            "--amplitude",
            "1",
            "--frequency",
            "1",
            "--periods",
            "5",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ],
        "another crr process",
    );
    assert!(!out.join("poincare.json").exists());
    // A lock left by a process that no longer runs is taken over, and released at the end.
    std::fs::write(out.join(".crr.lock"), "4294967295\n").unwrap();
    run_ok(&args);
    assert!(out.join("summary.json").exists());
    assert!(!out.join(".crr.lock").exists());
    // An animation of those results while another process holds the animation folder.
    let animation = out.join("animation");
    std::fs::create_dir_all(&animation).unwrap();
    std::fs::write(
        animation.join(".crr.lock"),
        format!("{}\n", std::process::id()),
    )
    .unwrap();
    refused(&["animate", out.to_str().unwrap()], "another crr process");
    std::fs::remove_file(animation.join(".crr.lock")).unwrap();
    run_ok(&["animate", out.to_str().unwrap(), "--every", "20"]);
    assert!(!animation.join(".crr.lock").exists());
}

#[test]
fn two_forced_runs_into_one_folder_leave_one_complete_result() {
    let dir = scratch("folder_lock_race");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/block_record.toml");
    for trial in 0..3 {
        let out = dir.join(format!("out{trial}"));
        let spawn = || {
            std::process::Command::new(env!("CARGO_BIN_EXE_crr"))
                .args([
                    "simulate",
                    model.to_str().unwrap(),
                    "--quiet",
                    "--force",
                    "--out",
                ])
                .arg(&out)
                .current_dir(env!("CARGO_MANIFEST_DIR"))
                .output()
        };
        let (a, b) = std::thread::scope(|s| {
            let a = s.spawn(spawn);
            let b = s.spawn(spawn);
            (a.join().unwrap().unwrap(), b.join().unwrap().unwrap())
        });
        for o in [&a, &b] {
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(
                o.status.success() || err.contains("another crr process"),
                "trial {trial}: {err}"
            );
        }
        assert!(
            a.status.success() || b.status.success(),
            "trial {trial}: neither ran"
        );
        // Whoever announced results left them whole.
        let summary: serde_json::Value =
            serde_json::from_str(&read(&out.join("summary.json"))).unwrap();
        assert!(summary["end_time"].as_f64().unwrap() > 0.0);
        assert!(read(&out.join("history.csv")).lines().count() > 100);
        assert!(!out.join(".crr.lock").exists());
    }
}

#[cfg(unix)]
#[test]
fn a_study_file_or_cases_file_that_is_a_device_or_a_pipe_is_refused_at_once() {
    let dir = scratch("study_folder_devices");
    // /dev/zero as the study file: refused without reading (it read 2 GB before).
    refused(&["study", "/dev/zero", "--quiet"], "not a regular file");
    // A FIFO as the study file: refused instead of waiting for a writer.
    let fifo = dir.join("study.fifo");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        refused(
            &["study", fifo.to_str().unwrap(), "--quiet"],
            "not a regular file",
        );
    }
    // cases.csv linked to /dev/zero in the output folder: the resume refuses it.
    let study = map(&dir, 3.0);
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink("/dev/zero", out.join("cases.csv")).unwrap();
    refused(
        &[
            "study",
            study.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ],
        "not a regular file",
    );
}
