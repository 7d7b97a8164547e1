//! From geometry to hinges: the contact faces of blocks placed in contact, found from their
//! shapes alone, and the CRR structure whose rocking interfaces they are (documented in
//! `docs/assembly.md`).
//!
//! Two faces touch when they face each other (outward normals opposite to within
//! [`MAX_CONTACT_TILT`]) and their overlap lies within the tolerance of both planes; the contact
//! face is the overlap of the two convex polygons (clipped in the plane of one, Sutherland–
//! Hodgman). The pieces of a body's face that rounded coordinates split lie in one plane within
//! the tolerance and are one face (`merge_coplanar_pieces`), and a rectangular contact is written
//! squared (`squared`). The ground is the horizontal plane at the
//! ground level (z = 0 unless a site elevation is given): a face lying on it with its outward
//! normal down rests on the ground whole. A contact whose normal
//! leans less than 45° from the vertical is a **bed** (the lower body supports the upper one: a
//! rocking interface); a steeper one is a **side** contact (a head joint, a block against a
//! neighbour), reported but not made an interface, since a CRR interface is a support rocking
//! under gravity.

use nalgebra::Vector3;

use crate::shapes::Surface;
use crate::shapes::{Shape, any_perpendicular};
use crate::spec::{BodySpec, InterfaceSpec, PivotSpec, RockingBaseSpec, StructureSpec};

/// A contact face between two bodies (or a body and the ground).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactFace {
    /// The supporting body (None: the ground) of a bed; of a side contact, the first body.
    pub lower: Option<usize>,
    /// The supported body of a bed; of a side contact, the second body.
    pub upper: usize,
    /// Unit normal from `lower` into `upper`.
    pub normal: Vector3<f64>,
    /// The overlap polygon's corners, counter-clockwise about `normal` (convex).
    pub corners: Vec<Vector3<f64>>,
    /// Its area (m²).
    pub area: f64,
    /// Whether it is a bed (normal within 45° of the vertical) or a side contact.
    pub bed: bool,
    /// For a contact with the ground (`lower` None), the fixed block it rests on or against
    /// (an index into the assembly's bodies; None: the ground plane, or faces merged over
    /// several supports), for the reports: the model has one ground.
    pub support: Option<usize>,
}

/// Why an assembly cannot be turned into a structure.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{item}: {message}")]
pub struct AssemblyError {
    /// The body or contact concerned.
    pub item: String,
    /// What is wrong.
    pub message: String,
}

fn error(item: impl Into<String>, message: impl Into<String>) -> AssemblyError {
    AssemblyError {
        item: item.into(),
        message: message.into(),
    }
}

/// The shape of a block of an assembly: exactly one, not a compound body (an assembly lists the
/// blocks as they are built; `crr assemble --mechanism` merges them).
fn shape_of(body: &BodySpec) -> Result<Shape, AssemblyError> {
    let item = || format!("body \"{}\"", body.name);
    if body.is_compound() {
        return Err(error(
            item(),
            "is a compound body: an assembly lists single blocks (each with one shape)",
        ));
    }
    match <[Shape; 1]>::try_from(body.own_shapes()) {
        Ok([shape]) => Ok(shape),
        Err(s) => Err(error(
            item(),
            format!("has {} shapes: give exactly one", s.len()),
        )),
    }
}

/// The closed surface of a body's shape, in world coordinates.
pub fn body_surface(body: &BodySpec) -> Result<Surface, AssemblyError> {
    shape_of(body)?
        .surface()
        .map_err(|e| error(format!("body \"{}\"", body.name), e.to_string()))
}

/// One face of a surface: its polygon, unit outward normal and plane offset n·x.
#[derive(Clone)]
struct Face {
    polygon: Vec<Vector3<f64>>,
    normal: Vector3<f64>,
    offset: f64,
    /// Its area (m²).
    area: f64,
    /// Whether the polygon is convex (every turn the same way about the normal).
    convex: bool,
}

/// The faces of a body's surface, pieces of one face in one plane within `tolerance` (m)
/// merged ([`merge_coplanar_pieces`]).
fn faces_of(surface: &Surface, tolerance: f64) -> Vec<Face> {
    merge_coplanar_pieces(surface_faces(surface), tolerance)
}

fn surface_faces(surface: &Surface) -> Vec<Face> {
    (0..surface.faces.len())
        .filter_map(|f| {
            let polygon: Vec<Vector3<f64>> = surface.faces[f]
                .iter()
                .map(|&i| surface.vertices[i])
                .collect();
            let area = surface.face_area_vector(f);
            let norm = area.norm();
            (norm > 0.0).then(|| {
                let normal = area / norm;
                let m = polygon.len();
                let convex = (0..m).all(|i| {
                    let (a, b, c) = (polygon[i], polygon[(i + 1) % m], polygon[(i + 2) % m]);
                    (b - a).cross(&(c - b)).dot(&normal) >= -1e-12 * (b - a).norm() * (c - b).norm()
                });
                Face {
                    offset: normal.dot(&polygon[0]),
                    polygon,
                    normal,
                    area: norm,
                    convex,
                }
            })
        })
        .collect()
}

/// The faces of one body that lie in one plane to within `tolerance` (m), as one face each: a
/// convex block written with rounded coordinates has its faces' vertices off their planes by
/// up to the rounding (0.87e-6 m at six decimals, as CAD programs export OBJ files), and its
/// hull then splits such a face into pieces at slightly different angles, so that a block
/// resting on it met "more than one face" (a 9-voussoir arch turned to a 30° bearing and
/// exported at six decimals was refused, whatever `--tolerance`). Pieces are merged when every
/// vertex of each lies within `tolerance` of the other's plane and their normals agree in
/// sense; the merged face is the convex hull of their vertices in the plane of their summed
/// area vector, through their mean offset. Only convex faces are merged (a prism's non-convex
/// caps are whole faces already).
fn merge_coplanar_pieces(faces: Vec<Face>, tolerance: f64) -> Vec<Face> {
    let n = faces.len();
    let on_plane = |a: &Face, b: &Face| {
        b.polygon
            .iter()
            .all(|v| (a.normal.dot(v) - a.offset).abs() <= tolerance)
    };
    let mut group: Vec<usize> = (0..n).collect();
    let root = |group: &[usize], mut i: usize| {
        while group[i] != i {
            i = group[i];
        }
        i
    };
    // Pieces of one face share an edge: two vertices within the tolerance (the separate feet of
    // a portal cut from one stone lie in one plane and are two faces).
    let adjacent = |a: &Face, b: &Face| {
        a.polygon
            .iter()
            .filter(|p| b.polygon.iter().any(|q| (*p - q).norm() <= tolerance))
            .count()
            >= 2
    };
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = (&faces[i], &faces[j]);
            if a.convex
                && b.convex
                && a.normal.dot(&b.normal) > 0.0
                && adjacent(a, b)
                && on_plane(a, b)
                && on_plane(b, a)
            {
                let (ri, rj) = (root(&group, i), root(&group, j));
                group[rj.max(ri)] = ri.min(rj);
            }
        }
    }
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); n];
    for i in 0..n {
        members[root(&group, i)].push(i);
    }
    members
        .into_iter()
        .filter(|m| !m.is_empty())
        .flat_map(|m| {
            if m.len() == 1 {
                return vec![faces[m[0]].clone()];
            }
            let area: Vector3<f64> = m.iter().map(|&i| faces[i].normal * faces[i].area).sum();
            let normal = area.normalize();
            let vertices: Vec<Vector3<f64>> = m
                .iter()
                .flat_map(|&i| faces[i].polygon.iter().copied())
                .collect();
            let offset =
                vertices.iter().map(|v| normal.dot(v)).sum::<f64>() / vertices.len() as f64;
            let u = any_perpendicular(&normal);
            let w = normal.cross(&u);
            let mut points: Vec<[f64; 2]> = vertices.iter().map(|p| [u.dot(p), w.dot(p)]).collect();
            let hull = simplified(convex_hull_2d(&mut points), tolerance);
            // One face only if the pieces are flat together (pairs within the tolerance chain
            // along a faceted camber: 20 facets of a 0.25 mm camber merged into a flat bed
            // under --tolerance 1e-4) and fill the hull (no gap between them).
            let flat = vertices
                .iter()
                .all(|v| (normal.dot(v) - offset).abs() <= tolerance);
            let pieces: f64 = m.iter().map(|&i| faces[i].area).sum();
            let perimeter: f64 = (0..hull.len())
                .map(|k| {
                    let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
                    (a[0] - b[0]).hypot(a[1] - b[1])
                })
                .sum();
            if !flat || (area_2d(&hull) - pieces).abs() > tolerance * perimeter {
                return m.iter().map(|&i| faces[i].clone()).collect();
            }
            vec![Face {
                polygon: hull
                    .iter()
                    .map(|p| u * p[0] + w * p[1] + normal * offset)
                    .collect(),
                normal,
                offset,
                convex: true,
                area: area_2d(&hull),
            }]
        })
        .collect()
}

/// The largest angle (rad) between two faces that touch (their outward normals opposite to
/// within it). Within it the faces touch where their overlap lies within the tolerance of both
/// planes, so that the tolerance decides: a block seated 0.01° askew on another (1e-4 m of gap
/// across it), as a survey or a scan gives, touches under `--tolerance 2e-4` and not under the
/// default 1e-6 m; opposite normals to 1e-9 were required, whatever the tolerance.
pub const MAX_CONTACT_TILT: f64 = 1e-2;

/// A contact's four corners as an exact rectangle in the plane normal to `normal`: the same
/// centre, and edges the means of its opposite edges, the second made normal to the first. A
/// contact found between faces written with rounded coordinates is a rectangle only to the
/// rounding (angles of 89.9999° at six decimals), which the model refuses (its corners must
/// make right angles to 1e-6); squared, it moves by no more than that rounding. A contact that
/// squaring would move by more than `tolerance` (m) at a corner (a rhombus, a trapezoid: not
/// a rectangle) and other polygons are returned as they are, to be refused as no rectangle.
fn squared(corners: &[Vector3<f64>], normal: &Vector3<f64>, tolerance: f64) -> Vec<Vector3<f64>> {
    let [a, b, c, d] = corners else {
        return corners.to_vec();
    };
    let flat = |v: Vector3<f64>| v - normal * normal.dot(&v);
    let centre = (a + b + c + d) / 4.0;
    let first = flat((b - a) + (c - d)) / 2.0;
    let Some(along) = first.try_normalize(0.0) else {
        return corners.to_vec();
    };
    let second = flat((d - a) + (c - b)) / 2.0;
    let second = second - along * along.dot(&second);
    let square = vec![
        centre - first / 2.0 - second / 2.0,
        centre + first / 2.0 - second / 2.0,
        centre + first / 2.0 + second / 2.0,
        centre - first / 2.0 + second / 2.0,
    ];
    if square
        .iter()
        .zip(corners)
        .all(|(p, q)| (p - q).norm() <= tolerance)
    {
        square
    } else {
        corners.to_vec()
    }
}

/// For a block that rests on nothing: how far below its bed the nearest face under it lies (a
/// face of another block facing it, or the ground plane), with the tolerance that would make
/// it a contact. A post 0.5 mm short was dropped from its lintel's supports without a word, and
/// "rests on nothing" did not say what `--tolerance` would join it; `None` where no face lies
/// under it at all.
fn nearest_bed_below(
    bodies: &[BodySpec],
    b: usize,
    ground_level: f64,
    tolerance: f64,
) -> Option<String> {
    let surfaces: Vec<Option<Surface>> = bodies.iter().map(|s| body_surface(s).ok()).collect();
    let mine = surfaces[b].as_ref()?;
    // Distances are taken near the block: plane offsets at survey coordinates carry the
    // normals' round-off times the distance (as in `detect_contacts`).
    let reference = mine.vertices.iter().sum::<Vector3<f64>>() / mine.vertices.len() as f64;
    let near = |s: &Surface| {
        let mut s = s.clone();
        for v in &mut s.vertices {
            *v -= reference;
        }
        s
    };
    let beds: Vec<Face> = faces_of(&near(mine), tolerance)
        .into_iter()
        .filter(|f| f.normal.z < -std::f64::consts::FRAC_1_SQRT_2)
        .collect();
    let facing = MAX_CONTACT_TILT.cos();
    let lowest = mine
        .vertices
        .iter()
        .map(|v| v.z)
        .fold(f64::INFINITY, f64::min);
    let mut best: Option<(f64, String)> =
        (lowest > ground_level).then(|| (lowest - ground_level, "the ground".to_string()));
    for (j, s) in surfaces.iter().enumerate() {
        let Some(s) = s.as_ref().filter(|_| j != b) else {
            continue;
        };
        for fb in faces_of(&near(s), tolerance) {
            for fa in &beds {
                let gap = -(fa.offset + fb.offset);
                if fa.normal.dot(&fb.normal) > -facing || gap <= 0.0 {
                    continue;
                }
                let (_, area) = overlap(&fa.polygon, &fb.polygon, &fb.normal, tolerance);
                if area > 0.0 && best.as_ref().is_none_or(|(g, _)| gap < *g) {
                    best = Some((gap, format!("\"{}\"", bodies[j].name)));
                }
            }
        }
    }
    let (gap, on) = best?;
    Some(format!(
        "; the nearest face under it is {gap:.3e} m below its bed (on {on}): a tolerance above \
         that (`--tolerance {:.2e}`) makes it a contact, if the gap is the drawing's and not the \
         structure's",
        gap * 1.1
    ))
}

/// The largest gap (a fraction of the smaller block's size) between two facing faces that
/// [`near_misses`] reports: a drawing's slip (a post 0.5 mm short under a lintel, 2.5e-4 of
/// its size) and not a joint left open on purpose (a mortar joint drawn 1 cm thick between
/// stones of 0.5 m is 2e-2).
pub const NEAR_MISS: f64 = 1e-2;

/// Two blocks whose faces face each other over an overlap, farther apart than the tolerance
/// but within [`NEAR_MISS`] of the smaller block's size: not a contact, perhaps meant to be one.
#[derive(Clone, Debug, PartialEq)]
pub struct NearMiss {
    /// The blocks (indices into the assembly's bodies).
    pub bodies: (usize, usize),
    /// The distance between the faces' planes (m).
    pub gap: f64,
    /// Whether the faces would make a bed (their normal within 45° of the vertical), the only
    /// contacts that are interfaces without `--all-contacts`.
    pub bed: bool,
}

/// The pairs of blocks of `bodies` with faces facing each other (opposite within
/// [`MAX_CONTACT_TILT`]) over an overlap, at a distance above `tolerance` and at most
/// [`NEAR_MISS`] of the smaller block's size: the smallest such gap of each pair. Pairs of
/// blocks both `fixed` are not looked at. Distances are taken near the pair (plane offsets at
/// survey coordinates carry the normals' round-off times the distance).
pub fn near_misses(bodies: &[BodySpec], tolerance: f64, fixed: &[bool]) -> Vec<NearMiss> {
    let surfaces: Vec<Option<Surface>> = bodies.iter().map(|s| body_surface(s).ok()).collect();
    let bounds = |s: &Surface| {
        s.vertices.iter().fold(
            (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), v| (lo.inf(v), hi.sup(v)),
        )
    };
    let is_fixed = |b: usize| fixed.get(b).copied().unwrap_or(false);
    let facing = MAX_CONTACT_TILT.cos();
    let mut out = Vec::new();
    for i in 0..bodies.len() {
        for j in i + 1..bodies.len() {
            let (Some(si), Some(sj)) = (&surfaces[i], &surfaces[j]) else {
                continue;
            };
            if is_fixed(i) && is_fixed(j) {
                continue;
            }
            let ((lo_i, hi_i), (lo_j, hi_j)) = (bounds(si), bounds(sj));
            let near = NEAR_MISS * (hi_i - lo_i).norm().min((hi_j - lo_j).norm());
            if (0..3).any(|k| lo_i[k] > hi_j[k] + near || lo_j[k] > hi_i[k] + near) {
                continue;
            }
            let reference = (lo_i + hi_i) / 2.0;
            let moved = |s: &Surface| {
                let mut s = s.clone();
                for v in &mut s.vertices {
                    *v -= reference;
                }
                s
            };
            let (fi, fj) = (
                faces_of(&moved(si), tolerance),
                faces_of(&moved(sj), tolerance),
            );
            let mut smallest: Option<(f64, bool)> = None;
            for fa in &fi {
                for fb in &fj {
                    let gap = -(fa.offset + fb.offset);
                    if fa.normal.dot(&fb.normal) > -facing || gap <= tolerance || gap > near {
                        continue;
                    }
                    let (_, area) = overlap(&fa.polygon, &fb.polygon, &fb.normal, tolerance);
                    if area > tolerance * near / NEAR_MISS && smallest.is_none_or(|(g, _)| gap < g)
                    {
                        smallest = Some((gap, fa.normal.z.abs() > std::f64::consts::FRAC_1_SQRT_2));
                    }
                }
            }
            if let Some((gap, bed)) = smallest {
                out.push(NearMiss {
                    bodies: (i, j),
                    gap,
                    bed,
                });
            }
        }
    }
    out
}

/// Signed area of a 2D polygon (positive counter-clockwise).
fn area_2d(p: &[[f64; 2]]) -> f64 {
    let m = p.len();
    (0..m)
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % m]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        * 0.5
}

/// The part of the convex polygon `subject` inside the convex polygon `clip` (both
/// counter-clockwise), by Sutherland–Hodgman: clipped by each edge's half-plane in turn.
fn clip_convex(subject: &[[f64; 2]], clip: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut out = subject.to_vec();
    let m = clip.len();
    for i in 0..m {
        if out.is_empty() {
            break;
        }
        let (a, b) = (clip[i], clip[(i + 1) % m]);
        // Inside: left of the edge a → b.
        let side = |p: [f64; 2]| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
        let input = std::mem::take(&mut out);
        let k = input.len();
        for j in 0..k {
            let (p, q) = (input[j], input[(j + 1) % k]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                let s = sp / (sp - sq);
                out.push([p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1])]);
            }
        }
    }
    out
}

/// The polygon without repeated points (within `tol`) and collinear middle points.
fn simplified(p: Vec<[f64; 2]>, tol: f64) -> Vec<[f64; 2]> {
    let mut q: Vec<[f64; 2]> = Vec::with_capacity(p.len());
    for v in p {
        if q.last()
            .is_none_or(|l| (l[0] - v[0]).hypot(l[1] - v[1]) > tol)
        {
            q.push(v);
        }
    }
    while q.len() > 1 {
        let (f, l) = (q[0], q[q.len() - 1]);
        if (f[0] - l[0]).hypot(f[1] - l[1]) > tol {
            break;
        }
        q.pop();
    }
    let mut changed = true;
    while changed && q.len() >= 3 {
        changed = false;
        let m = q.len();
        for i in 0..m {
            let (a, b, c) = (q[(i + m - 1) % m], q[i], q[(i + 1) % m]);
            let cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            let len = (c[0] - a[0]).hypot(c[1] - a[1]);
            if cross.abs() <= tol * len {
                q.remove(i);
                changed = true;
                break;
            }
        }
    }
    q
}

/// Which contacts become interfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactSet {
    /// The beds only (normals within 45° of the vertical: supports rocking under gravity); side
    /// contacts are reported. Every body needs a bed under it.
    Beds,
    /// Every contact face (beds, the inclined joints of an arch, head joints). Every body needs a
    /// chain of contacts to the ground; each interface's parent is the body nearer the ground
    /// along the contacts (breadth first).
    All,
}

/// The contact faces of `bodies` resting on the ground (the plane z = `ground_level`, m) and on
/// each other: faces facing each other in one plane (distance at most `tolerance`, m) whose
/// overlap has an area above tolerance × the model size. Every body must be supported through
/// the contacts of `set` (else it floats: an error naming it, and where the blocks' lowest point
/// is when none reaches the ground), and two bodies may touch on one face only (faces of a pair
/// in one plane are one face, their convex hull, when that is a rectangle).
///
/// The bodies marked in `fixed` (index by index; a shorter slice leaves the rest free) are part
/// of the ground: abutments, foundations, the rock of a stepped site. They may reach below the
/// ground level, they need no support, and a face of a free body on one of them rests on the
/// ground (`lower` None, the normal out of the fixed block), bed or side, beside, on or under
/// it; a block on several of them (or on them and the ground plane) by faces in one plane rests
/// on their convex hull when that is a rectangle ([`merge_coplanar`]), and by faces in several
/// planes has a ground contact on each. Fixed blocks may overlap each other; no contact is
/// reported between them.
pub fn detect_contacts(
    bodies: &[BodySpec],
    tolerance: f64,
    set: ContactSet,
    ground_level: f64,
    fixed: &[bool],
) -> Result<Vec<ContactFace>, AssemblyError> {
    let is_fixed = |b: usize| fixed.get(b).copied().unwrap_or(false);
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(error(
            "tolerance",
            format!("must be a positive length (m), got {tolerance}"),
        ));
    }
    if !ground_level.is_finite() {
        return Err(error(
            "ground level",
            format!("must be a finite height (m), got {ground_level}"),
        ));
    }
    let mut surfaces = bodies
        .iter()
        .map(body_surface)
        .collect::<Result<Vec<_>, _>>()?;
    // Faces are compared near the origin: a plane's offset n·x taken at survey coordinates
    // carries the normal's round-off times the distance (1e-9 × 4.5e6 m ≈ 5e-3 m, far beyond
    // the tolerance). The contacts are moved back.
    let reference = reference_near(&surfaces);
    for v in surfaces.iter_mut().flat_map(|s| s.vertices.iter_mut()) {
        *v -= reference;
    }
    let ground_near = ground_level - reference.z;
    let faces: Vec<Vec<Face>> = surfaces.iter().map(|s| faces_of(s, tolerance)).collect();
    let boxes: Vec<(Vector3<f64>, Vector3<f64>)> = surfaces
        .iter()
        .map(|s| {
            s.vertices.iter().fold(
                (
                    Vector3::repeat(f64::INFINITY),
                    Vector3::repeat(f64::NEG_INFINITY),
                ),
                |(lo, hi), v| (lo.inf(v), hi.sup(v)),
            )
        })
        .collect();
    let size = boxes
        .iter()
        .fold(0.0f64, |m, (lo, hi)| m.max((hi - lo).norm()));
    refuse_overlaps(
        bodies,
        &surfaces,
        &boxes,
        tolerance,
        ground_level,
        &reference,
        &is_fixed,
    )?;
    let min_area = tolerance * size;
    let facing = MAX_CONTACT_TILT.cos();
    let mut contacts = Vec::new();
    // On the ground: a face on the ground level whose outward normal is −z rests whole.
    for (b, fs) in faces.iter().enumerate().filter(|&(b, _)| !is_fixed(b)) {
        for f in fs {
            if f.normal.z < -facing
                && f.polygon
                    .iter()
                    .all(|v| (v.z - ground_near).abs() <= tolerance)
            {
                if !f.convex {
                    return Err(non_convex(&bodies[b].name));
                }
                let (corners, area) = overlap(&f.polygon, &f.polygon, &-f.normal, tolerance);
                if area > min_area {
                    contacts.push(ContactFace {
                        lower: None,
                        upper: b,
                        normal: Vector3::z(),
                        corners,
                        area,
                        bed: true,
                        support: None,
                    });
                }
            }
        }
    }
    for i in 0..bodies.len() {
        for j in i + 1..bodies.len() {
            let (lo_i, hi_i) = boxes[i];
            let (lo_j, hi_j) = boxes[j];
            let apart =
                (0..3).any(|k| lo_i[k] > hi_j[k] + tolerance || lo_j[k] > hi_i[k] + tolerance);
            if apart || (is_fixed(i) && is_fixed(j)) {
                continue;
            }
            for fa in &faces[i] {
                for fb in &faces[j] {
                    if fa.normal.dot(&fb.normal) > -facing {
                        continue;
                    }
                    // The normal from the lower body into the upper one; a side contact keeps
                    // the order of the file; a contact with a fixed block (beside, under or on
                    // it) has its normal out of the ground.
                    let bed = fa.normal.z.abs() > std::f64::consts::FRAC_1_SQRT_2;
                    let (lower, upper, normal) = if is_fixed(j) {
                        (j, i, fb.normal)
                    } else if is_fixed(i) || !bed || fa.normal.z > 0.0 {
                        (i, j, fa.normal)
                    } else {
                        (j, i, fb.normal)
                    };
                    let (corners, area) = overlap(&fa.polygon, &fb.polygon, &normal, tolerance);
                    // Within the tolerance of both faces' planes over their whole overlap: two
                    // faces apart, or tilted against each other by more than the tolerance
                    // over the overlap, do not touch.
                    let gap = |f: &Face| {
                        corners
                            .iter()
                            .map(|c| (f.normal.dot(c) - f.offset).abs())
                            .fold(0.0f64, f64::max)
                    };
                    if gap(fa) > tolerance || gap(fb) > tolerance {
                        continue;
                    }
                    if area > min_area && !(fa.convex && fb.convex) {
                        let b = if fa.convex { j } else { i };
                        return Err(non_convex(&bodies[b].name));
                    }
                    if area > min_area {
                        contacts.push(ContactFace {
                            lower: Some(lower).filter(|&b| !is_fixed(b)),
                            upper,
                            normal,
                            corners,
                            area,
                            bed,
                            support: Some(lower).filter(|&b| is_fixed(b)),
                        });
                    }
                }
            }
        }
    }
    // A block on two fixed blocks (or on one and the ground plane), or on a face split in
    // pieces, by faces in one plane rests on their convex hull when that is a rectangle (exact
    // for rigid bodies: merge_coplanar). Compared near the origin, as the faces were.
    let mut contacts = merge_coplanar(&contacts, InterfaceStyle::RockingBase, tolerance);
    let counts = |c: &ContactFace| c.bed || set == ContactSet::All;
    // Where the free blocks stand (a fixed footing may reach below the ground).
    let free_boxes: Vec<_> = (0..boxes.len())
        .filter(|&b| !is_fixed(b))
        .map(|b| boxes[b])
        .collect();
    let hint = ground_hint(&free_boxes, ground_near, reference.z, tolerance);
    for c in &mut contacts {
        for p in &mut c.corners {
            *p += reference;
        }
    }
    for (k, c) in contacts.iter().enumerate() {
        let same_pair = |d: &ContactFace| {
            (d.lower == c.lower && d.upper == c.upper)
                || (d.lower == Some(c.upper) && c.lower == Some(d.upper))
        };
        // Two faces of a pair in one plane that merge_coplanar left apart: their hull is no
        // rectangle, and one rocking interface cannot stand for them.
        let same_plane = |d: &ContactFace| {
            d.normal.dot(&c.normal).abs() >= MAX_CONTACT_TILT.cos()
                && (c.corners[0] - d.corners[0]).dot(&c.normal).abs() <= tolerance
        };
        // Two convex blocks meet on one face; a block that is not convex (an L-shaped stone in
        // a notch, a joggled voussoir), like a block on the ground (its plane and the fixed
        // blocks), may meet another on faces in several planes: interfaces `…_on_ground`,
        // `…_on_ground_2`, one per plane (structure_of).
        if let Some(lower) = c.lower
            && counts(c)
            && contacts[..k]
                .iter()
                .any(|d| counts(d) && same_pair(d) && same_plane(d))
        {
            let lower = &bodies[lower].name;
            return Err(error(
                format!("body \"{}\"", bodies[c.upper].name),
                format!(
                    "meets \"{lower}\" on faces in one plane whose convex hull is no rectangle: \
                     the faces of two blocks in one plane are one rocking interface, whose \
                     contact is a rectangle (its corners); cut the blocks so that they meet on a \
                     rectangle in that plane"
                ),
            ));
        }
    }
    match set {
        ContactSet::Beds => {
            for (b, body) in bodies.iter().enumerate() {
                let rests = |c: &ContactFace| c.bed && c.upper == b && c.normal.z > 0.0;
                if !is_fixed(b) && !contacts.iter().any(rests) {
                    return Err(error(
                        format!("body \"{}\"", body.name),
                        format!(
                            "rests on nothing: no face of it lies on the ground (z = \
                             {ground_level} m) or on a block below within the tolerance of \
                             {tolerance} m{}",
                            if hint.is_empty() {
                                nearest_bed_below(bodies, b, ground_level, tolerance)
                                    .unwrap_or_default()
                            } else {
                                hint.clone()
                            }
                        ),
                    ));
                }
            }
        }
        ContactSet::All => {
            let depth = ground_depths(bodies.len(), &contacts);
            if let Some(b) = (0..bodies.len()).find(|&b| !is_fixed(b) && depth[b].is_none()) {
                return Err(error(
                    format!("body \"{}\"", bodies[b].name),
                    format!(
                        "rests on nothing: no chain of contacts within the tolerance of \
                         {tolerance} m reaches it from the ground (z = {ground_level} m){hint}"
                    ),
                ));
            }
        }
    }
    // A block whose every contact pushes it down hangs: nothing can hold it up.
    for (b, body) in bodies.iter().enumerate().filter(|&(b, _)| !is_fixed(b)) {
        let mut into = contacts.iter().filter(|c| counts(c)).filter_map(|c| {
            if c.upper == b {
                Some(c.normal.z)
            } else if c.lower == Some(b) {
                Some(-c.normal.z)
            } else {
                None
            }
        });
        if let Some(first) = into.next()
            && first < -1e-9
            && into.all(|z| z < -1e-9)
        {
            return Err(error(
                format!("body \"{}\"", body.name),
                "hangs: every contact of it pushes it down (it lies under its supports), and \
                 nothing holds it up",
            ));
        }
    }
    Ok(contacts)
}

/// The free blocks of an assembly and its contacts ([`detect_contacts`]) renumbered for them:
/// the blocks marked in `fixed` are part of the ground (the contacts on them already rest on it)
/// and leave the structure.
pub fn free_blocks(
    bodies: &[BodySpec],
    contacts: &[ContactFace],
    fixed: &[bool],
) -> (Vec<BodySpec>, Vec<ContactFace>) {
    let is_fixed = |b: usize| fixed.get(b).copied().unwrap_or(false);
    let mut index = vec![None; bodies.len()];
    let mut free = Vec::with_capacity(bodies.len());
    for (b, body) in bodies.iter().enumerate().filter(|&(b, _)| !is_fixed(b)) {
        index[b] = Some(free.len());
        free.push(body.clone());
    }
    let renumbered = contacts
        .iter()
        .map(|c| ContactFace {
            lower: c.lower.and_then(|b| index[b]),
            upper: index[c.upper].expect("a contact's upper block is free"),
            ..c.clone()
        })
        .collect();
    (free, renumbered)
}

/// What a body resting on nothing is told when no block reaches down to the ground: where the
/// lowest block stands (blocks in a survey's coordinates, on ground at a site elevation), and
/// how to give that level. Empty when some block stands on the ground.
fn ground_hint(
    boxes: &[(Vector3<f64>, Vector3<f64>)],
    ground_near: f64,
    reference_z: f64,
    tolerance: f64,
) -> String {
    let lowest = boxes
        .iter()
        .map(|(lo, _)| lo.z)
        .fold(f64::INFINITY, f64::min);
    if lowest.is_finite() && lowest > ground_near + tolerance {
        // To the micrometre, in the shortest form (1.8, not 1.7999999999999998).
        let lowest = ((lowest + reference_z) * 1e6).round() / 1e6;
        format!(
            "; no block reaches down to the ground: the lowest stands at z = {lowest:.6} m, and \
             where the ground is there, give its level (`crr assemble --ground-level {lowest}`)"
        )
    } else {
        String::new()
    }
}

/// The point the surfaces are moved to the origin from ([`detect_contacts`]): none (zero) for
/// blocks within [`crate::MOVED_BEYOND`] sizes of the origin, so that their contacts are found
/// from their coordinates as given; otherwise the mean of the vertices rounded to a multiple of
/// the power of two at or above the size ([`crate::exact_reference`], as
/// [`crate::Model::moved_near_origin`]), which moves every coordinate exactly.
fn reference_near(surfaces: &[Surface]) -> Vector3<f64> {
    let vertices = || surfaces.iter().flat_map(|s| s.vertices.iter());
    let (lo, hi) = vertices().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), v| (lo.inf(v), hi.sup(v)),
    );
    let size = (hi - lo).norm();
    let count = vertices().count();
    if count == 0
        || size.is_nan()
        || size <= 0.0
        || vertices().all(|v| v.norm() <= crate::MOVED_BEYOND * size)
    {
        return Vector3::zeros();
    }
    let mean = vertices().sum::<Vector3<f64>>() / count as f64;
    crate::exact_reference(&mean, size)
}

/// The number of contacts between each body and the ground along the shortest chain of
/// contacts (breadth first; None: not reached).
fn ground_depths(bodies: usize, contacts: &[ContactFace]) -> Vec<Option<usize>> {
    let mut depth: Vec<Option<usize>> = vec![None; bodies];
    let mut frontier: Vec<usize> = contacts
        .iter()
        .filter(|c| c.lower.is_none())
        .map(|c| c.upper)
        .collect();
    let mut level = 1;
    while !frontier.is_empty() {
        let mut next = Vec::new();
        for b in frontier {
            if depth[b].is_none() {
                depth[b] = Some(level);
                for c in contacts {
                    match (c.lower, c.upper) {
                        (Some(l), u) if l == b && depth[u].is_none() => next.push(u),
                        (Some(l), u) if u == b && depth[l].is_none() => next.push(l),
                        _ => {}
                    }
                }
            }
        }
        frontier = next;
        level += 1;
    }
    depth
}

/// Blocks below the ground or inside one another are errors of the geometry: each is named, with
/// the depth and a point of the overlap (`surfaces` and `boxes` are moved by −`reference`, the
/// points reported moved back).
fn refuse_overlaps(
    bodies: &[BodySpec],
    surfaces: &[Surface],
    boxes: &[(Vector3<f64>, Vector3<f64>)],
    tolerance: f64,
    ground_level: f64,
    reference: &Vector3<f64>,
    is_fixed: &dyn Fn(usize) -> bool,
) -> Result<(), AssemblyError> {
    let ground_near = ground_level - reference.z;
    for (b, (lo, _)) in boxes.iter().enumerate() {
        if lo.z < ground_near - tolerance && !is_fixed(b) {
            return Err(error(
                format!("body \"{}\"", bodies[b].name),
                format!(
                    "reaches {:.6} m below the ground (z = {ground_level} m): a block must stand \
                     on or above it (where the ground lies lower, give its level: `crr assemble \
                     --ground-level Z`)",
                    ground_near - lo.z
                ),
            ));
        }
    }
    for i in 0..bodies.len() {
        for j in i + 1..bodies.len() {
            let ((lo_i, hi_i), (lo_j, hi_j)) = (boxes[i], boxes[j]);
            // Bounding boxes that overlap by at most the tolerance along some axis: apart or
            // touching. Fixed blocks are one ground and may overlap each other.
            if (0..3).any(|k| hi_i[k].min(hi_j[k]) - lo_i[k].max(lo_j[k]) <= tolerance)
                || (is_fixed(i) && is_fixed(j))
            {
                continue;
            }
            if let Some(p) =
                crate::interpenetration::interpenetration(&surfaces[i], &surfaces[j], tolerance)
            {
                return Err(error(
                    format!("bodies \"{}\" and \"{}\"", bodies[i].name, bodies[j].name),
                    format!(
                        "overlap: they interpenetrate by {:.6} m, around ({:.4}, {:.4}, {:.4}) m; \
                         blocks in contact touch along faces (within the tolerance of {tolerance} \
                         m)",
                        p.depth,
                        p.point.x + reference.x,
                        p.point.y + reference.y,
                        p.point.z + reference.z
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn non_convex(body: &str) -> AssemblyError {
    error(
        format!("body \"{body}\""),
        "touches another body (or the ground) with a face that is not convex: crr assemble \
         clips convex faces only (cut the block into convex parts)",
    )
}

/// The overlap of two facing planar polygons, expressed in the plane of `a`: its corners
/// counter-clockwise about `normal` and its area.
fn overlap(
    a: &[Vector3<f64>],
    b: &[Vector3<f64>],
    normal: &Vector3<f64>,
    tolerance: f64,
) -> (Vec<Vector3<f64>>, f64) {
    let e1 = any_perpendicular(normal);
    let e2 = normal.cross(&e1);
    let origin = a[0];
    let to_2d = |p: &Vector3<f64>| [(p - origin).dot(&e1), (p - origin).dot(&e2)];
    let ccw = |pts: &[Vector3<f64>]| {
        let mut p: Vec<[f64; 2]> = pts.iter().map(to_2d).collect();
        if area_2d(&p) < 0.0 {
            p.reverse();
        }
        p
    };
    let clipped = simplified(clip_convex(&ccw(a), &ccw(b)), tolerance);
    if clipped.len() < 3 {
        return (Vec::new(), 0.0);
    }
    let area = area_2d(&clipped);
    let corners = clipped
        .iter()
        .map(|p| origin + e1 * p[0] + e2 * p[1])
        .collect();
    (corners, area)
}

/// How the bed contacts become interfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InterfaceStyle {
    /// A rocking base per bed (3D rocking on the face's edges).
    RockingBase,
    /// A hinge about y per bed, its pivots the overlap's lines of least and greatest x (a planar
    /// layout in the x–z plane: every bed horizontal and spanning the same depth along y).
    PlanarHinge,
}

/// The structure whose interfaces are the contacts of `set` (named `CHILD_on_PARENT`; `ground`
/// for the ground), listed from the ground up so that the spanning tree reaches each body through
/// its first support and the other supports close loops. A bed's parent is its lower body; with
/// [`ContactSet::All`] an interface's parent is the body nearer the ground along the contacts (at
/// equal distance, a bed's lower body, else the body listed first), its normal and corners turned
/// to point into the child.
pub fn structure_of(
    name: &str,
    gravity: f64,
    bodies: &[BodySpec],
    contacts: &[ContactFace],
    style: InterfaceStyle,
    set: ContactSet,
    tolerance: f64,
) -> Result<StructureSpec, AssemblyError> {
    let name_of = |b: Option<usize>| b.map_or("ground", |b| bodies[b].name.as_str());
    let oriented: Vec<ContactFace> = match set {
        ContactSet::Beds => contacts.iter().filter(|c| c.bed).cloned().collect(),
        ContactSet::All => {
            let depth = ground_depths(bodies.len(), contacts);
            contacts
                .iter()
                .map(|c| match c.lower {
                    Some(l) if depth[c.upper] < depth[l] => ContactFace {
                        lower: Some(c.upper),
                        upper: l,
                        normal: -c.normal,
                        corners: c.corners.iter().rev().copied().collect(),
                        ..c.clone()
                    },
                    _ => c.clone(),
                })
                .collect()
        }
    };
    let mut beds: Vec<&ContactFace> = oriented.iter().collect();
    // From the ground up: by the contact's height, then by the bodies' order.
    beds.sort_by(|a, b| {
        let za = a.corners.iter().map(|c| c.z).fold(f64::INFINITY, f64::min);
        let zb = b.corners.iter().map(|c| c.z).fold(f64::INFINITY, f64::min);
        za.total_cmp(&zb)
            .then(a.upper.cmp(&b.upper))
            .then(a.lower.cmp(&b.lower))
    });
    let mut interfaces = Vec::with_capacity(beds.len());
    for c in beds {
        let iname = format!("{}_on_{}", name_of(Some(c.upper)), name_of(c.lower));
        let item = || format!("contact \"{iname}\"");
        let mut spec = InterfaceSpec {
            name: iname.clone(),
            parent: name_of(c.lower).to_string(),
            child: name_of(Some(c.upper)).to_string(),
            axis: None,
            pivot_positive: None,
            pivot_negative: None,
            rocking_base: None,
            normal: None,
            impact: Default::default(),
        };
        match style {
            InterfaceStyle::RockingBase => {
                spec.rocking_base = Some(RockingBaseSpec {
                    corners: squared(&c.corners, &c.normal, tolerance)
                        .iter()
                        .map(|p| [p.x, p.y, p.z])
                        .collect(),
                    twist: false,
                });
            }
            InterfaceStyle::PlanarHinge => {
                let (axis, pivot_positive, pivot_negative) = planar_pivots(c, tolerance)
                    .ok_or_else(|| {
                        error(
                            item(),
                            "is not a rectangle spanning the blocks' depth along y in a plane \
                             containing y: a planar layout (--planar) needs joints whose \
                             faces contain the y direction",
                        )
                    })?;
                spec.axis = Some(axis);
                spec.pivot_positive = Some(PivotSpec::Segment(pivot_positive));
                spec.pivot_negative = Some(PivotSpec::Segment(pivot_negative));
            }
        }
        spec.normal = needs_normal(bodies, c, &spec).then(|| c.normal.into());
        interfaces.push(spec);
    }
    // Two bodies meeting on faces in different planes (rigid domains along a stepped joint, a
    // stone that is not convex): the second and later interfaces of a pair are named `…_2`,
    // `…_3`, skipping any name another pair has (a body named `ell_2` makes `block_on_ell_2`
    // too).
    let mut taken: std::collections::HashSet<String> =
        interfaces.iter().map(|i| i.name.clone()).collect();
    let mut seen: std::collections::HashSet<String> = std::collections::HashSet::new();
    for spec in &mut interfaces {
        if seen.insert(spec.name.clone()) {
            continue;
        }
        let name = (2..)
            .map(|k| format!("{}_{k}", spec.name))
            .find(|n| !taken.contains(n))
            .expect("a free suffix");
        taken.insert(name.clone());
        spec.name = name;
    }
    Ok(StructureSpec {
        name: name.to_string(),
        gravity,
        body: bodies.to_vec(),
        interface: interfaces,
        symmetry: Vec::new(),
    })
}

/// Whether the interface `spec` of contact `c` must say which side is its child's: the model
/// takes the side of the child's centre of mass by default (`Model::from_spec`), which a stone
/// that is not convex can lie across, a joggled or hooked stone resting on a ledge above its
/// centre (the joint then turned round could only pull it down: a joggled lintel's multiplier
/// along −x came out 0.700 for 0.486, an independent review). Written where the default side is
/// not clearly the contact's: its direction from the face within 0.06° of the face's plane, or
/// beyond it.
fn needs_normal(bodies: &[BodySpec], c: &ContactFace, spec: &InterfaceSpec) -> bool {
    let face = spec.face_points();
    if face.is_empty() {
        return false;
    }
    let Some(side) = crate::model::default_side_point(&bodies[c.upper], &face) else {
        return false;
    };
    let towards = side - Vector3::from(face[0]);
    c.normal.dot(&towards) <= 1e-3 * towards.norm()
}

/// The contacts with every group of coplanar faces between the same two bodies (or a body and
/// the ground) replaced by one face, the convex hull of their corners, when that hull is an
/// interface of `style` (a rectangle; for hinges, one spanning the depth along y). Exact for
/// rigid bodies: compressive forces at a set of points in a plane transmit the same wrenches as
/// forces at the vertices of its convex hull (every point of the hull is a convex combination
/// of them, and the hull's vertices are points of the set), and a rigid pair rocks on an edge of
/// that hull. Faces of a pair in different planes (a stepped joint) are kept as they are.
pub fn merge_coplanar(
    contacts: &[ContactFace],
    style: InterfaceStyle,
    tolerance: f64,
) -> Vec<ContactFace> {
    let mut used = vec![false; contacts.len()];
    let mut out = Vec::with_capacity(contacts.len());
    for i in 0..contacts.len() {
        if used[i] {
            continue;
        }
        used[i] = true;
        let first = &contacts[i];
        let offset = first.normal.dot(&first.corners[0]);
        // The same pair in the same plane, oriented as the first (lower into upper).
        let mut group = vec![first.clone()];
        for (j, c) in contacts.iter().enumerate().skip(i + 1) {
            if used[j] {
                continue;
            }
            let oriented = if (c.lower, Some(c.upper)) == (first.lower, Some(first.upper)) {
                c.clone()
            } else if (c.lower, Some(c.upper)) == (Some(first.upper), first.lower) {
                let Some(lower) = c.lower else { continue };
                ContactFace {
                    lower: Some(c.upper),
                    upper: lower,
                    normal: -c.normal,
                    corners: c.corners.iter().rev().copied().collect(),
                    ..c.clone()
                }
            } else {
                continue;
            };
            let coplanar = (oriented.normal - first.normal).norm() <= 1e-9
                && oriented
                    .corners
                    .iter()
                    .all(|p| (first.normal.dot(p) - offset).abs() <= tolerance);
            if coplanar {
                used[j] = true;
                group.push(oriented);
            }
        }
        if group.len() == 1 {
            out.push(group.pop().expect("one face"));
            continue;
        }
        let hull = coplanar_hull(&group, tolerance);
        let fits = match style {
            InterfaceStyle::PlanarHinge => planar_pivots(&hull, tolerance).is_some(),
            InterfaceStyle::RockingBase => is_rectangle(&hull.corners, tolerance),
        };
        if fits {
            out.push(hull);
        } else {
            out.extend(group);
        }
    }
    out
}

/// One face whose corners are the convex hull (counter-clockwise about the normal) of the
/// corners of `faces`, coplanar faces of one pair oriented alike.
fn coplanar_hull(faces: &[ContactFace], tolerance: f64) -> ContactFace {
    let n = faces[0].normal;
    let u = any_perpendicular(&n);
    let v = n.cross(&u);
    let h = n.dot(&faces[0].corners[0]);
    let mut points: Vec<[f64; 2]> = faces
        .iter()
        .flat_map(|f| f.corners.iter().map(|p| [u.dot(p), v.dot(p)]))
        .collect();
    let hull = simplified(convex_hull_2d(&mut points), tolerance);
    let support = faces[0].support;
    ContactFace {
        corners: hull.iter().map(|p| u * p[0] + v * p[1] + n * h).collect(),
        area: area_2d(&hull),
        support: support.filter(|_| faces.iter().all(|f| f.support == support)),
        ..faces[0].clone()
    }
}

/// The convex hull of 2D points, counter-clockwise (Andrew's monotone chain).
fn convex_hull_2d(points: &mut [[f64; 2]]) -> Vec<[f64; 2]> {
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(points.len() + 1);
    for pass in [false, true] {
        let start = hull.len();
        let ordered: Vec<[f64; 2]> = if pass {
            points.iter().rev().copied().collect()
        } else {
            points.to_vec()
        };
        for p in ordered {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// Whether four corners in order make a rectangle (each corner's two edges at right angles,
/// within `tolerance` times the edges' lengths).
pub fn is_rectangle(corners: &[Vector3<f64>], tolerance: f64) -> bool {
    corners.len() == 4
        && (0..4).all(|i| {
            let (a, b, c) = (corners[(i + 3) % 4], corners[i], corners[(i + 1) % 4]);
            let (e1, e2) = (a - b, c - b);
            e1.dot(&e2).abs() <= tolerance * (e1.norm() + e2.norm())
        })
}

/// The rocking base a contact face that is no rectangle (a drum's polygon) is given with
/// `crr assemble --inscribed`: the largest rectangle with the proportions of the face's bounding
/// box, centred at its centroid, inside it. Its edges run along u and v = n × u in the face's
/// plane, u = x for a horizontal face (else the horizontal direction in its plane, z × n
/// normalised), so that a bed's rocking base tilts about x and y. The rectangle
/// c + s(±W/2, ±H/2) (W × H the bounding box in (u, v), c the centroid) lies in the face where
/// every corner satisfies every edge's half-plane a·p ≤ b, the worst corner
/// a·c + s(|a_u| W/2 + |a_v| H/2) ≤ b: s is the least (b − a·c)/(|a_u| W/2 + |a_v| H/2) over the
/// edges, in closed form (not the largest rectangle of any proportions: a regular hexagon with a
/// vertex on u holds a larger one than its bounding box's shape); a regular 16-gon of radius R
/// with a vertex on u gives the square of half-side R cos 45°. A subset of
/// the face carries a subset of its contact forces, so multipliers computed on it are lower
/// bounds of the whole face's (the static theorem).
pub fn inscribed_rectangle(face: &ContactFace) -> ContactFace {
    let n = face.normal;
    let u = if n.z.abs() >= 1.0 - 1e-9 {
        Vector3::x()
    } else {
        Vector3::z().cross(&n).normalize()
    };
    let v = n.cross(&u);
    // Relative to a corner: a face in survey coordinates keeps its precision (its centroid's
    // shoelace sums of absolute coordinates lost it: a drum bed 1e5 m away shrank to a third).
    let origin = face.corners[0];
    let p: Vec<[f64; 2]> = face
        .corners
        .iter()
        .map(|c| [u.dot(&(c - origin)), v.dot(&(c - origin))])
        .collect();
    let count = p.len();
    // Area centroid of the polygon (corners counter-clockwise about n, so about (u, v)).
    let (mut area2, mut cu, mut cv) = (0.0, 0.0, 0.0);
    for i in 0..count {
        let (a, b) = (p[i], p[(i + 1) % count]);
        let cross = a[0] * b[1] - b[0] * a[1];
        area2 += cross;
        cu += (a[0] + b[0]) * cross;
        cv += (a[1] + b[1]) * cross;
    }
    let c = [cu / (3.0 * area2), cv / (3.0 * area2)];
    let (lo, hi) = p.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), q| {
            (
                [lo[0].min(q[0]), lo[1].min(q[1])],
                [hi[0].max(q[0]), hi[1].max(q[1])],
            )
        },
    );
    let (half_w, half_h) = ((hi[0] - lo[0]) / 2.0, (hi[1] - lo[1]) / 2.0);
    let scale = (0..count)
        .filter_map(|i| {
            let (a, b) = (p[i], p[(i + 1) % count]);
            // The edge's outward normal (the polygon counter-clockwise): (dv, −du).
            let out = [b[1] - a[1], a[0] - b[0]];
            let reach = out[0].abs() * half_w + out[1].abs() * half_h;
            let slack = out[0] * (a[0] - c[0]) + out[1] * (a[1] - c[1]);
            (reach > 0.0).then(|| slack / reach)
        })
        .fold(1.0f64, f64::min)
        .max(0.0);
    let (w, hh) = (scale * half_w, scale * half_h);
    let corners = [[-w, -hh], [w, -hh], [w, hh], [-w, hh]]
        .iter()
        .map(|d| origin + u * (c[0] + d[0]) + v * (c[1] + d[1]))
        .collect();
    ContactFace {
        corners,
        area: 4.0 * w * hh,
        ..face.clone()
    }
}

/// The hinge about y of a contact face of a planar layout (in the x–z plane): its plane must
/// contain y (normal n ⟂ y) and its overlap be a rectangle with edges along y and along
/// s = y × n (for a horizontal bed, s = x). The pivot lines run along y at the least and greatest
/// s; a positive angle about +y moves a point at distance d from the line at the greatest s by
/// y × (−d s) = d n, off the parent: the child pivots on that line (P⁺), as a block on its +x edge.
#[allow(clippy::type_complexity)]
fn planar_pivots(
    c: &ContactFace,
    tolerance: f64,
) -> Option<([f64; 3], [[f64; 3]; 2], [[f64; 3]; 2])> {
    if c.normal.y.abs() > 1e-9 {
        return None;
    }
    let y = Vector3::y();
    let s = y.cross(&c.normal);
    let range = |u: &Vector3<f64>| {
        c.corners
            .iter()
            .map(|p| u.dot(p))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            })
    };
    let ((s0, s1), (y0, y1)) = (range(&s), range(&y));
    let rectangle = (s1 - s0) * (y1 - y0);
    if (rectangle - c.area).abs() > tolerance * (s1 - s0 + y1 - y0) {
        return None;
    }
    // The face's plane: n·x = h; a point of it at (s, y) is s ŝ + y ŷ + h n.
    let h = c.normal.dot(&c.corners[0]);
    let at = |sv: f64, yv: f64| {
        let p = s * sv + y * yv + c.normal * h;
        [p.x, p.y, p.z]
    };
    Some((
        [0.0, 1.0, 0.0],
        [at(s1, y0), at(s1, y1)],
        [at(s0, y0), at(s0, y1)],
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square face at z = 0 from the ground into body `upper`, its corners from (x0, y0).
    fn square(upper: usize, x0: f64, y0: f64) -> ContactFace {
        let c = |x: f64, y: f64| Vector3::new(x0 + x, y0 + y, 0.0);
        ContactFace {
            lower: None,
            upper,
            normal: Vector3::z(),
            corners: vec![c(0.0, 0.0), c(1.0, 0.0), c(1.0, 1.0), c(0.0, 1.0)],
            area: 1.0,
            bed: true,
            support: None,
        }
    }

    #[test]
    fn coplanar_faces_of_one_pair_merge_into_their_hull_when_it_is_a_rectangle() {
        // Two squares side by side under one body: one face, the 2 × 1 rectangle.
        let merged = merge_coplanar(
            &[square(0, 0.0, 0.0), square(0, 1.0, 0.0)],
            InterfaceStyle::RockingBase,
            1e-9,
        );
        assert_eq!(merged.len(), 1);
        assert!((merged[0].area - 2.0).abs() < 1e-15);
        assert_eq!(merged[0].corners.len(), 4);
        assert!(is_rectangle(&merged[0].corners, 1e-9));
        // Two feet apart: the hull (3 × 1) spans the gap, the same cone of contact wrenches.
        let apart = merge_coplanar(
            &[square(0, 0.0, 0.0), square(0, 2.0, 0.0)],
            InterfaceStyle::RockingBase,
            1e-9,
        );
        assert_eq!(apart.len(), 1);
        assert!((apart[0].area - 3.0).abs() < 1e-15);
        // Diagonal squares: a hexagonal hull, not a rocking base; kept apart.
        let diagonal = merge_coplanar(
            &[square(0, 0.0, 0.0), square(0, 1.0, 1.0)],
            InterfaceStyle::RockingBase,
            1e-9,
        );
        assert_eq!(diagonal.len(), 2);
        // Other bodies, or another plane, are never merged.
        let mut high = square(0, 1.0, 0.0);
        high.corners.iter_mut().for_each(|p| p.z = 0.5);
        assert_eq!(
            merge_coplanar(
                &[square(0, 0.0, 0.0), square(1, 1.0, 0.0), high],
                InterfaceStyle::RockingBase,
                1e-9
            )
            .len(),
            3
        );
    }

    #[test]
    fn clipping_two_squares_gives_their_overlap() {
        let a = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        let b = [[1.0, 1.0], [3.0, 1.0], [3.0, 3.0], [1.0, 3.0]];
        let o = simplified(clip_convex(&a, &b), 1e-12);
        assert_eq!(o.len(), 4);
        assert!((area_2d(&o) - 1.0).abs() < 1e-15);
        let far = [[5.0, 5.0], [6.0, 5.0], [6.0, 6.0]];
        assert!(clip_convex(&a, &far).is_empty());
        // Touching along an edge only: no area.
        let edge = [[2.0, 0.0], [3.0, 0.0], [3.0, 2.0], [2.0, 2.0]];
        assert!(simplified(clip_convex(&a, &edge), 1e-12).len() < 3);
    }
}
