//! Benchmarks of `crr assemble` on a wall of about 200 stones (20 courses of a running-bond wall
//! of 10 blocks 0.6 × 0.3 × 0.25 m: 210 blocks): finding the contacts and building the model
//! (`assemble_200/contacts_and_model`), and the collapse multiplier of the assembled model along +x
//! (`assemble_200/collapse_multiplier`), the limit analysis that the mechanism step of the
//! assembly takes per direction. Issue target: both together ≤ 1 s.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;

use crr::impact::statics::{StaticsOptions, collapse_multiplier};
use crr::kinematics::Model;
use crr::kinematics::assembly::{ContactSet, InterfaceStyle, detect_contacts, structure_of};
use crr::kinematics::fixtures::running_bond_wall;

fn wall_of_200(c: &mut Criterion) {
    let bodies = running_bond_wall(20, 10, 0.6, 0.25, 0.3).body;
    let assemble = || {
        let contacts = detect_contacts(&bodies, 1e-6, ContactSet::Beds).unwrap();
        let spec = structure_of(
            "wall",
            9.81,
            &bodies,
            &contacts,
            InterfaceStyle::PlanarHinge,
            ContactSet::Beds,
            1e-6,
        )
        .unwrap();
        Model::from_spec(&spec).unwrap()
    };
    let model = assemble();
    println!(
        "assemble_200: {} stones, {} interfaces, DOF(1) = {}",
        model.bodies.len(),
        model.interfaces.len(),
        model.dof()
    );
    let mut group = c.benchmark_group("assemble_200");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    group.bench_function("contacts_and_model", |b| b.iter(|| black_box(assemble())));
    group.bench_function("collapse_multiplier", |b| {
        b.iter(|| {
            black_box(
                collapse_multiplier(&model, Vector3::x(), &StaticsOptions::default()).unwrap(),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, wall_of_200);
criterion_main!(benches);
