//! Tests of the shapes module. Tolerances: results are sums of O(10–1000)
//! rounded terms of size comparable to the result, so agreement to a relative
//! 1e-12 (a few thousand ulps) is expected unless stated otherwise.

use std::f64::consts::{PI, TAU};

use nalgebra::{Matrix3, Rotation3, Vector3};
use proptest::prelude::*;

use super::*;

/// Asserts that two mass properties agree: volume relative to `rel`,
/// centroid within `rel` × `length`, second moment within `rel` × ‖S‖.
fn assert_mp_close(a: &MassProperties, b: &MassProperties, rel: f64) {
    let length = b.volume.cbrt();
    assert!(
        (a.volume - b.volume).abs() <= rel * b.volume.abs(),
        "volume {} vs {}",
        a.volume,
        b.volume
    );
    assert!(
        (a.centroid - b.centroid).norm() <= rel * length.max(b.centroid.norm()),
        "centroid {} vs {}",
        a.centroid,
        b.centroid
    );
    let scale = b.second_moment.norm();
    assert!(
        (a.second_moment - b.second_moment).norm() <= rel * scale,
        "second moment {} vs {}",
        a.second_moment,
        b.second_moment
    );
}

fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn box_shape(center: [f64; 3], size: [f64; 3], rotation: Option<[f64; 3]>) -> BoxShape {
    BoxShape {
        center,
        size,
        rotation,
    }
}

/// The 8 corners of a box.
fn box_corners(b: &BoxShape) -> Vec<Vector3<f64>> {
    let r = b.rotation_matrix();
    let c = v3(&b.center);
    let mut out = Vec::new();
    for sx in [-0.5, 0.5] {
        for sy in [-0.5, 0.5] {
            for sz in [-0.5, 0.5] {
                let local = Vector3::new(sx * b.size[0], sy * b.size[1], sz * b.size[2]);
                out.push(c + r * local);
            }
        }
    }
    out
}

fn to_arrays(v: &[Vector3<f64>]) -> Vec<[f64; 3]> {
    v.iter().map(|p| [p.x, p.y, p.z]).collect()
}

// ---------------------------------------------------------------- box

#[test]
fn box_axis_aligned_closed_form() {
    let (a, b, c) = (0.4, 1.3, 2.2);
    let mp = box_shape([1.0, -2.0, 3.0], [a, b, c], None)
        .mass_properties()
        .unwrap();
    let rho = 2400.0;
    let m = rho * a * b * c;
    assert!(rel_err(mp.volume, a * b * c) < 1e-15);
    assert_eq!(mp.centroid, Vector3::new(1.0, -2.0, 3.0));
    let i = mp.inertia(rho);
    assert!(rel_err(i[(0, 0)], m * (b * b + c * c) / 12.0) < 1e-14);
    assert!(rel_err(i[(1, 1)], m * (a * a + c * c) / 12.0) < 1e-14);
    assert!(rel_err(i[(2, 2)], m * (a * a + b * b) / 12.0) < 1e-14);
    assert_eq!(i[(0, 1)], 0.0);
    assert_eq!(i[(0, 2)], 0.0);
    assert_eq!(i[(1, 2)], 0.0);
}

#[test]
fn box_rotated_is_rotated_inertia() {
    let (a, b, c) = (0.4, 1.3, 2.2);
    let base = box_shape([0.5, 0.2, 1.0], [a, b, c], None);
    let rho = 2000.0;
    let m = rho * a * b * c;
    // A quarter turn about z lays the box's a edge along y and its b edge along x: the moments
    // about x and y trade places (closed form of the box, m (sides²)/12).
    let quarter = BoxShape {
        rotation: Some([0.0, 0.0, std::f64::consts::FRAC_PI_2]),
        ..base.clone()
    }
    .mass_properties()
    .unwrap();
    let i = quarter.inertia(rho);
    assert!(rel_err(i[(0, 0)], m * (a * a + c * c) / 12.0) < 1e-14);
    assert!(rel_err(i[(1, 1)], m * (b * b + c * c) / 12.0) < 1e-14);
    assert!(rel_err(i[(2, 2)], m * (a * a + b * b) / 12.0) < 1e-14);
    assert!(i[(0, 1)].abs().max(i[(0, 2)].abs()).max(i[(1, 2)].abs()) < 1e-14 * m);
    // Any turn (here 1.36 rad about (0.3, −0.7, 1.1)/|·|): the same principal moments, and the
    // least of them, m (a² + b²)/12, about the box's c edge turned by Rodrigues' formula
    // v cos θ + (k × v) sin θ + k (k·v)(1 − cos θ), written out here.
    let rot = Vector3::new(0.3, -0.7, 1.1);
    let turned = BoxShape {
        rotation: Some([rot.x, rot.y, rot.z]),
        ..base.clone()
    }
    .mass_properties()
    .unwrap();
    let m0 = base.mass_properties().unwrap();
    assert_eq!(turned.volume, m0.volume);
    assert_eq!(turned.centroid, m0.centroid);
    let eigen = turned.inertia(rho).symmetric_eigen();
    let mut moments: Vec<f64> = eigen.eigenvalues.iter().copied().collect();
    moments.sort_by(f64::total_cmp);
    let mut expected = [
        m * (b * b + c * c) / 12.0,
        m * (a * a + c * c) / 12.0,
        m * (a * a + b * b) / 12.0,
    ];
    expected.sort_by(f64::total_cmp);
    for (got, want) in moments.iter().zip(expected) {
        assert!(rel_err(*got, want) < 1e-13, "{got} against {want}");
    }
    let (theta, k) = (rot.norm(), rot.normalize());
    let v = Vector3::z();
    let axis = v * theta.cos() + k.cross(&v) * theta.sin() + k * k.dot(&v) * (1.0 - theta.cos());
    let least = eigen.eigenvalues.imin();
    let found = eigen.eigenvectors.column(least).into_owned();
    assert!(
        found.dot(&axis).abs() > 1.0 - 1e-12,
        "{found} against {axis}"
    );
    // Rotation preserves the trace (polar moment about the centroid).
    assert!(rel_err(turned.second_moment.trace(), m0.second_moment.trace()) < 1e-14);
}

#[test]
fn box_as_polyhedron_both_routes() {
    for rot in [None, Some([0.3, -0.7, 1.1])] {
        let b = box_shape([10.0, -3.0, 2.0], [0.4, 1.3, 2.2], rot);
        let exact = b.mass_properties().unwrap();
        let corners = box_corners(&b);
        let div = polyhedron_properties_divergence(&corners).unwrap();
        let tet = polyhedron_properties_tetrahedra(&corners).unwrap();
        assert_mp_close(&div, &exact, 1e-12);
        assert_mp_close(&tet, &exact, 1e-12);
        let shape = Shape::Polyhedron(PolyhedronShape {
            vertices: to_arrays(&corners),
        });
        assert_mp_close(&shape.mass_properties().unwrap(), &exact, 1e-12);
        // Axis-aligned cube faces are split into two triangles each.
        assert_eq!(convex_hull_triangles(&corners).unwrap().len(), 12);
    }
}

// ---------------------------------------------------------------- polyhedron

fn regular_tetrahedron() -> Vec<Vector3<f64>> {
    vec![
        Vector3::new(1.0, 1.0, 1.0),
        Vector3::new(1.0, -1.0, -1.0),
        Vector3::new(-1.0, 1.0, -1.0),
        Vector3::new(-1.0, -1.0, 1.0),
    ]
}

#[test]
fn regular_tetrahedron_closed_form() {
    // Edge a = 2√2: V = a³/(6√2) = 8/3; inertia about any centroidal axis
    // m a²/20, so S = (m a²/40) I at unit density.
    let a2 = 8.0;
    let shift = Vector3::new(5.0, -1.0, 2.0);
    let pts: Vec<_> = regular_tetrahedron().iter().map(|p| p + shift).collect();
    let v = 8.0 / 3.0;
    let expected = MassProperties {
        volume: v,
        centroid: shift,
        second_moment: Matrix3::identity() * (v * a2 / 40.0),
    };
    assert_mp_close(
        &polyhedron_properties_divergence(&pts).unwrap(),
        &expected,
        1e-13,
    );
    assert_mp_close(
        &polyhedron_properties_tetrahedra(&pts).unwrap(),
        &expected,
        1e-13,
    );
    assert_eq!(convex_hull_triangles(&pts).unwrap().len(), 4);
}

fn octahedron(r: f64) -> Vec<Vector3<f64>> {
    let mut v = Vec::new();
    for i in 0..3 {
        for s in [-r, r] {
            let mut p = Vector3::zeros();
            p[i] = s;
            v.push(p);
        }
    }
    v
}

#[test]
fn octahedron_closed_form() {
    // |x|+|y|+|z| <= r: V = 4r³/3, ∫x² dV = 2r⁵/15.
    let r = 1.7;
    let pts = octahedron(r);
    let expected = MassProperties {
        volume: 4.0 * r.powi(3) / 3.0,
        centroid: Vector3::zeros(),
        second_moment: Matrix3::identity() * (2.0 * r.powi(5) / 15.0),
    };
    assert_mp_close(
        &polyhedron_properties_divergence(&pts).unwrap(),
        &expected,
        1e-13,
    );
    assert_mp_close(
        &polyhedron_properties_tetrahedra(&pts).unwrap(),
        &expected,
        1e-13,
    );
    // Inertia m r²/5.
    let i = polyhedron_properties_tetrahedra(&pts).unwrap().inertia(1.0);
    assert!(rel_err(i[(2, 2)], expected.volume * r * r / 5.0) < 1e-13);
}

#[test]
fn interior_and_duplicate_points_are_ignored() {
    let base = octahedron(1.0);
    let reference = polyhedron_properties_tetrahedra(&base).unwrap();
    let mut pts = base.clone();
    pts.push(Vector3::new(0.1, 0.2, -0.3)); // interior
    pts.push(Vector3::zeros()); // interior
    pts.push(base[2]); // exact duplicate
    pts.push(base[4] + Vector3::new(1e-13, 0.0, 0.0)); // near duplicate
    pts.push(Vector3::new(0.5, 0.5, 0.0)); // on an edge
    pts.push(Vector3::new(1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0)); // on a face
    pts.rotate_left(3); // order independence
    assert_mp_close(
        &polyhedron_properties_tetrahedra(&pts).unwrap(),
        &reference,
        1e-13,
    );
    assert_mp_close(
        &polyhedron_properties_divergence(&pts).unwrap(),
        &reference,
        1e-13,
    );
    assert_eq!(convex_hull_triangles(&pts).unwrap().len(), 8);
}

#[test]
fn cube_with_face_centres_and_edge_midpoints() {
    // Coplanar points on every face: each face is re-triangulated from its 2D
    // hull, the 4 corners (face centres and edge midpoints are dropped).
    let b = box_shape([0.0, 0.0, 0.0], [2.0, 2.0, 2.0], None);
    let mut pts = box_corners(&b);
    for i in 0..3 {
        for s in [-1.0, 1.0] {
            let mut p = Vector3::zeros();
            p[i] = s;
            pts.push(p);
            // an off-centre point on the same face
            let mut p2 = p;
            p2[(i + 1) % 3] = 0.3;
            p2[(i + 2) % 3] = -0.6;
            pts.push(p2);
        }
    }
    for x in [-1.0, 1.0] {
        pts.push(Vector3::new(x, 1.0, 0.0)); // edge midpoint
    }
    let tris = convex_hull_triangles(&pts).unwrap();
    assert_eq!(tris.len(), 12);
    let exact = b.mass_properties().unwrap();
    assert_mp_close(
        &polyhedron_properties_divergence(&pts).unwrap(),
        &exact,
        1e-13,
    );
    assert_mp_close(
        &polyhedron_properties_tetrahedra(&pts).unwrap(),
        &exact,
        1e-13,
    );
}

/// Checks that the triangles form a closed, consistently oriented surface
/// enclosing all points.
fn check_hull(points: &[Vector3<f64>], tris: &[[usize; 3]]) {
    use std::collections::HashMap;
    let mut edges: HashMap<(usize, usize), i32> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &count) in &edges {
        assert_eq!(count, 1, "directed edge ({a},{b}) used {count} times");
        assert_eq!(edges.get(&(b, a)), Some(&1), "edge ({a},{b}) has no twin");
    }
    let scale = bbox_diagonal(points);
    for t in tris {
        let (a, b, c) = (points[t[0]], points[t[1]], points[t[2]]);
        let n = (b - a).cross(&(c - a));
        let n = n / n.norm();
        for p in points {
            assert!(n.dot(&(p - a)) <= 1e-9 * scale, "point outside hull face");
        }
    }
}

#[test]
fn hull_is_closed_and_supporting_on_sphere_points() {
    // Deterministic spiral points on a sphere: every point is a hull vertex.
    let n = 200;
    let pts: Vec<Vector3<f64>> = (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = i as f64 * 2.399_963_229_728_653;
            Vector3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect();
    let tris = convex_hull_triangles(&pts).unwrap();
    check_hull(&pts, &tris);
    // Euler: a triangulated sphere with n vertices has 2n - 4 triangles.
    assert_eq!(tris.len(), 2 * n - 4);
    let a = polyhedron_properties_divergence(&pts).unwrap();
    let b = polyhedron_properties_tetrahedra(&pts).unwrap();
    assert_mp_close(&a, &b, 1e-12);
    // Inscribed in the unit ball: volume below 4π/3 but close to it.
    assert!(a.volume < 4.0 * PI / 3.0 && a.volume > 0.95 * 4.0 * PI / 3.0);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The two independent routes agree on random convex point clouds; the
    /// result is invariant under a rigid motion of the cloud.
    #[test]
    fn polyhedron_routes_agree(
        raw in prop::collection::vec(prop::array::uniform3(-1.0f64..1.0), 4..40),
        offset in prop::array::uniform3(-50.0f64..50.0),
        rot in prop::array::uniform3(-3.0f64..3.0),
    ) {
        let off = Vector3::from(offset);
        let pts: Vec<Vector3<f64>> = raw.iter().map(|p| Vector3::from(*p) + off).collect();
        let tet = polyhedron_properties_tetrahedra(&pts);
        prop_assume!(tet.is_ok());
        let tet = tet.unwrap();
        // Skip nearly flat clouds, whose second moment is ill-conditioned.
        prop_assume!(tet.volume > 1e-3);
        let div = polyhedron_properties_divergence(&pts).unwrap();
        // Offsets up to 50 with unit-size clouds cost ~2 digits: 1e-10.
        assert_mp_close(&div, &tet, 1e-10);
        check_hull(&pts, &convex_hull_triangles(&pts).unwrap());

        let r = *Rotation3::new(Vector3::from(rot)).matrix();
        let t = Vector3::new(1.0, 2.0, 3.0);
        let moved: Vec<Vector3<f64>> = pts.iter().map(|p| r * p + t).collect();
        let tet2 = polyhedron_properties_tetrahedra(&moved).unwrap();
        assert_mp_close(&tet2, &tet.transformed(&r, &t), 1e-10);
    }
}

// ---------------------------------------------------------------- prism

#[test]
fn prism_rectangle_equals_box() {
    let b = box_shape([1.0, 2.0, 0.75], [0.4, 1.3, 1.5], None);
    let prism = PrismShape {
        polygon: vec![
            [0.8, 1.35, 0.0],
            [1.2, 1.35, 0.0],
            [1.2, 2.65, 0.0],
            [0.8, 2.65, 0.0],
        ],
        extrude: [0.0, 0.0, 1.5],
    };
    let exact = b.mass_properties().unwrap();
    assert_mp_close(&prism.mass_properties().unwrap(), &exact, 1e-13);
    // Reversed winding and a closing vertex give the same solid.
    let mut rev = prism.clone();
    rev.polygon.reverse();
    rev.polygon.push(rev.polygon[0]);
    assert_mp_close(&rev.mass_properties().unwrap(), &exact, 1e-13);
    // A rotated box built as a prism.
    let rot = [0.2, 0.9, -0.4];
    let rb = BoxShape {
        rotation: Some(rot),
        ..b.clone()
    };
    let r = rb.rotation_matrix();
    let c = Vector3::from(b.center);
    let corners: Vec<[f64; 3]> = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
        .iter()
        .map(|s| {
            let p = c + r * Vector3::new(0.2 * s[0], 0.65 * s[1], -0.75);
            [p.x, p.y, p.z]
        })
        .collect();
    let e = r * Vector3::new(0.0, 0.0, 1.5);
    let rp = PrismShape {
        polygon: corners,
        extrude: [e.x, e.y, e.z],
    };
    assert_mp_close(
        &rp.mass_properties().unwrap(),
        &rb.mass_properties().unwrap(),
        1e-13,
    );
}

#[test]
fn triangular_prism_closed_form() {
    // Right triangle with legs p (x), q (y), extruded h (z):
    // V = pqh/2, c = (p/3, q/3, h/2), S_xx = h q p³/36, S_yy = h p q³/36,
    // S_xy = -h p²q²/72, S_zz = V h²/12.
    let (p, q, h) = (0.6, 0.9, 2.5);
    let prism = PrismShape {
        polygon: vec![[0.0, 0.0, 0.0], [p, 0.0, 0.0], [0.0, q, 0.0]],
        extrude: [0.0, 0.0, h],
    };
    let v = p * q * h / 2.0;
    let expected = MassProperties {
        volume: v,
        centroid: Vector3::new(p / 3.0, q / 3.0, h / 2.0),
        second_moment: Matrix3::new(
            h * q * p.powi(3) / 36.0,
            -h * p * p * q * q / 72.0,
            0.0,
            -h * p * p * q * q / 72.0,
            h * p * q.powi(3) / 36.0,
            0.0,
            0.0,
            0.0,
            v * h * h / 12.0,
        ),
    };
    assert_mp_close(&prism.mass_properties().unwrap(), &expected, 1e-13);
}

#[test]
fn oblique_prism_cavalieri_and_shear() {
    let polygon = vec![
        [0.0, 0.0, 1.0],
        [2.0, 0.0, 1.0],
        [2.5, 1.0, 1.0],
        [1.0, 2.0, 1.0],
        [-0.5, 1.2, 1.0],
    ];
    let h = 1.7;
    let straight = PrismShape {
        polygon: polygon.clone(),
        extrude: [0.0, 0.0, h],
    };
    let d = Vector3::new(0.8, -0.5, h);
    let oblique = PrismShape {
        polygon: polygon.clone(),
        extrude: [d.x, d.y, d.z],
    };
    let ms = straight.mass_properties().unwrap();
    let mo = oblique.mass_properties().unwrap();
    // Cavalieri: same volume.
    assert!(rel_err(mo.volume, ms.volume) < 1e-14);
    // Centroid = polygon centroid + d/2.
    let poly_centroid = ms.centroid - Vector3::new(0.0, 0.0, h / 2.0);
    assert!((mo.centroid - (poly_centroid + d / 2.0)).norm() < 1e-14);
    // The oblique prism is the straight one under the shear
    // A = I + (d_∥ / h) e_zᵀ (det 1), so S_o = A S_s Aᵀ.
    let mut a = Matrix3::identity();
    a[(0, 2)] = d.x / h;
    a[(1, 2)] = d.y / h;
    let expected = a * ms.second_moment * a.transpose();
    assert!((mo.second_moment - expected).norm() <= 1e-13 * expected.norm());
}

#[test]
fn l_shaped_prism_is_sum_of_rectangles() {
    // L = [0,2]×[0,1] ∪ [0,1]×[1,3] (non-convex, reflex vertex at (1,1)) in
    // the tilted plane spanned by (1,0,0) and (0,1,1)/√2, extruded along an
    // oblique vector; it is the disjoint union of the two rectangle prisms.
    let e1 = Vector3::new(1.0, 0.0, 0.0);
    let e2 = Vector3::new(0.0, 1.0, 1.0) / 2f64.sqrt();
    let o = Vector3::new(3.0, -1.0, 2.0);
    let map = |u: f64, v: f64| {
        let p = o + e1 * u + e2 * v;
        [p.x, p.y, p.z]
    };
    let extrude = [0.3, -0.6, 0.4];
    let prism = |pts: &[(f64, f64)]| PrismShape {
        polygon: pts.iter().map(|&(u, v)| map(u, v)).collect(),
        extrude,
    };
    let l = prism(&[
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 3.0),
        (0.0, 3.0),
    ]);
    let r1 = prism(&[(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]);
    let r2 = prism(&[(0.0, 1.0), (1.0, 1.0), (1.0, 3.0), (0.0, 3.0)]);
    let sum =
        MassProperties::combine(&[r1.mass_properties().unwrap(), r2.mass_properties().unwrap()])
            .unwrap();
    assert_mp_close(&l.mass_properties().unwrap(), &sum, 1e-13);
    // Starting the L at its reflex vertex does not matter.
    let mut l2 = l.clone();
    l2.polygon.rotate_left(3);
    assert_mp_close(&l2.mass_properties().unwrap(), &sum, 1e-13);
}

// ---------------------------------------------------------------- annular sector

fn sector(a: f64, b: f64, from: f64, to: f64, t: f64) -> AnnularSectorShape {
    AnnularSectorShape {
        center: [0.0, 0.0, 0.0],
        axis: [0.0, 0.0, 1.0],
        inner_radius: a,
        outer_radius: b,
        start: [1.0, 0.0, 0.0],
        from_angle: from,
        to_angle: to,
        thickness: t,
    }
}

#[test]
fn annular_sector_volume_and_centroid() {
    let (a, b, t) = (4.0, 4.6, 0.5);
    let (from, to) = (0.3, 0.3 + 0.25);
    let mp = sector(a, b, from, to, t).mass_properties().unwrap();
    let dth = to - from;
    assert!(rel_err(mp.volume, t * (b * b - a * a) * dth / 2.0) < 1e-14);
    let rc =
        2.0 * (b.powi(3) - a.powi(3)) * (dth / 2.0).sin() / (3.0 * (b * b - a * a) * dth / 2.0);
    let mid = (from + to) / 2.0;
    let expected = Vector3::new(rc * mid.cos(), rc * mid.sin(), 0.0);
    assert!((mp.centroid - expected).norm() < 1e-14 * rc);
}

#[test]
fn full_ring_closed_form() {
    // ∫x² dV = ∫y² dV = t π (b⁴ - a⁴)/4; polar (about the axis) ρ t π (b⁴ - a⁴)/2;
    // in-plane moments of inertia ρ [t π (b⁴-a⁴)/4 + V t²/12].
    let (a, b, t, rho) = (1.2, 1.5, 0.4, 2000.0);
    let mp = sector(a, b, -1.0, -1.0 + TAU, t).mass_properties().unwrap();
    let v = t * PI * (b * b - a * a);
    assert!(rel_err(mp.volume, v) < 1e-14);
    assert!(mp.centroid.norm() < 1e-14 * b);
    let i = mp.inertia(rho);
    let quarter = t * PI * (b.powi(4) - a.powi(4)) / 4.0;
    assert!(rel_err(i[(2, 2)], rho * 2.0 * quarter) < 1e-14);
    let inplane = rho * (quarter + v * t * t / 12.0);
    assert!(rel_err(i[(0, 0)], inplane) < 1e-14);
    assert!(rel_err(i[(1, 1)], inplane) < 1e-14);
    assert!(i[(0, 1)].abs() < 1e-14 * inplane);
    // A full disc (inner radius 0): polar ρ t π b⁴ / 2.
    let disc = sector(0.0, b, 0.0, TAU, t).mass_properties().unwrap();
    assert!(rel_err(disc.inertia(rho)[(2, 2)], rho * t * PI * b.powi(4) / 2.0) < 1e-14);
}

/// Polygonal cross-section of a sector: outer arc then inner arc, `n` chords
/// each (a non-convex simple polygon), extruded along the axis.
fn sector_as_prism(s: &AnnularSectorShape, n: usize) -> PrismShape {
    let frame = s.frame().unwrap();
    let (es, et, w) = (frame.column(0), frame.column(1), frame.column(2));
    let c = Vector3::from(s.center) - w * (s.thickness / 2.0);
    let point = |r: f64, k: usize| {
        let th = s.from_angle + (s.to_angle - s.from_angle) * k as f64 / n as f64;
        let p = c + es * (r * th.cos()) + et * (r * th.sin());
        [p.x, p.y, p.z]
    };
    let mut polygon: Vec<[f64; 3]> = (0..=n).map(|k| point(s.outer_radius, k)).collect();
    polygon.extend((0..=n).rev().map(|k| point(s.inner_radius, k)));
    let e = w * s.thickness;
    PrismShape {
        polygon,
        extrude: [e.x, e.y, e.z],
    }
}

/// Largest relative discrepancy between two mass properties.
fn mp_discrepancy(a: &MassProperties, b: &MassProperties) -> f64 {
    let length = b.volume.cbrt().max(b.centroid.norm());
    rel_err(a.volume, b.volume)
        .max((a.centroid - b.centroid).norm() / length)
        .max((a.second_moment - b.second_moment).norm() / b.second_moment.norm())
}

#[test]
fn annular_sector_polygonal_approximation_converges() {
    let s = AnnularSectorShape {
        center: [1.0, 2.0, 3.0],
        axis: [0.3, -1.0, 0.5],
        inner_radius: 2.0,
        outer_radius: 2.8,
        start: [1.0, 0.0, 0.0],
        from_angle: 0.4,
        to_angle: 2.6,
        thickness: 0.6,
    };
    let exact = s.mass_properties().unwrap();
    let mut previous = f64::INFINITY;
    for n in [4, 16, 64, 256, 1024] {
        let approx = sector_as_prism(&s, n).mass_properties().unwrap();
        let err = mp_discrepancy(&approx, &exact);
        // Chord approximation: error O(n⁻²), so a 4× finer subdivision cuts
        // the error by about 16; require at least a factor 10.
        assert!(
            err < previous / 10.0,
            "n = {n}: error {err} vs previous {previous}"
        );
        previous = err;
    }
    assert!(previous < 1e-5, "finest error {previous}");
}

#[test]
fn annular_sector_arbitrary_orientation_is_rotated_reference() {
    let reference = sector(3.0, 3.45, 0.2, 0.2 + 0.3, 0.7);
    let m0 = reference.mass_properties().unwrap();
    let r = *Rotation3::new(Vector3::new(0.7, -1.2, 0.4)).matrix();
    let c = Vector3::new(-4.0, 2.5, 7.0);
    let axis = r * Vector3::z() * 2.5; // length is irrelevant
    // start with a component along the axis: it is projected out
    let start = r * Vector3::new(3.0, 0.0, 0.0) + axis * 0.4;
    let s = AnnularSectorShape {
        center: [c.x, c.y, c.z],
        axis: [axis.x, axis.y, axis.z],
        start: [start.x, start.y, start.z],
        ..reference.clone()
    };
    assert_mp_close(
        &s.mass_properties().unwrap(),
        &m0.transformed(&r, &c),
        1e-13,
    );
    // Rotating the start direction by δ about the axis equals shifting the
    // angles by δ.
    let delta: f64 = 0.9;
    let s2 = AnnularSectorShape {
        start: [delta.cos(), delta.sin(), 0.0],
        from_angle: reference.from_angle - delta,
        to_angle: reference.to_angle - delta,
        ..reference.clone()
    };
    assert_mp_close(&s2.mass_properties().unwrap(), &m0, 1e-13);
}

#[test]
fn thin_voussoir_matches_richardson_extrapolated_prisms() {
    // A small-angle voussoir of a large arch (Δθ = 0.02 rad, radius 10 m,
    // depth 0.3 m): a regime where the naive closed form loses digits to
    // cancellation. The chord approximation error has an expansion in even
    // powers of 1/n, so Richardson extrapolation (4 A(2n) - A(n))/3 removes the
    // O(n⁻²) term, leaving O(n⁻⁴) ≈ 1e-17 here; the remaining discrepancy is
    // round-off only.
    let s = sector(10.0, 10.3, 1.0, 1.0 + 0.02, 0.5);
    let exact = s.mass_properties().unwrap();
    let a1 = sector_as_prism(&s, 400).mass_properties().unwrap();
    let a2 = sector_as_prism(&s, 800).mass_properties().unwrap();
    assert!(mp_discrepancy(&a2, &exact) < 1e-9);
    let extrapolated = MassProperties {
        volume: (4.0 * a2.volume - a1.volume) / 3.0,
        centroid: (a2.centroid * 4.0 - a1.centroid) / 3.0,
        second_moment: (a2.second_moment * 4.0 - a1.second_moment) / 3.0,
    };
    assert!(mp_discrepancy(&extrapolated, &exact) < 1e-12);
}

// ---------------------------------------------------------------- errors

fn err_msg(r: Result<MassProperties, ShapeError>) -> String {
    r.unwrap_err().to_string()
}

#[test]
fn box_errors() {
    let m = err_msg(box_shape([0.0; 3], [1.0, 0.0, 2.0], None).mass_properties());
    assert_eq!(
        m,
        "box size must be positive in all three directions, got [1, 0, 2]"
    );
    let m = err_msg(box_shape([0.0, f64::NAN, 0.0], [1.0; 3], None).mass_properties());
    assert_eq!(m, "non-finite number in center");
    let m =
        err_msg(box_shape([0.0; 3], [1.0; 3], Some([f64::INFINITY, 0.0, 0.0])).mass_properties());
    assert_eq!(m, "non-finite number in rotation");
    // An angle of many turns is refused (1e300 rad made the inertia NaN, reported as mass
    // properties that are not finite); 100 rad is allowed and is the rotation by 100 − 30π rad.
    let m = err_msg(box_shape([0.0; 3], [1.0; 3], Some([0.0, 0.0, 1e300])).mass_properties());
    assert!(
        m.starts_with("rotation is 1e300 rad about its axis, more than 100 rad"),
        "{m}"
    );
    let turned = |angle: f64| {
        box_shape([0.0; 3], [1.0, 2.0, 3.0], Some([0.0, 0.0, angle]))
            .mass_properties()
            .expect("a valid box")
            .second_moment
    };
    let (many, few) = (turned(100.0), turned(100.0 - 30.0 * std::f64::consts::PI));
    assert!((many - few).amax() < 1e-12 * many.amax(), "{many} vs {few}");
}

#[test]
fn polyhedron_errors() {
    let poly =
        |v: Vec<[f64; 3]>| Shape::Polyhedron(PolyhedronShape { vertices: v }).mass_properties();
    let m = err_msg(poly(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]));
    assert_eq!(m, "polyhedron needs at least 4 points, got 3");
    // A cloud beyond the brute-force hull's limit is refused at once, before any hull work
    // (3 000 points took minutes).
    let cloud: Vec<[f64; 3]> = (0..3000)
        .map(|i| {
            let t = i as f64;
            [t.cos(), t.sin(), (0.37 * t).sin()]
        })
        .collect();
    let m = err_msg(poly(cloud));
    assert!(
        m.starts_with("polyhedron has 3000 vertices, more than the 1000"),
        "{m}"
    );
    let m = err_msg(poly(vec![
        [0.0; 3],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.5, 0.2, 0.0],
    ]));
    assert_eq!(m, "polyhedron vertices are coplanar: zero volume");
    // Collinear and coincident clouds are coplanar too.
    let m = err_msg(poly(vec![[0.0; 3], [1.0; 3], [2.0; 3], [3.0; 3]]));
    assert!(m.contains("coplanar"));
    let m = err_msg(poly(vec![[1.0; 3]; 5]));
    assert!(m.contains("coplanar"));
    let m = err_msg(poly(vec![
        [0.0; 3],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, f64::NAN],
    ]));
    assert_eq!(m, "non-finite number in vertices");
}

fn square_prism() -> PrismShape {
    PrismShape {
        polygon: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        extrude: [0.0, 0.0, 1.0],
    }
}

#[test]
fn prism_errors() {
    let with_polygon = |polygon: Vec<[f64; 3]>| {
        PrismShape {
            polygon,
            ..square_prism()
        }
        .mass_properties()
    };
    assert_eq!(
        err_msg(with_polygon(vec![[0.0; 3], [1.0, 0.0, 0.0]])),
        "prism polygon needs at least 3 points, got 2"
    );
    // Closing vertex removed, leaving 2.
    assert_eq!(
        err_msg(with_polygon(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0; 3]])),
        "prism polygon needs at least 3 points, got 2"
    );
    assert_eq!(
        err_msg(with_polygon(vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [f64::NAN, 1.0, 0.0]
        ])),
        "non-finite number in polygon"
    );
    let m = err_msg(with_polygon(vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.012],
    ]));
    assert_eq!(
        m,
        "prism polygon is not planar: vertex 3 is 0.012 m off the plane through vertices 0, 1 and 2"
    );
    // Within the tolerance (1e-6 × size) the polygon is accepted.
    assert!(
        with_polygon(vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 1e-7],
        ])
        .is_ok()
    );
    assert_eq!(
        err_msg(with_polygon(vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0]
        ])),
        "prism polygon has zero area: its vertices are collinear"
    );
    assert_eq!(
        err_msg(with_polygon(vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0]
        ])),
        "prism polygon vertex 2 repeats the previous vertex"
    );
    // Bow tie: edges 0 and 2 cross.
    let m = err_msg(with_polygon(vec![
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    ]));
    assert!(
        m.starts_with("prism polygon is not simple: edge 0 and edge 2"),
        "{m}"
    );
    // A spike folding back onto the previous edge.
    let m = err_msg(with_polygon(vec![
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
    ]));
    assert!(m.starts_with("prism polygon is not simple"), "{m}");
    let with_extrude = |extrude| {
        PrismShape {
            extrude,
            ..square_prism()
        }
        .mass_properties()
    };
    assert_eq!(err_msg(with_extrude([0.0; 3])), "extrude must be non-zero");
    assert_eq!(
        err_msg(with_extrude([1.0, 2.0, 0.0])),
        "prism extrusion is parallel to the polygon plane: zero volume"
    );
    assert_eq!(
        err_msg(with_extrude([1.0, f64::INFINITY, 0.0])),
        "non-finite number in extrude"
    );
}

#[test]
fn annular_sector_errors() {
    let base = sector(1.0, 1.5, 0.0, 1.0, 0.3);
    let run = |s: AnnularSectorShape| err_msg(Shape::AnnularSector(s).mass_properties());
    assert_eq!(
        run(AnnularSectorShape {
            inner_radius: 2.0,
            ..base.clone()
        }),
        "inner_radius 2 must be smaller than outer_radius 1.5"
    );
    assert_eq!(
        run(AnnularSectorShape {
            inner_radius: -0.5,
            ..base.clone()
        }),
        "inner_radius must not be negative, got -0.5"
    );
    assert_eq!(
        run(AnnularSectorShape {
            center: [f64::NAN, 0.0, 0.0],
            ..base.clone()
        }),
        "non-finite number in center"
    );
    assert_eq!(
        run(AnnularSectorShape {
            outer_radius: f64::INFINITY,
            ..base.clone()
        }),
        "non-finite number in outer_radius"
    );
    assert_eq!(
        run(AnnularSectorShape {
            axis: [0.0; 3],
            ..base.clone()
        }),
        "axis must be non-zero"
    );
    assert_eq!(
        run(AnnularSectorShape {
            start: [0.0; 3],
            ..base.clone()
        }),
        "start must be non-zero"
    );
    assert_eq!(
        run(AnnularSectorShape {
            start: [0.0, 0.0, -2.0],
            ..base.clone()
        }),
        "start direction is parallel to the axis"
    );
    assert_eq!(
        run(AnnularSectorShape {
            to_angle: 0.0,
            ..base.clone()
        }),
        "to_angle 0 must exceed from_angle 0"
    );
    assert_eq!(
        run(AnnularSectorShape {
            to_angle: 7.0,
            ..base.clone()
        }),
        "angle span to_angle - from_angle = 7 rad exceeds a full turn (2π)"
    );
    assert_eq!(
        run(AnnularSectorShape {
            thickness: 0.0,
            ..base.clone()
        }),
        "thickness must be positive, got 0"
    );
}

#[test]
fn kinds() {
    let b = Shape::Box(box_shape([0.0; 3], [1.0; 3], None));
    assert_eq!(b.kind(), "box");
    assert_eq!(
        Shape::Polyhedron(PolyhedronShape { vertices: vec![] }).kind(),
        "polyhedron"
    );
    assert_eq!(Shape::Prism(square_prism()).kind(), "prism");
    assert_eq!(
        Shape::AnnularSector(sector(1.0, 2.0, 0.0, 1.0, 1.0)).kind(),
        "annular_sector"
    );
}

#[test]
fn small_angle_series_match_closed_forms() {
    // At α = 1.5 both forms of each helper are accurate; compare them.
    for alpha in [0.9f64, 1.5, 1.99] {
        let (s, c) = alpha.sin_cos();
        let direct = alpha + s * c - 2.0 * s * s / alpha;
        assert!(rel_err(cos2_defect(alpha), direct) < 1e-13, "alpha {alpha}");
        if alpha < 1.0 {
            assert!(rel_err(sin2_integral(alpha), alpha - s * c) < 1e-14);
        }
    }
    // Leading terms: 2α⁵/45 and 2α³/3.
    let a = 1e-4f64;
    assert!(rel_err(cos2_defect(a), 2.0 * a.powi(5) / 45.0) < 1e-7);
    assert!(rel_err(sin2_integral(a), 2.0 * a.powi(3) / 3.0) < 1e-7);
}
