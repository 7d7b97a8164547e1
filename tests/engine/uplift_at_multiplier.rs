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
    /// The last sample's time (s).
    end: f64,
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
        end: t.samples.last().map_or(0.0, |s| s.t),
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

/// A rigid set of rectangular blocks (in the x–z plane) turning about a foot under gravity and
/// a constant ground acceleration `a` (m/s², along +x), towards −x: its angle θ(t) from rest,
/// by fourth-order Runge–Kutta on Lagrange's equation I_O θ̈ = −V′(θ) written here, with
/// V(θ) = Σ m (g z_c + a x_c), (x_c, z_c) = R(θ) c each block's centre turned about the foot
/// (c its offset at rest, x towards the side it does not tip to) and
/// I_O = Σ (m (w² + h²)/12 + m |c|²). `blocks`: (mass, c, (w, h)).
fn tipping_angle(blocks: &[(f64, [f64; 2], [f64; 2])], g: f64, a: f64, t: f64) -> f64 {
    let inertia: f64 = blocks
        .iter()
        .map(|(m, [x, z], [w, h])| m * (w * w + h * h) / 12.0 + m * (x * x + z * z))
        .sum();
    // −V′(θ)/I_O: d/dθ of R(θ)c = (−x sin θ − z cos θ, x cos θ − z sin θ).
    let accel = |theta: f64| {
        let (s, c) = theta.sin_cos();
        -blocks
            .iter()
            .map(|(m, [x, z], _)| m * (g * (x * c - z * s) + a * (-x * s - z * c)))
            .sum::<f64>()
            / inertia
    };
    let steps = 20_000;
    let dt = t / steps as f64;
    let (mut theta, mut rate) = (0.0_f64, 0.0_f64);
    for _ in 0..steps {
        let k1 = (rate, accel(theta));
        let k2 = (rate + 0.5 * dt * k1.1, accel(theta + 0.5 * dt * k1.0));
        let k3 = (rate + 0.5 * dt * k2.1, accel(theta + 0.5 * dt * k2.0));
        let k4 = (rate + dt * k3.1, accel(theta + dt * k3.0));
        theta += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        rate += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
    }
    theta
}

/// Under a constant load 1.01 λ g along `d` from rest, the structure leaves rest at t = 0 with
/// no violation, and its largest angle at the run's end is `expected(a, end)` (a the load,
/// m/s²), the angle of the blocks that turn as [`tipping_angle`] gives it: to 1e-9 of it (the
/// integrator's tolerances; 2.5e-14 measured on 2026-12-08, the Runge–Kutta's own error far
/// below). 1 % below λ nothing happens.
fn leaves_rest_as(
    name: &str,
    model: &Model,
    d: Vector3<f64>,
    lambda: f64,
    expected: impl Fn(f64, f64) -> f64,
) {
    let g = model.gravity;
    let below = held_under(model, d * (0.99 * lambda * g));
    assert!(below.violation.is_none(), "{name}: {:?}", below.violation);
    assert_eq!(below.uplift, None, "{name}");
    assert_eq!(below.largest_angle, 0.0, "{name}");
    let load = 1.01 * lambda * g;
    let run = held_under(model, d * load);
    assert_eq!(run.uplift, Some(0.0), "{name}: it leaves rest at once");
    assert!(run.violation.is_none(), "{name}: {:?}", run.violation);
    let theta = expected(load, run.end);
    assert!(theta > 1e-6, "{name}: {theta}");
    assert!(
        (run.largest_angle - theta).abs() <= 1e-9 * theta,
        "{name}: {} rad at {} s, against {theta} rad by Lagrange's equation",
        run.largest_angle,
        run.end
    );
}

/// The assembly of a block 0.4 × 1 × 1 m standing against a pier 1 × 1 × 2 m (fixed or free),
/// on the pier's +x face (`side` 1) or its −x face (−1).
fn pier_bodies(fixed: bool, side: f64) -> String {
    format!(
        "name = \"infill\"\n{}{}{}",
        if fixed { "fixed = [\"pier\"]\n" } else { "" },
        crate::common::box_body("pier", [-0.5 * side, 0.0, 1.0], [1.0, 1.0, 2.0]),
        crate::common::box_body("block", [0.2 * side, 0.0, 0.5], [0.4, 1.0, 1.0]),
    )
}

/// The assembly of two equal blocks 0.5 × 1 × 1 m side by side, their common face at x = 0.
fn pair_bodies() -> String {
    format!(
        "name = \"pair\"\n{}{}",
        crate::common::box_body("left", [-0.25, 0.0, 0.5], [0.5, 1.0, 1.0]),
        crate::common::box_body("right", [0.25, 0.0, 0.5], [0.5, 1.0, 1.0]),
    )
}

/// A block b × h = 0.4 × 1 m (1 m deep) standing against a face of a pier 1 × 1 × 2 m, every
/// contact an interface, the pier free or fixed. Away from the pier it overturns at
/// λ = b/h = 0.4 (virtual work of the block alone), turning about its far foot while its lowest
/// edge rises along the pier's face: the face grazes at first order and opens at second, by
/// b(1 − cos θ). The run takes that face out of the chain and the block turns alone: 1 % above
/// 0.4 it leaves rest at t = 0 and its angle follows the lone block's equation (written in the
/// test) to 1e-9; 1 % below nothing happens. The same with the block on the pier's other side
/// and the load reversed. Until 2026-12-08 the run stayed at rest up to the convex program's
/// multiplier (47/55 with the pier free, the cap with it fixed), held by shear across the
/// pier's face with no compression (a `sliding_unloaded` violation): the face's gap, measured
/// from the block's face plane extended past the edge it had lifted, read the pier's corner as
/// a penetration of b(1 − cos θ), and the face landed at once.
#[test]
fn a_block_tipping_away_from_a_pier_leaves_its_face() {
    for fixed in [true, false] {
        for side in [1.0, -1.0] {
            let bodies = pier_bodies(fixed, side);
            let model = assembled(&format!("pier_{fixed}_{side}"), &bodies, false);
            let name = format!("block against a pier (fixed: {fixed}, side {side})");
            // Seen from the side it tips to: its centre 0.2 m inside its far foot, 0.5 m up.
            let block = [(1.0, [0.2, 0.5], [0.4, 1.0])];
            let g = model.gravity;
            leaves_rest_as(&name, &model, -side * Vector3::x(), 0.4, |a, t| {
                tipping_angle(&block, g, a, t)
            });
        }
    }
}

/// A wall of three courses in running bond, blocks 1 × 0.5 × 0.5 m (half blocks at the ends of
/// the middle course), every contact a joint (planar). Along +x its corner wedge, the left half
/// block of course 1 and the block over it, turns about the half block's outer foot at
/// λ = 5/7 (their common centre 5/12 m beside and 7/12 m above that foot, by hand): the block
/// over it lifts off its other support, and the half block's head joint rises along its
/// neighbour's and leaves it at second order. The run takes both faces out of the chain: 1 %
/// above 5/7 the wedge leaves rest at t = 0 and turns as one body about the foot, its angle
/// following Lagrange's equation of the two blocks (written in the test) to 1e-9; 1 % below
/// nothing happens; the same along −x with the right wedge. Until 2026-12-08 the run stayed at
/// rest with a `sliding_unloaded` violation up to the convex program's multiplier (after
/// 2026-12-05; before that the faces landed at once and the run stopped at t = 0 on 200
/// "impacts" of zero rates).
#[test]
fn a_corner_wedge_whose_half_block_rises_along_its_head_joint_leaves_rest() {
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
    // The half block (0.25 m beside and above its outer foot) and the block over it (0.5 m
    // beside, 0.75 m above), masses as their areas.
    let wedge = [
        (0.25, [0.25, 0.25], [0.5, 0.5]),
        (0.5, [0.5, 0.75], [1.0, 0.5]),
    ];
    for d in [Vector3::x(), -Vector3::x()] {
        let collapse = collapse_multiplier(&model, d, &StaticsOptions::default()).unwrap();
        assert!(
            (collapse.lambda.unwrap() - 5.0 / 7.0).abs() < 1e-9,
            "{:?}",
            collapse.lambda
        );
        assert!(
            collapse.lifting_off().next().is_some()
                && collapse.sliding_in_contact().next().is_some(),
            "a block lifts off a support and a head joint slides in contact"
        );
        let g = model.gravity;
        let name = format!("3 × 2 wall along {d:?}");
        leaves_rest_as(&name, &model, d, 5.0 / 7.0, |a, t| {
            tipping_angle(&wedge, g, a, t)
        });
    }
}

/// Two equal blocks b × h = 0.5 × 1 m side by side (1 m deep), their common face a joint. Each
/// overturns on its own at λ = b/h = 0.5, and both do together, turning about their feet on the
/// same side at the same rate: their common face slides and carries nothing at first order, but
/// the leading block's lower corner enters the other by b(1 − cos θ) at second (the gap's own
/// test in `open_loops.rs`), so the motion needs that face to slide under compression, which the
/// CRR chain cannot follow, face closed or open. So 1 % above 0.5 the run stays at rest with a
/// `sliding_unloaded` violation at t = 0 on that face, in both directions; beyond the convex
/// program's multiplier (the pair as one block, 2b/h = 1) it leaves rest.
#[test]
fn two_blocks_that_tip_together_press_their_common_face_and_are_held() {
    let bodies = pair_bodies();
    let model = assembled("pair", &bodies, true);
    let common = (0..model.interfaces.len())
        .find(|&i| {
            crr::kinematics::ContactFace::of_interface(&model, i)
                .normal
                .x
                .abs()
                > 0.99
        })
        .map(|i| model.interfaces[i].name.clone())
        .expect("the common face");
    for d in [Vector3::x(), -Vector3::x()] {
        let collapse = collapse_multiplier(&model, d, &StaticsOptions::default()).unwrap();
        assert!(
            (collapse.lambda.unwrap() - 0.5).abs() < 1e-9,
            "{:?}",
            collapse.lambda
        );
        let convex = collapse.convex_lambda.expect("the pair as one block");
        assert!((convex - 1.0).abs() < 1e-9, "{convex}");
        held_between(
            &format!("pair along {d:?}"),
            &model,
            d,
            0.5,
            &[0.8],
            &[&common],
            Some(convex),
        );
    }
}

/// The same decisions where a load crosses the multiplier: a one-sine pulse of amplitude
/// 1.5 λ g and period 0.5 s reaches λ g at t* = (T/2π) asin(1/1.5), and the run's uplift test
/// finds that instant by bisection, where the chain without the joints that slide in contact
/// has no opening of its own (its multiplier is the structure's, within its test's margin): the
/// mechanism's sides move it there. The block against the fixed pier leaves rest at t* (to
/// 1e-7 s) with no violation and turns; the pair of equal blocks is held from t* with the
/// `sliding_unloaded` violation and nothing moves, the run going to its end.
#[test]
fn joints_sliding_in_contact_are_decided_where_a_pulse_crosses_the_multiplier() {
    use crr::dynamics::ground_motion::SineSpec;
    let pulse = |amplitude: f64| {
        let spec = ComponentSpec::new(SignalSpec::Sine(SineSpec {
            amplitude,
            period: Some(0.5),
            frequency: None,
            phase: 0.0,
            cycles: Some(1.0),
            start: 0.0,
        }));
        GroundMotion::none()
            .with_component(Axis::X, &spec, std::path::Path::new("."))
            .unwrap()
    };
    let crossing = 0.5 / (2.0 * std::f64::consts::PI) * (1.0f64 / 1.5).asin();
    let run = |model: &Model, amplitude: f64| {
        let initial = solve_initial(model, &InitialSpec::default()).unwrap();
        let params = Parameters {
            duration: 0.2,
            ..Default::default()
        };
        Simulation::new(model, &pulse(amplitude), &initial, params)
            .unwrap()
            .run()
            .unwrap()
    };
    let largest = |t: &crr::impact::Trajectory| {
        t.samples
            .iter()
            .flat_map(|s| s.q.iter())
            .fold(0.0_f64, |m, q| m.max(q.abs()))
    };
    let bodies = pier_bodies(true, 1.0);
    let pier = assembled("pier_pulse", &bodies, false);
    let t = run(&pier, -1.5 * 0.4 * pier.gravity);
    let uplift = t.uplift_time.expect("the block leaves rest");
    assert!(
        (uplift - crossing).abs() < 1e-7,
        "{uplift} against {crossing}"
    );
    assert!(t.violation.is_none(), "{:?}", t.violation);
    assert!(largest(&t) > 1e-4, "{}", largest(&t));

    let bodies = pair_bodies();
    let pair = assembled("pair_pulse", &bodies, true);
    let t = run(&pair, 1.5 * 0.5 * pair.gravity);
    assert_eq!(t.uplift_time, None);
    assert_eq!(largest(&t), 0.0);
    assert!(t.end_time >= 0.2 - 1e-12, "{}", t.end_time);
    let v = t.violation.expect("the hold is a violation");
    assert_eq!(v.kind, "sliding_unloaded");
    assert!((v.t - crossing).abs() < 1e-7, "{} against {crossing}", v.t);
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
