//! Benchmarks of the dynamics: q̈ from the equations of motion on open serial chains of N bodies
//! (as `Dynamics` picks the solver, by the articulated-body algorithm, by CRBA and Cholesky)
//! and on three closed chains (a trilithon, a four-hinge arch, a 2×2 colonnade) at consistent states, and the
//! smooth integration of 1 s of the closed chains (constrained form, DOP853).

use std::collections::BTreeMap;
use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::DVector;

use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::integrator::{Method, Options};
use crr_dynamics::{
    Dynamics, Form, ForwardSolver, InitialSpec, InitialState, integrate_smooth, solve_initial,
};
use crr_kinematics::fixtures::{colonnade, four_hinge_arch, serial_chain, trilithon};
use crr_kinematics::{ActivePivots, Model, Side, StructureSpec};

/// Chain lengths of the scaling study.
const SIZES: [usize; 8] = [1, 2, 4, 8, 16, 32, 64, 128];

/// The closed chains: name, structure, the coordinate given an angle and a rate.
fn closed_chains() -> [(&'static str, StructureSpec, &'static str, f64, f64); 3] {
    [
        (
            "trilithon",
            trilithon(0.25, 1.5, 2.0, 0.5, 1.0),
            "base_left",
            0.05,
            0.1,
        ),
        (
            "four_hinge_arch",
            four_hinge_arch(4.0, 4.6, 1.0, false),
            "springing_right",
            0.02,
            0.05,
        ),
        (
            // 2×2 colonnade: 10 coordinates, 12 closure rows of rank 8.
            "colonnade",
            colonnade(0.2, 1.5, 1.2, 0.4),
            "base_1.1",
            0.03,
            0.1,
        ),
    ]
}

/// The consistent initial state with `coord` at `angle` and rate `rate`.
fn consistent(model: &Model, coord: &str, angle: f64, rate: f64) -> InitialState {
    let spec = InitialSpec {
        angles: BTreeMap::from([(coord.to_string(), angle)]),
        rates: BTreeMap::from([(coord.to_string(), rate)]),
    };
    solve_initial(model, &spec).expect("consistent initial state")
}

/// q̈ of the serial chains of N bodies with the given solver, as the group `name`.
fn forward_dynamics_with(c: &mut Criterion, name: &str, solver: ForwardSolver) {
    let mut group = c.benchmark_group(name);
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    let ground = GroundMotion::none();
    for n in SIZES {
        let model = Model::from_spec(&serial_chain(n)).expect("valid serial chain");
        let q = DVector::from_fn(n, |k, _| 0.3 * ((k + 1) as f64).sin());
        let qdot = DVector::from_fn(n, |k, _| 0.5 * ((2 * k + 1) as f64).cos());
        let mut pivots = ActivePivots::uniform(&model, Side::Positive);
        pivots.follow_coordinates(&q);
        let mut dynamics = Dynamics::new(&model, pivots);
        dynamics.solver = solver;
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                dynamics
                    .accelerations(&model, &ground, 0.0, black_box(&q), black_box(&qdot))
                    .expect("regular mass matrix");
                black_box(&dynamics.qddot);
            });
        });
    }
    group.finish();
}

/// What `Dynamics::accelerations` picks (`ForwardSolver::Auto`).
fn forward_dynamics(c: &mut Criterion) {
    forward_dynamics_with(c, "forward_dynamics", ForwardSolver::Auto);
}

/// The articulated-body algorithm at every N (kinematics, Q, Q_g and q̈ in O(N)).
fn forward_dynamics_aba(c: &mut Criterion) {
    forward_dynamics_with(c, "forward_dynamics_aba", ForwardSolver::ArticulatedBody);
}

/// M by composite rigid bodies, h, Q, Cholesky at every N (the crossover's other side).
fn forward_dynamics_cholesky(c: &mut Criterion) {
    forward_dynamics_with(c, "forward_dynamics_cholesky", ForwardSolver::Cholesky);
}

fn closed_chain_accelerations(c: &mut Criterion) {
    let mut group = c.benchmark_group("closed_chains");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    let ground = GroundMotion::none();
    for (name, spec, coord, angle, rate) in closed_chains() {
        let model = Model::from_spec(&spec).expect("valid closed chain");
        let init = consistent(&model, coord, angle, rate);
        let mut dynamics = Dynamics::new(&model, init.pivots.clone());
        group.bench_function(BenchmarkId::new("accelerations", name), |b| {
            b.iter(|| {
                dynamics
                    .accelerations(
                        &model,
                        &ground,
                        0.0,
                        black_box(&init.q),
                        black_box(&init.qdot),
                    )
                    .expect("solvable closed chain");
                black_box((&dynamics.qddot, &dynamics.lambda));
            });
        });
    }
    group.finish();
}

fn integrate_1s(c: &mut Criterion) {
    let mut group = c.benchmark_group("integrate_1s");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    let ground = GroundMotion::none();
    let options = Options {
        rtol: 1e-10,
        ..Options::default()
    };
    for (name, spec, coord, angle, rate) in closed_chains() {
        let model = Model::from_spec(&spec).expect("valid closed chain");
        let init = consistent(&model, coord, angle, rate);
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                integrate_smooth(
                    &model,
                    &ground,
                    black_box(&init),
                    1.0,
                    0.01,
                    Method::Dop853,
                    options,
                    Form::Constrained,
                )
                .expect("smooth run")
            });
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    forward_dynamics,
    forward_dynamics_aba,
    forward_dynamics_cholesky,
    closed_chain_accelerations,
    integrate_1s
);
criterion_main!(benches);
