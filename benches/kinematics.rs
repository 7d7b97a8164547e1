//! Benchmarks of the kinematics: M(q) and h(q, q̇) by the recursive algorithms (forward kinematics,
//! composite-rigid-body mass matrix, spatial velocities, velocity product) on serial chains of N
//! bodies with non-parallel axes, and the eq-2 γ assembly of M (the allocating reference); the
//! convex hull of a polyhedron body against its number of vertices (`convex_hull`: the timings
//! docs/model-format.md gives for `MAX_HULL_POINTS`).

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::{DVector, Vector3};

use crr_kinematics::fixtures::serial_chain;
use crr_kinematics::shapes::convex_hull_faces;
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

/// `n` points spread evenly on a sphere of radius 1 m (the golden-angle spiral): every one is a
/// hull vertex, the hull's worst case for its size.
fn sphere_points(n: usize) -> Vec<Vector3<f64>> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * k as f64;
            Vector3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

fn convex_hull(c: &mut Criterion) {
    let mut group = c.benchmark_group("convex_hull");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_secs(2));
    for n in [100, 200, 500, 1000] {
        let points = sphere_points(n);
        // Every point is a vertex: the faces use all of them.
        let faces = convex_hull_faces(&points).expect("a sphere's hull");
        let used: std::collections::BTreeSet<usize> = faces.iter().flatten().copied().collect();
        assert_eq!(
            used.len(),
            n,
            "{n} points on a sphere are all hull vertices"
        );
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| convex_hull_faces(black_box(&points)).expect("hull"));
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    mass_matrix_and_h,
    mass_matrix_gamma_reference,
    convex_hull
);
criterion_main!(benches);
