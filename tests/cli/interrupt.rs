//! SIGINT (Ctrl-C) and SIGTERM stop `crr simulate` within one integration step: it writes the results
//! computed until then into the folder, says in summary.json and on stderr that the run was
//! interrupted and is partial, and exits with 1 (a simulation stopped part-way).

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common;

fn interrupted_by(signal: &str) {
    let dir = common::scratch(&format!("interrupt_{signal}"));
    let out = dir.join("run");
    // The bundled block rocking under a sine for 1e6 s: minutes of work (some 9 000 simulated
    // seconds per second in a release build), with a sample every 0.5 s.
    let text = common::bundled_text("single_block").replace("angles = { base = 0.1 }", "")
        + "\n[ground_motion]\nx = { sine = { amplitude = 4.0, frequency = 2.0 } }\n\n[analysis]\noutput_interval = 0.5\n";
    let model = common::write_model(&format!("interrupt_{signal}"), &text);
    let mut child = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(["simulate", "--quiet", "--duration", "1e6", "--out"])
        .arg(&out)
        .arg(&model)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("crr runs");
    // The history's temporary file exists once the run is under way.
    let started = Instant::now();
    while !out.join(".partial.history.csv").is_file() {
        assert!(
            started.elapsed() < Duration::from_secs(common::HANG_GUARD_S),
            "the run never started"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(300));
    let status = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let sent = Instant::now();
    while child.try_wait().unwrap().is_none() {
        assert!(
            sent.elapsed() < Duration::from_secs(common::HANG_GUARD_S),
            "crr did not stop after SIG{signal}"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("interrupted at t = "), "{stderr}");
    assert!(stderr.contains("partial results written to"), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["completed"], false);
    assert!(
        summary["error"]
            .as_str()
            .unwrap()
            .starts_with("interrupted at t = ")
    );
    let end = summary["end_time"].as_f64().unwrap();
    assert!(end > 0.0 && end < 1e6, "end time {end}");
    // Every sample up to the interruption is in the history, the last one at the end time.
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let last = history.lines().last().unwrap();
    let t: f64 = last.split(',').next().unwrap().parse().unwrap();
    assert!((t - end).abs() <= 1e-9 * end, "last sample {t}, end {end}");
    assert!(!out.join(".partial.history.csv").exists());
}

#[test]
fn sigint_stops_a_run_with_its_partial_results() {
    interrupted_by("INT");
}

#[test]
fn sigterm_stops_a_run_with_its_partial_results() {
    interrupted_by("TERM");
}

#[test]
fn sigint_stops_a_study_that_the_same_command_resumes() {
    let dir = common::scratch("interrupt_study");
    let out = dir.join("map");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let args = |out: &std::path::Path| {
        vec![
            "study".to_string(),
            "examples/studies/housner_map.toml".to_string(),
            "--quiet".to_string(),
            "--jobs".to_string(),
            "2".to_string(),
            "--out".to_string(),
            out.display().to_string(),
        ]
    };
    let child = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(args(&out))
        .current_dir(root)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("crr runs");
    let csv = out.join("cases.csv");
    let started = Instant::now();
    while std::fs::read_to_string(&csv).map_or(0, |t| t.lines().count()) < 2 {
        assert!(started.elapsed() < Duration::from_secs(common::HANG_GUARD_S));
        std::thread::sleep(Duration::from_millis(2));
    }
    Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("interrupted: "), "{stderr}");
    assert!(stderr.contains("the same command resumes it"), "{stderr}");
    assert!(!out.join("study.json").exists());
    let written = std::fs::read_to_string(&csv).unwrap().lines().count() - 1;
    assert!(written < 3600, "{written} rows");
    // The same command resumes and finishes.
    let args = args(&out);
    let again = common::crr(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        again.status.success(),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
    assert_eq!(std::fs::read_to_string(&csv).unwrap().lines().count(), 3601);
    assert!(out.join("study.json").exists());
}
