//! Stopping a run early, keeping what it computed. Its cancellation flag (`RunOptions::cancel`):
//! set before the run, the run stops within its first step, after one integration step (or one
//! interval of the uplift test's grid at rest) at a state of the motion; set from another thread
//! while it runs, it stops soon after; a study stops and resumes. Its sample limit
//! (`RunOptions::max_samples`) stops it after the step that passes the limit. In every case the run is partial
//! (`"completed": false`) and keeps every sample and impact computed until then, identical to
//! those of the run not stopped.

use crr::impact::simulation::SimulationError;
use crr::{Cancel, RunOptions};

use crate::common;

fn options(duration: f64, cancel: &Cancel) -> RunOptions {
    RunOptions {
        duration: Some(duration),
        cancel: Some(cancel.clone()),
        ..Default::default()
    }
}

/// The instant at which `run` was cancelled (a run that was not is a failure of the test).
fn cancelled_at(run: &crr::Run) -> f64 {
    match run.failure {
        Some(SimulationError::Cancelled { t }) => t,
        _ => panic!("not cancelled: {:?}", run.failure),
    }
}

#[test]
fn a_flag_set_before_the_run_stops_it_after_one_step() {
    let model = crr::ModelInput::read(common::bundled_path("block_record")).unwrap();
    let cancel = Cancel::new();
    cancel.cancel();
    let run = crr::run(&model, &options(20.0, &cancel)).unwrap();
    assert!(!run.completed());
    let t = cancelled_at(&run);
    assert!(t > 0.0 && t < 20.0, "stopped at {t}");
    assert_eq!(run.trajectory.end_time, t);
    assert!(
        run.summary
            .error
            .as_deref()
            .unwrap()
            .starts_with("interrupted at t = ")
    );
    // What it kept is the beginning of the full run, sample for sample.
    let full = crr::run(&model, &options(20.0, &Cancel::new())).unwrap();
    assert!(full.completed());
    let (a, b) = (&run.trajectory.samples, &full.trajectory.samples);
    assert_eq!(
        a.iter().next_back().unwrap().t,
        t,
        "the last sample is where the run stopped"
    );
    let before: Vec<_> = a.iter().filter(|x| x.t < t).collect();
    assert!(!before.is_empty());
    for (x, y) in before.iter().zip(b.iter()) {
        assert_eq!((x.t, x.q, x.qdot), (y.t, y.q, y.qdot));
    }
}

/// The flag is read inside a step too. The bundled block released at θ₀ = 0.1 rad rocks freely
/// about its +x edge: its first step would run to the first impact (about 0.5 s: θ = α − (α − θ₀)
/// cosh pt in the linear range). Under a flag already set it stops after one integration step,
/// long before, at a state of the motion: Housner's energy integral,
/// θ̇² = 2p² (cos(α − θ₀) − cos(α − θ)) with p² = 3g/4R for a box about its edge (I_O = 4mR²/3),
/// holds at the last sample to the integrator's tolerance.
#[test]
fn a_flag_stops_a_rocking_step_at_a_state_of_the_motion() {
    let model = crr::ModelInput::read(common::bundled_path("single_block")).unwrap();
    let cancel = Cancel::new();
    cancel.cancel();
    let run = crr::run(&model, &options(20.0, &cancel)).unwrap();
    let t = cancelled_at(&run);
    assert!(t > 0.0 && t < 0.4, "stopped at {t}");
    assert!(run.trajectory.impacts.is_empty());
    let last = run.trajectory.samples.iter().next_back().unwrap();
    assert_eq!(last.t, t);
    let (b, h, g, theta0) = (0.2f64, 1.0f64, 9.81, 0.1);
    let (alpha, r) = (b.atan2(h), b.hypot(h));
    let p2 = 0.75 * g / r;
    let (theta, rate) = (last.q[0], last.qdot[0]);
    assert!(
        theta > 0.0 && theta < theta0 && rate < 0.0,
        "{theta} {rate}"
    );
    let expected = 2.0 * p2 * ((alpha - theta0).cos() - (alpha - theta).cos());
    // rtol 1e-10 per step on q̇ ~ 0.1 rad/s: q̇² to far better than 1e-9 p².
    assert!(
        (rate * rate - expected).abs() <= 1e-9 * p2,
        "θ̇² = {} against {expected}",
        rate * rate
    );
}

/// At rest under a ground motion below its uplift threshold (a sine of 0.5 m/s² against
/// g tan α = 1.96 m/s²), with a sample every 0.5 s, the block's first step is the whole run of
/// 1 000 s at rest (one segment, the uplift test on its grid). A flag already set stops it after
/// one interval of that grid instead, every sample until then at rest.
#[test]
fn a_flag_stops_a_long_rest_within_one_interval_of_the_uplift_grid() {
    let text = common::bundled_text("single_block").replace("angles = { base = 0.1 }", "")
        + "\n[ground_motion]\nx = { sine = { amplitude = 0.5, frequency = 2.0 } }\n\n[analysis]\noutput_interval = 0.5\n";
    let model = crr::ModelInput::parse("resting.toml", &text, false).unwrap();
    let cancel = Cancel::new();
    cancel.cancel();
    let run = crr::run(&model, &options(1000.0, &cancel)).unwrap();
    let t = cancelled_at(&run);
    // The uplift test's grid under a 2 Hz sine is far finer than a second.
    assert!(t > 0.0 && t < 1.0, "stopped at {t}");
    assert_eq!(run.trajectory.end_time, t);
    for s in run.trajectory.samples.iter() {
        assert_eq!((s.q[0], s.qdot[0]), (0.0, 0.0), "at {}", s.t);
    }
    // Not stopped, the same block stays at rest through a step that reaches the run's end.
    let full = crr::run(&model, &options(30.0, &Cancel::new())).unwrap();
    assert!(full.completed());
    assert!(full.trajectory.samples.iter().all(|s| s.q[0] == 0.0));
}

/// The bundled block rocking under a sine (a sample every 0.5 s): some 9 000 simulated seconds
/// per second of a release build, so that 1e6 s would take minutes.
fn rocking_for_ever() -> crr::ModelInput {
    let text = common::bundled_text("single_block").replace("angles = { base = 0.1 }", "")
        + "\n[ground_motion]\nx = { sine = { amplitude = 4.0, frequency = 2.0 } }\n\n[analysis]\noutput_interval = 0.5\n";
    crr::ModelInput::parse("rocking.toml", &text, false).unwrap()
}

#[test]
fn a_flag_set_from_another_thread_stops_a_long_run() {
    let model = rocking_for_ever();
    let cancel = Cancel::new();
    let remote = cancel.clone();
    let timer = std::thread::spawn(move || {
        std::thread::sleep(std::time::Duration::from_millis(200));
        remote.cancel();
    });
    let run = crr::run(&model, &options(1e6, &cancel)).unwrap();
    timer.join().unwrap();
    let t = cancelled_at(&run);
    assert!(t < 1e6);
    assert!(!run.trajectory.impacts.is_empty());
    assert_eq!(run.trajectory.end_time, t);
    let last = run.trajectory.samples.iter().next_back().unwrap();
    assert_eq!(last.t, t, "the last sample is where the run stopped");
}

/// A study cancelled while it runs writes the rows of the cases that ended, none for the cases
/// under way, and no study.json; running it again into the same folder runs only the missing
/// cases and ends with the cases.csv of an uninterrupted run, byte for byte.
#[test]
fn a_cancelled_study_keeps_its_rows_and_resumes_to_the_same_cases_csv() {
    use crr::analysis::study::Study;
    use crr::output::study::{Shard, StudyOptions, run_study};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/studies/drum_fragility.toml");
    let study = Study::load(&path).unwrap();
    // 50 of its 200 cases.
    let shard = Shard { index: 1, count: 4 };
    let dir = common::scratch("cancelled_study");
    let opts = |out: &str, cancel: Option<Cancel>| StudyOptions {
        out: dir.join(out),
        jobs: Some(2),
        shard,
        quiet: true,
        cancel,
    };
    let full = run_study(&study, &path, &opts("full", None)).unwrap();
    assert!(!full.interrupted);
    assert_eq!(full.ran, 50);

    // Cancelled as soon as the first row is in cases.csv.
    let cancel = Cancel::new();
    let remote = cancel.clone();
    let csv = dir.join("resumed/cases.csv");
    let timer = std::thread::spawn(move || {
        while std::fs::read_to_string(&csv).map_or(0, |t| t.lines().count()) < 2 {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        remote.cancel();
    });
    let first = run_study(&study, &path, &opts("resumed", Some(cancel))).unwrap();
    timer.join().unwrap();
    assert!(first.interrupted);
    assert!(first.ran < first.cases, "{first:?}");
    assert!(!dir.join("resumed/study.json").exists());

    let second = run_study(&study, &path, &opts("resumed", None)).unwrap();
    assert!(!second.interrupted);
    assert_eq!(second.skipped, first.ran);
    assert_eq!(second.skipped + second.ran, second.cases);
    let read = |d: &str| std::fs::read_to_string(dir.join(d).join("cases.csv")).unwrap();
    assert_eq!(read("full"), read("resumed"));
}

/// A sample limit stops an in-memory run after the step that passes it, keeping what it computed:
/// the samples until then are those of the unlimited run.
#[test]
fn a_sample_limit_stops_a_run_in_memory() {
    let model = crr::ModelInput::read(common::bundled_path("block_record")).unwrap();
    let limited = RunOptions {
        duration: Some(20.0),
        max_samples: Some(300),
        ..Default::default()
    };
    let run = crr::run(&model, &limited).unwrap();
    let Some(SimulationError::TooManySamples { max: 300, t }) = run.failure else {
        panic!("{:?}", run.failure);
    };
    assert!(t < 20.0);
    let samples = &run.trajectory.samples;
    // Past the limit by at most one step's samples (4 096, two per impact).
    assert!(samples.len() > 300 && samples.len() <= 300 + 4096 + 2 * run.trajectory.impacts.len());
    assert!(
        run.summary
            .error
            .as_deref()
            .unwrap()
            .starts_with("more than 300 output samples")
    );
    let full = crr::run(&model, &options(20.0, &Cancel::new())).unwrap();
    for (x, y) in samples.iter().zip(full.trajectory.samples.iter()) {
        assert_eq!((x.t, x.q, x.qdot), (y.t, y.q, y.qdot));
    }
}

/// The bundled planar wall (`wall.toml`: 2186 sets of joints that may open and slide per
/// direction, about 2.7 s of a release build each) along `n` directions in the plane, each
/// with a small vertical part of its own: some n × 1.35 s on two cores uninterrupted.
fn wall_directions(n: usize) -> (crr::kinematics::Model, Vec<nalgebra::Vector3<f64>>) {
    let model = common::bundled_model("wall");
    let directions = (0..n)
        .map(|k| {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            nalgebra::Vector3::new(sign, 0.0, 1e-3 * k as f64)
        })
        .collect();
    (model, directions)
}

/// A check whose request to stop is set before it starts gives no report, and so do the
/// statics below it (`static_multiplier_with`, `collapse_multiplier`); a request not set
/// changes nothing.
#[test]
fn a_check_asked_to_stop_before_it_starts_gives_no_report() {
    use crr::analysis::check::{CheckInterrupted, check_with};
    use crr::analysis::static_multiplier::{
        INTERRUPTED, MultiplierOptions, static_multiplier_with,
    };
    use crr::impact::statics::{StaticsError, StaticsOptions, collapse_multiplier};
    let (model, _) = wall_directions(0);
    let x = nalgebra::Vector3::x();
    let cancel = Cancel::new();
    cancel.cancel();
    let asked = MultiplierOptions {
        cancel: Some(cancel.clone()),
        ..MultiplierOptions::default()
    };
    assert_eq!(
        check_with(&model, &[x], &asked).err(),
        Some(CheckInterrupted)
    );
    assert_eq!(
        static_multiplier_with(&model, x, &asked).err(),
        Some(INTERRUPTED.to_string())
    );
    let options = StaticsOptions {
        cancel: Some(cancel.clone()),
        ..StaticsOptions::default()
    };
    assert_eq!(
        collapse_multiplier(&model, x, &options).err(),
        Some(StaticsError::Interrupted)
    );
    // Not set: the same report as without a flag (the wall's 7/11 along +x, its corner wedge).
    let asked = MultiplierOptions {
        cancel: Some(Cancel::new()),
        ..MultiplierOptions::default()
    };
    let flagged = check_with(&model, &[x], &asked).unwrap();
    let plain = check_with(&model, &[x], &MultiplierOptions::default()).unwrap();
    assert_eq!(
        serde_json::to_string(&flagged).unwrap(),
        serde_json::to_string(&plain).unwrap()
    );
    let lambda = plain.static_multipliers[0].lambda.unwrap();
    assert!((lambda - 7.0 / 11.0).abs() < 1e-9, "{lambda}");
}

/// A check of 96 directions of the wall (some two minutes of two cores uninterrupted) asked to
/// stop 0.2 s in stops after the linear program under way on each direction's thread: it answers
/// no report, long before the directions could have run through (the bound is a fraction of the
/// uninterrupted time, far above any scheduling delay on a loaded machine).
#[test]
fn a_check_asked_to_stop_while_it_runs_stops_after_the_program_under_way() {
    use crr::analysis::check::{CheckInterrupted, check_with};
    use crr::analysis::static_multiplier::MultiplierOptions;
    let (model, directions) = wall_directions(96);
    let cancel = Cancel::new();
    let remote = cancel.clone();
    let timer = std::thread::spawn(move || {
        std::thread::sleep(std::time::Duration::from_millis(200));
        remote.cancel();
    });
    let asked = MultiplierOptions {
        cancel: Some(cancel),
        ..MultiplierOptions::default()
    };
    let started = std::time::Instant::now();
    let report = check_with(&model, &directions, &asked);
    let took = started.elapsed();
    timer.join().unwrap();
    assert_eq!(report.err(), Some(CheckInterrupted));
    assert!(
        took < std::time::Duration::from_secs(40),
        "the check went on for {took:?} after the request to stop"
    );
}
