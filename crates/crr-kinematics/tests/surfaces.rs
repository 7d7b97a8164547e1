//! The bodies' surfaces moved by the kinematics (`body_points`): rigid, carried with the centre
//! of mass the kinematics computes, and with every tree interface's active pivot where the
//! parent holds it (on the ground, or on the neighbour).

use crr_kinematics::fixtures::{SplitMix, four_hinge_arch, random_chain, trilithon};
use crr_kinematics::*;
use nalgebra::{DVector, Vector3};

/// Random q (±0.6 rad) and pivots for `model`.
fn random_state(model: &Model, seed: u64) -> (DVector<f64>, ActivePivots) {
    let mut rng = SplitMix(seed);
    let q = DVector::from_fn(model.dof(), |_, _| rng.uniform(-0.6, 0.6));
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    for s in pivots.sides.iter_mut() {
        if rng.below(2) == 0 {
            *s = Side::Negative;
        }
    }
    (q, pivots)
}

/// Checks the moved surfaces of every body of `spec` at a few random states. Tolerances:
/// 1e-12 × the model size, a few hundred ulps of the coordinates after the tens of products
/// of a chain's composition; the discretised annular sectors' centroids are compared with
/// their own discretised centroid at rest, moved.
fn check(spec: &StructureSpec, seeds: std::ops::Range<u64>) {
    let model = Model::from_spec(spec).unwrap();
    let surfaces: Vec<shapes::Surface> = model
        .bodies
        .iter()
        .map(|b| b.shape.surface().unwrap())
        .collect();
    let mut data = Data::new(&model);
    let tol = 1e-12 * model.size;
    for seed in seeds {
        let (q, pivots) = random_state(&model, seed);
        forward_kinematics(&model, &mut data, &q, &pivots);
        let mut moved: Vec<Vec<Vector3<f64>>> = Vec::new();
        for (b, s) in surfaces.iter().enumerate() {
            let mut out = Vec::new();
            body_points(&model, &data, b, &s.vertices, &mut out);
            // Rigid: every distance between vertices is kept.
            for i in 0..out.len() {
                for j in i + 1..out.len() {
                    let (d0, d1) = (
                        (s.vertices[i] - s.vertices[j]).norm(),
                        (out[i] - out[j]).norm(),
                    );
                    assert!((d0 - d1).abs() <= tol, "body {b}: {d0} vs {d1}");
                }
            }
            // Proper (no mirror): the enclosed volume keeps its sign and size.
            let at_rest = s.volume_centroid();
            let now = shapes::Surface {
                vertices: out.clone(),
                faces: s.faces.clone(),
            }
            .volume_centroid();
            assert!((now.0 - at_rest.0).abs() <= 1e-12 * at_rest.0);
            // The surface's centroid is where the kinematics put the centre of mass (exact
            // shapes: boxes here), or, for a discretised sector, its own rest centroid moved.
            let rest_offset = at_rest.1 - model.bodies[b].com;
            let rot = body_rotation(&model, &data, b);
            assert!(
                (now.1 - (data.com[b] + rot * rest_offset)).norm() <= tol,
                "body {b}: centroid {} vs {}",
                now.1,
                data.com[b]
            );
            if matches!(model.bodies[b].shape, shapes::Shape::Box(_)) {
                assert!(rest_offset.norm() <= tol);
            }
            moved.push(out);
        }
        // Every tree interface's active pivot: the child's point there is the parent's.
        for iface in &model.interfaces {
            if let Role::Tree { .. } = iface.role {
                let p = iface.kind.pivot(&pivots.sides[iface.slots.clone()]);
                let on_child = body_point(&model, &data, iface.child, &p);
                let on_parent = match iface.parent {
                    Parent::Ground => p,
                    Parent::Body(pb) => body_point(&model, &data, pb, &p),
                };
                assert!(
                    (on_child - on_parent).norm() <= tol,
                    "{}: pivot {on_child} vs {on_parent}",
                    iface.name
                );
            }
        }
    }
}

#[test]
fn random_chains_move_their_surfaces_rigidly_about_their_pivots() {
    for seed in 0..6 {
        check(&random_chain(seed, 6, 0), 0..4);
    }
}

#[test]
fn trilithon_and_arch_surfaces_follow_the_kinematics() {
    check(&trilithon(0.25, 2.0, 3.0, 0.5, 0.3), 0..4);
    check(&four_hinge_arch(4.0, 4.6, 0.5, true), 0..4);
}
