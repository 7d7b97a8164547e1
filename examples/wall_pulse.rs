//! A planar running-bond wall of n × n blocks (`fixtures::running_bond_wall`, blocks 1.0 × 0.5 m,
//! 0.5 m deep) under a one-sine pulse along x of amplitude `factor` × its collapse multiplier
//! λ g (period 0.5 s), 3 s (or the duration given third): blocks lift off one of their supports and land again
//! (docs/simulation.md, "Faces that open"). Prints DOF, loops, λ, impacts, faces opened, steps,
//! the end, the energy-balance error and the wall time; the landings of open faces (and how many
//! came within 10 µs of their opening) and the hypotheses monitor's first violation, if any. For
//! profiling:
//!
//! ```sh
//! cargo build --profile bench --example wall_pulse
//! target/release/examples/wall_pulse 10 1.5
//! ```

use std::path::Path;
use std::time::Instant;

use crr::dynamics::ground_motion::{Axis, ComponentSpec, GroundMotion, PulseSpec, SignalSpec};
use crr::dynamics::{InitialSpec, solve_initial};
use crr::impact::statics::{StaticsOptions, collapse_multiplier};
use crr::impact::{Parameters, Simulation, SlotState};
use crr::kinematics::{Model, fixtures::running_bond_wall};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(Ok(10), |s| s.parse())?;
    let factor: f64 = args.next().map_or(Ok(1.5), |s| s.parse())?;
    let duration: f64 = args.next().map_or(Ok(3.0), |s| s.parse())?;
    let model = Model::from_spec(&running_bond_wall(n, n, 1.0, 0.5, 0.5))?;
    let x = nalgebra::Vector3::x();
    let lambda = collapse_multiplier(&model, x, &StaticsOptions::default())?
        .lambda
        .ok_or("the wall holds up to 10 g")?;
    let pulse = SignalSpec::OneSinePulse(PulseSpec {
        amplitude: factor * lambda * model.gravity,
        period: 0.5,
        start: 0.0,
    });
    let ground =
        GroundMotion::none().with_component(Axis::X, &ComponentSpec::new(pulse), Path::new("."))?;
    let init = solve_initial(&model, &InitialSpec::default())?;
    let params = Parameters {
        duration,
        ..Parameters::default()
    };
    let start = Instant::now();
    let (traj, error) = match Simulation::new(&model, &ground, &init, params)?.run() {
        Ok(t) => (t, None),
        Err(f) => (f.partial, Some(f.error.to_string())),
    };
    let seconds = start.elapsed().as_secs_f64();
    let opened = (0..model.slot_count)
        .filter(|&s| traj.samples.iter().any(|x| x.states[s] == SlotState::Open))
        .count();
    println!(
        "{n} x {n} wall, λ = {lambda:.4}, pulse {factor} λ g: DOF {}, {} loops, {} impacts, \
         {opened} faces opened, {} steps, end {:.4} s, energy-balance error {:.3e} J; {seconds:.2} s",
        model.dof(),
        model.closures.len(),
        traj.impacts.len(),
        traj.solver_stats.steps,
        traj.end_time,
        traj.energy_balance_error
    );
    // Faces that land again within 10 µs of opening (a lift-off the chain did not follow).
    let mut opened_at = vec![f64::NEG_INFINITY; model.slot_count];
    let (mut landings, mut at_once) = (0usize, 0usize);
    let samples: Vec<_> = traj.samples.iter().collect();
    for pair in samples.windows(2) {
        for s in 0..model.slot_count {
            let (was, is) = (pair[0].states[s], pair[1].states[s]);
            if is == SlotState::Open && was != SlotState::Open {
                opened_at[s] = pair[1].t;
            }
            if was == SlotState::Open && is != SlotState::Open {
                landings += 1;
                if pair[1].t - opened_at[s] < 1e-5 {
                    at_once += 1;
                }
            }
        }
    }
    println!("{landings} landings of open faces, {at_once} of them within 10 µs of the opening");
    if let Some(v) = &traj.violation {
        let force = if v.kind == "lift_off" {
            String::new()
        } else if v.kind == "impulse_tension" {
            format!(" (normal impulse {:.1} N s)", v.normal)
        } else {
            format!(" (normal force {:.1} N)", v.normal)
        };
        println!(
            "first hypothesis violation: at t = {:.4} s, interface {}: {}{force}",
            v.t, v.interface, v.kind
        );
    }
    if let Some(e) = error {
        println!("stopped: {e}");
    }
    Ok(())
}
