//! Face-level contact geometry (`contact_geometry`, `contact_bias`) checked against quantities
//! computed here from the bodies' poses alone (`body_point`, `body_rotation` after
//! `forward_kinematics`): gaps and slips at rest, their Jacobians against central differences,
//! their biases (and rates) against differences along a trajectory, and the rocking convention
//! (a child rocking on its active pivot keeps that point closed and opens the others).
//!
//! The reference gap of a face point X (at rest) of interface A → B is
//! g = (Γ_A n)·(x_B(X) − x_A(X)) and the slips (Γ_A t_k)·(x_B − x_A), with the face's rest normal
//! and tangents from `contact_faces` (the input geometry, not the code under test).

use crr_kinematics::fixtures::{
    SplitMix, colonnade, four_hinge_arch, random_chain, single_block, trilithon,
};
use crr_kinematics::*;
use nalgebra::{DMatrix, DVector, Matrix3};

/// The models: random chains with hinges, rocking bases and closures, and the bundled-like
/// fixtures (a block, the trilithon, the two-sided and the plain four-hinge arch, the colonnade).
fn models() -> Vec<(String, Model)> {
    let mut specs = vec![
        single_block(0.25, 1.0, 2500.0),
        trilithon(0.25, 1.5, 2.0, 0.5, 1.0),
        four_hinge_arch(4.0, 5.0, 1.0, true),
        four_hinge_arch(4.0, 5.0, 1.0, false),
        colonnade(0.2, 1.5, 1.0, 0.3),
    ];
    for seed in 0..48u64 {
        let n = 1 + (seed as usize % 6);
        specs.push(random_chain(seed, n, (seed as usize % 3).min(n)));
    }
    specs
        .into_iter()
        .map(|spec| {
            let name = spec.name.clone();
            let model = Model::from_spec(&spec).unwrap_or_else(|e| panic!("{name}: {e}"));
            (name, model)
        })
        .collect()
}

/// A random state: q in ±0.6 rad, sides drawn at random (not following q: g(q) is smooth for
/// fixed sides), q̇ and q̈ in ±2.
fn random_state(
    model: &Model,
    rng: &mut SplitMix,
) -> (DVector<f64>, DVector<f64>, DVector<f64>, ActivePivots) {
    let n = model.dof();
    let q = DVector::from_fn(n, |_, _| rng.uniform(-0.6, 0.6));
    let qdot = DVector::from_fn(n, |_, _| rng.uniform(-2.0, 2.0));
    let qddot = DVector::from_fn(n, |_, _| rng.uniform(-2.0, 2.0));
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    for s in pivots.sides.iter_mut() {
        if rng.below(2) == 0 {
            *s = Side::Negative;
        }
    }
    (q, qdot, qddot, pivots)
}

/// Reference gaps (length m) and slips (length 2m, row 2p + k) from the bodies' poses.
fn reference(
    model: &Model,
    faces: &[ContactFace],
    data: &mut Data,
    q: &DVector<f64>,
    pivots: &ActivePivots,
) -> (DVector<f64>, DVector<f64>) {
    forward_kinematics(model, data, q, pivots);
    let mut gaps = Vec::new();
    let mut slips = Vec::new();
    for face in faces {
        let iface = &model.interfaces[face.interface];
        let rot_a = match iface.parent {
            Parent::Ground => Matrix3::identity(),
            Parent::Body(a) => body_rotation(model, data, a),
        };
        let (n, t1, t2) = (
            rot_a * face.normal,
            rot_a * face.tangents[0],
            rot_a * face.tangents[1],
        );
        for x in &face.points {
            let xb = body_point(model, data, iface.child, x);
            let xa = match iface.parent {
                Parent::Ground => *x,
                Parent::Body(a) => body_point(model, data, a, x),
            };
            let d = xb - xa;
            gaps.push(n.dot(&d));
            slips.push(t1.dot(&d));
            slips.push(t2.dot(&d));
        }
    }
    (DVector::from_vec(gaps), DVector::from_vec(slips))
}

/// Fills `contacts` (geometry and biases) at (q, q̇, pivots).
fn evaluate(
    model: &Model,
    data: &mut Data,
    contacts: &mut ContactKinematics,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    pivots: &ActivePivots,
) {
    forward_kinematics(model, data, q, pivots);
    velocities(model, data, qdot);
    contact_geometry(model, data, contacts);
    contact_bias(model, data, contacts);
}

/// The point layout follows the faces, and at q = 0 (any sides) every gap and slip is 0 and the
/// two copies coincide with the rest point (to 1e-15 of the model's size; they are exact).
#[test]
fn gaps_and_slips_vanish_at_rest() {
    let mut worst: f64 = 0.0;
    for (name, model) in models() {
        let mut data = Data::new(&model);
        let mut contacts = ContactKinematics::new(&model);
        let faces = contact_faces(&model);
        assert_eq!(contacts.faces, faces);
        let m: usize = faces.iter().map(|f| f.points.len()).sum();
        assert_eq!(contacts.point_count(), m);
        assert_eq!(contacts.gap_jacobian.shape(), (m, model.dof()));
        assert_eq!(contacts.slip_jacobian.shape(), (2 * m, model.dof()));
        let mut rng = SplitMix(0x5EED);
        for _ in 0..4 {
            let (_, qdot, _, pivots) = random_state(&model, &mut rng);
            let q = DVector::zeros(model.dof());
            evaluate(&model, &mut data, &mut contacts, &q, &qdot, &pivots);
            for face in &faces {
                let range = contacts.point_range(face.interface);
                assert_eq!(range.len(), face.points.len());
                for (p, x) in range.zip(&face.points) {
                    assert_eq!(contacts.interface_of_point[p], face.interface);
                    worst = worst
                        .max((contacts.child_point[p] - x).amax())
                        .max((contacts.parent_point[p] - x).amax());
                }
            }
            worst = worst.max(contacts.gap.amax()).max(contacts.slip.amax());
            assert!(
                worst <= 1e-15 * model.size,
                "{name}: gap, slip or copy off by {worst:e} at rest"
            );
        }
    }
    eprintln!("at rest: largest |g|, |s|, |x − X| = {worst:e} m");
}

/// G and S against central differences of g(q), s(q) from the bodies' poses, h = 1e-6. The
/// difference quotient errs by h²/6·|g‴| ≈ 1e-12 L (truncation) plus ε|g|/h ≈ 1e-10 L (round-off
/// of g ~ L, the model's size), so 1e-7 relative to max(|G|, L) leaves three orders of margin.
#[test]
fn jacobians_match_central_differences() {
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for (name, model) in models() {
        let mut data = Data::new(&model);
        let mut contacts = ContactKinematics::new(&model);
        let faces = contact_faces(&model);
        let mut rng = SplitMix(0x7AC0 ^ model.dof() as u64);
        for state in 0..4 {
            let (mut q, qdot, _, pivots) = random_state(&model, &mut rng);
            if state == 0 {
                q.fill(0.0);
            }
            evaluate(&model, &mut data, &mut contacts, &q, &qdot, &pivots);
            let (g0, s0) = reference(&model, &faces, &mut data, &q, &pivots);
            // The values themselves: the same numbers by another route.
            let value_err = (&g0 - &contacts.gap)
                .amax()
                .max((&s0 - &contacts.slip).amax());
            assert!(
                value_err <= 1e-13 * model.size,
                "{name}: values {value_err:e}"
            );
            let m = contacts.point_count();
            let mut g_fd = DMatrix::zeros(m, model.dof());
            let mut s_fd = DMatrix::zeros(2 * m, model.dof());
            for k in 0..model.dof() {
                let mut qp = q.clone();
                qp[k] += h;
                let mut qm = q.clone();
                qm[k] -= h;
                let (gp, sp) = reference(&model, &faces, &mut data, &qp, &pivots);
                let (gm, sm) = reference(&model, &faces, &mut data, &qm, &pivots);
                g_fd.set_column(k, &((gp - gm) / (2.0 * h)));
                s_fd.set_column(k, &((sp - sm) / (2.0 * h)));
            }
            let scale = contacts
                .gap_jacobian
                .amax()
                .max(contacts.slip_jacobian.amax())
                .max(model.size);
            let err = (&g_fd - &contacts.gap_jacobian)
                .amax()
                .max((&s_fd - &contacts.slip_jacobian).amax())
                / scale;
            worst = worst.max(err);
            assert!(err < 1e-7, "{name}, state {state}: Jacobian off by {err:e}");
        }
    }
    eprintln!("Jacobians: largest error {worst:e} relative to max(|G|, |S|, L)");
}

/// The biases β (g̈ at q̈ = 0) against the second derivative of g along q(t) = q₀ + q̇t + ½q̈t²
/// minus G q̈, the second derivative by the five-point stencil
/// (−g(2h) + 16g(h) − 30g(0) + 16g(−h) − g(−2h))/(12h²) with h = 1e-3 on the reference g: its
/// truncation h⁴/90·|g⁽⁶⁾| is about 1e-12 L, its round-off 64ε|g|/(12h²) about 1e-9 L. The rates
/// ġ, ṡ against the stencil (−g(2h) + 8g(h) − 8g(−h) + g(−2h))/(12h) (truncation h⁴/30·|g⁽⁵⁾|,
/// round-off 18ε|g|/(12h), both below 1e-12 L), and against G q̇. Tolerance 1e-7 relative to the
/// largest of the quantities compared and L.
#[test]
fn biases_match_differences_along_a_trajectory() {
    let h = 1e-3;
    let (mut worst_bias, mut worst_rate, mut worst_jac_rate): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for (name, model) in models() {
        let mut data = Data::new(&model);
        let mut contacts = ContactKinematics::new(&model);
        let faces = contact_faces(&model);
        let mut rng = SplitMix(0xB1A5 ^ model.dof() as u64);
        for state in 0..4 {
            let (mut q0, qdot, qddot, pivots) = random_state(&model, &mut rng);
            if state == 0 {
                q0.fill(0.0);
            }
            evaluate(&model, &mut data, &mut contacts, &q0, &qdot, &pivots);
            let mut along = |t: f64| {
                let q = &q0 + &qdot * t + &qddot * (0.5 * t * t);
                reference(&model, &faces, &mut data, &q, &pivots)
            };
            let (g2m, s2m) = along(-2.0 * h);
            let (g1m, s1m) = along(-h);
            let (g0, s0) = along(0.0);
            let (g1p, s1p) = along(h);
            let (g2p, s2p) = along(2.0 * h);
            let second = |a2m: &DVector<f64>,
                          a1m: &DVector<f64>,
                          a0: &DVector<f64>,
                          a1p: &DVector<f64>,
                          a2p: &DVector<f64>| {
                (-a2p + a1p * 16.0 - a0 * 30.0 + a1m * 16.0 - a2m) / (12.0 * h * h)
            };
            let first =
                |a2m: &DVector<f64>, a1m: &DVector<f64>, a1p: &DVector<f64>, a2p: &DVector<f64>| {
                    (-a2p + a1p * 8.0 - a1m * 8.0 + a2m) / (12.0 * h)
                };
            let g_dd = second(&g2m, &g1m, &g0, &g1p, &g2p);
            let s_dd = second(&s2m, &s1m, &s0, &s1p, &s2p);
            let g_bias_fd = &g_dd - &contacts.gap_jacobian * &qddot;
            let s_bias_fd = &s_dd - &contacts.slip_jacobian * &qddot;
            let scale = g_dd
                .amax()
                .max(s_dd.amax())
                .max(contacts.gap_bias.amax())
                .max(contacts.slip_bias.amax())
                .max(model.size);
            let err = (&g_bias_fd - &contacts.gap_bias)
                .amax()
                .max((&s_bias_fd - &contacts.slip_bias).amax())
                / scale;
            worst_bias = worst_bias.max(err);
            assert!(err < 1e-7, "{name}, state {state}: bias off by {err:e}");

            let g_d = first(&g2m, &g1m, &g1p, &g2p);
            let s_d = first(&s2m, &s1m, &s1p, &s2p);
            let scale = g_d.amax().max(s_d.amax()).max(model.size);
            let err = (&g_d - &contacts.gap_rate)
                .amax()
                .max((&s_d - &contacts.slip_rate).amax())
                / scale;
            worst_rate = worst_rate.max(err);
            assert!(err < 1e-7, "{name}, state {state}: rate off by {err:e}");
            let err = (&contacts.gap_jacobian * &qdot - &contacts.gap_rate)
                .amax()
                .max((&contacts.slip_jacobian * &qdot - &contacts.slip_rate).amax())
                / scale;
            worst_jac_rate = worst_jac_rate.max(err);
            assert!(err < 1e-12, "{name}, state {state}: G q̇ ≠ ġ by {err:e}");
        }
    }
    eprintln!(
        "biases: largest error {worst_bias:e}; rates: {worst_rate:e} (differences), \
         {worst_jac_rate:e} (against G q̇), relative"
    );
}

/// The convention of the faces: a tree interface's child turns relative to its parent about its
/// active pivot P (sides following the signs of q), so P's gap and slips stay 0 and every other
/// point opens. In the parent's rest frame the child's point X moves to P + R(X − P), so
/// g = n·(R − I)(X − P): for a hinge |sin φ|·|u × (P⁻ − P⁺)| at the idle pivot; for a rocking
/// base, X − P = a e₁ + b e₂ + c n and R = R(e₁, θ₁)R(e₂, θ₂),
/// g = −a sin θ₂ cos θ₁ + b sin θ₁ + c(cos θ₁ cos θ₂ − 1), positive at the corners off P when
/// both tilts are non-zero, and off the pivot edge when one is. Whatever the other coordinates,
/// the relative motion is the interface's own; checked to 1e-12 L.
#[test]
fn rocking_on_the_active_pivot_keeps_it_closed_and_opens_the_others() {
    let mut worst: f64 = 0.0;
    let mut opened = 0usize;
    let mut least_open = f64::INFINITY;
    for (name, model) in models() {
        let mut data = Data::new(&model);
        let mut contacts = ContactKinematics::new(&model);
        let mut rng = SplitMix(0x0CC0 ^ model.dof() as u64);
        for state in 0..6 {
            let (_, qdot, _, mut pivots) = random_state(&model, &mut rng);
            // |qₖ| in [0.05, 1.2] with a random sign; in half the states one tilt of each rocking
            // base is exactly 0 (its side then stays the drawn one).
            let mut q = DVector::from_fn(model.dof(), |_, _| {
                let a = rng.uniform(0.05, 1.2);
                if rng.below(2) == 0 { a } else { -a }
            });
            if state % 2 == 1 {
                for iface in &model.interfaces {
                    if let (InterfaceKind::RockingBase { .. }, Role::Tree { first_coord }) =
                        (&iface.kind, iface.role)
                    {
                        q[first_coord + rng.below(2)] = 0.0;
                    }
                }
            }
            pivots.follow_coordinates(&q);
            evaluate(&model, &mut data, &mut contacts, &q, &qdot, &pivots);
            for (i, iface) in model.interfaces.iter().enumerate() {
                let Role::Tree { first_coord } = iface.role else {
                    continue;
                };
                let face = &contacts.faces[i];
                let pivot = iface.kind.pivot(pivots.of_interface(&model, i));
                for (p, x) in contacts.point_range(i).zip(&face.points) {
                    let r = x - pivot;
                    let expected = match &iface.kind {
                        InterfaceKind::Hinge { axis, .. } => {
                            let phi = q[first_coord];
                            let rotated = rotation::axis_angle(axis, phi) * r;
                            // The idle pivot: |sin φ|·|u × (P⁻ − P⁺)| (0 at P itself).
                            let closed_form = phi.sin().abs() * axis.cross(&r).norm();
                            let g = face.normal.dot(&(rotated - r));
                            assert!((g - closed_form).abs() <= 1e-12 * model.size);
                            closed_form
                        }
                        InterfaceKind::RockingBase { normal, e1, e2, .. } => {
                            let (t1, t2) = (q[first_coord], q[first_coord + 1]);
                            let (a, b, c) = (e1.dot(&r), e2.dot(&r), normal.dot(&r));
                            -a * t2.sin() * t1.cos()
                                + b * t1.sin()
                                + c * (t1.cos() * t2.cos() - 1.0)
                        }
                    };
                    let err = (contacts.gap[p] - expected).abs();
                    worst = worst.max(err);
                    assert!(
                        err <= 1e-12 * model.size,
                        "{name}, interface {}: gap {} against {expected}",
                        iface.name,
                        contacts.gap[p]
                    );
                    // On the pivot (or on the axis through it) the point stays closed and does
                    // not slip; elsewhere it opens.
                    let on_axis = match &iface.kind {
                        InterfaceKind::Hinge { axis, .. } => {
                            axis.cross(&r).norm() <= 1e-9 * model.size
                        }
                        InterfaceKind::RockingBase { e1, e2, .. } => {
                            let (t1, t2) = (q[first_coord], q[first_coord + 1]);
                            r.norm() <= 1e-9 * model.size
                                || (t1 == 0.0 && e1.dot(&r).abs() <= 1e-9 * model.size)
                                || (t2 == 0.0 && e2.dot(&r).abs() <= 1e-9 * model.size)
                        }
                    };
                    if on_axis {
                        let slip = contacts.slip[2 * p]
                            .abs()
                            .max(contacts.slip[2 * p + 1].abs());
                        let g = contacts.gap[p].abs();
                        worst = worst.max(g).max(slip);
                        assert!(
                            g.max(slip) <= 1e-12 * model.size,
                            "{name}, interface {}: pivot moved by g {g:e}, s {slip:e}",
                            iface.name
                        );
                    } else {
                        assert!(
                            contacts.gap[p] > 0.0,
                            "{name}, interface {}: point {p} does not open (g = {})",
                            iface.name,
                            contacts.gap[p]
                        );
                        opened += 1;
                        least_open = least_open.min(contacts.gap[p] / model.size);
                    }
                }
            }
        }
    }
    assert!(opened > 100, "too few opening points checked: {opened}");
    eprintln!(
        "rocking: {opened} points opened (least g/L {least_open:e}); largest error \
         {worst:e} m"
    );
}
