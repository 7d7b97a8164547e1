//! Loops released in motion (docs/simulation.md, "Faces that open"): a block of a running-bond
//! wall that lifts off one of its two supports leaves its loop open, and lands on it again with
//! a plastic impulse. Checked against facts computed here from the bodies' poses and velocities,
//! not by the engine's own bookkeeping.

mod common;

use std::path::Path;

use crr_dynamics::ground_motion::{Axis, ComponentSpec, GroundMotion, SignalSpec, SineSpec};
use crr_dynamics::{InitialSpec, InitialState, solve_initial};
use crr_impact::{Parameters, Sample, Simulation, SlotState};
use crr_kinematics::fixtures::running_bond_wall;
use crr_kinematics::{
    ActivePivots, Data, InterfaceKind, Model, Parent, Role, Side, forward_kinematics,
};
use nalgebra::{DVector, Vector3};

fn sine_pulse(amplitude: f64, period: f64) -> GroundMotion {
    GroundMotion::none()
        .with_component(
            Axis::X,
            &ComponentSpec::new(SignalSpec::Sine(SineSpec {
                amplitude,
                period: Some(period),
                frequency: None,
                phase: 0.0,
                cycles: Some(1.0),
                start: 0.0,
            })),
            Path::new("."),
        )
        .unwrap()
}

/// A running-bond wall of `courses` × `blocks` (blocks 0.6 × 0.25 m, 0.3 m deep) at rest under a
/// one-sine pulse of 8 m/s² along x (0.5 s), and 2 s of simulation.
fn wall_under_a_pulse(
    courses: usize,
    blocks: usize,
) -> (Model, GroundMotion, InitialState, Parameters) {
    let model = Model::from_spec(&running_bond_wall(courses, blocks, 0.6, 0.25, 0.3)).unwrap();
    let init = solve_initial(&model, &InitialSpec::default()).unwrap();
    let params = Parameters {
        duration: 2.0,
        ..Parameters::default()
    };
    (model, sine_pulse(8.0, 0.5), init, params)
}

/// The bodies' poses in `sample` (`data`), each slot on the pivot of its sample state.
fn pose_at(model: &Model, data: &mut Data, sample: &Sample) {
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    for (slot, state) in sample.states.iter().enumerate() {
        if *state == SlotState::Negative {
            pivots.sides[slot] = Side::Negative;
        }
    }
    forward_kinematics(model, data, &DVector::from_column_slice(sample.q), &pivots);
}

/// Hinge `k`'s pivot points P⁺, P⁻ at rest and its face's normal u × (P⁻ − P⁺), unit.
fn hinge_face(model: &Model, k: usize) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let InterfaceKind::Hinge {
        axis,
        pivot_positive,
        pivot_negative,
    } = model.interfaces[k].kind
    else {
        panic!("the wall's joints are hinges")
    };
    let lift = axis.cross(&(pivot_negative - pivot_positive)).normalize();
    (pivot_positive, pivot_negative, lift)
}

/// The least clearance (m) between the two faces of hinge `k` in `sample`: each end of the
/// face (its two pivot points) as the child carries it, measured from the parent's face plane
/// where it lies over the parent's face, and as the parent carries it, from the child's face
/// plane where it lies over the child's (negative: inside the other block). A corner that has
/// moved past the other face's edge meets nothing there (over the block beside, in a wall).
/// Positive infinity where no corner lies over the other face.
fn face_clearance(model: &Model, data: &mut Data, sample: &Sample, k: usize) -> f64 {
    pose_at(model, data, sample);
    let iface = &model.interfaces[k];
    let (pivot_positive, pivot_negative, lift) = hinge_face(model, k);
    let along = pivot_negative - pivot_positive;
    // A body's pose: world point of x at rest, and the rest point of a world point.
    let pose = |b: Option<usize>| match b {
        None => (nalgebra::Matrix3::identity(), Vector3::zeros()),
        Some(b) => {
            let frame = model.body_coord[b];
            (data.rot_ops[frame], data.frame_translation[frame])
        }
    };
    let parent = match iface.parent {
        Parent::Ground => None,
        Parent::Body(b) => Some(b),
    };
    let (child_pose, parent_pose) = (pose(Some(iface.child)), pose(parent));
    // Whether a world point lies over the face as the body of `pose` carries it.
    let over = |(rot, t): (nalgebra::Matrix3<f64>, Vector3<f64>), x: &Vector3<f64>| {
        let rest = rot.transpose() * (x - t);
        let s = (rest - pivot_positive).dot(&along) / along.norm_squared();
        (-1e-12..=1.0 + 1e-12).contains(&s)
    };
    let mut least = f64::INFINITY;
    for x in [pivot_positive, pivot_negative] {
        let on_child = child_pose.0 * x + child_pose.1;
        let on_parent = parent_pose.0 * x + parent_pose.1;
        if over(parent_pose, &on_child) {
            least = least.min((parent_pose.0 * lift).dot(&(on_child - on_parent)));
        }
        if over(child_pose, &on_parent) {
            least = least.min((child_pose.0 * lift).dot(&(on_child - on_parent)));
        }
    }
    least
}

/// The normal gap and the relative velocity (child − parent) of both contact points of hinge
/// `k` at the state of `sample`, from the bodies' poses and velocities.
fn face_points(
    model: &Model,
    data: &mut Data,
    sample: &Sample,
    k: usize,
) -> [(f64, Vector3<f64>); 2] {
    pose_at(model, data, sample);
    crr_kinematics::velocities(model, data, &DVector::from_column_slice(sample.qdot));
    let iface = &model.interfaces[k];
    let (pivot_positive, pivot_negative, lift) = hinge_face(model, k);
    // World position and velocity of the point at `x` at rest, moving with body `b`.
    let point = |data: &Data, b: usize, x: &Vector3<f64>| {
        let frame = model.body_coord[b];
        let p = data.rot_ops[frame] * x + data.frame_translation[frame];
        let v = data.spatial_velocity[frame];
        let (w, v0) = (v.fixed_rows::<3>(0), v.fixed_rows::<3>(3));
        (p, v0 + w.cross(&p))
    };
    [pivot_positive, pivot_negative].map(|x| {
        let (xc, vc) = point(data, iface.child, &x);
        let (xp, vp, n) = match iface.parent {
            Parent::Ground => (x, Vector3::zeros(), lift),
            Parent::Body(b) => {
                let (xp, vp) = point(data, b, &x);
                (xp, vp, data.rot_ops[model.body_coord[b]] * lift)
            }
        };
        (n.dot(&(xc - xp)), vc - vp)
    })
}

/// A running-bond wall of 4 courses of 3 blocks under a one-sine pulse of 8 m/s² (0.5 s): two
/// blocks leave one of their supports, both land again, and the run goes to its end; the
/// mirrored wedge does the same in the pulse's second half.
#[test]
fn a_wall_releases_its_loops_and_lands_on_them_again() {
    let (model, ground, init, params) = wall_under_a_pulse(4, 3);
    let traj = common::run_to_end(&model, &ground, &init, params);
    assert_eq!(traj.end_time, 2.0);
    // The energy balance T + U − W + D = E(0), T from the bodies' velocities: the released
    // phases add no energy (the integrator's tolerance, rtol 1e-10, on W·L).
    let scale = model.total_mass() * model.gravity * model.size;
    assert!(
        traj.energy_balance_error.abs() < 1e-9 * scale,
        "energy balance {:e} J",
        traj.energy_balance_error
    );
    let mut data = Data::new(&model);
    // The faces that close loops of the file's tree: the samples' coordinates give their
    // bodies' poses exactly (an open face of the tree is drawn turned about its pivot).
    let open_slots: Vec<usize> = (0..model.slot_count)
        .filter(|&s| traj.samples.iter().any(|x| x.states[s] == SlotState::Open))
        .filter(|&s| s >= model.dof())
        .collect();
    assert!(
        open_slots.len() >= 2,
        "open loop-closing slots {open_slots:?}"
    );
    let interface_of = |s: usize| {
        model
            .interfaces
            .iter()
            .position(|i| i.slots.contains(&s))
            .unwrap()
    };
    // No open face penetrates its support, and every open face is open (a gap above 1e-6 of the
    // size at some sample).
    for &s in &open_slots {
        let k = interface_of(s);
        let mut widest: f64 = 0.0;
        for x in traj
            .samples
            .iter()
            .filter(|x| x.states[s] == SlotState::Open)
        {
            for (gap, _) in face_points(&model, &mut data, &x, k) {
                assert!(gap > -1e-9 * model.size, "t = {}: gap {gap:e} m", x.t);
                widest = widest.max(gap);
            }
        }
        assert!(
            widest > 1e-6 * model.size,
            "{}: widest gap {widest:e} m",
            model.interfaces[k].name
        );
    }
    // Landings: the face open just before, closed just after on the point that touched; the
    // impulse stops the relative velocity there and takes the kinetic energy the impact
    // records.
    let samples: Vec<Sample> = traj.samples.iter().collect();
    let mut landings = 0;
    for imp in &traj.impacts {
        // Every face the record names (faces resting at one instant land together).
        let mut kinetic = None;
        for name in &imp.interfaces {
            let k = model.interface_index(name).unwrap();
            let s = model.interfaces[k].slots.start;
            if s < model.dof() {
                continue;
            }
            let before = samples
                .iter()
                .rev()
                .find(|x| x.t == imp.t && x.states[s] == SlotState::Open);
            let Some(before) = before else { continue };
            let after = samples
                .iter()
                .find(|x| x.t == imp.t && x.states[s] != SlotState::Open)
                .expect("a sample after the landing");
            landings += 1;
            let points = face_points(&model, &mut data, after, k);
            let touching = if points[0].0 <= points[1].0 { 0 } else { 1 };
            let speed = points.iter().map(|p| p.1.norm()).fold(0.0, f64::max) + 1e-3;
            assert!(
                points[touching].1.norm() < 1e-9 * speed.max(1.0),
                "{name}: relative velocity after landing {:e} m/s",
                points[touching].1.norm()
            );
            kinetic = Some((before.kinetic, after.kinetic));
        }
        let Some((before_kinetic, after_kinetic)) = kinetic else {
            continue;
        };
        let lost = before_kinetic - after_kinetic;
        assert!(imp.energy_lost >= 0.0);
        assert!(
            (lost - imp.energy_lost).abs() <= 1e-6 * before_kinetic + 1e-12,
            "ΔT {lost} J, recorded {} J",
            imp.energy_lost
        );
    }
    assert!(
        landings >= 2,
        "the lifted blocks land ({landings} landings)"
    );
    // At rest after the pulse every face is closed again.
    let last = traj.samples.last().unwrap();
    assert!(!last.states.contains(&SlotState::Open), "{:?}", last.states);
    // Mirror symmetry: the wall is its own mirror image and the pulse's second half is the
    // first mirrored, T/2 = 0.25 s later. The wedge lifted in the first half lands (its crack's
    // faces and its toe at one instant) before 0.25 s, with the wall at rest again, so the
    // second half repeats the first mirrored: the mirrored wedge lands 0.25 s after the first,
    // losing the same energy, on the mirrored faces (block b of a course of k ↦ k − 1 − b).
    let blocks_in = |course: &str| {
        model
            .bodies
            .iter()
            .filter(|b| b.name.starts_with(&format!("{course}_")))
            .count()
    };
    let mirrored = |name: &str| -> String {
        name.split("_on_")
            .map(|block| {
                let Some((course, b)) = block.split_once('_') else {
                    return block.to_string(); // the ground
                };
                let b: usize = b[1..].parse().unwrap();
                format!("{course}_b{}", blocks_in(course) - 1 - b)
            })
            .collect::<Vec<_>>()
            .join("_on_")
    };
    let [first, second] = &traj.impacts[..] else {
        panic!(
            "two landings, one per half of the pulse: {:?}",
            traj.impacts
        );
    };
    assert!(
        (second.t - first.t - 0.25).abs() < 1e-9,
        "landings at {} and {} s",
        first.t,
        second.t
    );
    assert!(
        (second.energy_lost - first.energy_lost).abs() <= 1e-9 * first.energy_lost,
        "{} J and {} J lost",
        first.energy_lost,
        second.energy_lost
    );
    let mut names: Vec<String> = first.interfaces.iter().map(|n| mirrored(n)).collect();
    let mut other = second.interfaces.clone();
    names.sort();
    other.sort();
    assert_eq!(names, other);
}

/// A wall of 5 courses of 4 blocks under a one-sine pulse of 8 m/s² (0.5 s): faces of the
/// file's spanning tree lift off too, so the chain is grown again through the blocks' other
/// supports (interfaces turned round). Checked at every step from the chain's own poses: every
/// body of the file stays where the file's definition of each closed interface puts it (its
/// two bodies meet at the file's pivot for the angles the outputs report), no open face's point
/// goes below its support, every uplift names the file's slots (seated before, rocking on the
/// reported side after; two happen on a chain grown again), and the energy balance holds.
#[test]
fn a_wall_whose_tree_faces_lift_off_goes_on_with_its_chain_grown_again() {
    let (model, ground, init, params) = wall_under_a_pulse(5, 4);
    let mut sim = Simulation::new(&model, &ground, &init, params).unwrap();
    let (mut regrown, mut uplifts_on_regrown) = (0, 0);
    loop {
        let before = sim.states();
        let stop = sim.step().unwrap();
        let chain = sim.chain().clone();
        let mut data = Data::new(&chain);
        forward_kinematics(&chain, &mut data, &sim.chain_q(), sim.pivots());
        let pose = |b: usize| {
            let f = chain.body_coord[b];
            (data.rot_ops[f], data.frame_translation[f])
        };
        if (0..model.dof())
            .any(|k| model.coords[k].name != chain.coords.get(k).map_or("", |c| c.name.as_str()))
        {
            regrown += 1;
        }
        let (file_q, states) = (sim.q(), sim.states());
        // An uplift names the file's slots: each was seated and now rocks on the side it
        // reports.
        if let crr_impact::StopReason::Uplift(_, mode) = &stop {
            for &(slot, side) in mode {
                let rocking = match side {
                    Side::Positive => SlotState::Positive,
                    Side::Negative => SlotState::Negative,
                };
                assert_eq!(before[slot], SlotState::Seated, "slot {slot} of the file");
                assert_eq!(states[slot], rocking, "slot {slot} of the file");
            }
            if chain.slot_count != model.slot_count
                || (0..model.dof()).any(|k| model.coords[k].name != chain.coords[k].name)
            {
                uplifts_on_regrown += 1;
            }
        }
        for iface in &model.interfaces {
            let InterfaceKind::Hinge {
                axis,
                pivot_positive,
                pivot_negative,
            } = iface.kind
            else {
                unreachable!("hinges")
            };
            let (rc, tc) = pose(iface.child);
            let (rp, tp) = match iface.parent {
                Parent::Ground => (nalgebra::Matrix3::identity(), Vector3::zeros()),
                Parent::Body(b) => pose(b),
            };
            let s = iface.slots.start;
            if states[s] == SlotState::Open {
                // Both points of an open face above the parent's face, along its normal.
                let n = rp * axis.cross(&(pivot_negative - pivot_positive)).normalize();
                for x in [pivot_positive, pivot_negative] {
                    let gap = n.dot(&((rc * x + tc) - (rp * x + tp)));
                    assert!(gap > -1e-9 * model.size, "{}: gap {gap:e}", iface.name);
                }
            } else if s < model.dof() {
                // A closed tree interface of the file: its bodies meet at the file's pivot for
                // the side of the angle reported.
                let x = if states[s] == SlotState::Negative {
                    pivot_negative
                } else {
                    pivot_positive
                };
                let apart = ((rc * x + tc) - (rp * x + tp)).norm();
                assert!(apart < 1e-8 * model.size, "{}: {apart:e} m", iface.name);
                let turn = nalgebra::Rotation3::from_axis_angle(
                    &nalgebra::Unit::new_normalize(axis),
                    file_q[s],
                );
                let off = (rp.transpose() * rc - turn.into_inner()).norm();
                assert!(off < 1e-8, "{}: rotation off by {off:e}", iface.name);
            }
        }
        if matches!(
            stop,
            crr_impact::StopReason::End(_) | crr_impact::StopReason::Collapse(_)
        ) {
            break;
        }
    }
    assert!(regrown > 0, "the chain was grown again");
    assert!(
        uplifts_on_regrown > 0,
        "joints open while the chain is grown again"
    );
    let traj = sim.into_trajectory();
    assert_eq!(traj.end_time, 2.0);
    let scale = model.total_mass() * model.gravity * model.size;
    assert!(traj.energy_balance_error.abs() < 1e-9 * scale);
}

/// The outputs put every body where it is while faces of the file's spanning tree are open
/// (docs/simulation.md, "Faces that open"): the file's coordinates give such a face as its
/// bodies' relative rotation about its reference pivot P⁺, and each sample carries the face's
/// offset x_c(P⁺) − x_p(P⁺) ([`crr_impact::simulation::FaceOpening`]); the bodies below it move
/// by the sum of the open tree faces' offsets on their way to the ground (`body_offsets`).
///
/// On the 4 × 4 wall of `examples/wall_pulse.rs` under a one-sine pulse of 1.8 λ g for 1 s
/// (faces of the file's tree lift off at 0.349 s and at 0.662 s, and the chain is grown
/// again), after every step: the file's model at the reported q (an open
/// slot on its positive side) with those translations gives every body's rotation and
/// translation of the chain integrated (independent: the chain's own tree and coordinates) to
/// 1e-8 (of the size for the translations). The translations matter: without them a body is
/// off by more than 1e-4 of the size at some step. The samples list an opening for an interface
/// exactly where they report it `open`.
#[test]
fn the_outputs_put_the_bodies_below_an_open_tree_face_where_they_are() {
    let (model, ground, init) = wall_of_wall_pulse(4, 1.8);
    let params = Parameters {
        duration: 1.0,
        ..Parameters::default()
    };
    let mut sim = Simulation::new(&model, &ground, &init, params).unwrap();
    let mut file = Data::new(&model);
    let mut samples = crr_impact::Samples::new(model.dof(), model.slot_count);
    let (mut tree_open_steps, mut largest_offset) = (0, 0.0f64);
    loop {
        let stop = sim.step().unwrap();
        samples.append(&sim.drain_samples());
        let chain = sim.chain().clone();
        let mut data = Data::new(&chain);
        forward_kinematics(&chain, &mut data, &sim.chain_q(), sim.pivots());
        let states = sim.states();
        let openings = sim.face_openings();
        let mut pivots = ActivePivots::uniform(&model, Side::Positive);
        for (slot, state) in states.iter().enumerate() {
            if *state == SlotState::Negative {
                pivots.sides[slot] = Side::Negative;
            }
        }
        forward_kinematics(&model, &mut file, &sim.q(), &pivots);
        let offsets = crr_impact::simulation::body_offsets(&model, &openings);
        if model.interfaces.iter().any(|i| {
            matches!(i.role, Role::Tree { .. }) && states[i.slots.start] == SlotState::Open
        }) {
            tree_open_steps += 1;
        }
        for b in 0..model.bodies.len() {
            let (fc, ff) = (chain.body_coord[b], model.body_coord[b]);
            let turn = (data.rot_ops[fc] - file.rot_ops[ff]).norm();
            assert!(
                turn < 1e-8,
                "body {b} at {} s: rotation off by {turn:e}",
                sim.time()
            );
            let moved = file.frame_translation[ff] + offsets[b];
            let apart = (data.frame_translation[fc] - moved).norm();
            assert!(
                apart < 1e-8 * model.size,
                "body {b} at {} s: {apart:e} m from where the outputs put it",
                sim.time()
            );
            largest_offset = largest_offset.max(offsets[b].norm());
        }
        if matches!(
            stop,
            crr_impact::StopReason::End(_) | crr_impact::StopReason::Collapse(_)
        ) {
            break;
        }
    }
    assert!(tree_open_steps > 0, "faces of the file's tree opened");
    assert!(
        largest_offset > 1e-4 * model.size,
        "the largest offset {largest_offset:e} m"
    );
    let mut listed = 0;
    for x in &samples {
        for (k, iface) in model.interfaces.iter().enumerate() {
            let open = x.states[iface.slots.start] == SlotState::Open;
            let opening = x.openings.iter().any(|o| o.interface == k);
            assert_eq!(open, opening, "{} at {} s", iface.name, x.t);
            listed += usize::from(opening);
        }
    }
    assert!(listed > 0, "samples with open faces");
}

/// The n × n running-bond wall of `examples/wall_pulse.rs` (blocks 1.0 × 0.5 m, 0.5 m deep) at
/// rest under a one-sine pulse along x of `factor` × its collapse multiplier λ (times g), 0.5 s.
fn wall_of_wall_pulse(n: usize, factor: f64) -> (Model, GroundMotion, InitialState) {
    use crr_dynamics::ground_motion::PulseSpec;
    use crr_impact::statics::{StaticsOptions, collapse_multiplier};
    let model = Model::from_spec(&running_bond_wall(n, n, 1.0, 0.5, 0.5)).unwrap();
    let lambda = collapse_multiplier(&model, Vector3::x(), &StaticsOptions::default())
        .unwrap()
        .lambda
        .unwrap();
    let ground = GroundMotion::none()
        .with_component(
            Axis::X,
            &ComponentSpec::new(SignalSpec::OneSinePulse(PulseSpec {
                amplitude: factor * lambda * model.gravity,
                period: 0.5,
                start: 0.0,
            })),
            Path::new("."),
        )
        .unwrap();
    let init = solve_initial(&model, &InitialSpec::default()).unwrap();
    (model, ground, init)
}

/// The wall of [`wall_of_wall_pulse`] run for `duration` (s) to its end, which it must reach.
fn run_wall_to_end(n: usize, factor: f64, duration: f64) -> (Model, crr_impact::Trajectory) {
    let (model, ground, init) = wall_of_wall_pulse(n, factor);
    let params = Parameters {
        duration,
        ..Parameters::default()
    };
    let traj = common::run_to_end(&model, &ground, &init, params);
    (model, traj)
}

/// The run's first violation: an `impulse_tension` at about `t` (to 1e-4 s), at the instant of
/// one of its impact records (a landing or an impact).
fn impulse_tension_at(traj: &crr_impact::Trajectory, t: f64) -> &crr_impact::monitor::Violation {
    let v = traj.violation.as_ref().expect("an impulse that pulls");
    assert_eq!(v.kind, "impulse_tension");
    assert!((v.t - t).abs() < 1e-4, "at {} s", v.t);
    assert!(
        traj.impacts.iter().any(|i| i.t == v.t),
        "at an impact record"
    );
    v
}

/// A face that lifts off leaves its support (docs/simulation.md, "Faces that open"): it opens
/// only where its points separate under the motion of the chain without it, so it cannot land
/// again at once. The 6 × 6 running-bond wall of `examples/wall_pulse.rs` (blocks 1.0 × 0.5 m,
/// 0.5 m deep) under a one-sine pulse of 1.5 λ g (0.5 s), to its end or its stop: every face
/// that opens stays open for more than 10 µs before it lands. A face released under a motion
/// other than its chain's (the contact program's, whose lifted faces keep their slip rows)
/// lifted off with gap accelerations of −1 to −4 m/s² there and landed 1 µs later, over and
/// over: 117 of the 133 landings of the 8 × 8 wall, 2 of the 13 of this one. Where neither the
/// lift-off nor a release with the face closed is consistent, the run records a `lift_off`
/// violation at that instant.
#[test]
fn faces_that_lift_off_do_not_land_again_at_once() {
    let (model, ground, init) = wall_of_wall_pulse(6, 1.5);
    let params = Parameters {
        duration: 1.0,
        ..Parameters::default()
    };
    let traj = match Simulation::new(&model, &ground, &init, params)
        .unwrap()
        .run()
    {
        Ok(t) => t,
        Err(f) => f.partial,
    };
    // The samples at every event, before and after it: a face opens between two samples of one
    // instant and lands between two others.
    let (mut opened_at, mut landings, mut openings) = (vec![None; model.slot_count], 0, 0);
    let samples: Vec<Sample> = traj.samples.iter().collect();
    for pair in samples.windows(2) {
        let (before, after) = (&pair[0], &pair[1]);
        for s in 0..model.slot_count {
            let (was, is) = (before.states[s], after.states[s]);
            if is == SlotState::Open && was != SlotState::Open {
                openings += 1;
                opened_at[s] = Some(after.t);
            }
            if was == SlotState::Open && is != SlotState::Open {
                landings += 1;
                let open_for = after.t - opened_at[s].expect("a face lands after it opened");
                assert!(
                    open_for > 1e-5,
                    "{} landed {open_for:e} s after it opened, at t = {} s",
                    model.interfaces[model
                        .interfaces
                        .iter()
                        .position(|i| i.slots.contains(&s))
                        .unwrap()]
                    .name,
                    after.t
                );
            }
        }
    }
    assert!(
        openings >= 5 && landings >= 5,
        "{openings} openings, {landings} landings"
    );
    // At 0.3355 s the program lifts `c5_b1_on_c4_b1` off, the chain without it drives it back
    // (−0.085 m/s² at a point) and with it closed nothing opens: the run records that instant as
    // its first violation, before the monitor's next sample (0.34 s, where the face's resultant
    // lies outside the face), and goes on with the face closed.
    let v = traj.violation.as_ref().expect("a hypothesis violation");
    assert_eq!(v.kind, "lift_off");
    assert_eq!(v.interface, "c5_b1_on_c4_b1");
    assert!(v.t > 0.33 && v.t < 0.34, "t = {} s", v.t);
    assert!(
        traj.end_time > v.t + 0.1,
        "the run goes on to {} s",
        traj.end_time
    );
    let face = model.interface_index(&v.interface).unwrap();
    let after = samples
        .iter()
        .find(|x| x.t > v.t)
        .expect("a sample after the violation");
    for s in model.interfaces[face].slots.clone() {
        assert_ne!(after.states[s], SlotState::Open, "t = {} s", after.t);
    }
}

/// A wedge that rocks back about its toe closes every joint of its crack at one instant: the
/// faces land together, as one impact record that names each of them (docs/simulation.md,
/// "Faces that open"). The 5 × 5 running-bond wall of `examples/wall_pulse.rs` under a one-sine
/// pulse of 1.2 λ g (0.5 s) lifts a wedge off three bed joints of a stepped crack, and it lands
/// again at 0.2703 s. Their gap events fired one at a time: the first face landed with an
/// impulse while the others were 1e-13 m inside their supports, and the landings spread over
/// microseconds (on the 7 × 7 wall under 1.01 λ g the first impulse threw a block off its other
/// support, and the run stopped on a flight). Checked from the bodies' poses (the three faces
/// close loops of the file's tree, so the samples' coordinates give their poses exactly): the
/// faces are open 0.01 s before, every one of them touches its support at the landing, and after
/// it the run goes on to its end with every face closed and no hypothesis violated.
#[test]
fn a_wedge_lands_on_its_whole_crack_at_once() {
    let (model, traj) = run_wall_to_end(5, 1.2, 0.3);
    assert!(traj.violation.is_none(), "{:?}", traj.violation);
    let samples: Vec<Sample> = traj.samples.iter().collect();
    let slot_of = |name: &str| {
        let k = model.interface_index(name).unwrap();
        (k, model.interfaces[k].slots.start)
    };
    let landing = traj.impacts.first().expect("the wedge lands");
    assert!(
        (landing.t - 0.2703).abs() < 1e-3,
        "it lands at {} s",
        landing.t
    );
    assert!(
        landing.interfaces.len() >= 3,
        "one record for the crack: {:?}",
        landing.interfaces
    );
    let mut data = Data::new(&model);
    let before = samples
        .iter()
        .rev()
        .find(|x| {
            x.t == landing.t
                && landing
                    .interfaces
                    .iter()
                    .all(|n| x.states[slot_of(n).1] == SlotState::Open)
        })
        .expect("a sample of the instant with the faces open");
    let earlier = samples
        .iter()
        .rev()
        .find(|x| x.t <= landing.t - 0.01)
        .expect("a sample 0.01 s before");
    for name in &landing.interfaces {
        let (k, s) = slot_of(name);
        assert!(s >= model.dof(), "{name} closes a loop of the file's tree");
        let lowest = |x: &Sample, data: &mut Data| {
            face_points(&model, data, x, k)
                .iter()
                .map(|p| p.0)
                .fold(f64::INFINITY, f64::min)
        };
        let open = lowest(earlier, &mut data);
        assert!(
            open > 1e-6 * model.size,
            "{name}: {open:e} m at {} s",
            earlier.t
        );
        let touching = lowest(before, &mut data);
        assert!(
            touching.abs() <= 1e-9 * model.size,
            "{name}: lowest gap {touching:e} m at the landing"
        );
    }
    let last = samples.last().unwrap();
    assert_eq!(last.t, 0.3);
    assert!(!last.states.contains(&SlotState::Open), "{:?}", last.states);
}

/// The corner wedge of a 3 × 3 running-bond wall (the end half block of the middle course and
/// the block over it, turning about the half block's outer foot; the block over it leaves its
/// other support) has λ = 10/14 by hand (blocks 1.0 × 0.5 m). Under a one-sine pulse of
/// amplitude f λ g and period T it leaves rest when the pulse first reaches λ g, at
/// t* = (T/2π) asin(1/f), the block lifting off its other support there. At that crossing the
/// chain without the lifted face found no opening of its own (its multiplier equals the
/// structure's to round-off, and the test at rest keeps a margin of 1e-9 λ), nothing moved, the
/// face rested on its support again, closed, and lifted off again at the same instant: the run
/// stopped after 200 impacts at t* with no step (f = 1.01, 1.1, 1.5; 1.2 ran). The mechanism's
/// joints now open with the face, as they do at a crossing without a lift-off. Checked from the
/// bodies' poses: the face opens by more than 1e-6 of the size and no point of it goes below its
/// support; the run reaches its end with a handful of impacts.
#[test]
fn a_corner_wedge_lifts_off_when_the_pulse_reaches_its_multiplier() {
    let period = 0.5;
    for factor in [1.01, 1.1, 1.5] {
        let (model, ground, init) = wall_of_wall_pulse(3, factor);
        let params = Parameters {
            duration: 0.6,
            ..Parameters::default()
        };
        let traj = Simulation::new(&model, &ground, &init, params)
            .unwrap()
            .run()
            .unwrap_or_else(|f| panic!("f = {factor}: {}", f.error));
        let crossing = period / (2.0 * std::f64::consts::PI) * (1.0 / factor).asin();
        let uplift = traj.uplift_time.expect("the wedge leaves rest");
        assert!(
            (uplift - crossing).abs() < 1e-9,
            "f = {factor}: uplift at {uplift} s, the pulse reaches λ g at {crossing} s"
        );
        assert!(
            traj.impacts.len() < 10,
            "f = {factor}: {} impacts",
            traj.impacts.len()
        );
        assert!(
            traj.end_time >= 0.6 - 1e-12,
            "f = {factor}: ends at {} s",
            traj.end_time
        );
        let face = model.interface_index("c2_b0_on_c1_b1").unwrap();
        let slot = model.interfaces[face].slots.start;
        let samples: Vec<Sample> = traj.samples.iter().collect();
        let first_open = samples
            .iter()
            .find(|s| s.states[slot] == SlotState::Open)
            .expect("the block over the half block leaves its other support");
        // Open from the uplift on: at the first output sample after it (0.01 s apart).
        assert!(
            first_open.t >= uplift && first_open.t <= uplift + 0.01 + 1e-12,
            "f = {factor}: first open at {} s",
            first_open.t
        );
        assert!(
            matches!(model.interfaces[face].role, Role::Closure { .. }),
            "the face closes a loop of the file's tree (the samples give its bodies' poses)"
        );
        let mut data = Data::new(&model);
        let mut widest = 0.0f64;
        for s in samples.iter().filter(|s| s.states[slot] == SlotState::Open) {
            let clearance = face_clearance(&model, &mut data, s, face);
            assert!(
                clearance > -1e-9 * model.size,
                "f = {factor}: a corner {clearance:e} m inside the other block at {} s",
                s.t
            );
            for (gap, _) in face_points(&model, &mut data, s, face) {
                widest = widest.max(gap);
            }
        }
        assert!(
            widest > 1e-6 * model.size,
            "f = {factor}: widest gap {widest:e} m"
        );
        let lambda = crr_impact::statics::collapse_multiplier(
            &model,
            Vector3::x(),
            &crr_impact::statics::StaticsOptions::default(),
        )
        .unwrap()
        .lambda
        .unwrap();
        assert!((lambda - 10.0 / 14.0).abs() < 1e-9, "λ = {lambda}");
    }
}

/// A landing's snap puts the landing point back on its pivot; an open face's child turns about
/// a pivot on another support, so its point lands displaced along the face by a slip of second
/// order in the angle, and the snap that removes it moves the bodies. On the 4 × 4 wall of
/// `examples/wall_pulse.rs` under a one-sine pulse of 1.8 λ g the landing of `c3_b1_on_c2_b1` at
/// 0.4028 s moved q by 1.6e-4 rad and pushed the open face of `c2_b0_on_c1_b0` 7.2e-5 m into
/// its support: the run stopped there (its landing missed). A face the snap pushes in lands at
/// the same instant, as its own impact record after the first, and is closed in the instant's
/// last sample. That face is one of the file's tree, whose open poses the samples do not carry
/// (its translation off the pivot is not a coordinate), so the run's invariant (no point of an
/// open face deeper than 1e-6 of the size, checked at every step) is what guards it; checked
/// here from the bodies' poses, at every sample with no face of the file's tree open, no point
/// of an open loop-closing face is inside its support by more than that. The run reaches its
/// end and the energy balance closes to 1e-9 of m g L. Its first hypothesis violation is a
/// contact force of the monitor that pulls, at the sample of 0.36 s (`tension`, 164 N at
/// `c1_b1_on_c0_b0`). Until 2026-11-29 (sixth session), when faces whose blocks did not move
/// relative to each other could be lifted off (one at 0.3488 s here), it was the impulse of a
/// landing at 0.3896 s (`impulse_tension`, module `simulation::landing_check`).
#[test]
fn a_face_pushed_into_its_support_by_a_landing_lands_with_it() {
    let (model, traj) = run_wall_to_end(4, 1.8, 1.0);
    assert_eq!(traj.end_time, 1.0);
    let v = traj.violation.as_ref().expect("a contact that pulls");
    assert_eq!(
        (v.kind.as_str(), v.interface.as_str()),
        ("tension", "c1_b1_on_c0_b0")
    );
    assert!((v.t - 0.36).abs() < 1e-12, "at {} s", v.t);
    let scale = model.total_mass() * model.gravity * model.size;
    assert!(
        traj.energy_balance_error.abs() < 1e-9 * scale,
        "energy balance {:e} J of m g L = {scale} J",
        traj.energy_balance_error
    );
    // Two landings at one instant, the pushed face's after the other's.
    let pair = traj
        .impacts
        .windows(2)
        .find(|w| {
            w[0].t == w[1].t
                && w[0].interfaces.iter().any(|n| n == "c3_b1_on_c2_b1")
                && w[1].interfaces.iter().any(|n| n == "c2_b0_on_c1_b0")
        })
        .expect("the pushed face lands with the landing that pushed it");
    assert!((pair[0].t - 0.4028).abs() < 1e-3, "at {} s", pair[0].t);
    // The pushed face (a face of the file's tree) is closed in the last sample of that instant.
    let pushed = model.interfaces[model.interface_index("c2_b0_on_c1_b0").unwrap()]
        .slots
        .start;
    let last = traj
        .samples
        .iter()
        .rfind(|x| x.t == pair[1].t)
        .expect("samples at the landings");
    assert_ne!(last.states[pushed], SlotState::Open);
    let mut data = Data::new(&model);
    let loop_faces: Vec<usize> = (0..model.interfaces.len())
        .filter(|&k| model.interfaces[k].slots.start >= model.dof())
        .collect();
    let samples: Vec<Sample> = traj.samples.iter().collect();
    let mut deepest = f64::INFINITY;
    // Where a face of the file's tree is open, the file's coordinates do not give the poses
    // (its child's translation is not among them): those samples are left out.
    let tree_open = |x: &Sample| (0..model.dof()).any(|s| x.states[s] == SlotState::Open);
    for x in samples.iter().filter(|x| !tree_open(x)) {
        for &k in &loop_faces {
            if x.states[model.interfaces[k].slots.start] != SlotState::Open {
                continue;
            }
            for (gap, _) in face_points(&model, &mut data, x, k) {
                deepest = deepest.min(gap);
                assert!(
                    gap >= -1e-6 * model.size,
                    "{}: a point {:e} m inside its support at {} s",
                    model.interfaces[k].name,
                    -gap,
                    x.t
                );
            }
        }
    }
    assert!(deepest.is_finite(), "open loop-closing faces were sampled");
}

/// A landing whose plastic impulse needs tension is a hypothesis violation (`impulse_tension`,
/// docs/simulation.md, "The hypotheses monitor"): the 3 × 3 running-bond wall of
/// `examples/wall_pulse.rs` under a one-sine pulse of 1.5 λ g lifts its corner wedge, which
/// lands again at 0.3476 s; stopping it with every contact held needs −33.6 N s at the end half
/// block's bed `c1_b0_on_c0_b0` (the most compressive distribution of the impulses, about 2e-3 of
/// W √(L/g)). The record is at that landing, and the run goes on to its end with the plastic
/// impulse (the check records, it changes nothing).
/// Whether such an impulse pulls is the linear program's answer on the contact points; the
/// contact program at the velocity level agrees with it in
/// `the_impulse_program_holds_exactly_where_compressive_impulses_exist` (unit test).
#[test]
fn a_landing_whose_impulse_pulls_is_recorded() {
    let (model, traj) = run_wall_to_end(3, 1.5, 1.0);
    assert_eq!(traj.end_time, 1.0);
    let v = impulse_tension_at(&traj, 0.3476);
    assert_eq!(v.interface, "c1_b0_on_c0_b0");
    let unit = model.total_mass() * model.gravity * (model.size / model.gravity).sqrt();
    assert!(
        v.normal < -1e-3 * unit && v.normal > -1e-2 * unit,
        "normal impulse {} N s of W √(L/g) = {unit} N s",
        v.normal
    );
    let scale = model.total_mass() * model.gravity * model.size;
    assert!(traj.energy_balance_error.abs() < 1e-9 * scale);
}

/// A structure at rest never stays at rest under a load beyond its collapse multiplier (the
/// static theorem: no compressive equilibrium exists there). The running-bond walls of
/// `examples/wall_pulse.rs` of 3 × 3 and 6 × 6 blocks under a one-sine pulse of 1.5 λ g (0.5 s):
/// a wedge lifts off in the pulse's first half and lands in its second, at 0.3476 s and
/// 0.3465 s, under 1.01 g and 0.81 g along −x, above the multiplier along −x (0.714 and 0.579).
/// A landing can lock a joint rocking beside the landing face (a block rocking on one support
/// whose face lands on its other), leaving it at an angle of round-off with no rate; it was left
/// unseated, so the structure was at rest with one joint not seated, the test at rest with every
/// joint seated (the collapse multiplier's) was never asked, and both walls stayed at rest for
/// 0.11 s, until the load fell below λ. Checked against λ along ±x from the contact faces'
/// program on the model, and the kinetic energy of the samples (from the bodies' velocities):
/// wherever two consecutive samples are at rest, the load at the first is within the multiplier
/// along its direction (a structure leaving rest does so from a sample at rest, so one sample
/// alone may be at rest above λ); the check meets rests after the landing, and the landing's
/// record names a seated joint beyond its own slots.
#[test]
fn a_wall_at_rest_after_a_landing_leaves_rest_under_a_load_above_its_multiplier() {
    use crr_impact::statics::{StaticsOptions, collapse_multiplier};
    for (n, landing) in [(3, 0.3476), (6, 0.3465)] {
        let (model, traj) = run_wall_to_end(n, 1.5, 1.0);
        let (_, ground, _) = wall_of_wall_pulse(n, 1.5);
        let lambda = |d: Vector3<f64>| {
            collapse_multiplier(&model, d, &StaticsOptions::default())
                .unwrap()
                .lambda
                .unwrap()
        };
        let (plus, minus) = (lambda(Vector3::x()), lambda(-Vector3::x()));
        // At rest: T below 1e-12 of the weight times the size (a wedge rocking by 1e-6 rad/s
        // has some 1e-8 of it; round-off rates of 1e-17 rad/s give 1e-30).
        let weight = model.total_mass() * model.gravity;
        let at_rest = |s: &Sample| s.kinetic <= 1e-12 * weight * model.size;
        assert!(
            traj.impacts.iter().any(|i| (i.t - landing).abs() < 1e-4),
            "{n} × {n}: the wedge lands at {landing} s"
        );
        let samples: Vec<Sample> = traj.samples.iter().collect();
        let (mut checked, mut after_landing) = (0, 0);
        for pair in samples.windows(2) {
            if pair[1].t > pair[0].t && at_rest(&pair[0]) && at_rest(&pair[1]) {
                if pair[0].t > landing {
                    after_landing += 1;
                }
                let a = ground.acceleration(pair[0].t).x / model.gravity;
                let limit = if a >= 0.0 { plus } else { minus };
                assert!(
                    a.abs() <= limit * (1.0 + 1e-6),
                    "{n} × {n}: at rest at {} s and {} s under {a:.4} g, beyond λ = {limit:.4}",
                    pair[0].t,
                    pair[1].t
                );
                checked += 1;
            }
        }
        // The wall rests before the pulse reaches λ g, and again after the landing (where a
        // landing that seated no joint of its own is what the check is about).
        assert!(checked > 5, "{n} × {n}: {checked} pairs of samples at rest");
        assert!(
            after_landing > 10,
            "{n} × {n}: {after_landing} pairs at rest after the landing"
        );
        // The landing seats a joint other than its own slots: one it locked.
        assert!(
            traj.impacts
                .iter()
                .any(|i| (i.t - landing).abs() < 1e-4
                    && i.seated.iter().any(|s| !i.slots.contains(s))),
            "{n} × {n}: the landing seated no joint it locked"
        );
    }
}

/// A face whose lift-off ties (its blocks do not move without it) stays closed and is left out
/// of the contact program until the next impact or landing, so that the uplift event can fire
/// again for the other joints (docs/simulation.md, "Faces that open"). The 3 × 3 wall of
/// `examples/wall_pulse.rs` under 2 λ g: at 0.0796 s the program lifts off `c2_b1_on_c1_b2`,
/// whose blocks do not move, and then `c2_b2_on_c1_b3`, which the chain without it drives back
/// into its support: the run records that `lift_off` at its instant. With the tied face kept
/// closed but still offered to the program (28f35b8), the program's answer stayed "opens", the
/// uplift event never fired again, and the run's first record was an `outside_face` of the
/// monitor at 0.0900 s, the lift-off unseen.
#[test]
fn a_tied_face_does_not_hide_the_lift_offs_that_follow() {
    let (_, traj) = run_wall_to_end(3, 2.0, 1.0);
    assert_eq!(traj.end_time, 1.0);
    let v = traj
        .violation
        .as_ref()
        .expect("a lift-off the chain contradicts");
    assert_eq!(
        (v.kind.as_str(), v.interface.as_str()),
        ("lift_off", "c2_b2_on_c1_b3"),
        "at {} s",
        v.t
    );
    assert!((v.t - 0.0796).abs() < 1e-4, "at {} s", v.t);
}

/// A state the engine cannot decide stops the run instead of stalling it (docs/simulation.md,
/// "Limitations"). The 5 × 5 wall of `examples/wall_pulse.rs` under 1.8 λ g (λ = 0.6) is back at
/// rest after a landing at 0.4032 s, under a ground acceleration of about 1.7 λ g: it must move.
/// The contact program lifts 14 faces off, the chain without them drives some into their
/// supports, and the chain with them confirms none of the program's other releases; the uplift
/// test fired again one round-off step (6e-14 s) later, for ever (the run did not end in 5
/// minutes). It now stops with `SimulationError::Undecided` after 100 such events: checked
/// here against the load (the structure cannot be at rest at that instant: |a_g| > λ g along
/// the load's direction, λ from the static theorem) and against the time the events took (no
/// step of the motion: the pulse's period is 0.5 s), with the results up to that instant kept
/// and the lifting faces named.
#[test]
fn a_state_the_engine_cannot_decide_stops_the_run() {
    use crr_impact::SimulationError;
    use crr_impact::statics::{StaticsOptions, collapse_multiplier};
    let (model, ground, init) = wall_of_wall_pulse(5, 1.8);
    let params = Parameters {
        duration: 0.45,
        ..Parameters::default()
    };
    let failure = Simulation::new(&model, &ground, &init, params)
        .unwrap()
        .run()
        .expect_err("the run cannot decide the state at 0.4032 s");
    let SimulationError::Undecided {
        t,
        events,
        span,
        interfaces,
    } = &failure.error
    else {
        panic!("not an undecided state: {}", failure.error)
    };
    assert!((t - 0.40316).abs() < 1e-4, "at {t} s");
    // The events came round-off steps apart (measured: 5.8e-14 s each), not steps of the
    // motion: all of them within 1e-10 s, a billionth of the pulse's half period.
    assert!(
        *events >= 100 && *span < 1e-10,
        "{events} events in {span} s"
    );
    // The load at that instant is beyond the wall's multiplier along its direction: rest is
    // not an answer, so the stop is not a result withheld.
    let a = ground.acceleration(*t).x / model.gravity;
    let direction = Vector3::x() * a.signum();
    let lambda = collapse_multiplier(&model, direction, &StaticsOptions::default())
        .unwrap()
        .lambda
        .unwrap();
    assert!(a.abs() > 1.5 * lambda, "{a} g against λ = {lambda}");
    assert!(!interfaces.is_empty(), "the faces the program lifts off");
    for name in interfaces {
        assert!(model.interface_index(name).is_some(), "{name}");
    }
    // The results until then are kept: samples every 10 ms to the stop and its impacts.
    let partial = &failure.partial;
    assert_eq!(partial.end_time, *t);
    assert!(
        partial.samples.len() >= 40,
        "{} samples",
        partial.samples.len()
    );
    let last = partial.samples.iter().next_back().unwrap();
    assert!((last.t - t).abs() < 1e-9, "last sample at {} s", last.t);
    assert!(
        partial.impacts.len() >= 2,
        "{} impacts",
        partial.impacts.len()
    );
}
