//! The bundled synthetic accelerogram `examples/records/synthetic.AT2`: it reads as a PEER AT2
//! record with the stated NPTS, DT and PGA, and `crr::input::synthetic` regenerates it byte for byte.

use std::path::Path;

use crr::dynamics::ground_motion::{STANDARD_GRAVITY, read_at2};
use crr::input::synthetic;

fn bundled() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(synthetic::FILE)
}

#[test]
fn reads_with_the_stated_npts_dt_and_pga() {
    let record = read_at2(&bundled()).expect("the bundled record reads");
    assert!(record.warnings().is_empty(), "{:?}", record.warnings());
    assert_eq!(record.len(), 2001);
    assert_eq!(record.dt(), Some(0.01));
    assert_eq!(STANDARD_GRAVITY, 9.80665);
    let pga_g = record.peak() / STANDARD_GRAVITY;
    assert!((pga_g - 0.25).abs() < 1e-6, "PGA {pga_g} g");
    // Starts at rest (envelope 0 at t = 0) and ends with ~0 ground velocity (baseline
    // correction; the 7 significant digits of the file leave a round-off).
    assert_eq!(record.accel()[0], 0.0);
    let v_end: f64 = record
        .accel()
        .windows(2)
        .map(|w| 0.5 * 0.01 * (w[0] + w[1]))
        .sum();
    assert!(v_end.abs() < 1e-6, "final ground velocity {v_end} m/s");
}

#[test]
fn regenerating_gives_the_same_bytes() {
    let committed = std::fs::read_to_string(bundled()).expect("the bundled record exists");
    assert!(
        committed == synthetic::at2_text(),
        "examples/records/synthetic.AT2 differs from crr::input::synthetic::at2_text(); \
         regenerate with `cargo run --example make_record`"
    );
    let lines: Vec<&str> = committed.lines().collect();
    assert_eq!(lines[3], "NPTS=  2001, DT=   .0100 SEC");
    assert_eq!(lines.len(), 4 + 2001_usize.div_ceil(5));
    assert!(lines[4..lines.len() - 1].iter().all(|l| l.len() == 70));
}

#[test]
fn band_limit_and_envelope_are_as_documented() {
    let f3 = synthetic::half_power_frequency();
    assert!((f3 - 4.64).abs() < 0.01, "{f3}");
    assert!(synthetic::band_gain(15.0) < 0.01);
    assert_eq!(synthetic::envelope(0.0), 0.0);
    assert_eq!(synthetic::envelope(1.0), 0.5);
    assert_eq!(synthetic::envelope(2.0), 1.0);
    assert_eq!(synthetic::envelope(10.0), 1.0);
    assert!((synthetic::envelope(12.5) - (-1.0f64).exp()).abs() < 1e-15);
    assert_eq!(synthetic::fortran_e(-0.012345678), " -.1234568E-01");
    assert_eq!(synthetic::fortran_e(0.25), "  .2500000E+00");
    assert_eq!(synthetic::fortran_e(0.0), "  .0000000E+00");
}

/// The second horizontal component (`synthetic_y.AT2`, the temple's y): the same procedure with
/// another seed, byte-identical to what `cargo run --example make_record` writes, PGA 0.25 g,
/// and another signal than the first component.
#[test]
fn the_second_component_regenerates_and_differs() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(synthetic::FILE_Y);
    let committed = std::fs::read_to_string(&path).expect("the second component exists");
    assert!(
        committed == synthetic::at2_text_with_seed(synthetic::SEED_Y),
        "{} differs; regenerate with `cargo run --example make_record`",
        synthetic::FILE_Y
    );
    let a = synthetic::accelerogram_with_seed(synthetic::SEED_Y);
    let peak = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!((peak - synthetic::PGA_G).abs() < 1e-15);
    let b = synthetic::accelerogram();
    let diff = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(
        diff > 0.1 * synthetic::PGA_G,
        "the components differ by {diff} g at most"
    );
}
