use super::*;
use approx::assert_relative_eq;
use proptest::prelude::*;
use std::f64::consts::{PI, TAU};
use std::path::PathBuf;

const G0: f64 = STANDARD_GRAVITY;

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data")
}

fn data(name: &str) -> PathBuf {
    data_dir().join(name)
}

fn component(signal: SignalSpec) -> GroundMotion {
    GroundMotion::none()
        .with_component(Axis::X, &ComponentSpec::new(signal), Path::new("."))
        .expect("valid spec")
}

fn sine(amplitude: f64, period: f64, phase: f64, cycles: Option<f64>, start: f64) -> SignalSpec {
    SignalSpec::Sine(SineSpec {
        amplitude,
        period: Some(period),
        frequency: None,
        phase,
        cycles,
        start,
    })
}

fn err_string<T: std::fmt::Debug>(r: Result<T, GroundMotionError>) -> String {
    r.expect_err("expected an error").to_string()
}

// ---------------------------------------------------------------- AT2 files

#[test]
fn at2_npts_dt_layout_reads_values_in_g() {
    let r = read_at2(&data("at2_npts_dt.AT2")).unwrap();
    let expected_g = [
        0.01,
        -0.02,
        0.03,
        -0.04,
        0.05,
        0.0,
        0.01,
        -0.025,
        0.1234e-102,
        0.1,
        -0.1,
        0.2,
    ];
    assert_eq!(r.len(), 12);
    assert_eq!(r.dt(), Some(0.01));
    for (a, g) in r.accel().iter().zip(expected_g) {
        assert_eq!(*a, g * G0);
    }
    assert_eq!(r.time(11), Some(11.0 * 0.01));
    assert_eq!(r.time(12), None);
    // The three values after the 12th are ignored and reported.
    assert_eq!(r.warnings().len(), 1);
    assert!(
        r.warnings()[0].contains(":7: 3 value(s)"),
        "{:?}",
        r.warnings()
    );
}

#[test]
fn at2_old_layout_two_numbers_after_three_lines() {
    let r = read_at2(&data("at2_old_layout.AT2")).unwrap();
    assert_eq!(r.len(), 8);
    assert_eq!(r.dt(), Some(0.005));
    assert_eq!(r.accel()[0], 0.1 * G0);
    assert_eq!(r.accel()[7], -0.8 * G0);
    assert!(r.warnings().is_empty());
}

#[test]
fn at2_crlf_line_endings() {
    let bytes = std::fs::read(data("at2_crlf.AT2")).unwrap();
    assert!(
        bytes.windows(2).any(|w| w == b"\r\n"),
        "fixture must be CRLF"
    );
    let r = read_at2(&data("at2_crlf.AT2")).unwrap();
    assert_eq!(r.dt(), Some(0.005));
    let expected: Vec<f64> = [0.01, -0.02, 0.03, -0.04, 0.05, -0.06]
        .iter()
        .map(|g| g * G0)
        .collect();
    assert_eq!(r.accel(), expected.as_slice());
}

#[test]
fn at2_truncated_names_file_and_last_line() {
    let msg = err_string(read_at2(&data("at2_truncated.AT2")));
    assert!(msg.contains("at2_truncated.AT2:6:"), "{msg}");
    assert!(msg.contains("7 of NPTS = 10"), "{msg}");
}

#[test]
fn at2_non_numeric_token_names_line_and_token() {
    let e = read_at2(&data("at2_bad_token.AT2")).unwrap_err();
    match &e {
        GroundMotionError::Parse { path, line, .. } => {
            assert!(path.ends_with("at2_bad_token.AT2"));
            assert_eq!(*line, 6);
        }
        other => panic!("unexpected error {other:?}"),
    }
    assert!(e.to_string().contains("`abc`"), "{e}");
}

#[test]
fn at2_missing_file_names_path() {
    let msg = err_string(read_at2(Path::new("no/such/file.AT2")));
    assert!(
        msg.starts_with("no/such/file.AT2: cannot read file"),
        "{msg}"
    );
}

#[test]
fn at2_header_variants() {
    let body = "0.1 0.2\n0.3\n";
    for header in [
        "NPTS=3,DT=.005",
        "npts = 3 , dt = 0.005 sec",
        "  NPTS=    3   DT=   5.0E-03 SEC",
        "DT= .0050 SEC, NPTS= 3",
        "3   .005   NPTS, DT",
    ] {
        let text = format!("a\nb\nc\n{header}\n{body}");
        let r = parse_at2(&text, "mem.AT2").unwrap_or_else(|e| panic!("{header}: {e}"));
        assert_eq!(r.dt(), Some(0.005), "{header}");
        assert_eq!(r.accel()[2], 0.3 * G0, "{header}");
    }
}

#[test]
fn at2_without_header_is_an_error() {
    let msg = err_string(parse_at2("a\nb\nc\n0.1 0.2 0.3\n", "x.AT2"));
    assert!(msg.starts_with("x.AT2: no NPTS/DT header"), "{msg}");
}

#[test]
fn at2_bad_dt_is_an_error_with_line() {
    let msg = err_string(parse_at2("a\nb\nc\nNPTS= 3, DT= 0.0\n1 2 3\n", "x.AT2"));
    assert_eq!(msg, "x.AT2:4: DT must be positive, got 0");
}

/// Four samples 1e308 s apart span 3e308 s, beyond the largest float: refused at the header's
/// line (and by `Record::uniform` for records built in memory).
#[test]
fn at2_whose_samples_span_beyond_any_time_is_an_error() {
    let msg = err_string(parse_at2("a\nb\nc\nNPTS= 4, DT= 1e308\n1 2 3 4\n", "x.AT2"));
    assert_eq!(
        msg,
        "x.AT2:4: NPTS = 4 samples at DT = 1e308 s span more than any time"
    );
}

#[test]
fn fortran_numbers() {
    assert_eq!(parse_fortran_float(".1234E-02"), Some(0.1234e-2));
    assert_eq!(parse_fortran_float("-0.1234567E-01"), Some(-0.1234567e-1));
    assert_eq!(parse_fortran_float("1.2D-03"), Some(1.2e-3));
    assert_eq!(parse_fortran_float("0.5-100"), Some(0.5e-100));
    assert_eq!(parse_fortran_float("5."), Some(5.0));
    assert_eq!(parse_fortran_float("nan"), None);
    assert_eq!(parse_fortran_float("inf"), None);
    assert_eq!(parse_fortran_float("1.0.0"), None);
}

// ---------------------------------------------------------------- tables

#[test]
fn csv_with_header_in_cm_s2_is_divided_by_100() {
    let opts = TableOptions::new(RecordFormat::Csv, Units::CentimetersPerSecondSquared);
    let r = read_table(&data("accel_cm.csv"), &opts).unwrap();
    let times: Vec<f64> = r.times().collect();
    assert_eq!(times, vec![0.0, 0.01, 0.02, 0.03, 0.05]);
    let expected: Vec<f64> = [0.0, 12.5, -30.0, 7.25, 0.0]
        .iter()
        .map(|v| v / 100.0)
        .collect();
    assert_eq!(r.accel(), expected.as_slice());
    assert_eq!(r.dt(), None);
}

#[test]
fn text_in_g_is_multiplied_by_standard_gravity() {
    let r = read_record(&data("accel_g.txt"), RecordFormat::Text, Some(Units::G)).unwrap();
    let expected: Vec<f64> = [0.0, 0.1, -0.25, 0.05]
        .iter()
        .map(|v| v * 9.80665)
        .collect();
    assert_eq!(r.accel(), expected.as_slice());
    assert_eq!(r.time(3), Some(0.06));
}

#[test]
fn non_increasing_times_error_names_line() {
    let opts = TableOptions::new(RecordFormat::Csv, Units::MetersPerSecondSquared);
    let e = read_table(&data("nonincreasing.csv"), &opts).unwrap_err();
    match &e {
        GroundMotionError::Parse { line, .. } => assert_eq!(*line, 4),
        other => panic!("unexpected error {other:?}"),
    }
    assert!(e.to_string().contains("strictly increasing"), "{e}");
}

/// A headerless CSV that starts with a UTF-8 byte-order mark keeps its first sample (the issue:
/// the mark made the first line look like a header and it was dropped).
#[test]
fn a_byte_order_mark_keeps_the_first_sample() {
    let opts = TableOptions::new(RecordFormat::Csv, Units::MetersPerSecondSquared);
    let plain = parse_table("0,1.5\n0.01,2\n0.02,3\n", "a.csv", &opts).unwrap();
    let marked = parse_table("\u{feff}0,1.5\n0.01,2\n0.02,3\n", "a.csv", &opts).unwrap();
    assert_eq!(marked.len(), 3);
    assert_eq!(marked.accel(), plain.accel());
    assert_eq!(marked.times().collect::<Vec<_>>(), vec![0.0, 0.01, 0.02]);
}

/// A column index at the top of the integers (a typo or a script's -1) is an error naming the
/// line, not an overflow: for each of the time and acceleration columns, in CSV and text.
#[test]
fn a_column_beyond_any_line_is_an_error() {
    for format in [RecordFormat::Csv, RecordFormat::Text] {
        for time_column in [true, false] {
            let mut opts = TableOptions::new(format, Units::MetersPerSecondSquared);
            if time_column {
                opts.time_column = usize::MAX;
            } else {
                opts.accel_column = usize::MAX;
            }
            let text = match format {
                RecordFormat::Csv => "0,1\n0.1,2\n",
                _ => "0 1\n0.1 2\n",
            };
            assert_eq!(
                err_string(parse_table(text, "a.csv", &opts)),
                format!("a.csv:1: expected at least {} columns, found 2", usize::MAX)
            );
        }
    }
}

#[test]
fn table_errors() {
    let opts = TableOptions::new(RecordFormat::Csv, Units::MetersPerSecondSquared);
    assert_eq!(
        err_string(parse_table("0,1\n0.1\n", "a.csv", &opts)),
        "a.csv:2: expected at least 2 columns, found 1"
    );
    assert_eq!(
        err_string(parse_table("0,1\n0.1,x\n", "a.csv", &opts)),
        "a.csv:2: invalid acceleration `x` in column 1"
    );
    assert_eq!(
        err_string(parse_table("t,a\n0,1\n", "a.csv", &opts)),
        "a.csv: a record needs at least 2 samples, found 1"
    );
    // Only the first row may be a header.
    assert!(
        err_string(parse_table("t,a\nt,a\n0,1\n1,2\n", "a.csv", &opts)).starts_with("a.csv:2:")
    );
}

#[test]
fn table_columns_and_skip_rows() {
    let mut opts = TableOptions::new(RecordFormat::Text, Units::MetersPerSecondSquared);
    opts.time_column = 2;
    opts.accel_column = 0;
    opts.skip_rows = 2;
    let text = "garbage line\n1 2 3 4\n 5.0 x 0.0\n-5.0 y 0.5\n";
    let r = parse_table(text, "t.txt", &opts).unwrap();
    assert_eq!(r.accel(), &[5.0, -5.0]);
    assert_eq!(r.times().collect::<Vec<_>>(), vec![0.0, 0.5]);
}

// ---------------------------------------------------------------- records at run time

fn small_record() -> Record {
    Record::from_samples(vec![0.0, 0.1, 0.3, 0.4], vec![1.0, -2.0, 4.0, 0.5]).unwrap()
}

#[test]
fn record_breakpoints_are_exactly_the_sample_times() {
    for r in [small_record(), read_at2(&data("at2_npts_dt.AT2")).unwrap()] {
        let times: Vec<f64> = r.times().collect();
        let gm = GroundMotion::from_record(Axis::Y, r, 2.0).unwrap();
        let mut t = -1.0;
        let mut seen = Vec::new();
        while let Some(b) = gm.next_breakpoint(t) {
            assert!(b > t);
            seen.push(b);
            t = b;
        }
        assert_eq!(seen, times);
        // From inside a segment: the next sample.
        assert_eq!(
            gm.next_breakpoint(0.5 * (times[1] + times[2])),
            Some(times[2])
        );
    }
}

#[test]
fn record_interpolation_midpoints_and_outside() {
    let r = small_record();
    let gm = GroundMotion::from_record(Axis::Z, r.clone(), 1.0).unwrap();
    let t: Vec<f64> = r.times().collect();
    let a = r.accel();
    for i in 0..r.len() - 1 {
        let mid = 0.5 * (t[i] + t[i + 1]);
        assert_relative_eq!(
            gm.acceleration(mid).z,
            0.5 * (a[i] + a[i + 1]),
            epsilon = 1e-14
        );
        assert_eq!(gm.acceleration(t[i]).z, a[i]);
    }
    assert_eq!(gm.acceleration(0.4).z, 0.5); // last sample itself
    assert_eq!(gm.acceleration(0.4 + 1e-12).z, 0.0);
    assert_eq!(gm.acceleration(-1e-12).z, 0.0);
    assert_eq!(gm.acceleration_limit(0.4, Side::Before).z, 0.5);
    assert_eq!(gm.acceleration_limit(0.4, Side::After).z, 0.0);
    assert_eq!(gm.acceleration_limit(0.0, Side::Before).z, 0.0);
    assert_eq!(gm.acceleration_limit(0.0, Side::After).z, 1.0);
    assert_eq!(gm.acceleration(0.2).x, 0.0);
    assert_eq!(gm.duration(), 0.4);
    assert_eq!(gm.pga(), Vector3::new(0.0, 0.0, 4.0));
}

#[test]
fn record_velocity_is_the_trapezoidal_integral() {
    let r = small_record();
    let gm = GroundMotion::from_record(Axis::X, r.clone(), 3.0).unwrap();
    let t: Vec<f64> = r.times().collect();
    let a = r.accel();
    let mut trapz = 0.0;
    assert_eq!(gm.velocity(0.0).x, 0.0);
    for i in 1..r.len() {
        trapz += 0.5 * (t[i] - t[i - 1]) * (a[i - 1] + a[i]);
        assert_relative_eq!(gm.velocity(t[i]).x, 3.0 * trapz, epsilon = 1e-14);
    }
    // Constant after the record; exact inside a segment (integral of a linear function).
    assert_relative_eq!(gm.velocity(10.0).x, 3.0 * trapz, epsilon = 1e-14);
    let tm = 0.2; // in [0.1, 0.3]: a = -2 + 30 (t − 0.1)
    let exact = 0.5 * 0.1 * (1.0 - 2.0) + (-2.0 * 0.1 + 15.0 * 0.01);
    assert_relative_eq!(gm.velocity(tm).x, 3.0 * exact, epsilon = 1e-14);
}

#[test]
fn record_constructor_errors() {
    assert!(Record::uniform(0.0, vec![1.0, 2.0]).is_err());
    assert!(Record::uniform(0.1, vec![1.0]).is_err());
    assert!(Record::uniform(0.1, vec![1.0, f64::NAN]).is_err());
    // Three samples 1e308 s apart end at 2e308 s: no time.
    assert!(Record::uniform(1e308, vec![1.0, 2.0, 3.0]).is_err());
    assert!(Record::uniform(1e308, vec![1.0, 2.0]).is_ok());
    assert!(Record::from_samples(vec![0.0, 0.0], vec![1.0, 2.0]).is_err());
    assert!(Record::from_samples(vec![0.0, 1.0], vec![1.0]).is_err());
    assert!(GroundMotion::from_record(Axis::X, small_record(), f64::INFINITY).is_err());
}

proptest! {
    #[test]
    fn uniform_record_breakpoint_inside_segment(n in 2usize..200, dt in 1e-4f64..0.1, frac in 0.0f64..1.0) {
        let r = Record::uniform(dt, vec![1.0; n]).unwrap();
        let gm = GroundMotion::from_record(Axis::X, r, 1.0).unwrap();
        let i = ((n - 1) as f64 * frac) as usize % (n - 1);
        let ti = i as f64 * dt;
        let next = (i + 1) as f64 * dt;
        prop_assert_eq!(gm.next_breakpoint(ti), Some(next));
        let inside = ti + 0.5 * dt;
        prop_assert_eq!(gm.next_breakpoint(inside), Some(next));
        prop_assert_eq!(gm.next_breakpoint((n - 1) as f64 * dt), None);
    }
}

// ---------------------------------------------------------------- analytic signals

#[test]
fn sine_matches_formula_inside_and_is_zero_outside() {
    let (a, period, phase, start) = (2.0, 0.5, 0.3, 0.25);
    let gm = component(sine(a, period, phase, Some(3.0), start));
    for t in [0.25, 0.3, 0.61, 1.0, 1.7, 1.75] {
        let expected = a * (TAU * (t - start) / period + phase).sin();
        assert_relative_eq!(gm.acceleration(t).x, expected, epsilon = 1e-12);
    }
    for t in [0.0, 0.2499, 1.7501, 5.0] {
        assert_eq!(gm.acceleration(t).x, 0.0, "t = {t}");
    }
    assert_eq!(gm.next_breakpoint(0.0), Some(0.25));
    assert_eq!(gm.next_breakpoint(0.25), Some(1.75));
    assert_eq!(gm.next_breakpoint(1.75), None);
    assert_eq!(gm.duration(), 1.75);
    assert_eq!(gm.pga().x, 2.0);
}

#[test]
fn sine_by_frequency_equals_sine_by_period() {
    let by_f = component(SignalSpec::Sine(SineSpec {
        amplitude: 1.5,
        period: None,
        frequency: Some(4.0),
        phase: 0.0,
        cycles: None,
        start: 0.0,
    }));
    let by_t = component(sine(1.5, 0.25, 0.0, None, 0.0));
    for t in [0.01, 0.1, 0.77, 3.3] {
        assert_relative_eq!(
            by_f.acceleration(t).x,
            by_t.acceleration(t).x,
            epsilon = 1e-14
        );
    }
    assert_eq!(by_f.duration(), f64::INFINITY);
}

#[test]
fn sine_velocity_closed_form() {
    let (a, period) = (2.0, 0.5);
    let gm = component(sine(a, period, 0.0, None, 0.0));
    for t in [0.0, 0.1, 0.25, 0.4, 1.3] {
        let expected = a * period / TAU * (1.0 - (TAU * t / period).cos());
        assert_relative_eq!(gm.velocity(t).x, expected, epsilon = 1e-14);
    }
    // With a window, velocity is frozen after the end (integer cycles → 0).
    let gm = component(sine(a, period, 0.0, Some(2.0), 0.0));
    assert_relative_eq!(gm.velocity(5.0).x, 0.0, epsilon = 1e-14);
}

#[test]
fn sine_velocity_matches_numerical_integral_with_phase_and_start() {
    let gm = component(sine(1.3, 0.4, 0.7, Some(2.5), 0.2));
    // Cells aligned with the window's jumps at 0.2 and 1.2 s.
    let n = 150_000;
    let t_end = 1.5;
    let h = t_end / n as f64;
    let mut sum = 0.0;
    for k in 0..n {
        let t = (k as f64 + 0.5) * h;
        sum += gm.acceleration(t).x * h;
    }
    assert_relative_eq!(gm.velocity(t_end).x, sum, epsilon = 1e-6);
}

#[test]
fn partial_sine_window_pga_is_exact() {
    // Quarter cycle from phase 0: argument in [0, π/2] → peak reached at the end.
    let gm = component(sine(3.0, 1.0, 0.0, Some(0.25), 0.0));
    assert_relative_eq!(gm.pga().x, 3.0, epsilon = 1e-15);
    // One eighth of a cycle: argument in [0, π/4] → peak sin(π/4).
    let gm = component(sine(3.0, 1.0, 0.0, Some(0.125), 0.0));
    assert_relative_eq!(gm.pga().x, 3.0 * (PI / 4.0).sin(), epsilon = 1e-15);
}

#[test]
fn one_sine_and_cosine_pulses() {
    let s = component(SignalSpec::OneSinePulse(PulseSpec {
        amplitude: 1.0,
        period: 0.4,
        start: 0.1,
    }));
    let c = component(SignalSpec::OneCosinePulse(PulseSpec {
        amplitude: 1.0,
        period: 0.4,
        start: 0.1,
    }));
    for t in [0.1, 0.2, 0.33, 0.5] {
        assert_relative_eq!(
            s.acceleration(t).x,
            (TAU * (t - 0.1) / 0.4).sin(),
            epsilon = 1e-14
        );
        assert_relative_eq!(
            c.acceleration(t).x,
            (TAU * (t - 0.1) / 0.4).cos(),
            epsilon = 1e-14
        );
    }
    assert_eq!(c.acceleration(0.0999).x, 0.0);
    assert_eq!(c.acceleration(0.5001).x, 0.0);
    assert_eq!(c.acceleration_limit(0.1, Side::Before).x, 0.0);
    assert_eq!(c.acceleration_limit(0.5, Side::After).x, 0.0);
    assert_relative_eq!(
        c.acceleration_limit(0.5, Side::Before).x,
        1.0,
        epsilon = 1e-14
    );
    assert_eq!(s.duration(), 0.5);
    assert_eq!(c.next_breakpoint(0.1), Some(0.5));
    // Velocities: sine pulse → A T/2π (1 − cos), cosine pulse → A T/2π sin.
    let t = 0.27;
    let u = TAU * (t - 0.1) / 0.4;
    assert_relative_eq!(
        s.velocity(t).x,
        0.4 / TAU * (1.0 - u.cos()),
        epsilon = 1e-14
    );
    assert_relative_eq!(c.velocity(t).x, 0.4 / TAU * u.sin(), epsilon = 1e-14);
    assert_relative_eq!(s.velocity(2.0).x, 0.0, epsilon = 1e-14);
    assert_eq!(c.velocity(2.0).x, 0.0);
}

#[test]
fn rectangular_pulse_velocity_is_a_times_min() {
    let (a, start, d) = (-1.5, 0.3, 0.2);
    let gm = component(SignalSpec::RectangularPulse(RectangularPulseSpec {
        amplitude: a,
        duration: d,
        start,
    }));
    for t in [0.0, 0.3, 0.35, 0.5, 0.9] {
        let expected = if t <= start {
            0.0
        } else {
            a * (t - start).min(d)
        };
        assert_eq!(gm.velocity(t).x, expected, "t = {t}");
    }
    assert_eq!(gm.acceleration(0.4).x, a);
    assert_eq!(gm.acceleration(0.6).x, 0.0);
    assert_eq!(gm.next_breakpoint(0.0), Some(0.3));
    assert_eq!(gm.next_breakpoint(0.3), Some(0.3 + 0.2));
    assert_eq!(gm.duration(), 0.3 + 0.2);
    assert_eq!(gm.pga().x, 1.5);
}

#[test]
fn ricker_value_velocity_and_duration() {
    let (a, f, c) = (2.0, 2.5, 1.0);
    let gm = component(SignalSpec::Ricker(RickerSpec {
        amplitude: a,
        frequency: f,
        center: c,
    }));
    let ricker = |t: f64| {
        let x = (PI * f * (t - c)).powi(2);
        a * (1.0 - 2.0 * x) * (-x).exp()
    };
    for t in [0.0, 0.8, 1.0, 1.13] {
        assert_relative_eq!(gm.acceleration(t).x, ricker(t), epsilon = 1e-14);
    }
    assert_eq!(gm.acceleration(c).x, a);
    assert_eq!(gm.next_breakpoint(0.0), None);
    assert_eq!(gm.duration(), c + 3.0 / f);
    // Closed-form velocity vs midpoint rule.
    let n = 100_000;
    let h = 2.0 / n as f64;
    let sum: f64 = (0..n).map(|k| ricker((k as f64 + 0.5) * h) * h).sum();
    assert_relative_eq!(gm.velocity(2.0).x, sum, epsilon = 1e-8);
}

#[test]
fn constant_and_none() {
    let gm = component(SignalSpec::Constant(ConstantSpec { value: 0.7 }));
    assert_eq!(gm.acceleration(123.0).x, 0.7);
    assert_relative_eq!(gm.velocity(2.0).x, 1.4, epsilon = 1e-15);
    assert_eq!(gm.duration(), f64::INFINITY);
    assert_eq!(gm.next_breakpoint(0.0), None);
    let none = GroundMotion::none();
    assert!(none.is_none());
    assert_eq!(none.acceleration(1.0), Vector3::zeros());
    assert_eq!(none.velocity(1.0), Vector3::zeros());
    assert_eq!(none.duration(), 0.0);
    assert_eq!(none.next_breakpoint(0.0), None);
}

#[test]
fn scale_multiplies_acceleration_velocity_and_pga() {
    let spec = ComponentSpec {
        signal: SignalSpec::Constant(ConstantSpec { value: -2.0 }),
        scale: 1.5,
    };
    let gm = GroundMotion::none()
        .with_component(Axis::Z, &spec, Path::new("."))
        .unwrap();
    assert_eq!(gm.acceleration(0.0), Vector3::new(0.0, 0.0, -3.0));
    assert_relative_eq!(gm.velocity(2.0).z, -6.0);
    assert_eq!(gm.pga().z, 3.0);
}

#[test]
fn next_breakpoint_is_the_minimum_over_components() {
    let spec = GroundMotionSpec {
        x: Some(ComponentSpec::new(sine(1.0, 1.0, 0.0, Some(1.0), 0.5))),
        y: Some(ComponentSpec::new(SignalSpec::RectangularPulse(
            RectangularPulseSpec {
                amplitude: 1.0,
                duration: 1.0,
                start: 0.75,
            },
        ))),
        z: None,
    };
    let gm = GroundMotion::from_spec(&spec, Path::new(".")).unwrap();
    let mut t = 0.0;
    let mut seen = Vec::new();
    while let Some(b) = gm.next_breakpoint(t) {
        seen.push(b);
        t = b;
    }
    assert_eq!(seen, vec![0.5, 0.75, 1.5, 1.75]);
    assert_eq!(gm.duration(), 1.75);
}

// ---------------------------------------------------------------- validation

#[test]
fn invalid_parameters_name_component_and_field() {
    let base = Path::new(".");
    let build = |axis: Axis, signal: SignalSpec| {
        GroundMotion::none().with_component(axis, &ComponentSpec::new(signal), base)
    };
    assert_eq!(
        err_string(build(Axis::X, sine(1.0, 0.0, 0.0, None, 0.0))),
        "ground_motion.x.sine: period must be positive, got 0"
    );
    assert_eq!(
        err_string(build(Axis::Y, sine(f64::NAN, 1.0, 0.0, None, 0.0))),
        "ground_motion.y.sine: amplitude must be finite, got NaN"
    );
    assert_eq!(
        err_string(build(Axis::Z, sine(1.0, 1.0, 0.0, Some(-1.0), 0.0))),
        "ground_motion.z.sine: cycles must be positive, got -1"
    );
    let both = SignalSpec::Sine(SineSpec {
        amplitude: 1.0,
        period: Some(1.0),
        frequency: Some(1.0),
        phase: 0.0,
        cycles: None,
        start: 0.0,
    });
    assert!(err_string(build(Axis::X, both)).contains("not both"));
    assert_eq!(
        err_string(build(
            Axis::X,
            SignalSpec::Ricker(RickerSpec {
                amplitude: 1.0,
                frequency: -2.0,
                center: 1.0
            })
        )),
        "ground_motion.x.ricker: frequency must be positive, got -2"
    );
    assert_eq!(
        err_string(build(
            Axis::Y,
            SignalSpec::RectangularPulse(RectangularPulseSpec {
                amplitude: 1.0,
                duration: 0.0,
                start: 0.0
            })
        )),
        "ground_motion.y.rectangular_pulse: duration must be positive, got 0"
    );
    let scaled = ComponentSpec {
        signal: SignalSpec::Constant(ConstantSpec { value: 1.0 }),
        scale: f64::INFINITY,
    };
    assert_eq!(
        err_string(GroundMotion::none().with_component(Axis::X, &scaled, base)),
        "ground_motion.x: scale must be finite, got inf"
    );
}

/// Accelerations whose peak overflows, or is finite but beyond any ground motion, are refused
/// naming the component (a constant 1e308 m/s² used to leave a block at rest: its forces were
/// infinite and the uplift test compared NaN); the bound itself is accepted, and a record's
/// peak counts with its scale.
#[test]
fn accelerations_beyond_any_ground_motion_are_refused() {
    let base = Path::new(".");
    let build = |signal: SignalSpec, scale: f64| {
        GroundMotion::none().with_component(Axis::X, &ComponentSpec { signal, scale }, base)
    };
    let constant = |value: f64| SignalSpec::Constant(ConstantSpec { value });
    let pulse = SignalSpec::RectangularPulse(RectangularPulseSpec {
        amplitude: -1e308,
        duration: 0.1,
        start: 0.5,
    });
    for (signal, scale) in [
        (constant(1e308), 1.0),
        (pulse, 1.0),
        (sine(1e300, 0.5, 0.0, None, 0.0), 1e300),
        (constant(1.0), 1.000001e6),
    ] {
        let e = err_string(build(signal, scale));
        assert!(
            e.starts_with("ground_motion.x: its peak acceleration") && e.contains("at most 1e6"),
            "{e}"
        );
    }
    let at_bound = build(constant(-1.0), MAX_GROUND_ACCELERATION).expect("the bound is allowed");
    assert_eq!(at_bound.pga().x, MAX_GROUND_ACCELERATION);
    let record = read_table(
        &data("accel_cm.csv"),
        &TableOptions::new(RecordFormat::Csv, Units::CentimetersPerSecondSquared),
    )
    .expect("the test record");
    let e = err_string(GroundMotion::from_record(Axis::Y, record, 1e308));
    assert!(
        e.starts_with("ground_motion.y: its peak acceleration"),
        "{e}"
    );
}

fn record_spec(file: &str, format: RecordFormat, units: Option<Units>) -> SignalSpec {
    SignalSpec::Record(RecordSpec {
        file: PathBuf::from(file),
        format,
        units,
        time_column: None,
        accel_column: None,
        skip_rows: None,
    })
}

#[test]
fn record_spec_resolves_relative_paths_against_base_dir() {
    let spec = GroundMotionSpec {
        x: None,
        y: Some(ComponentSpec {
            signal: record_spec("at2_old_layout.AT2", RecordFormat::PeerAt2, None),
            scale: 1.5,
        }),
        z: Some(ComponentSpec::new(record_spec(
            "accel_cm.csv",
            RecordFormat::Csv,
            Some(Units::CentimetersPerSecondSquared),
        ))),
    };
    let gm = GroundMotion::from_spec(&spec, &data_dir()).unwrap();
    assert_relative_eq!(gm.acceleration(0.0).y, 1.5 * 0.1 * G0, epsilon = 1e-15);
    assert_eq!(gm.acceleration(0.01).z, 0.125);
    assert_relative_eq!(
        gm.pga(),
        Vector3::new(0.0, 1.5 * 0.8 * G0, 0.3),
        epsilon = 1e-14
    );
    assert_eq!(gm.duration(), 0.05);
    assert!(gm.record(Axis::Y).is_some());
    assert!(gm.record(Axis::X).is_none());
}

#[test]
fn record_spec_errors_carry_context_and_path() {
    let base = data_dir();
    let build = |signal: SignalSpec| {
        GroundMotion::none().with_component(Axis::Y, &ComponentSpec::new(signal), &base)
    };
    let msg = err_string(build(record_spec(
        "at2_bad_token.AT2",
        RecordFormat::PeerAt2,
        None,
    )));
    assert!(msg.starts_with("ground_motion.y.record: "), "{msg}");
    assert!(
        msg.contains("at2_bad_token.AT2:6: invalid number `abc`"),
        "{msg}"
    );
    let msg = err_string(build(record_spec("accel_cm.csv", RecordFormat::Csv, None)));
    assert!(msg.contains("units are required for csv"), "{msg}");
    let msg = err_string(build(record_spec(
        "at2_old_layout.AT2",
        RecordFormat::PeerAt2,
        Some(Units::CentimetersPerSecondSquared),
    )));
    assert!(msg.contains("always in g"), "{msg}");
    let msg = err_string(build(record_spec(
        "missing.AT2",
        RecordFormat::PeerAt2,
        None,
    )));
    assert!(msg.contains("missing.AT2: cannot read file"), "{msg}");
}

#[test]
fn spec_enums_parse_from_strings() {
    assert_eq!(
        "peer-at2".parse::<RecordFormat>(),
        Ok(RecordFormat::PeerAt2)
    );
    assert_eq!("CSV".parse::<RecordFormat>(), Ok(RecordFormat::Csv));
    assert_eq!(
        "cm/s2".parse::<Units>(),
        Ok(Units::CentimetersPerSecondSquared)
    );
    assert_eq!("m/s2".parse::<Units>(), Ok(Units::MetersPerSecondSquared));
    assert_eq!("y".parse::<Axis>(), Ok(Axis::Y));
    assert!("w".parse::<Axis>().is_err());
    assert_eq!(Units::G.to_si(1.0), 9.80665);
}

/// `is_affine_on` claims a(t) is affine on an interval without breakpoints: where it says so,
/// five equally spaced values lie on the line through the ends (to round-off of the
/// interpolation, 1e-12 of the peak); a sine inside its window is not affine (its second
/// difference is of order A(2πΔt/T)², far above round-off), and it is after its window.
#[test]
fn is_affine_on_holds_where_claimed() {
    let collinear = |gm: &GroundMotion, t0: f64, t1: f64| {
        let (a0, a1) = (gm.acceleration(t0).x, gm.acceleration(t1).x);
        (1..4).all(|i| {
            let t = t0 + (t1 - t0) * i as f64 / 4.0;
            let line = a0 + (a1 - a0) * i as f64 / 4.0;
            (gm.acceleration(t).x - line).abs() <= 1e-12 * a0.abs().max(a1.abs()).max(1.0)
        })
    };
    let record = GroundMotion::from_record(
        Axis::X,
        Record::uniform(0.01, vec![0.0, 1.5, -2.0, 0.3, 0.0]).unwrap(),
        1.0,
    )
    .unwrap();
    let mut t = 0.0;
    while let Some(b) = record.next_breakpoint(t) {
        assert!(
            record.is_affine_on(t, b) && collinear(&record, t, b),
            "[{t}, {b}]"
        );
        t = b;
    }
    let pulse = component(sine(2.0, 0.5, 0.0, Some(1.0), 0.1));
    assert!(pulse.is_affine_on(0.0, 0.1) && collinear(&pulse, 0.0, 0.1));
    assert!(!pulse.is_affine_on(0.2, 0.3) && !collinear(&pulse, 0.2, 0.3));
    assert!(pulse.is_affine_on(0.6, 2.0) && collinear(&pulse, 0.6, 2.0));
    let step = component(SignalSpec::RectangularPulse(RectangularPulseSpec {
        amplitude: 1.0,
        duration: 0.2,
        start: 0.1,
    }));
    assert!(step.is_affine_on(0.1, 0.3) && collinear(&step, 0.15, 0.25));
}
