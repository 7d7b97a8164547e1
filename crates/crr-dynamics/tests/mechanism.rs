//! One-DOF reduction from the engine's own M, U and Q (nothing typed in): the trilithon's
//! reduced equation has p̂² = p²(1 + 2γ)/(1 + 3γ) (Makris & Vassiliou 2013), and the activation
//! multiplier λ = U′(0)/(g Q(0)) is tan α for a block and for the trilithon.

use std::collections::BTreeMap;

use crr_dynamics::mechanism::{configuration, reduce_at};
use crr_dynamics::{InitialSpec, equivalent_block, solve_initial};
use crr_kinematics::Model;
use crr_kinematics::fixtures::{single_block, trilithon};
use nalgebra::Vector3;

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
