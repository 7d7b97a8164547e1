//! The impulse of a restitution or Dirac impact checked at the contacts it holds besides the
//! impacting face (docs/simulation.md, The hypotheses monitor, "Impulses at landings and
//! impacts"). These laws set the impacting joint's rate; the impulse that takes on the impacting
//! face is the law's own hypothesis and is not checked, but the seated joints held through the
//! impact must give their share of it by pushing.
//!
//! A stack of two blocks (planar, rocking about y): a lower block 0.6 × 0.6 × 1.5 m seated on the
//! ground, an upper block 0.4 × 0.4 × 1.6 m on it, released from a tilt of 0.05 rad on its +x
//! pivot. At its first impact the lower block is held seated, so it does not move, and the upper
//! block turns about its pivots with ω = ψ̇ ŷ (ψ the joint's angle). The ground's impulse on the
//! stack is then the upper block's change of momentum, worked out by hand from its velocities
//! about its pivots, v = ω × (c − P):
//!
//! * Δp = m (v⁺ − v⁻), and the change of the stack's angular momentum about a ground corner A,
//!   H_A = [(c − A) × Δp]_y + I_y (ω⁺ − ω⁻);
//! * the ground acts on the lower block by normal impulses N_L, N_R at its corners x = ∓0.3 and a
//!   tangential one at z = 0 (no moment about either corner), so N_L = H_R / 0.6 and
//!   N_R = −H_L / 0.6, one answer (two unknowns, two moments).
//!
//! Where min(N_L, N_R) is below −1e-3 W·√(L/g) (the monitor's impulse tolerance), the run records
//! an `impulse_tension` at the impact's instant on `base` with that impulse as its `normal` (to
//! 1e-8 of the unit W·√(L/g) = 9 113 N s, i.e. 9.1e-5 N s: the distribution is unique, so the program's proximal term moves
//! nothing and what is left is its interior point's accuracy; measured 3e-10 of the unit); where
//! both push, the impact records nothing. The laws chosen give both answers (r = 0.3, 0.6 and
//! the Dirac law with r^C = 0.35 pull at the right corner by 618, 330 and 567 N s; r = 1 pushes
//! with 54 N s at each), each far from the tolerance (checked below).
use std::collections::BTreeMap;

use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::{InitialSpec, solve_initial};
use crr_impact::{Parameters, Simulation};
use crr_kinematics::Model;
use crr_kinematics::fixtures::{box_body, hinge};
use crr_kinematics::spec::{ImpactLaw, StructureSpec};
use nalgebra::Vector3;

const RHO: f64 = 2400.0;

fn stack(law: ImpactLaw) -> Model {
    let mut joint = hinge(
        "joint",
        "lower",
        "upper",
        [0.0, 1.0, 0.0],
        [0.2, 0.0, 1.5],
        [-0.2, 0.0, 1.5],
    );
    joint.impact = law;
    let spec = StructureSpec {
        name: "stack".into(),
        gravity: 9.81,
        body: vec![
            box_body("lower", RHO, [0.0, 0.0, 0.75], [0.6, 0.6, 1.5]),
            box_body("upper", RHO, [0.0, 0.0, 2.3], [0.4, 0.4, 1.6]),
        ],
        interface: vec![
            hinge(
                "base",
                "ground",
                "lower",
                [0.0, 1.0, 0.0],
                [0.3, 0.0, 0.0],
                [-0.3, 0.0, 0.0],
            ),
            joint,
        ],
        symmetry: Vec::new(),
    };
    Model::from_spec(&spec).unwrap()
}

/// The ground's normal impulses (N_L, N_R) on the lower block when the upper block's rate goes
/// from `before` about its +x pivot to `after` about its −x pivot, the lower block at rest.
fn ground_impulses(before: f64, after: f64) -> (f64, f64) {
    let mass = RHO * 0.4 * 0.4 * 1.6;
    let inertia = mass * (0.4f64.powi(2) + 1.6f64.powi(2)) / 12.0;
    let c = Vector3::new(0.0, 0.0, 2.3);
    let y = Vector3::y();
    let v_before = (before * y).cross(&(c - Vector3::new(0.2, 0.0, 1.5)));
    let v_after = (after * y).cross(&(c - Vector3::new(-0.2, 0.0, 1.5)));
    let dp = mass * (v_after - v_before);
    let about = |a: Vector3<f64>| (c - a).cross(&dp).y + inertia * (after - before);
    let h_right = about(Vector3::new(0.3, 0.0, 0.0));
    let h_left = about(Vector3::new(-0.3, 0.0, 0.0));
    (h_right / 0.6, -h_left / 0.6)
}

#[test]
fn a_rate_law_impact_pulling_at_a_held_seat_is_recorded_and_one_pushing_is_not() {
    let laws = [
        (ImpactLaw::Restitution(0.3), 0.3),
        (ImpactLaw::Restitution(0.6), 0.6),
        (ImpactLaw::Restitution(1.0), 1.0),
        (ImpactLaw::Dirac { r: 0.5, c: 1.5 }, 0.5f64.powf(1.5)),
    ];
    let (mut pulls, mut pushes) = (0, 0);
    for (law, factor) in laws {
        let model = stack(law);
        let unit = model.total_mass() * model.gravity * (model.size / model.gravity).sqrt();
        let initial = solve_initial(
            &model,
            &InitialSpec {
                angles: BTreeMap::from([("joint".to_string(), 0.05)]),
                ..Default::default()
            },
        )
        .unwrap();
        let ground = GroundMotion::none();
        let params = Parameters {
            duration: 0.6,
            ..Default::default()
        };
        let run = Simulation::new(&model, &ground, &initial, params)
            .unwrap()
            .run()
            .map_err(|f| f.error)
            .unwrap();
        let first = run.impacts.first().expect("the upper block impacts");
        assert_eq!(first.interfaces, vec!["joint".to_string()], "{law:?}");
        let before = first.rates_before[0];
        assert!(before < 0.0, "{law:?}: it falls back from +x: {before}");
        let (left, right) = ground_impulses(before, factor * before);
        let least = left.min(right);
        // Each verdict far from the tolerance, so that it does not rest on its exact value.
        assert!(
            (least / unit).abs() > 1e-2 || least > 0.0,
            "{law:?}: least impulse {least} N s too near the tolerance"
        );
        let recorded = run.violation.as_ref().filter(|v| v.t <= first.t + 1e-12);
        if least < -1e-3 * unit {
            pulls += 1;
            let v = recorded.unwrap_or_else(|| {
                panic!("{law:?}: N = ({left}, {right}) N s, nothing recorded at the impact")
            });
            assert_eq!(
                (v.kind.as_str(), v.interface.as_str()),
                ("impulse_tension", "base"),
                "{law:?}"
            );
            assert!(
                (v.t - first.t).abs() <= 1e-12,
                "{law:?}: at {} not {}",
                v.t,
                first.t
            );
            assert!(
                (v.normal - least).abs() <= 1e-8 * unit,
                "{law:?}: recorded {} N s against {least} N s by hand",
                v.normal
            );
        } else {
            pushes += 1;
            assert!(
                recorded.is_none(),
                "{law:?}: N = ({left}, {right}) N s push, yet {recorded:?}"
            );
        }
    }
    assert!(pulls >= 1 && pushes >= 1, "pulls {pulls}, pushes {pushes}");
}
