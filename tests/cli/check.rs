//! `crr check`: mobility of the bundled models; for the one-DOF ones λ, the equivalent block and r
//! against closed forms, and the engine's free-rocking frequencies against Housner's.

use std::process::Command;

fn check(model: &str) -> serde_json::Value {
    let o = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(["check", model, "--json"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("crr runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn single_block_is_housners_block() {
    let r = check("examples/models/single_block.toml");
    assert_eq!(r["mobility"]["dof1"], 1);
    assert_eq!(r["mobility"]["dof2"], 1);
    let m = &r["mechanism"];
    let (b, h, g): (f64, f64, f64) = (0.2, 1.0, 9.81);
    let alpha = (b / h).atan();
    let f = |k: &str| m[k].as_f64().unwrap();
    assert!((f("lambda") - b / h).abs() < 1e-9);
    assert!((f("alpha_eq") - alpha).abs() < 1e-6);
    assert!((f("p_squared") - 3.0 * g / (4.0 * b.hypot(h))).abs() < 1e-6);
    assert!((f("r") - (1.0 - 1.5 * alpha.sin().powi(2))).abs() < 1e-12);
    let rows = m["frequencies"].as_array().unwrap();
    assert_eq!(rows.len(), 9);
    for row in rows {
        // The exact nonlinear frequency is within 1% of the linearised formula for this block.
        let q = row["ratio"].as_f64().unwrap();
        assert!((q - 1.0).abs() < 0.01, "{row}");
    }
}

#[test]
fn trilithon_is_makris_vassiliou() {
    let r = check("examples/models/trilithon.toml");
    assert_eq!(r["mobility"]["dof1"], 3);
    assert_eq!(r["mobility"]["closures"], 1);
    assert_eq!(r["mobility"]["dof2"], 1);
    let m = &r["mechanism"];
    let (b, h, g): (f64, f64, f64) = (0.25, 2.0, 9.81);
    let alpha = (b / h).atan();
    let gamma = (3.5 * 0.5 * 0.6) / (2.0 * 0.5 * 0.5 * 4.0);
    let p2 = 3.0 * g / (4.0 * b.hypot(h)) * (1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma);
    let rr =
        (1.0 - 1.5 * alpha.sin().powi(2) + 3.0 * gamma * (2.0 * alpha).cos()) / (1.0 + 3.0 * gamma);
    let f = |k: &str| m[k].as_f64().unwrap();
    assert!((f("lambda") - b / h).abs() < 1e-8);
    assert!((f("p_squared") - p2).abs() < 1e-5 * p2);
    assert!((f("r") - rr).abs() < 1e-10);
}

#[test]
fn multi_dof_models_report_mobility_only() {
    let r = check("examples/models/two_block_stack.toml");
    assert_eq!(r["mobility"]["dof2"], 2);
    assert!(r["mechanism"].is_null());
    assert!(r["note"].as_str().unwrap().contains("DOF(2) = 2"));
    // An open chain has no finite-mobility check.
    assert!(r["finite_mobility"].is_null());
    let a = check("examples/models/arch.toml");
    assert_eq!(a["mobility"]["dof2"], 1);
    assert_eq!(a["mobility"]["rank"], 2);
    assert_eq!(a["finite_mobility"]["dof2"], 1);
    // The baldachin's loops close for finite tilts: still two DOF away from rest.
    let b = check("examples/models/baldachin.toml");
    assert_eq!(b["mobility"]["dof2"], 2);
    assert_eq!(b["mobility"]["redundant"], 4);
    assert_eq!(b["finite_mobility"]["dof2"], 2);
    assert!(b["finite_mobility"]["residual"].as_f64().unwrap() < 1e-12);
}

#[test]
fn text_output_has_the_table() {
    let o = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(["check", "examples/models/single_block.toml"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let s = String::from_utf8(o.stdout).unwrap();
    assert!(s.contains("DOF(2) = 1"));
    assert!(s.contains("activation multiplier λ = 0.200000"));
    assert!(s.contains("F_H Housner (Hz)"));
}

/// A squat block, b/h = 2 (a slab 2 m wide and 1 m high): sin²α = 0.8 > 2/3, so Housner's
/// r = 1 − 1.5 sin²α = −0.2 is negative. The momentum law would send the block on about its
/// new corner into the ground, so its first impact seats it: `crr check` reports T⁺/T⁻ = 0 (not
/// r² = 0.04) and says why, and `crr simulate` of the slab released from 0.01 rad loses at its
/// one impact all the energy it fell with, m g R (cos(α − θ₀) − cos α) by hand (found by an
/// independent review: the report said 0.04).
#[test]
fn a_squat_block_s_negative_r_seats_it_at_its_first_impact() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("squat_block");
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join("squat_block.toml");
    std::fs::write(
        &model,
        r#"name = "squat_block"
gravity = 9.81

[[body]]
name = "block"
density = 2500.0
box = { center = [0.0, 0.0, 0.5], size = [2.0, 0.4, 1.0] }

[[interface]]
name = "base"
parent = "ground"
child = "block"
axis = [0.0, 1.0, 0.0]
pivot_positive = [1.0, 0.0, 0.0]
pivot_negative = [-1.0, 0.0, 0.0]

[initial]
angles = { base = 0.01 }

[analysis]
duration = 3.0
"#,
    )
    .unwrap();
    let r = check(model.to_str().unwrap());
    let (b, h, g, theta0): (f64, f64, f64, f64) = (1.0, 0.5, 9.81, 0.01);
    let alpha = (b / h).atan();
    let m = &r["mechanism"];
    assert!((m["r"].as_f64().unwrap() - (1.0 - 1.5 * alpha.sin().powi(2))).abs() < 1e-12);
    assert!((m["r"].as_f64().unwrap() + 0.2).abs() < 1e-12);
    assert_eq!(m["energy_ratio"].as_f64().unwrap(), 0.0);
    let text = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(["check", model.to_str().unwrap()])
        .output()
        .unwrap();
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(text.contains("T⁺/T⁻ = 0.000000"), "{text}");
    assert!(text.contains("r < 0"), "{text}");
    let out = dir.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args([
            "simulate",
            model.to_str().unwrap(),
            "--force",
            "--quiet",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let impacts = std::fs::read_to_string(out.join("impacts.csv")).unwrap();
    let rows: Vec<&str> = impacts.lines().skip(1).collect();
    assert_eq!(rows.len(), 1, "one impact, then at rest: {impacts}");
    let lost: f64 = rows[0].split(',').nth(4).unwrap().parse().unwrap();
    let mass = 2.0 * 0.4 * 1.0 * 2500.0;
    let radius = b.hypot(h);
    let fallen = mass * g * radius * ((alpha - theta0).cos() - alpha.cos());
    assert!(
        (lost - fallen).abs() < 1e-6 * fallen,
        "lost {lost} J, fell with {fallen} J"
    );
}

/// A model written by hand whose joint does not sit where its bodies touch is reported (the
/// analysis layer's `contact_geometry`): the bundled single block with its positive pivot typed
/// 2.0 for 0.2 (it lies 1.8 m from the block, by hand: the block's side is at x = 0.2), and the
/// bundled two-block stack with its upper block placed 0.2 m above its joint or sunk 0.1 m into
/// the lower block. Each runs, and `crr check` names the interface, the body and the distance;
/// no bundled model is reported.
#[test]
fn pivots_off_their_bodies_and_overlapping_blocks_are_reported() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("contact_geometry");
    std::fs::create_dir_all(&dir).unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models");
    let warnings = |path: &std::path::Path| -> Vec<String> {
        let r = check(path.to_str().unwrap());
        r["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .map(|w| w.as_str().unwrap().to_string())
            .filter(|w| w.starts_with("interface"))
            .collect()
    };
    let edited = |name: &str, from: &str, to: &str| {
        let text = std::fs::read_to_string(root.join(format!("{name}.toml"))).unwrap();
        assert!(text.contains(from), "{from}");
        let path = dir.join(format!("{name}_{}.toml", to.len()));
        std::fs::write(&path, text.replace(from, to)).unwrap();
        path
    };
    let typo = edited(
        "single_block",
        "pivot_positive = [[0.2, -0.2, 0.0], [0.2, 0.2, 0.0]]",
        "pivot_positive = [[2.0, -0.2, 0.0], [2.0, 0.2, 0.0]]",
    );
    let w = warnings(&typo);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("\"base\"") && w[0].contains("\"block\""),
        "{}",
        w[0]
    );
    assert!(w[0].contains("lies 1.8000 m"), "{}", w[0]);
    let gap = edited(
        "two_block_stack",
        "center = [0.0, 0.0, 2.3]",
        "center = [0.0, 0.0, 2.50]",
    );
    let w = warnings(&gap);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("\"joint\"") && w[0].contains("\"upper\""),
        "{}",
        w[0]
    );
    assert!(w[0].contains("lies 0.2000 m"), "{}", w[0]);
    let overlap = edited(
        "two_block_stack",
        "center = [0.0, 0.0, 2.3]",
        "center = [0.0, 0.0, 2.200]",
    );
    let w = warnings(&overlap);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("overlap by 0.1000 m"), "{}", w[0]);
    for entry in std::fs::read_dir(&root).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            assert_eq!(warnings(&path), Vec::<String>::new(), "{}", path.display());
        }
    }
}

/// A reader that closes the pipe early (`crr check --json … | head -1`) ends the program quietly
/// with 141 (128 + SIGPIPE, what a shell reports for a tool the signal ends), not with a panic
/// and a backtrace (an independent review). The report, `crr inspect` of the temple in JSON
/// (79 kB), is longer than a pipe holds (64 kB on Linux), so it cannot be written whole before
/// the reader closes, however the two processes are scheduled.
#[test]
fn a_reader_that_closes_the_pipe_ends_the_program_quietly() {
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(["inspect", "examples/models/temple.toml", "--json"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("crr runs");
    // The reader closes the pipe with nothing read.
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("crr ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.code(), Some(141), "{stderr}");
}

/// A structure that falls under its own weight (a leaning prism, its centre of mass 0.3 m
/// beyond its base's edge over a height of 1 m, by its trapezoid's centroid) has no activation
/// multiplier, equivalent block or free-rocking frequencies: the report says so instead of
/// printing them for a negative α_eq (an independent review).
#[test]
fn a_structure_that_falls_under_its_own_weight_has_no_free_rocking_report() {
    let path = crate::common::write_model(
        "leaning_prism",
        r#"name = "lean"
[[body]]
name = "block"
density = 2000.0
prism = { polygon = [[-0.2, -0.2, 0.0], [0.2, -0.2, 0.0], [1.2, -0.2, 2.0], [0.8, -0.2, 2.0]], extrude = [0.0, 0.4, 0.0] }
[[interface]]
name = "base"
parent = "ground"
child = "block"
axis = [0.0, 1.0, 0.0]
pivot_positive = [0.2, 0.0, 0.0]
pivot_negative = [-0.2, 0.0, 0.0]
"#,
    );
    let o = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(["check", path.to_str().unwrap()])
        .output()
        .expect("crr runs");
    let text = String::from_utf8_lossy(&o.stdout);
    // The centroid of the parallelogram lies at x = 0.5 over its base [−0.2, 0.2]: 0.3 m beyond
    // the + edge, 1 m up, so it would need 0.3 g along +x to stand.
    assert!(
        text.contains("does not hold at rest") && text.contains("0.300000 g"),
        "{text}"
    );
    assert!(text.contains("falls under its own weight"), "{text}");
    assert!(!text.contains("free-rocking frequency"), "{text}");
    assert!(!text.contains("activation multiplier λ"), "{text}");
}

/// A direction is a direction whatever its scale: components of 1e-300 (whose norm underflows
/// to 0) or 1e300 (whose norm overflows) give the same report as the unit vector. The single
/// block's multiplier along x is its b/h = 0.2 (Housner). Along d = (1, 0, 1)/√2 the effective
/// gravity is (−λg/√2, 0, −g − λg/√2), and the block tips when its horizontal part reaches b/h
/// of its vertical one: (λ/√2)/(1 + λ/√2) = 0.2, λ = 0.25 √2 = 0.353553.
#[test]
fn directions_of_any_scale_give_the_same_multiplier() {
    let report = |direction: &str| {
        let o = Command::new(env!("CARGO_BIN_EXE_crr"))
            .args([
                "check",
                "examples/models/single_block.toml",
                "--direction",
                direction,
            ])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .expect("crr runs");
        let text = String::from_utf8_lossy(&o.stdout).into_owned();
        assert!(o.status.success(), "{direction}: {text}");
        text.lines()
            .find(|l| l.trim_start().starts_with("d = "))
            .unwrap_or_else(|| panic!("{direction}: {text}"))
            .to_string()
    };
    let x = report("+x");
    assert!(x.contains("λ = 0.200000"), "{x}");
    assert_eq!(report("1e-300,0,0"), x);
    assert_eq!(report("1e300,0,0"), x);
    let diagonal = report("1,0,1");
    assert!(diagonal.contains("λ = 0.353553"), "{diagonal}");
    assert_eq!(report("1e-300,0,1e-300"), diagonal);
    assert_eq!(report("1e300,0,1e300"), diagonal);
}

/// A planar wall of 0.5 m courses of boxes 0.5 m thick cut at the lengths `courses` (from
/// x = 0), written as blocks in the scratch folder `tag` and assembled with `crr assemble
/// --planar` (and `--all-contacts` where asked); the model file's path.
fn assembled_planar_wall(tag: &str, courses: &[&[f64]], all_contacts: bool) -> String {
    let dir = crate::common::scratch(tag);
    let mut assembly = format!("name = \"{tag}\"\ngravity = 9.81\n");
    for (c, lengths) in courses.iter().enumerate() {
        let mut x = 0.0;
        for (k, len) in lengths.iter().enumerate() {
            assembly += &format!(
                "\n[[body]]\nname = \"c{c}_b{k}\"\ndensity = 2000.0\nbox = {{ center = [{}, 0.0, {}], size = [{len}, 0.5, 0.5] }}\n",
                x + len / 2.0,
                0.5 * c as f64 + 0.25
            );
            x += len;
        }
    }
    let (blocks, model) = (dir.join("blocks.toml"), dir.join("model.toml"));
    std::fs::write(&blocks, assembly).unwrap();
    let (blocks, model) = (blocks.to_str().unwrap(), model.to_str().unwrap());
    let mut args = vec!["assemble", blocks, "--planar", "--out", model];
    if all_contacts {
        args.push("--all-contacts");
    }
    let o = crate::common::crr(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    model.to_string()
}

/// The JSON report of `crr check MODEL --json --direction -x` with the options `extra`: its one
/// static multiplier.
fn multiplier_along_minus_x(model: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["check", model, "--json", "--direction", "-x"];
    args.extend_from_slice(extra);
    let o = crate::common::crr(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    r["static_multipliers"][0].clone()
}

/// `--exhaustive-sets N` is the exhaustive pass's budget. A wall of three courses
/// ([0.53 | 0.18 | 0.29], [0.29 | 0.39 | 0.32], [1], 0.5 m high, every contact a joint) has more
/// sets of joints that may open and slide than the default 4096: along −x the report gives the
/// search's upper bound, the whole wall (1 m × 1.5 m) overturning about its outer foot at
/// λ = (1/2)/(1.5/2) = 2/3, with `too_many_sets` and the number of sets; asked with that budget it
/// tries them all and answers the least collapse, 0.328658189978, the value the independent
/// enumeration of `tests/statics/exhaustive.rs` finds (1e-7 there;
/// `a_budget_of_the_counted_sets_makes_a_larger_wall_exhaustive`). A budget that is no count is
/// refused, naming the option.
#[test]
fn a_larger_budget_of_sets_makes_the_answer_exhaustive() {
    let courses: [&[f64]; 3] = [&[0.53, 0.18, 0.29], &[0.29, 0.39, 0.32], &[1.0]];
    let model = &assembled_planar_wall("check_exhaustive_sets", &courses, true);
    let along_minus_x = |extra: &[&str]| multiplier_along_minus_x(model, extra);
    let default = along_minus_x(&[]);
    assert_eq!(default["exhaustive"], false, "{default}");
    assert_eq!(default["not_exhaustive_because"], "too_many_sets");
    assert!(
        (default["lambda"].as_f64().unwrap() - 2.0 / 3.0).abs() < 1e-9,
        "{default}"
    );
    let needed = default["exhaustive_sets_needed"].as_u64().expect("a count");
    assert!(needed > 4096, "{needed}");
    let budget = needed.to_string();
    let full = along_minus_x(&["--exhaustive-sets", &budget]);
    assert_eq!(full["exhaustive"], true, "{full}");
    assert_eq!(full["not_exhaustive_because"], serde_json::Value::Null);
    let lambda = full["lambda"].as_f64().unwrap();
    assert!((lambda - 0.328658189978).abs() < 1e-9, "{full}");
    // The text says how many sets there are and how to try them all.
    let o = crate::common::crr(&["check", model, "--direction", "-x"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains(&format!(
            "`crr check --exhaustive-sets {needed}` tries them all"
        )),
        "{text}"
    );
    for bad in ["-1", "many", "1.5"] {
        let o = crate::common::crr(&["check", model, "--exhaustive-sets", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        let said = String::from_utf8_lossy(&o.stderr);
        assert!(
            said.contains(&format!("invalid value '{bad}' for '--exhaustive-sets")),
            "{said}"
        );
    }
}

/// A wall of beds only whose answer without sliding rests on shear across a joint whose
/// compression vanishes ([0.301 | 0.699] under [0.585 | 0.415], courses 0.5 m, along −x; the
/// independent LP of `tests/statics/independent.rs` finds λ(1000) 2.5e-5 of λ short): the line
/// says "needs μ > 1000" and the JSON `friction_unbounded`, with no μ, and the text ends the
/// multipliers with what such an answer means and the option that answers with friction; with
/// `--friction 0.7` the multiplier is lower, the one a real wall has.
#[test]
fn a_multiplier_that_needs_unbounded_friction_says_so() {
    let courses: [&[f64]; 2] = [&[0.301, 0.699], &[0.585, 0.415]];
    let model = &assembled_planar_wall("check_unbounded_friction", &courses, false);
    let along_minus_x = |extra: &[&str]| multiplier_along_minus_x(model, extra);
    let m = along_minus_x(&[]);
    assert_eq!(m["friction_unbounded"], true, "{m}");
    assert!(m["required_friction"].is_null(), "{m}");
    let lambda = m["lambda"].as_f64().unwrap();
    let real = along_minus_x(&["--friction", "0.7"]);
    assert_eq!(real["friction_unbounded"], false, "{real}");
    let with_friction = real["lambda"].as_f64().unwrap();
    assert!(
        with_friction < lambda * (1.0 - 1e-3),
        "{with_friction} {lambda}"
    );
    let o = crate::common::crr(&["check", model, "--direction", "-x"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains(&format!("λ = {lambda:.6} (needs μ > 1000)")),
        "{text}"
    );
    // The report tells what to do with such an answer, once; not where no answer needs it.
    let advice = "an answer that needs μ > 1000 rests on shear across a joint";
    assert_eq!(text.matches(advice).count(), 1, "{text}");
    assert!(text.contains("`--friction MU`"), "{text}");
    let o = crate::common::crr(&["check", model, "--direction", "-x", "--friction", "0.7"]);
    assert!(!String::from_utf8_lossy(&o.stdout).contains(advice));
    let block = crate::common::bundled_path("single_block");
    let o = crate::common::crr(&["check", block.to_str().unwrap()]);
    assert!(!String::from_utf8_lossy(&o.stdout).contains(advice));
}

/// A stone between two fixed piers, touching only their vertical faces, with nothing under it
/// (`crr assemble --all-contacts`, planar and 3D): its weight rests on shear alone, which the
/// statics grant without sliding (and with friction by a clamping the blocks at rest do not
/// supply), so `crr check` says it holds up to 10 g. Both `crr check` and `crr simulate` warn,
/// naming the stone; the bundled arch, whose voussoirs meet on inclined joints, gets no such
/// warning.
#[test]
fn a_stone_held_by_vertical_faces_alone_is_warned() {
    let dir = crate::common::scratch("check_shear_alone");
    let blocks = dir.join("wedged.toml");
    std::fs::write(
        &blocks,
        "name = \"wedged\"\nfixed = [\"pL\", \"pR\"]\n\
         [[body]]\nname = \"pL\"\ndensity = 2500.0\nbox = { center = [-0.5, 0.0, 1.0], size = [0.6, 0.6, 2.0] }\n\
         [[body]]\nname = \"pR\"\ndensity = 2500.0\nbox = { center = [0.5, 0.0, 1.0], size = [0.6, 0.6, 2.0] }\n\
         [[body]]\nname = \"stone\"\ndensity = 2500.0\nbox = { center = [0.0, 0.0, 1.5], size = [0.4, 0.6, 0.4] }\n",
    )
    .unwrap();
    let blocks = blocks.to_str().unwrap();
    for planar in [true, false] {
        let model = dir.join(format!("model_{planar}.toml"));
        let model = model.to_str().unwrap();
        let mut args = vec!["assemble", blocks, "--all-contacts", "--out", model];
        if planar {
            args.push("--planar");
        }
        let o = crate::common::crr(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let o = crate::common::crr(&["check", model, "--json"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let warned = r["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|w| w.as_str())
            .filter(|w| w.starts_with("body \"stone\": every contact it has is a vertical face"))
            .count();
        assert_eq!(warned, 1, "planar {planar}: {r}");
        let out = dir.join(format!("run_{planar}"));
        let o = crate::common::crr(&[
            "simulate",
            model,
            "--duration",
            "0.1",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            stderr.contains("body \"stone\": every contact it has is a vertical face"),
            "planar {planar}: {stderr}"
        );
    }
    let arch = crate::common::bundled_path("arch");
    let o = crate::common::crr(&["check", arch.to_str().unwrap()]);
    assert!(!String::from_utf8_lossy(&o.stdout).contains("vertical face"));
}

/// A direction that is not one is refused with exit code 2, naming the option and the part that
/// is wrong: Rust reads "nan" and "inf" as numbers, and `--direction nan,1,0` used to be taken,
/// its report saying only that the statics had no direction, with exit code 0 (an independent
/// review, 2026-12-06).
#[test]
fn a_direction_with_a_part_that_is_no_finite_number_is_refused() {
    for (direction, part) in [
        ("nan,1,0", "'nan'"),
        ("1,inf,0", "'inf'"),
        ("0,0,0", "not a non-zero finite vector"),
        ("1,x,0", "'x'"),
    ] {
        let o = crate::common::crr(&[
            "check",
            "examples/models/single_block.toml",
            "--direction",
            direction,
        ]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{direction}: {stderr}");
        assert!(
            stderr.contains("--direction") && stderr.contains(part),
            "{direction}: {stderr}"
        );
    }
}

/// `--friction` is a coefficient from 0 to 1000 (1e300 ended in the statics' solver failing
/// with exit 0; the largest need the statics report is 1000): outside, refused naming it.
#[test]
fn a_friction_outside_zero_to_a_thousand_is_refused() {
    for mu in ["-0.1", "nan", "inf", "1000.5", "1e300"] {
        crate::common::refused(
            &[
                "check",
                "examples/models/single_block.toml",
                &format!("--friction={mu}"),
            ],
            &format!(
                "--friction must be a number from 0 to 1000 (no masonry joint needs more to hold), got {}",
                mu.parse::<f64>().unwrap()
            ),
        );
    }
    let o = crate::common::crr(&[
        "check",
        "examples/models/single_block.toml",
        "--friction",
        "1000",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The mechanism `crr check` reports follows from the structure, not from the sense a file gives
/// its coordinate: a hinge written with its axis reversed and its pivots exchanged (the same
/// joint) gives the same report. `mechanism` is read as JSON for both writings of one model.
fn mechanism_of(tag: &str, text: &str) -> serde_json::Value {
    report_of(tag, text)["mechanism"].clone()
}

fn report_of(tag: &str, text: &str) -> serde_json::Value {
    let path = crate::common::write_model(tag, text);
    check(path.to_str().unwrap())
}

/// Every number of two mechanism reports agrees within `tol` relative (the frequency table's
/// released angles in magnitude: they carry the side's sign).
fn assert_same_mechanism(a: &serde_json::Value, b: &serde_json::Value, tol: f64) {
    let close = |x: f64, y: f64| (x - y).abs() <= tol * x.abs().max(y.abs()).max(1e-12);
    for key in [
        "lambda",
        "mass",
        "potential_slope",
        "potential_curvature",
        "alpha_eq",
        "p_eq",
        "r",
        "energy_ratio",
        "mode_change",
    ] {
        let (x, y) = (a[key].as_f64().unwrap(), b[key].as_f64().unwrap());
        assert!(close(x, y), "{key}: {x} vs {y}");
    }
    for key in ["nu", "xi", "eta", "chi"] {
        let (x, y) = (
            a["lagrangian"][key].as_f64().unwrap(),
            b["lagrangian"][key].as_f64().unwrap(),
        );
        assert!(close(x, y), "lagrangian.{key}: {x} vs {y}");
    }
    // The activating ground acceleration is one vector: its direction and sign may both flip.
    let activating = |m: &serde_json::Value| -> Vec<f64> {
        let s = m["lambda_sign"].as_f64().unwrap();
        (0..3)
            .map(|i| s * m["direction"][i].as_f64().unwrap())
            .collect()
    };
    let (u, v) = (activating(a), activating(b));
    assert!(
        u.iter().zip(&v).all(|(x, y)| (x - y).abs() < 1e-12),
        "{u:?} vs {v:?}"
    );
    let rows = |m: &serde_json::Value| m["frequencies"].as_array().unwrap().clone();
    for (x, y) in rows(a).iter().zip(&rows(b)) {
        let m = |r: &serde_json::Value, k: &str| r[k].as_f64().unwrap();
        assert!(
            close(m(x, "theta_m").abs(), m(y, "theta_m").abs()),
            "{x} vs {y}"
        );
        assert!(close(m(x, "housner_hz"), m(y, "housner_hz")), "{x} vs {y}");
    }
}

/// A block on a parallelogram section (base x ∈ [−0.2, 0.2], top shifted 0.1 m along +x, 2 m
/// high): its centroid lies at x = 0.05, 1 m up, so it tips about its +x edge at λ = 0.15/1 and
/// about its −x edge at 0.25/1 (Housner's tan α of each side, α the angle of the centroid from
/// the vertical through the pivot). The report gives the side a growing load opens first,
/// λ = 0.15 with α_eq = atan 0.15, however the hinge is written.
#[test]
fn the_mechanism_reported_is_the_side_that_opens_first_in_any_sense_of_its_coordinate() {
    let block = crate::common::leaning_block;
    let report = report_of("leaning_plus", &block(1.0, 0.2, -0.2));
    let written = report["mechanism"].clone();
    let reversed = mechanism_of("leaning_minus", &block(-1.0, -0.2, 0.2));
    assert_eq!(
        (written["side"].as_str(), reversed["side"].as_str()),
        (Some("+"), Some("-"))
    );
    for m in [&written, &reversed] {
        assert!((m["lambda"].as_f64().unwrap() - 0.15).abs() < 1e-9, "{m}");
        assert!(
            (m["alpha_eq"].as_f64().unwrap() - 0.15f64.atan()).abs() < 1e-6,
            "{m}"
        );
        assert_eq!(m["pivots"]["base"], m["side"]);
    }
    // The statics' linear program, independent of the mechanism's reduction, gives both sides:
    // 0.15 with the ground accelerating along −x (the block tips over its +x edge), 0.25 along +x.
    let along = |x: f64| {
        report["static_multipliers"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["direction"][0].as_f64() == Some(x))
            .unwrap()["lambda"]
            .as_f64()
            .unwrap()
    };
    assert!((along(-1.0) - 0.15).abs() < 1e-9 && (along(1.0) - 0.25).abs() < 1e-9);
    assert_same_mechanism(&written, &reversed, 1e-9);
}

/// The bundled four-hinge arch is symmetric: its two sides are mirror images, equal in λ, read
/// in one coordinate (the right springing's angle) with two different α_eq. Written with that
/// springing's axis reversed and its pivots exchanged it used to report the other side (α_eq
/// 0.107 instead of 0.302, r 1.20 instead of 0.47); both writings now report the same block.
#[test]
fn the_arch_written_with_a_reversed_springing_reports_the_same_block() {
    let text = crate::common::bundled_text("arch");
    let flipped = text
        .replacen(
            "axis = [0.0, 1.0, 0.0]\npivot_positive = [2.5, 0.0, 0.0]\npivot_negative = [2.0, 0.0, 0.0]",
            "axis = [0.0, -1.0, 0.0]\npivot_positive = [2.0, 0.0, 0.0]\npivot_negative = [2.5, 0.0, 0.0]",
            1,
        )
        .replace(
            "angles = { springing_right = 0.03 }",
            "angles = { springing_right = -0.03 }",
        );
    assert_ne!(flipped, text);
    let written = mechanism_of("arch_as_bundled", &text);
    let reversed = mechanism_of("arch_springing_reversed", &flipped);
    assert_eq!(
        (written["side"].as_str(), reversed["side"].as_str()),
        (Some("+"), Some("-"))
    );
    // The frequency table's engine runs are the same runs mirrored in the coordinate's sign.
    assert_same_mechanism(&written, &reversed, 1e-9);
    let engine = |m: &serde_json::Value| -> Vec<Option<f64>> {
        m["frequencies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r["engine_hz"].as_f64())
            .collect()
    };
    for (x, y) in engine(&written).iter().zip(engine(&reversed)) {
        match (x, y) {
            (Some(x), Some(y)) => assert!((x - y).abs() < 1e-6 * x, "{x} vs {y}"),
            (x, y) => assert_eq!(*x, y),
        }
    }
    // The side reported is the larger α_eq of the two (equal λ): θ > 0 as bundled.
    assert!((written["alpha_eq"].as_f64().unwrap() - 0.301858).abs() < 1e-6);
}
