//! Seated coordinates held by elimination (q̈ₖ = 0: the free block of M solved alone, or locked
//! joints of the articulated-body algorithm), both paths checked
//! against Newton–Euler on the bodies: the accelerations of the bodies come from central
//! differences of the forward kinematics along q(t) = q + q̇t + ½q̈t², never from M, h or Q.

use nalgebra::{DVector, Vector3};

use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::{Dynamics, ForwardSolver};
use crr_kinematics::fixtures::{box_body, hinge, serial_chain};
use crr_kinematics::mass_matrix::world_inertia;
use crr_kinematics::{ActivePivots, Data, Model, Side, StructureSpec, forward_kinematics};

/// Centres and angular momenta about the centres of the bodies at q(t), q̇(t).
fn bodies_at(
    model: &Model,
    data: &mut Data,
    pivots: &ActivePivots,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    forward_kinematics(model, data, q, pivots);
    model
        .bodies
        .iter()
        .enumerate()
        .map(|(b, body)| {
            let k = model.body_coord[b];
            // ω = Σ over the path of the axes times their rates.
            let mut omega = Vector3::zeros();
            let mut j = Some(k);
            while let Some(jj) = j {
                omega += data.axis[jj] * qdot[jj];
                j = model.coords[jj].parent;
            }
            let inertia = world_inertia(body, &data.rot_ops[k]);
            (data.com[b], inertia * omega)
        })
        .collect()
}

/// For each coordinate k, w_k · Σ over its subtree of [(c − p_k) × m(c̈ − g) + Ḣ]: the moment
/// the joint must carry about its axis (0 at a free joint, the reaction at a seated one).
fn joint_moments(
    model: &Model,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    qddot: &DVector<f64>,
) -> Vec<f64> {
    let pivots = ActivePivots::uniform(model, Side::Positive);
    joint_moments_about(model, &pivots, &pivots, q, qdot, qddot)
}

/// [`joint_moments`] of the motion on `pivots`, taken about the pivots (and axes) that the
/// kinematics on `about` puts at q.
fn joint_moments_about(
    model: &Model,
    pivots: &ActivePivots,
    about: &ActivePivots,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    qddot: &DVector<f64>,
) -> Vec<f64> {
    let mut data = Data::new(model);
    let h = 1e-4;
    let mut at = |t: f64| {
        let qt = q + qdot * t + qddot * (0.5 * t * t);
        let qdt = qdot + qddot * t;
        bodies_at(model, &mut data, pivots, &qt, &qdt)
    };
    let (minus, zero, plus) = (at(-h), at(0.0), at(h));
    forward_kinematics(model, &mut data, q, about);
    let g = Vector3::new(0.0, 0.0, -model.gravity);
    (0..model.dof())
        .map(|k| {
            let mut moment = Vector3::zeros();
            for (b, body) in model.bodies.iter().enumerate() {
                // Body b is in the subtree of k when k is on its coordinate's path.
                let mut j = Some(model.body_coord[b]);
                let mut inside = false;
                while let Some(jj) = j {
                    inside |= jj == k;
                    j = model.coords[jj].parent;
                }
                if !inside {
                    continue;
                }
                let c = zero[b].0;
                let c_ddot = (plus[b].0 - 2.0 * c + minus[b].0) / (h * h);
                let h_dot = (plus[b].1 - minus[b].1) / (2.0 * h);
                moment += (c - data.pivot[k]).cross(&(body.mass * (c_ddot - g))) + h_dot;
            }
            data.axis[k].dot(&moment)
        })
        .collect()
}

#[test]
fn seated_coordinates_carry_the_newton_euler_moments() {
    let model = Model::from_spec(&serial_chain(4)).unwrap();
    let ground = GroundMotion::none();
    // Scale of the joint moments: m g L of the whole chain.
    let scale = model.total_mass() * model.gravity * model.size;
    for (seated, solver) in [vec![1], vec![0, 2], vec![3], vec![0, 1, 2, 3]]
        .into_iter()
        .flat_map(|s| {
            [
                (s.clone(), ForwardSolver::Cholesky),
                (s, ForwardSolver::ArticulatedBody),
            ]
        })
    {
        let q = DVector::from_fn(4, |k, _| {
            if seated.contains(&k) {
                0.0
            } else {
                0.4 * ((k + 1) as f64).sin()
            }
        });
        let qdot = DVector::from_fn(4, |k, _| {
            if seated.contains(&k) {
                0.0
            } else {
                0.7 * ((2 * k + 1) as f64).cos()
            }
        });
        let mut dynamics = Dynamics::new(&model, ActivePivots::uniform(&model, Side::Positive));
        dynamics.seated = seated.clone();
        dynamics.solver = solver;
        dynamics
            .accelerations(&model, &ground, 0.0, &q, &qdot)
            .unwrap();
        let moments = joint_moments(&model, &q, &qdot, &dynamics.qddot);
        for k in 0..4 {
            match seated.iter().position(|&s| s == k) {
                Some(i) => {
                    assert_eq!(
                        dynamics.qddot[k], 0.0,
                        "seated {seated:?} ({solver:?}): q̈{k}"
                    );
                    // Central differences with h = 1e-4: truncation ~h²·|d⁴x/dt⁴|, round-off
                    // ~ε/h² of the positions: both below 1e-6 of m g L here.
                    let err = (dynamics.seat_reactions[i] - moments[k]).abs() / scale;
                    assert!(
                        err < 1e-6,
                        "seated {seated:?} ({solver:?}): reaction {k} = {} vs Newton–Euler {} ({err:e})",
                        dynamics.seat_reactions[i],
                        moments[k]
                    );
                }
                None => {
                    let err = moments[k].abs() / scale;
                    assert!(
                        err < 1e-6,
                        "seated {seated:?} ({solver:?}): free joint {k} carries {err:e} m g L"
                    );
                }
            }
        }
    }
}

/// The joint force of the articulated-body solve gives a seated joint's reaction about the pivot
/// on its other side (what the uplift test reads for the other side's release): equal to the seat
/// reaction of a separate solve on the flipped pivot (the same locked motion) and to Newton–Euler
/// about that pivot.
/// Four drums 0.6 m wide and 0.5 m high, stacked on two-sided hinges whose axes alternate
/// between y and x (a pivot on each edge: 0.3 m either side of the axis), so that the stack moves
/// in 3D.
fn drum_stack() -> StructureSpec {
    let (b, h) = (0.3, 0.5);
    let mut body = Vec::new();
    let mut interface = Vec::new();
    for k in 0..4 {
        let z = k as f64 * h;
        body.push(box_body(
            &format!("drum{k}"),
            2500.0,
            [0.02 * k as f64, 0.0, z + 0.5 * h],
            [2.0 * b, 2.0 * b, h],
        ));
        let parent = if k == 0 {
            "ground".to_string()
        } else {
            format!("drum{}", k - 1)
        };
        let (axis, pos, neg) = if k % 2 == 0 {
            ([0.0, 1.0, 0.0], [b, 0.0, z], [-b, 0.0, z])
        } else {
            ([-1.0, 0.0, 0.0], [0.0, b, z], [0.0, -b, z])
        };
        interface.push(hinge(
            &format!("j{k}"),
            &parent,
            &format!("drum{k}"),
            axis,
            pos,
            neg,
        ));
    }
    StructureSpec {
        name: "drum_stack".into(),
        gravity: 9.81,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

#[test]
fn joint_force_gives_the_reaction_about_the_other_pivot() {
    let model = Model::from_spec(&drum_stack()).unwrap();
    let ground = GroundMotion::none();
    let scale = model.total_mass() * model.gravity * model.size;
    for seated in [vec![1], vec![0, 2], vec![1, 3], vec![0, 1, 2, 3]] {
        let q = DVector::from_fn(4, |k, _| {
            if seated.contains(&k) {
                0.0
            } else {
                0.3 * ((k + 2) as f64).sin()
            }
        });
        let qdot = DVector::from_fn(4, |k, _| {
            if seated.contains(&k) {
                0.0
            } else {
                0.9 * ((3 * k + 1) as f64).cos()
            }
        });
        let pivots = ActivePivots::uniform(&model, Side::Positive);
        let mut dynamics = Dynamics::new(&model, pivots.clone());
        dynamics.seated = seated.clone();
        dynamics.solver = ForwardSolver::ArticulatedBody;
        dynamics
            .accelerations(&model, &ground, 0.0, &q, &qdot)
            .unwrap();
        for (i, &k) in seated.iter().enumerate() {
            let f = dynamics.joint_force(k).expect("an articulated-body solve");
            // Along the joint's own axis: the seat reaction (no applied joint torque here).
            let own = crr_kinematics::mass_matrix::spatial_axis(&dynamics.kin, k).dot(&f);
            assert!((own - dynamics.seat_reactions[i]).abs() < 1e-12 * scale);
            let mut flipped = pivots.clone();
            flipped.sides[k] = Side::Negative;
            let mut other = Dynamics::new(&model, flipped.clone());
            other.seated = seated.clone();
            other.solver = ForwardSolver::Cholesky;
            other
                .accelerations(&model, &ground, 0.0, &q, &qdot)
                .unwrap();
            // The locked motion does not depend on the seated joint's pivot.
            assert!((&other.qddot - &dynamics.qddot).amax() < 1e-12 * model.gravity / model.size);
            let mut data = Data::new(&model);
            forward_kinematics(&model, &mut data, &q, &flipped);
            assert!((data.pivot[k] - dynamics.kin.pivot[k]).norm() > 0.5);
            let about_other = crr_kinematics::mass_matrix::spatial_axis(&data, k).dot(&f);
            let err = (about_other - other.seat_reactions[i]).abs() / scale;
            assert!(
                err < 1e-12,
                "seated {seated:?}: slot {k}: {about_other} vs {} ({err:e})",
                other.seat_reactions[i]
            );
            let newton_euler =
                joint_moments_about(&model, &pivots, &flipped, &q, &qdot, &dynamics.qddot);
            let err = (about_other - newton_euler[k]).abs() / scale;
            assert!(
                err < 1e-6,
                "seated {seated:?}: slot {k}: {about_other} vs Newton–Euler {} ({err:e})",
                newton_euler[k]
            );
        }
    }
}

/// A seated tree coordinate of an open chain stays at +0.0 bit for bit under integration, on
/// both forward solvers (the locked coordinate's q̈ is 0.0, so every stage adds h·0.0 to 0.0),
/// and the projection after a step then reports no move (f(t, y) and the step end's events stay
/// valid); a seated coordinate off +0.0 (−0.0, or 1e-300) is set to +0.0 and reported moved.
#[test]
fn an_open_chain_s_seated_coordinate_stays_at_zero_and_needs_no_projection() {
    use crr_dynamics::ConstrainedSystem;
    use crr_dynamics::integrator::{DenseStep, Method, NoEvents, OdeSystem, Options, Solver};
    let model = Model::from_spec(&serial_chain(4)).unwrap();
    let ground = GroundMotion::none();
    let n = model.dof();
    for solver in [ForwardSolver::Cholesky, ForwardSolver::ArticulatedBody] {
        let mut dynamics = Dynamics::new(&model, ActivePivots::uniform(&model, Side::Positive));
        dynamics.seated = vec![1];
        dynamics.solver = solver;
        let mut sys = ConstrainedSystem::new(&model, &ground, &mut dynamics);
        let mut y = vec![0.0; 2 * n + 2];
        for k in [0, 2, 3] {
            y[k] = 0.3 * ((k + 1) as f64).sin();
            y[n + k] = 0.5 * ((k + 2) as f64).cos();
        }
        let mut integrator = Solver::new(Method::Dop853, Options::default(), 2 * n + 2).unwrap();
        integrator.reset(0.0, &y);
        let mut steps = 0usize;
        integrator
            .advance(&mut sys, 0.5, &mut NoEvents, &mut |_: &DenseStep| {
                steps += 1
            })
            .unwrap();
        let end = integrator.y().to_vec();
        assert!(steps > 3, "{solver:?}: {steps} steps");
        assert_eq!(
            (end[1].to_bits(), end[n + 1].to_bits()),
            (0, 0),
            "{solver:?}"
        );
        assert!(end[0] != y[0], "{solver:?}: the free coordinates moved");
        let mut at = end.clone();
        assert!(!sys.project(0.5, &mut at).unwrap(), "{solver:?}");
        assert_eq!(at, end);
        for off in [-0.0, 1e-300] {
            let mut at = end.clone();
            at[n + 1] = off;
            assert!(sys.project(0.5, &mut at).unwrap(), "{solver:?}: {off:e}");
            assert_eq!(at[n + 1].to_bits(), 0, "{solver:?}");
        }
    }
}
