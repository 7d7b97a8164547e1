//! A structure at rest under a constant ground acceleration leaves rest exactly at its collapse
//! multiplier: 1 % above λ it opens at t = 0, 1 % below it stays at rest, in every direction
//! asked. λ comes from the contact faces' linear program (`crr check`); the run decides with the
//! simulation's own uplift test, which at rest with every joint seated also consults the same
//! global program where the local search over pivot sides finds nothing. Where the mechanism
//! lifts a block off a support, the run takes those faces out of the dynamic chain (their slots
//! `open`, docs/simulation.md "Faces that open") instead of leaving the structure at rest.
//!
//! 1 % is far outside both tests' thresholds (1e-9 g/size on accelerations, 1e-9 relative on λ).
use nalgebra::Vector3;

use crate::common::bundled_model as bundled;
use crr::dynamics::ground_motion::{Axis, ComponentSpec, ConstantSpec, GroundMotion, SignalSpec};
use crr::dynamics::{InitialSpec, solve_initial};
use crr::impact::statics::{StaticsOptions, collapse_multiplier};
use crr::impact::{Parameters, Simulation, SimulationError, SlotState};
use crr::kinematics::Model;

fn constant_ground(a: Vector3<f64>) -> GroundMotion {
    let mut ground = GroundMotion::none();
    for (axis, value) in [(Axis::X, a.x), (Axis::Y, a.y), (Axis::Z, a.z)] {
        if value != 0.0 {
            let spec = ComponentSpec::new(SignalSpec::Constant(ConstantSpec { value }));
            ground = ground
                .with_component(axis, &spec, std::path::Path::new("."))
                .unwrap();
        }
    }
    ground
}

/// The outcome of 0.05 s from rest under a constant ground acceleration.
enum Outcome {
    AtRest,
    /// Left rest at this time; `opened`: some loop-closing face lifted off (an `open` slot).
    Uplift {
        t: f64,
        opened: bool,
    },
    LiftOff(Vec<String>),
}

fn run_from_rest(model: &Model, a: Vector3<f64>) -> Outcome {
    let ground = constant_ground(a);
    let initial = solve_initial(model, &InitialSpec::default()).unwrap();
    let params = Parameters {
        duration: 0.05,
        ..Default::default()
    };
    // A lift-off at t = 0 is found when the run is set up.
    let sim = match Simulation::new(model, &ground, &initial, params) {
        Ok(sim) => sim,
        Err(SimulationError::LiftOff {
            interfaces,
            t,
            in_flight,
            ..
        }) => {
            assert_eq!(t, 0.0);
            // A mechanism at λ turns blocks about other contacts: none flies.
            assert!(in_flight.is_empty(), "{in_flight:?}");
            return Outcome::LiftOff(interfaces);
        }
        Err(e) => panic!("{e}"),
    };
    match sim.run() {
        Ok(t) => match t.uplift_time {
            Some(u) => Outcome::Uplift {
                t: u,
                opened: t
                    .samples
                    .iter()
                    .any(|s| s.states.contains(&SlotState::Open)),
            },
            None => Outcome::AtRest,
        },
        Err(failure) => match failure.error {
            SimulationError::LiftOff {
                interfaces,
                in_flight,
                ..
            } => {
                assert!(in_flight.is_empty(), "{in_flight:?}");
                Outcome::LiftOff(interfaces)
            }
            e => panic!("{e}"),
        },
    }
}

/// Checks both sides of λ along `d`; returns whether the mechanism lifts off.
fn check_threshold(name: &str, model: &Model, d: Vector3<f64>) -> bool {
    let c = collapse_multiplier(model, d, &StaticsOptions::default()).unwrap();
    let lambda = c.lambda.expect("it opens");
    let lifts = c.lifting_off().next().is_some();
    let g = model.gravity;
    match run_from_rest(model, d * (0.99 * lambda * g)) {
        Outcome::AtRest => {}
        _ => panic!("{name} {d:?}: moved 1 % below λ = {lambda}"),
    }
    match run_from_rest(model, d * (1.01 * lambda * g)) {
        Outcome::Uplift { t, opened } => {
            assert_eq!(
                opened, lifts,
                "{name} {d:?}: loops open exactly when the mechanism lifts a block off"
            );
            assert_eq!(t, 0.0, "{name} {d:?}")
        }
        Outcome::LiftOff(names) => {
            assert!(lifts && !names.is_empty(), "{name} {d:?}: {names:?}")
        }
        Outcome::AtRest => panic!("{name} {d:?}: at rest 1 % above λ = {lambda}"),
    }
    lifts
}

#[test]
fn bundled_structures_leave_rest_at_their_multiplier() {
    for (name, along_y) in [
        ("single_block", false),
        ("two_block_stack", false),
        ("drum_column", false),
        ("trilithon", false),
        ("arch", false),
        ("arch_3d", true),
        ("baldachin", true),
    ] {
        let model = bundled(name);
        let mut directions = vec![Vector3::x(), -Vector3::x()];
        if along_y {
            directions.extend([Vector3::y(), -Vector3::y()]);
        }
        for d in directions {
            assert!(!check_threshold(name, &model, d), "{name}: no lift-off");
        }
    }
}

/// Semicircular arches of many voussoirs (every joint a two-sided hinge): the case where the
/// former local search over pivot sides gave direction-dependent multipliers, and a load above
/// the true one left the arch at rest in one direction.
#[test]
fn voussoir_arches_leave_rest_at_their_multiplier() {
    use crr::kinematics::fixtures::voussoir_arch;
    for n in [5, 9, 17] {
        let model = Model::from_spec(&voussoir_arch(n, 2.0, 2.5, 1.0)).unwrap();
        for d in [Vector3::x(), -Vector3::x()] {
            check_threshold(&format!("arch of {n}"), &model, d);
        }
    }
}

/// A running-bond wall fails by a corner wedge that lifts a block off one of its two supports:
/// above λ the run releases those faces' loops at t = 0 instead of staying at rest.
#[test]
fn walls_release_their_wedges_loops_above_their_multiplier() {
    use crr::kinematics::fixtures::running_bond_wall;
    let model = Model::from_spec(&running_bond_wall(3, 3, 1.0, 0.5, 0.5)).unwrap();
    let mut lifted = false;
    for d in [Vector3::x(), -Vector3::x()] {
        lifted |= check_threshold("wall 3×3", &model, d);
    }
    assert!(lifted, "the wall's mechanism lifts a block off");
}

/// Models of rigid domains (`crr assemble --mechanism`: compound bodies) leave rest at their
/// multiplier too: the arch of 9 stones as 5 domains on 6 hinges (λ = 0.365716), the domains
/// rocking with no lift-off; the multiplier is the one the model of every stone has without
/// sliding (`tests/cli/mechanism.rs`). (The bundled façade's domains collapse by its corner
/// wedges lifting off their supports at 65/138 since the search for wedges, 2026-12-03: outside
/// the CRR chain, so not a case for this test.)
#[test]
fn models_of_rigid_domains_leave_rest_at_their_multiplier() {
    use crr::analysis::assemble::{AssemblyOptions, read_assembly};
    use crr::analysis::rigid_domains::mechanism_model;
    for (name, lambda) in [("arch", 0.365716)] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("examples/assemblies/{name}.toml"));
        let file = read_assembly(&path).unwrap();
        let directions = [Vector3::x(), -Vector3::x()];
        let m = mechanism_model(
            &path,
            &file,
            &directions,
            &AssemblyOptions::default().in_plane(),
        )
        .unwrap();
        assert!(
            m.merged
                .model
                .bodies
                .iter()
                .any(|b| b.shape.kind() == "compound"),
            "{name}"
        );
        for (d, every_stone) in directions.into_iter().zip(&m.collapses) {
            let found = collapse_multiplier(&m.merged.model, d, &StaticsOptions::default())
                .unwrap()
                .lambda
                .unwrap();
            assert!((found - lambda).abs() < 1e-6, "{name} {d:?}: {found}");
            assert!((found - every_stone.convex_lambda.unwrap()).abs() < 1e-7 * found);
            assert!(
                !check_threshold(name, &m.merged.model, d),
                "{name}: the domains rock, no lift-off"
            );
        }
    }
}

/// Under a load that turns as it grows, a(t) = A(t)(cos θ(t), sin θ(t), 0), a structure leaves
/// rest at the first instant where |a| passes λ(a/|a|)·g: the load's direction is new at every
/// instant, so the run's rest statics decide most instants from the answers they have found
/// (the polygon of boundary points and the mechanisms' cuts, docs/simulation.md, Uplift, item
/// 4). The reference instant is found here from the contact faces' program solved afresh along
/// the load's direction at each instant: a scan every 2 ms brackets the first crossing, and a
/// bisection narrows it to 1e-10 s. The run's uplift test at rest locates its instant by its
/// own bisection on the time grid (to 1e-9 s and better); asserted to 1e-7 s.
#[test]
fn a_structure_under_a_turning_load_leaves_rest_where_it_first_passes_its_multiplier() {
    use crr::dynamics::ground_motion::Record;
    let model = bundled("baldachin");
    let g = model.gravity;
    let lambda_x = collapse_multiplier(&model, Vector3::x(), &StaticsOptions::default())
        .unwrap()
        .lambda
        .unwrap();
    let dt = 1e-3;
    let samples = 801;
    let load = |t: f64| {
        let (magnitude, angle) = (lambda_x * g * (0.8 + 0.5 * t), 0.3 + 2.5 * t);
        Vector3::new(magnitude * angle.cos(), magnitude * angle.sin(), 0.0)
    };
    let component =
        |k: usize| -> Vec<f64> { (0..samples).map(|i| load(i as f64 * dt)[k]).collect() };
    let ground = GroundMotion::none()
        .with_record(Axis::X, Record::uniform(dt, component(0)).unwrap(), 1.0)
        .unwrap()
        .with_record(Axis::Y, Record::uniform(dt, component(1)).unwrap(), 1.0)
        .unwrap();
    // The reference: does the load the run sees at t exceed the program's λ along it?
    let exceeds = |t: f64| {
        let a = ground.acceleration(t);
        let lambda = collapse_multiplier(&model, a.normalize(), &StaticsOptions::default())
            .unwrap()
            .lambda
            .unwrap_or(f64::INFINITY);
        a.norm() > lambda * g
    };
    let step = 2e-3;
    let mut upper = step;
    while !exceeds(upper) {
        upper += step;
        assert!(upper < 0.8, "the load never passes the multiplier");
    }
    let mut lower = upper - step;
    assert!(lower > 0.0 && !exceeds(lower));
    while upper - lower > 1e-10 {
        let mid = 0.5 * (lower + upper);
        if exceeds(mid) {
            upper = mid;
        } else {
            lower = mid;
        }
    }
    let initial = solve_initial(&model, &InitialSpec::default()).unwrap();
    let params = Parameters {
        duration: upper + 0.02,
        ..Default::default()
    };
    let run = Simulation::new(&model, &ground, &initial, params)
        .unwrap()
        .run()
        .unwrap_or_else(|f| panic!("{}", f.error));
    let uplift = run.uplift_time.expect("the baldachin leaves rest");
    eprintln!(
        "turning load: uplift at {uplift} s, the programs' crossing at {upper} s ({:e} s apart)",
        uplift - upper
    );
    assert!((uplift - upper).abs() <= 1e-7, "{uplift} against {upper}");
}

/// The run's end under a constant load from rest: its first violation, whether it left rest, and
/// the largest angle any sample reached (rad).
struct Held {
    violation: Option<crr::impact::monitor::Violation>,
    uplift: Option<f64>,
    largest_angle: f64,
    held_on_search: Option<crr::impact::HeldOnSearch>,
}

fn held_under(model: &Model, a: Vector3<f64>) -> Held {
    let ground = constant_ground(a);
    let initial = solve_initial(model, &InitialSpec::default()).unwrap();
    let params = Parameters {
        duration: 0.05,
        ..Default::default()
    };
    let t = Simulation::new(model, &ground, &initial, params)
        .unwrap()
        .run()
        .unwrap();
    let largest_angle = t
        .samples
        .iter()
        .flat_map(|s| s.q.iter())
        .fold(0.0_f64, |m, q| m.max(q.abs()));
    Held {
        violation: t.violation,
        uplift: t.uplift_time,
        largest_angle,
        held_on_search: t.held_on_search,
    }
}

/// The model `crr assemble --all-contacts [--planar]` makes of the blocks `bodies` (assembly
/// text), written under `tag`.
fn assembled(tag: &str, bodies: &str, planar: bool) -> Model {
    use crr::analysis::assemble::{AssemblyOptions, assemble, read_assembly};
    let path = crate::common::scratch("sliding_unloaded").join(format!("{tag}.toml"));
    std::fs::write(&path, bodies).unwrap();
    let file = read_assembly(&path).unwrap();
    let options = AssemblyOptions {
        planar,
        ..AssemblyOptions::default()
    }
    .with_all_contacts();
    assemble(&path, &file, &options).unwrap().model
}

/// Under constant loads along `d` from rest: 1 % below `lambda` (a mechanism whose joints slide
/// unloaded while keeping contact, which the CRR chain cannot follow) nothing happens; 1 % above
/// it, and at each load of `held` (× λ_c g, below the convex program's multiplier), the run
/// stays at rest, nothing moves, and a `sliding_unloaded` violation names a joint of `sliding`
/// at t = 0; 1 % above `convex` (when given) it leaves rest and moves.
fn held_between(
    name: &str,
    model: &Model,
    d: Vector3<f64>,
    lambda: f64,
    held: &[f64],
    sliding: &[&str],
    convex: Option<f64>,
) {
    let g = model.gravity;
    let below = held_under(model, d * (0.99 * lambda * g));
    assert!(below.violation.is_none(), "{name}: {:?}", below.violation);
    assert_eq!(below.uplift, None, "{name}");
    for &load in [1.01 * lambda].iter().chain(held) {
        let run = held_under(model, d * (load * g));
        assert_eq!(run.uplift, None, "{name}, {load} g: no uplift");
        assert_eq!(run.largest_angle, 0.0, "{name}, {load} g: nothing moves");
        let v = run.violation.expect("the hold is a violation");
        assert_eq!((v.kind.as_str(), v.t), ("sliding_unloaded", 0.0), "{name}");
        assert!(
            sliding.contains(&v.interface.as_str()),
            "{name}: {}",
            v.interface
        );
    }
    if let Some(convex) = convex {
        let moved = held_under(model, d * (1.01 * convex * g));
        assert_eq!(
            moved.uplift,
            Some(0.0),
            "{name}: beyond {convex} it leaves rest"
        );
        assert!(
            moved.largest_angle > 1e-6,
            "{name}: {}",
            moved.largest_angle
        );
    }
}

/// A block b × h = 0.4 × 1 m (1 m deep) standing against the +x face of a pier 1 × 1 × 2 m,
/// every contact an interface. Away from the pier it overturns at λ = b/h = 0.4 (virtual work of
/// the block alone): it turns about its far foot while its lowest edge slides up the pier,
/// carrying nothing. The CRR chain cannot follow that: its face on the pier is a joint, which
/// does not slide. Without sliding the pier and the block turn as one about the block's far foot
/// (the free pier), at the lever of their common centre: (0.4 + 23/60)/(11/12) = 47/55; a fixed
/// pier holds up to the cap. Between the two the run stays at rest, held by shear across the
/// pier's face with no compression, and says so at t = 0 (`sliding_unloaded`, on that face);
/// below 0.4 there is nothing to say; beyond 47/55 the structure leaves rest. Until 2026-12-05
/// the run released the sliding mechanism's sides at 1.01 × 0.4, moved nothing and reported an
/// uplift at t = 0 with no warning.
#[test]
fn a_load_beyond_a_sliding_mechanism_the_chain_cannot_follow_is_a_violation() {
    for fixed in [true, false] {
        let bodies = format!(
            "name = \"infill\"\n{}{}{}",
            if fixed { "fixed = [\"pier\"]\n" } else { "" },
            crate::common::box_body("pier", [-0.5, 0.0, 1.0], [1.0, 1.0, 2.0]),
            crate::common::box_body("block", [0.2, 0.0, 0.5], [0.4, 1.0, 1.0]),
        );
        let model = assembled(&format!("pier_{fixed}"), &bodies, false);
        // The face on the pier: the block's interface whose face normal is along x.
        let on_pier = (0..model.interfaces.len())
            .find(|&i| {
                crr::kinematics::ContactFace::of_interface(&model, i)
                    .normal
                    .x
                    .abs()
                    > 0.99
            })
            .map(|i| model.interfaces[i].name.clone())
            .expect("a face on the pier");
        let (held, convex): (&[f64], _) = if fixed {
            (&[2.0], None)
        } else {
            (&[], Some(47.0 / 55.0))
        };
        let name = format!("block against a pier (fixed: {fixed})");
        held_between(&name, &model, -Vector3::x(), 0.4, held, &[&on_pier], convex);
    }
}

/// A wall of three courses in running bond, blocks 1 × 0.5 × 0.5 m (half blocks at the ends of
/// the middle course), every contact a joint (planar). Along +x its corner wedge, the left half
/// block of course 1 and the block over it, turns about the half block's outer foot at
/// λ = 5/7 (their common centre 5/12 m beside and 7/12 m above that foot, by hand): the block
/// over it lifts off its other support, and the half block's head joint slides up its
/// neighbour's, carrying nothing, which the CRR chain cannot follow. Until 2026-12-05 the run
/// lifted the faces off, moved nothing, landed them at once and stopped at t = 0 on 200
/// "impacts" of zero rates (`SimulationError::Chatter`), or reported an uplift with nothing
/// moving; now it stays at rest with the violation up to the convex program's multiplier, and
/// leaves rest beyond it.
#[test]
fn a_corner_wedge_that_slides_up_its_head_joint_is_a_violation() {
    let mut bodies = String::from("name = \"wall\"\n");
    for (name, centre, width) in [
        ("c0_b0", [-0.5, 0.0, 0.25], 1.0),
        ("c0_b1", [0.5, 0.0, 0.25], 1.0),
        ("c1_b0", [-0.75, 0.0, 0.75], 0.5),
        ("c1_b1", [0.0, 0.0, 0.75], 1.0),
        ("c1_b2", [0.75, 0.0, 0.75], 0.5),
        ("c2_b0", [-0.5, 0.0, 1.25], 1.0),
        ("c2_b1", [0.5, 0.0, 1.25], 1.0),
    ] {
        bodies.push_str(&crate::common::box_body(name, centre, [width, 0.5, 0.5]));
    }
    let model = assembled("wall_3x2", &bodies, true);
    let d = Vector3::x();
    let wedge = collapse_multiplier(&model, d, &StaticsOptions::default()).unwrap();
    assert!(
        (wedge.lambda.unwrap() - 5.0 / 7.0).abs() < 1e-9,
        "{:?}",
        wedge.lambda
    );
    assert!(
        wedge.lifting_off().next().is_some(),
        "a block lifts off a support"
    );
    let convex = wedge.convex_lambda.expect("the convex program's mechanism");
    assert!(convex > 1.1 * 5.0 / 7.0, "{convex}");
    held_between(
        "3 × 2 wall",
        &model,
        d,
        5.0 / 7.0,
        &[0.99 * convex],
        &["c1_b1_on_c1_b0", "c1_b0_on_c1_b1"],
        Some(convex),
    );
}

/// A run that holds a load at rest on a multiplier the search alone found says so. The bundled
/// wall has 2186 sets of joints that may open and slide along ±x (more than the 256 a run tries
/// along an axis, fewer than the 4096 of `crr check`): under half its multiplier along +x it
/// stays at rest and records that instant (t = 0) with the load; `crr check`'s pass, exhaustive
/// there, confirms the search's 7/11. The trilithon, whose answer is exhaustive, records none.
#[test]
fn a_run_held_on_a_multiplier_that_is_not_exhaustive_says_so() {
    use crr::impact::statics::rest_options;
    let x = Vector3::x();
    let wall = bundled("wall");
    let run = collapse_multiplier(&wall, x, &rest_options(&x)).unwrap();
    let check = collapse_multiplier(&wall, x, &StaticsOptions::default()).unwrap();
    assert!(!run.exhaustive && check.exhaustive);
    let lambda = check.lambda.unwrap();
    assert!((lambda - 7.0 / 11.0).abs() < 1e-7 && (run.lambda.unwrap() - lambda).abs() < 1e-7);
    let a = 0.5 * lambda * wall.gravity * x;
    let run = held_under(&wall, a);
    let held = run
        .held_on_search
        .expect("the wall is held on the search's answer");
    assert!(run.uplift.is_none());
    assert_eq!(held.t, 0.0);
    assert_eq!(held.load, [a.x, a.y, a.z]);

    let trilithon = bundled("trilithon");
    let c = collapse_multiplier(&trilithon, x, &rest_options(&x)).unwrap();
    assert!(c.exhaustive);
    let a = 0.5 * c.lambda.unwrap() * trilithon.gravity * x;
    let run = held_under(&trilithon, a);
    assert_eq!(run.held_on_search, None);
    assert!(run.uplift.is_none());
}
