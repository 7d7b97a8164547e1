//! Boundary surfaces of the shapes: vertices and planar polygonal faces, in the frame the mass
//! properties and the contact geometry use (world coordinates of the structure at rest).
//!
//! Every face is a planar polygon listed counter-clockwise seen from outside, so its right-hand
//! (Newell) normal points out of the solid, and every edge is shared by exactly two faces, once
//! in each direction. Flat shapes (box, prism, polyhedron) are represented exactly; the curved
//! faces of an annular sector are discretised (see [`sector_segments`]).

use nalgebra::Vector3;

use super::{
    AnnularSectorShape, BoxShape, PolyhedronShape, PrismShape, Shape, ShapeError,
    convex_hull_faces, v3,
};

/// Segments of a full turn (2π) used to discretise the arcs of an annular sector: a sector of
/// span s gets `max(SECTOR_MIN_SEGMENTS, ceil(s / 2π · SECTOR_SEGMENTS_PER_TURN))` segments.
pub const SECTOR_SEGMENTS_PER_TURN: usize = 96;

/// The fewest segments of an annular sector's arcs, however small its span.
pub const SECTOR_MIN_SEGMENTS: usize = 4;

/// The number of segments an arc of `span` radians is cut into (see
/// [`SECTOR_SEGMENTS_PER_TURN`]). With Δ = span / n the vertices lie on the arcs (inscribed
/// polygons), so the discretised sector's volume is the exact one times sin Δ / Δ ≈ 1 − Δ²/6
/// and its centroid's distance from the axis the exact one times (Δ/2) cot(Δ/2) ≈ 1 − Δ²/12
/// (Δ ≤ 2π/96 = 0.065: relative errors below 7.2e-4 and 3.6e-4).
pub fn sector_segments(span: f64) -> usize {
    let per_turn = SECTOR_SEGMENTS_PER_TURN as f64;
    let n = (span / std::f64::consts::TAU * per_turn).ceil();
    if n.is_finite() {
        (n as usize).max(SECTOR_MIN_SEGMENTS)
    } else {
        SECTOR_MIN_SEGMENTS
    }
}

/// A closed polyhedral surface: vertices (m) and planar faces (indices into `vertices`,
/// counter-clockwise seen from outside).
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Vertex positions (m).
    pub vertices: Vec<Vector3<f64>>,
    /// Faces: at least 3 vertex indices each, outward by the right-hand rule.
    pub faces: Vec<Vec<usize>>,
}

impl Surface {
    /// Volume (m³) and centroid (m) of the enclosed solid by the divergence theorem:
    /// V = ∮ x·n dA / 3 and ∫ xᵢ dV = ∮ xᵢ² nᵢ dA / 2, each face split into a fan of triangles
    /// from its first vertex (signed by their vector areas, so non-convex planar faces are
    /// exact) and integrated exactly (centroid rule for the linear integrand, edge-midpoint rule
    /// for the quadratic ones). Coordinates are taken relative to the vertex mean.
    pub fn volume_centroid(&self) -> (f64, Vector3<f64>) {
        let n = self.vertices.len().max(1) as f64;
        let origin = self.vertices.iter().sum::<Vector3<f64>>() / n;
        let mut volume = 0.0;
        let mut first = Vector3::zeros();
        for face in &self.faces {
            let a = self.vertices[face[0]] - origin;
            for w in 1..face.len().saturating_sub(1) {
                let b = self.vertices[face[w]] - origin;
                let c = self.vertices[face[w + 1]] - origin;
                let area = (b - a).cross(&(c - a)) * 0.5;
                volume += area.dot(&((a + b + c) / 3.0)) / 3.0;
                let mids = [(a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5];
                for i in 0..3 {
                    let sq: f64 = mids.iter().map(|m| m[i] * m[i]).sum::<f64>() / 3.0;
                    first[i] += area[i] * sq / 2.0;
                }
            }
        }
        (volume, origin + first / volume)
    }

    /// The number of polygon faces.
    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// Unit outward normal of face `f` (Newell's method).
    pub fn face_normal(&self, f: usize) -> Vector3<f64> {
        self.face_area_vector(f).normalize()
    }

    /// Vector area of face `f` (Newell's method): its area times its unit outward normal.
    pub fn face_area_vector(&self, f: usize) -> Vector3<f64> {
        newell(&self.faces[f], &self.vertices)
    }
}

/// Newell's area vector of a polygon (twice its vector area halved: the vector area itself).
fn newell(face: &[usize], vertices: &[Vector3<f64>]) -> Vector3<f64> {
    let m = face.len();
    (0..m).fold(Vector3::zeros(), |acc, i| {
        acc + vertices[face[i]].cross(&vertices[face[(i + 1) % m]]) * 0.5
    })
}

impl BoxShape {
    /// The box's 8 corners and 6 quadrilateral faces.
    pub fn surface(&self) -> Result<Surface, ShapeError> {
        self.mass_properties()?;
        let r = self.rotation_matrix();
        let c = v3(&self.center);
        let h = Vector3::new(self.size[0], self.size[1], self.size[2]) * 0.5;
        // Vertex index bits: 1 → +x, 2 → +y, 4 → +z.
        let vertices = (0..8)
            .map(|i| {
                let s = |bit: usize| if i & bit != 0 { 1.0 } else { -1.0 };
                c + r * Vector3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z)
            })
            .collect();
        let faces = vec![
            vec![0, 4, 6, 2], // −x
            vec![1, 3, 7, 5], // +x
            vec![0, 1, 5, 4], // −y
            vec![2, 6, 7, 3], // +y
            vec![0, 2, 3, 1], // −z
            vec![4, 5, 7, 6], // +z
        ];
        Ok(Surface { vertices, faces })
    }
}

impl PolyhedronShape {
    /// The convex hull's vertices and planar faces (coplanar hull points form one polygon).
    pub fn surface(&self) -> Result<Surface, ShapeError> {
        let pts: Vec<Vector3<f64>> = self.vertices.iter().map(v3).collect();
        let faces = convex_hull_faces(&pts)?;
        // Keep only the hull's vertices, renumbered.
        let mut index = vec![usize::MAX; pts.len()];
        let mut vertices = Vec::new();
        let faces = faces
            .into_iter()
            .map(|f| {
                f.into_iter()
                    .map(|i| {
                        if index[i] == usize::MAX {
                            index[i] = vertices.len();
                            vertices.push(pts[i]);
                        }
                        index[i]
                    })
                    .collect()
            })
            .collect();
        Ok(Surface { vertices, faces })
    }
}

impl PrismShape {
    /// The two polygon caps and one quadrilateral per polygon edge.
    pub fn surface(&self) -> Result<Surface, ShapeError> {
        self.mass_properties()?;
        let mut pts: Vec<Vector3<f64>> = self.polygon.iter().map(v3).collect();
        // The closing vertex, when given, is dropped as `mass_properties` does.
        let scale = super::bbox_diagonal(&pts);
        if (pts[pts.len() - 1] - pts[0]).norm() <= 1e-9 * scale {
            pts.pop();
        }
        let n = pts.len();
        let d = v3(&self.extrude);
        let indices: Vec<usize> = (0..n).collect();
        let along = newell(&indices, &pts).dot(&d) > 0.0;
        let mut vertices = pts.clone();
        vertices.extend(pts.iter().map(|p| p + d));
        // Written for a polygon counter-clockwise about the extrusion; reversed otherwise.
        let mut faces: Vec<Vec<usize>> = Vec::with_capacity(n + 2);
        faces.push((0..n).rev().collect());
        faces.push((n..2 * n).collect());
        for i in 0..n {
            let j = (i + 1) % n;
            faces.push(vec![i, j, n + j, n + i]);
        }
        if !along {
            for f in &mut faces {
                f.reverse();
            }
        }
        Ok(Surface { vertices, faces })
    }
}

impl AnnularSectorShape {
    /// The discretised sector: its arcs cut into [`sector_segments`] chords (vertices on the
    /// arcs), one planar quadrilateral per segment on the outer and inner faces (none inner when
    /// `inner_radius` is 0) and on each flat side (triangles when `inner_radius` is 0), and the
    /// two end faces.
    pub fn surface(&self) -> Result<Surface, ShapeError> {
        self.surface_with_segments(sector_segments(self.to_angle - self.from_angle))
    }

    /// [`AnnularSectorShape::surface`] with the arcs cut into `segments` chords (at least 1).
    pub fn surface_with_segments(&self, segments: usize) -> Result<Surface, ShapeError> {
        self.mass_properties()?;
        let frame = self.frame()?;
        let (es, et, w) = (
            frame.column(0).into_owned(),
            frame.column(1).into_owned(),
            frame.column(2).into_owned(),
        );
        let c = v3(&self.center);
        let span = self.to_angle - self.from_angle;
        let n = segments.max(1);
        let half = w * (0.5 * self.thickness);
        let radial = |j: usize| {
            let th = self.from_angle + span * j as f64 / n as f64;
            let (s, co) = th.sin_cos();
            es * co + et * s
        };
        let solid_core = self.inner_radius == 0.0;
        let mut vertices = Vec::new();
        // Outer bottom O⁻ⱼ = 4j, outer top O⁺ⱼ = 4j + 1, inner bottom I⁻ⱼ = 4j + 2, inner top
        // I⁺ⱼ = 4j + 3; with a solid core the inner vertices are the two axis points, after.
        for j in 0..=n {
            let e = radial(j);
            vertices.push(c + e * self.outer_radius - half);
            vertices.push(c + e * self.outer_radius + half);
            if !solid_core {
                vertices.push(c + e * self.inner_radius - half);
                vertices.push(c + e * self.inner_radius + half);
            }
        }
        let stride = if solid_core { 2 } else { 4 };
        let (core_bottom, core_top) = (vertices.len(), vertices.len() + 1);
        if solid_core {
            vertices.push(c - half);
            vertices.push(c + half);
        }
        let ob = |j: usize| stride * j;
        let ot = |j: usize| stride * j + 1;
        let ib = |j: usize| {
            if solid_core {
                core_bottom
            } else {
                stride * j + 2
            }
        };
        let it = |j: usize| {
            if solid_core { core_top } else { stride * j + 3 }
        };
        let mut faces = Vec::new();
        for j in 0..n {
            let k = j + 1;
            faces.push(vec![ob(j), ob(k), ot(k), ot(j)]);
            if solid_core {
                faces.push(vec![it(j), ot(j), ot(k)]);
                faces.push(vec![ib(j), ob(k), ob(j)]);
            } else {
                faces.push(vec![ib(j), it(j), it(k), ib(k)]);
                faces.push(vec![it(j), ot(j), ot(k), it(k)]);
                faces.push(vec![ib(j), ib(k), ob(k), ob(j)]);
            }
        }
        faces.push(vec![ib(0), ob(0), ot(0), it(0)]);
        faces.push(vec![ib(n), it(n), ot(n), ob(n)]);
        Ok(Surface { vertices, faces })
    }
}

impl Shape {
    /// The boundary surface (see [`Surface`]): exact for boxes, prisms and polyhedra, the arcs
    /// discretised for an annular sector ([`sector_segments`]).
    pub fn surface(&self) -> Result<Surface, ShapeError> {
        match self {
            Shape::Box(s) => s.surface(),
            Shape::Polyhedron(s) => s.surface(),
            Shape::Prism(s) => s.surface(),
            Shape::AnnularSector(s) => s.surface(),
            Shape::Compound(parts) => {
                // The union of the parts' closed surfaces: one mesh of disjoint shells (the
                // divergence theorem sums over them, so volume and centroid stay exact).
                let mut all = Surface {
                    vertices: Vec::new(),
                    faces: Vec::new(),
                };
                for part in parts {
                    let s = part.surface()?;
                    let base = all.vertices.len();
                    all.vertices.extend(s.vertices);
                    all.faces.extend(
                        s.faces
                            .into_iter()
                            .map(|f| f.into_iter().map(|i| i + base).collect()),
                    );
                }
                Ok(all)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;
    use std::f64::consts::{PI, TAU};

    use super::*;

    /// Closed and consistently oriented: every directed edge appears once and its reverse once;
    /// every face is planar (vertices within 1e-12 × size of the Newell plane) and non-degenerate.
    fn assert_closed(s: &Surface) {
        let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
        let size = s
            .vertices
            .iter()
            .map(|v| (v - s.vertices[0]).norm())
            .fold(0.0, f64::max);
        for f in &s.faces {
            assert!(f.len() >= 3);
            let m = f.len();
            for i in 0..m {
                *edges.entry((f[i], f[(i + 1) % m])).or_default() += 1;
            }
            let area = newell(f, &s.vertices);
            assert!(area.norm() > 1e-12 * size * size, "degenerate face {f:?}");
            let nrm = area.normalize();
            for &v in f {
                let off = nrm.dot(&(s.vertices[v] - s.vertices[f[0]]));
                assert!(off.abs() <= 1e-12 * size, "face {f:?} not planar: {off}");
            }
        }
        for (&(a, b), &count) in &edges {
            assert_eq!(count, 1, "edge {a}→{b} used {count} times in one direction");
            assert_eq!(
                edges.get(&(b, a)),
                Some(&1),
                "edge {a}→{b} has no reverse: the surface is open or not oriented"
            );
        }
    }

    /// For a convex solid, every vertex lies on the inner side of every face plane (to round-off
    /// 1e-12 × size): with a positive volume this means the normals point outward.
    fn assert_outward_convex(s: &Surface) {
        let (volume, centroid) = s.volume_centroid();
        assert!(volume > 0.0);
        let size = volume.cbrt();
        for (f, face) in s.faces.iter().enumerate() {
            let n = s.face_normal(f);
            let p0 = s.vertices[face[0]];
            assert!(n.dot(&(p0 - centroid)) > 0.0, "face {f} points inward");
            for v in &s.vertices {
                assert!(n.dot(&(v - p0)) <= 1e-12 * size);
            }
        }
    }

    fn assert_matches_mass_properties(shape: &Shape) {
        let s = shape.surface().unwrap();
        let mp = shape.mass_properties().unwrap();
        let (v, c) = s.volume_centroid();
        // Sums of a few dozen products of O(1) terms: round-off a few 1e-16 relative.
        assert!(
            (v - mp.volume).abs() <= 1e-12 * mp.volume,
            "{v} vs {}",
            mp.volume
        );
        let length = mp.volume.cbrt().max(mp.centroid.norm());
        assert!(
            (c - mp.centroid).norm() <= 1e-12 * length,
            "{c} vs {}",
            mp.centroid
        );
    }

    fn boxed() -> Shape {
        Shape::Box(BoxShape {
            center: [0.3, -0.2, 1.0],
            size: [0.4, 0.5, 2.0],
            rotation: Some([0.2, -0.4, 0.7]),
        })
    }

    fn l_prism(extrude: [f64; 3]) -> Shape {
        // An L (non-convex) in a tilted plane, given clockwise seen from +z.
        let l = [
            [0.0, 0.0],
            [0.0, 2.0],
            [0.5, 2.0],
            [0.5, 0.5],
            [1.5, 0.5],
            [1.5, 0.0],
        ];
        Shape::Prism(PrismShape {
            polygon: l.iter().map(|p| [p[0], p[1], 0.1 * p[0] + 3.0]).collect(),
            extrude,
        })
    }

    fn octahedron_with_extras() -> Shape {
        // An octahedron plus an interior point and a point in the middle of a face.
        let mut v = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        v.push([0.1, 0.1, 0.1]);
        v.push([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0]);
        for p in &mut v {
            p[2] += 2.0;
        }
        Shape::Polyhedron(PolyhedronShape { vertices: v })
    }

    fn sector(a: f64, b: f64, from: f64, to: f64, t: f64) -> AnnularSectorShape {
        AnnularSectorShape {
            center: [0.5, 0.0, 0.2],
            axis: [0.0, 1.0, 0.1],
            inner_radius: a,
            outer_radius: b,
            start: [1.0, 0.0, 0.0],
            from_angle: from,
            to_angle: to,
            thickness: t,
        }
    }

    #[test]
    fn box_surface_is_closed_outward_and_exact() {
        let shape = boxed();
        let s = shape.surface().unwrap();
        assert_eq!((s.vertices.len(), s.faces.len()), (8, 6));
        assert!(s.faces.iter().all(|f| f.len() == 4));
        assert_closed(&s);
        assert_outward_convex(&s);
        assert_matches_mass_properties(&shape);
    }

    #[test]
    fn prism_surface_is_closed_and_exact_for_both_windings_and_oblique_sweeps() {
        for extrude in [[0.0, 0.0, 0.7], [0.3, -0.2, 0.7], [0.0, 0.1, -0.9]] {
            let shape = l_prism(extrude);
            let s = shape.surface().unwrap();
            // 6 polygon edges: 6 sides + 2 caps.
            assert_eq!((s.vertices.len(), s.faces.len()), (12, 8));
            assert_closed(&s);
            assert!(s.volume_centroid().0 > 0.0, "inward for {extrude:?}");
            assert_matches_mass_properties(&shape);
        }
        // The same L wound the other way, with a closing vertex repeated.
        let Shape::Prism(mut p) = l_prism([0.0, 0.0, 0.7]) else {
            unreachable!()
        };
        p.polygon.reverse();
        p.polygon.push(p.polygon[0]);
        let shape = Shape::Prism(p);
        let s = shape.surface().unwrap();
        assert_eq!(s.faces.len(), 8);
        assert_closed(&s);
        assert_matches_mass_properties(&shape);
    }

    #[test]
    fn polyhedron_surface_is_its_hull_faces() {
        let shape = octahedron_with_extras();
        let s = shape.surface().unwrap();
        // The interior point and the face point are not hull vertices; 8 triangles.
        assert_eq!((s.vertices.len(), s.faces.len()), (6, 8));
        assert_closed(&s);
        assert_outward_convex(&s);
        assert_matches_mass_properties(&shape);
        // A cube given as a point cloud: its faces are 6 quadrilaterals, not 12 triangles.
        let mut cube = Vec::new();
        for i in 0..8 {
            let s = |b: usize| if i & b != 0 { 0.5 } else { -0.5 };
            cube.push([s(1) + 1.0, s(2), s(4) + 0.5]);
        }
        cube.push([1.0, 0.0, 1.0]); // the centre of the top face
        let shape = Shape::Polyhedron(PolyhedronShape { vertices: cube });
        let s = shape.surface().unwrap();
        assert_eq!((s.vertices.len(), s.faces.len()), (8, 6));
        assert_closed(&s);
        assert_outward_convex(&s);
        assert_matches_mass_properties(&shape);
    }

    /// Exact volume and centroid of the discretised sector (inscribed polygons of n chords of
    /// angle Δ): V_n = V sin Δ / Δ and r_n = r_c (Δ/2) cot(Δ/2), r_c the exact centroid's
    /// distance from the axis; derived by summing the chord triangles (c, Pⱼ, Pⱼ₊₁) of the
    /// outer minus the inner polygon.
    #[test]
    fn sector_surface_matches_the_derived_discretisation_error() {
        for (a, b, from, to) in [
            (4.0, 4.6, 0.3, 0.55),
            (1.0, 1.5, 0.0, PI),
            (0.0, 1.0, -0.5, 1.5),
            (0.8, 1.0, 0.0, TAU),
        ] {
            let shape = sector(a, b, from, to, 0.4);
            let s = shape.surface().unwrap();
            assert_closed(&s);
            let mp = shape.mass_properties().unwrap();
            let (v, c) = s.volume_centroid();
            let n = sector_segments(to - from);
            let delta = (to - from) / n as f64;
            let v_n = mp.volume * delta.sin() / delta;
            assert!((v - v_n).abs() <= 1e-12 * mp.volume, "{v} vs {v_n}");
            // The centroid moves along the line from the centre through the exact centroid.
            let centre = Vector3::from(shape.center);
            let c_n = centre + (mp.centroid - centre) * ((delta / 2.0) / (delta / 2.0).tan());
            assert!((c - c_n).norm() <= 1e-12 * b, "{c} vs {c_n}");
            // The discretisation error is what the docs promise.
            assert!(1.0 - v / mp.volume <= 7.2e-4);
            if a > 0.0 {
                assert_eq!(s.faces.len(), 4 * n + 2);
            } else {
                assert_eq!(s.faces.len(), 3 * n + 2);
            }
        }
    }

    #[test]
    fn sector_discretisation_converges_at_second_order() {
        // Volume error 1 − sin Δ/Δ = Δ²/6 (1 − Δ²/20 + …) and centroid error
        // 1 − (Δ/2) cot(Δ/2) = Δ²/12 (1 + Δ²/60 + …): doubling the segments divides both by
        // 4 within (1 + O(Δ²)), i.e. 1 % for Δ ≤ 0.3.
        let sec = sector(1.0, 1.4, 0.2, 1.4, 0.3);
        let mp = sec.mass_properties().unwrap();
        let centre = Vector3::from(sec.center);
        let exact_r = (mp.centroid - centre).norm();
        let errors = |n: usize| {
            let (v, c) = sec.surface_with_segments(n).unwrap().volume_centroid();
            (1.0 - v / mp.volume, 1.0 - (c - centre).norm() / exact_r)
        };
        let mut previous = errors(4);
        for n in [8, 16, 32, 64] {
            let e = errors(n);
            let delta = 1.2 / n as f64;
            assert!((e.0 / (delta * delta / 6.0) - 1.0).abs() < 0.01, "{e:?}");
            assert!((e.1 / (delta * delta / 12.0) - 1.0).abs() < 0.01, "{e:?}");
            assert!((previous.0 / e.0 - 4.0).abs() < 0.1, "{previous:?} {e:?}");
            assert!((previous.1 / e.1 - 4.0).abs() < 0.1, "{previous:?} {e:?}");
            previous = e;
        }
    }

    #[test]
    fn segment_counts() {
        assert_eq!(sector_segments(1e-3), SECTOR_MIN_SEGMENTS);
        assert_eq!(sector_segments(TAU), SECTOR_SEGMENTS_PER_TURN);
        assert_eq!(sector_segments(PI / 3.0), 16);
    }
}
