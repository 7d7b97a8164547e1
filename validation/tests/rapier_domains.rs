//! A model of rigid domains (`crr assemble --mechanism`) against the same assembly's stones, in
//! crr and in rapier.
//!
//! The assembly: Housner's block of `examples/models/single_block.toml` (0.4 × 0.4 × 2 m,
//! ρ = 2500) cut into five courses of 0.4 m. No mechanism separates them (λ = b/h = 0.2 along ±x,
//! the whole panel rocking on its base), so the merged model is one compound body on one hinge,
//! with the block's mass properties. Released at θ₀ = 0.1 rad:
//! - the merged model's first crossing is the exact quarter period of the block (the energy
//!   quadrature of `src/closed_forms.rs`), to 1e-6 relative, as the single block's is;
//! - the model of every stone (five bodies, a hinge on every bed) crosses at the same instant
//!   (1e-6), its beds between courses never opening;
//! - rapier, with the merged model as one rigid body whose colliders are the five boxes,
//!   crosses within 0.5 % of crr, the bound measured for rapier on the single block
//!   (`rapier_block.rs`): +0.090 % here, +0.048 % for the uncut block;
//! - rapier with the five stones as separate rigid bodies keeps every bed closed until the
//!   crossing (below 1e-4 rad: the panel rocks as one domain there too), but crosses 5.7 % late
//!   (0.5246 s against 0.4966 s), whatever its contact stiffness (500 to 4000 Hz: 0.5243–0.5246 s)
//!   or solver substeps (4 to 64: 0.5236–0.5246 s): a stack of separate bodies in its iterative
//!   contact solver rocks slower than the same stones as one body. Printed, not asserted.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use crr::analysis::assemble::{AssemblyOptions, read_assembly};
use crr::analysis::rigid_domains::mechanism_model;
use crr::analysis::simulation::{Prepared, prepare};
use crr::dynamics::InitialSpec;
use crr::output::assemble::{write_merged_model, write_model};
use crr::{ModelInput, RunOptions};
use crr_validation::closed_forms::Block;
use crr_validation::run::run;
use crr_validation::scene::Settings;

fn scratch() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("rapier_domains");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn prepared(path: &Path) -> Prepared {
    let options = RunOptions {
        duration: Some(0.6),
        ..Default::default()
    };
    prepare(&ModelInput::read(path).unwrap(), &options).unwrap()
}

fn tilted(coordinate: &str) -> Option<InitialSpec> {
    Some(InitialSpec {
        angles: BTreeMap::from([(coordinate.to_string(), 0.1)]),
        rates: BTreeMap::new(),
    })
}

#[test]
fn a_block_cut_in_courses_rocks_as_one_domain_in_crr_and_in_rapier() {
    let dir = scratch();
    let mut text = String::from("name = \"courses\"\n");
    for k in 0..5 {
        text += &format!(
            "[[body]]\nname = \"course_{k}\"\ndensity = 2500.0\nbox = {{ center = [0.0, 0.0, {}], size = [0.4, 0.4, 0.4] }}\n",
            0.2 + 0.4 * k as f64
        );
    }
    let assembly = dir.join("courses.toml");
    std::fs::write(&assembly, text).unwrap();
    let file = read_assembly(&assembly).unwrap();
    let directions = [Vector3::x(), -Vector3::x()];
    let mut m = mechanism_model(
        &assembly,
        &file,
        &directions,
        &AssemblyOptions::default().in_plane(),
    )
    .unwrap();
    for c in &m.collapses {
        assert!((c.lambda.unwrap() - 0.2).abs() < 1e-9, "{c:?}");
    }
    assert_eq!(m.domains.len(), 1);
    assert_eq!(m.merged.model.dof(), 1);
    assert_eq!(m.all_contacts.model.dof(), 5);

    // Both models released at 0.1 rad on the base, the stones above seated on one another.
    m.merged.file.initial = tilted(&m.merged.model.coords[0].name);
    m.all_contacts.file.initial = tilted("course_0_on_ground");
    assert_eq!(m.all_contacts.model.coords[0].name, "course_0_on_ground");
    let (merged_path, stones_path) = (dir.join("merged.toml"), dir.join("stones.toml"));
    write_merged_model(&m, &merged_path, true).unwrap();
    write_model(&m.all_contacts, &stones_path, true).unwrap();

    let merged = prepared(&merged_path);
    let exact = Block::new(0.2, 1.0, merged.model.gravity).quarter_period(0.1);
    let merged_run = merged.run();
    let merged_first = merged_run.trajectory.impacts[0].t;
    assert!(
        ((merged_first - exact) / exact).abs() < 1e-6,
        "merged {merged_first} vs exact {exact}"
    );

    let stones = prepared(&stones_path);
    let stones_run = stones.run();
    let first = &stones_run.trajectory.impacts[0];
    assert!(
        ((first.t - merged_first) / merged_first).abs() < 1e-6,
        "stones {} vs merged {merged_first}",
        first.t
    );
    assert_eq!(first.interfaces, ["course_0_on_ground"]);

    // Rapier: the merged model (one rigid body, the five boxes its colliders) and the stones
    // (five rigid bodies in contact).
    let first_crossing = |r: &crr_validation::run::RapierRun| {
        r.t.windows(2)
            .zip(r.q.windows(2))
            .find(|(_, q)| q[0][0] != 0.0 && q[0][0] * q[1][0] < 0.0)
            .map(|(t, q)| t[0] + (t[1] - t[0]) * q[0][0] / (q[0][0] - q[1][0]))
            .expect("rapier's panel crosses")
    };
    let domain = run(&merged, &Settings::default()).unwrap();
    let domain_crossing = first_crossing(&domain);
    let off = (domain_crossing - merged_first) / merged_first;
    println!(
        "first crossing: exact {exact}, crr {merged_first}, rapier domain {domain_crossing} ({off:+.2e})"
    );
    assert!(
        off.abs() < 5e-3,
        "rapier {domain_crossing} vs crr {merged_first}"
    );
    assert!(domain.max_slip < 1e-4, "slip {}", domain.max_slip);

    let rapier = run(&stones, &Settings::default()).unwrap();
    let crossing = first_crossing(&rapier);
    // Until the crossing the beds between the courses stay closed in rapier too.
    let largest_bed = rapier
        .t
        .iter()
        .zip(&rapier.q)
        .filter(|(t, _)| **t < crossing)
        .flat_map(|(_, q)| q[1..].iter().map(|x| x.abs()))
        .fold(0.0, f64::max);
    println!(
        "rapier stones: crossing {crossing} ({:+.2e} against crr), largest bed angle before it {largest_bed:e} rad",
        (crossing - merged_first) / merged_first
    );
    assert!(largest_bed < 1e-4, "a bed opened in rapier: {largest_bed}");
}
