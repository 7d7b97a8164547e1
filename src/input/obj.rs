//! Blocks from a Wavefront OBJ file (`[[obj]]` of an assembly, docs/assembly.md): one object (or
//! group) per block, each a closed convex polyhedron, in the file's units, turned into bodies of
//! the model format (a `polyhedron` with the block's vertices, named after its object).
//!
//! The mesh is read by `tobj`. Each object's vertices are welded by position (a CAD export often
//! repeats them per face), its faces must close it (every edge shared by exactly two faces; a
//! face wound the other way from its neighbours is turned to agree) and it must be convex (every vertex on the inner side of every face),
//! since a `polyhedron` body is the convex hull of its vertices; a block that is not is refused
//! by name, with the edge or the face concerned.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crr_kinematics::exact_reference;
use crr_kinematics::shapes::{PolyhedronShape, Shape};
use crr_kinematics::spec::BodySpec;

use crate::Error;

/// Length unit of an OBJ file's coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ObjUnits {
    /// Metres (the default).
    #[default]
    M,
    /// Centimetres.
    Cm,
    /// Millimetres.
    Mm,
}

impl ObjUnits {
    /// Metres per unit.
    pub fn metres(self) -> f64 {
        match self {
            ObjUnits::M => 1.0,
            ObjUnits::Cm => 0.01,
            ObjUnits::Mm => 0.001,
        }
    }
}

/// The vertical axis of an OBJ file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ObjUp {
    /// z up, as crr (the default).
    #[default]
    Z,
    /// y up (many modelling tools): (x, y, z) is read as (x, −z, y), a rotation of 90° about x.
    Y,
}

/// An `[[obj]]` table: the blocks of a Wavefront OBJ file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjSpec {
    /// The OBJ file; a relative path is resolved against the assembly file's folder.
    pub file: PathBuf,
    /// Density of every block (kg/m³).
    pub density: f64,
    /// Unit of the coordinates (`m`, `cm` or `mm`; default `m`).
    #[serde(default)]
    pub units: ObjUnits,
    /// The vertical axis (`z` or `y`; default `z`).
    #[serde(default)]
    pub up: ObjUp,
}

/// The largest OBJ file read (bytes): a mesh of a few hundred blocks takes a few megabytes.
pub const OBJ_FILE_LIMIT: u64 = 256 << 20;

/// How far (a fraction of a block's size, its bounding-box diagonal) a vertex may lie outside a
/// face's plane before the block is refused as not convex: CAD programs write OBJ coordinates
/// to six decimals (a rounding of up to 0.87e-6 m off a plane), and a 9-voussoir arch turned to
/// a 30° bearing so written was refused at 1e-9 of its size. 1e-5 of a block (5 µm on 0.5 m)
/// is far below any concavity a mason cuts; the block is the convex hull of its vertices.
pub const CONVEX_TOLERANCE: f64 = 1e-5;

/// The bodies of the OBJ file of `spec` (its path relative to `folder`), one per object.
pub fn obj_bodies(spec: &ObjSpec, folder: &Path) -> Result<Vec<BodySpec>, Error> {
    let path = folder.join(&spec.file);
    let here = |m: String| Error::Argument(format!("{}: {m}", path.display()));
    if !(spec.density.is_finite() && spec.density > 0.0) {
        return Err(here(format!(
            "density must be a positive number (kg/m³), got {}",
            spec.density
        )));
    }
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ..Default::default()
    };
    // A regular file of bounded size, like every other input (a FIFO hung the reader, and
    // /dev/zero exhausted the memory); materials are not read (only the geometry is used).
    let bytes = crr_dynamics::input::read_regular_file(&path, OBJ_FILE_LIMIT)
        .map_err(|e| here(e.to_string()))?;
    let text = ObjText::new(&bytes);
    let (models, _) = tobj::load_obj_buf(&mut text.bytes.as_slice(), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| here(format!("{e}")))?;
    if models.is_empty() {
        return Err(here("no object in the file".into()));
    }
    let mut bodies: Vec<BodySpec> = Vec::with_capacity(models.len());
    for (k, m) in models.iter().enumerate() {
        let name = if m.name.trim().is_empty() {
            format!("object_{}", k + 1)
        } else {
            m.name.trim().to_string()
        };
        if bodies.iter().any(|b| b.name == name) {
            return Err(here(format!(
                "object \"{name}\" appears twice: every block needs its own name"
            )));
        }
        let item = |m: String| here(format!("object \"{name}\": {m}{}", text.groups_hint(&name)));
        let block = Block::from_mesh(&m.mesh, spec).map_err(item)?;
        let mut block = block;
        block.orient_faces_alike();
        block.check_closed().map_err(item)?;
        block.check_convex().map_err(item)?;
        bodies.push(BodySpec::simple(
            &name,
            spec.density,
            Shape::Polyhedron(PolyhedronShape {
                vertices: block.vertices.iter().map(|v| [v.x, v.y, v.z]).collect(),
            }),
        ));
    }
    Ok(bodies)
}

/// An OBJ file's text as tobj is given it, and what was changed: each object (`o`) is one block,
/// the groups (`g`) inside an object are parts of its surface (a CAD program's material or
/// layer groups: a column's sides `g stone` and its polished top `g polished`; tobj starts a
/// model at each `o` and each `g` alike, so a column so written was split into open meshes);
/// groups before the first object, or in a file without objects, stay blocks. A block without a
/// name is `object_N`, N its number among the blocks that have faces (`object_N_2` … where the
/// file names another block so), and faces before any `o` or `g` are a block of their own
/// (`o object_1` is put before them; every other line keeps its place).
struct ObjText {
    bytes: Vec<u8>,
    /// The groups merged into each object, by the object's name.
    groups_of: HashMap<String, Vec<String>>,
}

impl ObjText {
    fn new(bytes: &[u8]) -> ObjText {
        let lines: Vec<&[u8]> = bytes.split(|&b| b == b'\n').collect();
        let parsed: Vec<(String, String)> = lines
            .iter()
            .map(|line| {
                let text = String::from_utf8_lossy(line);
                let mut words = text.trim_start().splitn(2, char::is_whitespace);
                let keyword = words.next().unwrap_or("").to_string();
                (keyword, words.next().unwrap_or("").trim().to_string())
            })
            .collect();
        // Which lines start a block: every `o`, and a `g` before the first `o`.
        let first_object = parsed.iter().position(|(k, _)| k == "o");
        let starts: Vec<bool> = parsed
            .iter()
            .enumerate()
            .map(|(i, (k, _))| k == "o" || (k == "g" && first_object.is_none_or(|o| i < o)))
            .collect();
        // A block is numbered when faces follow it before the next start; faces before any
        // start are a block of their own (block 1).
        let mut with_faces = vec![false; lines.len()];
        let mut current = None;
        let mut leading_faces = false;
        for (i, (k, _)) in parsed.iter().enumerate() {
            if starts[i] {
                current = Some(i);
            } else if k == "f" {
                match current {
                    Some(c) => with_faces[c] = true,
                    None => leading_faces = true,
                }
            }
        }
        let mut taken: std::collections::HashSet<String> = parsed
            .iter()
            .zip(&starts)
            .filter(|((_, name), start)| **start && !name.is_empty())
            .map(|((_, name), _)| name.clone())
            .collect();
        let mut fresh = |number: usize| {
            let name = (1..)
                .map(|k| match k {
                    1 => format!("object_{number}"),
                    k => format!("object_{number}_{k}"),
                })
                .find(|n| !taken.contains(n))
                .expect("a free name");
            taken.insert(name.clone());
            name
        };
        let mut out = Vec::with_capacity(bytes.len() + 64);
        let mut groups_of: HashMap<String, Vec<String>> = HashMap::new();
        let (mut object, mut number) = (None::<String>, usize::from(leading_faces));
        if leading_faces {
            out.extend_from_slice(format!("o {}\n", fresh(1)).as_bytes());
        }
        for (i, line) in lines.iter().enumerate() {
            if i > 0 {
                out.push(b'\n');
            }
            let (keyword, name) = &parsed[i];
            if starts[i] {
                number += usize::from(with_faces[i]);
                let name = if name.is_empty() {
                    fresh(number)
                } else {
                    name.clone()
                };
                if keyword == "o" {
                    object = Some(name.clone());
                }
                out.extend_from_slice(format!("{keyword} {name}").as_bytes());
                if line.ends_with(b"\r") {
                    out.push(b'\r');
                }
            } else if keyword == "g" {
                let inside = object.clone().unwrap_or_default();
                groups_of.entry(inside).or_default().push(name.clone());
                out.extend_from_slice(b"# ");
                out.extend_from_slice(line);
            } else {
                out.extend_from_slice(line);
            }
        }
        ObjText {
            bytes: out,
            groups_of,
        }
    }

    /// What an object that is refused should be told about the groups merged into it.
    fn groups_hint(&self, object: &str) -> String {
        match self.groups_of.get(object) {
            Some(groups) if !groups.is_empty() => format!(
                " (its faces come in the groups {} inside object \"{object}\": the groups \
                 inside an object are parts of one block; if each group is a block, write an \
                 `o` line before each, or remove the object's `o` line)",
                groups
                    .iter()
                    .map(|g| format!("\"{g}\""))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            _ => String::new(),
        }
    }
}

/// One object's mesh with its vertices welded (m, z up).
struct Block {
    vertices: Vec<Vector3<f64>>,
    faces: Vec<Vec<usize>>,
}

impl Block {
    fn from_mesh(mesh: &tobj::Mesh, spec: &ObjSpec) -> Result<Block, String> {
        let scale = spec.units.metres();
        let point = |i: usize| {
            let p = &mesh.positions[3 * i..3 * i + 3];
            let v = Vector3::new(p[0], p[1], p[2]) * scale;
            match spec.up {
                ObjUp::Z => v,
                ObjUp::Y => Vector3::new(v.x, -v.z, v.y),
            }
        };
        // Weld equal positions: the same corner written once per face is one vertex.
        let mut index: HashMap<[u64; 3], usize> = HashMap::new();
        let mut vertices = Vec::new();
        let mut welded = Vec::with_capacity(mesh.positions.len() / 3);
        for i in 0..mesh.positions.len() / 3 {
            let v = point(i);
            if !(v.x.is_finite() && v.y.is_finite() && v.z.is_finite()) {
                return Err(format!("vertex {} is not finite", i + 1));
            }
            // −0.0 and 0.0 are one position (+ 0.0 turns −0.0 into 0.0).
            let key = [
                (v.x + 0.0).to_bits(),
                (v.y + 0.0).to_bits(),
                (v.z + 0.0).to_bits(),
            ];
            let id = *index.entry(key).or_insert_with(|| {
                vertices.push(v);
                vertices.len() - 1
            });
            welded.push(id);
        }
        let arities: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        let mut faces = Vec::with_capacity(arities.len());
        let mut at = 0;
        for a in arities {
            let face: Vec<usize> = mesh.indices[at..at + a]
                .iter()
                .map(|&i| welded[i as usize])
                .collect();
            at += a;
            faces.push(face);
        }
        if vertices.len() < 4 || faces.len() < 4 {
            return Err(format!(
                "{} vertices and {} faces do not close a solid",
                vertices.len(),
                faces.len()
            ));
        }
        Ok(Block { vertices, faces })
    }

    fn edges(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.faces.iter().flat_map(|f| {
            let m = f.len();
            (0..m).map(move |i| (f[i], f[(i + 1) % m]))
        })
    }

    /// Turns faces wound the other way from their neighbours to agree with them, when every
    /// edge belongs to exactly two faces (a closed surface; otherwise nothing is turned and
    /// [`Block::check_closed`] names the edge). Exporters write a face reversed now and then,
    /// and it changes nothing here: the block is the convex hull of its vertices. Each connected
    /// surface keeps the winding of its first face; the outward side is taken from the sign of
    /// its volume later.
    fn orient_faces_alike(&mut self) {
        let mut sharing: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        for (f, face) in self.faces.iter().enumerate() {
            let m = face.len();
            for i in 0..m {
                let (a, b) = (face[i], face[(i + 1) % m]);
                sharing.entry((a.min(b), a.max(b))).or_default().push(f);
            }
        }
        if sharing.values().any(|faces| faces.len() != 2) {
            return;
        }
        // Whether face f runs along a → b.
        let runs = |face: &[usize], a: usize, b: usize| {
            let m = face.len();
            (0..m).any(|i| face[i] == a && face[(i + 1) % m] == b)
        };
        let mut settled = vec![false; self.faces.len()];
        for start in 0..self.faces.len() {
            if settled[start] {
                continue;
            }
            settled[start] = true;
            let mut stack = vec![start];
            while let Some(f) = stack.pop() {
                let face = self.faces[f].clone();
                let m = face.len();
                for i in 0..m {
                    let (a, b) = (face[i], face[(i + 1) % m]);
                    for &g in &sharing[&(a.min(b), a.max(b))] {
                        if g == f || settled[g] {
                            continue;
                        }
                        // A neighbour agreeing with f runs along the shared edge b → a.
                        if runs(&self.faces[g], a, b) {
                            self.faces[g].reverse();
                        }
                        settled[g] = true;
                        stack.push(g);
                    }
                }
            }
        }
    }

    /// Every edge is met once in each direction: two faces share it, oriented alike. A hole or
    /// an edge of more than two faces is named first (the first such edge in the faces' order,
    /// whatever the winding of the others), then an edge met twice the same way, which
    /// [`Block::orient_faces_alike`] leaves only on a one-sided surface.
    fn check_closed(&self) -> Result<(), String> {
        if let Some((a, _)) = self.edges().find(|(a, b)| a == b) {
            let p = self.vertices[a];
            return Err(format!(
                "a face repeats the vertex ({:.6}, {:.6}, {:.6}) m: an edge of no length",
                p.x, p.y, p.z
            ));
        }
        let mut count: HashMap<(usize, usize), usize> = HashMap::new();
        for (a, b) in self.edges() {
            *count.entry((a, b)).or_default() += 1;
        }
        let met = |a: usize, b: usize| count.get(&(a, b)).copied().unwrap_or(0);
        let edge = |a: usize, b: usize| {
            let (p, q) = (self.vertices[a], self.vertices[b]);
            format!(
                "the edge from ({:.6}, {:.6}, {:.6}) to ({:.6}, {:.6}, {:.6}) m",
                p.x, p.y, p.z, q.x, q.y, q.z
            )
        };
        if let Some((a, b)) = self.edges().find(|&(a, b)| met(a, b) + met(b, a) != 2) {
            return Err(format!(
                "the mesh is not a closed surface: {} belongs to {} face(s) (each edge of a \
                 closed surface belongs to two)",
                edge(a, b),
                met(a, b) + met(b, a)
            ));
        }
        if let Some((a, b)) = self.edges().find(|&(a, b)| met(a, b) != 1) {
            return Err(format!(
                "the surface has no consistent orientation: {} is met twice the same way \
                 whichever faces are turned (a one-sided surface)",
                edge(a, b)
            ));
        }
        Ok(())
    }

    /// Every vertex lies on the inner side of every face's plane (to [`CONVEX_TOLERANCE`] of the
    /// block's size),
    /// the faces oriented outward by the mesh's sign of volume. Computed with the block moved
    /// near the origin ([`exact_reference`], exact): a face's plane taken at 4.5e6 m would carry
    /// its normal's round-off times that distance, about 1e-9 × 4.5e6 m, and a box turned to a
    /// bearing in survey coordinates was refused as not convex (measured).
    fn check_convex(&self) -> Result<(), String> {
        let lo = self
            .vertices
            .iter()
            .fold(Vector3::repeat(f64::INFINITY), |a, v| a.inf(v));
        let hi = self
            .vertices
            .iter()
            .fold(Vector3::repeat(f64::NEG_INFINITY), |a, v| a.sup(v));
        let size = (hi - lo).norm();
        let mean = self.vertices.iter().sum::<Vector3<f64>>() / self.vertices.len() as f64;
        let reference = exact_reference(&mean, size);
        let near: Vec<Vector3<f64>> = self.vertices.iter().map(|v| v - reference).collect();
        let area_vector = |f: &[usize]| {
            (0..f.len()).fold(Vector3::zeros(), |s: Vector3<f64>, i| {
                let (a, b) = (near[f[i]], near[f[(i + 1) % f.len()]]);
                s + a.cross(&b) * 0.5
            })
        };
        let volume: f64 = self
            .faces
            .iter()
            .map(|f| area_vector(f).dot(&near[f[0]]) / 3.0)
            .sum();
        if volume.abs() <= 1e-12 * size.powi(3) {
            return Err("the mesh encloses no volume".into());
        }
        let outward = volume.signum();
        for (k, f) in self.faces.iter().enumerate() {
            let Some(n) = (area_vector(f) * outward).try_normalize(0.0) else {
                continue;
            };
            let offset = n.dot(&near[f[0]]);
            if let Some(v) = self.vertices.iter().zip(&near).find_map(|(v, w)| {
                let out = n.dot(w) - offset;
                (out > CONVEX_TOLERANCE * size).then_some((v, out))
            }) {
                let (v, out) = v;
                return Err(format!(
                    "the block is not convex: the vertex ({:.6}, {:.6}, {:.6}) m lies {out:.1e} m \
                     outside the plane of face {} (more than {CONVEX_TOLERANCE:e} of the block's \
                     size, {size:.3} m; a polyhedron body is the convex hull of its vertices: cut \
                     the block into convex parts, or, if its coordinates were rounded, write them \
                     with more decimals)",
                    v.x,
                    v.y,
                    v.z,
                    k + 1
                ));
            }
        }
        Ok(())
    }
}
