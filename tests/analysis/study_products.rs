//! `crr study` products and axes of issue 13: the size axis (`scales`), synthetic records by seed,
//! and the figures and fragility table of `crr plot STUDY_DIR` / `crr study --plot`.

use std::path::{Path, PathBuf};

use crate::common::{crr, scratch};
use crr::analysis::study::{Motion, Study};

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models")
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn run_ok(args: &[&str]) -> String {
    let out = crr(args);
    assert!(
        out.status.success(),
        "crr {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Runs `crr study STUDY --out OUT --quiet --plot`, which must succeed; returns its stderr.
fn study_plotted(study: &Path, out: &Path) -> String {
    let o = crr(&[
        "study",
        study.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--plot",
    ]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{err}");
    err
}

/// A JSON file read back.
fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A PNG of the project's size that is not blank, and an SVG with at least `min_shapes` drawn
/// elements.
fn assert_figure(dir: &Path, stem: &str, min_shapes: usize) {
    let png = std::fs::read(dir.join(format!("{stem}.png"))).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{stem}.png is a PNG");
    // A blank 1000 × 700 PNG compresses to a few kB; axes, labels and data take tens of kB.
    assert!(png.len() > 15_000, "{stem}.png has {} bytes", png.len());
    let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
    assert!(svg.contains("<svg"));
    let shapes = ["<rect", "<polyline", "<circle", "<line", "<path"]
        .iter()
        .map(|t| svg.matches(t).count())
        .sum::<usize>();
    assert!(
        shapes >= min_shapes,
        "{stem}.svg: {shapes} shapes, expected at least {min_shapes}"
    );
}

/// Scaling a block by s scales its lengths by s: its mass by s³ (densities kept), its height by
/// s, and its frequency parameter p = √(3g/4R) by 1/√s, so that at fixed ω_p/p the pulse period
/// T_p = 2π/(ω_p) scales by √s; a_p/(g tan α) converts to the same a_p since α is unchanged.
#[test]
fn scale_axis_scales_p_mass_and_periods() {
    let dir = scratch("study_scales");
    let study = write(
        &dir,
        "s.toml",
        &format!(
            "model = \"{}\"\nscales = [0.5, 2.0]\nduration = 3.0\n\n[pulses]\n\
             kind = \"one_sine_pulse\"\namplitude_ratios = [3.0, 4.0]\nfrequency_ratios = [2.0]\n",
            models().join("single_block.toml").display()
        ),
    );
    let s = Study::load(&study).unwrap();
    assert_eq!(s.variants.len(), 2);
    let (a, b) = (&s.variants[0], &s.variants[1]);
    let rel = |x: f64, y: f64| (x - y).abs() / y.abs();
    // Exact scalings, up to round-off of the mass and equivalent-block computations.
    assert!(rel(b.model.total_mass() / a.model.total_mass(), 64.0) < 1e-12);
    assert!(rel(a.height.unwrap(), 1.0) < 1e-12 && rel(b.height.unwrap(), 4.0) < 1e-12);
    let (pa, pb) = (a.lambda_p.unwrap().1, b.lambda_p.unwrap().1);
    assert!(rel(pa / pb, 2.0) < 1e-9, "p ∝ 1/√s: {pa} / {pb}");
    // Housner's p = √(3g/4R) of the 0.4 × 0.4 × 2 m block scaled by 0.5: R = 0.5·√(0.04 + 1).
    let r = 0.5 * (0.2f64 * 0.2 + 1.0).sqrt();
    assert!(rel(pa, (3.0 * 9.81 / (4.0 * r)).sqrt()) < 1e-9);
    assert!(rel(a.lambda_p.unwrap().0, b.lambda_p.unwrap().0) < 1e-12);
    // Case order: scale-major, then the pulse grid (amplitude-major).
    assert_eq!(s.cases.len(), 4);
    let periods: Vec<(usize, f64, f64)> = s
        .cases
        .iter()
        .map(|c| match c.motion {
            Motion::Pulse {
                amplitude, period, ..
            } => (c.variant, amplitude, period),
            _ => panic!("a pulse study"),
        })
        .collect();
    assert_eq!(
        periods.iter().map(|p| p.0).collect::<Vec<_>>(),
        [0, 0, 1, 1]
    );
    assert_eq!(s.cases[3].id, "c000003");
    assert!(rel(periods[2].2 / periods[0].2, 2.0) < 1e-9, "T_p ∝ √s");
    assert!(
        rel(periods[2].1, periods[0].1) < 1e-12,
        "a_p = r λ g, size-free"
    );
    assert!(rel(periods[1].1 / periods[0].1, 4.0 / 3.0) < 1e-12);

    // The run writes the scale and the height; the spectrum is drawn.
    let out = dir.join("out");
    run_ok(&[
        "study",
        study.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--plot",
    ]);
    let csv = std::fs::read_to_string(out.join("cases.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.starts_with("id,scale,height_m,amplitude_m_s2,"));
    assert!(csv.lines().nth(3).unwrap().starts_with("c000002,2,4,"));
    assert_figure(&out, "map", 4);
    assert_figure(&out, "spectrum", 4);
}

/// Synthetic records by seed: deterministic, every one with the family's PGA (0.25 g exactly),
/// different from seed to seed, and the bundled seed is the bundled record.
#[test]
fn synthetic_records_by_seed() {
    use crr::input::synthetic::{PGA_G, SEED, accelerogram, accelerogram_with_seed};
    let a1 = accelerogram_with_seed(1);
    assert_eq!(a1, accelerogram_with_seed(1), "same seed, same record");
    assert_eq!(accelerogram_with_seed(SEED), accelerogram());
    let a2 = accelerogram_with_seed(2);
    for a in [&a1, &a2] {
        let peak = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!((peak - PGA_G).abs() < 1e-12);
    }
    // Independent noises: the records differ by a good fraction of their PGA somewhere.
    let diff = a1
        .iter()
        .zip(&a2)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(
        diff > 0.1 * PGA_G,
        "seeds 1 and 2 differ by at most {diff} g"
    );

    // In a study: one record per seed, after the files, named by the seed.
    let dir = scratch("study_synthetic");
    let study = write(
        &dir,
        "s.toml",
        &format!(
            "model = \"{}\"\n\n[records]\nsynthetic = {{ seeds = {{ from = 3, to = 5, count = 3 }} }}\n\
             \n[intensity]\npga = [0.1]\n",
            models().join("single_block.toml").display()
        ),
    );
    let s = Study::load(&study).unwrap();
    let names: Vec<String> = s
        .records
        .iter()
        .map(|r| r.file.display().to_string())
        .collect();
    assert_eq!(names, ["synthetic:3", "synthetic:4", "synthetic:5"]);
    let rec = s.records[1].record.as_ref().unwrap();
    // PGA 0.25 g, in m/s², scaled to 0.1 g by the factor 0.4.
    assert!((rec.peak() - 0.25 * 9.80665).abs() < 1e-12);
    match s.cases[1].motion {
        Motion::Record { factor, .. } => assert!((factor.unwrap() - 0.4).abs() < 1e-12),
        _ => panic!("a records study"),
    }
    // A seed that is not a whole number is refused, naming the key.
    let bad = write(
        &dir,
        "bad.toml",
        &format!(
            "model = \"{}\"\n\n[records]\nsynthetic = {{ seeds = [1.5] }}\n",
            models().join("single_block.toml").display()
        ),
    );
    let e = Study::load(&bad).unwrap_err().to_string();
    assert!(e.contains("records.synthetic.seeds"), "{e}");
}

/// A records study of Housner's block (2 m tall, g tan α = 0.2 g) under 4 synthetic records at
/// 8 PGA levels: the fragility table and figure are written, and each fitted median lies within
/// the levels where the empirical fraction crosses 1/2 (the lognormal curve is 1/2 at its
/// median, and the maximum-likelihood curve follows the fractions).
#[test]
fn fragility_products() {
    let dir = scratch("study_fragility");
    let study = write(
        &dir,
        "f.toml",
        &format!(
            "name = \"frag\"\nmodel = \"{}\"\nduration = 21.0\n\n[records]\n\
             synthetic = {{ seeds = [1, 2, 3, 4] }}\n\n[intensity]\n\
             pga = {{ from = 0.1, to = 0.8, count = 8 }}\n",
            models().join("single_block.toml").display()
        ),
    );
    let out = dir.join("out");
    run_ok(&[
        "study",
        study.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--jobs",
        "2",
    ]);
    let listed = run_ok(&["plot", out.to_str().unwrap()]);
    assert!(listed.contains("fragility.csv") && listed.contains("fragility.png"));
    assert_figure(&out, "fragility", 8);
    let fits = std::fs::read_to_string(out.join("fragility.csv")).unwrap();
    let points = std::fs::read_to_string(out.join("fragility_points.csv")).unwrap();
    let mut lines = fits.lines();
    assert_eq!(
        lines.next().unwrap(),
        "measure,threshold,median_pga_g,dispersion,log_likelihood,levels_used,cases_used,\
         level_min,level_max,cases_outside_model"
    );
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    assert_eq!(rows.len(), 4, "collapse and three thresholds");
    let outside = violation_times(&out).iter().flatten().count();
    let mut fitted = 0;
    for r in &rows {
        assert_eq!(r[5], "8");
        assert_eq!(r[6], "32");
        assert_eq!(r[9], outside.to_string(), "cases outside the model");
        let key = format!("{},{},", r[0], r[1]);
        let fr: Vec<(f64, f64)> = points
            .lines()
            .filter(|l| l.starts_with(&key))
            .map(|l| {
                let f: Vec<f64> = l.split(',').skip(2).map(|x| x.parse().unwrap()).collect();
                (f[0], f[3])
            })
            .collect();
        assert_eq!(fr.len(), 8);
        let Ok(median) = r[2].parse::<f64>() else {
            // No fit: every case exceeded, or none.
            assert!(fr.iter().all(|p| p.1 == 1.0) || fr.iter().all(|p| p.1 == 0.0));
            continue;
        };
        fitted += 1;
        let dispersion: f64 = r[3].parse().unwrap();
        assert!(dispersion > 0.0 && dispersion.is_finite());
        let first_up = fr.iter().position(|p| p.1 >= 0.5).unwrap();
        let last_down = fr.iter().rposition(|p| p.1 <= 0.5).unwrap();
        let lo = fr[first_up.saturating_sub(1)].0;
        let hi = fr[(last_down + 1).min(fr.len() - 1)].0;
        assert!(
            lo <= median && median <= hi,
            "{key}: median {median} outside the crossing levels [{lo}, {hi}]"
        );
    }
    // The collapse curve at least has a transition over 0.1–0.8 g for a block of g tan α = 0.2 g.
    assert!(fitted >= 1);
    assert!(!rows[0][2].is_empty(), "the collapse curve is fitted");
}

/// The overturning map of a pulse study: one cell per case, and `crr plot` on a folder that is
/// neither a simulation's nor a study's results is refused.
#[test]
fn map_has_one_cell_per_case() {
    let dir = scratch("study_map");
    let study = write(
        &dir,
        "m.toml",
        &format!(
            "model = \"{}\"\nduration = 3.0\n\n[pulses]\nkind = \"one_sine_pulse\"\n\
             amplitude_ratios = {{ from = 1.5, to = 6.0, count = 5 }}\n\
             frequency_ratios = {{ from = 1.0, to = 8.0, count = 4 }}\n",
            models().join("single_block.toml").display()
        ),
    );
    let out = dir.join("out");
    run_ok(&[
        "study",
        study.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--plot",
    ]);
    let svg = std::fs::read_to_string(out.join("map.svg")).unwrap();
    // 20 cells + 4 legend keys + the legend box + the background, at least.
    assert!(svg.matches("<rect").count() >= 20 + 4);
    assert_figure(&out, "map", 24);
    assert!(
        !out.join("fragility.csv").exists(),
        "no fragility for pulses"
    );
    legend_hides_no_cell(&svg, 20);
}

/// The rectangles of an SVG, in document order: (x, y, width, height, the tag's text).
fn svg_rects(svg: &str) -> Vec<(f64, f64, f64, f64, String)> {
    let attr = |tag: &str, name: &str| -> f64 {
        let start = tag.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        let end = start + tag[start..].find('"').unwrap();
        tag[start..end].parse().unwrap()
    };
    svg.match_indices("<rect ")
        .map(|(i, _)| {
            let tag = &svg[i..i + svg[i..].find('>').unwrap()];
            (
                attr(tag, "x"),
                attr(tag, "y"),
                attr(tag, "width"),
                attr(tag, "height"),
                tag.to_string(),
            )
        })
        .collect()
}

/// The map's legend box overlaps none of its cells (before, it hid the top row of a map: the
/// box is drawn over the cells, with their rectangles before it in the file).
fn legend_hides_no_cell(svg: &str, cells_drawn: usize) {
    let rects = svg_rects(svg);
    let boxed = rects
        .iter()
        .position(|r| r.4.contains("stroke=\"#969696\""))
        .expect("a legend box");
    let (lx, ly, lw, lh, _) = rects[boxed].clone();
    // Cells: every rectangle after the background and before the legend's own two.
    let cells = &rects[1..boxed - 1];
    assert!(cells.len() >= cells_drawn, "{} cells", cells.len());
    for (x, y, w, h, _) in cells {
        let apart = x + w <= lx || *x >= lx + lw || y + h <= ly || *y >= ly + lh;
        assert!(
            apart,
            "the cell at ({x}, {y}) {w}×{h} px lies under the legend ({lx}, {ly}) {lw}×{lh}"
        );
    }
}

/// The bundled studies load with the documented numbers of cases, in size-major order, and a
/// scale factor that is not positive is refused naming `scales`.
#[test]
fn bundled_studies_load() {
    let studies = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/studies");
    let spectrum = Study::load(&studies.join("block_spectrum.toml")).unwrap();
    assert_eq!(spectrum.variants.len(), 20);
    assert_eq!(spectrum.records.len(), 5, "the bundled record and 4 seeds");
    assert_eq!(spectrum.cases.len(), 100);
    // Case k is at size k div 5 (5 records × 1 level per size).
    assert!(spectrum.cases.iter().all(|c| c.variant == c.index / 5));
    assert!((spectrum.variants[19].height.unwrap() - 10.0).abs() < 1e-12);
    let drum = Study::load(&studies.join("drum_fragility.toml")).unwrap();
    assert_eq!(drum.records.len(), 20);
    assert_eq!(drum.cases.len(), 200);
    assert!(!drum.sized);
    let map = Study::load(&studies.join("housner_map.toml")).unwrap();
    assert_eq!(map.cases.len(), 3600);

    let dir = scratch("study_bad_scales");
    let bad = write(
        &dir,
        "bad.toml",
        &format!(
            "model = \"{}\"\nscales = [1.0, 0.0]\n\n[pulses]\nkind = \"ricker\"\n\
             amplitudes = [1.0]\nperiods = [0.5]\n",
            models().join("single_block.toml").display()
        ),
    );
    let e = Study::load(&bad).unwrap_err().to_string();
    assert!(e.contains("scales") && e.contains("> 0"), "{e}");
}

/// A Sa(T₁) study's levels are its `sa_g` column, not the scale factor (issue: the fragility of an
/// Sa study was fitted against the factor and its axis labelled so).
#[test]
fn a_spectral_acceleration_study_is_read_against_sa() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("products_sa");
    let _ = std::fs::remove_dir_all(&dir);
    write(&dir, "study.json", "{\"name\": \"sa\"}");
    write(
        &dir,
        "cases.csv",
        "id,record,sa_g,factor,status,collapse\n\
         c0,\"a.AT2\",0.2,0.5,ok,0\n\
         c1,\"a.AT2\",0.4,1,ok,1\n",
    );
    let r = crr::output::study::products::StudyResults::read(&dir).unwrap();
    assert_eq!(r.intensity.as_deref(), Some("sa_g"));
    let levels: Vec<Option<f64>> = r.cases.iter().map(|c| c.level).collect();
    assert_eq!(levels, vec![Some(0.2), Some(0.4)]);
}

/// The fields of one line of a CSV file, fields in double quotes taken whole (`""` a quote).
fn csv_fields(line: &str) -> Vec<String> {
    let (mut fields, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    fields.push(field);
    fields
}

/// The named columns of every row of `dir/cases.csv`, in the file's order.
fn cases_columns(dir: &Path, names: &[&str]) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(dir.join("cases.csv")).unwrap();
    let mut lines = text.lines();
    let header = csv_fields(lines.next().unwrap());
    let at: Vec<usize> = names
        .iter()
        .map(|n| header.iter().position(|h| h == n).expect(n))
        .collect();
    lines
        .map(|l| {
            let f = csv_fields(l);
            assert_eq!(f.len(), header.len(), "{l}");
            at.iter().map(|&i| f[i].clone()).collect()
        })
        .collect()
}

/// Every case's `violation_time_s` (None where empty).
fn violation_times(dir: &Path) -> Vec<Option<f64>> {
    cases_columns(dir, &["violation_time_s"])
        .into_iter()
        .map(|r| (!r[0].is_empty()).then(|| r[0].parse().unwrap()))
        .collect()
}

/// A case whose run leaves crr's model says so in its row, as `crr simulate` does for the same
/// run. The bundled drum column under its own pulse (one sine of 2.5 m/s², 0.5 s, 4 s from rest)
/// rocks, and at 0.5028 s the bed under the seventh drum would have to pull (the drums above
/// hop; tests/cli/warnings.rs): the study's case of that pulse gives the same time, bit for bit,
/// the same kind and interface as `summary.json`'s `hypothesis_violation` of `crr simulate` on
/// the model file, and counts it in `study.json` (a run's and a merge's of its two shards), on
/// stderr and in the map's caption and legend. Under 1.0 m/s², below the column's uplift acceleration g tan α = 1.19 m/s² (the
/// whole column rocking on its base), the column stays seated: no impact and no violation.
#[test]
fn a_case_that_leaves_the_model_says_so_as_crr_simulate_does() {
    let dir = scratch("study_outside_model");
    let model = models().join("drum_column.toml");
    let study = write(
        &dir,
        "d.toml",
        &format!(
            "model = \"{}\"\nduration = 4.0\n\n[pulses]\nkind = \"one_sine_pulse\"\n\
             amplitudes = [1.0, 2.5]\nperiods = [0.5]\n",
            model.display()
        ),
    );
    let out = dir.join("out");
    let err = study_plotted(&study, &out);
    assert!(
        err.contains("1 of the 2 case(s) of this part left crr's model"),
        "{err}"
    );
    let rows = cases_columns(
        &out,
        &[
            "impacts",
            "violation_time_s",
            "violation",
            "violation_interface",
        ],
    );
    assert_eq!(rows[0], ["0", "", "", ""], "below the uplift acceleration");
    let single = dir.join("single");
    run_ok(&[
        "simulate",
        model.to_str().unwrap(),
        "--out",
        single.to_str().unwrap(),
        "--quiet",
    ]);
    let summary = read_json(&single.join("summary.json"));
    let v = &summary["hypothesis_violation"];
    let t = v["time"].as_f64().unwrap();
    assert!((t - 0.5028).abs() < 1e-4, "{v}");
    assert_eq!(rows[1][1].parse::<f64>().unwrap().to_bits(), t.to_bits());
    assert_eq!(rows[1][2], v["kind"].as_str().unwrap());
    assert_eq!(rows[1][2], "tension");
    assert_eq!(rows[1][3], v["interface"].as_str().unwrap());
    assert_eq!(rows[1][0], summary["impacts"].to_string(), "the same run");
    let info = read_json(&out.join("study.json"));
    assert_eq!(info["cases_outside_model"], 1);
    // Shards merged count it too.
    let parts: Vec<PathBuf> = (1..=2).map(|i| dir.join(format!("part_{i}"))).collect();
    for (i, part) in parts.iter().enumerate() {
        let shard = format!("{}/2", i + 1);
        run_ok(&[
            "study",
            study.to_str().unwrap(),
            "--shard",
            &shard,
            "--out",
            part.to_str().unwrap(),
            "--quiet",
        ]);
    }
    let merged = dir.join("merged");
    run_ok(&[
        "study",
        "merge",
        parts[0].to_str().unwrap(),
        parts[1].to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    let info = read_json(&merged.join("study.json"));
    assert_eq!(
        (info["cases"].as_u64(), info["cases_outside_model"].as_u64()),
        (Some(2), Some(1))
    );
    let svg = std::fs::read_to_string(out.join("map.svg")).unwrap();
    assert!(svg.contains("(1 of 2 cases outside crr"), "the caption");
    assert!(svg.contains("left crr"), "the legend");
    legend_hides_no_cell(&svg, 2);
}

/// The fragility tables count, per level, the cases whose runs left crr's model, as their rows
/// in `cases.csv` say: the drum column under two synthetic records at 0.1, 0.3 and 0.5 g for 8 s
/// (at 0.1 g, below its uplift acceleration of about 0.14 g, it stays seated; at 0.3 and 0.5 g
/// both records make a bed pull, measured 2026-12-01).
#[test]
fn fragility_tables_count_the_cases_outside_the_model() {
    let dir = scratch("study_fragility_outside");
    let study = write(
        &dir,
        "f.toml",
        &format!(
            "name = \"drums\"\nmodel = \"{}\"\nduration = 8.0\n\n[records]\n\
             synthetic = {{ seeds = [1, 2] }}\n\n[intensity]\npga = [0.1, 0.3, 0.5]\n",
            models().join("drum_column.toml").display()
        ),
    );
    let out = dir.join("out");
    study_plotted(&study, &out);
    // From the rows: the finished cases outside the model at each level (a case stopped by an
    // error is not in the fragility tables).
    let rows = cases_columns(&out, &["pga_g", "violation_time_s", "status"]);
    let count = |level: f64| {
        rows.iter()
            .filter(|r| (r[0].parse::<f64>().unwrap() - level).abs() < 1e-9)
            .filter(|r| !r[1].is_empty() && r[2] == "ok")
            .count()
    };
    let expected = [count(0.1), count(0.3), count(0.5)];
    assert_eq!(expected[0], 0, "at rest under 0.1 g");
    assert!(expected[1] + expected[2] > 0, "some case leaves the model");
    let points = std::fs::read_to_string(out.join("fragility_points.csv")).unwrap();
    let mut lines = points.lines();
    assert_eq!(
        lines.next().unwrap(),
        "measure,threshold,level,trials,exceed,fraction,outside_model"
    );
    let mut curves = 0;
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        let level: f64 = f[2].parse().unwrap();
        let i = [0.1, 0.3, 0.5]
            .iter()
            .position(|x| (x - level).abs() < 1e-9)
            .unwrap();
        assert_eq!(f[6], expected[i].to_string(), "{l}");
        curves += usize::from(i == 0);
    }
    assert_eq!(curves, 4, "collapse and three thresholds");
    let fits = std::fs::read_to_string(out.join("fragility.csv")).unwrap();
    let total: usize = expected.iter().sum();
    for l in fits.lines().skip(1) {
        assert_eq!(l.rsplit(',').next().unwrap(), total.to_string(), "{l}");
    }
    let svg = std::fs::read_to_string(out.join("fragility.svg")).unwrap();
    let finished = rows.iter().filter(|r| r[2] == "ok").count();
    assert!(
        svg.contains(&format!("({total} of {finished} cases outside crr")),
        "the caption"
    );
}

/// A case whose run stops part-way with an error keeps what its run computed: its row holds the
/// error and the measures up to it, equal to those of `crr simulate` on the same model and pulse
/// (partial results, `"completed": false`). The drum column under one sine of 3.3 m/s² and
/// 0.84 s: at 0.8207 s the contacts' decision would lift the capital off every support (a
/// flight, which stops the run), after the monitor's flight at `bed_4` at 0.8195 s. The collapse
/// columns stay empty: the run neither collapsed nor lasted.
#[test]
fn a_case_stopped_by_an_error_keeps_the_measures_its_run_reached() {
    let dir = scratch("study_error_measures");
    let model_text = std::fs::read_to_string(models().join("drum_column.toml")).unwrap();
    let bundled = "x = { one_sine_pulse = { amplitude = 2.5, period = 0.5 } }";
    assert!(model_text.contains(bundled));
    let model = write(
        &dir,
        "drums.toml",
        &model_text.replace(
            bundled,
            "x = { one_sine_pulse = { amplitude = 3.3, period = 0.84 } }",
        ),
    );
    let study = write(
        &dir,
        "d.toml",
        &format!(
            "model = \"{}\"\nduration = 4.0\n\n[pulses]\nkind = \"one_sine_pulse\"\n\
             amplitudes = [3.3]\nperiods = [0.84]\n",
            model.display()
        ),
    );
    let out = dir.join("out");
    run_ok(&[
        "study",
        study.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    let single = dir.join("single");
    let o = crr(&[
        "simulate",
        model.to_str().unwrap(),
        "--out",
        single.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!o.status.success(), "the run stops with an error");
    let summary = read_json(&single.join("summary.json"));
    assert_eq!(summary["completed"], false);
    let coords: Vec<String> = summary["coordinates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap().to_string())
        .collect();
    let mut names: Vec<String> = [
        "status",
        "collapse",
        "collapse_time_s",
        "impacts",
        "end_time_s",
        "violation_time_s",
        "violation_interface",
        "error",
    ]
    .map(String::from)
    .to_vec();
    names.extend(coords.iter().map(|c| format!("peak_{c}_rad")));
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let row = &cases_columns(&out, &names)[0];
    assert_eq!(row[..3], ["error", "", ""]);
    assert_eq!(row[3], summary["impacts"].to_string());
    let end = summary["end_time"].as_f64().unwrap();
    assert!((end - 0.8207).abs() < 1e-4, "{end}");
    assert_eq!(row[4].parse::<f64>().unwrap().to_bits(), end.to_bits());
    let v = &summary["hypothesis_violation"];
    assert_eq!(
        row[5].parse::<f64>().unwrap().to_bits(),
        v["time"].as_f64().unwrap().to_bits()
    );
    assert_eq!(row[6], v["interface"].as_str().unwrap());
    let kind = &cases_columns(&out, &["violation"])[0][0];
    assert_eq!(kind, v["kind"].as_str().unwrap());
    assert_eq!(row[7], summary["error"].as_str().unwrap());
    assert!(
        row[7].contains("capital lose(s) every support"),
        "{}",
        row[7]
    );
    for (k, c) in summary["coordinates"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        let peak = c["peak_abs"].as_f64().unwrap();
        assert_eq!(row[8 + k].parse::<f64>().unwrap().to_bits(), peak.to_bits());
    }
    assert!(
        row[8].parse::<f64>().unwrap() > 0.04,
        "the base joint rocked"
    );
    // The residual rotation and the dissipated energy: those of the last row of the partial
    // history.csv (its largest |angle| and its `dissipated`).
    let history = std::fs::read_to_string(single.join("history.csv")).unwrap();
    let header: Vec<&str> = history.lines().next().unwrap().split(',').collect();
    let last: Vec<&str> = history.lines().last().unwrap().split(',').collect();
    let value = |name: &str| -> f64 {
        last[header.iter().position(|h| *h == name).unwrap()]
            .parse()
            .unwrap()
    };
    let residual = coords.iter().map(|c| value(c).abs()).fold(0.0f64, f64::max);
    let measured = cases_columns(&out, &["residual_rad", "dissipated_j"]);
    assert_eq!(
        measured[0][0].parse::<f64>().unwrap().to_bits(),
        residual.to_bits()
    );
    assert_eq!(
        measured[0][1].parse::<f64>().unwrap().to_bits(),
        value("dissipated").to_bits()
    );
}

/// A study of the bundled drum column under one-sine pulses of 2.5 m/s² and 0.5 s for 4 s,
/// with `setting` (one `key = value` line) among its keys.
fn drum_column_study(setting: &str) -> String {
    format!(
        "model = \"{}\"\nduration = 4.0\n{setting}\n\n[pulses]\n\
         kind = \"one_sine_pulse\"\namplitudes = [2.5]\nperiods = [0.5]\n",
        models().join("drum_column.toml").display()
    )
}

/// Writes `text` as `DIR/NAME.toml` and runs `crr study` on it into `DIR/NAME`, which must
/// succeed; its output folder and stderr.
fn study_quietly(dir: &Path, name: &str, text: &str) -> (PathBuf, String) {
    let study = write(dir, &format!("{name}.toml"), text);
    let out = dir.join(name);
    let o = crr(&[
        "study",
        study.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{err}");
    (out, err)
}

/// Writes `text` as `DIR/bad.toml` and runs `crr study` on it, which must be refused (status
/// 2) naming the file and `key`.
fn study_refused(dir: &Path, text: &str, key: &str) {
    let bad = write(dir, "bad.toml", text);
    let o = crr(&[
        "study",
        bad.to_str().unwrap(),
        "--out",
        dir.join("bad").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(key) && err.contains("bad.toml"), "{err}");
}

/// A study's `hop_tolerance` replaces the model's: the drum column's pull at 0.5028 s under its
/// own pulse is a hop of 1.1e-8 m (docs/simulation.md, "Hops"), so with a tolerance of 1 µm the
/// case stays inside the model, with the same impacts; a negative tolerance is refused, naming
/// the key.
#[test]
fn a_study_s_hop_tolerance_accepts_the_hops_that_land_within_it() {
    let dir = scratch("study_hop_tolerance");
    let text = |tolerance: &str| drum_column_study(&format!("hop_tolerance = {tolerance}"));
    let columns = ["impacts", "violation_time_s", "violation"];
    let mut rows = Vec::new();
    for (name, tolerance) in [("strict", "0.0"), ("micrometre", "1e-6")] {
        let (out, err) = study_quietly(&dir, name, &text(tolerance));
        assert_eq!(err.contains("left crr's model"), name == "strict", "{err}");
        rows.push(cases_columns(&out, &columns).remove(0));
    }
    assert_eq!(rows[0][2], "tension");
    assert_eq!((rows[1][1].as_str(), rows[1][2].as_str()), ("", ""));
    assert_eq!(rows[0][0], rows[1][0], "the same impacts");
    study_refused(&dir, &text("-1.0"), "hop_tolerance");
}

/// A study's `stop_at_violation` replaces the model's: the drum column's case under its own
/// pulse fails the hypotheses at 0.5028 s (a pull of `bed_7` just after an impact, measured as a
/// hop to 0.50292 s); with the setting the case ends within a step of that, with the same
/// violation, and fewer impacts than the case that runs its 4 s; a value that is not a boolean
/// is refused, naming the key.
#[test]
fn a_study_s_stop_at_violation_ends_each_case_at_its_first_violation() {
    let dir = scratch("study_stop_at_violation");
    let text = |stop: &str| drum_column_study(&format!("stop_at_violation = {stop}"));
    let columns = [
        "impacts",
        "violation_time_s",
        "violation",
        "violation_interface",
        "end_time_s",
    ];
    let mut rows = Vec::new();
    for (name, stop) in [("on", "false"), ("stopped", "true")] {
        let (out, _) = study_quietly(&dir, name, &text(stop));
        rows.push(cases_columns(&out, &columns).remove(0));
    }
    let number = |s: &str| s.parse::<f64>().unwrap();
    assert_eq!(rows[0][1..4], rows[1][1..4], "the same first violation");
    assert_eq!(rows[0][2], "tension");
    let (violation, end) = (number(&rows[1][1]), number(&rows[1][4]));
    assert_eq!(number(&rows[0][4]), 4.0);
    assert!(
        end >= violation && end < violation + 0.05,
        "{end} against {violation}"
    );
    assert!(number(&rows[1][0]) < number(&rows[0][0]), "{rows:?}");
    study_refused(&dir, &text("\"yes\""), "stop_at_violation");
}

/// What every case of a study shares is checked before any case runs: a study duration beyond
/// the model's time scales, a model setting that would change the physics, and an initial state
/// through its support are refused (status 2, naming the file and the item, no cases.csv), where
/// each failed every case alike (16 error rows, exit 0).
#[test]
fn a_study_whose_every_case_would_fail_alike_is_refused_before_any_runs() {
    let dir = scratch("study_shared_checks");
    let block = std::fs::read_to_string(models().join("single_block.toml")).unwrap();
    let seat = write(
        &dir,
        "seat.toml",
        &format!("{block}\n[analysis]\nseat_rate = 100.0\n"),
    );
    let tilted = write(
        &dir,
        "tilted.toml",
        &block.replace("angles = { base = 0.1 }", "angles = { base = 7.0 }"),
    );
    let plain = models().join("single_block.toml");
    let study = |model: &Path, extra: &str| {
        format!(
            "model = \"{}\"\n{extra}\n[pulses]\nkind = \"one_sine_pulse\"\n\
             amplitudes = [2.0, 3.0]\nperiods = [0.5, 1.0]\n",
            model.display()
        )
    };
    for (text, key) in [
        (
            study(&plain, "duration = 1e300"),
            "duration = 1e300 s is more than",
        ),
        (study(&seat, ""), "seat_rate = 100 rad/s is not small"),
        (
            study(&tilted, "start = \"model\""),
            "the initial angle of base is 7e0 rad",
        ),
    ] {
        study_refused(&dir, &text, key);
        assert!(!dir.join("bad").join("cases.csv").exists(), "no case ran");
    }
    // The same study from rest with a sound duration runs its four cases.
    let (out, _) = study_quietly(&dir, "sound", &study(&plain, "duration = 3.0"));
    let cases = std::fs::read_to_string(out.join("cases.csv")).unwrap();
    assert_eq!(cases.lines().count(), 5, "{cases}");
}

/// Sa(T₁) is taken at periods from 1e-3 to 1e3 s: outside, refused naming the key before any
/// case (a period of 1e-300 s hung before the first case).
#[test]
fn a_spectral_period_outside_any_use_is_refused() {
    let dir = scratch("study_sa_period");
    let model = models().join("single_block.toml");
    let record = models().join("../records/synthetic.AT2");
    for period in ["1e-300", "1e-4", "1e4"] {
        let text = format!(
            "model = \"{}\"\n[records]\nfiles = [\"{}\"]\nformat = \"peer-at2\"\n\
             [intensity]\nsa = {{ period = {period}, levels = [0.2] }}\n",
            model.display(),
            record.display()
        );
        study_refused(
            &dir,
            &text,
            "intensity.sa.period must be from 0.001 to 1000 s",
        );
    }
}
