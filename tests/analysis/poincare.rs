//! `crr poincare` (docs/poincare.md): the section is the simulation sampled at t = kT, the
//! symmetric 1:1 orbit of the harmonically forced block gives a one-point section whose state half
//! a period later is its mirror image, free rocking's crossing section decays by r² per cycle,
//! overturning ends the section, sweeps do not depend on the thread count, and bad options are
//! refused with exit code 2.

use std::path::{Path, PathBuf};

use crate::common::{crr, refused, scratch};
use crr::analysis::poincare::{
    Computed, Forcing, Outcome, PoincareOptions, Prepared, Range, SAME_POINT_TOLERANCE,
    SectionKind, Sweep, compute, detect_period, distinct_points, prepare, run_section,
};
use crr::impact::{Parameters, Simulation};

fn single_block() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml")
}

/// The bundled single block (b = 0.2 m, h = 1 m: α = 0.1974 rad, p = 2.686 rad/s, g tan α =
/// 1.962 m/s²) from rest under a_g = A sin(2πF t) in x.
fn block_section(
    tag: &str,
    amplitude: f64,
    frequency: f64,
    transient: usize,
    n: usize,
) -> Prepared {
    let opts = PoincareOptions {
        amplitude,
        frequency: Some(frequency),
        transient,
        periods: n,
        rest: true,
        out: Some(scratch(tag)),
        ..Default::default()
    };
    prepare(&single_block(), &opts).unwrap()
}

/// The largest |angle| and |rate| of a set of states.
fn scale(states: &[(Vec<f64>, Vec<f64>)]) -> (f64, f64) {
    let mut s = (0.0f64, 0.0f64);
    for (q, r) in states {
        s.0 = q.iter().fold(s.0, |m, v| m.max(v.abs()));
        s.1 = r.iter().fold(s.1, |m, v| m.max(v.abs()));
    }
    s
}

/// A reference run of the library `Simulation` under the same harmonic ground motion, with
/// `output_interval` = T/`divisions`; its samples at output times (the impacts' extra samples
/// left out).
fn reference_samples(
    p: &Prepared,
    divisions: usize,
    periods: usize,
) -> Vec<(f64, Vec<f64>, Vec<f64>)> {
    let ground = p.settings.forcing.ground_motion().unwrap();
    let period = p.settings.forcing.period();
    let params = Parameters {
        output_interval: period / divisions as f64,
        duration: periods as f64 * period,
        ..p.params.clone()
    };
    let dt = params.output_interval;
    let mut sim = Simulation::new(&p.model, &ground, &p.initial, params).unwrap();
    let mut out = Vec::new();
    let mut next = 0usize;
    loop {
        let stop = sim.step().unwrap();
        for s in &sim.drain_samples() {
            if s.t == next as f64 * dt {
                out.push((s.t, s.q.to_vec(), s.qdot.to_vec()));
                next += 1;
            }
        }
        if matches!(
            stop,
            crr::impact::StopReason::End(_) | crr::impact::StopReason::Collapse(_)
        ) {
            break;
        }
    }
    out
}

/// Fact 1: the section points are the simulation's states at t = kT. The section is computed with
/// output_interval = T, the reference with output_interval = T/4 (which divides T): the two runs
/// take the same steps (sampling only evaluates the dense output, it never shortens a step), so
/// their states at kT differ only by the evaluation time (k·T versus 4k·(T/4), a few ulp apart) and,
/// when those fall on either side of a step end, by the difference of two steps' interpolants,
/// which is of the order of the local error, rtol = 1e-10 relative. 1e-8 of the run's scale bounds
/// both with a margin of 100.
#[test]
fn section_points_are_the_simulation_states_at_multiples_of_the_period() {
    let p = block_section("pc_agree", 4.0, 2.0, 0, 30);
    assert_eq!(p.settings.kind, SectionKind::Stroboscopic);
    let section = run_section(&p.model, &p.initial, &p.params, &p.settings);
    assert!(section.error.is_none() && section.collapse.is_none());
    assert_eq!(section.points.len(), 30);
    let period = p.settings.forcing.period();
    for (i, pt) in section.points.iter().enumerate() {
        // k = M+1 … M+N, and t is exactly (k as f64)·T: sampled at kT, not at a nearby sample.
        assert_eq!(pt.k, i + 1);
        assert_eq!(pt.t, pt.k as f64 * period);
    }
    let reference = reference_samples(&p, 4, 30);
    assert_eq!(reference.len(), 4 * 30 + 1);
    let (sq, sr) = scale(
        &reference
            .iter()
            .map(|r| (r.1.clone(), r.2.clone()))
            .collect::<Vec<_>>(),
    );
    // The block rocks (well beyond round-off): the comparison is not between two rests.
    assert!(sq > 0.01, "peak angle {sq}");
    for pt in &section.points {
        let (t, q, r) = &reference[4 * pt.k];
        assert!((t - pt.t).abs() <= 1e-12 * pt.t);
        assert!(
            (q[0] - pt.q[0]).abs() <= 1e-8 * sq,
            "k = {}: {} vs {}",
            pt.k,
            q[0],
            pt.q[0]
        );
        assert!(
            (r[0] - pt.qdot[0]).abs() <= 1e-8 * sr,
            "k = {}: {} vs {}",
            pt.k,
            r[0],
            pt.qdot[0]
        );
    }
}

/// Fact 2: the single block's symmetric 1:1 orbit (one impact per half period, the motion over the
/// second half period the mirror image of the first) gives a one-point section.
///
/// Hogan (1989, "On the dynamics of rigid-block motion under harmonic forcing", Proc. R. Soc.
/// Lond. A 425) constructs these symmetric single-impact-per-half-cycle orbits and shows that they
/// exist once the forcing amplitude is large enough for the frequency and are stable in a band of
/// amplitudes above that threshold; at a fixed frequency, raising the amplitude past the band's
/// upper stability boundary destroys the symmetric response (period doubling towards chaos, or
/// overturning). Spanos & Koh (1984) find the same 1:1 "fundamental mode" regions by harmonic
/// balance. The setting here, F = 2 Hz (ω/p = 4.68) and A = 4 m/s² (2.04 g tan α),
/// with r = 1 − 1.5 sin²α = 0.942 from the momentum law, lies in that band: the sweep
/// `crr poincare single_block.toml --rest --frequency 2 --amplitudes 2:12:11 --transient 200`
/// gives one-point sections for A = 3 … 7 m/s² and overturning from 8 m/s² on.
///
/// Checked: after 300 periods of transient the 20 section points coincide to 1e-8 of the orbit's
/// scale (the orbit is attracting: the distance to it shrinks geometrically, and after 300 periods
/// it is far below that); the detected period is 1; and, independently of the section, the state
/// half a period later, computed by a run sampled at T/2, is the mirror image (θ, θ̇) → (−θ, −θ̇)
/// to 1e-7 of the scale (the forcing changes sign over half a period, so the orbit's second half
/// mirrors the first: the state at kT + T/2 is minus the state at kT), and the orbit has exactly
/// two impacts per period.
#[test]
fn the_symmetric_one_one_orbit_is_a_one_point_section_and_its_half_period_mirror() {
    let (m, n) = (300, 20);
    let p = block_section("pc_orbit", 4.0, 2.0, m, n);
    let section = run_section(&p.model, &p.initial, &p.params, &p.settings);
    assert!(section.error.is_none() && section.collapse.is_none());
    assert_eq!(section.points.len(), n);
    let first = &section.points[0];
    let (sq, sr) = (first.q[0].abs(), first.qdot[0].abs());
    // A rocking state, not the rest (0, 0).
    assert!(sq > 1e-3 || sr > 1e-2, "{first:?}");
    let (sq, sr) = (sq.max(1e-3), sr.max(1e-2));
    for pt in &section.points {
        assert!(
            (pt.q[0] - first.q[0]).abs() <= 1e-8 * sq,
            "{pt:?} vs {first:?}"
        );
        assert!(
            (pt.qdot[0] - first.qdot[0]).abs() <= 1e-8 * sr,
            "{pt:?} vs {first:?}"
        );
    }
    assert_eq!(distinct_points(&section.points, SAME_POINT_TOLERANCE), 1);
    assert_eq!(
        detect_period(&section.points, SAME_POINT_TOLERANCE),
        Some(1)
    );

    let reference = reference_samples(&p, 2, m + n);
    let (rq, rr) = scale(
        &reference[2 * m..]
            .iter()
            .map(|r| (r.1.clone(), r.2.clone()))
            .collect::<Vec<_>>(),
    );
    for pt in &section.points[..n - 1] {
        let (_, q, r) = &reference[2 * pt.k + 1];
        assert!(
            (q[0] + pt.q[0]).abs() <= 1e-7 * rq,
            "k = {}: {} vs {}",
            pt.k,
            q[0],
            pt.q[0]
        );
        assert!(
            (r[0] + pt.qdot[0]).abs() <= 1e-7 * rr,
            "k = {}: {} vs {}",
            pt.k,
            r[0],
            pt.qdot[0]
        );
    }
    // One impact per half period: 2 per period over the kept periods.
    let ground = p.settings.forcing.ground_motion().unwrap();
    let period = p.settings.forcing.period();
    let params = Parameters {
        output_interval: period,
        duration: (m + n) as f64 * period,
        ..p.params.clone()
    };
    let traj = Simulation::new(&p.model, &ground, &p.initial, params)
        .unwrap()
        .run()
        .unwrap();
    let kept = traj
        .impacts
        .iter()
        .filter(|i| i.t > m as f64 * period)
        .count();
    assert_eq!(kept, 2 * n);
}

/// A crossing section of free rocking (no forcing): the block released at 0.1 rad crosses θ = 0
/// upward every second impact. Between two impacts the flight conserves energy, so |θ̇| on
/// leaving 0 equals |θ̇| on returning to 0; each impact multiplies θ̇ by r = 1 − 1.5 sin²α (the
/// momentum law for a rectangular block, docs/simulation.md). Successive section points are then
/// at θ = 0 with rates in the ratio r² (to 1e-6: the integrator's relative tolerance is 1e-10 and
/// the event location is exact to round-off).
#[test]
fn free_rocking_crossing_section_decays_by_r_squared_per_point() {
    let opts = PoincareOptions {
        amplitude: 0.0,
        transient: 0,
        periods: 5,
        out: Some(scratch("pc_free")),
        ..Default::default()
    };
    let p = prepare(&single_block(), &opts).unwrap();
    assert_eq!(p.settings.kind, SectionKind::Crossing(0));
    let section = run_section(&p.model, &p.initial, &p.params, &p.settings);
    assert!(section.error.is_none() && section.collapse.is_none());
    assert_eq!(section.points.len(), 5);
    let alpha = (0.2f64 / 1.0).atan();
    let r = 1.0 - 1.5 * alpha.sin().powi(2);
    for w in section.points.windows(2) {
        assert!(w[0].q[0].abs() < 1e-12 && w[1].q[0].abs() < 1e-12);
        assert!(w[0].qdot[0] > 0.0 && w[1].t > w[0].t);
        let ratio = w[1].qdot[0] / w[0].qdot[0];
        assert!(
            (ratio - r * r).abs() < 1e-6 * r * r,
            "{ratio} vs r² = {}",
            r * r
        );
    }
}

/// Fact 3: a forcing far above what the block resists (A = 12 m/s² ≈ 6 g tan α at 1 Hz, where the
/// sweep finds every A ≥ 3 m/s² overturning) overturns it: the section ends at the collapse, the
/// points kept are those before it, and the command reports it on stderr and in poincare.json with
/// exit code 0.
#[test]
fn overturning_ends_the_section_and_is_reported() {
    let p = block_section("pc_over_lib", 12.0, 1.0, 0, 50);
    let section = run_section(&p.model, &p.initial, &p.params, &p.settings);
    let c = section.collapse.as_ref().expect("the block overturns");
    assert!(section.error.is_none());
    assert!(section.points.len() < 50);
    assert_eq!(section.end_time, c.t);
    assert!(section.points.iter().all(|pt| pt.t < c.t));

    let out = scratch("pc_over_cli");
    let o = crr(&[
        "poincare",
        single_block().to_str().unwrap(),
        "--amplitude",
        "12",
        "--frequency",
        "1",
        "--transient",
        "0",
        "--periods",
        "50",
        "--rest",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("overturned at t = "), "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("poincare.json")).unwrap()).unwrap();
    assert_eq!(json["section"]["overturned"], true);
    // serde_json reads decimals back to within an ulp or so.
    let t = json["section"]["overturn_time"].as_f64().unwrap();
    assert!((t - c.t).abs() <= 1e-14 * c.t, "{t} vs {}", c.t);
    assert_eq!(
        json["section"]["points"].as_u64(),
        Some(section.points.len() as u64)
    );
    let csv = std::fs::read_to_string(out.join("poincare.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + section.points.len());
    assert_eq!(csv.lines().next(), Some("k,t,base,base_rate,base_state"));
}

fn sweep(out: &Path, jobs: &str, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "poincare",
        "examples/models/single_block.toml",
        "--rest",
        "--quiet",
        "--jobs",
        jobs,
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = crr(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// Fact 4: the cases of a sweep are computed independently, so 1 and 2 worker threads write
/// byte-identical files; a bifurcation over 5 amplitudes none of which overturns (3 … 7 m/s² at
/// 2 Hz, fact 2's band) has 5 × N rows.
#[test]
fn sweeps_are_identical_for_one_and_two_threads() {
    let n = 4;
    let ns = n.to_string();
    let bif = [
        "--frequency",
        "2",
        "--amplitudes",
        "3:7:5",
        "--transient",
        "20",
        "--periods",
        ns.as_str(),
    ];
    let (a, b) = (scratch("pc_bif_1"), scratch("pc_bif_2"));
    sweep(&a, "1", &bif);
    sweep(&b, "2", &bif);
    for f in ["bifurcation.csv", "poincare.json"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    let csv = std::fs::read_to_string(a.join("bifurcation.csv")).unwrap();
    assert_eq!(
        csv.lines().next(),
        Some("case,amplitude,k,t,base,base_rate")
    );
    assert_eq!(csv.lines().count(), 1 + 5 * n);
    let amplitudes: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(amplitudes[0], 3.0);
    assert_eq!(amplitudes[5 * n - 1], 7.0);

    // A frequency sweep at A = 4 m/s² over 2, 3 and 4 Hz (amplitude sweeps at each of these
    // frequencies find A = 4 m/s² on a bounded orbit, not overturning): 3 × N rows, identical for
    // 1 and 2 threads.
    let freq = [
        "--amplitude",
        "4",
        "--frequencies",
        "2:4:3",
        "--transient",
        "20",
        "--periods",
        ns.as_str(),
    ];
    let (a, b) = (scratch("pc_freq_1"), scratch("pc_freq_2"));
    sweep(&a, "1", &freq);
    sweep(&b, "2", &freq);
    let csv = std::fs::read_to_string(a.join("bifurcation.csv")).unwrap();
    assert_eq!(
        csv,
        std::fs::read_to_string(b.join("bifurcation.csv")).unwrap()
    );
    assert_eq!(
        csv.lines().next(),
        Some("case,frequency,k,t,base,base_rate")
    );
    assert_eq!(csv.lines().count(), 1 + 3 * n);

    let grid = [
        "--frequency",
        "2",
        "--amplitude",
        "4",
        "--transient",
        "5",
        "--periods",
        "2",
        "--grid=-0.1:0.3:3,-0.5:0.5:2",
    ];
    let (a, b) = (scratch("pc_basin_1"), scratch("pc_basin_2"));
    sweep(&a, "1", &grid);
    sweep(&b, "2", &grid);
    for f in ["basins.csv", "poincare.json"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    let csv = std::fs::read_to_string(a.join("basins.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3 * 2);
    // Every case ends in one of the documented outcomes (none fails).
    for l in csv.lines().skip(1) {
        let outcome = l.split(',').nth(2).unwrap();
        assert!(["settles", "orbits", "overturns"].contains(&outcome), "{l}");
    }
}

/// Fact 5: bad options exit with 2 and a message naming the option; never a panic.
#[test]
fn bad_options_are_refused_naming_the_option() {
    let m = "examples/models/single_block.toml";
    let out = scratch("pc_refused");
    let o = out.to_str().unwrap();
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "-1",
            "--frequency",
            "1",
            "--out",
            o,
        ],
        "--amplitude",
    );
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "inf",
            "--frequency",
            "1",
            "--out",
            o,
        ],
        "--amplitude",
    );
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "2",
            "--frequency",
            "0",
            "--out",
            o,
        ],
        "--frequency",
    );
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "2",
            "--frequency",
            "NaN",
            "--out",
            o,
        ],
        "--frequency",
    );
    refused(
        &["poincare", m, "--amplitude", "2", "--out", o],
        "--frequency",
    );
    refused(
        &[
            "poincare",
            m,
            "--frequency",
            "1",
            "--amplitudes",
            "1:2:0",
            "--out",
            o,
        ],
        "--amplitudes",
    );
    refused(
        &[
            "poincare",
            m,
            "--frequency",
            "1",
            "--amplitudes",
            "1:x:3",
            "--out",
            o,
        ],
        "--amplitudes",
    );
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "2",
            "--frequencies",
            "0:1:3",
            "--out",
            o,
        ],
        "--frequencies",
    );
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "2",
            "--frequency",
            "1",
            "--section",
            "nope",
            "--out",
            o,
        ],
        "--section",
    );
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "2",
            "--frequency",
            "1",
            "--coordinate",
            "nope",
            "--out",
            o,
        ],
        "--coordinate",
    );
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "2",
            "--frequency",
            "1",
            "--periods",
            "0",
            "--out",
            o,
        ],
        "--periods",
    );
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "2",
            "--frequency",
            "1",
            "--jobs",
            "0",
            "--out",
            o,
        ],
        "--jobs",
    );
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "2",
            "--frequency",
            "1",
            "--grid",
            "0:1:2",
            "--out",
            o,
        ],
        "--grid",
    );
    refused(
        &[
            "poincare",
            m,
            "--amplitude",
            "2",
            "--frequency",
            "1",
            "--component",
            "w",
            "--out",
            o,
        ],
        "--component",
    );
    // An output folder with earlier results is refused without --force, replaced with it.
    let args = [
        "poincare",
        m,
        "--amplitude",
        "2",
        "--frequency",
        "1",
        "--periods",
        "2",
        "--transient",
        "0",
        "--quiet",
        "--out",
        o,
    ];
    let first = crr(&args);
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    refused(&args, "--force");
    let mut forced = args.to_vec();
    forced.push("--force");
    assert!(crr(&forced).status.success());
}

/// `--plot` writes the section plot (PNG and SVG) with the data files; the forcing is
/// the same harmonic as `Forcing` builds (A sin(2πF t + φ)).
#[test]
fn plot_writes_the_section_images() {
    let out = scratch("pc_plot");
    let o = crr(&[
        "poincare",
        "examples/models/single_block.toml",
        "--amplitude",
        "4",
        "--frequency",
        "2",
        "--rest",
        "--transient",
        "10",
        "--periods",
        "10",
        "--plot",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "poincare.csv",
        "poincare.json",
        "section.png",
        "section.svg",
    ] {
        assert!(std::fs::metadata(out.join(f)).unwrap().len() > 0, "{f}");
    }
    let png = std::fs::read(out.join("section.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let forcing = Forcing {
        amplitude: 4.0,
        frequency: 2.0,
        phase: 0.3,
        axis: crr::dynamics::ground_motion::Axis::X,
    };
    let g = forcing.ground_motion().unwrap();
    let t = 0.1234;
    let expected = 4.0 * (2.0 * std::f64::consts::PI * 2.0 * t + 0.3).sin();
    assert!((g.acceleration(t).x - expected).abs() < 1e-12);
}

/// The basins' outcomes against two closed-form facts of the single block: under a forcing below
/// the uplift acceleration g tan α = 1.962 m/s² (here 1.5 m/s²) a block seated at rest never
/// uplifts (Housner's uplift criterion: seated, it needs |a_g| > g tan α to rock), so it settles;
/// released at 0.45 rad, beyond the point of no return 2α = 0.395 rad (its centre already below the
/// rest height), it overturns at once. (A block released rocking, at 0.05 rad, is not at rest
/// under the same forcing: the criterion is about a seated block only, and the grid finds it on a
/// sustained orbit; that case is not asserted here.)
#[test]
fn basins_settle_below_the_uplift_acceleration_and_overturn_beyond_two_alpha() {
    let opts = PoincareOptions {
        amplitude: 1.5,
        frequency: Some(2.0),
        transient: 40,
        periods: 5,
        rest: true,
        sweep: Sweep::Grid {
            angle: Range {
                start: 0.0,
                end: 0.45,
                count: 2,
            },
            rate: Range {
                start: 0.0,
                end: 0.0,
                count: 1,
            },
        },
        jobs: Some(2),
        out: Some(scratch("pc_basins_facts")),
        ..Default::default()
    };
    let p = prepare(&single_block(), &opts).unwrap();
    let Computed::Basins(cases) = compute(&p, &opts, false).unwrap() else {
        panic!("a grid gives basins");
    };
    assert_eq!(cases.len(), 2);
    let (a, w, settled) = &cases[0];
    assert_eq!((*a, *w), (0.0, 0.0));
    assert_eq!(Outcome::of(settled), Outcome::Settles, "{settled:?}");
    // At rest at every kept point: θ = θ̇ = 0 exactly (seated coordinates are held at 0).
    assert_eq!(settled.points.len(), 5);
    assert!(
        settled
            .points
            .iter()
            .all(|pt| pt.q[0] == 0.0 && pt.qdot[0] == 0.0)
    );
    let (a, _, over) = &cases[1];
    assert_eq!(*a, 0.45);
    assert_eq!(Outcome::of(over), Outcome::Overturns);
    assert!(over.points.is_empty());
}

/// A crossing section of a two-DOF system: the bundled two-block stack under 3 m/s² at 2 Hz
/// (above the top block's uplift acceleration g tan 0.245 = 2.45 m/s², below the 3.43 m/s² pulse
/// that overturns it), sectioned where the top joint crosses 0 upward. By definition every point
/// is a post-impact state of that joint: its angle is 0 (to round-off: the impact is located on
/// the dense output and the state projected onto it), its rate is positive and it now rocks on
/// its positive pivot; the times increase.
#[test]
fn crossing_section_of_the_two_block_stack_is_on_the_joint_seat_moving_up() {
    let opts = PoincareOptions {
        amplitude: 3.0,
        frequency: Some(2.0),
        transient: 2,
        periods: 10,
        rest: true,
        section: Some("joint".into()),
        duration: Some(60.0),
        out: Some(scratch("pc_stack")),
        ..Default::default()
    };
    let stack = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/two_block_stack.toml");
    let p = prepare(&stack, &opts).unwrap();
    let joint = p.model.coord_index("joint").unwrap();
    assert_eq!(p.settings.kind, SectionKind::Crossing(joint));
    let section = run_section(&p.model, &p.initial, &p.params, &p.settings);
    assert!(
        section.error.is_none() && section.collapse.is_none(),
        "{section:?}"
    );
    assert_eq!(section.points.len(), 10);
    for (i, pt) in section.points.iter().enumerate() {
        assert_eq!(pt.k, i + 3);
        assert!(pt.q[joint].abs() <= 1e-12, "{pt:?}");
        assert!(pt.qdot[joint] > 0.0, "{pt:?}");
        assert_eq!(pt.states[joint], crr::impact::SlotState::Positive);
    }
    assert!(section.points.windows(2).all(|w| w[1].t > w[0].t));
}

/// A sweep counts its cases that leave crr's model in a warning, as `crr study` does, each case's
/// `hypothesis_violation` in `poincare.json` being the one a single section of that amplitude
/// reports. The bundled drum column forced at 2 Hz from rest: at 1.5 m/s², just above its uplift
/// acceleration g tan α = 1.19 m/s², it keeps every hypothesis; at 4 m/s² a bed pulls (the
/// drums above fly).
#[test]
fn a_sweep_counts_the_cases_that_leave_the_model() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/drum_column.toml");
    let dir = scratch("poincare_outside");
    let common = [
        "--frequency",
        "2",
        "--periods",
        "5",
        "--transient",
        "2",
        "--rest",
        "--quiet",
        "--force",
    ];
    let run = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "poincare",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(&common);
        args.extend_from_slice(extra);
        let o = crr(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("poincare.json")).unwrap())
                .unwrap();
        (String::from_utf8_lossy(&o.stderr).to_string(), json)
    };
    let (err, json) = run(&dir.join("sweep"), &["--amplitudes", "1.5:4:2"]);
    let cases = json["cases"].as_array().unwrap();
    assert!(cases[0]["hypothesis_violation"].is_null(), "{}", cases[0]);
    let v = &cases[1]["hypothesis_violation"];
    assert_eq!(v["kind"], "tension", "{v}");
    assert!(err.contains("1 of 2 case(s) left crr's model"), "{err}");
    let (err, single) = run(&dir.join("single"), &["--amplitude", "4"]);
    assert_eq!(&single["section"]["hypothesis_violation"], v);
    assert!(err.contains("the rigid-contact hypotheses fail"), "{err}");
}
