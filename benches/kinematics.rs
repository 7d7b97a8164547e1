//! Benchmarks of the kinematics: M(q) and h(q, q̇) by the recursive algorithms (forward kinematics,
//! composite-rigid-body mass matrix, spatial velocities, velocity product) on serial chains of N
//! bodies with non-parallel axes, and the eq-2 γ assembly of M (the allocating reference).

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::DVector;

use crr_kinematics::fixtures::serial_chain;
use crr_kinematics::{
    ActivePivots, Data, Model, Side, forward_kinematics, mass_matrix, mass_matrix_gamma,
    velocities, velocity_product,
};

/// Chain lengths of the scaling study.
const SIZES: [usize; 8] = [1, 2, 4, 8, 16, 32, 64, 128];

/// A fixed non-zero state (q, q̇) of a serial chain and its active pivots.
fn state(model: &Model) -> (DVector<f64>, DVector<f64>, ActivePivots) {
    let n = model.dof();
    let q = DVector::from_fn(n, |k, _| 0.3 * ((k + 1) as f64).sin());
    let qdot = DVector::from_fn(n, |k, _| 0.5 * ((2 * k + 1) as f64).cos());
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    pivots.follow_coordinates(&q);
    (q, qdot, pivots)
}

fn mass_matrix_and_h(c: &mut Criterion) {
    let mut group = c.benchmark_group("mass_matrix_and_h");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    for n in SIZES {
        let model = Model::from_spec(&serial_chain(n)).expect("valid serial chain");
        let (q, qdot, pivots) = state(&model);
        let mut data = Data::new(&model);
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                forward_kinematics(&model, &mut data, black_box(&q), &pivots);
                mass_matrix(&model, &mut data);
                velocities(&model, &mut data, black_box(&qdot));
                velocity_product(&model, &mut data);
                black_box((&data.mass_matrix, &data.velocity_product));
            });
        });
    }
    group.finish();
}

fn mass_matrix_gamma_reference(c: &mut Criterion) {
    let mut group = c.benchmark_group("mass_matrix_gamma");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    for n in [1, 2, 4, 8] {
        let model = Model::from_spec(&serial_chain(n)).expect("valid serial chain");
        let (q, _, pivots) = state(&model);
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| mass_matrix_gamma(&model, black_box(&q), &pivots));
        });
    }
    group.finish();
}

criterion_group!(benches, mass_matrix_and_h, mass_matrix_gamma_reference);
criterion_main!(benches);
