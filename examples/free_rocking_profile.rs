//! The free-rocking bench case (`benches/simulation.rs`, `free_rocking/single_block`) repeated
//! N times, for instruction counts that do not depend on the machine's load: Housner's block
//! (b = 0.2 m, h = 1 m) released at θ₀ = α/2, 15 s at rtol 1e-10. Prints the last run's impacts,
//! energy-balance error and right-hand sides (134, about 2.3e-8 J, 7 156), and the mean time.
//!
//! ```sh
//! cargo build --profile bench --example free_rocking_profile
//! valgrind --tool=callgrind target/release/examples/free_rocking_profile 20
//! ```
//!
//! A second argument sets the output interval (s, 0.01 unless given), e.g. `20 15` for no samples
//! but the first and the last.
//!
//! The instructions reported divided by N are the cost of one run (the model's set-up is a few
//! thousandths of them); docs/performance.md quotes them.

use std::collections::BTreeMap;
use std::time::Instant;

use crr::dynamics::ground_motion::GroundMotion;
use crr::dynamics::integrator::Options;
use crr::dynamics::{InitialSpec, solve_initial};
use crr::impact::{Parameters, Simulation};
use crr::kinematics::{Model, fixtures::single_block};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let runs: usize = match std::env::args().nth(1) {
        Some(s) => s
            .parse()
            .map_err(|e| format!("the number of runs {s:?}: {e}"))?,
        None => 20,
    };
    // The output interval (s), 0.01 s as in the bench unless given: the cost of the output
    // samples is the difference between two counts.
    let output_interval: f64 = match std::env::args().nth(2) {
        Some(s) => s
            .parse()
            .map_err(|e| format!("the output interval {s:?}: {e}"))?,
        None => 0.01,
    };
    let (b, h) = (0.2, 1.0);
    let alpha = f64::atan(b / h);
    let model = Model::from_spec(&single_block(b, h, 2500.0))?;
    let init = solve_initial(
        &model,
        &InitialSpec {
            angles: BTreeMap::from([("base".into(), alpha / 2.0)]),
            ..Default::default()
        },
    )?;
    let ground = GroundMotion::none();
    let params = Parameters {
        duration: 15.0,
        options: Options {
            rtol: 1e-10,
            atol: 1e-12,
            ..Options::default()
        },
        output_interval,
        ..Parameters::default()
    };
    let start = Instant::now();
    let mut last = None;
    for _ in 0..runs {
        let traj = Simulation::new(&model, &ground, &init, params.clone())?
            .run()
            .map_err(|f| f.error)?;
        last = Some(traj);
    }
    let elapsed = start.elapsed().as_secs_f64();
    if let Some(traj) = last {
        println!(
            "{runs} runs: {} impacts, energy-balance error {:.3e} J, {} right-hand sides; {:.3} ms a run",
            traj.impacts.len(),
            traj.energy_balance_error,
            traj.solver_stats.rhs_evals,
            1e3 * elapsed / runs as f64
        );
    }
    Ok(())
}
