//! The hypotheses monitor against closed forms for a single block: contact force at rest and
//! under a horizontal acceleration (friction demand a_x/g), and at θ = 0 while rocking with rate
//! θ̇₀ (N = m(g + z̈_c), F_x = m ẍ_c), with flight and sliding reported at the first sample.

use std::collections::BTreeMap;
use std::path::Path;

use crr_dynamics::ForwardSolver;
use crr_dynamics::eom::Dynamics;
use crr_dynamics::ground_motion::{Axis, ComponentSpec, ConstantSpec, GroundMotion, SignalSpec};
use crr_dynamics::{InitialSpec, solve_initial};
use crr_impact::monitor::{ContactForce, contact_forces};
use crr_impact::{Parameters, Simulation};
use crr_kinematics::fixtures::{box_body, single_block, transformed};
use crr_kinematics::{ActivePivots, Model, Side};
use nalgebra::{DVector, Matrix3, Rotation3, Vector3};

const G: f64 = 9.81;

/// A constant ground acceleration with the given components (m/s²).
fn constant_ground(components: &[(Axis, f64)]) -> GroundMotion {
    components
        .iter()
        .fold(GroundMotion::none(), |ground, &(axis, value)| {
            ground
                .with_component(
                    axis,
                    &ComponentSpec::new(SignalSpec::Constant(ConstantSpec { value })),
                    Path::new("."),
                )
                .unwrap()
        })
}

/// The contact force of the one interface of a one-coordinate model at (θ, θ̇), on the pivots of
/// `side`, seated or not, with `solver`; and whether the one-coordinate closed form solved it.
fn one_force(
    model: &Model,
    ground: &GroundMotion,
    side: Side,
    seated: bool,
    solver: ForwardSolver,
    (theta, rate): (f64, f64),
) -> (ContactForce, bool) {
    let mut d = Dynamics::new(model, ActivePivots::uniform(model, side));
    d.solver = solver;
    if seated {
        d.seated = vec![0];
    }
    let q = DVector::from_element(1, theta);
    let f = contact_forces(
        model,
        &mut d,
        ground,
        0.0,
        &q,
        &DVector::from_element(1, rate),
    )
    .unwrap()[0]
        .unwrap();
    (f, d.used_single_coordinate())
}

#[test]
fn seated_block_force_and_sliding_demand() {
    let model = Model::from_spec(&single_block(0.2, 1.0, 2500.0)).unwrap();
    let m = model.total_mass();
    let ax = 0.15 * G;
    let ground = constant_ground(&[(Axis::X, ax)]);
    let (f, _) = one_force(
        &model,
        &ground,
        Side::Positive,
        true,
        ForwardSolver::Auto,
        (0.0, 0.0),
    );
    // The ground holds the weight and pushes the block with the ground: F = m (a_x, 0, g).
    assert!((f.normal - m * G).abs() < 1e-9 * m * G, "N = {}", f.normal);
    assert!(
        (f.force[0] - m * ax).abs() < 1e-9 * m * G && (f.tangential - m * ax).abs() < 1e-9 * m * G
    );
    assert!((f.friction_demand() - 0.15).abs() < 1e-12);
    // Below uplift (0.15 < tan α = 0.2), the monitor reports sliding for μ = 0.1, nothing for 0.3.
    let init = solve_initial(&model, &InitialSpec::default()).unwrap();
    for (mu, slides) in [(0.1, true), (0.3, false)] {
        let params = Parameters {
            duration: 0.1,
            friction: Some(mu),
            ..Parameters::default()
        };
        let traj = Simulation::new(&model, &ground, &init, params)
            .unwrap()
            .run()
            .map_err(|f| f.error)
            .unwrap();
        assert!(traj.uplift_time.is_none());
        assert_eq!(
            traj.violation.is_some(),
            slides,
            "μ = {mu}: {:?}",
            traj.violation
        );
        if let Some(v) = traj.violation {
            assert_eq!(
                (v.t, v.kind.as_str(), v.interface.as_str()),
                (0.0, "sliding", "base")
            );
        }
    }
}

#[test]
fn rocking_block_contact_force_and_flight() {
    let (b, h): (f64, f64) = (0.2, 1.0);
    let model = Model::from_spec(&single_block(b, h, 2500.0)).unwrap();
    let m = model.total_mass();
    let (r, alpha) = ((b * b + h * h).sqrt(), (b / h).atan());
    let p2 = 3.0 * G / (4.0 * r);
    let ground = GroundMotion::none();
    for rate in [0.5, 2.5, 3.5] {
        let (f, _) = one_force(
            &model,
            &ground,
            Side::Positive,
            false,
            ForwardSolver::Auto,
            (0.0, rate),
        );
        let theta_dd = -p2 * alpha.sin();
        let z_dd = r * alpha.sin() * theta_dd - r * alpha.cos() * rate * rate;
        let x_dd = r * alpha.cos() * theta_dd + r * alpha.sin() * rate * rate;
        assert!(
            (f.normal - m * (G + z_dd)).abs() < 1e-9 * m * G,
            "θ̇ = {rate}: N {} vs {}",
            f.normal,
            m * (G + z_dd)
        );
        assert!((f.force[0] - m * x_dd).abs() < 1e-9 * m * G);
        // Flight at the first sample iff N < 0, i.e. θ̇² > (g − R p² sin²α)/(R cos α) ≈ 3.09².
        let init = solve_initial(
            &model,
            &InitialSpec {
                rates: BTreeMap::from([("base".into(), rate)]),
                ..Default::default()
            },
        )
        .unwrap();
        let traj = Simulation::new(
            &model,
            &ground,
            &init,
            Parameters {
                duration: 0.05,
                ..Parameters::default()
            },
        )
        .unwrap()
        .run()
        .map_err(|f| f.error)
        .unwrap();
        let flies = G + z_dd < 0.0;
        assert_eq!(rate > 3.09, flies);
        match &traj.violation {
            Some(v) if flies => assert_eq!((v.t, v.kind.as_str()), (0.0, "tension")),
            None if !flies => {}
            other => panic!("θ̇ = {rate}: {other:?}"),
        }
    }
}

/// On a closed chain the reactions come from the loop's multipliers too: the seated trilithon's
/// two base contacts carry its whole weight, and each top contact carries the architrave's
/// weight split between them (N_top_left + N_top_right = m_beam g).
#[test]
fn trilithon_reactions_balance_the_weight() {
    let model = Model::from_spec(&crr_kinematics::fixtures::trilithon(
        0.25, 1.5, 2.0, 0.5, 1.0,
    ))
    .unwrap();
    let mut d = Dynamics::new(&model, ActivePivots::uniform(&model, Side::Positive));
    d.seated = (0..model.slot_count).collect();
    let n = model.dof();
    let f = contact_forces(
        &model,
        &mut d,
        &GroundMotion::none(),
        0.0,
        &DVector::zeros(n),
        &DVector::zeros(n),
    )
    .unwrap();
    let normal = |name: &str| f[model.interface_index(name).unwrap()].unwrap().normal;
    let w = model.total_mass() * G;
    let w_beam = model.bodies[model.body_index("architrave").unwrap()].mass * G;
    assert!((normal("base_left") + normal("base_right") - w).abs() < 1e-9 * w);
    assert!((normal("top_left") + normal("top_right") - w_beam).abs() < 1e-9 * w);
    assert!(
        ["base_left", "base_right", "top_left", "top_right"]
            .iter()
            .all(|i| normal(i) > 0.0)
    );
}

/// The hyperstatic rule of `monitor::check`: a tension in the given (least-norm) forces is a
/// violation only if no self-stress state makes every normal force ≥ −tolerance/2. On the
/// trilithon's four monitored joints (two column bases, two lintel seats), one synthetic
/// self-stress state moving force from the first joint to the second: N = (−3, 5, 10, 10) kN is
/// made compressive by moving 3 to 5 kN (no violation), N = (−10, 5, 10, 10) kN is not (moving
/// 10 would leave −5: the tension is reported on the first joint, with its least-norm N).
#[test]
fn hyperstatic_tension_needs_no_compressive_distribution() {
    use crr_impact::monitor::{ContactForce, check};
    use nalgebra::DMatrix;
    let model = Model::from_spec(&crr_kinematics::fixtures::trilithon(
        0.25, 1.5, 2.0, 0.5, 1.0,
    ))
    .unwrap();
    let monitored = model.interfaces.len();
    assert_eq!(monitored, 4);
    let forces = |n: [f64; 4]| -> Vec<Option<ContactForce>> {
        n.iter()
            .map(|&normal| {
                Some(ContactForce {
                    force: [0.0, 0.0, normal],
                    normal,
                    tangential: 0.0,
                })
            })
            .collect()
    };
    let mut d = DMatrix::zeros(monitored, 1);
    d[(0, 0)] = 1.0;
    d[(1, 0)] = -1.0;
    let tol = 1.0;
    let fixable = forces([-3e3, 5e3, 1e4, 1e4]);
    assert!(check(&model, &fixable, None, 0.0, None, tol).is_some());
    assert_eq!(check(&model, &fixable, Some(&d), 0.0, None, tol), None);
    let hopeless = forces([-1e4, 5e3, 1e4, 1e4]);
    let v = check(&model, &hopeless, Some(&d), 0.0, None, tol).expect("tension");
    assert_eq!(
        (v.kind.as_str(), v.interface.as_str()),
        ("tension", model.interfaces[0].name.as_str())
    );
    assert_eq!(v.normal, -1e4);
    // A state that moves no force at all changes nothing.
    let none = DMatrix::zeros(monitored, 1);
    assert!(check(&model, &fixable, Some(&none), 0.0, None, tol).is_some());
}

/// On one body with one coordinate the monitor takes the contact force in closed form, with θ̈
/// from the kinematics and the one-coordinate kernel's I_p (`Dynamics::
/// single_coordinate_accelerations`), or θ̈ = 0 when the joint is seated; with
/// `ForwardSolver::Cholesky` it solves M(q) q̈ = Q − h (with the seated row held) and assembles
/// the forces along the tree in general. Both are exact, so the contact forces agree to
/// round-off: here on a block whose centre is off the hinge's mid-plane and off its symmetry
/// plane, turned 0.7 rad about z (its inertia is full in world axes and the force has a component
/// along the hinge axis), under a constant ground acceleration with three components, on both
/// pivots, at tilts on either side and rates up to flight, and seated (at rest, and with a rate
/// the seat holds). The forces are of order mg and a few hundred roundings apart: 1e-12 mg.
#[test]
fn one_coordinate_forces_match_the_general_solve() {
    let (b, h) = (0.25, 0.9);
    // Housner's block on its hinge, with the body moved off the hinge's mid-plane (x) and off
    // its symmetry plane (y), and wider than the base.
    let mut spec = single_block(b, h, 2500.0);
    spec.body[0] = box_body(
        "block",
        2500.0,
        [0.06, 0.11, h],
        [2.0 * b + 0.12, 0.5, 2.0 * h],
    );
    let turn: Matrix3<f64> = *Rotation3::from_axis_angle(&Vector3::z_axis(), 0.7).matrix();
    let model =
        Model::from_spec(&transformed(&spec, &turn, &Vector3::new(1.0, -2.0, 0.0))).unwrap();
    let scale = model.total_mass() * G;
    let ground = constant_ground(&[
        (Axis::X, 0.21 * G),
        (Axis::Y, -0.13 * G),
        (Axis::Z, 0.08 * G),
    ]);
    let mut compared = 0;
    for side in [Side::Positive, Side::Negative] {
        for (theta, rate, seated) in [
            (0.0, 0.0, false),
            (0.12, -1.3, false),
            (-0.2, 2.4, false),
            (0.35, 4.0, false),
            (0.0, 0.0, true),
            (0.0, 1.5, true),
        ] {
            let forces = |solver| one_force(&model, &ground, side, seated, solver, (theta, rate));
            let ((closed, kernel_used), (general, general_kernel)) =
                (forces(ForwardSolver::Auto), forces(ForwardSolver::Cholesky));
            assert!(
                (kernel_used || seated) && !general_kernel,
                "the two paths were not taken"
            );
            for i in 0..3 {
                assert!(
                    (closed.force[i] - general.force[i]).abs() < 1e-12 * scale,
                    "{side:?} θ = {theta}, θ̇ = {rate}, seated {seated}: F[{i}] {} against {}",
                    closed.force[i],
                    general.force[i]
                );
            }
            assert!((closed.normal - general.normal).abs() < 1e-12 * scale);
            assert!((closed.tangential - general.tangential).abs() < 1e-12 * scale);
            // The case is three-dimensional: a force along the turned hinge axis.
            let axis = turn * Vector3::y();
            compared += usize::from(Vector3::from(general.force).dot(&axis).abs() > 1e-3 * scale);
        }
    }
    assert!(compared > 0, "no force along the hinge axis in any case");
}
