//! Rotations about an axis (Rodrigues) and the cross-product matrix.

use nalgebra::{Matrix3, Vector3};

/// The cross-product matrix `[v]×`, so that `[v]× x = v × x`.
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Rotation by `angle` (rad, right-handed) about the unit vector `axis` (Rodrigues' formula):
/// `R = I + sin θ [u]× + (1 − cos θ) [u]×²`.
pub fn axis_angle(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    // I + s[u]× + (1 − c)[u]×², with [u]×² = uuᵀ − |u|²I written out (no 3 × 3 product).
    let (s, c) = angle.sin_cos();
    let d = 1.0 - c;
    let u = axis;
    let diag = 1.0 - d * u.norm_squared();
    let (xy, xz, yz) = (d * u.x * u.y, d * u.x * u.z, d * u.y * u.z);
    Matrix3::new(
        diag + d * u.x * u.x,
        xy - s * u.z,
        xz + s * u.y,
        xy + s * u.z,
        diag + d * u.y * u.y,
        yz - s * u.x,
        xz - s * u.y,
        yz + s * u.x,
        diag + d * u.z * u.z,
    )
}

/// dR/dθ of [`axis_angle`]: `[u]× R(u, θ)`.
pub fn axis_angle_derivative(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    let k = skew(axis);
    let (s, c) = angle.sin_cos();
    k * c + k * k * s
}

/// Rotation matrix of an axis-angle vector (direction = axis, norm = angle in rad).
pub fn rotation_vector(v: &Vector3<f64>) -> Matrix3<f64> {
    let angle = v.norm();
    if angle == 0.0 {
        Matrix3::identity()
    } else {
        axis_angle(&(v / angle), angle)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_angle_is_orthonormal_and_derivative_matches_finite_difference() {
        let u = Vector3::new(1.0, -2.0, 0.5).normalize();
        let r = axis_angle(&u, 0.7);
        // Rᵀ R = I to round-off (1e-15 per entry).
        assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-14);
        assert!((r.determinant() - 1.0).abs() < 1e-14);
        // The axis is fixed by its rotation.
        assert!((r * u - u).norm() < 1e-15);
        // Central difference, h = 1e-6: truncation error O(h²) ≈ 1e-12.
        let h = 1e-6;
        let fd = (axis_angle(&u, 0.7 + h) - axis_angle(&u, 0.7 - h)) / (2.0 * h);
        assert!((fd - axis_angle_derivative(&u, 0.7)).norm() < 1e-9);
    }

    #[test]
    fn quarter_turn_about_z_maps_x_to_y() {
        let r = axis_angle(&Vector3::z(), std::f64::consts::FRAC_PI_2);
        assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
        assert!(
            (rotation_vector(&(Vector3::z() * std::f64::consts::FRAC_PI_2)) - r).norm() < 1e-15
        );
    }
}
