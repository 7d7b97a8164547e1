//! A small writer of VTK XML files: one `UnstructuredGrid` (`.vtu`) per frame and the
//! `Collection` index (`.pvd`) ParaView opens as a time series.
//!
//! Format (`docs/animation.md`): ASCII data arrays, numbers written with Rust's `{:e}` (the
//! shortest text that reads back to the same f64, so the points are the engine's values
//! exactly). Points: every body's surface vertices in body order, then the ground's 4 corners.
//! Cells: one `VTK_POLYGON` (type 7) per face of every body, in body order, then one for the
//! ground. Cell data `body`: the body's index (0-based, in model order), −1 for the ground.
//! Field data `body_names`: the names in body order (a `String` array), `TimeValue`: the
//! frame's time (s).

use std::fmt::Write;

use nalgebra::Vector3;

use crr_kinematics::shapes::Surface;

use super::Ground;

/// VTK's cell type of a polygon.
pub const VTK_POLYGON: u8 = 7;

/// The `body` value of the ground's cell.
pub const GROUND_BODY: i32 = -1;

/// Escapes text for an XML attribute.
fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// The `.vtu` text of one frame: `names` and `surfaces` of the bodies, `vertices` their world
/// vertices (one vector per body, as [`super::pose_vertices`] gives), the ground, and the
/// frame's time `t` (s).
pub fn vtu(
    names: &[&str],
    surfaces: &[Surface],
    vertices: &[Vec<Vector3<f64>>],
    ground: &Ground,
    t: f64,
) -> String {
    let n_points: usize = vertices.iter().map(Vec::len).sum::<usize>() + 4;
    let n_cells: usize = surfaces.iter().map(Surface::face_count).sum::<usize>() + 1;
    let mut s = String::with_capacity(64 * n_points + 32 * n_cells + 1024);
    // Writing to a String cannot fail.
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\">"
    );
    let _ = writeln!(s, "  <UnstructuredGrid>");
    // Field data: the body names (VTK's ASCII String array: each string as its byte values,
    // ended by a 0) and the time.
    let _ = writeln!(s, "    <FieldData>");
    let _ = write!(
        s,
        "      <DataArray type=\"String\" Name=\"body_names\" NumberOfTuples=\"{}\" \
         format=\"ascii\">\n       ",
        names.len()
    );
    for name in names {
        for b in name.bytes() {
            let _ = write!(s, " {b}");
        }
        s.push_str(" 0");
    }
    let _ = writeln!(s, "\n      </DataArray>");
    let _ = writeln!(
        s,
        "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" \
         format=\"ascii\">{t:e}</DataArray>"
    );
    let _ = writeln!(s, "    </FieldData>");
    let _ = writeln!(
        s,
        "    <Piece NumberOfPoints=\"{n_points}\" NumberOfCells=\"{n_cells}\">"
    );
    let _ = writeln!(s, "      <Points>");
    let _ = writeln!(
        s,
        "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" \
         format=\"ascii\">"
    );
    for p in vertices.iter().flatten().chain(ground.corners.iter()) {
        let _ = writeln!(s, "          {:e} {:e} {:e}", p.x, p.y, p.z);
    }
    let _ = writeln!(s, "        </DataArray>");
    let _ = writeln!(s, "      </Points>");
    let _ = writeln!(s, "      <Cells>");
    let _ = writeln!(
        s,
        "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    );
    let mut base = 0usize;
    for (surface, verts) in surfaces.iter().zip(vertices) {
        for face in &surface.faces {
            s.push_str("         ");
            for &v in face {
                let _ = write!(s, " {}", base + v);
            }
            s.push('\n');
        }
        base += verts.len();
    }
    let _ = writeln!(
        s,
        "          {} {} {} {}",
        base,
        base + 1,
        base + 2,
        base + 3
    );
    let _ = writeln!(s, "        </DataArray>");
    let _ = writeln!(
        s,
        "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    );
    let mut offset = 0usize;
    s.push_str("         ");
    for face in surfaces.iter().flat_map(|x| &x.faces) {
        offset += face.len();
        let _ = write!(s, " {offset}");
    }
    let _ = writeln!(s, " {}", offset + 4);
    let _ = writeln!(s, "        </DataArray>");
    let _ = writeln!(
        s,
        "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    );
    s.push_str("         ");
    for _ in 0..n_cells {
        let _ = write!(s, " {VTK_POLYGON}");
    }
    s.push('\n');
    let _ = writeln!(s, "        </DataArray>");
    let _ = writeln!(s, "      </Cells>");
    let _ = writeln!(s, "      <CellData Scalars=\"body\">");
    let _ = writeln!(
        s,
        "        <DataArray type=\"Int32\" Name=\"body\" format=\"ascii\">"
    );
    s.push_str("         ");
    for (b, surface) in surfaces.iter().enumerate() {
        for _ in &surface.faces {
            let _ = write!(s, " {b}");
        }
    }
    let _ = writeln!(s, " {GROUND_BODY}");
    let _ = writeln!(s, "        </DataArray>");
    let _ = writeln!(s, "      </CellData>");
    let _ = writeln!(s, "    </Piece>");
    let _ = writeln!(s, "  </UnstructuredGrid>");
    let _ = writeln!(s, "</VTKFile>");
    s
}

/// The `.pvd` index: one `DataSet` per frame, `timestep` its time (s), `file` its name
/// (relative to the index).
pub fn pvd(frames: &[(f64, String)]) -> String {
    let mut s = String::with_capacity(80 * frames.len() + 200);
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">"
    );
    let _ = writeln!(s, "  <Collection>");
    for (t, file) in frames {
        let _ = writeln!(
            s,
            "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{}\"/>",
            xml_escape(file)
        );
    }
    let _ = writeln!(s, "  </Collection>");
    let _ = writeln!(s, "</VTKFile>");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_attribute_text() {
        assert_eq!(xml_escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&apos;");
    }

    #[test]
    fn pvd_lists_frames_in_order_with_exact_times() {
        let text = pvd(&[
            (0.0, "frame_00000.vtu".into()),
            (0.1, "frame_00001.vtu".into()),
        ]);
        let a = text.find("timestep=\"0e0\"").unwrap();
        let b = text.find("timestep=\"1e-1\" group=\"\" part=\"0\" file=\"frame_00001.vtu\"");
        assert!(b.is_some_and(|b| b > a), "{text}");
    }
}
