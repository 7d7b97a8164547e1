//! Whether two blocks of an assembly interpenetrate, and by how much: blocks in contact touch
//! along faces, so any overlap of their volumes deeper than the contact tolerance is an error
//! of the geometry (a block placed into its neighbour), which `crr assemble` reports by name.
//!
//! Two convex blocks are tested exactly by the separating-axis theorem: they are apart (or only
//! touch) when their projections on some axis overlap by at most the tolerance, the candidate
//! axes being the face normals of both and the cross products of their edges; otherwise the
//! least overlap over those axes is the depth by which one must move to free the other. A
//! non-convex block (an annular sector's concave intrados) is tested by its points: the vertices,
//! edge midpoints and face centroids of each block that lie inside the other (winding number of
//! its closed surface) deeper than the tolerance (distance to its surface); an overlap that none
//! of those points enters (two long bars crossing) is not seen.

use nalgebra::Vector3;

use crate::shapes::Surface;

/// How two blocks interpenetrate.
#[derive(Clone, Debug, PartialEq)]
pub struct Penetration {
    /// Depth (m): the least translation that separates them (convex blocks), or the depth of the
    /// deepest point of one found inside the other.
    pub depth: f64,
    /// A point of the overlap (the deepest point found) or near it (convex blocks: the blocks'
    /// mean centre moved to the middle of the overlap along the axis of least overlap), m.
    pub point: Vector3<f64>,
}

/// The interpenetration of the closed surfaces `a` and `b` deeper than `tolerance` (m), if any.
pub fn interpenetration(a: &Surface, b: &Surface, tolerance: f64) -> Option<Penetration> {
    if is_convex(a, tolerance) && is_convex(b, tolerance) {
        separating_axes(a, b, tolerance)
    } else {
        deepest_point_inside(a, b, tolerance).or_else(|| deepest_point_inside(b, a, tolerance))
    }
}

/// Unit outward normals of the faces of `s` (faces of no area left out).
fn face_normals(s: &Surface) -> Vec<Vector3<f64>> {
    (0..s.faces.len())
        .filter_map(|f| s.face_area_vector(f).try_normalize(0.0))
        .collect()
}

/// Every vertex lies on the inner side of every face's plane (to the tolerance).
fn is_convex(s: &Surface, tolerance: f64) -> bool {
    (0..s.faces.len()).all(|f| {
        let Some(n) = s.face_area_vector(f).try_normalize(0.0) else {
            return true;
        };
        let offset = n.dot(&s.vertices[s.faces[f][0]]);
        s.vertices.iter().all(|v| n.dot(v) - offset <= tolerance)
    })
}

/// The edges of `s` as vectors (each once per face that has it).
fn edges(s: &Surface) -> impl Iterator<Item = (Vector3<f64>, Vector3<f64>)> + '_ {
    s.faces.iter().flat_map(move |face| {
        let m = face.len();
        (0..m).map(move |i| (s.vertices[face[i]], s.vertices[face[(i + 1) % m]]))
    })
}

/// The interval of the projections of `s`'s vertices on `axis`.
fn projection(s: &Surface, axis: &Vector3<f64>) -> (f64, f64) {
    s.vertices
        .iter()
        .map(|v| axis.dot(v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        })
}

/// The separating-axis test of two convex blocks.
fn separating_axes(a: &Surface, b: &Surface, tolerance: f64) -> Option<Penetration> {
    let mut axes = face_normals(a);
    axes.extend(face_normals(b));
    let edge_directions = |s: &Surface| -> Vec<Vector3<f64>> {
        edges(s)
            .filter_map(|(p, q)| (q - p).try_normalize(1e-12))
            .collect()
    };
    let (ea, eb) = (edge_directions(a), edge_directions(b));
    for u in &ea {
        for v in &eb {
            if let Some(axis) = u.cross(v).try_normalize(1e-9) {
                axes.push(axis);
            }
        }
    }
    let mut least: Option<(f64, Vector3<f64>, f64)> = None;
    for axis in axes {
        let ((lo_a, hi_a), (lo_b, hi_b)) = (projection(a, &axis), projection(b, &axis));
        let (lo, hi) = (lo_a.max(lo_b), hi_a.min(hi_b));
        let overlap = hi - lo;
        if overlap <= tolerance {
            return None;
        }
        if least.is_none_or(|(d, _, _)| overlap < d) {
            least = Some((overlap, axis, 0.5 * (lo + hi)));
        }
    }
    let (depth, axis, middle) = least?;
    // A point near the overlap, for the message: the mean of the two blocks' vertex centroids,
    // moved to the middle of the overlap along the axis of least overlap.
    let centre = |s: &Surface| s.vertices.iter().sum::<Vector3<f64>>() / s.vertices.len() as f64;
    let c = 0.5 * (centre(a) + centre(b));
    Some(Penetration {
        depth,
        point: c + axis * (middle - axis.dot(&c)),
    })
}

/// The points of `a` tested against `b`: vertices, edge midpoints and face centroids.
fn sample_points(a: &Surface) -> Vec<Vector3<f64>> {
    let mut points = a.vertices.clone();
    points.extend(edges(a).map(|(p, q)| 0.5 * (p + q)));
    points.extend(
        a.faces.iter().map(|face| {
            face.iter().map(|&i| a.vertices[i]).sum::<Vector3<f64>>() / face.len() as f64
        }),
    );
    points
}

/// The triangles of the faces of `s` (fans from each face's first vertex).
fn triangles(s: &Surface) -> impl Iterator<Item = [Vector3<f64>; 3]> + '_ {
    s.faces.iter().flat_map(move |face| {
        (1..face.len().saturating_sub(1)).map(move |k| {
            [
                s.vertices[face[0]],
                s.vertices[face[k]],
                s.vertices[face[k + 1]],
            ]
        })
    })
}

/// The distance (m) from `p` to the closed surface `s`: the least over its faces' triangles.
pub fn distance_to_surface(s: &Surface, p: &Vector3<f64>) -> f64 {
    triangles(s)
        .map(|t| distance_to_triangle(p, &t))
        .fold(f64::INFINITY, f64::min)
}

/// The winding number of the closed surface `s` about `p` (1 inside, 0 outside): the solid
/// angles of its triangles seen from p (Van Oosterom & Strackee 1983) over 4π.
fn winding_number(s: &Surface, p: &Vector3<f64>) -> f64 {
    triangles(s)
        .map(|[a, b, c]| {
            let (a, b, c) = (a - p, b - p, c - p);
            let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
            let numerator = a.dot(&b.cross(&c));
            let denominator = la * lb * lc + a.dot(&b) * lc + a.dot(&c) * lb + b.dot(&c) * la;
            2.0 * numerator.atan2(denominator)
        })
        .sum::<f64>()
        / (4.0 * std::f64::consts::PI)
}

/// The distance from `p` to the triangle (a, b, c) (Ericson 2005, closest point on a triangle).
fn distance_to_triangle(p: &Vector3<f64>, [a, b, c]: &[Vector3<f64>; 3]) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.norm();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.norm();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (p - (a + ab * (d1 / (d1 - d3)))).norm();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.norm();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (p - (a + ac * (d2 / (d2 - d6)))).norm();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * w)).norm();
    }
    let denominator = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denominator, vc * denominator);
    (p - (a + ab * v + ac * w)).norm()
}

/// The deepest of `a`'s sample points lying inside `b` deeper than the tolerance.
fn deepest_point_inside(a: &Surface, b: &Surface, tolerance: f64) -> Option<Penetration> {
    sample_points(a)
        .into_iter()
        .filter(|p| winding_number(b, p) > 0.5)
        .map(|p| {
            let depth = triangles(b)
                .map(|t| distance_to_triangle(&p, &t))
                .fold(f64::INFINITY, f64::min);
            Penetration { depth, point: p }
        })
        .filter(|p| p.depth > tolerance)
        .max_by(|x, y| x.depth.total_cmp(&y.depth))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::BoxShape;

    fn cube(center: [f64; 3], size: f64) -> Surface {
        BoxShape {
            center,
            size: [size; 3],
            rotation: None,
        }
        .surface()
        .unwrap()
    }

    /// Two unit cubes: touching along a face is no overlap; moved 0.1 m into each other they
    /// interpenetrate by exactly 0.1 m (the separating axes), and the point-sampling test of
    /// non-convex blocks finds a point at least that deep inside; apart, neither reports.
    #[test]
    fn cubes_touching_apart_and_overlapping() {
        let a = cube([0.0, 0.0, 0.5], 1.0);
        let tol = 1e-6;
        assert_eq!(interpenetration(&a, &cube([1.0, 0.0, 0.5], 1.0), tol), None);
        assert_eq!(interpenetration(&a, &cube([1.5, 0.3, 0.5], 1.0), tol), None);
        let b = cube([0.9, 0.2, 0.5], 1.0);
        let p = interpenetration(&a, &b, tol).expect("overlap");
        assert!((p.depth - 0.1).abs() < 1e-12, "{p:?}");
        assert!(winding_number(&a, &p.point) > 0.5 && winding_number(&b, &p.point) > 0.5);
        let sampled = deepest_point_inside(&a, &b, tol)
            .or_else(|| deepest_point_inside(&b, &a, tol))
            .expect("a point inside");
        assert!((sampled.depth - 0.1).abs() < 1e-12, "{sampled:?}");
        assert_eq!(
            deepest_point_inside(&a, &cube([1.0, 0.0, 0.5], 1.0), tol),
            None
        );
    }

    /// The winding number is 1 inside a closed surface and 0 outside, and the distance to a
    /// triangle is the distance to its plane over its interior, to an edge or to a vertex beyond.
    #[test]
    fn winding_number_and_triangle_distance() {
        let a = cube([0.0, 0.0, 0.0], 2.0);
        assert!((winding_number(&a, &Vector3::new(0.3, -0.2, 0.9)) - 1.0).abs() < 1e-12);
        assert!(winding_number(&a, &Vector3::new(1.3, 0.0, 0.0)).abs() < 1e-12);
        let t = [Vector3::zeros(), Vector3::x(), Vector3::y()];
        let d = |p: [f64; 3]| distance_to_triangle(&Vector3::from(p), &t);
        assert!((d([0.2, 0.2, 0.7]) - 0.7).abs() < 1e-15);
        assert!((d([0.5, -1.0, 0.0]) - 1.0).abs() < 1e-15);
        assert!((d([2.0, 0.0, 0.0]) - 1.0).abs() < 1e-15);
        assert!((d([1.0, 1.0, 0.0]) - 0.5f64.sqrt()).abs() < 1e-15);
    }

    /// The distance to a cube of side 2 centred at the origin, by hand: 0 on a face, an edge or
    /// a corner; a point inside, its distance to the nearest face; outside beside a face, the
    /// excess of its coordinate; beyond a corner, the length of the excess vector.
    #[test]
    fn distance_to_a_cube_s_surface() {
        let a = cube([0.0, 0.0, 0.0], 2.0);
        let d = |p: [f64; 3]| distance_to_surface(&a, &Vector3::from(p));
        assert!(d([1.0, 0.3, -0.2]).abs() < 1e-15);
        assert!(d([1.0, 1.0, 0.5]).abs() < 1e-15);
        assert!(d([1.0, -1.0, 1.0]).abs() < 1e-15);
        assert!((d([0.2, 0.5, -0.1]) - 0.5).abs() < 1e-15);
        assert!((d([3.0, 0.5, 0.0]) - 2.0).abs() < 1e-15);
        assert!((d([2.0, 2.0, 3.0]) - 6.0f64.sqrt()).abs() < 1e-15);
    }
}
