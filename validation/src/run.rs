//! Runs a crr model in rapier: the ground motion enters as crr's effective gravity
//! g_eff(t) = (−a_x, −a_y, −g − a_z) in the frame of the ground (the ground is fixed, every body
//! feels −M a_g), the interface angles are measured from the bodies' poses at every output
//! sample, and the run stops at collapse by crr's own criterion.

use std::io::Write;
use std::path::Path;

use crr::analysis::simulation::Prepared;
use crr::kinematics::{InterfaceKind, Model, Parent, interface_angles};
use nalgebra::{Matrix3, Vector3};
use rapier3d_f64::prelude::*;

use crate::scene::{Scene, Settings, build, rotation_matrix, world_point};

/// The histories of a rapier run, in crr's coordinates.
#[derive(Clone, Debug, Default)]
pub struct RapierRun {
    /// Coordinate names (crr's, in the order of q).
    pub coordinates: Vec<String>,
    /// Sample times (s).
    pub t: Vec<f64>,
    /// q at each sample (rad), measured from the poses.
    pub q: Vec<Vec<f64>>,
    /// q̇ at each sample (rad/s), by a backward difference over one rapier step.
    pub qdot: Vec<Vec<f64>>,
    /// Kinetic and potential energy (U − U_rest) at each sample (J).
    pub energy: Vec<(f64, f64)>,
    /// Largest slip or gap at an active pivot over the run (m): the distance between the two
    /// bodies' images of the nearest pivot point.
    pub max_slip: f64,
    /// Collapse time (s), by crr's criterion: U below rest by `collapse_drop` m g L.
    pub collapse: Option<f64>,
    /// Rapier steps taken.
    pub steps: usize,
}

/// Runs `p` (model, ground motion, initial state, duration and output interval) in rapier.
pub fn run(p: &Prepared, s: &Settings) -> Result<RapierRun, String> {
    let model = &p.model;
    let Scene { mut world, bodies } = build(model, &p.initial, s)?;
    let n = model.dof();
    let mut out = RapierRun {
        coordinates: model.coords.iter().map(|c| c.name.clone()).collect(),
        ..RapierRun::default()
    };
    let scale = model.total_mass() * model.gravity * model.size;
    let u_rest: f64 = model
        .bodies
        .iter()
        .map(|b| b.mass * model.gravity * b.com.z)
        .sum();
    let mut angles = vec![0.0; model.slot_count];
    let mut previous = vec![0.0; model.slot_count];
    let mut rotations = vec![Matrix3::identity(); bodies.len()];
    measure(model, &world, &bodies, &mut rotations, &mut previous);
    let steps = (p.params.duration / s.dt).round() as usize;
    let every = ((p.params.output_interval / s.dt).round() as usize).max(1);
    let mut record = |world: &PhysicsWorld, step: usize, angles: &[f64], previous: &[f64]| {
        let t = step as f64 * s.dt;
        out.t.push(t);
        out.q.push(angles[..n].to_vec());
        out.qdot.push(
            angles[..n]
                .iter()
                .zip(&previous[..n])
                .map(|(a, b)| if step == 0 { 0.0 } else { (a - b) / s.dt })
                .collect(),
        );
        let (kinetic, potential) = energies(model, world, &bodies);
        out.energy.push((kinetic, potential - u_rest));
        out.max_slip = out.max_slip.max(slip(model, world, &bodies));
        potential - u_rest
    };
    record(&world, 0, &previous.clone(), &previous);
    for step in 1..=steps {
        let t_mid = (step as f64 - 0.5) * s.dt;
        let a = p.ground.acceleration(t_mid);
        world.gravity = Vector::new(-a.x, -a.y, -model.gravity - a.z);
        world.step();
        measure(model, &world, &bodies, &mut rotations, &mut angles);
        if !angles.iter().all(|x| x.is_finite()) {
            return Err(format!(
                "rapier produced a non-finite pose at t = {}",
                step as f64 * s.dt
            ));
        }
        if step % every == 0 || step == steps {
            let drop = record(&world, step, &angles, &previous);
            if drop < -p.params.collapse_drop * scale && out.collapse.is_none() {
                out.collapse = Some(step as f64 * s.dt);
                out.steps = step;
                return Ok(out);
            }
        }
        std::mem::swap(&mut angles, &mut previous);
    }
    out.steps = steps;
    Ok(out)
}

/// Every slot's angle from the bodies' poses (`rotations` is workspace, one per body).
fn measure(
    model: &Model,
    world: &PhysicsWorld,
    bodies: &[RigidBodyHandle],
    rotations: &mut [Matrix3<f64>],
    out: &mut [f64],
) {
    for (r, h) in rotations.iter_mut().zip(bodies) {
        *r = rotation_matrix(&world.bodies[*h]);
    }
    interface_angles(model, rotations, out);
}

/// Kinetic energy from rapier's velocities and the bodies' exact inertia; potential energy from
/// the centres' heights (J).
fn energies(model: &Model, world: &PhysicsWorld, bodies: &[RigidBodyHandle]) -> (f64, f64) {
    let mut kinetic = 0.0;
    let mut potential = 0.0;
    for (b, h) in bodies.iter().enumerate() {
        let rb = &world.bodies[*h];
        let body = &model.bodies[b];
        let r = rotation_matrix(rb);
        let w = rb.angvel();
        let w = Vector3::new(w.x, w.y, w.z);
        let c = world_point(rb, &body.com);
        let vc = rb.velocity_at_point(Vector::new(c.x, c.y, c.z));
        let vc = Vector3::new(vc.x, vc.y, vc.z);
        kinetic += 0.5 * body.mass * vc.norm_squared()
            + 0.5 * w.dot(&(r * body.inertia * r.transpose() * w));
        potential += body.mass * model.gravity * c.z;
    }
    (kinetic, potential)
}

/// The largest, over the interfaces, of the smallest distance between the parent's and the
/// child's images of one of its pivot points: the slip (or gap) at the active pivot.
fn slip(model: &Model, world: &PhysicsWorld, bodies: &[RigidBodyHandle]) -> f64 {
    model
        .interfaces
        .iter()
        .map(|iface| {
            let points: Vec<Vector3<f64>> = match &iface.kind {
                InterfaceKind::Hinge {
                    pivot_positive,
                    pivot_negative,
                    ..
                } => vec![*pivot_positive, *pivot_negative],
                InterfaceKind::RockingBase { corners, .. } => corners.to_vec(),
            };
            let child = &world.bodies[bodies[iface.child]];
            points
                .iter()
                .map(|x| {
                    let xp = match iface.parent {
                        Parent::Ground => *x,
                        Parent::Body(p) => world_point(&world.bodies[bodies[p]], x),
                    };
                    (xp - world_point(child, x)).norm()
                })
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// Writes `history.csv`: `t`, the coordinates, their rates, `kinetic`, `potential`: the same
/// coordinate columns as `crr simulate`'s history.
pub fn write_history(run: &RapierRun, path: &Path) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    let names = run.coordinates.join(",");
    let rates: Vec<String> = run
        .coordinates
        .iter()
        .map(|c| format!("{c}_rate"))
        .collect();
    writeln!(f, "t,{names},{},kinetic,potential", rates.join(","))?;
    for i in 0..run.t.len() {
        let mut row = vec![format!("{:e}", run.t[i])];
        row.extend(run.q[i].iter().map(|x| format!("{x:e}")));
        row.extend(run.qdot[i].iter().map(|x| format!("{x:e}")));
        row.push(format!("{:e}", run.energy[i].0));
        row.push(format!("{:e}", run.energy[i].1));
        writeln!(f, "{}", row.join(","))?;
    }
    f.flush()
}
