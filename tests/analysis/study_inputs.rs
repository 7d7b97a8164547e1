//! Study inputs beyond the ground motion: the spectral-acceleration intensity measure and the
//! impact law of the whole model.

use std::path::Path;

use crr::analysis::study::Study;
use crr::analysis::study::cases::{IntensityMeasure, Motion, spectral_acceleration};
use crr::dynamics::ground_motion::Record;
use crr::kinematics::ImpactLaw;

/// A harmonic record at the oscillator's own period: after the transient (e^(−ζωt) ≈ e^(−31)
/// after 100 periods at ζ = 0.05) the response is A/(2ζω²), so Sa = ω²·max|u| = A/(2ζ); the
/// peak is read at samples T/200 apart (1 − cos(π/200) ≈ 1.2e-4 below the crest).
#[test]
fn spectral_acceleration_at_resonance_is_a_over_two_zeta() {
    let (period, amplitude) = (0.5, 1.3);
    let dt = period / 200.0;
    let w = 2.0 * std::f64::consts::PI / period;
    let accel: Vec<f64> = (0..=20_000)
        .map(|i| amplitude * (w * i as f64 * dt).sin())
        .collect();
    let record = Record::uniform(dt, accel).unwrap();
    for zeta in [0.05, 0.02] {
        let sa = spectral_acceleration(&record, period, zeta).unwrap();
        let want = amplitude / (2.0 * zeta);
        assert!(
            (sa / want - 1.0).abs() < 1e-3,
            "ζ = {zeta}: Sa {sa} vs {want}"
        );
    }
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn records_scale_to_spectral_levels_and_the_impact_law_is_replaced() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("study_inputs");
    let model = root.join("examples/models/single_block.toml");
    let record = root.join("examples/records/synthetic.AT2");
    let file = write(
        &dir,
        "sa.toml",
        &format!(
            "model = \"{}\"\nimpact = {{ restitution = 0.9 }}\n[records]\nfiles = [\"{}\"]\nformat = \"peer-at2\"\n\
             [intensity]\nsa = {{ period = 0.8, levels = [0.2, 0.5] }}\n",
            model.display(),
            record.display()
        ),
    );
    let study = Study::load(&file).expect("a valid study");
    assert!(
        study
            .model
            .interfaces
            .iter()
            .all(|i| i.impact == ImpactLaw::Restitution(0.9))
    );
    assert_eq!(
        study.intensity,
        IntensityMeasure::Sa {
            period: 0.8,
            damping: 0.05
        }
    );
    // The factor brings the record's Sa(0.8 s) to the level: Sa is linear in the record.
    let rec = study.records[0].record.as_ref().unwrap();
    let sa = spectral_acceleration(rec, 0.8, 0.05).unwrap() / 9.80665;
    for case in &study.cases {
        let Motion::Record { level, factor, .. } = case.motion else {
            panic!("a records study");
        };
        assert!((factor.unwrap() * sa - level).abs() < 1e-12 * level);
    }
    // Bad values are refused naming the key.
    for (text, key) in [
        (
            "sa = { period = 0.0, levels = [0.2] }",
            "intensity.sa.period",
        ),
        (
            "sa = { period = 1.0, damping = 1.5, levels = [0.2] }",
            "intensity.sa.damping",
        ),
    ] {
        let bad = write(
            &dir,
            "bad.toml",
            &format!(
                "model = \"{}\"\n[records]\nfiles = [\"{}\"]\nformat = \"peer-at2\"\n[intensity]\n{text}\n",
                model.display(),
                record.display()
            ),
        );
        let err = Study::load(&bad).unwrap_err().to_string();
        assert!(err.contains(key), "{err}");
    }
    let bad = write(
        &dir,
        "bad_impact.toml",
        &format!(
            "model = \"{}\"\nimpact = {{ restitution = 1.5 }}\n[pulses]\nkind = \"one_sine_pulse\"\namplitudes = [3.0]\nperiods = [0.5]\n",
            model.display()
        ),
    );
    let err = Study::load(&bad).unwrap_err().to_string();
    assert!(err.contains("impact"), "{err}");
}

/// A range whose count is not a whole number ≥ 1 is refused with its own message (issue:
/// `count = -3` said "data did not match any variant of untagged enum Values").
#[test]
fn a_range_count_below_one_is_named() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("study_bad_count");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
    for (count, shown) in [("-3", "-3"), ("0", "0"), ("2.5", "2.5")] {
        let text = format!(
            "name = \"bad\"\nmodel = \"{}\"\nduration = 1.0\n\n[pulses]\nkind = \"one_sine_pulse\"\n\
             amplitude_ratios = {{ from = 1.0, to = 2.0, count = {count} }}\n\
             frequency_ratios = {{ from = 1.0, to = 2.0, count = 2 }}\n",
            model.display()
        );
        let bad = write(&dir, "bad.toml", &text);
        let err = Study::load(&bad).unwrap_err().to_string();
        assert!(
            err.contains(&format!(
                "count must be a whole number ≥ 1 in {{ from, to, count }}, got {shown}"
            )),
            "{count}: {err}"
        );
    }
}

/// A study too large is refused before its cases are listed (issue: a 100 000 × 100 000 grid
/// filled 18 GB within 30 s, and `count = 10000000000000` aborted on an 80 TB allocation): an
/// axis holds at most `MAX_AXIS_VALUES` values, a study at most `MAX_STUDY_CASES` cases.
#[test]
fn a_study_too_large_is_refused_before_anything_is_allocated() {
    use crr::analysis::study::cases::MAX_STUDY_CASES;
    use crr::analysis::study::spec::MAX_AXIS_VALUES;
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("study_too_large");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
    let grid = |a: u64, f: u64| {
        format!(
            "name = \"big\"\nmodel = \"{}\"\nduration = 1.0\n\n[pulses]\nkind = \"one_sine_pulse\"\n\
             amplitude_ratios = {{ from = 1.0, to = 2.0, count = {a} }}\n\
             frequency_ratios = {{ from = 1.0, to = 2.0, count = {f} }}\n",
            model.display()
        )
    };
    for (a, f, needle) in [
        (
            10_000_000_000_000,
            20,
            format!("count must be at most {MAX_AXIS_VALUES}, got 10000000000000"),
        ),
        (
            100_000,
            100_000,
            format!(
                "amplitudes × periods × scales make 10000000000 cases, more than the {MAX_STUDY_CASES} a study may hold"
            ),
        ),
        (
            1001,
            1000,
            format!("make 1001000 cases, more than the {MAX_STUDY_CASES}"),
        ),
    ] {
        let bad = write(&dir, "big.toml", &grid(a, f));
        let err = Study::load(&bad).unwrap_err().to_string();
        assert!(err.contains(&needle), "{a} × {f}: {err}");
    }
    // At the limit it loads.
    let ok = write(&dir, "ok.toml", &grid(1000, 1000));
    assert_eq!(Study::load(&ok).unwrap().cases.len(), MAX_STUDY_CASES);
}
