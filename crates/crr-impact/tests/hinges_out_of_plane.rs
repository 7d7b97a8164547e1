//! `statics::hinges_out_of_plane`: the load a hinge must carry out of its plane at a multiplier,
//! against the equilibrium of a block that stands on that hinge alone (statically determinate,
//! so every distribution gives its hinge the same wrench). The model is not planar: beside the
//! block stands a cube on a rocking base.
//!
//! The block (0.4 × 0.4 × 2 m, centre c = (0, 0, 1)) stands on a hinge about y with pivots at
//! x = ±0.2, z = 0. Under the load λ′ m g along −y (the ground accelerating along +y) and its
//! weight, the hinge's force is m g (λ′ ŷ + ẑ) and its moment about P⁺ = (0.2, 0, 0) is
//! −(c − P⁺) × (−λ′ m g ŷ − m g ẑ) = m g (−λ′, 0.2, −0.2 λ′): a force λ′ m g along its axis,
//! and a couple λ′ m g √(1 + 0.2²) out of its plane (the 0.2 m g about y is the in-plane moment
//! its pivots carry). Along x the load stays in the hinge's plane: nothing to name.
//!
//! Tolerance 1e-8 relative: the program's accuracy (1e-12 of the weight) on a determinate wrench.

use crr_impact::statics::{StaticsOptions, hinges_out_of_plane};
use crr_kinematics::Model;
use crr_kinematics::fixtures::{box_body, hinge, rocking_base};
use crr_kinematics::spec::{DEFAULT_GRAVITY, StructureSpec};
use nalgebra::Vector3;

fn block_on_a_hinge_beside_a_cube() -> Model {
    let spec = StructureSpec {
        name: "hinge_and_cube".into(),
        gravity: DEFAULT_GRAVITY,
        body: vec![
            box_body("block", 2000.0, [0.0, 0.0, 1.0], [0.4, 0.4, 2.0]),
            box_body("cube", 2000.0, [3.0, 0.0, 0.5], [1.0, 1.0, 1.0]),
        ],
        interface: vec![
            hinge(
                "block_base",
                "ground",
                "block",
                [0.0, 1.0, 0.0],
                [0.2, 0.0, 0.0],
                [-0.2, 0.0, 0.0],
            ),
            rocking_base(
                "cube_base",
                "ground",
                "cube",
                [
                    [2.5, -0.5, 0.0],
                    [3.5, -0.5, 0.0],
                    [3.5, 0.5, 0.0],
                    [2.5, 0.5, 0.0],
                ],
            ),
        ],
        symmetry: Vec::new(),
    };
    Model::from_spec(&spec).expect("the model is valid")
}

#[test]
fn a_determinate_hinge_carries_its_blocks_out_of_plane_load() {
    let model = block_on_a_hinge_beside_a_cube();
    assert_eq!(model.planar_axis(), None, "the cube's rocking base");
    let lambda = 0.05;
    let options = StaticsOptions::default();
    let loaded = hinges_out_of_plane(&model, Vector3::y(), &options, lambda).unwrap();
    assert_eq!(loaded.len(), 1, "{loaded:?}");
    let h = &loaded[0];
    assert_eq!(h.name, "block_base");
    // λ is fixed at λ·(1 − 1e-7), inside the program's feasible interval.
    let load = lambda * (1.0 - 1e-7) * model.bodies[0].mass * model.gravity;
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-8 * b;
    assert!(close(h.axial, load), "axial {} against {load}", h.axial);
    let couple = load * (1.0f64 + 0.2 * 0.2).sqrt();
    assert!(
        close(h.couple, couple),
        "couple {} against {couple}",
        h.couple
    );
    // Along x the load stays in the hinge's plane.
    let in_plane = hinges_out_of_plane(&model, Vector3::x(), &options, lambda).unwrap();
    assert!(in_plane.is_empty(), "{in_plane:?}");
}
