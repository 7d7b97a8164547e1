//! Smooth integration (no impacts, fixed dynamic chain) from a consistent initial state, in the
//! constrained or the reduced form, sampled at a fixed interval. The step never crosses a
//! breakpoint of the ground motion (a record sample, a pulse edge): every one is landed on.

use nalgebra::DVector;

use crr_kinematics::Model;

use crate::closed_chain::{InitialState, REPARTITION_THRESHOLD, partition, partition_condition};
use crate::eom::Dynamics;
use crate::ground_motion::GroundMotion;
use crate::integrator::{Method, NoEvents, OdeSystem, Options, SolveError, Solver};
use crate::system::{ConstrainedSystem, ReducedSystem};

/// Which form of the equations to integrate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Form {
    /// All DOF(1) coordinates with multipliers and projection.
    Constrained,
    /// The DOF(2) independent coordinates, dependent ones by Newton.
    Reduced,
}

/// One output sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// q (rad).
    pub q: DVector<f64>,
    /// q̇ (rad/s).
    pub qdot: DVector<f64>,
    /// Work done by the ground motion since the start (J).
    pub work_in: f64,
}

/// Integrates from `init` at t = 0 to `t_end`, sampling every `dt` (and at t = 0).
pub fn integrate_smooth(
    model: &Model,
    ground: &GroundMotion,
    init: &InitialState,
    t_end: f64,
    dt: f64,
    method: Method,
    options: Options,
    form: Form,
) -> Result<Vec<Sample>, SolveError> {
    let mut dynamics = Dynamics::new(model, init.pivots.clone());
    let mut out = vec![Sample {
        t: 0.0,
        q: init.q.clone(),
        qdot: init.qdot.clone(),
        work_in: 0.0,
    }];
    let n_samples = (t_end / dt).round() as usize;
    let stops = |t: f64, k: usize| -> f64 {
        let next_sample = (k as f64 * dt).min(t_end);
        ground
            .next_breakpoint(t)
            .map_or(next_sample, |b| b.min(next_sample))
    };
    match form {
        Form::Constrained => {
            let mut sys = ConstrainedSystem::new(model, ground, &mut dynamics);
            let mut solver = Solver::new(method, options, 2 * model.dof() + 2)?;
            solver.reset(0.0, &ConstrainedSystem::pack(&init.q, &init.qdot, 0.0, 0.0));
            for k in 1..=n_samples {
                while solver.t() < (k as f64 * dt).min(t_end) {
                    let target = stops(solver.t(), k);
                    advance_unread(&mut solver, &mut sys, target)?;
                }
                let (n, y) = (model.dof(), solver.y());
                out.push(Sample {
                    t: solver.t(),
                    q: DVector::from_column_slice(&y[..n]),
                    qdot: DVector::from_column_slice(&y[n..2 * n]),
                    work_in: y[2 * n],
                });
            }
        }
        Form::Reduced => {
            // The partition is chosen again (and the solver restarted from the same full state)
            // whenever its dependent block becomes ill-conditioned.
            let mut part = partition(model, &init.q, &init.pivots);
            let (mut q, mut qdot, mut work) = (init.q.clone(), init.qdot.clone(), 0.0);
            let mut t = 0.0;
            let mut k = 1;
            while k <= n_samples {
                let mut sys = ReducedSystem::new(model, ground, &mut dynamics, part.clone(), &q);
                let k_dof = sys.reduced_dof();
                let mut solver = Solver::new(method, options, 2 * k_dof + 1)?;
                solver.reset(t, &sys.pack(&q, &qdot, work));
                let mut repartition = false;
                while k <= n_samples && !repartition {
                    while solver.t() < (k as f64 * dt).min(t_end) {
                        let target = stops(solver.t(), k);
                        advance_unread(&mut solver, &mut sys, target)?;
                    }
                    let y = solver.y().to_vec();
                    sys.expand(&y).map_err(|source| SolveError::Rhs {
                        t: solver.t(),
                        source,
                    })?;
                    (q, qdot, work, t) =
                        (sys.q.clone(), sys.qdot.clone(), y[2 * k_dof], solver.t());
                    out.push(Sample {
                        t,
                        q: q.clone(),
                        qdot: qdot.clone(),
                        work_in: work,
                    });
                    k += 1;
                    if partition_condition(model, &q, &sys.dynamics.pivots, &part)
                        < REPARTITION_THRESHOLD
                    {
                        part = partition(model, &q, &sys.dynamics.pivots);
                        repartition = true;
                    }
                }
            }
        }
    }
    Ok(out)
}

/// Advances `solver` to `target` without events, reading no step's interpolant (the samples are
/// taken at step ends, `target` a breakpoint): DOP853's extra stages are never computed.
fn advance_unread(
    solver: &mut Solver,
    sys: &mut impl OdeSystem,
    target: f64,
) -> Result<(), SolveError> {
    solver.advance_lazily(sys, target, &mut NoEvents, &mut |_| false, &mut |_, _| {})?;
    Ok(())
}
