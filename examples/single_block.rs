//! Housner's block through the library API: a 0.4 m × 0.4 m × 2 m stone block (b = 0.2 m,
//! h = 1 m, `crr_kinematics::fixtures::single_block`) released from rest at θ₀ = α/2, free
//! rocking for 10 s. Prints each fact next to what it should be: the closed-form quarter period,
//! the coefficient of restitution r = 1 − 1.5 sin²α of the momentum law, the peak angle θ₀, an
//! energy balance at round-off, no collapse.
//!
//! ```sh
//! cargo run --release --example single_block
//! ```

use std::collections::BTreeMap;

use crr::dynamics::ground_motion::GroundMotion;
use crr::dynamics::{InitialSpec, solve_initial};
use crr::impact::{Parameters, Simulation};
use crr::kinematics::{Model, fixtures::single_block};

/// Time (s) for the block to fall from rest at θm to θ = 0 under θ̈ = −p² sin(α − θ):
/// τ = ∫₀^θm dθ / √(2p²(cos(α − θm) − cos(α − θ))), with θ = θm − u² and Simpson's rule.
fn quarter_period(alpha: f64, p2: f64, tm: f64) -> f64 {
    let f = |u: f64| {
        if u == 0.0 {
            2.0 / (2.0 * p2 * (alpha - tm).sin()).sqrt()
        } else {
            let th = tm - u * u;
            2.0 * u / (2.0 * p2 * ((alpha - tm).cos() - (alpha - th).cos())).sqrt()
        }
    };
    let (z, n) = (tm.sqrt(), 2000);
    let h = z / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(0.0) + f(z) + inner) * h / 3.0
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (b, h, density) = (0.2, 1.0, 2500.0);
    let spec = single_block(b, h, density);
    let g = spec.gravity;
    let model = Model::from_spec(&spec)?;
    let alpha = f64::atan(b / h);
    let big_r = b.hypot(h);
    let p2 = 3.0 * g / (4.0 * big_r);
    let theta0 = alpha / 2.0;
    let initial = solve_initial(
        &model,
        &InitialSpec {
            angles: BTreeMap::from([("base".to_string(), theta0)]),
            ..Default::default()
        },
    )?;
    let ground = GroundMotion::none();
    let params = Parameters {
        duration: 10.0,
        ..Parameters::default()
    };
    let run = Simulation::new(&model, &ground, &initial, params)?
        .run()
        .map_err(|f| f.error)?;

    let r = 1.0 - 1.5 * alpha.sin().powi(2);
    println!(
        "Housner's block b = {b} m, h = {h} m: α = {alpha:.6} rad, p = √(3g/4R) = {:.6} rad/s, released from θ₀ = α/2 = {theta0:.6} rad, 10 s",
        p2.sqrt()
    );
    println!("impacts: {} in 10 s", run.impacts.len());
    let first = run.impacts.first().ok_or("no impact")?;
    let tau = quarter_period(alpha, p2, theta0);
    println!(
        "first impact at t = {:.9} s; should be the quarter period ∫dθ/θ̇ = {tau:.9} s (difference {:.1e} s)",
        first.t,
        first.t - tau
    );
    let ratios: Vec<f64> = run
        .impacts
        .iter()
        .map(|i| i.rates_after[0] / i.rates_before[0])
        .collect();
    let worst = ratios.iter().fold(0.0f64, |m, x| m.max((x - r).abs()));
    println!(
        "rate ratio θ̇⁺/θ̇⁻ at the first impact {:.12}; should be r = 1 − 1.5 sin²α = {r:.12} (largest deviation over all impacts {worst:.1e})",
        ratios[0]
    );
    let peak = run.peak_abs[0];
    println!(
        "peak |θ| = {peak:.9} rad = {:.6} α; should be θ₀ = {theta0:.9} rad = 0.5 α",
        peak / alpha
    );
    let lost: f64 = run.impacts.iter().map(|i| i.energy_lost).sum();
    let mass = density * (2.0 * b) * (2.0 * b) * (2.0 * h);
    let e0 = mass * g * big_r * ((alpha - theta0).cos() - alpha.cos());
    println!(
        "energy: E(0) = m g R (cos(α − θ₀) − cos α) = {e0:.6} J, lost at impacts {lost:.6} J; balance error |T + U − W + D − E(0)| = {:.2e} J = {:.1e} E(0); should be ~0 (integration tolerance rtol 1e-10)",
        run.energy_balance_error,
        run.energy_balance_error / e0
    );
    println!(
        "collapse: {}; should be no (θ₀ < α and no ground motion)",
        match &run.collapse {
            Some(c) => format!("yes, {} at {:.3} s", c.body, c.t),
            None => "no".into(),
        }
    );
    Ok(())
}
