//! The paper's Dirac-delta impact (eq 5) in the simulation: integrated exactly it multiplies the
//! rate by r^C at every crossing; regularised with a unit-area bump of width ε it converges to the
//! restitution result with error O(ε).

use std::collections::BTreeMap;

use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::{InitialSpec, solve_initial};
use crr_impact::{Parameters, Simulation, Trajectory};
use crr_kinematics::fixtures::single_block;
use crr_kinematics::{ImpactLaw, Model};

fn run(law: ImpactLaw, duration: f64) -> Trajectory {
    let mut spec = single_block(0.2, 1.0, 2500.0);
    spec.interface[0].impact = law;
    let model = Model::from_spec(&spec).unwrap();
    let init = solve_initial(
        &model,
        &InitialSpec {
            angles: BTreeMap::from([("base".into(), 0.1)]),
            ..Default::default()
        },
    )
    .unwrap();
    let params = Parameters {
        duration,
        options: crr_dynamics::integrator::Options {
            rtol: 1e-12,
            atol: 1e-14,
            ..Default::default()
        },
        ..Parameters::default()
    };
    Simulation::new(&model, &GroundMotion::none(), &init, params)
        .unwrap()
        .run()
        .map_err(|f| f.error)
        .unwrap()
}

#[test]
fn exact_dirac_multiplies_the_rate_by_r_to_the_c() {
    for c in [0.5, 1.0, 2.0] {
        let traj = run(ImpactLaw::Dirac { r: 0.8, c }, 3.0);
        assert!(traj.impacts.len() >= 3);
        for imp in &traj.impacts {
            let ratio = imp.rates_after[0] / imp.rates_before[0];
            assert!((ratio - 0.8f64.powf(c)).abs() < 1e-12, "C = {c}: {ratio}");
        }
    }
    // C = 1 is the classical restitution law.
    let (a, b) = (
        run(ImpactLaw::Dirac { r: 0.8, c: 1.0 }, 3.0),
        run(ImpactLaw::Restitution(0.8), 3.0),
    );
    // The two laws give the same map up to round-off (r^(1/2)·r^(1/2) vs r); the runs then agree
    // to the integration tolerance.
    assert_eq!(a.impacts.len(), b.impacts.len());
    let (mut dt, mut dv): (f64, f64) = (0.0, 0.0);
    for (x, y) in a.impacts.iter().zip(&b.impacts) {
        dt = dt.max((x.t - y.t).abs());
        dv = dv.max((x.rates_after[0] - y.rates_after[0]).abs());
    }
    eprintln!("Dirac C = 1 vs restitution: |Δt| ≤ {dt:e} s, |Δθ̇⁺| ≤ {dv:e} rad/s");
    assert!(dt < 1e-9 && dv < 1e-9);
}

#[test]
fn regularised_dirac_converges_to_restitution_with_order_one() {
    let reference = run(ImpactLaw::Restitution(0.8), 2.0);
    // The first peak after the first crossing measures the rate that left the impact.
    let first_peak = |t: &Trajectory| {
        t.peaks
            .iter()
            .find(|p| p.value < 0.0)
            .map(|p| p.value)
            .unwrap()
    };
    let exact = first_peak(&reference);
    let widths = [1e-2, 1e-3, 1e-4];
    let errors: Vec<f64> = widths
        .iter()
        .map(|&w| {
            let traj = run(
                ImpactLaw::DiracRegularised {
                    r: 0.8,
                    c: 1.0,
                    width: w,
                },
                2.0,
            );
            // No impulsive event: the crossing switches the pivot with continuous rate.
            assert!(
                traj.impacts
                    .iter()
                    .all(|i| (i.rates_after[0] - i.rates_before[0]).abs() < 1e-12)
            );
            // The energy the bump removes is booked as dissipated: the balance closes.
            assert!(
                traj.energy_balance_error < 1e-7 * traj.samples[0].potential,
                "{:e}",
                traj.energy_balance_error
            );
            ((first_peak(&traj) - exact) / exact).abs()
        })
        .collect();
    let orders: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log10()).collect();
    eprintln!("regularised δ: errors {errors:?}, observed orders {orders:?}");
    for o in orders {
        assert!((o - 1.0).abs() < 0.3, "observed order {o}");
    }
    assert!(errors[2] < 1e-3);
}
