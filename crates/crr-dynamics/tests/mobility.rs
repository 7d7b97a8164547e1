//! Mobility DOF(2) = DOF(1) − rank Φ_q of the reference structures, computed by the engine:
//! single block 1, trilithon 1, four-hinge arch 1, 2×2 colonnade on rocking bases 2 (with
//! redundant closure rows), a spatial four-hinge loop with non-parallel axes 0 (locked).

use crr_dynamics::mobility;
use crr_kinematics::fixtures::{
    colonnade, four_hinge_arch, single_block, skew_four_hinge_loop, trilithon,
};
use crr_kinematics::{ActivePivots, Model, Side, StructureSpec};
use nalgebra::DVector;

fn mobility_at_rest(spec: &StructureSpec) -> crr_dynamics::Mobility {
    let model = Model::from_spec(spec).unwrap();
    mobility(
        &model,
        &DVector::zeros(model.dof()),
        &ActivePivots::uniform(&model, Side::Positive),
    )
}

#[test]
fn single_block_has_one_dof() {
    let m = mobility_at_rest(&single_block(0.2, 1.0, 2500.0));
    assert_eq!((m.dof1, m.rank, m.dof2, m.locked), (1, 0, 1, false));
}

#[test]
fn trilithon_has_one_dof() {
    let m = mobility_at_rest(&trilithon(0.25, 1.5, 2.0, 0.5, 1.0));
    // Three tree coordinates; the planar hinge closure has rank 2 of its 5 rows.
    assert_eq!(
        (m.dof1, m.closures, m.constraint_rows, m.rank, m.dof2),
        (3, 1, 5, 2, 1)
    );
}

#[test]
fn four_hinge_arch_has_one_dof() {
    for two_sided in [false, true] {
        let m = mobility_at_rest(&four_hinge_arch(4.0, 4.6, 1.0, two_sided));
        assert_eq!(
            (m.dof1, m.rank, m.dof2),
            (3, 2, 1),
            "two_sided = {two_sided}"
        );
    }
}

#[test]
fn colonnade_has_two_dof_with_redundant_rows() {
    let m = mobility_at_rest(&colonnade(0.2, 1.5, 1.0, 0.3));
    assert_eq!(m.dof1, 10);
    assert_eq!(m.constraint_rows, 12);
    assert_eq!(m.dof2, 2, "{m:?}");
    assert_eq!(m.redundant, 12 - m.rank);
    assert!(m.redundant > 0);
}

#[test]
fn skew_four_hinge_loop_is_locked() {
    let m = mobility_at_rest(&skew_four_hinge_loop());
    assert_eq!((m.dof1, m.dof2, m.locked), (3, 0, true), "{m:?}");
}

/// DOF(3): a symmetry constraint between the two base tilts of a rocking base fixes the diagonal
/// direction (DOF(1) = 2 → DOF(3) = 1); on the colonnade, tying the two slab tilts leaves 1; an
/// unknown coordinate in a symmetry is an error naming it.
#[test]
fn symmetry_constraints_give_dof3() {
    use crr_kinematics::{SymmetryRelation, SymmetrySpec};
    let mut spec = colonnade(0.2, 1.5, 1.0, 0.3);
    spec.symmetry.push(SymmetrySpec {
        coordinates: ["base_1.1".into(), "base_1.2".into()],
        relation: SymmetryRelation::Opposite,
    });
    let m = mobility_at_rest(&spec);
    assert_eq!((m.dof2, m.symmetries, m.dof3), (2, 1, 1), "{m:?}");
    spec.symmetry[0].coordinates[1] = "base_9.2".into();
    let e = Model::from_spec(&spec).unwrap_err();
    assert!(
        e.item.contains("symmetry #1") && e.problem.contains("base_9.2"),
        "{e}"
    );
}

/// A symmetric motion integrated with the symmetry row as a constraint keeps φₐ = −φ_b exactly
/// (to the projection tolerance) while the structure moves.
#[test]
fn symmetry_constraint_holds_along_a_run() {
    use crr_dynamics::ground_motion::GroundMotion;
    use crr_dynamics::integrator::{Method, Options};
    use crr_dynamics::{Form, InitialSpec, integrate_smooth, solve_initial};
    use crr_kinematics::{SymmetryRelation, SymmetrySpec};
    let mut spec = crr_kinematics::fixtures::double_pendulum();
    spec.symmetry.push(SymmetrySpec {
        coordinates: ["shoulder".into(), "elbow".into()],
        relation: SymmetryRelation::Opposite,
    });
    let model = Model::from_spec(&spec).unwrap();
    let init = solve_initial(
        &model,
        &InitialSpec {
            angles: [("shoulder".to_string(), 0.5)].into(),
            ..Default::default()
        },
    )
    .unwrap();
    assert!(
        (init.q[1] + 0.5).abs() < 1e-12,
        "the elbow follows: {}",
        init.q[1]
    );
    let run = integrate_smooth(
        &model,
        &GroundMotion::none(),
        &init,
        2.0,
        0.1,
        Method::Dop853,
        Options::default(),
        Form::Constrained,
    )
    .unwrap();
    let travel = run.iter().map(|s| (s.q[0] - 0.5).abs()).fold(0.0, f64::max);
    assert!(travel > 0.1);
    for s in &run {
        assert!(
            (s.q[0] + s.q[1]).abs() < 1e-10,
            "t = {}: {:?}",
            s.t,
            s.q.as_slice()
        );
    }
}

/// Initial conditions on a closed chain: given values are kept and the rest solved so that Φ = 0
/// and Φ_q q̇ = 0; values that admit no closed state, or unknown names, are clear errors.
#[test]
fn initial_conditions_on_the_trilithon() {
    use crr_dynamics::{InitialSpec, solve_initial};
    let model = Model::from_spec(&trilithon(0.25, 1.5, 2.0, 0.5, 1.0)).unwrap();
    let spec = |angles: &[(&str, f64)], rates: &[(&str, f64)]| InitialSpec {
        angles: angles.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
        rates: rates.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
    };
    // One angle and one rate (DOF(2) = 1): the parallelogram, both columns equal, beam −θ.
    let s = solve_initial(
        &model,
        &spec(&[("base_left", 0.05)], &[("base_left", -0.3)]),
    )
    .unwrap();
    let (l, t, r) = (
        model.coord_index("base_left").unwrap(),
        model.coord_index("top_left").unwrap(),
        model.coord_index("base_right").unwrap(),
    );
    assert!(
        (s.q[r] - 0.05).abs() < 1e-12 && (s.q[t] + 0.05).abs() < 1e-12,
        "{:?}",
        s.q.as_slice()
    );
    assert!((s.qdot[r] + 0.3).abs() < 1e-12 && (s.qdot[t] - 0.3).abs() < 1e-12);
    assert_eq!(s.pivots.sides[l], crr_kinematics::Side::Positive);
    assert_eq!(s.pivots.sides[t], crr_kinematics::Side::Negative);
    // Two consistent angles are accepted.
    assert!(
        solve_initial(
            &model,
            &spec(&[("base_left", 0.05), ("base_right", 0.05)], &[])
        )
        .is_ok()
    );
    // Two inconsistent angles are not, and the message says the mobility.
    let e = solve_initial(
        &model,
        &spec(&[("base_left", 0.05), ("base_right", 0.1)], &[]),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("admit no configuration") && e.contains("DOF(2) = 1"),
        "{e}"
    );
    let e = solve_initial(
        &model,
        &spec(
            &[("base_left", 0.05)],
            &[("base_left", 1.0), ("base_right", 2.0)],
        ),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("rates") && e.contains("DOF(2) = 1"), "{e}");
    let e = solve_initial(&model, &spec(&[("base_lft", 0.05)], &[]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("base_lft") && e.contains("base_left"), "{e}");
    let e = solve_initial(&model, &spec(&[("base_left", f64::NAN)], &[]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a finite number"), "{e}");
}

/// The colonnade's loops close for finite tilts in both directions when the tops tilt in the
/// opposite order to the bases (the slab translates: Φ = 0 exactly at q = (φ₁, φ₂) on every base and
/// (−φ₂, φ₁) on the top, and DOF(2) stays 2). With the same order at both ends the slab would have
/// to twist: that configuration violates the closures, and after a finite step along the
/// first-order mechanism DOF(2) drops to 1, though it is 2 at rest.
#[test]
fn colonnade_stays_a_two_dof_mechanism_for_finite_tilts() {
    use crr_dynamics::closed_chain::follow_signs;
    use crr_dynamics::mobility_after_step;
    use crr_kinematics::fixtures::colonnade_with_top_order;
    use crr_kinematics::{Data, constraint_residual, forward_kinematics};
    let (p1, p2) = (0.05, -0.03);
    let mut q = DVector::zeros(10);
    for k in 0..4 {
        q[2 * k] = p1;
        q[2 * k + 1] = p2;
    }
    q[8] = -p2;
    q[9] = p1;
    for (swapped, dof_after) in [(true, 2), (false, 1)] {
        let model =
            Model::from_spec(&colonnade_with_top_order(0.2, 1.5, 1.0, 0.3, swapped)).unwrap();
        let mut kin = Data::new(&model);
        let mut pivots = ActivePivots::uniform(&model, Side::Positive);
        follow_signs(&model, &mut kin, &q, &mut pivots);
        forward_kinematics(&model, &mut kin, &q, &pivots);
        constraint_residual(&model, &mut kin, &pivots, &q);
        let residual = kin.phi.amax();
        if swapped {
            // Exact closure: round-off of 3 m lever arms.
            assert!(residual < 1e-14, "residual {residual:e}");
            assert_eq!(mobility(&model, &q, &pivots).dof2, 2);
        } else {
            // The twist the loop would need is second order: φ₁φ₂ times a lever arm.
            assert!(residual > 1e-4, "residual {residual:e}");
        }
        let finite = mobility_after_step(&model, 0.02).unwrap();
        assert!(finite.residual < 1e-12, "{finite:?}");
        assert!(finite.q.iter().any(|x| x.abs() > 0.01), "{finite:?}");
        assert_eq!(finite.dof2, dof_after, "swapped = {swapped}: {finite:?}");
    }
}

/// Initial conditions on the colonnade from one or two tilts: the other coordinates close the loops
/// with every pivot on the side of its angle (a column tilted about x alone leaves the y tilts at 0
/// and the slab's second tilt undoing the first; never a far branch beyond α = 0.13 rad).
#[test]
fn colonnade_initial_states_have_consistent_pivots() {
    use crr_dynamics::{InitialSpec, solve_initial};
    use crr_kinematics::{Data, closure_angles, forward_kinematics};
    let model = Model::from_spec(&colonnade(0.2, 1.5, 1.0, 0.3)).unwrap();
    let cases: [&[(&str, f64)]; 4] = [
        &[("base_1.1", 0.01)],
        &[("base_1.2", -0.05)],
        &[("base_1.1", 0.12), ("base_1.2", -0.05)],
        &[("base_1.1", -0.03), ("base_1.2", 0.02)],
    ];
    for angles in cases {
        let spec = InitialSpec {
            angles: angles.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            ..Default::default()
        };
        let init = solve_initial(&model, &spec).unwrap();
        let q = &init.q;
        // Pivots follow the signs of the solution's angles (tree and closure), except within the
        // Newton tolerance of 0 where either side is the same geometry.
        let mut kin = Data::new(&model);
        forward_kinematics(&model, &mut kin, q, &init.pivots);
        let mut slots: Vec<f64> = q.iter().copied().collect();
        slots.resize(model.slot_count, 0.0);
        closure_angles(&model, &kin, &mut slots[model.dof()..]);
        for (a, side) in slots.iter().zip(&init.pivots.sides) {
            assert!(
                a.abs() < 1e-8 || Side::of(*a, *side) == *side,
                "{angles:?}: angle {a} on side {side:?}"
            );
        }
        // A translating slab: every column as column 1, the slab's tilts undo it.
        for k in 1..4 {
            assert!((q[2 * k] - q[0]).abs() < 1e-9, "{angles:?}: {q}");
            assert!((q[2 * k + 1] - q[1]).abs() < 1e-9, "{angles:?}: {q}");
        }
        assert!(
            (q[8] + q[1]).abs() < 1e-9 && (q[9] - q[0]).abs() < 1e-9,
            "{angles:?}: {q}"
        );
        assert!(q.amax() <= 0.12 + 1e-12, "{angles:?}: {q}");
        if angles.len() == 1 && angles[0].0 == "base_1.1" {
            // The y tilt is the mechanism's second, free direction: Newton lands within 1e-8 of 0.
            assert!(q[1].abs() < 1e-7, "{angles:?}: {q}");
        }
    }
}

/// Every reference structure's mobility is the same at the model's precision: their loops are
/// exact (the fixtures above), so no singular value of Φ_q lies between 1e-9 and 1e-5 of the
/// largest.
#[test]
fn exact_structures_have_the_same_dof2_at_the_model_s_precision() {
    for spec in [
        single_block(0.2, 1.0, 2500.0),
        trilithon(0.25, 1.5, 2.0, 0.5, 1.0),
        four_hinge_arch(4.0, 4.6, 1.0, false),
        four_hinge_arch(4.0, 4.6, 1.0, true),
        colonnade(0.3, 2.0, 2.0, 0.4),
        skew_four_hinge_loop(),
    ] {
        let m = mobility_at_rest(&spec);
        assert_eq!(m.dof2_at_precision, m.dof2, "{}", spec.name);
    }
}
