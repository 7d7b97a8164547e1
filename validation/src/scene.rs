//! The rapier scene of a crr model: every body a dynamic rigid body with crr's exact mass
//! properties and colliders of its real shape, the ground a fixed body with one support slab per
//! ground interface, contacts stiff and rough enough that nothing slides. Rapier knows nothing of
//! pivots, rocking coordinates or impact laws: the rocking emerges from contacts and friction.
//!
//! Each rapier body's local frame is the world frame at rest, so its pose (R, t) maps a rest point
//! X to R X + t, exactly crr's Γ and frame translation: the interface angles are measured from
//! the poses with [`crr::kinematics::interface_angles`].

use crr::dynamics::InitialState;
use crr::kinematics::{Data, InterfaceKind, Model, Parent, forward_kinematics};
use nalgebra::{Matrix3, Point3, Vector3};
use rapier3d_f64::prelude::*;

use crate::pieces::convex_pieces;

/// Rapier's settings for rocking (what makes it accurate on a block, measured in the report).
#[derive(Clone, Debug)]
pub struct Settings {
    /// Time step (s). Rapier's default 1/60 s loses 10–14 % of a block's first cycle.
    pub dt: f64,
    /// Solver substeps per step (`num_solver_iterations`).
    pub substeps: usize,
    /// Coulomb friction coefficient, high so that nothing slides (the largest slip is reported).
    pub friction: f64,
    /// Natural frequency of contacts between two moving bodies (Hz).
    pub contact_hz: f64,
    /// Natural frequency of contacts with the fixed ground (Hz).
    pub static_contact_hz: f64,
    /// Damping ratio of the contact springs.
    pub damping_ratio: f64,
    /// Rapier's length unit as a fraction of the model size (its contact tolerances scale with it).
    pub length_unit: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            dt: 1e-4,
            substeps: 4,
            friction: 5.0,
            contact_hz: 500.0,
            static_contact_hz: 1000.0,
            damping_ratio: 10.0,
            length_unit: 0.005,
        }
    }
}

/// A rapier world built from a crr model, with the handle of each crr body.
pub struct Scene {
    /// Bodies, colliders, pipeline.
    pub world: PhysicsWorld,
    /// `bodies[b]` is crr body b.
    pub bodies: Vec<RigidBodyHandle>,
}

fn v(x: &Vector3<f64>) -> Vector {
    Vector::new(x.x, x.y, x.z)
}

fn nv(x: Vector) -> Vector3<f64> {
    Vector3::new(x.x, x.y, x.z)
}

/// The rotation of a rapier body as a nalgebra matrix.
pub fn rotation_matrix(rb: &RigidBody) -> Matrix3<f64> {
    let m = Matrix::from_quat(*rb.rotation());
    Matrix3::from_columns(&[nv(m.x_axis), nv(m.y_axis), nv(m.z_axis)])
}

/// The world position of the rest point `x` of a rapier body.
pub fn world_point(rb: &RigidBody, x: &Vector3<f64>) -> Vector3<f64> {
    nv(*rb.rotation() * v(x) + rb.translation())
}

/// Builds the scene at the initial state (crr's forward kinematics places the bodies; initial
/// rates must be zero: a released structure or one at rest).
pub fn build(model: &Model, initial: &InitialState, s: &Settings) -> Result<Scene, String> {
    if initial.qdot.iter().any(|r| *r != 0.0) {
        return Err(
            "initial rates: the rapier scene starts from rest (released or seated structures); \
             set the initial rates to 0"
                .into(),
        );
    }
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, 0.0, -model.gravity);
    let ip = &mut world.integration_parameters;
    ip.dt = s.dt;
    ip.num_solver_iterations = s.substeps.max(1);
    ip.contact_softness.natural_frequency = s.contact_hz;
    ip.contact_softness.damping_ratio = s.damping_ratio;
    ip.static_contact_softness.natural_frequency = s.static_contact_hz;
    ip.static_contact_softness.damping_ratio = s.damping_ratio;
    // Rapier's tolerances scale with its length unit: the penetration it allows before pushing
    // back (0.005 units) and its speculative contact distance (0.02 units). At the model size they
    // let a rocking edge sink and slide (3.3 % late on the block's first crossing, an arch
    // falling apart); at 0.005 of it they converge (0.05 %; 0.001 of it breaks the contacts).
    ip.length_unit = s.length_unit * model.size;

    let mut kin = Data::new(model);
    forward_kinematics(model, &mut kin, &initial.q, &initial.pivots);
    let mut bodies = Vec::with_capacity(model.bodies.len());
    for (b, body) in model.bodies.iter().enumerate() {
        let k = model.body_coord[b];
        let r = kin.rot_ops[k];
        let t = kin.frame_translation[k];
        let rot = Rotation::from_mat3(&Matrix::from_cols(
            v(&r.column(0).into_owned()),
            v(&r.column(1).into_owned()),
            v(&r.column(2).into_owned()),
        ));
        let i = body.inertia;
        let inertia = Matrix::from_cols(
            v(&i.column(0).into_owned()),
            v(&i.column(1).into_owned()),
            v(&i.column(2).into_owned()),
        );
        let rb = RigidBodyBuilder::dynamic()
            .pose(Pose::from_parts(v(&t), rot))
            .additional_mass_properties(MassProperties::with_inertia_matrix(
                v(&body.com),
                body.mass,
                inertia,
            ))
            .can_sleep(false)
            .build();
        let h = world.bodies.insert(rb);
        for piece in convex_pieces(&body.shape) {
            let pts: Vec<Vector> = piece.iter().map(|p| v(&p.coords)).collect();
            let c = ColliderBuilder::convex_hull(&pts)
                .ok_or_else(|| format!("body \"{}\": a piece of its shape has no hull", body.name))?
                .density(0.0)
                .friction(s.friction)
                .restitution(0.0)
                .build();
            world.colliders.insert_with_parent(c, h, &mut world.bodies);
        }
        bodies.push(h);
    }
    let ground = world.bodies.insert(RigidBodyBuilder::fixed().build());
    for iface in model
        .interfaces
        .iter()
        .filter(|i| i.parent == Parent::Ground)
    {
        let child = &model.bodies[iface.child];
        let slab = support_slab(&iface.kind, child, model.size)
            .map_err(|e| format!("interface \"{}\": {e}", iface.name))?;
        let c =
            ColliderBuilder::convex_hull(&slab.iter().map(|p| v(&p.coords)).collect::<Vec<_>>())
                .ok_or_else(|| {
                    format!("interface \"{}\": the support slab has no hull", iface.name)
                })?
                .friction(s.friction)
                .restitution(0.0)
                .build();
        world
            .colliders
            .insert_with_parent(c, ground, &mut world.bodies);
    }
    Ok(Scene { world, bodies })
}

/// The ground's support under a ground interface at rest: a slab whose top face is the contact
/// plane through the pivots, as wide as the contact plus a quarter on each side, as long as the
/// child along a hinge axis, half the model size thick.
fn support_slab(
    kind: &InterfaceKind,
    child: &crr::kinematics::Body,
    size: f64,
) -> Result<Vec<Point3<f64>>, String> {
    let thickness = 0.5 * size;
    let (center, a, b, n): (Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>) = match kind {
        InterfaceKind::Hinge {
            axis,
            pivot_positive,
            pivot_negative,
        } => {
            let d = (pivot_negative - pivot_positive)
                - axis * axis.dot(&(pivot_negative - pivot_positive));
            if d.norm() <= 1e-9 * size {
                return Err(
                    "a hinge on a single pivot line is a pin, not a contact: rapier \
                            needs two pivot lines"
                        .into(),
                );
            }
            let mut n = axis.cross(&d).normalize();
            if n.dot(&(child.com - pivot_positive)) < 0.0 {
                n = -n;
            }
            // The child's extent along the axis.
            let along: Vec<f64> = convex_pieces(&child.shape)
                .iter()
                .flatten()
                .map(|p| axis.dot(&(p.coords - pivot_positive)))
                .collect();
            let (lo, hi) = along
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
                    (l.min(x), h.max(x))
                });
            let mid = pivot_positive + d * 0.5 + axis * (0.5 * (lo + hi));
            (mid, axis * (0.5 * (hi - lo)), d * 0.75, n)
        }
        InterfaceKind::RockingBase {
            corners, normal, ..
        } => {
            let mid = corners.iter().sum::<Vector3<f64>>() / 4.0;
            (
                mid,
                (corners[1] - corners[0]) * 0.75,
                (corners[3] - corners[0]) * 0.75,
                *normal,
            )
        }
    };
    let mut out = Vec::with_capacity(8);
    for z in [0.0, -thickness] {
        for (sa, sb) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            out.push(Point3::from(center + a * sa + b * sb + n * z));
        }
    }
    Ok(out)
}
