//! A single block rocking freely from θ₀ = α/2 (docs/physics.md §6): impact times against the exact
//! energy quadrature, the momentum law's r = 1 − 1.5 sin²α, the amplitude recurrence
//! cos(α − θₙ₊₁) − cos α = r²[cos(α − θₙ) − cos α], the energy lost (1 − r²)T⁻ at each impact,
//! and rest in finite time.

mod common;

use crr_dynamics::ground_motion::GroundMotion;
use crr_impact::{Parameters, Simulation, SlotState};
use crr_kinematics::Model;
use crr_kinematics::fixtures::single_block;

fn free_run(b: f64, h: f64, duration: f64) -> (crr_impact::Trajectory, f64, f64) {
    let model = Model::from_spec(&single_block(b, h, 2500.0)).unwrap();
    let alpha = (b / h).atan();
    let init = common::released_at(&model, "base", alpha / 2.0);
    let ground = GroundMotion::none();
    let params = Parameters {
        duration,
        options: crr_dynamics::integrator::Options {
            rtol: 1e-12,
            atol: 1e-14,
            ..Default::default()
        },
        ..Parameters::default()
    };
    let traj = Simulation::new(&model, &ground, &init, params)
        .unwrap()
        .run()
        .map_err(|f| f.error)
        .unwrap();
    let p = (3.0 * 9.81 / (4.0 * (b * b + h * h).sqrt())).sqrt();
    (traj, alpha, p)
}

#[test]
fn impact_times_match_the_energy_quadrature() {
    let (traj, alpha, p) = free_run(0.2, 1.0, 9.0);
    let r = 1.0 - 1.5 * alpha.sin().powi(2);
    assert!(traj.impacts.len() >= 10);
    // Exact sequence: fall from θ₀, then each half-cycle rises to Aₙ and falls back.
    let mut t = common::fall_time(p, alpha, alpha / 2.0);
    let mut level = (alpha - alpha / 2.0).cos() - alpha.cos();
    let mut worst: f64 = 0.0;
    for (n, imp) in traj.impacts.iter().take(10).enumerate() {
        worst = worst.max((imp.t - t).abs());
        assert!(
            (imp.t - t).abs() < 1e-8,
            "impact {n}: {} vs exact {t}",
            imp.t
        );
        level *= r * r;
        let amplitude = alpha - (level + alpha.cos()).acos();
        t += 2.0 * common::fall_time(p, alpha, amplitude);
    }
    eprintln!("first 10 impact times: max |t − t_exact| = {worst:e} s");
}

#[test]
fn momentum_law_ratio_peaks_and_energy_loss() {
    for (b, h) in [(0.2, 1.0), (0.15, 1.2), (0.4, 1.0)] {
        let (traj, alpha, _) = free_run(b, h, 15.0);
        let r = 1.0 - 1.5 * alpha.sin().powi(2);
        let mut worst_r: f64 = 0.0;
        for imp in traj.impacts.iter().take(20) {
            // A ratio of angular velocities: exact to round-off (1e-12 leaves room for the
            // velocity's own integration error entering both numerator and denominator equally).
            let ratio = imp.rates_after[0] / imp.rates_before[0];
            worst_r = worst_r.max((ratio - r).abs());
            assert!((ratio - r).abs() < 1e-12, "ratio {ratio} vs r {r}");
            // Energy lost (1 − r²) T⁻, T⁻ = ½ I₀ θ̇⁻².
            let m = 2500.0 * 8.0 * b * b * h;
            let i0 = 4.0 / 3.0 * m * (b * b + h * h);
            let t_minus = 0.5 * i0 * imp.rates_before[0].powi(2);
            assert!((imp.energy_lost - (1.0 - r * r) * t_minus).abs() < 1e-10 * t_minus);
            assert!(!imp.energy_gain);
        }
        // Successive peaks |θₙ| follow the exact recurrence to 1e-8 (dense-output peaks at rtol 1e-12).
        let peaks: Vec<f64> = traj.peaks.iter().map(|p| p.value.abs()).collect();
        assert!(peaks.len() >= 6);
        let mut worst: f64 = 0.0;
        for w in peaks.windows(2).take(10) {
            let lhs = (alpha - w[1]).cos() - alpha.cos();
            let rhs = r * r * ((alpha - w[0]).cos() - alpha.cos());
            worst = worst.max((lhs - rhs).abs());
        }
        assert!(worst < 1e-8, "peak recurrence error {worst:e}");
        eprintln!("α = {alpha:.4}: max |ratio − r| = {worst_r:e}, peak recurrence error {worst:e}");
    }
}

#[test]
fn the_block_comes_to_rest_with_a_bounded_number_of_impacts() {
    let (traj, alpha, _) = free_run(0.2, 1.0, 80.0);
    let last = traj.samples.last().unwrap();
    assert_eq!(last.states[0], SlotState::Seated, "seated at the end");
    assert!(last.q[0] == 0.0 && last.qdot[0] == 0.0);
    // Each impact multiplies the rate by r; from the first impact's rate down to the seating rate
    // 1e-4 rad/s takes ln(1e-4/θ̇₁)/ln r impacts (+1 for the seating one).
    let r = 1.0 - 1.5 * alpha.sin().powi(2);
    let first = traj.impacts[0].rates_before[0].abs();
    let bound = ((1e-4 / first).ln() / r.ln()).ceil() as usize + 2;
    assert!(
        traj.impacts.len() <= bound,
        "{} impacts, bound {bound}",
        traj.impacts.len()
    );
    let t_rest = traj.impacts.last().unwrap().t;
    assert!(t_rest < 80.0);
    // Energy: everything the block had above rest was dissipated at the impacts.
    let e0 = traj.samples.first().unwrap().potential;
    assert!(
        (last.dissipated - e0).abs() < 1e-8 * e0,
        "dissipated {} vs initial {e0}",
        last.dissipated
    );
    assert!(traj.energy_balance_error < 1e-8 * e0);
    eprintln!(
        "rest at t = {t_rest:.6} s after {} impacts (bound {bound})",
        traj.impacts.len()
    );
}
