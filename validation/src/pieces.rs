//! A body's real shape as convex pieces (vertex sets, world coordinates at rest), the colliders
//! rapier needs: box → one cuboid hull, polyhedron → its hull, prism → one hull when its polygon
//! is convex, else one triangular prism per ear of the polygon, annular sector → sub-sectors
//! whose flat intrados chords keep them convex (a voussoir's concave intrados needs a compound).

use crr::kinematics::shapes::{AnnularSectorShape, BoxShape, PrismShape, Shape};
use nalgebra::{Point3, Vector3};

/// Largest angle of one piece of an annular sector (rad): 2°, so the flat outer face of a piece
/// departs from the extrados by at most R(1 − cos 1°) = 1.5e-4 R; the joint faces are exact.
pub const SECTOR_PIECE_ANGLE: f64 = std::f64::consts::PI / 90.0;

/// The convex pieces of `shape`, each a set of points whose hull it is.
pub fn convex_pieces(shape: &Shape) -> Vec<Vec<Point3<f64>>> {
    match shape {
        Shape::Box(b) => vec![box_corners(b)],
        Shape::Polyhedron(p) => vec![p.vertices.iter().map(|v| Point3::from(*v)).collect()],
        Shape::Prism(p) => prism_pieces(p),
        Shape::AnnularSector(s) => sector_pieces(s),
        Shape::Compound(parts) => parts.iter().flat_map(convex_pieces).collect(),
    }
}

fn box_corners(b: &BoxShape) -> Vec<Point3<f64>> {
    let r = b.rotation_matrix();
    let c = Vector3::from(b.center);
    let h = Vector3::from(b.size) * 0.5;
    let mut out = Vec::with_capacity(8);
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                out.push(Point3::from(
                    c + r * Vector3::new(sx * h.x, sy * h.y, sz * h.z),
                ));
            }
        }
    }
    out
}

fn prism_pieces(p: &PrismShape) -> Vec<Vec<Point3<f64>>> {
    let poly: Vec<Vector3<f64>> = p.polygon.iter().map(|v| Vector3::from(*v)).collect();
    let e = Vector3::from(p.extrude);
    let sweep = |pts: &[Vector3<f64>]| -> Vec<Point3<f64>> {
        pts.iter()
            .flat_map(|v| [Point3::from(*v), Point3::from(v + e)])
            .collect()
    };
    let normal = polygon_normal(&poly);
    if is_convex(&poly, &normal) {
        return vec![sweep(&poly)];
    }
    ear_clip(&poly, &normal)
        .into_iter()
        .map(|[a, b, c]| sweep(&[poly[a], poly[b], poly[c]]))
        .collect()
}

/// Newell's normal of a planar polygon (its length is twice the area).
fn polygon_normal(poly: &[Vector3<f64>]) -> Vector3<f64> {
    let mut n = Vector3::zeros();
    for i in 0..poly.len() {
        n += poly[i].cross(&poly[(i + 1) % poly.len()]);
    }
    n
}

fn turn(a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>, normal: &Vector3<f64>) -> f64 {
    (b - a).cross(&(c - b)).dot(normal)
}

fn is_convex(poly: &[Vector3<f64>], normal: &Vector3<f64>) -> bool {
    let n = poly.len();
    (0..n).all(|i| turn(&poly[i], &poly[(i + 1) % n], &poly[(i + 2) % n], normal) >= 0.0)
}

/// Triangles of a simple polygon by ear clipping (indices into `poly`).
fn ear_clip(poly: &[Vector3<f64>], normal: &Vector3<f64>) -> Vec<[usize; 3]> {
    let mut idx: Vec<usize> = (0..poly.len()).collect();
    let mut out = Vec::new();
    // Each pass removes one ear; a simple polygon always has one, the bound guards bad input.
    let mut guard = poly.len() * poly.len();
    while idx.len() > 3 && guard > 0 {
        guard -= 1;
        let m = idx.len();
        let ear = (0..m).find(|&i| {
            let (a, b, c) = (idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]);
            if turn(&poly[a], &poly[b], &poly[c], normal) <= 0.0 {
                return false;
            }
            idx.iter().all(|&k| {
                k == a
                    || k == b
                    || k == c
                    || !inside(&poly[k], [&poly[a], &poly[b], &poly[c]], normal)
            })
        });
        let Some(i) = ear else { break };
        out.push([idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]]);
        idx.remove(i);
    }
    if idx.len() == 3 {
        out.push([idx[0], idx[1], idx[2]]);
    }
    out
}

fn inside(p: &Vector3<f64>, [a, b, c]: [&Vector3<f64>; 3], normal: &Vector3<f64>) -> bool {
    turn(a, b, p, normal) >= 0.0 && turn(b, c, p, normal) >= 0.0 && turn(c, a, p, normal) >= 0.0
}

fn sector_pieces(s: &AnnularSectorShape) -> Vec<Vec<Point3<f64>>> {
    let Ok(frame) = s.frame() else {
        return Vec::new();
    };
    let (es, et, w) = (
        frame.column(0).into_owned(),
        frame.column(1).into_owned(),
        frame.column(2).into_owned(),
    );
    let c = Vector3::from(s.center);
    let span = s.to_angle - s.from_angle;
    // (A span of whole pieces must not gain one from round-off.)
    let count = (span / SECTOR_PIECE_ANGLE - 1e-9).ceil().max(1.0) as usize;
    let at =
        |r: f64, th: f64, z: f64| Point3::from(c + (es * th.cos() + et * th.sin()) * r + w * z);
    (0..count)
        .map(|k| {
            let (t0, t1) = (
                s.from_angle + span * k as f64 / count as f64,
                s.from_angle + span * (k + 1) as f64 / count as f64,
            );
            let mut pts = Vec::with_capacity(12);
            for z in [-0.5 * s.thickness, 0.5 * s.thickness] {
                for th in [t0, t1] {
                    pts.push(at(s.inner_radius, th, z));
                    pts.push(at(s.outer_radius, th, z));
                }
                // The extrados is convex: its mid-arc point belongs to the piece.
                pts.push(at(s.outer_radius, 0.5 * (t0 + t1), z));
            }
            pts
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crr::kinematics::shapes::PolyhedronShape;

    /// The volume of a convex hull of points, by rapier/parry's own hull (independent of crr's
    /// exact mass properties).
    fn hull_volume(pts: &[Point3<f64>]) -> f64 {
        use rapier3d_f64::prelude::*;
        let v: Vec<Vector> = pts.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
        let c = ColliderBuilder::convex_hull(&v).unwrap().build();
        c.shape().mass_properties(1.0).mass()
    }

    #[test]
    fn pieces_fill_the_shapes_volume() {
        let boxed = Shape::Box(BoxShape {
            center: [0.1, 0.2, 1.0],
            size: [0.4, 0.6, 2.0],
            rotation: Some([0.1, -0.2, 0.3]),
        });
        // An L-shaped prism (concave): area 0.75 × height 0.5.
        let prism = Shape::Prism(PrismShape {
            polygon: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 0.5, 0.0],
                [0.5, 0.5, 0.0],
                [0.5, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            extrude: [0.0, 0.0, 0.5],
        });
        let tetra = Shape::Polyhedron(PolyhedronShape {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
        });
        // Exact volumes: 0.48, 0.375, 1/6; the pieces of these polyhedral shapes are exact.
        for (shape, volume) in [(boxed, 0.48), (prism, 0.375), (tetra, 1.0 / 6.0)] {
            let pieces = convex_pieces(&shape);
            let v: f64 = pieces.iter().map(|p| hull_volume(p)).sum();
            assert!(
                (v - volume).abs() < 1e-12,
                "{}: {v} vs {volume}",
                shape.kind()
            );
        }
        // A voussoir of 60°: the pieces' flat outer faces cut segments of height R(1 − cos δ/4)
        // (δ = 2°, with the mid-arc point) and the inner chords add segments of R(1 − cos δ/2):
        // the hull volume differs from the exact one by far less than 1e-3 relative.
        let sector = AnnularSectorShape {
            center: [0.0, 0.0, 0.0],
            axis: [0.0, 1.0, 0.0],
            inner_radius: 2.0,
            outer_radius: 2.5,
            start: [1.0, 0.0, 0.0],
            from_angle: 0.0,
            to_angle: std::f64::consts::FRAC_PI_3,
            thickness: 0.6,
        };
        let exact = 0.5 * (2.5f64.powi(2) - 2.0f64.powi(2)) * std::f64::consts::FRAC_PI_3 * 0.6;
        let pieces = convex_pieces(&Shape::AnnularSector(sector));
        assert_eq!(pieces.len(), 30);
        let v: f64 = pieces.iter().map(|p| hull_volume(p)).sum();
        assert!(((v - exact) / exact).abs() < 1e-3, "{v} vs {exact}");
    }
}
