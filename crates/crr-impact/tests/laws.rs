//! Physical facts of the impact maps (docs/physics.md §5 and §6).

use crr_dynamics::eom::constraint_row_scale;
use crr_dynamics::integrator::{
    Direction, EventFunctions, Method, OdeSystem, Options, RhsError, Solver, Stop,
};
use crr_dynamics::linalg::pinv_solve;
use crr_impact::laws::*;
use crr_kinematics::fixtures::{box_body, hinge, oriented_hinge, single_block, trilithon};
use crr_kinematics::mass_matrix::world_inertia;
use crr_kinematics::shapes::PrismShape;
use crr_kinematics::spec::{BodySpec, DEFAULT_GRAVITY};
use crr_kinematics::{
    ActivePivots, Data, Model, Side, StructureSpec, constraint_jacobian, forward_kinematics,
    jacobians, mass_matrix,
};
use nalgebra::{DMatrix, DVector, Vector3};
use proptest::prelude::*;

fn block_model(b: f64, h: f64) -> Model {
    Model::from_spec(&single_block(b, h, 2500.0)).unwrap()
}

fn sides(s: &[Side]) -> ActivePivots {
    ActivePivots { sides: s.to_vec() }
}

/// The block in both crossing directions: (before, after, θ̇⁻).
fn crossings() -> [(Side, Side, f64); 2] {
    [
        (Side::Positive, Side::Negative, -1.3),
        (Side::Negative, Side::Positive, 0.7),
    ]
}

#[test]
fn housner_block_coefficient_and_energy_ratio() {
    for (b, h) in [(0.1, 1.0), (0.25, 1.0), (0.5, 1.0), (1.0, 1.0), (0.3, 0.2)] {
        let model = block_model(b, h);
        let mut kin = Data::new(&model);
        let alpha = (b / h).atan();
        let r = 1.0 - 1.5 * alpha.sin().powi(2);
        for (s0, s1, w) in crossings() {
            let q = DVector::zeros(1);
            let qd = DVector::from_element(1, w);
            let res =
                momentum_law(&model, &mut kin, &q, &qd, &sides(&[s0]), &sides(&[s1])).unwrap();
            // One scalar equation I₀ θ̇⁺ = (I₀ − 2 m b²)... evaluated from O(1) quantities:
            // a few round-offs, so 1e-12 relative is ample.
            let ratio = res.qdot[0] / w;
            assert!((ratio - r).abs() < 1e-12, "b={b} h={h}: {ratio} vs {r}");
            assert!((res.energy_ratio() - r * r).abs() < 1e-12);
            eprintln!("block b/h={:.2}: r error {:.2e}", b / h, (ratio - r).abs());
        }
    }
}

/// A prism whose section is a symmetric trapezoid (bottom half-width b, top half-width bt,
/// height H), depth d along y.
fn trapezoid(b: f64, bt: f64, height: f64, d: f64) -> StructureSpec {
    let body = BodySpec {
        name: "pier".into(),
        density: Some(2400.0),
        mass: None,
        box_shape: None,
        polyhedron: None,
        prism: Some(PrismShape {
            polygon: vec![
                [-b, -d / 2.0, 0.0],
                [b, -d / 2.0, 0.0],
                [bt, -d / 2.0, height],
                [-bt, -d / 2.0, height],
            ],
            extrude: [0.0, d, 0.0],
        }),
        annular_sector: None,
        blocks: Vec::new(),
    };
    StructureSpec {
        name: "trapezoid".into(),
        gravity: DEFAULT_GRAVITY,
        body: vec![body],
        interface: vec![hinge(
            "base",
            "ground",
            "pier",
            [0.0, 1.0, 0.0],
            [b, 0.0, 0.0],
            [-b, 0.0, 0.0],
        )],
        symmetry: Vec::new(),
    }
}

#[test]
fn symmetric_shape_coefficient_uses_inertia_about_the_pivot() {
    for (b, bt, height) in [(0.4, 0.2, 2.0), (0.3, 0.5, 1.5)] {
        let model = Model::from_spec(&trapezoid(b, bt, height, 0.6)).unwrap();
        let mut kin = Data::new(&model);
        let q = DVector::zeros(1);
        forward_kinematics(
            &model,
            &mut kin,
            &q,
            &ActivePivots::uniform(&model, Side::Positive),
        );
        mass_matrix(&model, &mut kin);
        let i0 = kin.mass_matrix[(0, 0)];
        let r = 1.0 - 2.0 * model.bodies[0].mass * b * b / i0;
        for (s0, s1, w) in crossings() {
            let qd = DVector::from_element(1, w);
            let res =
                momentum_law(&model, &mut kin, &q, &qd, &sides(&[s0]), &sides(&[s1])).unwrap();
            // Same scalar arithmetic as the block: round-off only.
            assert!(
                (res.qdot[0] / w - r).abs() < 1e-12,
                "{} vs {r}",
                res.qdot[0] / w
            );
        }
    }
}

/// The mechanism velocity of the trilithon: Φ_q q̇ = 0 and q̇_base_left = −1, solved exactly
/// (DOF(2) = 1: the stacked system has full column rank).
fn mechanism_velocity(model: &Model, q: &DVector<f64>, pivots: &ActivePivots) -> DVector<f64> {
    let n = model.dof();
    let mut kin = Data::new(model);
    forward_kinematics(model, &mut kin, q, pivots);
    constraint_jacobian(model, &mut kin, pivots);
    let scale = constraint_row_scale(model);
    let m = model.constraint_rows;
    let mut a = DMatrix::zeros(m + 1, n);
    let mut rhs = DVector::zeros(m + 1);
    for i in 0..m {
        for j in 0..n {
            a[(i, j)] = scale[i] * kin.phi_q[(i, j)];
        }
    }
    a[(m, model.coord_index("base_left").unwrap())] = 1.0;
    rhs[m] = -1.0;
    let (x, rank) = pinv_solve(&a, &rhs);
    assert_eq!(rank, n);
    x
}

fn scaled_phi_rate(model: &Model, kin: &mut Data, pivots: &ActivePivots, v: &DVector<f64>) -> f64 {
    constraint_jacobian(model, kin, pivots);
    let scale = constraint_row_scale(model);
    (&kin.phi_q * v).component_mul(&scale).amax()
}

#[test]
fn trilithon_makris_vassiliou_coefficient() {
    let (b, h): (f64, f64) = (0.3, 2.0);
    let alpha = (b / h).atan();
    // γ = 0 exactly would make the beam massless: its rotation would have no inertia, and the
    // tree mass matrix would be singular (the laws work on the mechanism's velocities, but the
    // model itself rejects a zero mass). With γ = 1e-12 the coefficient differs from the γ = 0
    // formula by O(1e-12), below the 1e-10 tolerance.
    for gamma in [1e-12, 0.5, 1.0, 2.0] {
        let model = Model::from_spec(&trilithon(b, h, 3.0, 0.5, gamma)).unwrap();
        let mut kin = Data::new(&model);
        let mut before = ActivePivots::uniform(&model, Side::Positive);
        for name in ["top_left", "top_right"] {
            let i = model.interface_index(name).unwrap();
            before.sides[model.interfaces[i].slots.start] = Side::Negative;
        }
        let after = ActivePivots {
            sides: before.sides.iter().map(|s| s.flipped()).collect(),
        };
        let q = DVector::zeros(model.dof());
        let qd = mechanism_velocity(&model, &q, &before);
        let res = momentum_law(&model, &mut kin, &q, &qd, &before, &after).unwrap();
        let r = (1.0 - 1.5 * alpha.sin().powi(2) + 3.0 * gamma * (2.0 * alpha).cos())
            / (1.0 + 3.0 * gamma);
        // Null-space basis from an SVD of a well-scaled Φ_q and a 1 × 1 reduced inertia: errors
        // are a few hundred ε at most; 1e-10 leaves a wide margin.
        let err = (&res.qdot - &qd * r).amax() / qd.amax();
        eprintln!("trilithon γ={gamma}: r={r:.12} error {err:.2e}");
        assert!(err < 1e-10, "γ={gamma}: {err}");
        // Closures hold at the new pivots (scaled rows, dimensionless rates).
        assert!(scaled_phi_rate(&model, &mut kin, &after, &res.qdot) < 1e-12);
        assert!(res.kinetic_after <= res.kinetic_before);
    }
}

#[test]
fn restitution_on_the_block_gives_exactly_r() {
    let model = block_model(0.2, 1.0);
    let mut kin = Data::new(&model);
    for r in [0.0, 0.5, 0.9, 1.0] {
        for (s0, s1, w) in crossings() {
            let q = DVector::zeros(1);
            let qd = DVector::from_element(1, w);
            let res = restitution_law(
                &model,
                &mut kin,
                &q,
                &qd,
                &sides(&[s0]),
                &sides(&[s1]),
                &[(0, r)],
            )
            .unwrap();
            // A 2 × 2 solve of O(1) numbers: round-off.
            assert!((res.qdot[0] - r * w).abs() < 1e-14);
        }
    }
}

/// Two boxes stacked on two-sided hinges about y (lower 2b₁ × 2h₁, upper 2b₂ × 2h₂).
fn two_block_stack() -> StructureSpec {
    let (b1, h1, b2, h2, d) = (0.4, 1.0, 0.25, 0.7, 0.5);
    StructureSpec {
        name: "stack".into(),
        gravity: DEFAULT_GRAVITY,
        body: vec![
            box_body("lower", 2500.0, [0.0, 0.0, h1], [2.0 * b1, d, 2.0 * h1]),
            box_body(
                "upper",
                2300.0,
                [0.0, 0.0, 2.0 * h1 + h2],
                [2.0 * b2, d, 2.0 * h2],
            ),
        ],
        interface: vec![
            hinge(
                "base",
                "ground",
                "lower",
                [0.0, 1.0, 0.0],
                [b1, 0.0, 0.0],
                [-b1, 0.0, 0.0],
            ),
            hinge(
                "joint",
                "lower",
                "upper",
                [0.0, 1.0, 0.0],
                [b2, 0.0, 2.0 * h1],
                [-b2, 0.0, 2.0 * h1],
            ),
        ],
        symmetry: Vec::new(),
    }
}

#[test]
fn restitution_keeps_the_momentum_of_the_motions_that_leave_the_slot_rate_unchanged() {
    // The impulse of the law, (J⁺)ᵀ𝕄(J⁺q̇⁺ − J⁻q̇⁻), acts along the impacting slot only: every
    // motion δq̇ with δq̇_slot = 0 has the same momentum before and after. The body momenta are
    // taken from the Jacobians here (body_momentum_rhs), not from M.
    let model = Model::from_spec(&two_block_stack()).unwrap();
    let mut kin = Data::new(&model);
    for r in [0.0, 0.6, 1.0] {
        for slot in [0, 1] {
            let mut q = DVector::from_vec(vec![0.04, -0.03]);
            q[slot] = 0.0;
            let qd = DVector::from_vec(vec![-0.8, 1.1]);
            let mut before = ActivePivots::uniform(&model, Side::Negative);
            before.follow_coordinates(&q);
            before.sides[slot] = Side::Positive;
            let mut after = before.clone();
            after.sides[slot] = Side::Negative;
            let res =
                restitution_law(&model, &mut kin, &q, &qd, &before, &after, &[(slot, r)]).unwrap();
            let p_before = body_momentum_rhs(&model, &q, &qd, &before, &after);
            let p_after = body_momentum_rhs(&model, &q, &res.qdot, &after, &after);
            let other = 1 - slot;
            // Momenta O(1e3–1e4) from O(1) rates: 1e-12 relative is a few round-offs.
            let scale = p_before.amax();
            assert!(
                (p_after[other] - p_before[other]).abs() < 1e-12 * scale,
                "r = {r}, slot {slot}: {p_before} → {p_after}"
            );
            if r == 1.0 {
                // An elastic switch: T is kept.
                assert!(
                    (res.kinetic_after - res.kinetic_before).abs() < 1e-12 * res.kinetic_before
                );
            }
            if r == 0.0 {
                assert!(res.qdot[slot].abs() < 1e-12);
            }
        }
    }
}

#[test]
fn dirac_exact_multiplies_the_rate_by_r_to_the_c() {
    let model = block_model(0.2, 1.0);
    let mut kin = Data::new(&model);
    let r = 0.7;
    for c in [0.5, 1.0, 2.0, 3.5] {
        for (s0, s1, w) in crossings() {
            let q = DVector::zeros(1);
            let qd = DVector::from_element(1, w);
            let (b, a) = (sides(&[s0]), sides(&[s1]));
            let res = dirac_law(&model, &mut kin, &q, &qd, &b, &a, &[(0, r, c)]).unwrap();
            // Two scalar half-steps: round-off.
            assert!((res.qdot[0] / w - r.powf(c)).abs() < 1e-14);
            if c == 1.0 {
                let rest = restitution_law(&model, &mut kin, &q, &qd, &b, &a, &[(0, r)]).unwrap();
                assert!((res.qdot[0] - rest.qdot[0]).abs() < 1e-14);
            }
        }
    }
}

#[test]
fn singular_restitution_is_an_error_not_a_panic() {
    // The same slot listed twice: two prescriptions for one rate.
    let model = block_model(0.2, 1.0);
    let mut kin = Data::new(&model);
    let q = DVector::zeros(1);
    let qd = DVector::from_element(1, -1.0);
    let (b, a) = (sides(&[Side::Positive]), sides(&[Side::Negative]));
    let e = restitution_law(&model, &mut kin, &q, &qd, &b, &a, &[(0, 0.5), (0, 0.6)]);
    assert!(matches!(e, Err(ImpactError::Invalid(_))), "{e:?}");
    let e = restitution_law(&model, &mut kin, &q, &qd, &b, &a, &[(3, 0.5)]);
    assert!(matches!(e, Err(ImpactError::SlotOutOfRange { .. })));
}

#[test]
fn regularised_delta_has_unit_area_and_width_eps() {
    for eps in [1.0, 1e-2, 1e-4] {
        // The composite trapezoid rule over a full period integrates cos exactly, and δ_ε
        // vanishes at both ends: the quadrature is exact up to round-off.
        let n = 64;
        let hq = eps / n as f64;
        let area: f64 = (0..=n)
            .map(|i| {
                let x = -eps / 2.0 + i as f64 * hq;
                let w = if i == 0 || i == n { 0.5 } else { 1.0 };
                w * regularised_delta(x, eps)
            })
            .sum::<f64>()
            * hq;
        assert!((area - 1.0).abs() < 1e-13, "{area}");
        assert_eq!(regularised_delta(0.5 * eps * (1.0 + 1e-12), eps), 0.0);
        assert_eq!(regularised_delta(-0.5 * eps * (1.0 + 1e-12), eps), 0.0);
        assert!(regularised_delta(0.499 * eps, eps) > 0.0);
        assert!((regularised_delta(0.0, eps) - 2.0 / eps).abs() < 1e-12 / eps);
    }
}

/// θ̈ = −p² sin(α sgnθ − θ) (+ C ln r θ̇|θ̇| δ_ε(θ) when `eps` is Some).
struct Block {
    p2: f64,
    alpha: f64,
    r: f64,
    c: f64,
    eps: Option<f64>,
}

impl OdeSystem for Block {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        let s = if y[0] > 0.0 { 1.0 } else { -1.0 };
        dydt[0] = y[1];
        dydt[1] = -self.p2 * (self.alpha * s - y[0]).sin();
        if let Some(eps) = self.eps {
            dydt[1] += self.c * self.r.ln() * y[1] * y[1].abs() * regularised_delta(y[0], eps);
        }
        Ok(())
    }
}

/// g = θ − level, falling.
struct Level(f64);
impl EventFunctions for Level {
    fn count(&self) -> usize {
        1
    }
    fn eval(&mut self, _t: f64, y: &[f64], g: &mut [f64]) {
        g[0] = y[0] - self.0;
    }
    fn direction(&self, _i: usize) -> Direction {
        Direction::Falling
    }
}

fn run_to(solver: &mut Solver, sys: &mut Block, level: f64) -> Vec<f64> {
    let stop = solver
        .advance(sys, 10.0, &mut Level(level), &mut |_| {})
        .unwrap();
    assert!(matches!(stop, Stop::Event { .. }));
    solver.y().to_vec()
}

#[test]
fn regularised_dirac_converges_to_the_exact_impulse_at_first_order() {
    let (b, h): (f64, f64) = (0.2, 1.0);
    let rr: f64 = (b * b + h * h).sqrt();
    let (r, c, w0): (f64, f64, f64) = (0.8, 1.5, -0.6);
    let p2 = 3.0 * DEFAULT_GRAVITY / (4.0 * rr);
    let alpha = (b / h).atan();
    let mut errors = Vec::new();
    for eps in [1e-2, 1e-3, 1e-4] {
        let opts = Options {
            rtol: 1e-13,
            atol: 1e-15,
            // Many steps inside the δ support: h_max ≪ ε/|θ̇|.
            h_max: eps / w0.abs() / 200.0,
            ..Options::default()
        };
        let mut sys = Block {
            p2,
            alpha,
            r,
            c,
            eps: Some(eps),
        };
        let mut solver = Solver::new(Method::Dop853, opts, 2).unwrap();
        solver.reset(0.0, &[2.0 * eps, w0]);
        let y = run_to(&mut solver, &mut sys, -2.0 * eps);
        // Exact flight: no δ, r^C applied at θ = 0.
        let mut reference = Block { eps: None, ..sys };
        let mut solver = Solver::new(Method::Dop853, opts, 2).unwrap();
        solver.reset(0.0, &[2.0 * eps, w0]);
        let y0 = run_to(&mut solver, &mut reference, 0.0);
        let t0 = solver.t();
        solver.reset(t0, &[y0[0], y0[1] * r.powf(c)]);
        let y1 = run_to(&mut solver, &mut reference, -2.0 * eps);
        let err = ((y[1] - y1[1]) / y1[1]).abs();
        eprintln!(
            "ε={eps:.0e}: ratio {:.10} (exact-flight {:.10}, r^C {:.10}), rel. error {err:.3e}",
            y[1] / w0,
            y1[1] / w0,
            r.powf(c)
        );
        errors.push(err);
    }
    for k in 0..errors.len() - 1 {
        let order = (errors[k] / errors[k + 1]).log10();
        eprintln!("observed order {order:.3}");
        // The δ_ε spreads the impulse over a time ε/|θ̇| during which gravity (bounded) acts
        // on a different velocity than in the exact flight: the error is O(ε).
        assert!((order - 1.0).abs() < 0.3, "order {order}");
    }
}

#[test]
fn regularised_force_matches_the_scalar_formula_on_the_block() {
    let model = block_model(0.2, 1.0);
    let mut kin = Data::new(&model);
    let q = DVector::from_element(1, 1e-3);
    forward_kinematics(
        &model,
        &mut kin,
        &q,
        &ActivePivots::uniform(&model, Side::Positive),
    );
    mass_matrix(&model, &mut kin);
    let qd = DVector::from_element(1, -0.5);
    let mut out = DVector::zeros(1);
    let (r, c, eps) = (0.7, 2.0, 1e-2);
    dirac_regularised_force(
        &model,
        &kin,
        &qd,
        &[1e-3],
        &[RegularisedSlot {
            slot: 0,
            r,
            c,
            width: eps,
        }],
        &mut out,
    );
    // One coordinate: F/M = C ln r θ̇|θ̇| δ_ε(θ) (the normalised single-block equation).
    let expect = c * r.ln() * -0.5 * 0.5 * regularised_delta(1e-3, eps);
    assert!((out[0] / kin.mass_matrix[(0, 0)] - expect).abs() < 1e-12 * expect.abs());
}

/// A random stack of `n` boxes, each on the previous one (or the ground) with a two-sided hinge
/// about x or y through its base edges.
fn random_stack(n: usize, dims: &[(f64, f64, f64, f64, bool)]) -> StructureSpec {
    let mut body = Vec::new();
    let mut interface = Vec::new();
    let mut z = 0.0;
    let mut parent = "ground".to_string();
    for (i, &(bx, by, h, off, about_x)) in dims.iter().take(n).enumerate() {
        let name = format!("b{i}");
        let c = Vector3::new(off, 0.0, z + h);
        body.push(box_body(
            &name,
            2000.0 + 300.0 * i as f64,
            c.into(),
            [2.0 * bx, 2.0 * by, 2.0 * h],
        ));
        let (axis, pa, pb) = if about_x {
            (
                Vector3::x(),
                Vector3::new(off, by, z),
                Vector3::new(off, -by, z),
            )
        } else {
            (
                Vector3::y(),
                Vector3::new(off + bx, 0.0, z),
                Vector3::new(off - bx, 0.0, z),
            )
        };
        interface.push(oriented_hinge(
            &format!("h{i}"),
            &parent,
            &name,
            axis,
            pa,
            pb,
            c,
        ));
        z += 2.0 * h;
        parent = name;
    }
    StructureSpec {
        name: "random_stack".into(),
        gravity: DEFAULT_GRAVITY,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

fn body_momentum_rhs(
    model: &Model,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
) -> DVector<f64> {
    let mut km = Data::new(model);
    forward_kinematics(model, &mut km, q, before);
    jacobians(model, &mut km);
    let mut kp = Data::new(model);
    forward_kinematics(model, &mut kp, q, after);
    jacobians(model, &mut kp);
    let mut b = DVector::zeros(model.dof());
    for (i, body) in model.bodies.iter().enumerate() {
        let (jcm, jwm) = (
            km.com_jacobian.rows(3 * i, 3),
            km.angular_jacobian.rows(3 * i, 3),
        );
        let (jcp, jwp) = (
            kp.com_jacobian.rows(3 * i, 3),
            kp.angular_jacobian.rows(3 * i, 3),
        );
        let iw = world_inertia(body, &kp.rot_ops[model.body_coord[i]]);
        b += jcp.transpose() * (jcm * qd) * body.mass + jwp.transpose() * (iw * (jwm * qd));
    }
    b
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 200,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x1A_B0_57),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn momentum_law_dissipates_and_balances_momentum(
        n in 2usize..=3,
        dims in proptest::collection::vec(
            (0.1f64..0.5, 0.1f64..0.5, 0.3f64..1.5, -0.05f64..0.05, any::<bool>()), 3),
        q0 in proptest::collection::vec(-0.1f64..0.1, 3),
        qd0 in proptest::collection::vec(-2.0f64..2.0, 3),
        impact in proptest::collection::vec(any::<bool>(), 3),
        first in 0usize..3,
        side in any::<bool>(),
    ) {
        let model = Model::from_spec(&random_stack(n, &dims)).unwrap();
        let mut q = DVector::from_vec(q0[..n].to_vec());
        let qd = DVector::from_vec(qd0[..n].to_vec());
        let tie = if side { Side::Positive } else { Side::Negative };
        let mut before = ActivePivots::uniform(&model, tie);
        let mut hit: Vec<usize> = (0..n).filter(|&k| impact[k]).collect();
        if !hit.contains(&(first % n)) {
            hit.push(first % n);
        }
        for &k in &hit {
            q[k] = 0.0;
        }
        before.follow_coordinates(&q);
        let mut after = before.clone();
        for &k in &hit {
            after.sides[k] = before.sides[k].flipped();
        }
        let mut kin = Data::new(&model);
        let res = momentum_law(&model, &mut kin, &q, &qd, &before, &after).unwrap();
        // T⁺ is the 𝕄-norm of the projection of the body velocities on the new chain's range:
        // never larger than T⁻ (round-off allowance 1e-12 relative).
        prop_assert!(res.kinetic_after <= res.kinetic_before * (1.0 + 1e-12),
            "{} > {}", res.kinetic_after, res.kinetic_before);
        // M⁺ q̇⁺ against the body-momentum right-hand side built independently here; M is well
        // conditioned for these stacks (ratios below ~1e4), so 1e-10 relative is generous.
        let b = body_momentum_rhs(&model, &q, &qd, &before, &after);
        let lhs = &kin.mass_matrix * &res.qdot;
        prop_assert!((&lhs - &b).norm() <= 1e-10 * b.norm().max(1e-300), "{lhs} vs {b}");
    }
}

#[test]
fn closure_slot_rates_match_the_closure_angles() {
    use crr_kinematics::closure_angles;
    use crr_kinematics::fixtures::{colonnade, random_chain};
    for spec in [
        colonnade(0.3, 2.0, 1.5, 0.4),
        random_chain(7, 4, 2),
        random_chain(11, 5, 2),
        trilithon(0.3, 2.0, 3.0, 0.5, 1.0),
    ] {
        let model = Model::from_spec(&spec).unwrap();
        let n = model.dof();
        let pivots = ActivePivots::uniform(&model, Side::Positive);
        let q = DVector::zeros(n);
        let qd = DVector::from_fn(n, |i, _| 0.3 + 0.17 * i as f64 - 0.05 * (i * i) as f64);
        let mut kin = Data::new(&model);
        forward_kinematics(&model, &mut kin, &q, &pivots);
        let nc = model.slot_count - n;
        let angles_at = |x: &DVector<f64>| {
            let mut k = Data::new(&model);
            forward_kinematics(&model, &mut k, x, &pivots);
            let mut out = vec![0.0; nc];
            closure_angles(&model, &k, &mut out);
            out
        };
        let hs = 1e-6;
        let (ap, am) = (angles_at(&(&q + &qd * hs)), angles_at(&(&q - &qd * hs)));
        for s in n..model.slot_count {
            let fd = (ap[s - n] - am[s - n]) / (2.0 * hs);
            let a = slot_rate_direction(&model, &kin, s);
            // Central difference: O(h²) ≈ 1e-12 truncation, round-off ε/h ≈ 1e-10.
            assert!(
                (a.dot(&qd) - fd).abs() < 1e-8,
                "{}: slot {s}: {} vs {fd}",
                model.name,
                a.dot(&qd)
            );
        }
    }
}

#[test]
fn redundant_closures_colonnade_momentum_law() {
    use crr_kinematics::fixtures::colonnade;
    // Four columns under a rigid slab: 3 rocking-base closures (12 rows), many redundant.
    let model = Model::from_spec(&colonnade(0.3, 2.0, 1.5, 0.4)).unwrap();
    let n = model.dof();
    let before = ActivePivots::uniform(&model, Side::Positive);
    let after = ActivePivots::uniform(&model, Side::Negative);
    let q = DVector::zeros(n);
    let mut kin = Data::new(&model);
    forward_kinematics(&model, &mut kin, &q, &before);
    constraint_jacobian(&model, &mut kin, &before);
    // q̇⁻ = the projection of an arbitrary vector on ker Φ_q⁻.
    let phi = kin.phi_q.clone();
    let v = DVector::from_fn(n, |i, _| (i as f64 * 0.7).sin());
    let (x, _) = pinv_solve(&phi, &(&phi * &v));
    let qd = &v - x;
    assert!(scaled_phi_rate(&model, &mut kin, &before, &qd) < 1e-12);
    let res = momentum_law(&model, &mut kin, &q, &qd, &before, &after).unwrap();
    assert!(scaled_phi_rate(&model, &mut kin, &after, &res.qdot) < 1e-12);
    assert!(res.kinetic_after <= res.kinetic_before * (1.0 + 1e-12));
    assert!(res.kinetic_after > 0.0);
}

#[test]
fn closed_chain_dirac_and_restitution_on_a_closure_slot() {
    let model = Model::from_spec(&trilithon(0.3, 2.0, 3.0, 0.5, 1.0)).unwrap();
    let mut before = ActivePivots::uniform(&model, Side::Positive);
    let slot = |name: &str| {
        model.interfaces[model.interface_index(name).unwrap()]
            .slots
            .start
    };
    for name in ["top_left", "top_right"] {
        before.sides[slot(name)] = Side::Negative;
    }
    let after = ActivePivots {
        sides: before.sides.iter().map(|s| s.flipped()).collect(),
    };
    let q = DVector::zeros(model.dof());
    let qd = mechanism_velocity(&model, &q, &before);
    let mut kin = Data::new(&model);
    forward_kinematics(&model, &mut kin, &q, &before);
    let s = slot("top_right");
    let a = slot_rate_direction(&model, &kin, s);
    let (r, c) = (0.8, 1.7);
    let res = dirac_law(&model, &mut kin, &q, &qd, &before, &after, &[(s, r, c)]).unwrap();
    // DOF(2) = 1: the closure slot's rate fixes the whole motion; round-off only.
    assert!((a.dot(&res.qdot) / a.dot(&qd) - r.powf(c)).abs() < 1e-12);
    assert!(scaled_phi_rate(&model, &mut kin, &after, &res.qdot) < 1e-12);
    // Two slots tied by the loop (DOF(2) = 1) are one impact mode: both rates take r and the
    // mechanism's kinetic energy r² (the fixture is symmetric: M⁺ = M⁻ on the mechanism).
    let res = restitution_law(
        &model,
        &mut kin,
        &q,
        &qd,
        &before,
        &after,
        &[(s, r), (0, r)],
    )
    .unwrap();
    assert!((a.dot(&res.qdot) / a.dot(&qd) - r).abs() < 1e-12);
    assert!((res.qdot[0] / qd[0] - r).abs() < 1e-12);
    assert!((res.energy_ratio() - r * r).abs() < 1e-12);
}
