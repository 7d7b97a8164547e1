//! The interface angles measured from the bodies' rotations alone (as another engine's poses
//! give them) are the coordinates that produced those rotations: forward kinematics from random
//! q on random open chains (hinges and rocking bases, whose two tilts compose in series), then
//! `interface_angles` recovers q to round-off.

use crr_kinematics::fixtures::random_chain;
use crr_kinematics::{
    ActivePivots, Data, Model, Side, body_rotation, forward_kinematics, interface_angles,
};
use nalgebra::DVector;

#[test]
fn angles_from_the_rotations_are_the_coordinates() {
    let mut checked = 0;
    for seed in 0..40u64 {
        let model = Model::from_spec(&random_chain(seed, 4, 0)).unwrap();
        let n = model.dof();
        // Angles up to ±0.6 rad, from a fixed sequence.
        let q = DVector::from_fn(n, |k, _| 0.6 * ((seed as f64 * 1.7 + k as f64 * 2.3).sin()));
        let mut pivots = ActivePivots::uniform(&model, Side::Positive);
        for k in 0..n {
            pivots.sides[k] = if q[k] >= 0.0 {
                Side::Positive
            } else {
                Side::Negative
            };
        }
        let mut data = Data::new(&model);
        forward_kinematics(&model, &mut data, &q, &pivots);
        let rotations: Vec<_> = (0..model.bodies.len())
            .map(|b| body_rotation(&model, &data, b))
            .collect();
        let mut angles = vec![0.0; model.slot_count];
        interface_angles(&model, &rotations, &mut angles);
        for k in 0..n {
            assert!(
                (angles[k] - q[k]).abs() < 1e-12,
                "seed {seed}, coordinate {k}: {} vs {}",
                angles[k],
                q[k]
            );
            checked += 1;
        }
    }
    assert!(checked > 100);
}
