//! Writes `examples/records/synthetic.AT2`, the bundled synthetic accelerogram (not a real
//! record): SplitMix64 white noise (fixed seed), 4 passes of a 5-point moving average (−3 dB at
//! ≈ 4.6 Hz), a trapezoidal–exponential envelope (rise 0–2 s, strong 2–10 s, decay τ = 2.5 s
//! after), baseline-corrected to a final ground velocity of 0, scaled to a PGA of 0.25 g; 20 s at
//! 0.01 s (NPTS = 2001). The procedure lives in `crr::input::synthetic` (also used by
//! `tests/cli/record_file.rs`, which checks the committed file is byte-identical).
//!
//! ```sh
//! cargo run --example make_record
//! ```

use std::path::Path;

use crr::input::synthetic;

fn main() -> std::io::Result<()> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(synthetic::FILE);
    synthetic::write_at2(&path)?;
    let path_y = Path::new(env!("CARGO_MANIFEST_DIR")).join(synthetic::FILE_Y);
    synthetic::write_at2_with_seed(&path_y, synthetic::SEED_Y)?;
    println!("wrote {} (seed {:#X})", path_y.display(), synthetic::SEED_Y);
    let a = synthetic::accelerogram();
    let g = crr::dynamics::ground_motion::STANDARD_GRAVITY;
    let v_end: f64 = a
        .windows(2)
        .map(|w| 0.5 * synthetic::DT * (w[0] + w[1]) * g)
        .sum();
    println!("wrote {}", path.display());
    println!(
        "NPTS = {}, DT = {} s, duration = {} s, seed = {:#X}",
        synthetic::NPTS,
        synthetic::DT,
        (synthetic::NPTS - 1) as f64 * synthetic::DT,
        synthetic::SEED
    );
    println!(
        "PGA = {:.6} g (should be {} g); band: -3 dB at {:.2} Hz; final ground velocity {:.2e} m/s (should be ~0)",
        a.iter().fold(0.0f64, |m, v| m.max(v.abs())),
        synthetic::PGA_G,
        synthetic::half_power_frequency(),
        v_end
    );
    Ok(())
}
