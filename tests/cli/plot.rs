//! `crr simulate … --plot`, `crr plot DIR` and `crr check MODEL --plot DIR`: the PNG and SVG files
//! documented in docs/outputs.md ("Plots"), drawn with the embedded font (no system font is
//! needed: a missing font makes plotters fail with FontUnavailable), and the error on a missing
//! results folder.

use crate::common::{crr, scratch};
use std::path::Path;

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

/// A PNG of 1000 × 700 pixels (width and height of the IHDR chunk) with enough content to be a
/// drawn plot rather than a blank image.
fn assert_png(file: &Path) {
    let bytes = std::fs::read(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    assert_eq!(bytes[..8], PNG_SIGNATURE, "{}", file.display());
    assert_eq!(&bytes[12..16], b"IHDR");
    let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((width, height), (1000, 700), "{}", file.display());
    assert!(
        bytes.len() > 10_000,
        "{}: {} bytes",
        file.display(),
        bytes.len()
    );
}

/// An SVG holding the given texts (axis labels, legend entries).
fn assert_svg(file: &Path, texts: &[&str]) {
    let svg = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    assert!(svg.contains("<svg"), "{}", file.display());
    for t in texts {
        assert!(svg.contains(t), "{}: no text {t:?}", file.display());
    }
}

#[test]
fn simulate_plot_writes_the_three_plots_of_the_single_block() {
    let out = scratch("plot_single_block");
    let o = crr(&[
        "simulate",
        "examples/models/single_block.toml",
        "--duration",
        "3",
        "--out",
        out.to_str().unwrap(),
        "--plot",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for stem in ["coordinates", "energy", "phase"] {
        assert_png(&out.join(format!("{stem}.png")));
    }
    assert_svg(
        &out.join("coordinates.svg"),
        &["time t (s)", "angle (rad)", "base (rad)", "impact ("],
    );
    assert_svg(
        &out.join("energy.svg"),
        &[
            "energy (J)",
            "balance error (J)",
            "kinetic T (J)",
            "dissipated D (J)",
        ],
    );
    // A one-coordinate block: the free-rocking levels with α = atan(0.2/1.0) = 0.1974 rad and
    // p = √(3g/4R) = 2.6860 rad/s (R = √(0.2² + 1²) m) are drawn and named in the legend.
    assert_svg(
        &out.join("phase.svg"),
        &[
            "angle θ (rad)",
            "rate dθ/dt (rad/s)",
            "α = 0.1974 rad, p = 2.6860 rad/s",
        ],
    );

    // `crr plot` on the same folder redraws the same files and lists them.
    let o = crr(&["plot", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let listed = String::from_utf8_lossy(&o.stdout);
    assert_eq!(listed.lines().count(), 6, "{listed}");
    assert!(listed.contains("phase.svg"));
    // A run that keeps every hypothesis shades nothing.
    for stem in ["coordinates", "energy"] {
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg"))).unwrap();
        assert!(!svg.contains("outside crr"), "{stem}.svg");
    }
}

/// The time histories and the energy balance of a run that leaves crr's model shade the time
/// after its first hypotheses violation and name it in the legend, at the time and interface
/// `summary.json` gives: the bundled drum column, whose bed under the seventh drum would have to
/// pull at 0.5028 s (the drums above hop, tests/cli/warnings.rs).
#[test]
fn plots_shade_the_time_outside_the_model() {
    let out = scratch("plot_outside_model");
    let o = crr(&[
        "simulate",
        "examples/models/drum_column.toml",
        "--out",
        out.to_str().unwrap(),
        "--plot",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let v = &summary["hypothesis_violation"];
    let label = format!(
        "outside crr's model from t = {:.4} s ({} at {})",
        v["time"].as_f64().unwrap(),
        v["kind"].as_str().unwrap(),
        v["interface"].as_str().unwrap()
    );
    assert_eq!(
        label,
        "outside crr's model from t = 0.5028 s (tension at bed_7)"
    );
    for stem in ["coordinates", "energy"] {
        assert_png(&out.join(format!("{stem}.png")));
        // (plotters writes the apostrophe as an entity in SVG text.)
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg")))
            .unwrap()
            .replace("&apos;", "'")
            .replace("&#39;", "'");
        assert!(svg.contains(&label), "{stem}.svg: no {label:?}");
    }
}

#[test]
fn plot_of_a_multi_coordinate_model_has_no_free_rocking_levels() {
    let out = scratch("plot_trilithon");
    let o = crr(&[
        "simulate",
        "examples/models/trilithon.toml",
        "--duration",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--plot",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_png(&out.join("phase.png"));
    let phase = std::fs::read_to_string(out.join("phase.svg")).unwrap();
    assert!(phase.contains("base_left") && phase.contains("top_left"));
    assert!(!phase.contains("free rocking"));
}

#[test]
fn check_plot_writes_the_housner_frequency_plot() {
    let out = scratch("plot_check");
    let o = crr(&[
        "check",
        "examples/models/single_block.toml",
        "--plot",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_png(&out.join("housner.png"));
    // p = 2.6860 rad/s and α_eq = 0.1974 rad of the block appear in the legend and axis label.
    assert_svg(
        &out.join("housner.svg"),
        &[
            "frequency (Hz)",
            "α_eq = 0.1974 rad",
            "p = 2.6860 rad/s",
            "engine",
        ],
    );
}

#[test]
fn plot_of_a_missing_folder_is_an_input_error_naming_it() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("no_such_results_folder");
    let _ = std::fs::remove_dir_all(&dir);
    let o = crr(&["plot", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("no_such_results_folder"), "{err}");
    assert!(err.starts_with("crr: error:"), "{err}");
}

#[test]
fn plot_of_a_folder_without_results_names_the_missing_file() {
    let dir = scratch("plot_empty_folder");
    let o = crr(&["plot", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("summary.json"), "{err}");
}

#[test]
fn check_plot_of_a_model_without_one_dof_mechanism_fails_and_writes_nothing() {
    let out = scratch("plot_check_two_blocks");
    // Two stacked blocks: DOF(2) = 2, no single equivalent block, so no frequency table.
    let o = crr(&[
        "check",
        "examples/models/two_block_stack.toml",
        "--plot",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("no frequency plot: DOF(2) = 2"), "{err}");
    assert!(!out.join("housner.png").exists() && !out.join("housner.svg").exists());
}

/// Every bundled model simulates (a short run) and plots: three PNGs of the documented size and
/// SVGs naming each coordinate in the legend.
#[test]
fn every_bundled_model_simulates_and_plots() {
    for (m, d) in [
        ("single_block", "1"),
        ("trilithon", "1"),
        ("arch", "0.5"),
        ("two_block_stack", "1"),
        ("baldachin", "1"),
        ("drum_column", "0.3"),
        ("block_record", "3"),
        ("trilithon_dirac", "1"),
        ("arch_dirac", "0.5"),
    ] {
        let out = scratch(&format!("plot_all_{m}"));
        let o = crr(&[
            "simulate",
            &format!("examples/models/{m}.toml"),
            "--duration",
            d,
            "--out",
            out.to_str().unwrap(),
            "--plot",
            "--quiet",
        ]);
        assert!(
            o.status.success(),
            "{m}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        for stem in ["coordinates", "energy", "phase"] {
            assert_png(&out.join(format!("{stem}.png")));
        }
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let names: Vec<String> = summary["coordinates"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| format!("{} (rad)", c["name"].as_str().unwrap()))
            .collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        assert_svg(&out.join("coordinates.svg"), &names);
    }
}

/// `crr check --plot DIR` into a folder that holds an earlier check's plots is refused (exit 2,
/// naming the folder and a file) unless `--force`, which replaces them; the refused run leaves
/// the earlier plots as they were.
#[test]
fn check_plot_does_not_overwrite_without_force() {
    let out = scratch("plot_check_force");
    let args = |force: bool| {
        let mut a = vec![
            "check",
            "examples/models/single_block.toml",
            "--plot",
            out.to_str().unwrap(),
        ];
        if force {
            a.push("--force");
        }
        crr(&a)
    };
    assert!(args(false).status.success());
    let before = std::fs::read(out.join("housner.svg")).unwrap();
    let o = args(false);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("pass --force"), "{err}");
    assert_eq!(std::fs::read(out.join("housner.svg")).unwrap(), before);
    assert!(args(true).status.success());
}
