//! Benchmarks of the statics on the contact faces: `crr check`'s static multipliers (±x, ±y,
//! with the friction each needs) of the bundled temple, the collapse multiplier of semicircular
//! arches of N voussoirs along +x, and of planar running-bond walls of n × n blocks, with the
//! growth exponent of the cost printed for each family (log-log slope between its first and last
//! sizes).

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;

use crr::impact::statics::{StaticsOptions, collapse_multiplier};
use crr::kinematics::Model;
use crr::kinematics::fixtures::{running_bond_wall, voussoir_arch};

fn bundled(name: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("examples/models/{name}.toml"));
    crr::load_model(&path).expect("bundled model loads").1
}

fn temple_check(c: &mut Criterion) {
    let mut group = c.benchmark_group("static_multipliers");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    let model = bundled("temple");
    group.bench_function("temple", |b| {
        b.iter(|| black_box(crr::analysis::static_multiplier::static_multipliers(&model).unwrap()))
    });
    group.finish();
}

/// Mean seconds of one collapse multiplier along +x (a few runs).
fn seconds(model: &Model) -> f64 {
    let runs = 3;
    let start = Instant::now();
    for _ in 0..runs {
        black_box(collapse_multiplier(model, Vector3::x(), &StaticsOptions::default()).unwrap());
    }
    start.elapsed().as_secs_f64() / runs as f64
}

fn family(c: &mut Criterion, name: &str, models: Vec<(usize, usize, Model)>) {
    let mut group = c.benchmark_group(name);
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(3));
    for (size, bodies, model) in &models {
        group.bench_with_input(BenchmarkId::from_parameter(size), bodies, |b, _| {
            b.iter(|| {
                black_box(
                    collapse_multiplier(model, Vector3::x(), &StaticsOptions::default()).unwrap(),
                )
            })
        });
    }
    group.finish();
    let (first, last) = (&models[0], &models[models.len() - 1]);
    let exponent =
        (seconds(&last.2) / seconds(&first.2)).ln() / (last.1 as f64 / first.1 as f64).ln();
    println!(
        "{name}: cost grows as (bodies)^{exponent:.2} from {} to {} bodies",
        first.1, last.1
    );
}

fn arches(c: &mut Criterion) {
    let models = [5, 11, 21, 41]
        .into_iter()
        .map(|n| {
            let model = Model::from_spec(&voussoir_arch(n, 2.0, 2.5, 1.0)).unwrap();
            (n, model.bodies.len(), model)
        })
        .collect();
    family(c, "arch_collapse", models);
}

fn walls(c: &mut Criterion) {
    let models = [3, 5, 8, 10]
        .into_iter()
        .map(|n| {
            let model = Model::from_spec(&running_bond_wall(n, n, 1.0, 0.5, 0.5)).unwrap();
            (n, model.bodies.len(), model)
        })
        .collect();
    family(c, "wall_collapse", models);
}

criterion_group!(benches, temple_check, arches, walls);
criterion_main!(benches);
