//! `crr poincare` refuses sizes it cannot hold or finish before it allocates or runs anything
//! (issue: 10⁸ amplitudes or a 10⁵ × 10⁵ grid aborted on a 16.8 GB allocation, F = 1e-300 Hz
//! hung, `--periods 18446744073709551615` wrapped to 99 periods): exit 2 with an error that names
//! the option and the limit.
use crate::common;

#[test]
fn sizes_beyond_the_limits_are_refused_before_running() {
    for (args, words) in [
        (
            vec!["--amplitudes", "1:2:100000000", "--frequency", "2"],
            ["--amplitudes", "100000"],
        ),
        (
            vec![
                "--grid",
                "0:0.1:100000,0:1:100000",
                "--frequency",
                "2",
                "--amplitude",
                "1",
            ],
            ["--grid", "1000000"],
        ),
        (
            vec!["--frequency", "1e-300", "--amplitude", "1"],
            ["simulated time", "1e7"],
        ),
        (
            vec![
                "--periods",
                "18446744073709551615",
                "--frequency",
                "2",
                "--amplitude",
                "1",
            ],
            ["--periods", "10000000"],
        ),
        (
            // Each case keeps its points: 10⁵ amplitudes × 1 000 periods would hold about 24 GB.
            vec![
                "--amplitudes",
                "0:4:100000",
                "--periods",
                "1000",
                "--frequency",
                "2",
            ],
            ["100000 case(s) × --periods 1000", "10000000"],
        ),
        (
            // 10⁷ periods at 2 Hz: 5e6 s per run, beyond 1e7 times the block's time scale
            // √(L/g) = 0.3193 s (it failed as a run stopping early, exit 1).
            vec![
                "--periods",
                "9999999",
                "--frequency",
                "2",
                "--amplitude",
                "3",
            ],
            ["each run would last 5", "(transient + periods) / F"],
        ),
        (
            vec![
                "--section",
                "base",
                "--duration",
                "1e300",
                "--amplitude",
                "0",
            ],
            ["each run would last 1e300 s", "--duration"],
        ),
    ] {
        let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("poincare_limits");
        let mut a = vec!["poincare", "examples/models/single_block.toml", "--out"];
        a.push(out.to_str().unwrap());
        a.push("--force");
        a.extend(args.iter().copied());
        let o = common::crr(&a);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        for w in words {
            assert!(err.contains(w), "{args:?}: {err}");
        }
    }
}
