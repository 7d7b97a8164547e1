//! Benchmarks of `crr assemble` on a wall of about 200 stones (20 courses of a running-bond wall
//! of 10 blocks 0.6 × 0.3 × 0.25 m: 210 blocks): finding the contacts and building the model
//! (`assemble_200/contacts_and_model`), and the collapse multiplier of the assembled model along +x
//! (`assemble_200/collapse_multiplier`), the limit analysis that the mechanism step of the
//! assembly takes per direction; the whole of `crr assemble --mechanism --planar` (contacts, the
//! limit analysis along ±x of every contact, the rigid domains and their model:
//! `assemble_200/mechanism_model`, issue target ≤ 1 s), and 10 s of the bundled record on the
//! merged model it writes (`assemble_200/simulate_merged_10s`, issue target ≤ 1 s).

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;

use crr::analysis::assemble::{AssemblyOptions, read_assembly};
use crr::analysis::rigid_domains::mechanism_model;
use crr::impact::statics::{StaticsOptions, collapse_multiplier};
use crr::kinematics::Model;
use crr::kinematics::assembly::{ContactSet, InterfaceStyle, detect_contacts, structure_of};
use crr::kinematics::fixtures::running_bond_wall;
use crr::output::assemble::write_merged_model;

fn wall_of_200(c: &mut Criterion) {
    let bodies = running_bond_wall(20, 10, 0.6, 0.25, 0.3).body;
    let assemble = || {
        let contacts = detect_contacts(&bodies, 1e-6, ContactSet::Beds, 0.0, &[]).unwrap();
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
    // The same wall as an assembly file, under the bundled record.
    let dir = std::env::temp_dir().join("crr_bench_assemble");
    std::fs::create_dir_all(&dir).unwrap();
    let record = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/records/synthetic.AT2")
        .canonicalize()
        .unwrap();
    let mut text = String::from("name = \"wall_200\"\n");
    for b in &bodies {
        text += &toml::to_string(&ToToml {
            body: vec![b.clone()],
        })
        .unwrap();
    }
    text += &format!(
        "[ground_motion]\nx = {{ record = {{ file = \"{}\", format = \"peer-at2\" }} }}\n\n[analysis]\nduration = 10.0\n",
        record.display()
    );
    let path = dir.join("wall_200.toml");
    std::fs::write(&path, text).unwrap();
    let file = read_assembly(&path).unwrap();
    let directions = [Vector3::x(), -Vector3::x()];
    let mechanism = || {
        mechanism_model(
            &path,
            &file,
            &directions,
            &AssemblyOptions::default().in_plane(),
        )
        .unwrap()
    };
    let m = mechanism();
    let merged_path = dir.join("wall_200_domains.toml");
    write_merged_model(&m, &merged_path, true).unwrap();
    let merged = crr::ModelInput::read(&merged_path).unwrap();
    println!(
        "assemble_200 --mechanism: λ = {:?} along ±x, {} rigid domain(s), DOF(1) = {}, DOF(2) = {}",
        m.collapses.iter().map(|c| c.lambda).collect::<Vec<_>>(),
        m.domains.len(),
        m.mobility.dof1,
        m.mobility.dof2
    );
    group.bench_function("mechanism_model", |b| b.iter(|| black_box(mechanism())));
    group.bench_function("simulate_merged_10s", |b| {
        b.iter(|| black_box(crr::run(&merged, &crr::RunOptions::default()).unwrap()))
    });
    group.finish();
}

/// One `[[body]]` table.
#[derive(serde::Serialize)]
struct ToToml {
    body: Vec<crr::kinematics::spec::BodySpec>,
}

criterion_group!(benches, wall_of_200);
criterion_main!(benches);
