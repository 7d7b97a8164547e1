//! Long runs stream their history: `crr::run_streaming` hands the samples over after every step,
//! a step never holds more than a few thousand of them, and the results (peaks, energy balance,
//! impacts) are those of the run that keeps everything in memory.

use std::path::Path;

use crr::{ModelInput, RunOptions};

fn single_block(duration: f64) -> (ModelInput, RunOptions) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
    let options = RunOptions {
        duration: Some(duration),
        ..Default::default()
    };
    (ModelInput::read(path).unwrap(), options)
}

#[test]
fn a_streamed_run_holds_bounded_chunks_and_agrees_with_the_in_memory_run() {
    let (model, options) = single_block(200.0);
    let whole = crr::run(&model, &options).unwrap();
    assert!(whole.completed());
    let (mut chunks, mut largest) = (0usize, 0usize);
    let mut times = Vec::new();
    let streamed = crr::run_streaming(&model, &options, |samples| {
        chunks += 1;
        largest = largest.max(samples.len());
        times.extend(samples.iter().map(|s| s.t));
        Ok(())
    })
    .unwrap();
    assert!(streamed.completed());
    let (a, b) = (&whole.trajectory, &streamed.trajectory);
    // 200 s at 0.01 s: 20 001 samples plus two per impact, in chunks of at most 4 096 (plus the
    // samples of the impacts of one step).
    assert!(b.samples.is_empty());
    assert_eq!(times.len(), a.samples.len());
    assert_eq!(streamed.summary.samples, a.samples.len());
    assert_eq!(times, a.samples.iter().map(|s| s.t).collect::<Vec<_>>());
    assert!(
        chunks >= 5 && largest <= 4096 + 2 * a.impacts.len(),
        "{chunks} chunks, largest {largest}"
    );
    // The same run: identical peaks, balance and impacts, and the same summary.
    assert_eq!(a.peak_abs, b.peak_abs);
    assert_eq!(a.energy_balance_error, b.energy_balance_error);
    assert_eq!(a.impacts, b.impacts);
    assert_eq!(whole.summary, streamed.summary);
}

#[test]
fn a_sink_that_fails_stops_the_run_with_an_error_and_keeps_the_results() {
    let (model, options) = single_block(100.0);
    let mut calls = 0;
    let o = crr::run_streaming(&model, &options, |_| {
        calls += 1;
        if calls == 3 {
            Err(std::io::Error::other("disk full"))
        } else {
            Ok(())
        }
    })
    .unwrap();
    assert!(!o.completed());
    // Typed for a program: the sink's failure, and its message in the summary.
    assert!(
        matches!(&o.failure, Some(crr::impact::SimulationError::Parameter(m)) if m.contains("disk full")),
        "{:?}",
        o.failure
    );
    let e = o.summary.error.expect("the sink's error stops the run");
    assert!(e.contains("cannot write the history: disk full"), "{e}");
    assert!(o.trajectory.end_time > 0.0 && o.trajectory.end_time < 100.0);
}
