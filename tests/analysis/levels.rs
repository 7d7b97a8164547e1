//! Energy levels of one-DOF mechanisms (`crr::analysis::levels`, `crr check --plot`, `crr plot`): the
//! engine's U(θ) and M(θ) along the mechanism against closed forms (single block, trilithon of
//! identical columns), against the engine's generalized gravity and its free-rocking simulation
//! (arch), and the files written.

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::DVector;

use crate::common::{crr, scratch};
use crr::analysis::levels::{
    LevelSample, MechanismLevels, SideEnd, evaluate, mechanism_levels, opening_pivots,
    rest_potential,
};
use crr::dynamics::ground_motion::GroundMotion;
use crr::dynamics::{InitialSpec, solve_initial};
use crr::impact::simulation::{Parameters, Simulation, StopReason};
use crr::load_model;

fn model(name: &str) -> crr::kinematics::Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("examples/models/{name}.toml"));
    load_model(&path).expect("bundled model loads").1
}

const G: f64 = 9.81;

/// Checks every sample against U(θ) = k_u (cos(α − |θ|) − cos α), U′ = sgn θ k_u sin(α − |θ|) and
/// M(θ) = m0, to `tol` relative (k_u for U and U′, m0 for M); both sides end at the overturning
/// angle ±α.
fn assert_block_like(levels: &MechanismLevels, alpha: f64, k_u: f64, m0: f64, tol: f64) {
    let samples: Vec<LevelSample> = levels.samples();
    assert!(samples.len() > 200, "{} samples", samples.len());
    for s in &samples {
        let a = s.theta.abs();
        let u = k_u * ((alpha - a).cos() - alpha.cos());
        let du = s.theta.signum() * k_u * (alpha - a).sin();
        assert!(
            (s.potential - u).abs() <= tol * k_u,
            "θ = {}: U = {} against {u}",
            s.theta,
            s.potential
        );
        if s.theta != 0.0 {
            assert!(
                (s.slope - du).abs() <= tol * k_u,
                "θ = {}: U′ = {} against {du}",
                s.theta,
                s.slope
            );
        }
        assert!(
            (s.mass - m0).abs() <= tol * m0,
            "θ = {}: M = {} against {m0}",
            s.theta,
            s.mass
        );
    }
    for side in [&levels.negative, &levels.positive] {
        assert_eq!(side.end, SideEnd::Overturning);
        // U′ is linear in θ − α there: the bisection on U′ stops within 1e-13 rad.
        assert!(
            (side.last().theta.abs() - alpha).abs() < 1e-9,
            "end {}",
            side.last().theta
        );
    }
    let top = k_u * (1.0 - alpha.cos());
    let sep = levels.separatrix.expect("both sides overturn");
    assert!(
        (sep - top).abs() <= tol * k_u,
        "separatrix {sep} against {top}"
    );
}

/// (a) Single block 0.4 × 0.4 × 2 m, ρ = 2500: U = mgR (cos(α − |θ|) − cos α) relative to rest and
/// M = I₀ = (4/3) m R² about either pivot edge, to 1e-10 (round-off of a Newton-free evaluation).
#[test]
fn single_block_levels_are_the_block_formula() {
    let m = model("single_block");
    let levels = mechanism_levels(&m, 1e-3).unwrap();
    let (b, h) = (0.2f64, 1.0f64);
    let mass = 2500.0 * 0.4 * 0.4 * 2.0;
    let r = b.hypot(h);
    let alpha = (b / h).atan();
    assert_block_like(
        &levels,
        alpha,
        mass * G * r,
        4.0 / 3.0 * mass * r * r,
        1e-10,
    );
    assert_eq!(levels.coordinate, "base");
}

/// (b) Trilithon of identical columns 2b × 2h (b = 0.25, h = 2, mass m_c) under a cap beam m_b.
/// For θ > 0 both columns rotate by θ about their +x base edges (a parallelogram), and the beam
/// rests on their −x top edges, diagonally opposite the base pivots: those points move on circles
/// of radius 2R, so the beam translates with them, its centre rising by 2R (cos(α − θ) − cos α)
/// (2h = 2R cos α). Hence U = g (2 m_c + 2 m_b) R (cos(α − |θ|) − cos α) and
/// M = 2 (4/3) m_c R² + m_b (2R)², constant (mirror image for θ < 0); at rest this gives
/// p̂² = √(U′² + U″²)/M = p² (1 + 2γ)/(1 + 3γ), γ = m_b/(2 m_c) (Makris & Vassiliou 2013).
/// Tolerance 1e-9: the closure Newton solve stops at 1e-13 of the model size.
#[test]
fn trilithon_levels_are_the_frame_closed_form() {
    let m = model("trilithon");
    let levels = mechanism_levels(&m, 1e-3).unwrap();
    let (b, h) = (0.25f64, 2.0f64);
    let m_c = 2500.0 * 0.5 * 0.5 * 4.0;
    let m_b = 2500.0 * 3.5 * 0.5 * 0.6;
    let r = b.hypot(h);
    let alpha = (b / h).atan();
    let k_u = G * (2.0 * m_c + 2.0 * m_b) * r;
    let m0 = 2.0 * 4.0 / 3.0 * m_c * r * r + m_b * 4.0 * r * r;
    assert_block_like(&levels, alpha, k_u, m0, 1e-9);
    // The same closed form as Makris & Vassiliou's p̂².
    let gamma = m_b / (2.0 * m_c);
    let p2 = 3.0 * G / (4.0 * r) * (1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma);
    assert!((k_u / m0 - p2).abs() < 1e-12 * p2);
}

/// The closed configuration at θ on side `sign`, reached by continuation from rest in steps of
/// 0.01 rad (Newton from the previous configuration).
fn closed_at(
    m: &crr::kinematics::Model,
    pivots: &crr::kinematics::ActivePivots,
    theta: f64,
) -> DVector<f64> {
    let u0 = rest_potential(m);
    let mut q = DVector::zeros(m.dof());
    let n = (theta.abs() / 0.01).ceil() as usize;
    for i in 1..=n {
        let t = theta * i as f64 / n as f64;
        q = evaluate(m, pivots, 0, &q, t, u0).unwrap().0;
    }
    q
}

/// (c) Four-hinge arch (no closed form): along the levels dU/dθ, the central difference of the
/// engine's potential energy U(q(θ)) (eq 3, heights of the centres), equals the engine's
/// generalized gravity projected on the mechanism, −Bᵀ Q_g (Jacobians, a different code path).
/// Step h = 1e-4 rad: truncation h²|U‴|/6 with |U‴| of order W L (W the weight, L the model size;
/// a few times larger through the mechanism's lever ratios) is ~1e-8 W L (measured: up to
/// 1.4e-8 W L), round-off ε W L / h ~ 1e-12 W L; tolerance 1e-6 W L. M(θ) > 0 everywhere, U > 0 away from rest (rest
/// is the minimum of U along the mechanism).
#[test]
fn arch_levels_slope_is_the_engine_gravity_force() {
    let m = model("arch");
    let levels = mechanism_levels(&m, 1e-3).unwrap();
    let w = m.total_mass() * G;
    let l = m.size;
    for s in levels.samples() {
        assert!(s.mass.is_finite() && s.mass > 0.0, "{s:?}");
        if s.theta != 0.0 {
            assert!(s.potential > 0.0, "{s:?}");
        }
    }
    let u0 = rest_potential(&m);
    let h = 1e-4;
    let mut checked = 0;
    for side in [&levels.negative, &levels.positive] {
        assert_eq!(side.end, SideEnd::Overturning, "{:?}", side.end);
        let pivots = opening_pivots(&m, 0, side.sign).unwrap();
        let reach = side.last().theta;
        for f in [0.1, 0.3, 0.5, 0.7, 0.9] {
            let theta = f * reach;
            let q = closed_at(&m, &pivots, theta);
            let (_, mid) = evaluate(&m, &pivots, 0, &q, theta, u0).unwrap();
            let (_, up) = evaluate(&m, &pivots, 0, &q, theta + h, u0).unwrap();
            let (_, down) = evaluate(&m, &pivots, 0, &q, theta - h, u0).unwrap();
            let fd = (up.potential - down.potential) / (2.0 * h);
            eprintln!(
                "θ = {theta:.5}: |FD − U′|/(W L) = {:.2e}",
                (fd - mid.slope).abs() / (w * l)
            );
            assert!(
                (fd - mid.slope).abs() <= 1e-6 * w * l,
                "θ = {theta}: FD {fd} against U′ {} (W L = {})",
                mid.slope,
                w * l
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 10);
}

/// The arch's levels against its free rocking: released at rest from θm on each side, the engine
/// (the full constrained equations of motion, not the reduction) reaches θ = 0 with
/// |θ̇| = √(2 U(θm) / M(0±)) by conservation of energy, M(0±) the reduced mass of that side at
/// rest. Tolerance 1e-8: a hundred times the integrator's rtol 1e-10 (measured: 1e-10); U(θm) is
/// evaluated at θm itself, not interpolated.
#[test]
fn arch_levels_hold_the_engine_free_rocking() {
    let m = model("arch");
    let levels = mechanism_levels(&m, 1e-3).unwrap();
    let u0 = rest_potential(&m);
    for side in [&levels.positive, &levels.negative] {
        let theta_m = 0.5 * side.last().theta;
        let pivots = opening_pivots(&m, 0, side.sign).unwrap();
        let q = closed_at(&m, &pivots, theta_m);
        let (_, at_m) = evaluate(&m, &pivots, 0, &q, theta_m, u0).unwrap();
        let m0 = side.samples[0].mass;
        let expected = (2.0 * at_m.potential / m0).sqrt();
        let spec = InitialSpec {
            angles: [(levels.coordinate.clone(), theta_m)].into_iter().collect(),
            rates: BTreeMap::new(),
        };
        let initial = solve_initial(&m, &spec).unwrap();
        let ground = GroundMotion::none();
        let params = Parameters {
            duration: 5.0,
            output_interval: 1.0,
            ..Parameters::default()
        };
        let mut sim = Simulation::new(&m, &ground, &initial, params).unwrap();
        let rate = loop {
            match sim.step().unwrap() {
                StopReason::Impact(i) => {
                    let imp = &sim.impacts[i];
                    let k = imp.slots.iter().position(|&s| s == 0).expect("θ impacts");
                    break imp.rates_before[k];
                }
                StopReason::End(_) | StopReason::Collapse(_) => panic!("no impact"),
                _ => {}
            }
        };
        eprintln!(
            "side {}: relative error {:.2e}",
            side.sign,
            (rate.abs() - expected).abs() / expected
        );
        assert!(
            (rate.abs() - expected).abs() <= 1e-8 * expected,
            "side {}: |θ̇(0)| = {} against √(2U/M) = {expected}",
            side.sign,
            rate.abs()
        );
        // It falls towards rest: the rate has the opposite sign of θm.
        assert!(rate * theta_m < 0.0);
    }
}

/// A PNG of 1000 × 700 pixels with a drawn plot (a blank one compresses to a few kB).
fn assert_png(file: &Path) {
    let bytes = std::fs::read(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    assert_eq!(&bytes[1..4], b"PNG", "{}", file.display());
    let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((width, height), (1000, 700));
    assert!(
        bytes.len() > 30_000,
        "{}: {} bytes",
        file.display(),
        bytes.len()
    );
}

/// (d) `crr check MODEL --plot DIR` writes levels.png/.svg/.csv for the trilithon and the arch: the
/// images are drawn plots, the SVG names the separatrix and θ, and the CSV holds θ increasing with
/// M > 0, U ≥ 0 and U = 0 at rest.
#[test]
fn check_plot_writes_the_levels_of_trilithon_and_arch() {
    for (name, coord) in [("trilithon", "base_left"), ("arch", "springing_right")] {
        let dir = scratch(&format!("levels_{name}"));
        let o = crr(&[
            "check",
            &format!("examples/models/{name}.toml"),
            "--plot",
            dir.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8(o.stdout).unwrap();
        assert!(text.contains("energy levels of"), "{text}");
        assert_png(&dir.join("levels.png"));
        assert_png(&dir.join("housner.png"));
        let svg = std::fs::read_to_string(dir.join("levels.svg")).unwrap();
        assert!(svg.len() > 20_000, "{} bytes", svg.len());
        assert!(svg.contains("separatrix") && svg.contains(coord));
        let csv = std::fs::read_to_string(dir.join("levels.csv")).unwrap();
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some("side,theta,U,dU_dtheta,M"));
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').skip(1).map(|x| x.parse().unwrap()).collect())
            .collect();
        assert!(rows.len() > 200);
        assert!(rows.windows(2).all(|w| w[0][0] <= w[1][0]));
        assert!(
            rows.iter()
                .all(|r| r[3] > 0.0 && r[1] >= -1e-9 && r.len() == 4)
        );
        assert!(rows.iter().any(|r| r[0] == 0.0 && r[1].abs() < 1e-9));
    }
}

/// `crr simulate … --plot` of the trilithon (a closed chain) draws its mechanism levels on the
/// phase portrait; a two-DOF stack has none.
#[test]
fn phase_plot_of_a_closed_chain_has_the_levels() {
    let dir = scratch("levels_phase_trilithon");
    let o = crr(&[
        "simulate",
        "examples/models/trilithon.toml",
        "--duration",
        "1",
        "--quiet",
        "--plot",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let svg = std::fs::read_to_string(dir.join("phase.svg")).unwrap();
    assert!(svg.contains("separatrix"));
    let dir = scratch("levels_phase_stack");
    let o = crr(&[
        "simulate",
        "examples/models/two_block_stack.toml",
        "--duration",
        "0.5",
        "--quiet",
        "--plot",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let svg = std::fs::read_to_string(dir.join("phase.svg")).unwrap();
    assert!(!svg.contains("separatrix"));
}

/// The drawn level curves of the trilithon: every point holds U(θ) + ½ M θ̇² = E with the closed
/// forms of U and M above (1e-9 of the energy scale, as the samples), the curve is closed (starts
/// and ends at the left turning point with θ̇ = 0) and its turning points are the roots of
/// U(θ*) = E, θ* = ±(α − arccos(cos α + E/k_u)), to the linear interpolation between samples
/// 1e-3 rad apart: h² |U″| / (8 |U′|) < 1e-5 rad away from the top, where U′ > 0.05 k_u.
#[test]
fn trilithon_level_curves_hold_their_energy() {
    let m = model("trilithon");
    let levels = mechanism_levels(&m, 1e-3).unwrap();
    let (b, h) = (0.25f64, 2.0f64);
    let m_c = 2500.0 * 0.5 * 0.5 * 4.0;
    let m_b = 2500.0 * 3.5 * 0.5 * 0.6;
    let r = b.hypot(h);
    let alpha = (b / h).atan();
    let k_u = G * (2.0 * m_c + 2.0 * m_b) * r;
    let m0 = 2.0 * 4.0 / 3.0 * m_c * r * r + m_b * 4.0 * r * r;
    assert_eq!(levels.energies.len(), 3);
    for e in levels.energies.clone() {
        let curve = levels.curve(e);
        assert!(curve.len() > 100);
        let turning = alpha - ((alpha.cos() + e / k_u).acos());
        let (first, last) = (curve[0], curve[curve.len() - 1]);
        assert_eq!(first, last, "closed curve");
        assert_eq!(first.1, 0.0);
        assert!(
            (first.0 + turning).abs() < 1e-5,
            "{} against −{turning}",
            first.0
        );
        let right = curve.iter().map(|p| p.0).fold(f64::MIN, f64::max);
        assert!((right - turning).abs() < 1e-5, "{right} against {turning}");
        for &(theta, rate) in &curve {
            if rate == 0.0 {
                continue;
            }
            let u = k_u * ((alpha - theta.abs()).cos() - alpha.cos());
            let total = u + 0.5 * m0 * rate * rate;
            assert!(
                (total - e).abs() <= 1e-9 * k_u,
                "θ = {theta}: {total} against {e}"
            );
        }
    }
}

/// A slender block (b/h = 0.02, α = 0.02 rad, 20 steps of 1e-3 rad) is followed again in finer steps
/// (at least 100 per side), and its levels are still the block formula to 1e-10.
#[test]
fn slender_block_levels_are_refined() {
    let text = r#"
name = "slender"
[[body]]
name = "block"
density = 2000.0
box = { center = [0.0, 0.0, 2.5], size = [0.2, 0.2, 5.0] }
[[interface]]
name = "base"
parent = "ground"
child = "block"
axis = [0.0, 1.0, 0.0]
pivot_positive = [0.1, 0.0, 0.0]
pivot_negative = [-0.1, 0.0, 0.0]
"#;
    let file = crr::input::model_file::parse_model_file(Path::new("slender.toml"), text).unwrap();
    let m = crr::kinematics::Model::from_spec(&file.structure()).unwrap();
    let levels = mechanism_levels(&m, 1e-3).unwrap();
    for side in [&levels.negative, &levels.positive] {
        assert!(side.samples.len() > 100, "{} samples", side.samples.len());
    }
    let (b, h) = (0.1f64, 2.5f64);
    let mass = 2000.0 * 0.2 * 0.2 * 5.0;
    let r = b.hypot(h);
    assert_block_like(
        &levels,
        (b / h).atan(),
        mass * G * r,
        4.0 / 3.0 * mass * r * r,
        1e-10,
    );
}

/// The levels drawn are those of the side `crr check` reports, whatever the sense the file gives
/// the coordinate: a leaning block (parallelogram section, centroid 0.05 m off its base's centre,
/// 1 m up: Housner's α = atan 0.15 on its weak side, atan 0.25 on the other) written with its
/// hinge in both senses has the same level energies, the weak side's U(θm) at θm = 0.25, 0.5 and
/// 0.75 of its overturning angle atan 0.15: m g R (cos(α − θm) − cos α) with R = √(0.15² + 1).
#[test]
fn the_levels_are_those_of_the_reported_side_in_either_sense() {
    let block = crate::common::leaning_block;
    // m = 2000 kg/m³ × (0.4 m × 2 m section) × 0.4 m.
    let (m, alpha, r) = (2000.0 * 0.8 * 0.4, 0.15f64.atan(), 0.15f64.hypot(1.0));
    let weak = |f: f64| m * 9.81 * r * ((alpha - f * alpha).cos() - alpha.cos());
    let mut all = Vec::new();
    for (tag, text) in [
        ("levels_leaning_plus", block(1.0, 0.2, -0.2)),
        ("levels_leaning_minus", block(-1.0, -0.2, 0.2)),
    ] {
        let path = crate::common::write_model(tag, &text);
        let model = load_model(&path).unwrap().1;
        let levels = mechanism_levels(&model, 1e-3).unwrap();
        assert_eq!(levels.energies.len(), 3, "{tag}: {:?}", levels.energies);
        for (e, f) in levels.energies.iter().zip([0.25, 0.5, 0.75]) {
            // Linear interpolation between samples h = 1e-3 rad apart: within h²/8 max|U″|,
            // |U″| ≤ m g R.
            let tol = 1e-6 / 8.0 * m * 9.81 * r;
            assert!((e - weak(f)).abs() < tol, "{tag}: {e} vs {}", weak(f));
        }
        all.push(levels.energies);
    }
    for (a, b) in all[0].iter().zip(&all[1]) {
        assert!((a - b).abs() < 1e-9 * a, "{a} vs {b}");
    }
}
