//! Helpers shared by the forward-dynamics tests: a constant extra force and a constant ground
//! acceleration.

use crr_dynamics::eom::GeneralizedForce;
use crr_dynamics::ground_motion::{Axis, GroundMotion, Record};
use crr_kinematics::{Data, Model};
use nalgebra::{DVector, Vector3};

/// A constant extra generalized force τ.
pub struct Tau(pub DVector<f64>);

impl GeneralizedForce for Tau {
    fn add(
        &mut self,
        _model: &Model,
        _kin: &Data,
        _t: f64,
        _q: &DVector<f64>,
        _qdot: &DVector<f64>,
        out: &mut DVector<f64>,
    ) {
        *out += &self.0;
    }
}

/// A ground motion of constant acceleration `a` (m/s²) around t = 0.
pub fn constant_ground(a: Vector3<f64>) -> GroundMotion {
    let rec = |v: f64| Record::uniform(1.0, vec![v, v, v]).expect("valid record");
    GroundMotion::from_record(Axis::X, rec(a.x), 1.0)
        .and_then(|g| g.with_record(Axis::Y, rec(a.y), 1.0))
        .and_then(|g| g.with_record(Axis::Z, rec(a.z), 1.0))
        .expect("valid ground motion")
}
