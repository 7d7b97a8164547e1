//! `Model::planar_axis`: the common axis of a model whose every interface is a hinge about
//! parallel axes. Checked against the axis the fixture was written with (y for the planar
//! fixtures), carried through a rotation of the whole structure (R·y, computed from R alone,
//! not from the model's hinges), and refused where a rocking base or a hinge about another axis
//! makes the motion three-dimensional. The tolerance 1e-12 is round-off of a rotated unit
//! vector; a hinge turned by 1e-6 rad (three orders above the rule's 1e-9) is refused, one
//! turned by 1e-11 rad (two below) is accepted.

use crr_kinematics::Model;
use crr_kinematics::fixtures::{
    colonnade, four_hinge_arch, random_chain, running_bond_wall, running_bond_wall_3d, transformed,
    trilithon, voussoir_arch,
};
use crr_kinematics::spec::StructureSpec;
use nalgebra::{Matrix3, Rotation3, Vector3};

fn model(spec: &StructureSpec) -> Model {
    Model::from_spec(spec).unwrap_or_else(|e| panic!("{} is refused: {e}", spec.name))
}

/// Parallel to `expected` (either sense), to 1e-12.
fn assert_parallel(axis: Vector3<f64>, expected: Vector3<f64>, what: &str) {
    assert!(
        (axis.norm() - 1.0).abs() < 1e-12,
        "{what}: the axis {axis:?} is not a unit vector"
    );
    assert!(
        axis.cross(&expected).norm() < 1e-12,
        "{what}: axis {axis:?}, expected ±{expected:?}"
    );
}

#[test]
fn planar_fixtures_turn_about_y() {
    for spec in [
        trilithon(1.0, 4.0, 3.0, 1.0, 1.0),
        four_hinge_arch(4.0, 5.0, 1.0, true),
        voussoir_arch(9, 2.0, 2.5, 1.0),
        running_bond_wall(4, 3, 1.0, 0.5, 0.5),
    ] {
        let m = model(&spec);
        let axis = m
            .planar_axis()
            .unwrap_or_else(|| panic!("{} is planar but has no common axis", spec.name));
        assert_parallel(axis, Vector3::y(), &spec.name);
    }
}

#[test]
fn the_axis_turns_with_the_structure() {
    let rot: Matrix3<f64> = Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8)),
        1.1,
    )
    .into_inner();
    let spec = transformed(
        &running_bond_wall(3, 3, 1.0, 0.5, 0.5),
        &rot,
        &Vector3::new(2.0, -1.0, 0.5),
    );
    let axis = model(&spec).planar_axis().expect("a turned wall is planar");
    assert_parallel(axis, rot * Vector3::y(), "the wall turned by R");
}

#[test]
fn three_dimensional_models_have_no_common_axis() {
    // Rocking bases: the columns and the 3D wall tilt about two axes.
    assert_eq!(
        model(&colonnade(1.0, 4.0, 3.0, 1.0)).planar_axis(),
        None,
        "colonnade"
    );
    assert_eq!(
        model(&running_bond_wall_3d(3, 3, 1.0, 0.5, 0.5)).planar_axis(),
        None,
        "3D wall"
    );
    // Rocking bases and hinges about random axes.
    assert_eq!(
        model(&random_chain(7, 4, 0)).planar_axis(),
        None,
        "random chain"
    );
    assert_eq!(
        model(&wall_with_one_hinge_turned(1e-6)).planar_axis(),
        None,
        "one hinge turned by 1e-6 rad"
    );
}

#[test]
fn a_hinge_turned_within_the_rule_keeps_the_model_planar() {
    let axis = model(&wall_with_one_hinge_turned(1e-11))
        .planar_axis()
        .expect("a hinge turned by 1e-11 rad is parallel within 1e-9");
    assert!(axis.cross(&Vector3::y()).norm() < 1e-10, "{axis:?}");
}

/// The planar 3 × 3 wall with its first hinge's axis turned by `angle` about x.
fn wall_with_one_hinge_turned(angle: f64) -> StructureSpec {
    let mut spec = running_bond_wall(3, 3, 1.0, 0.5, 0.5);
    let turn = Rotation3::from_axis_angle(&Vector3::x_axis(), angle);
    let axis = spec
        .interface
        .iter_mut()
        .find_map(|i| i.axis.as_mut())
        .expect("the wall has hinges");
    *axis = (turn * Vector3::from(*axis)).into();
    spec
}
