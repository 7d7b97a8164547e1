//! The contact program in motion (`opening_qp`: Gauss' principle over the seated faces, one convex
//! program) against an exhaustive search written here: every way the seated slots of a state can
//! go (held, open on the positive pivot, open on the negative one: 3^m choices) is solved by the
//! chain's own equations of motion, a choice is admissible when each slot it opens opens on its
//! side, and Gauss' function is evaluated body by body (Gibbs–Appell: Σ ½m|a − g_eff|² +
//! ½(α − α_free)ᵀI(α − α_free), from the bodies' accelerations, not from M). Gauss' principle says
//! the motion is the admissible one of least Gauss function; the program, which also allows faces
//! to lift off, may only do better, and where it lifts nothing off it must name that choice.
//! States: samples of runs where some slots rock and others are seated (a colonnade rocking
//! across, the bundled 3D arch), under several constant loads, and with the seated slots'
//! recorded sides flipped (the program does not depend on them).

use std::path::Path;

use crr::dynamics::eom::{Dynamics, slot_row};
use crr::dynamics::ground_motion::{
    Axis, ComponentSpec, ConstantSpec, GroundMotion, PulseSpec, SignalSpec,
};
use crr::dynamics::{InitialSpec, solve_initial};
use crr::impact::simulation::{SlotState, opening_qp};
use crr::impact::{Parameters, Simulation};
use crr::kinematics::fixtures::colonnade;
use crr::kinematics::velocity::point_bias_acceleration;
use crr::kinematics::{ActivePivots, Model, Side};
use nalgebra::{DVector, Vector3};

const G: f64 = 9.81;

/// A state of a run with some slots seated: q, q̇, the pivots, the seated slots.
type State = (DVector<f64>, DVector<f64>, ActivePivots, Vec<usize>);

/// Gauss' function of the motion in `d` (after a solve), body by body.
fn gauss(model: &Model, d: &Dynamics) -> f64 {
    let kin = &d.kin;
    let g_eff = d.effective_gravity();
    let mut total = 0.0;
    for (b, body) in model.bodies.iter().enumerate() {
        let f = model.body_coord[b];
        let c = kin.com[b];
        let mut a = point_bias_acceleration(kin, Some(f), &c);
        let mut alpha: Vector3<f64> = kin.bias_acceleration[f].fixed_rows::<3>(0).into_owned();
        let mut j = Some(f);
        while let Some(jj) = j {
            a += kin.axis[jj].cross(&(c - kin.pivot[jj])) * d.qddot[jj];
            alpha += kin.axis[jj] * d.qddot[jj];
            j = model.coords[jj].parent;
        }
        let r = kin.rot_ops[f];
        let inertia = r * body.inertia * r.transpose();
        let omega: Vector3<f64> = kin.spatial_velocity[f].fixed_rows::<3>(0).into_owned();
        let free = -inertia.try_inverse().unwrap() * omega.cross(&(inertia * omega));
        let e = alpha - free;
        total += 0.5 * body.mass * (a - g_eff).norm_squared() + 0.5 * e.dot(&(inertia * e));
    }
    total
}

/// The admissible choice of least Gauss function: (releases, Gauss function).
fn exhaustive(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> (Vec<(usize, Side)>, f64) {
    let seated = &template.seated;
    let m = seated.len();
    let tol = 1e-9 * model.gravity / model.size;
    let mut row = DVector::zeros(model.dof());
    let mut best: Option<(Vec<(usize, Side)>, f64)> = None;
    for code in 0..3usize.pow(m as u32) {
        let mut pivots = template.pivots.clone();
        let (mut held, mut released) = (Vec::new(), Vec::new());
        let mut c = code;
        for &k in seated {
            match c % 3 {
                0 => held.push(k),
                choice => {
                    let side = if choice == 1 {
                        Side::Positive
                    } else {
                        Side::Negative
                    };
                    pivots.sides[k] = side;
                    released.push((k, side));
                }
            }
            c /= 3;
        }
        let mut d = Dynamics::new(model, pivots);
        d.seated = held;
        if d.accelerations(model, ground, 0.0, q, qdot).is_err() {
            continue;
        }
        let admissible = released.iter().all(|&(k, side)| {
            let bias = slot_row(model, &d.kin, k, &mut row);
            side.sign() * (row.dot(&d.qddot) + bias) > tol
        });
        if !admissible {
            continue;
        }
        let value = gauss(model, &d);
        if best.as_ref().is_none_or(|b| value < b.1) {
            best = Some((released, value));
        }
    }
    best.expect("holding every slot is admissible")
}

/// The program's decision at (q, q̇) with `seated` held on `pivots`, its releases solved by the
/// chain (None when a face lifts off).
fn program(
    model: &Model,
    ground: &GroundMotion,
    pivots: &ActivePivots,
    seated: &[usize],
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> (Vec<(usize, Side)>, Option<f64>) {
    let mut d = Dynamics::new(model, pivots.clone());
    d.seated = seated.to_vec();
    d.evaluate(model, ground, 0.0, q, qdot);
    let decision = opening_qp(model, &d).expect("the program solves");
    let mut releases = decision.releases.clone();
    releases.sort_by_key(|r| r.0);
    if !decision.lifting_off.is_empty() {
        return (releases, None);
    }
    let mut chain = pivots.clone();
    for &(k, side) in &releases {
        chain.sides[k] = side;
    }
    let mut s = Dynamics::new(model, chain);
    s.seated = seated
        .iter()
        .copied()
        .filter(|k| !releases.iter().any(|r| r.0 == *k))
        .collect();
    s.accelerations(model, ground, 0.0, q, qdot).unwrap();
    (releases, Some(gauss(model, &s)))
}

fn constant(ax: f64, ay: f64) -> GroundMotion {
    let c = |v: f64| ComponentSpec::new(SignalSpec::Constant(ConstantSpec { value: v }));
    GroundMotion::none()
        .with_component(Axis::X, &c(ax), Path::new("."))
        .unwrap()
        .with_component(Axis::Y, &c(ay), Path::new("."))
        .unwrap()
}

/// Moving samples of a run with 1 to `most` seated slots: (q, q̇, pivots of the moving slots,
/// seated slots).
fn moving_states(
    model: &Model,
    ground: &GroundMotion,
    duration: f64,
    most: usize,
    every: usize,
) -> Vec<State> {
    let init = solve_initial(model, &InitialSpec::default()).unwrap();
    let params = Parameters {
        duration,
        ..Parameters::default()
    };
    let traj = Simulation::new(model, ground, &init, params)
        .unwrap()
        .run()
        .map_err(|f| f.error)
        .unwrap();
    let rate_scale = (model.gravity / model.size).sqrt();
    traj.samples
        .iter()
        .filter_map(|s| {
            let seated: Vec<usize> = (0..model.slot_count)
                .filter(|&k| s.states[k] == SlotState::Seated)
                .collect();
            let moving = s.qdot.iter().any(|v| v.abs() > 1e-3 * rate_scale);
            (moving && !seated.is_empty() && seated.len() <= most).then(|| {
                let mut pivots = ActivePivots::uniform(model, Side::Positive);
                for k in 0..model.slot_count {
                    if s.states[k] == SlotState::Negative {
                        pivots.sides[k] = Side::Negative;
                    }
                }
                (
                    DVector::from_column_slice(s.q),
                    DVector::from_column_slice(s.qdot),
                    pivots,
                    seated,
                )
            })
        })
        .step_by(every)
        .collect()
}

/// Checks the program against the exhaustive search at every state and load; returns how many
/// (state, load) pairs opened something and how many lifted a face off.
fn check(model: &Model, states: &[State], loads: &[(f64, f64)]) -> (usize, usize) {
    let (mut opened, mut lifted) = (0, 0);
    for (q, qdot, pivots, seated) in states {
        for &(ax, ay) in loads {
            let ground = constant(ax, ay);
            let template = {
                let mut d = Dynamics::new(model, pivots.clone());
                d.seated = seated.clone();
                d
            };
            let (best, best_value) = exhaustive(model, &ground, &template, q, qdot);
            let mut best_sorted = best.clone();
            best_sorted.sort_by_key(|r| r.0);
            // The program's answer does not depend on the sides the seated slots were left on.
            let mut flipped = pivots.clone();
            for &k in seated {
                flipped.sides[k] = flipped.sides[k].flipped();
            }
            for sides in [pivots, &flipped] {
                let (releases, value) = program(model, &ground, sides, seated, q, qdot);
                let tag = format!("{} a = ({ax}, {ay}), seated {seated:?}", model.name);
                match value {
                    Some(value) => {
                        assert!(
                            (value - best_value).abs() <= 1e-9 * best_value.abs().max(1.0),
                            "{tag}: Gauss {value} against the exhaustive {best_value}"
                        );
                        assert_eq!(releases, best_sorted, "{tag}");
                    }
                    None => lifted += 1,
                }
                if !releases.is_empty() {
                    opened += 1;
                }
            }
        }
    }
    (opened, lifted)
}

#[test]
fn the_program_is_the_least_gauss_function_on_a_colonnade_rocking_across() {
    let (b, h) = (0.2, 1.5);
    let model = Model::from_spec(&colonnade(b, h, 1.2, 0.4)).unwrap();
    let pulse = SignalSpec::OneSinePulse(PulseSpec {
        amplitude: 3.0 * G * b / h,
        period: 0.8,
        start: 0.0,
    });
    let ground = GroundMotion::none()
        .with_component(Axis::Y, &ComponentSpec::new(pulse), Path::new("."))
        .unwrap();
    let states = moving_states(&model, &ground, 0.6, 8, 7);
    assert!(states.len() >= 3, "{} states", states.len());
    let t = G * b / h;
    let loads = [
        (0.0, 0.0),
        (0.9 * t, 0.0),
        (1.2 * t, 0.5 * t),
        (3.0 * t, -t),
    ];
    let (opened, lifted) = check(&model, &states, &loads);
    eprintln!(
        "colonnade: {} states, {opened} opened, {lifted} lifted",
        states.len()
    );
    assert!(
        opened > 0,
        "no load opened anything: the check would be empty"
    );
}

#[test]
fn the_program_is_the_least_gauss_function_on_the_bundled_3d_arch() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = root.join("examples/models/arch_3d.toml");
    let opts = crr::RunOptions {
        duration: Some(3.0),
        ..Default::default()
    };
    let p =
        crr::analysis::simulation::prepare(&crr::ModelInput::read(&path).unwrap(), &opts).unwrap();
    let model = &p.model;
    let states = moving_states(model, &p.ground, 3.0, 6, 8);
    assert!(states.len() >= 3, "{} states", states.len());
    let loads = [
        (0.0, 0.0),
        (0.3 * G, 0.1 * G),
        (-0.6 * G, 0.0),
        (0.2 * G, -0.8 * G),
    ];
    let (opened, lifted) = check(model, &states, &loads);
    eprintln!(
        "arch_3d: {} states, {opened} opened, {lifted} lifted",
        states.len()
    );
    assert!(opened > 0, "no load opened anything");
}

/// A colonnade rocking across (its y tilts moving, its x tilts seated) when the ground starts
/// falling at 2 g: the effective gravity g + (−a_g) points up, no contact can press, and the
/// least Gauss function lifts every seated face off (each body would accelerate at g_eff). The
/// run stops there with `SimulationError::LiftOff`, at the instant the fall starts, naming the
/// seated interfaces (the bases and the tops) and every body as in flight (no path to the
/// ground through a closed contact), with the results before it kept.
#[test]
fn a_colonnade_rocking_when_the_ground_falls_faster_than_gravity_stops_with_a_lift_off() {
    use crr::dynamics::ground_motion::RectangularPulseSpec;
    use crr::impact::simulation::SimulationError;
    let (b, h) = (0.2, 1.5);
    let model = Model::from_spec(&colonnade(b, h, 1.2, 0.4)).unwrap();
    let start = 0.3;
    let across = SignalSpec::OneSinePulse(PulseSpec {
        amplitude: 3.0 * G * b / h,
        period: 0.8,
        start: 0.0,
    });
    let fall = SignalSpec::RectangularPulse(RectangularPulseSpec {
        amplitude: -2.0 * G,
        duration: 0.1,
        start,
    });
    let ground = GroundMotion::none()
        .with_component(Axis::Y, &ComponentSpec::new(across), Path::new("."))
        .unwrap()
        .with_component(Axis::Z, &ComponentSpec::new(fall), Path::new("."))
        .unwrap();
    let init = solve_initial(&model, &InitialSpec::default()).unwrap();
    let params = Parameters {
        duration: 1.0,
        ..Parameters::default()
    };
    let failure = Simulation::new(&model, &ground, &init, params)
        .unwrap()
        .run()
        .expect_err("the structure cannot stay on its supports");
    let SimulationError::LiftOff {
        t,
        interfaces,
        in_flight,
        ..
    } = &failure.error
    else {
        panic!("{}", failure.error);
    };
    // Nothing presses: every body leaves every support, a flight of the whole colonnade.
    assert_eq!(in_flight.len(), model.bodies.len(), "{in_flight:?}");
    assert!(
        failure
            .error
            .to_string()
            .contains("lose(s) every support: a flight"),
        "{}",
        failure.error
    );
    assert!((t - start).abs() < 1e-9, "lift-off at {t}");
    assert!(!interfaces.is_empty());
    assert!(
        interfaces
            .iter()
            .all(|i| i.starts_with("base_") || i.starts_with("top_")),
        "{interfaces:?}"
    );
    let moving = failure
        .partial
        .samples
        .iter()
        .filter(|s| s.t < start)
        .count();
    assert!(moving > 10, "{moving} samples before the lift-off");
}

/// Seats that may twist (`twist = true`): the bundled baldachin with its three loop-closing tops
/// allowed to twist, rocking along x under a pulse (its y tilts seated, its x tilts moving), under
/// loads across. The program offers a twisting seat's tilts both pivots (a tilt turns about e₁,
/// or about R(e₁, θ₁)e₂ = n_B × e₁, the axis perpendicular to e₁ and to the child's face normal),
/// so it is the whole problem there too, and must name the exhaustive search's choice.
#[test]
fn the_program_is_the_least_gauss_function_on_seats_that_twist() {
    let path = crate::common::write_model(
        "baldachin_twist_program",
        &crate::twist_closure::twisting_text(),
    );
    let model = crr::load_model(&path).unwrap().1;
    assert!(
        model.interfaces.iter().any(|f| matches!(
            f.kind,
            crr::kinematics::InterfaceKind::RockingBase { twist: true, .. }
        )),
        "the model has twisting seats"
    );
    let t = G * 0.2 / 1.5;
    let pulse = SignalSpec::OneSinePulse(PulseSpec {
        amplitude: 3.0 * t,
        period: 0.8,
        start: 0.0,
    });
    let ground = GroundMotion::none()
        .with_component(Axis::X, &ComponentSpec::new(pulse), Path::new("."))
        .unwrap();
    let states = moving_states(&model, &ground, 0.8, 8, 9);
    assert!(states.len() >= 3, "{} states", states.len());
    // The states compared hold twisting seats' tilts seated (the tops' y tilts).
    let twisting_slot = |k: usize| {
        model.interfaces.iter().any(|f| {
            f.slots.contains(&k)
                && matches!(
                    f.kind,
                    crr::kinematics::InterfaceKind::RockingBase { twist: true, .. }
                )
        })
    };
    let with_twisting = states
        .iter()
        .filter(|s| s.3.iter().any(|&k| twisting_slot(k)))
        .count();
    assert!(
        with_twisting >= 3,
        "{with_twisting} states seat a twisting tilt"
    );
    let loads = [
        (0.0, 0.0),
        (0.5 * t, 1.2 * t),
        (-t, -2.0 * t),
        (2.0 * t, 0.9 * t),
    ];
    let (opened, lifted) = check(&model, &states, &loads);
    eprintln!(
        "twisting baldachin: {} states, {opened} opened, {lifted} lifted",
        states.len()
    );
    assert!(opened > 0, "no load opened anything");
}

/// The certificate the uplift test asks in motion before the contact program
/// (`face_forces::PressingCertificate`: a distribution of the locked motion's contact forces on
/// the faces pressing everywhere by a margin) on rocking bases, against the exhaustive search
/// above and the program. The states hold every kind of rocking face the simulation lets it
/// decide (`simulation::openings_slide_nowhere`): bases on an edge with their first tilt turned
/// and their second seated (whose touching corners leave along the child's face normal, on
/// which the faces then pose their forces), with their first seated and their second turned,
/// on one corner, with both seated, and seats that may twist. One certificate is asked state
/// after state and load after load, as a simulation asks it (its distribution carried over the
/// columns two states share, the faces' program solved where none carries). Wherever it holds,
/// holding every seated slot is the exhaustive search's least Gauss function and the program
/// opens and lifts nothing. Both answers occur, and states with the two kinds of edge, on tree and
/// loop-closing bases.
#[test]
fn the_pressing_certificate_on_rocking_bases_holds_only_where_nothing_opens() {
    use crr::impact::face_forces::PressingCertificate;
    use crr::impact::monitor::{ForceWork, body_loads_into};
    use crr::impact::simulation::{offers_both_pivots, openings_slide_nowhere};
    let t = G * 0.2 / 1.5;
    let pulse = |axis: Axis| {
        GroundMotion::none()
            .with_component(
                axis,
                &ComponentSpec::new(SignalSpec::OneSinePulse(PulseSpec {
                    amplitude: 3.0 * t,
                    period: 0.8,
                    start: 0.0,
                })),
                Path::new("."),
            )
            .unwrap()
    };
    let colonnade_model = Model::from_spec(&colonnade(0.2, 1.5, 1.2, 0.4)).unwrap();
    let twisting = crr::load_model(&crate::common::write_model(
        "baldachin_twist_certificate",
        &crate::twist_closure::twisting_text(),
    ))
    .unwrap()
    .1;
    let arch = {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let opts = crr::RunOptions {
            duration: Some(3.0),
            ..Default::default()
        };
        let input = crr::ModelInput::read(root.join("examples/models/arch_3d.toml")).unwrap();
        crr::analysis::simulation::prepare(&input, &opts).unwrap()
    };
    let cases: Vec<(&Model, Vec<State>)> = vec![
        (
            &colonnade_model,
            moving_states(&colonnade_model, &pulse(Axis::X), 0.6, 8, 7),
        ),
        (
            &colonnade_model,
            moving_states(&colonnade_model, &pulse(Axis::Y), 0.6, 8, 7),
        ),
        (
            &twisting,
            moving_states(&twisting, &pulse(Axis::X), 0.8, 8, 9),
        ),
        (
            &twisting,
            moving_states(&twisting, &pulse(Axis::Y), 0.8, 8, 9),
        ),
        (
            &arch.model,
            moving_states(&arch.model, &arch.ground, 3.0, 6, 8),
        ),
    ];
    let loads = [
        (0.0, 0.0),
        (0.5 * t, 0.2 * t),
        (-0.3 * t, 0.6 * t),
        (1.5 * t, -t),
        (-2.0 * t, -0.5 * t),
        (4.0 * t, 2.0 * t),
        (-6.0 * t, 1.0 * t),
    ];
    // Certified states with an edge turned on the first tilt (second seated) and on the second
    // (first seated); certified (state, load) pairs; pairs where the exhaustive search opens.
    let (mut first_turned, mut second_turned, mut certified, mut opened) = (0, 0, 0, 0);
    // Certified states where a loop-closing base rocks on an edge of its first tilt.
    let mut closing_first_turned = 0;
    for (model, states) in &cases {
        assert!(states.len() >= 3, "{}: {} states", model.name, states.len());
        assert!(openings_slide_nowhere(model), "{}", model.name);
        let mut certificate = PressingCertificate::default();
        let mut work = ForceWork::default();
        for (q, qdot, pivots, seated) in states {
            for &(ax, ay) in &loads {
                let ground = constant(ax, ay);
                let mut d = Dynamics::new(model, pivots.clone());
                d.seated = seated.clone();
                if !offers_both_pivots(model, &{
                    let mut e = d.clone();
                    e.evaluate(model, &ground, 0.0, q, qdot);
                    e
                }) {
                    continue;
                }
                d.accelerations(model, &ground, 0.0, q, qdot).unwrap();
                body_loads_into(model, &d, d.effective_gravity(), &mut work);
                let holds = certificate.holds(model, &d, &work).expect("answers");
                let (best, _) = exhaustive(model, &ground, &d, q, qdot);
                let tag = format!("{} a = ({ax}, {ay}), seated {seated:?}", model.name);
                if holds {
                    assert!(
                        best.is_empty(),
                        "{tag}: certified, the search opens {best:?}"
                    );
                    let mut e = Dynamics::new(model, pivots.clone());
                    e.seated = seated.clone();
                    e.evaluate(model, &ground, 0.0, q, qdot);
                    let decision = opening_qp(model, &e).expect("the program solves");
                    assert!(
                        decision.releases.is_empty() && decision.lifting_off.is_empty(),
                        "{tag}: certified, the program opens {:?}, lifts {:?}",
                        decision.releases,
                        decision.lifting_off
                    );
                    certified += 1;
                    // Some rocking base (loop-closing only, when `closing`) with its slots
                    // seated as `pattern`.
                    let edges = |pattern: [bool; 2], closing: bool| {
                        model.interfaces.iter().any(|f| {
                            matches!(f.kind, crr::kinematics::InterfaceKind::RockingBase { .. })
                                && (!closing
                                    || matches!(f.role, crr::kinematics::Role::Closure { .. }))
                                && f.slots.clone().map(|k| seated.contains(&k)).eq(pattern)
                        })
                    };
                    first_turned += usize::from(edges([false, true], false));
                    second_turned += usize::from(edges([true, false], false));
                    closing_first_turned += usize::from(edges([false, true], true));
                } else {
                    let mut e = Dynamics::new(model, pivots.clone());
                    e.seated = seated.clone();
                    e.evaluate(model, &ground, 0.0, q, qdot);
                    let decision = opening_qp(model, &e).expect("the program solves");
                    if !best.is_empty()
                        || !decision.releases.is_empty()
                        || !decision.lifting_off.is_empty()
                    {
                        opened += 1;
                    }
                }
            }
        }
    }
    eprintln!(
        "certificate on rocking bases: {certified} certified ({first_turned} with an edge on \
         the first tilt, {closing_first_turned} of them on a loop-closing base, {second_turned} \
         on the second), {opened} opened"
    );
    assert!(
        certified >= 20 && opened >= 5,
        "{certified} certified, {opened} opened"
    );
    assert!(
        first_turned >= 3 && second_turned >= 3 && closing_first_turned >= 3,
        "{first_turned} / {second_turned} certified states with each kind of edge, \
         {closing_first_turned} on a loop-closing base's first tilt"
    );
}
