//! Damaged or hostile inputs get a clear error (exit 2, the file named), never a panic, a hang or
//! an allocation the input does not justify.

use crate::common;

use std::path::PathBuf;
use std::process::Command;

use crate::common::{crr, refused};

fn scratch(name: &str) -> PathBuf {
    common::scratch(&format!("hostile_{name}"))
}

#[test]
fn record_headers_cannot_ask_for_absurd_allocations() {
    let dir = scratch("at2");
    for npts in ["18446744073709551615", "99999999999999", "4000000000"] {
        let at2 = dir.join(format!("{npts}.AT2"));
        std::fs::write(
            &at2,
            format!("TEST\nTEST\nACCELERATION IN G\nNPTS= {npts}, DT= .0100 SEC\n 0.0 0.1 0.2\n"),
        )
        .unwrap();
        let out = dir.join(format!("out_{npts}"));
        refused(
            &[
                "simulate",
                "examples/models/single_block.toml",
                "--out",
                out.to_str().unwrap(),
                "--record",
                at2.to_str().unwrap(),
                "--format",
                "peer-at2",
            ],
            at2.to_str().unwrap(),
        );
    }
}

/// A time step in the wrong unit (or absurd): the samples' span overflows (a record error naming
/// the file), or the run it sets would last 3e300 s (refused before anything runs, naming the
/// duration; the bundled block's time scale √(L/g) is 0.33 s, its limit 1e7 of that).
#[test]
fn records_whose_time_step_is_absurd_are_refused() {
    let dir = scratch("dt");
    for (dt, needle) in [
        ("1e308", "span more than any time"),
        ("1e300", "duration = 3e300 s is more than 1e7 times"),
        ("1e3", "duration = 3e3 s"),
    ] {
        let at2 = dir.join(format!("dt_{dt}.AT2"));
        std::fs::write(
            &at2,
            format!("TEST\nTEST\nACCELERATION IN G\nNPTS= 4, DT= {dt} SEC\n 0.0 0.1 0.2 0.0\n"),
        )
        .unwrap();
        let out = dir.join(format!("out_{dt}"));
        let args = [
            "simulate",
            "examples/models/single_block.toml",
            "--out",
            out.to_str().unwrap(),
            "--record",
            at2.to_str().unwrap(),
            "--format",
            "peer-at2",
        ];
        if dt == "1e3" {
            // 3 000 s of record is a long run, not an absurd one: it is not refused for its
            // length (here it is stopped by --duration before it starts costing).
            let mut short = args.to_vec();
            short.extend(["--duration", "0.5", "--quiet"]);
            let o = crr(&short);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            continue;
        }
        refused(&args, needle);
        assert!(!out.join("history.csv").exists(), "{dt}: nothing written");
    }
}

#[test]
fn plot_refuses_empty_and_non_finite_histories() {
    let dir = scratch("plot");
    let good = dir.join("good");
    let o = crr(&[
        "simulate",
        "examples/models/single_block.toml",
        "--out",
        good.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success());
    let history = std::fs::read_to_string(good.join("history.csv")).unwrap();
    let header = history.lines().next().unwrap();
    let row = history.lines().nth(3).unwrap();
    let with_value = |v: &str| {
        let mut fields: Vec<&str> = row.split(',').collect();
        fields[1] = v;
        history.replacen(row, &fields.join(","), 1)
    };
    let cases = [
        ("header_only", format!("{header}\n"), "no data rows"),
        ("inf", with_value("inf"), "not a finite number"),
        ("nan", with_value("NaN"), "not a finite number"),
    ];
    for (name, text, needle) in cases {
        let bad = dir.join(name);
        std::fs::create_dir_all(&bad).unwrap();
        for f in ["impacts.csv", "summary.json"] {
            std::fs::copy(good.join(f), bad.join(f)).unwrap();
        }
        std::fs::write(bad.join("history.csv"), text).unwrap();
        refused(&["plot", bad.to_str().unwrap()], needle);
    }
}

#[cfg(unix)]
#[test]
fn devices_pipes_and_folders_are_not_read() {
    let dir = scratch("special");
    let fifo = dir.join("model.toml");
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .map(|s| s.success());
    let mut cases = vec!["/dev/zero".to_string(), dir.to_str().unwrap().to_string()];
    if made.is_ok_and(|ok| ok) {
        cases.push(fifo.to_str().unwrap().to_string());
    }
    for path in &cases {
        refused(&["inspect", path], "not a regular file");
        refused(
            &["simulate", path, "--out", dir.join("out").to_str().unwrap()],
            "not a regular file",
        );
    }
}

/// `--jobs` is bounded (issue: `crr study … --jobs 100000` started about 1 200 threads in 16 s
/// and finished none of 400 cases in a minute): above `MAX_JOBS` it is refused before any
/// thread starts or any file is written.
#[test]
fn jobs_beyond_the_bound_are_refused_before_anything_runs() {
    let dir = scratch("jobs_bound");
    let study = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/studies/block_spectrum.toml");
    let out = dir.join("study");
    let too_many = (crr::analysis::MAX_JOBS + 1).to_string();
    let needle = format!(
        "--jobs must be at most {}, got {too_many}",
        crr::analysis::MAX_JOBS
    );
    common::refused(
        &[
            "study",
            study.to_str().unwrap(),
            "--jobs",
            &too_many,
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ],
        &needle,
    );
    assert!(!out.join("cases.csv").exists(), "nothing written");
    let block = common::bundled_path("single_block");
    let pc = dir.join("poincare");
    common::refused(
        &[
            "poincare",
            block.to_str().unwrap(),
            "--frequency",
            "2",
            "--amplitudes",
            "1:3:4",
            "--jobs",
            &too_many,
            "--out",
            pc.to_str().unwrap(),
        ],
        &needle,
    );
    assert!(!pc.exists(), "nothing written");
}

/// A FIFO where an output file goes is replaced, never opened for writing (issue: a FIFO named
/// `study.json` in a study's folder, or `energy.png` in a results folder, blocked `crr study` and
/// `crr plot` for ever, deaf to SIGTERM). Each command must finish within the hang guard.
#[test]
#[cfg(unix)]
fn a_fifo_in_place_of_an_output_file_is_replaced() {
    use std::time::{Duration, Instant};
    let dir = scratch("fifo_outputs");
    let mkfifo = |p: &std::path::Path| {
        assert!(Command::new("mkfifo").arg(p).status().unwrap().success());
    };
    // The suite's hang guard, generous for a debug build on a loaded machine; a hang would last
    // for ever.
    let guard = Duration::from_secs(common::HANG_GUARD_S);
    let run = |args: &[&str]| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_crr"))
            .args(args)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let start = Instant::now();
        loop {
            if let Some(status) = child.try_wait().unwrap() {
                return status;
            }
            if start.elapsed() > guard {
                let _ = child.kill();
                panic!("{args:?} hangs on a FIFO");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    };
    let study = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/studies/block_spectrum.toml");
    let out = dir.join("study");
    std::fs::create_dir_all(&out).unwrap();
    mkfifo(&out.join("study.json"));
    let status = run(&[
        "study",
        study.to_str().unwrap(),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(status.success());
    let json = std::fs::read_to_string(out.join("study.json")).unwrap();
    assert!(json.contains("\"fingerprint\""), "{json}");

    let results = dir.join("results");
    let block = common::bundled_path("single_block");
    assert!(
        crr(&[
            "simulate",
            block.to_str().unwrap(),
            "--quiet",
            "--out",
            results.to_str().unwrap()
        ])
        .status
        .success()
    );
    mkfifo(&results.join("energy.png"));
    assert!(run(&["plot", results.to_str().unwrap()]).success());
    assert!(std::fs::metadata(results.join("energy.png")).unwrap().len() > 10_000);
}

/// A record column at the top of the integers is an error naming the record's line, not an
/// index overflow (it panicked with exit 101).
#[test]
fn a_record_column_beyond_any_line_is_an_error() {
    let dir = scratch("column");
    let csv = dir.join("a.csv");
    std::fs::write(&csv, "time,accel\n0.0,0.0\n0.1,5.0\n0.2,0\n").unwrap();
    let block =
        common::bundled_text("single_block").replace("[initial]\nangles = { base = 0.1 }\n", "");
    for key in ["accel_column", "time_column"] {
        let model = dir.join(format!("{key}.toml"));
        std::fs::write(
            &model,
            format!(
                "{block}\n[ground_motion]\nx = {{ record = {{ file = \"a.csv\", format = \"csv\", \
                 units = \"g\", {key} = 18446744073709551615 }} }}\n[analysis]\nduration = 1.0\n"
            ),
        )
        .unwrap();
        refused(
            &[
                "simulate",
                model.to_str().unwrap(),
                "--out",
                dir.join("out").to_str().unwrap(),
                "--force",
            ],
            "a.csv:2: expected at least 18446744073709551615 columns, found 2",
        );
    }
}

/// An assembly's OBJ file is read like every other input: a device, a folder or a FIFO is
/// refused (`/dev/zero` exhausted the memory, a FIFO hung `crr assemble`).
#[cfg(unix)]
#[test]
fn an_obj_file_that_is_not_a_regular_file_is_refused() {
    let dir = scratch("obj_special");
    let fifo = dir.join("blocks_fifo.obj");
    let _ = std::fs::remove_file(&fifo);
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    let mut files = vec!["/dev/zero".to_string(), dir.to_str().unwrap().to_string()];
    if made {
        files.push(fifo.to_str().unwrap().to_string());
    }
    for (k, file) in files.iter().enumerate() {
        let assembly = dir.join(format!("assembly_{k}.toml"));
        std::fs::write(
            &assembly,
            format!("name = \"a\"\n[[obj]]\nfile = \"{file}\"\ndensity = 2000.0\n"),
        )
        .unwrap();
        refused(
            &[
                "assemble",
                assembly.to_str().unwrap(),
                "--out",
                dir.join(format!("model_{k}.toml")).to_str().unwrap(),
            ],
            &format!("{file}: not a regular file"),
        );
    }
}

/// A write that fails during a run (here a file size limit, with SIGXFSZ ignored so that writes
/// past it fail) ends the run; the rows written before are kept under their own names, cut at
/// their last whole line (a row written in part was left), with a summary.json that says the
/// run did not complete, and the exit status is a run's failure (1). The kept folder is a
/// results folder: `crr plot` draws it.
#[cfg(unix)]
#[test]
fn results_written_before_the_disk_fills_are_kept() {
    let dir = scratch("disk_full");
    let out = dir.join("out");
    let model = common::bundled_path("single_block");
    let script = "trap '' XFSZ; ulimit -f 400; exec \"$0\" simulate \"$1\" --out \"$2\" \
                  --duration 100000 --force --quiet";
    let o = Command::new("sh")
        .args([
            "-c",
            script,
            env!("CARGO_BIN_EXE_crr"),
            model.to_str().unwrap(),
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    // A size limit per file: the run stops on the history's write, and the small files after
    // it are written (a disk with no room left at all is `keep_what_was_written`'s, whose unit
    // test cuts every write).
    assert!(
        err.contains("cannot write the history: File too large")
            && err.contains("partial results written to"),
        "{err}"
    );
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(history.ends_with('\n'), "cut at a whole line");
    let width = history.lines().next().unwrap().split(',').count();
    let rows: Vec<&str> = history.lines().skip(1).collect();
    assert!(rows.len() > 100, "{} rows kept", rows.len());
    for row in &rows {
        assert_eq!(row.split(',').count(), width, "{row}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["completed"], false);
    assert!(
        summary["error"]
            .as_str()
            .unwrap()
            .contains("cannot write the history"),
        "{summary}"
    );
    let hidden: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with(".partial."))
        .map(|e| e.file_name())
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
    let plotted = crr(&["plot", out.to_str().unwrap()]);
    assert!(
        plotted.status.success(),
        "{}",
        String::from_utf8_lossy(&plotted.stderr)
    );
}
