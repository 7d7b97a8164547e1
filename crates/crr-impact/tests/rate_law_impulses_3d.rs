//! The rate-law impulse check on a rocking base whose other tilt keeps rocking through the impact
//! (docs/simulation.md, "Impulses at landings and impacts"): the impacting slot touches on its
//! two pivots only, the edge the other tilt rocks on, not on the whole base.
//!
//! A 3D stack: a lower block 1.2 × 1.2 × 1.5 m seated on a rocking base on the ground, an upper
//! block 0.4 × 0.4 × 1.6 m on a rocking base on it, released from tilts (ψ₁, ψ₂) = (0.02, 0.05)
//! rad. It rocks on a corner; at its first impact ψ₁ reaches 0 while ψ₂ does not. The lower block
//! is held seated, so it does not move, and the ground's impulse on the stack is the upper
//! block's change of momentum, worked out here from the sampled rates before and after the
//! impact, independently of crr's kinematics:
//!
//! * the upper block turns about its pivot corner P with ω = ψ̇₁ e₁ + ψ̇₂ e₂ (ψ₁ = 0, so the
//!   second axis is not turned by the first), its pose R = Rot(e₂, ψ₂) about P (nalgebra's
//!   axis-angle), the pivot the corner that a small rotation (σ₁ε) e₁ + ψ₂ e₂ lowers most (σ₁ the
//!   side before or after);
//! * Δp = m (v⁺ − v⁻) with v = ω × (c − P), and the change of angular momentum about the ground
//!   point O below the lower block's centre, ΔH = (c − O) × Δp + R I_c Rᵀ (ω⁺ − ω⁻);
//! * the ground acts on the lower block by normal impulses Nᵢ at its corners (±b, ±b, 0), b = 0.6 m, and
//!   tangential ones in the plane z = 0 (no moment about a horizontal axis through O): ΣNᵢ = Δp_z,
//!   ΣNᵢ yᵢ = ΔH_x, −ΣNᵢ xᵢ = ΔH_y. Three equations for four unknowns: Nᵢ = N⁰ᵢ + t sᵢ with
//!   N⁰ᵢ = Δp_z/4 − ΔH_y xᵢ/(4b²) + ΔH_x yᵢ/(4b²) and the self-stress s = (1, −1, 1, −1) around
//!   the rectangle. The most compressive distribution maximises min Nᵢ over t: the two corners
//!   of each diagonal move together, so its least impulse is
//!   s* = (min of one diagonal's N⁰ + min of the other's) / 2.
//!
//! The rates come from the run's two samples at the impact; the kinetic energies they give here
//! equal the samples' (measured 1e-14 relative, asserted 1e-12), and the law leaves the angular
//! momentum about the edge line unchanged (1e-13 N m s against |ΔH| of order 100), as it must: the edge's impulses have no moment about it.
//!
//! The engine measures a contact's impulse per edge (`face_forces::touching_points_per_edge`):
//! a corner's times the two corners of the base's edge, 2 s*, what a planar hinge's pivot line
//! would carry. Where 2 s* is below −1e-3 W·√(L/g) the run records an `impulse_tension` at the
//! impact's instant on `base` with 2 s* as its `normal` (to 1e-8 of W·√(L/g), as in
//! `rate_law_impulses.rs`); where s* pushes, nothing is recorded. The lower block is light (240 kg/m³): being held, its mass
//! enters no impulse, only the tolerance's unit W·√(L/g) (about 5 400 N s). The laws chosen give
//! both answers: r = 0.3, 0.6 and the Dirac law with r^C = 0.35 pull by 95, 47 and 86 N s at a
//! corner (189, 94 and 172 N s per edge); r = 1 pushes with 4.5 N s. This does not tell the edge from the whole base apart (the upper block's
//! change of momentum alone sets the ground's impulse here); it checks the rate laws' impulses on
//! a 3D rocking base against a derivation of its own.
use std::collections::BTreeMap;

use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::{InitialSpec, solve_initial};
use crr_impact::{Parameters, Simulation};
use crr_kinematics::Model;
use crr_kinematics::fixtures::{box_body, rocking_base};
use crr_kinematics::spec::{ImpactLaw, StructureSpec};
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

const RHO: f64 = 2400.0;
/// The lower block's half-width b (m).
const B: f64 = 0.6;
/// The upper block's size (m) and rest centre.
const UPPER: [f64; 3] = [0.4, 0.4, 1.6];
const UPPER_CENTRE: [f64; 3] = [0.0, 0.0, 2.3];

fn square(half: f64, z: f64) -> [[f64; 3]; 4] {
    [
        [-half, -half, z],
        [half, -half, z],
        [half, half, z],
        [-half, half, z],
    ]
}

fn stack(law: ImpactLaw) -> Model {
    let mut joint = rocking_base("joint", "lower", "upper", square(0.2, 1.5));
    joint.impact = law;
    let spec = StructureSpec {
        name: "stack_3d".into(),
        gravity: 9.81,
        body: vec![
            box_body(
                "lower",
                RHO / 10.0,
                [0.0, 0.0, 0.75],
                [2.0 * B, 2.0 * B, 1.5],
            ),
            box_body("upper", RHO, UPPER_CENTRE, UPPER),
        ],
        interface: vec![
            rocking_base("base", "ground", "lower", square(B, 0.0)),
            joint,
        ],
        symmetry: Vec::new(),
    };
    Model::from_spec(&spec).unwrap()
}

/// The corner of the upper block's base that the small rotation σ₁ε e₁ + ψ₂ e₂ lowers most.
fn pivot(e1: Vector3<f64>, e2: Vector3<f64>, sigma1: f64, psi2: f64) -> Vector3<f64> {
    let theta = 1e-6 * sigma1 * e1 + psi2 * e2;
    let centre = Vector3::new(0.0, 0.0, 1.5);
    square(0.2, 1.5)
        .iter()
        .map(|c| Vector3::from(*c))
        .min_by(|a, b| {
            let drop = |c: &Vector3<f64>| theta.cross(&(c - centre)).z;
            drop(a).total_cmp(&drop(b))
        })
        .unwrap()
}

/// What the hand derivation gives at the impact.
struct ByHand {
    /// The ground's least normal impulse s* on the lower block (N s).
    least: f64,
    /// The upper block's kinetic energy before and after (J).
    kinetic: [f64; 2],
    /// The change of its angular momentum about the edge line through the pivots (N m s).
    about_edge: f64,
    /// |ΔH| about O, the scale of `about_edge` (N m s).
    scale: f64,
}

/// The derivation above for the upper block's rates (ψ̇₁, ψ̇₂) going from `before` to `after`
/// at ψ₁ = 0, ψ₂ = `psi2`.
fn by_hand(psi2: f64, before: [f64; 2], after: [f64; 2]) -> ByHand {
    let (e1, e2) = (Vector3::x(), Vector3::y());
    let mass = RHO * UPPER[0] * UPPER[1] * UPPER[2];
    let inertia = Matrix3::from_diagonal(&Vector3::new(
        mass * (UPPER[1].powi(2) + UPPER[2].powi(2)) / 12.0,
        mass * (UPPER[0].powi(2) + UPPER[2].powi(2)) / 12.0,
        mass * (UPPER[0].powi(2) + UPPER[1].powi(2)) / 12.0,
    ));
    let rotation = Rotation3::from_axis_angle(&Unit::new_normalize(e2), psi2);
    let world_inertia = rotation.matrix() * inertia * rotation.matrix().transpose();
    let omega = |rates: [f64; 2]| rates[0] * e1 + rates[1] * e2;
    // ψ₁ reaches 0 from the side opposite to its rate's sign, and leaves it on the other.
    let side_before = -before[0].signum();
    let (p_before, p_after) = (
        pivot(e1, e2, side_before, psi2),
        pivot(e1, e2, -side_before, psi2),
    );
    // The two pivots lie on one line along e₂, the axis of the pose's rotation: the same centre.
    let c_rest = Vector3::from(UPPER_CENTRE);
    let c = p_before + rotation * (c_rest - p_before);
    assert!((c - (p_after + rotation * (c_rest - p_after))).norm() < 1e-12);
    let v_before = omega(before).cross(&(c - p_before));
    let v_after = omega(after).cross(&(c - p_after));
    let dp = mass * (v_after - v_before);
    let dh = c.cross(&dp) + world_inertia * (omega(after) - omega(before));
    let edge = (p_after - p_before).normalize();
    let about_edge =
        ((c - p_before).cross(&dp) + world_inertia * (omega(after) - omega(before))).dot(&edge);
    let kinetic = |v: Vector3<f64>, w: Vector3<f64>| {
        0.5 * mass * v.norm_squared() + 0.5 * w.dot(&(world_inertia * w))
    };
    let corners = [(B, B), (-B, B), (-B, -B), (B, -B)];
    let n0: Vec<f64> = corners
        .iter()
        .map(|&(x, y)| dp.z / 4.0 + (dh.x * y - dh.y * x) / (4.0 * B * B))
        .collect();
    // The particular solution carries the three equations.
    let sum = |f: &dyn Fn(usize) -> f64| (0..4).map(f).sum::<f64>();
    let scale = dp.norm() + dh.norm();
    assert!((sum(&|i| n0[i]) - dp.z).abs() < 1e-9 * scale);
    assert!((sum(&|i| n0[i] * corners[i].1) - dh.x).abs() < 1e-9 * scale);
    assert!((sum(&|i| -n0[i] * corners[i].0) - dh.y).abs() < 1e-9 * scale);
    ByHand {
        least: (n0[0].min(n0[2]) + n0[1].min(n0[3])) / 2.0,
        kinetic: [
            kinetic(v_before, omega(before)),
            kinetic(v_after, omega(after)),
        ],
        about_edge,
        scale: dh.norm(),
    }
}

#[test]
fn a_rate_law_impact_on_a_base_rocking_on_its_other_tilt_is_checked_at_the_held_seat() {
    let laws = [
        ImpactLaw::Restitution(0.3),
        ImpactLaw::Restitution(0.6),
        ImpactLaw::Restitution(1.0),
        ImpactLaw::Dirac { r: 0.5, c: 1.5 },
    ];
    let (mut pulls, mut pushes) = (0, 0);
    for law in laws {
        let model = stack(law);
        let unit = model.total_mass() * model.gravity * (model.size / model.gravity).sqrt();
        let initial = solve_initial(
            &model,
            &InitialSpec {
                angles: BTreeMap::from([
                    ("joint.1".to_string(), 0.02),
                    ("joint.2".to_string(), 0.05),
                ]),
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
        let (tilt1, tilt2) = (2, 3);
        assert_eq!(first.interfaces, vec!["joint".to_string()], "{law:?}");
        assert_eq!(first.slots, vec![tilt1], "{law:?}: the first tilt impacts");
        // The samples before and after the impact (the two rows at its instant).
        let at: Vec<_> = run.samples.iter().filter(|s| s.t == first.t).collect();
        assert_eq!(at.len(), 2, "{law:?}");
        let (before, after) = (&at[0], &at[1]);
        // ψ₁ is 0 to the impact's location (a few 1e-12 rad): the terms it leaves out of ω
        // and of the pose are of that order relative to those kept.
        assert!(
            before.q[tilt1].abs() < 1e-9,
            "{law:?}: ψ₁ = {}",
            before.q[tilt1]
        );
        let psi2 = before.q[tilt2];
        assert!(psi2.abs() > 1e-3, "{law:?}: the other tilt rocks: {psi2}");
        assert_eq!(
            before.q[..2],
            [0.0, 0.0],
            "{law:?}: the lower block is seated"
        );
        assert_eq!(before.qdot[..2], [0.0, 0.0], "{law:?}");
        assert_eq!(after.qdot[..2], [0.0, 0.0], "{law:?}");
        let hand = by_hand(
            psi2,
            [before.qdot[tilt1], before.qdot[tilt2]],
            [after.qdot[tilt1], after.qdot[tilt2]],
        );
        // The kinematics here is crr's: the same kinetic energies (the lower block is still).
        for (mine, sample) in hand.kinetic.iter().zip([before.kinetic, after.kinetic]) {
            assert!(
                (mine - sample).abs() <= 1e-12 * sample,
                "{law:?}: T {mine} against {sample}"
            );
        }
        // The law keeps the momentum of the motion that leaves ψ̇₁ alone: the turn about the edge.
        assert!(
            hand.about_edge.abs() <= 1e-12 * hand.scale,
            "{law:?}: ΔH about the edge {}",
            hand.about_edge
        );
        // Per edge: the two corners of the seated base's edge each carrying s*.
        let least = 2.0 * hand.least;
        println!("{law:?}: ψ₂ = {psi2:.5} rad, least ground impulse {least:.3} N s");
        // Each verdict at least three tolerances (1e-3 W·√(L/g)) from the threshold, or a push.
        assert!(
            least > 0.0 || least < -3e-3 * unit,
            "{law:?}: least impulse {least} N s too near the tolerance ({unit} N s units)"
        );
        let recorded = run.violation.as_ref().filter(|v| v.t <= first.t + 1e-12);
        if least < -1e-3 * unit {
            pulls += 1;
            let v =
                recorded.unwrap_or_else(|| panic!("{law:?}: s* = {least} N s, nothing recorded"));
            assert_eq!(
                (v.kind.as_str(), v.interface.as_str()),
                ("impulse_tension", "base"),
                "{law:?}"
            );
            assert!((v.t - first.t).abs() <= 1e-12, "{law:?}");
            assert!(
                (v.normal - least).abs() <= 1e-8 * unit,
                "{law:?}: recorded {} N s against {least} N s by hand",
                v.normal
            );
        } else {
            pushes += 1;
            assert!(
                recorded.is_none(),
                "{law:?}: s* = {least} N s, yet {recorded:?}"
            );
        }
    }
    assert!(pulls >= 1 && pushes >= 1, "pulls {pulls}, pushes {pushes}");
}
