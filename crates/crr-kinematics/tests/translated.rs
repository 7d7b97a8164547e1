//! `Model::translated` (the simulation moves a model written far from the origin near it)
//! against the model built from the description moved point by point (`fixtures::transformed`
//! with no rotation: every point given plus d, every direction as it is): the same bodies (centre,
//! mass, inertia about the centre, shape), the same interfaces (pivot lines, corners, axes,
//! normals) and the same tree, loops and size. Structures of boxes, hinges and rocking bases,
//! loops, and voussoirs (the arch's shapes); moved by a survey offset (5e5, 4.5e6, 350) m and by
//! a small one. Points agree to 4 ulp of the offset (two roundings: of the description's points
//! and of the derived ones), masses to 1e-12 and inertias to 1e-9 relative, and directions to
//! 1e-12 plus what the moved description's own rounding gives those the builder derives from
//! points (a base's normal from its corners: twice the points' tolerance over 0.2 m).

use crr_kinematics::fixtures::{
    colonnade, four_hinge_arch, random_chain, running_bond_wall_3d, transformed, trilithon,
    voussoir_arch,
};
use crr_kinematics::{InterfaceKind, Model};
use nalgebra::{Matrix3, Vector3};

fn close(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol
}

#[test]
fn a_translated_model_is_the_model_of_the_moved_description() {
    let specs = [
        ("trilithon", trilithon(0.25, 2.0, 3.0, 0.6, 1.0)),
        ("colonnade", colonnade(0.2, 1.5, 2.4, 0.4)),
        ("random chain", random_chain(7, 6, 2)),
        ("four-hinge arch", four_hinge_arch(4.0, 5.0, 1.0, true)),
        ("voussoir arch", voussoir_arch(9, 4.0, 4.6, 1.0)),
        ("3D wall", running_bond_wall_3d(3, 3, 1.0, 0.5, 0.4)),
    ];
    for (name, spec) in &specs {
        let model = Model::from_spec(spec).unwrap();
        for d in [
            Vector3::new(5e5, 4.5e6, 350.0),
            Vector3::new(-3.25, 0.5, 1.0),
        ] {
            let expected = Model::from_spec(&transformed(spec, &Matrix3::identity(), &d)).unwrap();
            let moved = model.translated(&d);
            let point_tol = 4.0 * f64::EPSILON * d.norm().max(model.size);
            let rel = 1e-12;
            // Directions the builder derives from points (a base's normal and edges from its
            // corners) carry the points' rounding over the feature's length (0.2 m at least).
            let derived = rel + 2.0 * point_tol / 0.2;
            assert_eq!(moved.coords.len(), expected.coords.len(), "{name}");
            assert_eq!(moved.closures, expected.closures, "{name}");
            assert_eq!(moved.body_coord, expected.body_coord, "{name}");
            assert!(
                (moved.size - expected.size).abs() <= 1e-9 * model.size,
                "{name}"
            );
            for (a, b) in moved.bodies.iter().zip(&expected.bodies) {
                assert!(
                    close(&a.com, &b.com, point_tol),
                    "{name}: {} {} {}",
                    a.name,
                    a.com,
                    b.com
                );
                assert!(
                    (a.mass - b.mass).abs() <= rel * b.mass,
                    "{name}: {}",
                    a.name
                );
                let scale = b.inertia.norm();
                assert!(
                    (a.inertia - b.inertia).norm() <= 1e-9 * scale,
                    "{name}: {}",
                    a.name
                );
                // The moved shape has the moved centre: its mass properties from scratch.
                let props = a.shape.mass_properties().unwrap();
                assert!(
                    close(&props.centroid, &b.com, 1e-9 * model.size + point_tol),
                    "{name}: {} shape at {}, body at {}",
                    a.name,
                    props.centroid,
                    b.com
                );
            }
            for (a, b) in moved.interfaces.iter().zip(&expected.interfaces) {
                assert_eq!(
                    (a.parent, a.child, a.role, &a.slots),
                    (b.parent, b.child, b.role, &b.slots)
                );
                match (&a.kind, &b.kind) {
                    (
                        InterfaceKind::Hinge {
                            axis: ua,
                            pivot_positive: pa,
                            pivot_negative: na,
                        },
                        InterfaceKind::Hinge {
                            axis: ub,
                            pivot_positive: pb,
                            pivot_negative: nb,
                        },
                    ) => {
                        assert!(close(ua, ub, derived), "{name}: {}", a.name);
                        // A point of each pivot line: the same line (the offset along the axis
                        // is free).
                        for (p, q) in [(pa, pb), (na, nb)] {
                            let off = p - q;
                            let across = off - ub * ub.dot(&off);
                            assert!(across.norm() <= point_tol, "{name}: {} {p} {q}", a.name);
                        }
                    }
                    (
                        InterfaceKind::RockingBase {
                            corners: ca,
                            normal: na,
                            e1: a1,
                            e2: a2,
                            twist: ta,
                        },
                        InterfaceKind::RockingBase {
                            corners: cb,
                            normal: nb,
                            e1: b1,
                            e2: b2,
                            twist: tb,
                        },
                    ) => {
                        for (p, q) in ca.iter().zip(cb) {
                            assert!(close(p, q, point_tol), "{name}: {} {p} {q}", a.name);
                        }
                        assert!(
                            close(na, nb, derived)
                                && close(a1, b1, derived)
                                && close(a2, b2, derived),
                            "{name}: {} {na} {nb} {a1} {b1}",
                            a.name
                        );
                        assert_eq!(ta, tb);
                    }
                    _ => panic!("{name}: {} changed kind", a.name),
                }
            }
            for (a, b) in moved.coords.iter().zip(&expected.coords) {
                assert!(close(&a.axis, &b.axis, derived), "{name}: {}", a.name);
                assert_eq!(
                    (a.interface, a.component, a.parent),
                    (b.interface, b.component, b.parent)
                );
            }
        }
    }
}

/// The move near the origin (`Model::moved_near_origin`) is exact and does not depend on the
/// order of the file: a trilithon, a colonnade, a random chain with loops and a 3D wall written
/// about 5e5 m east, 4.5e6 m north and 350 m up (digits to the micrometre), with their bodies and
/// interfaces listed as built and reversed. Every body's centre and
/// every corner or pivot point moves by one and the same vector to the bit (no coordinate is
/// rounded), and both orders give the same moved points to the bit.
#[test]
fn the_move_near_the_origin_is_exact_and_independent_of_the_order() {
    let survey = Vector3::new(500_123.456_789, 4_500_987.654_321, 351.234_567);
    for spec in [
        trilithon(0.25, 2.0, 3.0, 0.6, 1.0),
        colonnade(0.2, 1.5, 2.4, 0.4),
        random_chain(7, 6, 2),
        running_bond_wall_3d(3, 3, 1.0, 0.5, 0.4),
    ] {
        let far = transformed(&spec, &Matrix3::identity(), &survey);
        let mut reversed = far.clone();
        reversed.body.reverse();
        reversed.interface.reverse();
        let points = |m: &Model| -> Vec<(String, Vector3<f64>)> {
            let mut p: Vec<_> = m.bodies.iter().map(|b| (b.name.clone(), b.com)).collect();
            for i in &m.interfaces {
                let at = match &i.kind {
                    InterfaceKind::Hinge {
                        pivot_positive,
                        pivot_negative,
                        ..
                    } => vec![*pivot_positive, *pivot_negative],
                    InterfaceKind::RockingBase { corners, .. } => corners.to_vec(),
                };
                p.extend(at.into_iter().map(|x| (i.name.clone(), x)));
            }
            p.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.x.total_cmp(&b.1.x)));
            p
        };
        let mut moved_points = Vec::new();
        for written in [&far, &reversed] {
            let model = Model::from_spec(written).unwrap();
            let moved = model.moved_near_origin().expect("far from the origin");
            let (given, near) = (points(&model), points(&moved));
            let shift = given[0].1 - near[0].1;
            for ((name, p), (_, q)) in given.iter().zip(&near) {
                assert_eq!(
                    p - q,
                    shift,
                    "{name}: moved by {} instead of {shift}",
                    p - q
                );
                assert!(q.norm() < 10.0 * model.size, "{name} at {q}");
            }
            moved_points.push(near);
        }
        assert_eq!(moved_points[0], moved_points[1]);
    }
}
