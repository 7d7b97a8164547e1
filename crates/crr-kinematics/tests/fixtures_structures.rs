//! The masonry fixtures (`voussoir_arch`, `stacked_panel`, `running_bond_wall`,
//! `running_bond_wall_3d`): `Model::from_spec` accepts them, their masses add up to the closed-form
//! volume × density, and every interface's face normal points from its parent into its child.
//!
//! Masses to 1e-12 relative: exact closed forms summed over at most a few dozen bodies. The
//! normal's side is a sign test with a margin of 1e-9 of the model's size.

use crr_kinematics::fixtures::{
    MASONRY_DENSITY, running_bond_wall, running_bond_wall_3d, stacked_panel, voussoir_arch,
};
use crr_kinematics::spec::StructureSpec;
use crr_kinematics::{InterfaceKind, Model, Parent};
use nalgebra::Vector3;

fn model(spec: &StructureSpec) -> Model {
    Model::from_spec(spec).unwrap_or_else(|e| panic!("{} is refused: {e}", spec.name))
}

/// The face normal of every interface points into its child: the child's centre lies on the +n
/// side of the face and a parent body's on the −n side. A hinge's n is u × (P⁻ − P⁺)/|…| (the
/// convention of the model format); a rocking base's is the model's own.
fn check_normals(m: &Model) -> Vec<Vector3<f64>> {
    let tol = 1e-9 * m.size;
    m.interfaces
        .iter()
        .map(|i| {
            let (n, point) = match &i.kind {
                InterfaceKind::Hinge {
                    axis,
                    pivot_positive,
                    pivot_negative,
                } => (
                    axis.cross(&(pivot_negative - pivot_positive)).normalize(),
                    *pivot_positive,
                ),
                InterfaceKind::RockingBase {
                    corners, normal, ..
                } => (*normal, corners[0]),
            };
            let child = n.dot(&(m.bodies[i.child].com - point));
            assert!(child > tol, "{}: child on the −n side ({child})", i.name);
            if let Parent::Body(p) = i.parent {
                let parent = n.dot(&(m.bodies[p].com - point));
                assert!(
                    parent < -tol,
                    "{}: parent on the +n side ({parent})",
                    i.name
                );
            }
            n
        })
        .collect()
}

fn close(a: f64, b: f64, rtol: f64) -> bool {
    (a - b).abs() <= rtol * b.abs()
}

#[test]
fn voussoir_arches() {
    for n in [1, 2, 3, 5, 9, 17, 41] {
        let (r_in, r_out, depth) = (2.0, 2.5, 0.8);
        let m = model(&voussoir_arch(n, r_in, r_out, depth));
        assert_eq!(m.bodies.len(), n);
        assert_eq!(m.interfaces.len(), n + 1);
        // Half an annulus: (π/2)(r_out² − r_in²) depth.
        let volume = std::f64::consts::FRAC_PI_2 * (r_out * r_out - r_in * r_in) * depth;
        assert!(close(m.total_mass(), MASONRY_DENSITY * volume, 1e-12));
        let normals = check_normals(&m);
        // n is the direction of increasing angle at the inner joints, +z at both springings.
        let step = std::f64::consts::PI / n as f64;
        for (j, n_j) in normals.iter().enumerate() {
            let expected = if j == n {
                Vector3::z()
            } else {
                let beta = step * j as f64;
                Vector3::new(-beta.sin(), 0.0, beta.cos())
            };
            assert!((n_j - expected).norm() < 1e-12, "joint {j}: {n_j:?}");
        }
        // The voussoirs' centres lie on the bisectors of their sectors, at the closed-form
        // radius (2/3)(r_out³ − r_in³)/(r_out² − r_in²) · sin(δ/2)/(δ/2).
        let rc = 2.0 / 3.0 * (r_out.powi(3) - r_in.powi(3)) / (r_out.powi(2) - r_in.powi(2))
            * (step / 2.0).sin()
            / (step / 2.0);
        for (k, b) in m.bodies.iter().enumerate() {
            let mid = step * (k as f64 + 0.5);
            let c = Vector3::new(rc * mid.cos(), 0.0, rc * mid.sin());
            assert!((b.com - c).norm() < 1e-12 * r_out, "{}", b.name);
        }
    }
}

#[test]
fn stacked_panels() {
    for courses in [1, 2, 3, 7] {
        let (b, h, depth) = (0.3, 1.2, 0.5);
        let m = model(&stacked_panel(courses, b, h, depth));
        assert_eq!(m.bodies.len(), courses);
        assert_eq!(m.dof(), courses);
        assert!(close(
            m.total_mass(),
            MASONRY_DENSITY * 2.0 * b * 2.0 * h * depth,
            1e-12
        ));
        for n in check_normals(&m) {
            assert!((n - Vector3::z()).norm() < 1e-12);
        }
    }
}

/// Bodies and interfaces of a running-bond wall counted by hand: even courses have `blocks`
/// blocks, odd ones `blocks + 1`; a course-0 block has one contact (the ground), a whole block of
/// a higher course two, a half block one.
#[test]
fn running_bond_walls() {
    for (courses, blocks) in [(1, 1), (2, 1), (3, 3), (4, 4), (5, 2)] {
        let (l, hb, depth) = (0.4, 0.2, 0.3);
        let odd = courses / 2;
        let bodies = courses * blocks + odd;
        let interfaces = blocks + (courses - 1) * 2 * blocks;
        let volume = (courses * blocks) as f64 * l * hb * depth;
        for spec in [
            running_bond_wall(courses, blocks, l, hb, depth),
            running_bond_wall_3d(courses, blocks, l, hb, depth),
        ] {
            let m = model(&spec);
            assert_eq!(m.bodies.len(), bodies, "{}", spec.name);
            assert_eq!(m.interfaces.len(), interfaces, "{}", spec.name);
            assert!(close(m.total_mass(), MASONRY_DENSITY * volume, 1e-12));
            for n in check_normals(&m) {
                assert!((n - Vector3::z()).norm() < 1e-12);
            }
            // Every course spans [−L_tot/2, L_tot/2] without gaps: the bodies of one course add
            // up to the course's volume.
            for c in 0..courses {
                let v: f64 = m
                    .bodies
                    .iter()
                    .filter(|b| b.name.starts_with(&format!("c{c}_")))
                    .map(|b| b.volume)
                    .sum();
                assert!(close(v, blocks as f64 * l * hb * depth, 1e-12));
            }
            // Names: c{course}_b{index}, index from −x.
            let first = &m.bodies[m.body_index("c0_b0").expect("c0_b0")];
            assert!(close(first.com.x, (1.0 - blocks as f64) * l / 2.0, 1e-12));
            if courses > 1 {
                let half = &m.bodies[m.body_index("c1_b0").expect("c1_b0")];
                assert!(close(
                    half.com.x,
                    -(blocks as f64) * l / 2.0 + l / 4.0,
                    1e-12
                ));
                assert!(close(half.volume, l / 2.0 * hb * depth, 1e-12));
            }
        }
    }
}
