//! 3D convex hull and exact mass properties of convex polyhedra.

use std::collections::HashSet;

use nalgebra::{Matrix3, Vector3};

use super::{MassProperties, ShapeError, any_perpendicular, bbox_diagonal};

/// Relative tolerance (w.r.t. the bounding-box diagonal of the point cloud)
/// below which points are merged and distances to a plane are treated as zero.
pub const HULL_REL_TOL: f64 = 1e-9;

/// The most points a polyhedron may have: the brute-force hull below takes 15 s for 1 000 points
/// spread on a sphere (`cargo bench --bench kinematics -- convex_hull`), and grows as n³ to n⁴
/// (a 3 000-point cloud took more than two minutes).
pub const MAX_HULL_POINTS: usize = 1000;

/// Outward-oriented triangles of the 3D convex hull of `points`.
///
/// Indices refer to `points`. Interior points are ignored; points closer than
/// [`HULL_REL_TOL`] × (bounding-box diagonal) are merged (the first one is
/// used); points lying on a hull face are grouped, each planar face polygon is
/// the 2D convex hull of its points (collinear boundary points dropped) and is
/// fan-triangulated, so the triangles form a closed, consistently oriented
/// surface (counter-clockwise seen from outside).
///
/// Brute force over point triples with early rejection: O(n³) to O(n⁴),
/// intended for up to a few hundred points (38 ms for 200 points spread on a
/// sphere, 1.05 s for 500, 15 s for 1 000: `cargo bench --bench kinematics --
/// convex_hull`); more than `MAX_HULL_POINTS` (1 000) are refused.
///
/// Errors: fewer than 4 points, non-finite coordinates, or all points
/// coplanar (within the tolerance).
pub fn convex_hull_triangles(points: &[Vector3<f64>]) -> Result<Vec<[usize; 3]>, ShapeError> {
    let mut triangles = Vec::new();
    for poly in convex_hull_faces(points)? {
        for w in 1..poly.len().saturating_sub(1) {
            triangles.push([poly[0], poly[w], poly[w + 1]]);
        }
    }
    Ok(triangles)
}

/// The planar faces of the 3D convex hull of `points`, each a convex polygon of indices into
/// `points`, counter-clockwise seen from outside (so the right-hand normal points out).
///
/// Same merging and tolerances as [`convex_hull_triangles`] (which fan-triangulates these
/// polygons): coplanar hull points form one face, collinear boundary points are dropped.
pub fn convex_hull_faces(points: &[Vector3<f64>]) -> Result<Vec<Vec<usize>>, ShapeError> {
    if points.len() > MAX_HULL_POINTS {
        return Err(ShapeError::TooManyPoints {
            found: points.len(),
            limit: MAX_HULL_POINTS,
        });
    }
    if points.len() < 4 {
        return Err(ShapeError::TooFewPoints {
            what: "polyhedron",
            required: 4,
            found: points.len(),
        });
    }
    if points.iter().any(|p| !p.iter().all(|v| v.is_finite())) {
        return Err(ShapeError::NonFinite { field: "vertices" });
    }
    let scale = bbox_diagonal(points);
    if scale == 0.0 {
        return Err(ShapeError::Coplanar);
    }
    let tol = HULL_REL_TOL * scale;
    // Merge (near-)duplicates.
    let mut uniq: Vec<usize> = Vec::new();
    for (i, p) in points.iter().enumerate() {
        if !uniq.iter().any(|&j| (p - points[j]).norm() <= tol) {
            uniq.push(i);
        }
    }
    // Centre for conditioning.
    let centre = uniq.iter().map(|&i| points[i]).sum::<Vector3<f64>>() / uniq.len() as f64;
    let q: Vec<Vector3<f64>> = uniq.iter().map(|&i| points[i] - centre).collect();
    let m = q.len();

    let mut seen: HashSet<Vec<usize>> = HashSet::new();
    let mut faces: Vec<(Vec<usize>, Vector3<f64>)> = Vec::new();
    let mut witnesses = [0usize, m - 1];
    for i in 0..m {
        for j in (i + 1)..m {
            let eij = q[j] - q[i];
            let lij = eij.norm();
            for k in (j + 1)..m {
                let nrm = eij.cross(&(q[k] - q[i]));
                let nn = nrm.norm();
                // Skip triples where k is within tol of the line (i, j).
                if nn <= tol * lij {
                    continue;
                }
                let u = nrm / nn;
                let d0 = u.dot(&q[i]);
                let (mut pos, mut neg) = (false, false);
                // Points that refuted earlier triples are tried first: they
                // usually refute this one too (large speed-up on round shapes).
                for l in witnesses.into_iter().chain(0..m) {
                    let s = u.dot(&q[l]) - d0;
                    if s > tol {
                        pos = true;
                        witnesses[0] = l;
                    } else if s < -tol {
                        neg = true;
                        witnesses[1] = l;
                    }
                    if pos && neg {
                        break;
                    }
                }
                if pos == neg {
                    // Both sides: not a supporting plane; neither: all coplanar.
                    continue;
                }
                let outward = if pos { -u } else { u };
                let set: Vec<usize> = (0..m)
                    .filter(|&l| (u.dot(&q[l]) - d0).abs() <= tol)
                    .collect();
                if seen.insert(set.clone()) {
                    faces.push((set, outward));
                }
            }
        }
    }
    if faces.is_empty() {
        return Err(ShapeError::Coplanar);
    }

    let mut polygons = Vec::with_capacity(faces.len());
    for (set, normal) in &faces {
        let e1 = any_perpendicular(normal);
        let e2 = normal.cross(&e1);
        let pts2: Vec<(usize, [f64; 2])> = set
            .iter()
            .map(|&l| (l, [e1.dot(&q[l]), e2.dot(&q[l])]))
            .collect();
        let poly = convex_hull_2d(pts2, tol);
        if poly.len() >= 3 {
            polygons.push(poly.into_iter().map(|l| uniq[l]).collect());
        }
    }
    Ok(polygons)
}

/// Counter-clockwise 2D convex hull (Andrew's monotone chain); points within
/// `tol` of a hull edge line are dropped. Returns the labels in order.
fn convex_hull_2d(mut pts: Vec<(usize, [f64; 2])>, tol: f64) -> Vec<usize> {
    pts.sort_by(|a, b| {
        a.1[0]
            .total_cmp(&b.1[0])
            .then_with(|| a.1[1].total_cmp(&b.1[1]))
    });
    // `a` is dropped when it lies within tol of (or right of) the line o → b.
    let drop = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        let ob = [b[0] - o[0], b[1] - o[1]];
        let oa = [a[0] - o[0], a[1] - o[1]];
        let cross = ob[0] * oa[1] - ob[1] * oa[0];
        // -cross / |ob| is the distance of a to the right of o → b, where a
        // must lie to be a strictly convex (counter-clockwise) vertex.
        -cross <= tol * (ob[0] * ob[0] + ob[1] * ob[1]).sqrt()
    };
    let mut hull: Vec<(usize, [f64; 2])> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(usize, [f64; 2])>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && drop(hull[hull.len() - 2].1, hull[hull.len() - 1].1, p.1)
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop(); // last point is the first of the next chain
    }
    hull.into_iter().map(|(l, _)| l).collect()
}

/// Exact degree-3 quadrature on a triangle: weights 1/20 at the vertices,
/// 2/15 at the edge midpoints, 9/20 at the centroid (weights sum to 1; the
/// result must be multiplied by the area).
fn triangle_rule(a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> [(f64, Vector3<f64>); 7] {
    [
        (1.0 / 20.0, *a),
        (1.0 / 20.0, *b),
        (1.0 / 20.0, *c),
        (2.0 / 15.0, (a + b) * 0.5),
        (2.0 / 15.0, (b + c) * 0.5),
        (2.0 / 15.0, (c + a) * 0.5),
        (9.0 / 20.0, (a + b + c) / 3.0),
    ]
}

/// Hull triangles and the vertex mean of the hull vertices (a strictly
/// interior point).
fn hull_with_centre(
    vertices: &[Vector3<f64>],
) -> Result<(Vec<[usize; 3]>, Vector3<f64>), ShapeError> {
    let tris = convex_hull_triangles(vertices)?;
    let mut used: Vec<usize> = tris.iter().flatten().copied().collect();
    used.sort_unstable();
    used.dedup();
    let centre = used.iter().map(|&i| vertices[i]).sum::<Vector3<f64>>() / used.len() as f64;
    Ok((tris, centre))
}

/// Mass properties of the convex hull of `vertices` by the divergence theorem.
///
/// With `g = x^a y^b z^c` and `G` its antiderivative along one coordinate
/// axis e (`∂G/∂e = g`), `∫_V g dV = ∮ G n_e dA`; the cubic face integrands
/// are evaluated exactly with a degree-3 triangle rule over the hull's
/// triangles (coordinates relative to an interior point).
pub fn polyhedron_properties_divergence(
    vertices: &[Vector3<f64>],
) -> Result<MassProperties, ShapeError> {
    let (tris, r) = hull_with_centre(vertices)?;
    let mut vol = 0.0;
    let mut m1 = Vector3::zeros();
    let (mut xx, mut yy, mut zz, mut xy, mut yz, mut zx) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for t in &tris {
        let a = vertices[t[0]] - r;
        let b = vertices[t[1]] - r;
        let c = vertices[t[2]] - r;
        // Outward normal times area.
        let n = (b - a).cross(&(c - a)) * 0.5;
        for (w, p) in triangle_rule(&a, &b, &c) {
            let (x, y, z) = (p.x, p.y, p.z);
            vol += w * n.x * x;
            m1.x += w * n.x * x * x / 2.0;
            m1.y += w * n.y * y * y / 2.0;
            m1.z += w * n.z * z * z / 2.0;
            xx += w * n.x * x * x * x / 3.0;
            yy += w * n.y * y * y * y / 3.0;
            zz += w * n.z * z * z * z / 3.0;
            xy += w * n.x * x * x * y / 2.0;
            yz += w * n.y * y * y * z / 2.0;
            zx += w * n.z * z * z * x / 2.0;
        }
    }
    let m2 = Matrix3::new(xx, xy, zx, xy, yy, yz, zx, yz, zz);
    Ok(from_moments(vol, m1, m2, r))
}

/// Mass properties of the convex hull of `vertices` by decomposition into
/// tetrahedra (interior point, hull triangle) with the exact tetrahedron
/// formulas `V = det[b-a, c-a, d-a]/6`, `∫x dV = V Σvᵢ/4`,
/// `∫xxᵀ dV = V/20 (Σvᵢvᵢᵀ + (Σvᵢ)(Σvᵢ)ᵀ)`.
pub fn polyhedron_properties_tetrahedra(
    vertices: &[Vector3<f64>],
) -> Result<MassProperties, ShapeError> {
    let (tris, r) = hull_with_centre(vertices)?;
    let mut vol = 0.0;
    let mut m1 = Vector3::zeros();
    let mut m2 = Matrix3::zeros();
    for t in &tris {
        // Fourth vertex: the interior point, at the local origin.
        let a = vertices[t[0]] - r;
        let b = vertices[t[1]] - r;
        let c = vertices[t[2]] - r;
        let v = a.dot(&b.cross(&c)) / 6.0;
        let s = a + b + c;
        vol += v;
        m1 += s * (v / 4.0);
        m2 += (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose())
            * (v / 20.0);
    }
    Ok(from_moments(vol, m1, m2, r))
}

/// Central properties from raw moments about the local origin `r`.
fn from_moments(vol: f64, m1: Vector3<f64>, m2: Matrix3<f64>, r: Vector3<f64>) -> MassProperties {
    let c = m1 / vol;
    MassProperties {
        volume: vol,
        centroid: r + c,
        second_moment: m2 - c * c.transpose() * vol,
    }
}
