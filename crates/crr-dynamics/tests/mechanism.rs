//! One-DOF reduction from the engine's own M, U and Q (nothing typed in): the trilithon's
//! reduced equation has p̂² = p²(1 + 2γ)/(1 + 3γ) (Makris & Vassiliou 2013), and the activation
//! multiplier λ = U′(0)/(g Q(0)) is tan α for a block and for the trilithon.

use std::collections::BTreeMap;

use crr_dynamics::mechanism::{configuration, reduce_at};
use crr_dynamics::{InitialSpec, equivalent_block, lagrangian_parameters, solve_initial};
use crr_kinematics::fixtures::{four_hinge_arch, single_block, trilithon};
use crr_kinematics::mass_matrix::world_inertia;
use crr_kinematics::{ActivePivots, Data, Model, forward_kinematics};
use nalgebra::{DVector, Matrix3, Vector3};

const G: f64 = 9.81;

#[test]
fn block_activation_multiplier_is_tan_alpha_and_p_squared_is_3g_over_4r() {
    let (b, h): (f64, f64) = (0.2, 1.0);
    let model = Model::from_spec(&single_block(b, h, 2500.0)).unwrap();
    let init = solve_initial(
        &model,
        &InitialSpec {
            angles: BTreeMap::from([("base".into(), 0.01)]),
            ..Default::default()
        },
    )
    .unwrap();
    let eq = equivalent_block(&model, &init.pivots, 0, &Vector3::x()).unwrap();
    let (r, alpha) = ((b * b + h * h).sqrt(), (b / h).atan());
    // λ is a ratio of exact quantities: round-off only.
    assert!(
        (eq.lambda - alpha.tan()).abs() < 1e-13,
        "λ {} vs tan α {}",
        eq.lambda,
        alpha.tan()
    );
    // Tipping towards +x needs the ground to accelerate towards −x.
    assert_eq!(eq.lambda_sign, -1.0);
    // U″ comes from central differences (h = 1e-5): 1e-9 relative covers truncation and round-off.
    let p2 = 3.0 * G / (4.0 * r);
    assert!(
        (eq.p_squared - p2).abs() < 1e-9 * p2,
        "{} vs {p2}",
        eq.p_squared
    );
    assert!((eq.alpha - alpha).abs() < 1e-9);
    assert!((eq.p_squared_linearised - p2 * alpha.cos()).abs() < 1e-9 * p2);
}

#[test]
fn trilithon_reduced_equation_is_makris_vassiliou() {
    let (b, h): (f64, f64) = (0.25, 1.5);
    let (r, alpha) = ((b * b + h * h).sqrt(), (b / h).atan());
    let p2 = 3.0 * G / (4.0 * r);
    for gamma in [0.5, 1.0, 2.0] {
        let model = Model::from_spec(&trilithon(b, h, 2.0, 0.5, gamma)).unwrap();
        let k = model.coord_index("base_left").unwrap();
        let init = solve_initial(
            &model,
            &InitialSpec {
                angles: BTreeMap::from([("base_left".into(), 0.01)]),
                ..Default::default()
            },
        )
        .unwrap();
        let p_hat2 = p2 * (1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma);
        let mut masses = Vec::new();
        for theta in [0.0, 0.01, 0.05, 0.1, 0.15] {
            let q = configuration(&model, &init.q, &init.pivots, k, theta).unwrap();
            let red = reduce_at(&model, &q, &init.pivots, k, &Vector3::x()).unwrap();
            // Exact reduced equation M θ̈ = −U′(θ) = −M p̂² sin(α − θ).
            let lhs = red.potential_slope / red.mass;
            let rhs = p_hat2 * (alpha - theta).sin();
            assert!(
                (lhs - rhs).abs() < 1e-10 * p_hat2,
                "γ = {gamma}, θ = {theta}: {lhs} vs {rhs}"
            );
            masses.push(red.mass);
        }
        // The architrave translates: M(θ) is constant.
        let m0 = masses[0];
        assert!(
            masses.iter().all(|m| (m - m0).abs() < 1e-10 * m0),
            "{masses:?}"
        );
        let eq = equivalent_block(&model, &init.pivots, k, &Vector3::x()).unwrap();
        assert!(
            (eq.lambda - alpha.tan()).abs() < 1e-12,
            "γ = {gamma}: λ = {}",
            eq.lambda
        );
        assert!(
            (eq.p_squared - p_hat2).abs() < 1e-9 * p_hat2,
            "γ = {gamma}: {} vs {p_hat2}",
            eq.p_squared
        );
    }
}

/// The pivots of the opening state of coordinate `name` > 0.
fn opening_pivots(model: &Model, name: &str) -> ActivePivots {
    solve_initial(
        model,
        &InitialSpec {
            angles: BTreeMap::from([(name.into(), 0.01)]),
            ..Default::default()
        },
    )
    .unwrap()
    .pivots
}

/// Eq 4's parameters against their closed forms. The block rocks about a corner at distance R from
/// its centre: M = I₀ = (4/3)mR² and U − U(0) = mgR[cos(α − θ) − cos α] for θ > 0, so ν = ξ = 0,
/// η = U′(0)/M = p² sin α, χ = −U″(0)/M = p² cos α with p² = 3g/(4R). In the trilithon
/// (Makris & Vassiliou 2013) the architrave translates with the far top corner of each column, at
/// 2R from its pivot on the same side of the vertical as the column's centre: M = 2I₀ + 4m_bR² is
/// constant and U − U(0) = g(2m_c + 2m_b)R[cos(α − θ) − cos α], m_b = 2γm_c. Eq 6's χ and ε are
/// p_eq² = √(η² + χ²) and 1/α.
#[test]
fn eq4_parameters_are_the_closed_forms_of_the_block_and_the_trilithon() {
    let (b, h): (f64, f64) = (0.25, 1.5);
    let (r, alpha) = ((b * b + h * h).sqrt(), (b / h).atan());
    for gamma in [0.0, 0.5, 2.0] {
        let (model, name, m_c) = if gamma == 0.0 {
            let m = 2500.0 * 8.0 * b * b * h;
            (
                Model::from_spec(&single_block(b, h, 2500.0)).unwrap(),
                "base",
                m,
            )
        } else {
            let m = 2500.0 * 8.0 * b * b * h;
            (
                Model::from_spec(&trilithon(b, h, 2.0, 0.5, gamma)).unwrap(),
                "base_left",
                m,
            )
        };
        let k = model.coord_index(name).unwrap();
        let pivots = opening_pivots(&model, name);
        let l = lagrangian_parameters(&model, &pivots, k, &Vector3::x()).unwrap();
        let (columns, m_b) = if gamma == 0.0 {
            (1.0, 0.0)
        } else {
            (2.0, 2.0 * gamma * m_c)
        };
        let mass = columns * 4.0 / 3.0 * m_c * r * r + 4.0 * m_b * r * r;
        let weight_arm = G * (columns * m_c + 2.0 * m_b) * r;
        let eta = weight_arm * alpha.sin() / mass;
        let chi = weight_arm * alpha.cos() / mass;
        // η from U′ (exact), χ from central differences of U′ (h = 1e-5: 1e-9 relative).
        assert!(
            (l.eta - eta).abs() < 1e-10 * eta,
            "γ = {gamma}: η {} vs {eta}",
            l.eta
        );
        assert!(
            (l.chi - chi).abs() < 1e-9 * chi,
            "γ = {gamma}: χ {} vs {chi}",
            l.chi
        );
        // M is constant: ν and ξ are differences of round-off over h = 1e-4 and h² = 1e-6.
        assert!(
            l.nu.abs() < 1e-9 && l.xi.abs() < 1e-7,
            "γ = {gamma}: ν {} ξ {}",
            l.nu,
            l.xi
        );
        let p2 = weight_arm / mass;
        assert!((l.chi_housner - p2).abs() < 1e-9 * p2);
        assert!((l.epsilon - 1.0 / alpha).abs() < 1e-9 / alpha);
        if gamma == 0.0 {
            assert!((p2 - 3.0 * G / (4.0 * r)).abs() < 1e-12 * p2);
        }
    }
}

/// The reduced inertia of a mechanism computed without M or B: ½M(θ)θ̇² is the bodies' kinetic
/// energy along the mechanism, with ċ and ω from central differences (δ = 1e-5) of the bodies'
/// positions and rotations at closed configurations θ ± δ.
fn kinetic_mass(model: &Model, pivots: &ActivePivots, k: usize, theta: f64) -> f64 {
    let delta = 1e-5;
    let zero = DVector::zeros(model.dof());
    let state = |t: f64| {
        let q = configuration(model, &zero, pivots, k, t).unwrap();
        let mut data = Data::new(model);
        forward_kinematics(model, &mut data, &q, pivots);
        let rots: Vec<Matrix3<f64>> = (0..model.bodies.len())
            .map(|b| data.rot_ops[model.body_coord[b]])
            .collect();
        (data.com.clone(), rots)
    };
    let (c_plus, r_plus) = state(theta + delta);
    let (c_minus, r_minus) = state(theta - delta);
    let (_, r_mid) = state(theta);
    let mut mass = 0.0;
    for (b, body) in model.bodies.iter().enumerate() {
        let v = (c_plus[b] - c_minus[b]) / (2.0 * delta);
        // [ω]× = Ṙ Rᵀ.
        let w = (r_plus[b] - r_minus[b]) / (2.0 * delta) * r_mid[b].transpose();
        let omega = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        mass += body.mass * v.norm_squared() + omega.dot(&(world_inertia(body, &r_mid[b]) * omega));
    }
    mass
}

/// In the four-hinge arch the reduced inertia varies along the mechanism (ν ≠ 0): eq 4's ν and ξ
/// agree with differences of the kinetic-energy inertia above (ν with h = 1e-3, ξ with h = 1e-2:
/// truncation ~h² of the relative derivatives, and the kinetic inertia's own error ~1e-10 over h
/// and h²).
#[test]
fn eq4_inertia_terms_of_the_arch_match_its_kinetic_energy() {
    let model = Model::from_spec(&four_hinge_arch(4.0, 5.0, 1.0, false)).unwrap();
    let name = model.coords[0].name.clone();
    let pivots = opening_pivots(&model, &name);
    let l = lagrangian_parameters(&model, &pivots, 0, &Vector3::x()).unwrap();
    let m0 = kinetic_mass(&model, &pivots, 0, 0.0);
    let red = reduce_at(
        &model,
        &DVector::zeros(model.dof()),
        &pivots,
        0,
        &Vector3::x(),
    )
    .unwrap();
    assert!((red.mass - m0).abs() < 1e-8 * m0, "{} vs {m0}", red.mass);
    let (h1, h2) = (1e-3, 1e-2);
    let nu = (kinetic_mass(&model, &pivots, 0, h1) - kinetic_mass(&model, &pivots, 0, -h1))
        / (2.0 * h1 * m0);
    let xi = (kinetic_mass(&model, &pivots, 0, h2) - 2.0 * m0
        + kinetic_mass(&model, &pivots, 0, -h2))
        / (2.0 * h2 * h2 * m0);
    assert!(nu.abs() > 1e-3, "the arch's inertia varies: ν = {nu}");
    assert!(
        (l.nu - nu).abs() < 1e-5 * (1.0 + nu.abs()),
        "ν {} vs {nu}",
        l.nu
    );
    assert!(
        (l.xi - xi).abs() < 1e-3 * (1.0 + xi.abs()),
        "ξ {} vs {xi}",
        l.xi
    );
}
