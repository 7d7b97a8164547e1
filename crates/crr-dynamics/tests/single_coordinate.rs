//! The one-coordinate closed form I_p θ̈ = Q + τ (`crr_dynamics::single_coordinate`, what
//! `ForwardSolver::Auto` uses when DOF(1) = 1 and nothing is seated) against two independent
//! routes: the articulated-body algorithm (6 × 6 spatial inertias, `ForwardSolver::ArticulatedBody`)
//! and M by composite rigid bodies with h by Newton–Euler and Cholesky
//! (`ForwardSolver::Cholesky`), on random 3D bodies hinged about random axes, with random
//! states, ground accelerations and extra forces; and against Housner's closed form
//! θ̈ = −p² sin(α sgn θ − θ), p² = 3g/(4R), for a rectangular block.

use crr_dynamics::eom::GeneralizedForce;
use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::{Dynamics, ForwardSolver};
use crr_kinematics::fixtures::{SplitMix, random_chain, single_block};
use crr_kinematics::{ActivePivots, Model, Side};
use nalgebra::{DVector, Vector3};

mod common;
use common::{Tau, constant_ground};

/// The random body of `seed` (`fixtures::random_chain`) when it is on a hinge; None for a rocking
/// base (two tilt coordinates).
fn hinged_body(seed: u64) -> Option<Model> {
    let model = Model::from_spec(&random_chain(seed, 1, 0)).expect("valid random body");
    (model.dof() == 1).then_some(model)
}

/// A uniform ground acceleration with random components, up to 6 m/s² horizontally and 3 m/s²
/// vertically.
fn random_acceleration(rng: &mut SplitMix) -> Vector3<f64> {
    Vector3::new(
        rng.uniform(-6.0, 6.0),
        rng.uniform(-6.0, 6.0),
        rng.uniform(-3.0, 3.0),
    )
}

/// Solves at (θ, θ̇) under `ground` with `solver` (and τ when given).
fn solve(
    model: &Model,
    theta: f64,
    theta_dot: f64,
    ground: &GroundMotion,
    tau: Option<f64>,
    solver: ForwardSolver,
) -> Dynamics {
    let q = DVector::from_element(1, theta);
    let qdot = DVector::from_element(1, theta_dot);
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    pivots.follow_coordinates(&q);
    let mut d = Dynamics::new(model, pivots);
    d.solver = solver;
    let mut force = tau.map(|t| Tau(DVector::from_element(1, t)));
    d.accelerations_with(
        model,
        ground,
        0.0,
        &q,
        &qdot,
        force.as_mut().map(|f| f as &mut dyn GeneralizedForce),
    )
    .expect("regular mass matrix");
    d
}

/// Random bodies (boxes turned by random rotations, random densities) on a hinge with a random
/// axis and pivots: the closed form, the articulated-body algorithm and Cholesky on M agree on
/// θ̈ to 1e-12 relative (a few ε of each route's sums, well above their round-off of ~1e-15), and
/// the closed form leaves V and A as the other routes do.
#[test]
fn closed_form_agrees_with_aba_and_cholesky_on_random_bodies() {
    let mut checked = 0;
    for seed in 0u64..400 {
        let Some(model) = hinged_body(seed) else {
            continue;
        };
        let mut rng = SplitMix(seed ^ 0x0051_C00D);
        let theta = rng.uniform(-0.6, 0.6);
        let theta_dot = rng.uniform(-3.0, 3.0);
        let a = random_acceleration(&mut rng);
        let ground = constant_ground(a);
        let moment = model.total_mass() * model.gravity * model.size;
        let tau = (rng.uniform(0.0, 1.0) < 0.5).then(|| moment * rng.uniform(-1.0, 1.0));
        let single = solve(&model, theta, theta_dot, &ground, tau, ForwardSolver::Auto);
        assert!(single.used_single_coordinate(), "seed {seed}");
        assert!(!single.used_articulated_body());
        let aba = solve(
            &model,
            theta,
            theta_dot,
            &ground,
            tau,
            ForwardSolver::ArticulatedBody,
        );
        assert!(aba.used_articulated_body() && !aba.used_single_coordinate());
        let chol = solve(
            &model,
            theta,
            theta_dot,
            &ground,
            tau,
            ForwardSolver::Cholesky,
        );
        let scale = aba.qddot[0].abs().max(chol.qddot[0].abs());
        for other in [&aba, &chol] {
            let diff = (single.qddot[0] - other.qddot[0]).abs();
            assert!(
                diff <= 1e-12 * scale,
                "seed {seed}: θ̈ {} against {} (difference {diff:e})",
                single.qddot[0],
                other.qddot[0]
            );
        }
        let (v, vr) = (
            &single.kin.spatial_velocity[0],
            &chol.kin.spatial_velocity[0],
        );
        assert!((v - vr).amax() <= 1e-14 * vr.amax().max(1.0), "seed {seed}");
        assert!(
            single.kin.bias_acceleration[0].amax()
                <= 1e-14 * chol.kin.spatial_velocity[0].amax().powi(2).max(1.0),
            "seed {seed}: a root coordinate's velocity product vanishes"
        );
        checked += 1;
    }
    assert!(checked > 200, "only {checked} one-coordinate bodies");
}

/// Housner's rectangular block of half-width b and half-height h rocking on its corners, gravity
/// only: I_O = (4/3) m R² and θ̈ = −p² sin(α sgn θ − θ) with p² = 3g/(4R), R = √(b² + h²),
/// α = atan(b/h), on both pivots and at rest on each (θ = 0±).
#[test]
fn housner_closed_form() {
    let (b, h) = (0.2, 1.0);
    let model = Model::from_spec(&single_block(b, h, 2500.0)).expect("valid block");
    let (r, alpha) = ((b * b + h * h).sqrt(), f64::atan(b / h));
    let p2 = 3.0 * model.gravity / (4.0 * r);
    let none = GroundMotion::none();
    for theta in [-0.3, -0.1, -1e-9, 1e-9, 0.05, 0.19, 0.4] {
        let d = solve(&model, theta, 0.7, &none, None, ForwardSolver::Auto);
        assert!(d.used_single_coordinate());
        let s = f64::signum(theta);
        let expected = -p2 * (alpha * s - theta).sin();
        assert!(
            (d.qddot[0] - expected).abs() <= 1e-13 * p2,
            "θ = {theta}: θ̈ {} against Housner's {expected}",
            d.qddot[0]
        );
    }
}

/// A seated coordinate, or a solver chosen by the caller, is not the closed form's: the
/// articulated-body path then gives the seat reaction r = −Q (θ̈ = 0 held), with Q the moment of
/// the weight about the pivot, m g b for Housner's block on its positive pivot.
#[test]
fn seated_block_takes_the_articulated_path() {
    let (b, h, density) = (0.2, 1.0, 2500.0);
    let model = Model::from_spec(&single_block(b, h, density)).expect("valid block");
    let pivots = ActivePivots::uniform(&model, Side::Positive);
    let mut d = Dynamics::new(&model, pivots);
    d.seated = vec![0];
    let zero = DVector::zeros(1);
    d.accelerations(&model, &GroundMotion::none(), 0.0, &zero, &zero)
        .expect("regular");
    assert!(d.used_articulated_body() && !d.used_single_coordinate());
    assert_eq!(d.qddot[0], 0.0);
    let weight_moment = model.total_mass() * model.gravity * b;
    assert!(
        (d.seat_reactions[0].abs() - weight_moment).abs() <= 1e-12 * weight_moment,
        "reaction {} against m g b = {weight_moment}",
        d.seat_reactions[0]
    );
    // Released, the same workspace takes the closed form and reports no reaction (none of the
    // seated solve's), and no joint force.
    d.seated.clear();
    d.accelerations(&model, &GroundMotion::none(), 0.0, &zero, &zero)
        .expect("regular");
    assert!(d.used_single_coordinate());
    assert!(d.seat_reactions.is_empty());
    assert!(d.joint_force(0).is_none());
    d.integration_accelerations(&model, &GroundMotion::none(), 0.0, &zero, &zero, None)
        .expect("regular");
    assert!(d.seat_reactions.is_empty());
}

/// `Dynamics::single_coordinate_accelerations` on a seated coordinate (held, θ̈ = 0, the seat's
/// reaction −Q) against the general solve with the coordinate eliminated (Cholesky on M, the
/// reaction the residual of its row, with h from the velocity product), on random bodies under
/// random ground accelerations, at θ = 0 and with a rate the seat holds: θ̈ exactly 0, Q, Q_g
/// and the reaction to 1e-12 of the force scale. For Housner's block the reaction is also
/// checked against m g b (`seated_block_takes_the_articulated_path`).
#[test]
fn seated_closed_form_agrees_with_the_general_solve() {
    let mut checked = 0;
    for seed in 0u64..100 {
        let Some(model) = hinged_body(seed) else {
            continue;
        };
        let mut rng = SplitMix(seed ^ 0x5EA7_ED00);
        let ground = constant_ground(random_acceleration(&mut rng));
        let force_scale = model.total_mass() * (model.gravity + 10.0) * model.size;
        for theta_dot in [0.0, rng.uniform(-2.0, 2.0)] {
            let (q, qdot) = (DVector::zeros(1), DVector::from_element(1, theta_dot));
            let held = |solver| {
                let mut d = Dynamics::new(&model, ActivePivots::uniform(&model, Side::Positive));
                d.solver = solver;
                d.seated = vec![0];
                d
            };
            let mut closed = held(ForwardSolver::Auto);
            closed
                .single_coordinate_accelerations(&model, &ground, 0.0, &q)
                .expect("a seated coordinate is held")
                .expect("regular");
            let mut general = held(ForwardSolver::Cholesky);
            general
                .accelerations(&model, &ground, 0.0, &q, &qdot)
                .expect("regular");
            assert_eq!((closed.qddot[0], general.qddot[0]), (0.0, 0.0));
            for (name, a, b) in [
                ("Q", closed.load[0], general.load[0]),
                ("Q_g", closed.ground_force[0], general.ground_force[0]),
                (
                    "reaction",
                    closed.seat_reactions[0],
                    general.seat_reactions[0],
                ),
            ] {
                assert!(
                    (a - b).abs() <= 1e-12 * force_scale,
                    "seed {seed}, θ̇ = {theta_dot}: {name} {a} against {b}"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 100, "only {checked} states");
}

/// The integrator's kernel (`Dynamics::integration_accelerations`: θ̈, Q and Q_g from sin θ,
/// cos θ and the moments a₁, a₂, a₃ of the rest pivot) against the full evaluation on the
/// kinematics (forward kinematics, generalized loads from subtree sums, Cholesky on M), on random
/// bodies, states and ground accelerations, on both pivots in turn with one workspace (the kernel
/// follows the active pivot): θ̈, Q and Q_g agree to 1e-12 of their scale. So do those of
/// `Dynamics::single_coordinate_accelerations` (from the forward kinematics of the state and the
/// kernel's I_p).
#[test]
fn integration_kernel_agrees_with_the_full_evaluation() {
    let mut checked = 0;
    for seed in 0u64..300 {
        let Some(model) = hinged_body(seed) else {
            continue;
        };
        let mut rng = SplitMix(seed ^ 0x00CE_EE11);
        let ground = constant_ground(random_acceleration(&mut rng));
        let mut kernel = Dynamics::new(&model, ActivePivots::uniform(&model, Side::Positive));
        for _ in 0..4 {
            let theta = rng.uniform(-0.6, 0.6);
            let theta_dot = rng.uniform(-3.0, 3.0);
            let (q, qdot) = (
                DVector::from_element(1, theta),
                DVector::from_element(1, theta_dot),
            );
            kernel.pivots = ActivePivots::uniform(&model, Side::Positive);
            kernel.pivots.follow_coordinates(&q);
            kernel
                .integration_accelerations(&model, &ground, 0.0, &q, &qdot, None)
                .expect("regular");
            assert!(kernel.used_single_coordinate());
            let full = solve(
                &model,
                theta,
                theta_dot,
                &ground,
                None,
                ForwardSolver::Cholesky,
            );
            // The same from the forward kinematics of the state and the kernel's I_p.
            let mut from_kin = Dynamics::new(&model, kernel.pivots.clone());
            from_kin
                .single_coordinate_accelerations(&model, &ground, 0.0, &q)
                .expect("the kernel applies")
                .expect("regular");
            assert!(from_kin.used_single_coordinate());
            let force_scale = model.total_mass() * (model.gravity + 10.0) * model.size;
            for d in [&kernel, &from_kin] {
                for (name, a, b, scale) in [
                    ("θ̈", d.qddot[0], full.qddot[0], full.qddot[0].abs()),
                    ("Q", d.load[0], full.load[0], force_scale),
                    ("Q_g", d.ground_force[0], full.ground_force[0], force_scale),
                ] {
                    assert!(
                        (a - b).abs() <= 1e-12 * scale.max(1e-300),
                        "seed {seed}, θ = {theta}: {name} {a} against {b}"
                    );
                }
            }
            checked += 1;
        }
    }
    assert!(checked > 600, "only {checked} states");
}
