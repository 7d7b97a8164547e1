//! Long runs stream their history: `run_with_sink` hands the samples over after every step, a
//! step never holds more than a few thousand of them, and the results (peaks, energy balance,
//! impacts) are those of the run that keeps everything in memory.

use std::path::Path;

use crr::simulate::{SampleStats, SimulateOptions, prepare, run, run_with_sink};

#[test]
fn a_streamed_run_holds_bounded_chunks_and_agrees_with_the_in_memory_run() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
    let opts = SimulateOptions {
        duration: Some(200.0),
        out: Some(std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("no-results")),
        ..Default::default()
    };
    let p = prepare(&path, &opts).unwrap();
    let whole = run(&p, false).unwrap();
    assert!(whole.error.is_none());
    let (mut chunks, mut largest, mut stats) = (0usize, 0usize, SampleStats::default());
    let mut times = Vec::new();
    let streamed = run_with_sink(
        &p,
        false,
        |samples| {
            chunks += 1;
            largest = largest.max(samples.len());
            stats.add(samples);
            times.extend(samples.iter().map(|s| s.t));
            Ok(())
        },
        true,
    )
    .unwrap();
    assert!(streamed.error.is_none());
    let (a, b) = (&whole.trajectory, &streamed.trajectory);
    // 200 s at 0.01 s: 20 001 samples plus two per impact, in chunks of at most 4 096 (plus the
    // samples of the impacts of one step).
    assert!(b.samples.is_empty());
    assert_eq!(stats.rows, a.samples.len());
    assert_eq!(times, a.samples.iter().map(|s| s.t).collect::<Vec<_>>());
    assert!(
        chunks >= 5 && largest <= 4096 + 2 * a.impacts.len(),
        "{chunks} chunks, largest {largest}"
    );
    // The same run: identical peaks, balance and impacts.
    assert_eq!(a.peak_abs, b.peak_abs);
    assert_eq!(a.energy_balance_error, b.energy_balance_error);
    assert_eq!(a.impacts, b.impacts);
}

#[test]
fn a_sink_that_fails_stops_the_run_with_an_error_and_keeps_the_results() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
    let opts = SimulateOptions {
        duration: Some(100.0),
        out: Some(std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("no-results")),
        ..Default::default()
    };
    let p = prepare(&path, &opts).unwrap();
    let mut calls = 0;
    let o = run_with_sink(
        &p,
        false,
        |_| {
            calls += 1;
            if calls == 3 {
                Err(std::io::Error::other("disk full"))
            } else {
                Ok(())
            }
        },
        true,
    )
    .unwrap();
    let e = o.error.expect("the sink's error stops the run").to_string();
    assert!(e.contains("cannot write the history: disk full"), "{e}");
    assert!(o.trajectory.end_time > 0.0 && o.trajectory.end_time < 100.0);
}
