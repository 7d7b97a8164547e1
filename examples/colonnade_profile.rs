//! The `colonnade_row` bench case (`benches/simulation.rs`) for profiling: a planar row of k
//! columns of three drums under architraves (`fixtures::colonnade_row`), 6 s of the bundled
//! record along x. Prints DOF, impacts, steps, energy-balance error and the wall time.
//!
//! ```sh
//! cargo build --profile bench --example colonnade_profile
//! perf record -F 199 --call-graph dwarf,16384 target/release/examples/colonnade_profile 16
//! ```

use std::path::Path;
use std::time::Instant;

use crr::dynamics::ground_motion::{
    Axis, ComponentSpec, GroundMotion, RecordFormat, RecordSpec, SignalSpec,
};
use crr::dynamics::{InitialSpec, solve_initial};
use crr::impact::{Parameters, Simulation};
use crr::kinematics::{Model, fixtures::colonnade_row};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let columns: usize = match std::env::args().nth(1) {
        Some(s) => s
            .parse()
            .map_err(|e| format!("the number of columns {s:?}: {e}"))?,
        None => 16,
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let record = ComponentSpec::new(SignalSpec::Record(RecordSpec {
        file: root.join("examples/records/synthetic.AT2"),
        format: RecordFormat::PeerAt2,
        units: None,
        time_column: None,
        accel_column: None,
        skip_rows: None,
    }));
    let ground = GroundMotion::none().with_component(Axis::X, &record, root)?;
    let model = Model::from_spec(&colonnade_row(columns, 3))?;
    let init = solve_initial(&model, &InitialSpec::default())?;
    let params = Parameters {
        duration: 6.0,
        ..Parameters::default()
    };
    let start = Instant::now();
    let traj = Simulation::new(&model, &ground, &init, params)?
        .run()
        .map_err(|f| f.error)?;
    println!(
        "{columns} columns: DOF {}, {} impacts, {} steps, energy-balance error {:.3e} J; {:.3} s",
        model.dof(),
        traj.impacts.len(),
        traj.solver_stats.steps,
        traj.energy_balance_error,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
