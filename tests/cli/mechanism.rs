//! `crr assemble --mechanism`: the limit analysis of an assembly per direction and the model of
//! its rigid domains. Checked against what is known without the code under test: a panel cut
//! into courses and the running-bond wall whose head joints are contacts overturn whole
//! (λ = b/h by virtual work of the monolith, one rigid domain); the merged model keeps the
//! multiplier of the model of every contact in every direction asked for (merging only removes
//! joints the mechanism does not move: the static theorem gives the same λ); the arch's domains
//! lie between the joints where the thrust line touches the intrados or the extrados
//! (`tests/statics/independent.rs` checks those against a thrust-line LP); and the merged arch
//! moves exactly as the arch of every contact while no other joint opens.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use crr::analysis::assemble::{AssemblyOptions, read_assembly};
use crr::analysis::rigid_domains::{MechanismModel, mechanism_model};
use crr::impact::SlotState;
use crr::impact::statics::{StaticsOptions, collapse_multiplier};
use crr::kinematics::{Model, Parent};
use crr::output::assemble::{write_merged_model, write_model};

use crate::common;

fn bundled_assembly(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("examples/assemblies/{name}.toml"))
}

fn mechanism(path: &Path, planar: bool, directions: &[Vector3<f64>]) -> MechanismModel {
    let file = read_assembly(path).unwrap();
    mechanism_model(
        path,
        &file,
        directions,
        &AssemblyOptions {
            planar,
            ..Default::default()
        },
    )
    .unwrap()
}

fn lambda(model: &Model, d: Vector3<f64>) -> Option<f64> {
    collapse_multiplier(model, d, &StaticsOptions::default())
        .unwrap()
        .lambda
}

/// λ of the program without sliding (`sliding_lift_off` off).
fn convex_lambda(model: &Model, d: Vector3<f64>) -> Option<f64> {
    let options = StaticsOptions {
        sliding_lift_off: false,
        ..StaticsOptions::default()
    };
    collapse_multiplier(model, d, &options).unwrap().lambda
}

fn along_x() -> Vec<Vector3<f64>> {
    vec![Vector3::x(), -Vector3::x()]
}

fn horizontal() -> Vec<Vector3<f64>> {
    vec![Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()]
}

/// Writes the model of every contact and the merged model of `m` in a scratch folder `tag` and
/// runs both through `crr::run` (each must complete): (every contact, merged).
fn run_both(m: &MechanismModel, tag: &str) -> (crr::Run, crr::Run) {
    let dir = common::scratch(tag);
    let (all_path, merged_path) = (dir.join("every_contact.toml"), dir.join("merged.toml"));
    write_model(&m.all_contacts, &all_path, true).unwrap();
    write_merged_model(m, &merged_path, true).unwrap();
    let run = |p: &Path| {
        let input = crr::ModelInput::read(p).unwrap();
        let run = crr::run(&input, &crr::RunOptions::default()).unwrap();
        assert!(run.completed(), "{tag}: {:?}", run.summary.error);
        run
    };
    (run(&all_path), run(&merged_path))
}

/// An assembly of `courses` boxes of `size` (ρ = `density`) stacked from the ground, named
/// `course_K`.
fn courses_text(courses: usize, size: [f64; 3], density: f64) -> String {
    let mut text = String::from("name = \"courses\"\n");
    for k in 0..courses {
        text += &format!(
            "[[body]]\nname = \"course_{k}\"\ndensity = {density}\nbox = {{ center = [0.0, 0.0, {}], size = [{}, {}, {}] }}\n",
            size[2] * (k as f64 + 0.5),
            size[0],
            size[1],
            size[2]
        );
    }
    text
}

/// A panel of 5 courses 0.4 × 0.3 × 0.5 m (2.5 m in all, ρ = 2000) rocks whole on a base edge:
/// one rigid domain, one interface on the ground, DOF(1) = DOF(2) = 2 with a rocking base (1 with
/// a hinge), λ = b/h = 0.2/1.25 = 0.16 along ±x and 0.15/1.25 = 0.12 along ±y; its compound
/// body has the panel's mass 2000 × 0.3 m³ and centre at 1.25 m.
#[test]
fn a_panel_cut_into_courses_is_one_rigid_domain_rocking_at_b_over_h() {
    let text = courses_text(5, [0.4, 0.3, 0.5], 2000.0);
    let path = common::write_model("panel_mechanism", &text);
    let m = mechanism(&path, false, &horizontal());
    assert_eq!(m.domains.len(), 1);
    assert_eq!(m.domains[0].blocks.len(), 5);
    assert_eq!(m.merged.model.interfaces.len(), 1);
    assert_eq!((m.mobility.dof1, m.mobility.dof2), (2, 2));
    let body = &m.merged.model.bodies[0];
    assert!((body.mass - 600.0).abs() < 1e-9, "{}", body.mass);
    assert!((body.com - Vector3::new(0.0, 0.0, 1.25)).norm() < 1e-12);
    for (c, expected) in m.collapses.iter().zip([0.16, 0.16, 0.12, 0.12]) {
        let l = c.lambda.unwrap();
        assert!((l - expected).abs() < 1e-9, "{:?}: {l}", c.direction);
        let merged = lambda(&m.merged.model, Vector3::from(c.direction)).unwrap();
        assert!(
            (merged - expected).abs() < 1e-9,
            "{:?}: {merged}",
            c.direction
        );
    }
    let planar = mechanism(&path, true, &along_x());
    assert_eq!((planar.mobility.dof1, planar.mobility.dof2), (1, 1));
    assert!((lambda(&planar.merged.model, Vector3::x()).unwrap() - 0.16).abs() < 1e-9);
}

/// The bundled running-bond wall (8 courses of 0.25 m, blocks 0.6 m long, 3 m long, 2 m high)
/// with its head joints as contacts (no sliding where a joint keeps contact). Its corner wedge,
/// the staircase of 16 blocks over the outer foot of course 1's end half block, turns about that
/// foot while its head and bed joints open and slide: λ = (0.3/0.25)(2·7 + 1)/(4·7 − 1) = 2/3 by
/// virtual work (`tests/statics/collapse_state.rs` derives it and certifies it as a collapse
/// state). Without that sliding the blocks are locked together and the wall overturns whole
/// about a base corner, λ = (3/2)/(2/2) = 1.5 by the virtual work of the monolith. Both
/// mechanisms' joints are hinges: the domains are the two wedges less the three blocks they
/// share near the top (13 blocks each), those three, and the rest of the wall (15 blocks), and
/// the merged model answers both: 1.5 without sliding, 2/3 with.
#[test]
fn the_running_bond_wall_loses_its_corner_wedges_before_it_overturns_whole() {
    let m = mechanism(&bundled_assembly("wall"), true, &along_x());
    for c in &m.collapses {
        assert!((c.lambda.unwrap() - 2.0 / 3.0).abs() < 1e-7, "{c:?}");
        assert!(c.from_sliding_search);
        assert!((c.convex_lambda.unwrap() - 1.5).abs() < 1e-7, "{c:?}");
    }
    let sizes: Vec<usize> = m.domains.iter().map(|d| d.blocks.len()).collect();
    assert_eq!(sizes, [15, 13, 13, 3]);
    assert!(m.domains[1].blocks.contains(&"c1_b0".to_string()));
    assert!(m.domains[2].blocks.contains(&"c1_b5".to_string()));
    let total: f64 = m.all_contacts.model.bodies.iter().map(|b| b.mass).sum();
    let merged: f64 = m.merged.model.bodies.iter().map(|b| b.mass).sum();
    assert!((merged - total).abs() <= 1e-12 * total);
    for d in along_x() {
        assert!((lambda(&m.merged.model, d).unwrap() - 2.0 / 3.0).abs() < 1e-7);
        assert!((convex_lambda(&m.merged.model, d).unwrap() - 1.5).abs() < 1e-7);
    }
}

/// The merged model has the multiplier of the model of every contact along every direction
/// asked for, by the program without sliding (1e-7, the statics' tolerance), on every bundled
/// assembly (where the search for joints that open and slide lowers λ, as on the façade, that
/// mechanism's joints are hinges too, so the domains are finer, never coarser).
#[test]
fn merged_models_keep_every_multiplier() {
    for (name, planar) in [
        ("arch", true),
        ("arch", false),
        ("trilithon", true),
        ("facade", true),
    ] {
        let directions = if planar { along_x() } else { horizontal() };
        let m = mechanism(&bundled_assembly(name), planar, &directions);
        assert!(m.domains.len() <= m.all_contacts.model.bodies.len());
        for c in &m.collapses {
            let d = Vector3::from(c.direction);
            let merged = convex_lambda(&m.merged.model, d);
            match (c.convex_lambda, merged) {
                (Some(a), Some(b)) => assert!(
                    (a - b).abs() <= 1e-7 * a.max(1.0),
                    "{name}, planar {planar}, {d:?}: every contact {a}, merged {b}"
                ),
                (a, b) => assert_eq!(a, b, "{name}, planar {planar}, {d:?}"),
            }
        }
    }
}

/// The arch of 9 voussoirs: the hinges along +x are joints 0, 3, 7, 9 and along −x 0, 2, 6, 9
/// (joint j between v_j and v_{j+1}, 0 and 9 the springings: the thrust-line LP's contacts with
/// intrados and extrados, `tests/statics/independent.rs`), so the domains are the runs of
/// voussoirs between the union {0, 2, 3, 6, 7, 9}: v1–v2, v3, v4–v6, v7, v8–v9; 5 bodies, 6
/// hinges, one loop, DOF(2) = 6 − 3 = 3 for a planar closed chain.
#[test]
fn the_arch_domains_lie_between_its_hinges() {
    let m = mechanism(&bundled_assembly("arch"), true, &along_x());
    let blocks: Vec<Vec<&str>> = m
        .domains
        .iter()
        .map(|d| d.blocks.iter().map(String::as_str).collect())
        .collect();
    assert_eq!(
        blocks,
        vec![
            vec!["v1", "v2"],
            vec!["v3"],
            vec!["v4", "v5", "v6"],
            vec!["v7"],
            vec!["v8", "v9"]
        ]
    );
    assert_eq!(m.merged.model.interfaces.len(), 6);
    assert_eq!(m.mobility.dof1, 5);
    assert_eq!(m.mobility.dof2, 3);
}

/// The angle of the interface of `a` between bodies that contain the blocks `child` and
/// `parent` of `b`'s interface `k` (+1 when they are the same way round, −1 when reversed).
fn matching_interface(m: &MechanismModel, k: usize) -> Option<(usize, f64)> {
    let all = &m.all_contacts.model;
    let merged = &m.merged.model;
    let domain_of = |block: usize| {
        let name = &all.bodies[block].name;
        m.domains
            .iter()
            .position(|d| d.blocks.contains(name))
            .unwrap()
    };
    let iface = &all.interfaces[k];
    let parent = match iface.parent {
        Parent::Ground => None,
        Parent::Body(p) => Some(domain_of(p)),
    };
    let child = domain_of(iface.child);
    merged.interfaces.iter().enumerate().find_map(|(j, i)| {
        let p = match i.parent {
            Parent::Ground => None,
            Parent::Body(p) => Some(p),
        };
        if (p, i.child) == (parent, child) {
            Some((j, 1.0))
        } else if (p, Some(i.child)) == (Some(child), parent) {
            Some((j, -1.0))
        } else {
            None
        }
    })
}

/// Under one cycle of a sine of amplitude 1.05 λ g along x, the merged arch and the arch of
/// every contact leave rest at the same instant (1e-9 relative) and their hinge angles agree
/// (1e-6 of the largest) until the arch of every contact opens a joint that the mechanism keeps
/// closed (the first hinge the merged model does not have), at least 0.05 s later.
#[test]
fn the_merged_arch_moves_as_the_arch_of_every_contact_while_its_mechanism_holds() {
    let g = 9.81;
    let source = std::fs::read_to_string(bundled_assembly("arch")).unwrap();
    let bodies = &source[..source.find("[ground_motion]").unwrap()];
    let lambda_x = 0.365716;
    let text = format!(
        "{bodies}[ground_motion]\nx = {{ sine = {{ amplitude = {}, period = 1.0, cycles = 1 }} }}\n\n[analysis]\nduration = 0.6\nmax_step = 0.002\noutput_interval = 0.001\n",
        1.05 * lambda_x * g
    );
    let path = common::write_model("arch_pulse_assembly", &text);
    let m = mechanism(&path, true, &along_x());
    let l = m.collapses[0].lambda.unwrap();
    assert!((l - lambda_x).abs() < 1e-6, "{l}");
    let (all, merged) = run_both(&m, "arch_pulse_models");
    let (ta, tm) = (
        all.trajectory.uplift_time.unwrap(),
        merged.trajectory.uplift_time.unwrap(),
    );
    assert!((ta - tm).abs() <= 1e-9 * ta, "{ta} vs {tm}");
    // The coordinates of the arch of every contact that are hinges of the merged model.
    let am = &all.model;
    let pairs: Vec<(usize, usize, f64)> = (0..am.dof())
        .filter_map(|k| {
            let (j, sign) = matching_interface(&m, am.coords[k].interface)?;
            let c = merged.model.coords.iter().position(|c| c.interface == j)?;
            Some((k, c, sign))
        })
        .collect();
    let names: Vec<String> = pairs
        .iter()
        .map(|&(k, _, _)| am.coords[k].name.clone())
        .collect();
    for hinge in ["v1_on_ground", "v9_on_ground", "v7_on_v8", "v4_on_v3"] {
        assert!(names.iter().any(|n| n == hinge), "{hinge} in {names:?}");
    }
    // The slots of the other joints (closed in the mechanism).
    let hinge_slots: Vec<usize> = (0..am.interfaces.len())
        .filter(|&i| matching_interface(&m, i).is_some())
        .flat_map(|i| am.interfaces[i].slots.clone())
        .collect();
    let samples = |r: &crr::Run| -> Vec<(f64, Vec<f64>, Vec<SlotState>)> {
        r.trajectory
            .samples
            .iter()
            .map(|s| (s.t, s.q.to_vec(), s.states.to_vec()))
            .collect()
    };
    let (sa, sm) = (samples(&all), samples(&merged));
    let held_until = sa
        .iter()
        .find(|(_, _, states)| {
            states
                .iter()
                .enumerate()
                .any(|(slot, s)| *s != SlotState::Seated && !hinge_slots.contains(&slot))
        })
        .map_or(f64::INFINITY, |s| s.0);
    assert!(held_until >= ta + 0.05, "held until {held_until}");
    let largest = sa
        .iter()
        .filter(|s| s.0 < held_until)
        .flat_map(|s| pairs.iter().map(move |&(k, _, _)| s.1[k].abs()))
        .fold(0.0, f64::max);
    assert!(largest > 1e-4, "the arch moves: {largest}");
    let mut compared = 0;
    for (t, qa, _) in sa.iter().filter(|s| s.0 < held_until) {
        let Some((_, qm, _)) = sm.iter().find(|s| s.0 == *t) else {
            continue;
        };
        for &(k, c, sign) in &pairs {
            assert!(
                (qa[k] - sign * qm[c]).abs() <= 1e-6 * largest,
                "t = {t}: {} vs {}",
                qa[k],
                sign * qm[c]
            );
        }
        compared += 1;
    }
    // At least the 0.05 s of motion at the output interval of 1 ms.
    assert!(compared > 50, "{compared} common samples");
}

/// `crr assemble --mechanism` reports λ and the moving interfaces per direction, the rigid
/// domains and the DOF, and writes a model that `crr check` and `crr simulate` run.
#[test]
fn crr_assemble_mechanism_reports_and_writes_the_merged_model() {
    let out = common::scratch("mechanism_cli");
    let model = out.join("arch_domains.toml");
    let source = bundled_assembly("arch");
    let o = common::crr(&[
        "assemble",
        source.to_str().unwrap(),
        "--planar",
        "--mechanism",
        "--out",
        model.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for line in [
        "  +x: λ = 0.365716, 4 moving interface(s): ",
        "  -x: λ = 0.365716, 4 moving interface(s): ",
        "5 rigid domain(s):",
        "  domain_v4 (3 blocks): v4, v5, v6",
        "merged model: 5 bodies, 6 interfaces, DOF(1) = 5, 1 loop closure(s)",
        "DOF(2) = 3",
    ] {
        assert!(text.contains(line), "{line:?} in {text}");
    }
    let written = std::fs::read_to_string(&model).unwrap();
    assert!(written.contains("[[body.block]]"), "{written}");
    let o = common::crr(&["check", model.to_str().unwrap()]);
    let report = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(report.contains("d = +x: λ = 0.365716"), "{report}");
    let results = out.join("run");
    let o = common::crr(&[
        "simulate",
        model.to_str().unwrap(),
        "--duration",
        "1.0",
        "--out",
        results.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // --direction needs --mechanism; a compound body is not an assembly's block.
    let o = common::crr(&["assemble", source.to_str().unwrap(), "--direction", "x"]);
    assert_eq!(o.status.code(), Some(2));
    let o = common::crr(&["assemble", model.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("an assembly lists bodies only"), "{err}");
}

/// DOF(3) from the assembly's `[[symmetry]]` tables (naming the merged model's coordinates): the
/// trilithon's one mechanism sways the two columns through equal angles (the lintel translates:
/// a parallelogram), so φ_left = φ_right keeps it (DOF(3) = 1) and the mirror relation
/// φ_left = −φ_right locks it (DOF(3) = 0). A symmetry naming no coordinate is refused naming it.
#[test]
fn symmetry_rows_of_the_assembly_give_dof3_of_the_merged_model() {
    let source = std::fs::read_to_string(bundled_assembly("trilithon")).unwrap();
    let records = format!("\"{}/examples/records/", env!("CARGO_MANIFEST_DIR"));
    let with = |relation: &str, first: &str| {
        let text = source.replace("\"../records/", &records)
            + &format!(
                "\n[[symmetry]]\ncoordinates = [\"{first}\", \"column_right_on_ground\"]\nrelation = \"{relation}\"\n"
            );
        common::write_model(&format!("trilithon_symmetry_{relation}_{first}"), &text)
    };
    for (relation, dof3) in [("equal", 1), ("opposite", 0)] {
        let m = mechanism(&with(relation, "column_left_on_ground"), true, &along_x());
        assert_eq!(m.mobility.dof2, 1);
        assert_eq!(m.mobility.symmetries, 1);
        assert_eq!(m.mobility.dof3, dof3, "{relation}");
        assert_eq!(m.merged.file.symmetry.len(), 1);
        assert!(m.all_contacts.file.symmetry.is_empty());
    }
    let path = with("equal", "nope");
    let file = read_assembly(&path).unwrap();
    let e = mechanism_model(
        &path,
        &file,
        &along_x(),
        &AssemblyOptions::default().in_plane(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("no coordinate named \"nope\""), "{e}");
}

/// Housner's block (0.4 × 0.4 × 2 m) cut into five courses, under one sine cycle of 1.5 λ g
/// (λ = b/h = 0.2, period 0.5 s): the merged model (one compound body) and the model of every
/// stone leave rest at the same instant and reach their first peak at the same time and angle
/// (1e-6 relative), the stones' beds staying seated until then: the mechanism
/// holds through the first peak.
#[test]
fn a_panel_of_courses_and_its_domain_agree_through_the_first_peak() {
    let mut text = courses_text(5, [0.4, 0.4, 0.4], 2500.0);
    text += &format!(
        "[ground_motion]\nx = {{ sine = {{ amplitude = {}, period = 0.5, cycles = 1 }} }}\n\n[analysis]\nduration = 1.5\nmax_step = 0.002\n",
        1.5 * 0.2 * 9.81
    );
    let path = common::write_model("courses_pulse", &text);
    let m = mechanism(&path, true, &along_x());
    assert_eq!(m.domains.len(), 1);
    let (stones, merged) = run_both(&m, "courses_pulse_models");
    let (ts, tm) = (
        stones.trajectory.uplift_time.unwrap(),
        merged.trajectory.uplift_time.unwrap(),
    );
    // Each model's uplift comes from its own contact program (λ to 1e-9 relative), which moves
    // the instant a(t) reaches λ g by about 1e-10 s here: 1e-6 relative, the bound.
    assert!((ts - tm).abs() <= 1e-6 * tm, "{ts} vs {tm}");
    let (ps, pm) = (&stones.trajectory.peaks[0], &merged.trajectory.peaks[0]);
    assert_eq!((ps.coordinate, pm.coordinate), (0, 0));
    assert!((ps.t - pm.t).abs() <= 1e-6 * pm.t, "{} vs {}", ps.t, pm.t);
    assert!(
        (ps.value - pm.value).abs() <= 1e-6 * pm.value.abs(),
        "{} vs {}",
        ps.value,
        pm.value
    );
    assert!(pm.value.abs() > 1e-3, "a real rocking peak: {}", pm.value);
    for s in stones.trajectory.samples.iter().filter(|s| s.t <= pm.t) {
        assert!(
            s.states[1..].iter().all(|st| *st == SlotState::Seated),
            "a bed opened at {}",
            s.t
        );
    }
}
