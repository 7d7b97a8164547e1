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
    assert!(check(&model, &fixable, &[], None, 0.0, None, tol).is_some());
    assert_eq!(check(&model, &fixable, &[], Some(&d), 0.0, None, tol), None);
    let hopeless = forces([-1e4, 5e3, 1e4, 1e4]);
    let v = check(&model, &hopeless, &[], Some(&d), 0.0, None, tol).expect("tension");
    assert_eq!(
        (v.kind.as_str(), v.interface.as_str()),
        ("tension", model.interfaces[0].name.as_str())
    );
    assert_eq!(v.normal, -1e4);
    // A state that moves no force at all changes nothing.
    let none = DMatrix::zeros(monitored, 1);
    assert!(check(&model, &fixable, &[], Some(&none), 0.0, None, tol).is_some());
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

/// The normal forces on the two edges of a seated joint and the check that the contact's
/// resultant lies within its face, at (q, q̇) = 0 with every slot seated, under a constant ground
/// acceleration `a` (m/s²) on the pivots of `side`.
fn seated_edges(
    model: &Model,
    a: [f64; 3],
    side: Side,
) -> (crr_impact::monitor::ForceWork, Dynamics) {
    let ground = constant_ground(&[(Axis::X, a[0]), (Axis::Y, a[1]), (Axis::Z, a[2])]);
    let zero = DVector::zeros(model.dof());
    let all: Vec<usize> = (0..model.slot_count).collect();
    let pivots = ActivePivots::uniform(model, side);
    monitored(model, &ground, pivots, &all, (&zero, &zero))
}

/// The monitor's contact forces and seated edges at (q, q̇) on `pivots` with `seated` held, and
/// the dynamics that solved them.
fn monitored(
    model: &Model,
    ground: &GroundMotion,
    pivots: ActivePivots,
    seated: &[usize],
    (q, qdot): (&DVector<f64>, &DVector<f64>),
) -> (crr_impact::monitor::ForceWork, Dynamics) {
    let mut d = Dynamics::new(model, pivots);
    d.seated = seated.to_vec();
    let mut work = crr_impact::monitor::ForceWork::default();
    crr_impact::monitor::contact_forces_into(model, &mut d, ground, 0.0, q, qdot, &mut work)
        .unwrap();
    (work, d)
}

/// Housner's block (half-width b, half-height h) seated under a ground acceleration a_x: moment
/// balance about the base's centre, m a_x h = b (N⁻ − N⁺), and N⁺ + N⁻ = m g give the edge
/// forces N^± = (m g ∓ m a_x h/b)/2 (the ground pushing the block with it unloads the +x edge).
/// The monitor's split matches on both pivot sides to 1e-9 of the weight, and beyond
/// a_x = g b/h (the uplift threshold) the +x edge would pull: `check` reports the resultant
/// outside the face with that edge's (negative) force.
#[test]
fn seated_block_edges_against_moment_balance() {
    use crr_impact::monitor::check;
    let (b, h) = (0.2, 1.0);
    let model = Model::from_spec(&single_block(b, h, 2500.0)).unwrap();
    let (m, w) = (model.total_mass(), model.total_mass() * G);
    for kappa in [0.1, -0.15, 0.25, -0.3] {
        let ax = kappa * G;
        let plus = (m * G - m * ax * h / b) / 2.0;
        let minus = (m * G + m * ax * h / b) / 2.0;
        for side in [Side::Positive, Side::Negative] {
            let (work, _) = seated_edges(&model, [ax, 0.0, 0.0], side);
            let [e] = work.edges[..] else {
                panic!("one seated slot: {:?}", work.edges)
            };
            let (near, far) = match side {
                Side::Positive => (plus, minus),
                Side::Negative => (minus, plus),
            };
            assert!(
                (e.near - near).abs() < 1e-9 * w && (e.far - far).abs() < 1e-9 * w,
                "κ = {kappa}, {side:?}: {e:?} against near {near}, far {far}"
            );
            let v = check(&model, &work.forces, &work.edges, None, 0.0, None, 1e-3 * w);
            if kappa.abs() <= b / h {
                assert_eq!(v, None, "κ = {kappa}");
            } else {
                let v = v.expect("beyond the uplift threshold");
                assert_eq!(
                    (v.kind.as_str(), v.interface.as_str()),
                    ("outside_face", "base")
                );
                assert!((v.normal - plus.min(minus)).abs() < 1e-9 * w, "{v:?}");
            }
        }
    }
}

/// A block of 2a × 2c × 2h on a rocking base under a_x and a_y together: by the moment balances
/// about the base's centre lines, the edges at x = ±a carry (m g ∓ m a_x h/a)/2 and those at
/// y = ±c carry (m g ∓ m a_y h/c)/2. The first tilt (about e₁ = x) splits N between the edges
/// at y = ±c, the second (about e₂ = y) between x = ±a; "near" is the edge through the pivot
/// corner. Checked on all four pivot corners to 1e-9 of the weight.
#[test]
fn rocking_base_edges_against_moment_balance() {
    let (a, c, h) = (0.3, 0.2, 0.8);
    let spec = crr_kinematics::spec::StructureSpec {
        name: "block_on_base".into(),
        gravity: G,
        body: vec![box_body(
            "block",
            2500.0,
            [0.0, 0.0, h],
            [2.0 * a, 2.0 * c, 2.0 * h],
        )],
        interface: vec![crr_kinematics::fixtures::rocking_base(
            "base",
            "ground",
            "block",
            [[-a, -c, 0.0], [a, -c, 0.0], [a, c, 0.0], [-a, c, 0.0]],
        )],
        symmetry: Vec::new(),
    };
    let model = Model::from_spec(&spec).unwrap();
    let (m, w) = (model.total_mass(), model.total_mass() * G);
    let (ax, ay) = (0.12 * G, -0.07 * G);
    let edge_x = |x: f64| (m * G - x.signum() * m * ax * h / a) / 2.0;
    let edge_y = |y: f64| (m * G - y.signum() * m * ay * h / c) / 2.0;
    for sides in [
        [Side::Positive, Side::Positive],
        [Side::Positive, Side::Negative],
        [Side::Negative, Side::Positive],
        [Side::Negative, Side::Negative],
    ] {
        let ground = constant_ground(&[(Axis::X, ax), (Axis::Y, ay)]);
        let mut pivots = ActivePivots::uniform(&model, Side::Positive);
        pivots.sides.copy_from_slice(&sides);
        let zero = DVector::zeros(2);
        let (work, _) = monitored(&model, &ground, pivots, &[0, 1], (&zero, &zero));
        let corner = model.interfaces[0].kind.pivot(&sides);
        let [tilt1, tilt2] = work.edges[..] else {
            panic!("two seated tilts: {:?}", work.edges)
        };
        let expect = [
            (edge_y(corner.y), edge_y(-corner.y)),
            (edge_x(corner.x), edge_x(-corner.x)),
        ];
        for (e, (near, far)) in [tilt1, tilt2].iter().zip(expect) {
            assert!(
                (e.near - near).abs() < 1e-9 * w && (e.far - far).abs() < 1e-9 * w,
                "{sides:?}: {e:?} against near {near}, far {far}"
            );
        }
    }
}

/// In motion the seat reaction r of a seated joint is the moment about its pivot line of the
/// wrench its parent transmits, which the articulated-body algorithm gives independently
/// (`Dynamics::joint_force`: [n₀; f] about the world origin). On a stack of two blocks on
/// rocking bases, the lower one tilted about both axes and turning, the upper seated, the split
/// of every seated tilt's normal force must equal the one from that wrench: far = (n₀ − P × f)·w
/// / ((w × (P′ − P))·n) and near = f·n − far, to 1e-9 of the weight.
#[test]
fn seated_edges_in_motion_against_articulated_wrench() {
    use crr_kinematics::kinematics::frame_point;
    let (a, c) = (0.3, 0.2);
    let face = |z: f64| [[-a, -c, z], [a, -c, z], [a, c, z], [-a, c, z]];
    let spec = crr_kinematics::spec::StructureSpec {
        name: "stack".into(),
        gravity: G,
        body: vec![
            box_body("lower", 2500.0, [0.0, 0.0, 0.6], [2.0 * a, 2.0 * c, 1.2]),
            box_body("upper", 2500.0, [0.0, 0.0, 1.6], [2.0 * a, 2.0 * c, 0.8]),
        ],
        interface: vec![
            crr_kinematics::fixtures::rocking_base("base", "ground", "lower", face(0.0)),
            crr_kinematics::fixtures::rocking_base("bed", "lower", "upper", face(1.2)),
        ],
        symmetry: Vec::new(),
    };
    let model = Model::from_spec(&spec).unwrap();
    let w_total = model.total_mass() * G;
    let ground = constant_ground(&[(Axis::X, 0.3 * G), (Axis::Y, -0.2 * G)]);
    let mut pivots = ActivePivots::uniform(&model, Side::Positive);
    pivots.sides[1] = Side::Negative;
    pivots.sides[3] = Side::Negative;
    let q = DVector::from_column_slice(&[0.04, -0.03, 0.0, 0.0]);
    let qdot = DVector::from_column_slice(&[0.5, -0.8, 0.0, 0.0]);
    let (work, d) = monitored(&model, &ground, pivots.clone(), &[2, 3], (&q, &qdot));
    assert!(d.used_articulated_body());
    assert_eq!(work.edges.len(), 2);
    let iface = &model.interfaces[1];
    let crr_kinematics::InterfaceKind::RockingBase { normal, .. } = iface.kind else {
        unreachable!()
    };
    let n = d.kin.rot_ops[1] * normal;
    for e in &work.edges {
        let k = e.slot;
        let wrench = d.joint_force(k).expect("articulated");
        let (n0, f) = (wrench.fixed_rows::<3>(0), wrench.fixed_rows::<3>(3));
        let (w, p) = (d.kin.axis[k], d.kin.pivot[k]);
        let mut sides = pivots.sides[2..4].to_vec();
        sides[k - 2] = sides[k - 2].flipped();
        let p_other = frame_point(&d.kin, model.coords[k].parent, &iface.kind.pivot(&sides));
        let moment = (n0 - p.cross(&f)).dot(&w);
        let far = moment / w.cross(&(p_other - p)).dot(&n);
        let near = f.dot(&n) - far;
        assert!(
            (e.far - far).abs() < 1e-9 * w_total && (e.near - near).abs() < 1e-9 * w_total,
            "slot {k}: {e:?} against near {near}, far {far}"
        );
    }
}

/// The hyperstatic check against the static theorem. A structure at rest with every joint
/// seated under a constant ground acceleration κ g d holds if and only if some equilibrium with
/// compressive contacts exists (the contacts' resultants within their faces), which is what the
/// collapse multiplier λ_c of `crr_impact::statics` (a linear program over the corner forces,
/// independent of the monitor's self-stress family) decides. So the monitor, given the
/// least-norm forces, their self-stress states and the edges, must report nothing at κ = 0.98 λ_c
/// and a violation at 1.02 λ_c, along ±x; on the planar trilithon (hinges, one loop) and on a
/// 3D portal (rocking bases, a twisting loop-closing seat). At rest the least-norm forces alone
/// show an edge in tension on the portal, which the self-stress states resolve. The check the
/// simulation runs, the most compressive distribution on the faces (`check_distribution`, body
/// equilibria, not the self-stress states), must decide the same.
#[test]
fn hyperstatic_edges_against_the_static_theorem() {
    use crr_impact::monitor::{check, check_distribution, self_stress_normals};
    use crr_impact::statics::{StaticsOptions, collapse_multiplier};
    use nalgebra::Vector3;
    let (a, c) = (0.2, 0.2);
    let face = |x: f64, z: f64| [[x - a, -c, z], [x + a, -c, z], [x + a, c, z], [x - a, c, z]];
    let mut on_b = crr_kinematics::fixtures::rocking_base("on_b", "b", "lintel", face(2.0, 2.0));
    if let Some(base) = on_b.rocking_base.as_mut() {
        base.twist = true;
    }
    let portal = crr_kinematics::spec::StructureSpec {
        name: "portal".into(),
        gravity: G,
        body: vec![
            box_body("a", 2500.0, [0.0, 0.0, 1.0], [2.0 * a, 2.0 * c, 2.0]),
            box_body("b", 2500.0, [2.0, 0.0, 1.0], [2.0 * a, 2.0 * c, 2.0]),
            box_body("lintel", 2500.0, [1.0, 0.0, 2.25], [2.4, 2.0 * c, 0.5]),
        ],
        interface: vec![
            crr_kinematics::fixtures::rocking_base("base_a", "ground", "a", face(0.0, 0.0)),
            crr_kinematics::fixtures::rocking_base("base_b", "ground", "b", face(2.0, 0.0)),
            crr_kinematics::fixtures::rocking_base("on_a", "a", "lintel", face(0.0, 2.0)),
            on_b,
        ],
        symmetry: Vec::new(),
    };
    let trilithon = crr_kinematics::fixtures::trilithon(0.25, 1.5, 2.0, 0.5, 1.0);
    for (spec, least_norm_tension) in [(portal, true), (trilithon, false)] {
        let model = Model::from_spec(&spec).unwrap();
        let w = model.total_mass() * G;
        let tol = 1e-3 * w;
        let (work, d) = seated_edges(&model, [0.0; 3], Side::Positive);
        let states = self_stress_normals(&model, &d, &work.edges).expect("hyperstatic");
        if least_norm_tension {
            assert!(work.edges.iter().any(|e| e.near.min(e.far) < -tol));
        }
        assert_eq!(
            check(
                &model,
                &work.forces,
                &work.edges,
                Some(&states),
                0.0,
                None,
                tol
            ),
            None,
            "{} at rest",
            model.name
        );
        assert_eq!(
            check_distribution(&model, &d, &work, 0.0, None, tol),
            None,
            "{} at rest, on the faces",
            model.name
        );
        for sign in [1.0, -1.0] {
            let dir = Vector3::new(sign, 0.0, 0.0);
            let lambda = collapse_multiplier(&model, dir, &StaticsOptions::default())
                .unwrap()
                .lambda
                .expect("collapses");
            for (factor, fails) in [(0.98, false), (1.02, true)] {
                let ax = sign * factor * lambda * G;
                let (work, d) = seated_edges(&model, [ax, 0.0, 0.0], Side::Positive);
                let states = self_stress_normals(&model, &d, &work.edges);
                let v = check(
                    &model,
                    &work.forces,
                    &work.edges,
                    states.as_ref(),
                    0.0,
                    None,
                    tol,
                );
                assert_eq!(
                    v.is_some(),
                    fails,
                    "{}: {factor} λ_c = {lambda} along {sign:+}x: {v:?}",
                    model.name
                );
                let v = check_distribution(&model, &d, &work, 0.0, None, tol);
                assert_eq!(
                    v.is_some(),
                    fails,
                    "{} on the faces: {factor} λ_c = {lambda} along {sign:+}x: {v:?}",
                    model.name
                );
            }
        }
    }
}
