//! The contact faces at the model's precision: directions of the faces' frames that agree to
//! it made equal.
//!
//! A model's geometry is known to [`crr_kinematics::GEOMETRY_TOLERANCE`] of its size (faces
//! whose corners lie off their plane by that much are planar to it), and an OBJ file written
//! with six decimals, or a structure given at survey coordinates, carries round-off of that
//! order in every face's frame. The statics' mechanisms depend on exact relations between
//! frames that round-off breaks: a block between two parallel head joints turns out of its
//! wall's plane by sliding in both only where their normals are parallel (else it is wedged
//! between them, however little they differ), and a block tips away from its neighbour about
//! its foot without closing their joint only where the joint's normal is square to the foot.
//! Written exactly, such a wall's multiplier is 0.514286 out of its plane; turned 40° at survey
//! coordinates it answered 0.545455, marked exhaustive (an independent review, 2026-12-07).
//!
//! So every direction of a face's frame (its normal and tangents) within [`SAME_DIRECTION`]
//! of one met before (up to sign, in the order of the interfaces) is replaced by it, and each
//! face's tangents are made square to its normal again. Directions that differ by more than
//! the model's precision are left as they are; those of an exact model move by round-off only.
use nalgebra::Vector3;

use crr_kinematics::{ContactFace, GEOMETRY_TOLERANCE, Model, contact_faces};

/// Angle (rad) within which two directions of faces' frames are the same direction: ten times
/// the model's relative precision. Six decimals (±5e-7 m) on an edge of 0.1 m turn it by up to
/// 7e-6 rad; a structure's distinct directions differ by far more (the joints of an arch of
/// 321 voussoirs by 1e-2 rad).
pub(super) const SAME_DIRECTION: f64 = 10.0 * GEOMETRY_TOLERANCE;

/// The model's contact faces ([`contact_faces`]) with their frames' directions that agree to
/// [`SAME_DIRECTION`] made equal.
pub(super) fn faces_at_precision(model: &Model) -> Vec<ContactFace> {
    let mut faces = contact_faces(model);
    let mut directions = Directions::default();
    for face in &mut faces {
        let normal = directions.snap(face.normal);
        let first = directions.snap(face.tangents[0]);
        // Square to the normal again (the two representatives may be 1e-5 off square).
        let first = (first - normal * normal.dot(&first)).normalize();
        let second = normal.cross(&first);
        for couple in &mut face.bilateral_couples {
            *couple = if couple.dot(&face.normal).abs() > 0.5 {
                normal
            } else {
                first
            };
        }
        face.normal = normal;
        face.tangents = [first, second];
    }
    faces
}

/// The directions met so far, each the representative of those within [`SAME_DIRECTION`].
#[derive(Default)]
struct Directions(Vec<Vector3<f64>>);

impl Directions {
    /// The representative of the unit vector `v` (with v's sign), `v` itself where none is
    /// near: it is then one.
    fn snap(&mut self, v: Vector3<f64>) -> Vector3<f64> {
        for r in &self.0 {
            if r.cross(&v).norm() <= SAME_DIRECTION {
                return if r.dot(&v) >= 0.0 { *r } else { -*r };
            }
        }
        self.0.push(v);
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directions within the precision become one, up to sign; those farther apart stay.
    #[test]
    fn directions_within_the_precision_become_one() {
        let mut directions = Directions::default();
        let a = Vector3::new(0.866_025_4, 0.5, 0.0).normalize();
        let near = Vector3::new(0.866_025_4, 0.500_001, 0.0).normalize();
        let far = Vector3::new(0.866_025_4, 0.51, 0.0).normalize();
        assert!(a.cross(&near).norm() < SAME_DIRECTION);
        assert!(a.cross(&far).norm() > 1e-3);
        assert_eq!(directions.snap(a), a);
        assert_eq!(directions.snap(near), a);
        assert_eq!(directions.snap(-near), -a);
        assert_eq!(directions.snap(far), far);
    }

    /// Every face's frame stays right-handed and orthonormal, and an exact model's faces move
    /// by round-off only (a 3D running-bond wall of 3 courses: beds along x and y).
    #[test]
    fn frames_stay_orthonormal_and_exact_faces_move_by_round_off_only() {
        let spec = crr_kinematics::fixtures::running_bond_wall_3d(3, 3, 0.5, 0.25, 0.3);
        let model = Model::from_spec(&spec).unwrap();
        let exact = contact_faces(&model);
        let snapped = faces_at_precision(&model);
        for (e, s) in exact.iter().zip(&snapped) {
            let [t1, t2] = s.tangents;
            assert!((t1.cross(&t2) - s.normal).norm() < 1e-15);
            assert!(t1.dot(&s.normal).abs() < 1e-15 && t2.dot(&s.normal).abs() < 1e-15);
            assert!((e.normal - s.normal).norm() < 1e-15);
            assert!((e.tangents[0] - t1).norm() < 1e-15 && (e.tangents[1] - t2).norm() < 1e-15);
            assert_eq!(e.points, s.points);
        }
    }
}
