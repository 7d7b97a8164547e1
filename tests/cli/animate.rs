//! `crr animate RESULTS_DIR` and `crr simulate … --animate` (docs/animation.md): the frames'
//! vertices against kinematics computed here by another route, the VTK files read back by an
//! independent reader (vtkio), the .pvd index, the GIF decoded by the `gif` crate, the sizes of
//! the bundled models' GIFs, and the refusals of bad inputs.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

use crate::common::{bundled_text, crr, refused, scratch, write_model};
use crr::kinematics::{Model, Parent, Role, Side};
use crr::load_model;
use crr::output::animate::render::{HEIGHT, WIDTH};

fn ok(args: &[&str]) -> String {
    let o = crr(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Simulates the bundled `model` for `duration` seconds into a scratch folder.
fn simulate(model: &str, duration: &str, tag: &str) -> PathBuf {
    let dir = scratch(&format!("animate_{tag}"));
    let results = dir.join("results");
    let path = format!("examples/models/{model}.toml");
    let out = results.to_str().unwrap();
    ok(&[
        "simulate",
        &path,
        "--out",
        out,
        "--duration",
        duration,
        "--quiet",
    ]);
    results
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The rows of history.csv: time, q (by coordinate order) and the `_state` codes by interface,
/// with the offsets of the faces open at it from openings.csv (by interface).
struct Row {
    t: f64,
    q: Vec<f64>,
    states: Vec<String>,
    offsets: HashMap<usize, Vector3<f64>>,
}

fn history(dir: &Path, model: &Model) -> Vec<Row> {
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let qc: Vec<usize> = model.coords.iter().map(|c| col(&c.name)).collect();
    let sc: Vec<usize> = model
        .interfaces
        .iter()
        .map(|i| col(&format!("{}_state", i.name)))
        .collect();
    let mut rows: Vec<Row> = lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            Row {
                t: f[0].parse().unwrap(),
                q: qc.iter().map(|&c| f[c].parse().unwrap()).collect(),
                states: sc.iter().map(|&c| f[c].to_string()).collect(),
                offsets: HashMap::new(),
            }
        })
        .collect();
    // openings.csv: row (1 = history's first data row), t, interface, dx, dy, dz.
    let text = std::fs::read_to_string(dir.join("openings.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("row,t,interface,dx,dy,dz"));
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        let row = &mut rows[f[0].parse::<usize>().unwrap() - 1];
        assert_eq!(row.t, f[1].parse::<f64>().unwrap(), "{l}");
        let k = model.interface_index(f[2]).unwrap();
        assert_eq!(row.states[k].split('/').next(), Some("open"), "{l}");
        let d: Vec<f64> = f[3..6].iter().map(|v| v.parse().unwrap()).collect();
        row.offsets.insert(k, Vector3::new(d[0], d[1], d[2]));
    }
    rows
}

/// Body poses (R, t: x = R X + t for a rest point X) computed from q and the pivots by
/// composing nalgebra's axis-angle rotations along the tree, each body placed so that its
/// active pivot stays where its parent holds it: R_b = R_p Π Rot(uⱼ, qⱼ),
/// t_b = R_p P + t_p − R_b P. Independent of crr's Γ/frame code (its own Rodrigues formula,
/// frames and translations). A face that is open (`open`) turns about its positive pivot P⁺ and
/// its child is moved by the face's offset x_c(P⁺) − x_p(P⁺) from openings.csv, which the bodies
/// below it inherit through their parents' poses.
fn poses(model: &Model, row: &Row) -> Vec<(Matrix3<f64>, Vector3<f64>)> {
    let mut pose = vec![(Matrix3::identity(), Vector3::zeros()); model.bodies.len()];
    let mut tree: Vec<(usize, usize)> = model
        .interfaces
        .iter()
        .enumerate()
        .filter_map(|(i, f)| match f.role {
            Role::Tree { first_coord } => Some((first_coord, i)),
            Role::Closure { .. } => None,
        })
        .collect();
    tree.sort();
    for (first, i) in tree {
        let f = &model.interfaces[i];
        let (rp, tp) = match f.parent {
            Parent::Ground => (Matrix3::identity(), Vector3::zeros()),
            Parent::Body(p) => pose[p],
        };
        let codes: Vec<&str> = row.states[i].split('/').collect();
        let sides: Vec<Side> = codes
            .iter()
            .enumerate()
            .map(|(k, c)| match *c {
                "+" | "open" => Side::Positive,
                "-" => Side::Negative,
                _ => {
                    assert_eq!(row.q[first + k], 0.0, "a seated angle is 0");
                    Side::Positive
                }
            })
            .collect();
        let pivot = f.kind.pivot(&sides);
        let mut r = rp;
        for k in 0..f.kind.angle_count() {
            let axis = Unit::new_normalize(f.kind.axis(k));
            r *= Rotation3::from_axis_angle(&axis, row.q[first + k]).into_inner();
        }
        let offset = row.offsets.get(&i).copied().unwrap_or_else(Vector3::zeros);
        let t = rp * pivot + tp - r * pivot + offset;
        pose[f.child] = (r, t);
    }
    pose
}

/// A .vtu read by vtkio: points, connectivity, offsets, cell types and the `body` array.
struct Vtu {
    points: Vec<Vector3<f64>>,
    connectivity: Vec<u64>,
    offsets: Vec<u64>,
    types: Vec<vtkio::model::CellType>,
    body: Vec<i32>,
}

fn read_vtu(path: &Path) -> Vtu {
    use vtkio::model::{Attribute, DataSet, Piece, VertexNumbers};
    let vtk = vtkio::Vtk::import(path).unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("{}: not an UnstructuredGrid", path.display())
    };
    assert_eq!(pieces.len(), 1);
    let Piece::Inline(piece) = &pieces[0] else {
        panic!("inline piece expected")
    };
    let coords: Vec<f64> = piece.points.clone().cast_into().unwrap();
    let points = coords
        .chunks_exact(3)
        .map(|c| Vector3::new(c[0], c[1], c[2]))
        .collect();
    let VertexNumbers::XML {
        connectivity,
        offsets,
    } = piece.cells.cell_verts.clone()
    else {
        panic!("XML cells expected")
    };
    let body = piece
        .data
        .cell
        .iter()
        .find_map(|a| match a {
            Attribute::DataArray(d) if d.name == "body" => {
                Some(d.data.clone().cast_into::<i32>().unwrap())
            }
            _ => None,
        })
        .expect("a `body` cell array");
    Vtu {
        points,
        connectivity,
        offsets,
        types: piece.cells.types.clone(),
        body,
    }
}

/// The `TimeValue` field of a .vtu (written by crr with `{:e}`, read back exactly).
fn time_value(path: &Path) -> f64 {
    let text = std::fs::read_to_string(path).unwrap();
    let i = text.find("Name=\"TimeValue\"").unwrap();
    let rest = &text[i..];
    let from = rest.find('>').unwrap() + 1;
    let to = rest.find("</DataArray>").unwrap();
    rest[from..to].trim().parse().unwrap()
}

/// The `body_names` field of a .vtu: VTK's ASCII `String` array, each name as its bytes and a 0
/// (vtkio skips field data, so it is read here from the text).
fn body_names(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let i = text.find("Name=\"body_names\"").unwrap();
    let rest = &text[i..];
    let from = rest.find('>').unwrap() + 1;
    let to = rest.find("</DataArray>").unwrap();
    let bytes: Vec<u8> = rest[from..to]
        .split_whitespace()
        .map(|b| b.parse().unwrap())
        .collect();
    assert_eq!(bytes.last(), Some(&0), "every name ends with a 0");
    bytes[..bytes.len() - 1]
        .split(|&b| b == 0)
        .map(|n| String::from_utf8(n.to_vec()).unwrap())
        .collect()
}

/// The (timestep, file) pairs of a .pvd, in order.
fn pvd_entries(path: &Path) -> Vec<(f64, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    let attr = |tag: &str, name: &str| -> String {
        let key = format!("{name}=\"");
        let i = tag.find(&key).unwrap() + key.len();
        tag[i..i + tag[i..].find('"').unwrap()].to_string()
    };
    text.split("<DataSet ")
        .skip(1)
        .map(|tag| (attr(tag, "timestep").parse().unwrap(), attr(tag, "file")))
        .collect()
}

/// Every frame of the series: read by vtkio, consistent (connectivity inside the points,
/// offsets increasing to the connectivity's length, polygons only), one cell per face of every
/// body plus the ground, and its body vertices equal to the poses computed by [`poses`] at the
/// history row of its time, to 1e-12 × the model size: both routes round a few tens of
/// products of numbers up to the model size (ε = 2.2e-16), and the file keeps every digit.
fn check_series(results: &Path, model_name: &str, every: usize) {
    check_series_of(
        results,
        &format!("examples/models/{model_name}.toml"),
        model_name,
        every,
    );
}

/// [`check_series`] of a model file given by its path.
fn check_series_of(results: &Path, model_path: &str, model_name: &str, every: usize) {
    let (_, model) = load_model(Path::new(model_path)).unwrap();
    let surfaces: Vec<_> = model
        .bodies
        .iter()
        .map(|b| b.shape.surface().unwrap())
        .collect();
    let faces: usize = surfaces.iter().map(|s| s.faces.len()).sum();
    let vertices: usize = surfaces.iter().map(|s| s.vertices.len()).sum();
    let rows = history(results, &model);
    let anim = results.join("animation");
    let entries = pvd_entries(&anim.join("animation.pvd"));
    // The rows merged at impacts (same t), then every K-th.
    let mut distinct: Vec<f64> = rows.iter().map(|r| r.t).collect();
    distinct.dedup();
    assert_eq!(
        entries.len(),
        distinct.len().div_ceil(every),
        "{model_name}"
    );
    let mut frame_files: Vec<String> = std::fs::read_dir(&anim)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".vtu"))
        .collect();
    frame_files.sort();
    assert_eq!(frame_files.len(), entries.len());
    let tol = 1e-12 * model.size.max(1.0);
    for (j, (t, file)) in entries.iter().enumerate() {
        assert_eq!(file, &format!("frame_{j:05}.vtu"));
        assert_eq!(*t, distinct[j * every], "{model_name}: frame {j}'s time");
        let path = anim.join(file);
        assert_eq!(time_value(&path), *t);
        // Body k of the `body` cell array is named body_names[k], the model's k-th body.
        let names: Vec<String> = model.bodies.iter().map(|b| b.name.clone()).collect();
        assert_eq!(body_names(&path), names);
        let vtu = read_vtu(&path);
        assert_eq!(vtu.points.len(), vertices + 4);
        assert_eq!(vtu.types.len(), faces + 1);
        assert_eq!(vtu.offsets.len(), faces + 1);
        assert!(
            vtu.types
                .iter()
                .all(|c| *c == vtkio::model::CellType::Polygon)
        );
        assert_eq!(
            *vtu.offsets.last().unwrap() as usize,
            vtu.connectivity.len()
        );
        assert!(vtu.offsets.windows(2).all(|w| w[1] >= w[0] + 3));
        assert!(
            vtu.connectivity
                .iter()
                .all(|&i| (i as usize) < vtu.points.len())
        );
        // Cells by body, the ground last.
        let mut expected_body = Vec::new();
        for (b, s) in surfaces.iter().enumerate() {
            expected_body.extend(std::iter::repeat_n(b as i32, s.faces.len()));
        }
        expected_body.push(-1);
        assert_eq!(vtu.body, expected_body);
        // The state of this time: the last row with it (after an impact).
        let row = rows.iter().rev().find(|r| r.t == *t).unwrap();
        let pose = poses(&model, row);
        let mut base = 0;
        for (b, surface) in surfaces.iter().enumerate() {
            let (r, tr) = pose[b];
            for (i, x) in surface.vertices.iter().enumerate() {
                let expected = r * x + tr;
                let got = vtu.points[base + i];
                assert!(
                    (got - expected).norm() <= tol,
                    "{model_name} t = {t}: body {b} vertex {i}: {got} vs {expected}"
                );
            }
            base += surface.vertices.len();
        }
    }
}

/// The GIF decodes (gif crate) into `frames` frames of WIDTH × HEIGHT; returns the sum of the
/// frame delays (centiseconds).
fn check_gif(path: &Path, frames: usize) -> u64 {
    let file = std::fs::File::open(path).unwrap();
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut decoder = options.read_info(file).unwrap();
    assert_eq!(
        (decoder.width() as u32, decoder.height() as u32),
        (WIDTH, HEIGHT)
    );
    let mut count = 0;
    let mut total = 0u64;
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert!(frame.left as u32 + frame.width as u32 <= WIDTH);
        assert!(frame.top as u32 + frame.height as u32 <= HEIGHT);
        total += frame.delay as u64;
        count += 1;
    }
    assert_eq!(count, frames, "{}", path.display());
    total
}

#[test]
fn single_block_series_matches_the_kinematics_and_the_gif_decodes() {
    let results = simulate("single_block", "2", "single");
    let out = ok(&["animate", s(&results), "--every", "5", "--view", "y"]);
    assert!(out.contains("frame(s)"), "{out}");
    check_series(&results, "single_block", 5);
    let entries = pvd_entries(&results.join("animation/animation.pvd"));
    let total = check_gif(&results.join("animation/animation.gif"), entries.len());
    // Real time: the frames span the run (2 s = 200 cs), each delay rounded so that the
    // rounding does not accumulate (≤ 0.5 cs off in all), plus the last frame's 100 cs hold.
    let span = entries.last().unwrap().0 - entries[0].0;
    assert!(
        (total as f64 - (100.0 * span + 100.0)).abs() <= 0.5,
        "{total} cs for {span} s"
    );
}

#[test]
fn chains_loops_rocking_bases_and_sectors_match_the_kinematics() {
    // An open chain, a loop (trilithon), rocking bases in loops (baldachin), voussoirs.
    for (model, every) in [
        ("two_block_stack", 7),
        ("trilithon", 4),
        ("baldachin", 9),
        ("arch", 6),
    ] {
        let results = simulate(model, "1.5", model);
        ok(&[
            "animate",
            s(&results),
            "--every",
            &every.to_string(),
            "--format",
            "vtk",
        ]);
        check_series(&results, model, every);
        assert!(!results.join("animation/animation.gif").exists());
    }
}

/// The bundled wall under a one-sine pulse of −10 m/s² (1.6 λ g, along −x first): faces of its
/// spanning tree lift off, so history.csv gives their angles as the bodies' relative rotation
/// only, and the frames must move the bodies below them by the offsets of openings.csv to draw
/// them where they are (checked against the poses composed here, [`poses`]). The offsets
/// matter: a face of the tree is open with an offset above 1e-3 of the model size in a frame
/// (0.039 m of `c3_b2_on_c2_b1`). Along +x the wedge lifts off faces that close loops instead.
#[test]
fn bodies_below_an_open_face_are_drawn_where_they_are() {
    let text = bundled_text("wall")
        + "\n[ground_motion]\nx = { one_sine_pulse = { amplitude = -10.0, period = 0.5 } }\n";
    let model_path = write_model("animate_wall_pulse", &text);
    let results = scratch("animate_wall_pulse").join("r");
    let model = model_path.to_str().unwrap();
    ok(&[
        "simulate",
        model,
        "--out",
        s(&results),
        "--duration",
        "1.0",
        "--quiet",
    ]);
    ok(&["animate", s(&results), "--every", "1", "--format", "vtk"]);
    check_series_of(&results, model, "wall_pulse", 1);
    let (_, structure) = load_model(Path::new(model)).unwrap();
    let largest = history(&results, &structure)
        .iter()
        .flat_map(|r| r.offsets.iter())
        .filter(|(k, _)| matches!(structure.interfaces[**k].role, Role::Tree { .. }))
        .map(|(_, d)| d.norm())
        .fold(0.0, f64::max);
    assert!(
        largest > 1e-3 * structure.size,
        "largest offset of an open tree face {largest} m"
    );
    // The same history with an openings.csv that lists none of its open faces (of another run)
    // is refused at the first row with a face open, naming that face, not drawn without offsets.
    let (row, open) = history(&results, &structure)
        .iter()
        .enumerate()
        .find_map(|(i, r)| {
            // In model order, from history.csv's own `_state` codes.
            let open: Vec<&str> = (r.states.iter().enumerate())
                .filter(|(_, code)| code.split('/').any(|c| c == "open"))
                .map(|(k, _)| structure.interfaces[k].name.as_str())
                .collect();
            (!open.is_empty()).then_some((i + 1, open))
        })
        .expect("a face opens");
    std::fs::write(results.join("openings.csv"), "row,t,interface,dx,dy,dz\n").unwrap();
    let open: Vec<String> = open.iter().map(|name| format!("`{name}`")).collect();
    refused(
        &["animate", s(&results), "--force"],
        &format!(
            "history.csv: line {}: the faces open there ({}) are not those",
            row + 1,
            open.join(", ")
        ),
    );
}

#[test]
fn prisms_and_polyhedra_match_the_kinematics() {
    // A pentagonal prism rocking under a frustum given as a point cloud (with an interior
    // point): the shapes no bundled model uses.
    let dir = scratch("animate_prism_polyhedron");
    let results = dir.join("r");
    let model = "tests/data/prism_polyhedron.toml";
    ok(&["simulate", model, "--out", s(&results), "--quiet"]);
    ok(&["animate", s(&results), "--every", "3", "--format", "vtk"]);
    check_series_of(&results, model, "prism_polyhedron", 3);
}

#[test]
fn every_view_draws_a_gif_and_simulate_animate_writes_both() {
    let results = simulate("trilithon", "1", "views");
    for view in ["x", "y", "z", "iso"] {
        let out = results.join(format!("view_{view}"));
        ok(&[
            "animate",
            s(&results),
            "--view",
            view,
            "--format",
            "gif",
            "--out",
            s(&out),
        ]);
        // Default step: 0.05 s between frames at the 0.01 s output interval → K = 5.
        let mut distinct: Vec<f64> = std::fs::read_to_string(results.join("history.csv"))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap().parse().unwrap())
            .collect();
        distinct.dedup();
        check_gif(&out.join("animation.gif"), distinct.len().div_ceil(5));
        assert!(!out.join("animation.pvd").exists());
    }
    // crr simulate --animate: the results and, in DIR/animation, the series and the GIF.
    let dir = scratch("animate_simulate_flag").join("r");
    ok(&[
        "simulate",
        "examples/models/single_block.toml",
        "--out",
        s(&dir),
        "--duration",
        "1",
        "--quiet",
        "--animate",
    ]);
    let entries = pvd_entries(&dir.join("animation/animation.pvd"));
    // 101 samples 0.01 s apart, K = 5: frames at 0, 0.05, …, 1.0.
    assert_eq!(entries.len(), 21);
    check_gif(&dir.join("animation/animation.gif"), 21);
    // A second run into the folder is refused without --force (the animation is named), and
    // with --force replaces results and animation together.
    let o = crr(&[
        "simulate",
        "examples/models/single_block.toml",
        "--out",
        s(&dir),
        "--duration",
        "0.5",
        "--quiet",
    ]);
    assert_eq!(o.status.code(), Some(2));
    ok(&[
        "simulate",
        "examples/models/single_block.toml",
        "--out",
        s(&dir),
        "--duration",
        "0.5",
        "--quiet",
        "--force",
    ]);
    // The earlier animation went with the earlier results.
    assert!(!dir.join("animation").exists());
}

#[test]
fn bad_inputs_are_refused_naming_the_item() {
    let results = simulate("single_block", "0.3", "bad");
    let r = s(&results);
    let missing = results.join("nowhere");
    refused(&["animate", s(&missing)], "no such results folder");
    refused(
        &["animate", r, "--every", "0"],
        "--every must be at least 1",
    );
    refused(
        &["animate", r, "--view", "top"],
        "--view: unknown view `top`",
    );
    refused(
        &["animate", r, "--format", "mp4"],
        "--format: unknown format `mp4`",
    );
    refused(
        &["animate", r, "--speed", "0"],
        "--speed must be a positive number",
    );
    // A folder without history.csv, and a run still being written.
    let empty = scratch("animate_bad_empty");
    refused(&["animate", s(&empty)], "history.csv: is missing");
    let half = scratch("animate_bad_half");
    std::fs::copy(results.join("summary.json"), half.join("summary.json")).unwrap();
    std::fs::write(half.join(".partial.history.csv"), "t,base\n0e0,").unwrap();
    refused(&["animate", s(&half)], "the run is still being written");
    // A truncated last line.
    let text = std::fs::read_to_string(results.join("history.csv")).unwrap();
    std::fs::write(half.join("history.csv"), &text[..text.len() - 10]).unwrap();
    refused(&["animate", s(&half)], "half-written");
    // A summary without the model.
    let old = scratch("animate_bad_old");
    std::fs::copy(results.join("history.csv"), old.join("history.csv")).unwrap();
    std::fs::write(old.join("summary.json"), "{\"coordinates\": []}").unwrap();
    refused(&["animate", s(&old)], "holds no `model`");
    // A damaged openings.csv: each refusal names the file and the line.
    let damaged = scratch("animate_bad_openings");
    for name in ["history.csv", "summary.json"] {
        std::fs::copy(results.join(name), damaged.join(name)).unwrap();
    }
    for (rows, needle) in [
        ("row,t,dx\n", "openings.csv: line 1: the header is not"),
        (
            "1,0e0,base,0e0,0e0\n",
            "openings.csv: line 2: 5 fields, 6 expected",
        ),
        (
            "0,0e0,base,0e0,0e0,0e0\n",
            "openings.csv: line 2: `row` is `0`",
        ),
        (
            "1,0e0,nowhere,0e0,0e0,0e0\n",
            "line 2: no interface `nowhere`",
        ),
        (
            "1,x,base,0e0,0e0,0e0\n",
            "line 2: `x` is not a finite number",
        ),
        (
            "1,0e0,base,0e0,NaN,0e0\n",
            "line 2: `NaN` is not a finite number",
        ),
        (
            "1,0e0,base,0e0,0e0,0e0\n1,0e0,base,1e0,0e0,0e0\n",
            "line 3: `base` listed twice at row 1",
        ),
        (
            "100000,0e0,base,0e0,0e0,0e0\n",
            "openings.csv: row 100000 is beyond the",
        ),
        // A face listed open at a row whose `base_state` is a pivot side: the files are not of
        // one run.
        (
            "1,0e0,base,0e0,0e0,0e0\n",
            "history.csv: line 2: the faces open there (none) are not those",
        ),
    ] {
        let text = if rows.starts_with("row,") {
            rows.to_string()
        } else {
            format!("row,t,interface,dx,dy,dz\n{rows}")
        };
        std::fs::write(damaged.join("openings.csv"), text).unwrap();
        refused(&["animate", s(&damaged)], needle);
    }
    // An earlier animation is kept without --force, replaced with it.
    ok(&["animate", r, "--format", "vtk"]);
    let before = std::fs::read_dir(results.join("animation"))
        .unwrap()
        .count();
    refused(
        &["animate", r],
        "holds an earlier animation (animation.pvd, frame_00000.vtu",
    );
    assert_eq!(
        std::fs::read_dir(results.join("animation"))
            .unwrap()
            .count(),
        before
    );
    ok(&["animate", r, "--format", "gif", "--force"]);
    let names: Vec<String> = std::fs::read_dir(results.join("animation"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    // Only the new GIF: no frame of the earlier series, no temporary folder left.
    assert_eq!(names, vec!["animation.gif".to_string()]);
}

/// The GIF of every bundled model, with the default options, stays under 5 MB; the counts are
/// the default step's (0.05 s between frames, at most 400 frames).
#[test]
fn bundled_models_gifs_are_under_5_mb() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models");
    let mut sizes: HashMap<String, (u64, usize)> = HashMap::new();
    let mut names: Vec<String> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    names.sort();
    for name in names {
        let model = name.trim_end_matches(".toml");
        let dir = scratch(&format!("animate_bundled_{model}"));
        let results = dir.join("r");
        // The run may end with an error (exit 1): its partial results are animated too.
        let _ = crr(&[
            "simulate",
            &format!("examples/models/{name}"),
            "--out",
            s(&results),
            "--quiet",
        ]);
        ok(&["animate", s(&results), "--format", "gif"]);
        let gif = results.join("animation/animation.gif");
        let bytes = std::fs::metadata(&gif).unwrap().len();
        let frames = {
            let mut d = gif::DecodeOptions::new()
                .read_info(std::fs::File::open(&gif).unwrap())
                .unwrap();
            let mut n = 0;
            while d.next_frame_info().unwrap().is_some() {
                n += 1;
            }
            n
        };
        assert!(frames <= 400, "{model}: {frames} frames");
        assert!(bytes < 5_000_000, "{model}: {bytes} bytes");
        sizes.insert(model.to_string(), (bytes, frames));
    }
    let mut list: Vec<_> = sizes.into_iter().collect();
    list.sort();
    for (m, (b, f)) in list {
        eprintln!("{m}: {f} frames, {:.1} kB", b as f64 / 1000.0);
    }
}

/// An animation of a run that leaves crr's model says so on every frame after the run's first
/// hypotheses violation (its time read from summary.json), and on none before: the bundled drum
/// column, whose bed under the seventh drum would have to pull at 0.5028 s.
#[test]
fn frames_after_a_violation_say_they_are_outside_the_model() {
    use crr::output::animate::{gif::caption, read_run};
    let results = simulate("drum_column", "1.0", "outside_model");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(results.join("summary.json")).unwrap())
            .unwrap();
    let t_v = summary["hypothesis_violation"]["time"].as_f64().unwrap();
    assert!((t_v - 0.5028).abs() < 1e-4, "{t_v}");
    let run = read_run(&results).unwrap();
    assert_eq!(run.violation_time, Some(t_v));
    let (mut before, mut after) = (0, 0);
    for state in run.states().unwrap() {
        let state = state.unwrap();
        let text = caption(&state, run.violation_time);
        assert_eq!(
            text.contains("outside crr's model"),
            state.t > t_v,
            "{text}"
        );
        if state.t > t_v {
            after += 1;
        } else {
            before += 1;
        }
    }
    assert!(before > 10 && after > 10, "{before} before, {after} after");
    // The GIF is written with those captions: the same folder with the violation removed from
    // its summary.json animates to other pixels (only the captions after 0.5028 s differ).
    ok(&["animate", s(&results), "--out", s(&results.join("anim"))]);
    let clean = results.with_file_name("clean");
    std::fs::create_dir_all(&clean).unwrap();
    for name in ["history.csv", "impacts.csv", "openings.csv"] {
        if results.join(name).is_file() {
            std::fs::copy(results.join(name), clean.join(name)).unwrap();
        }
    }
    let mut kept = summary.clone();
    kept["hypothesis_violation"] = serde_json::Value::Null;
    std::fs::write(clean.join("summary.json"), kept.to_string()).unwrap();
    ok(&["animate", s(&clean), "--out", s(&clean.join("anim"))]);
    let frames = |dir: &Path| -> Vec<Vec<u8>> {
        let file = std::fs::File::open(dir.join("anim").join("animation.gif")).unwrap();
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::RGBA);
        let mut decoder = options.read_info(file).unwrap();
        let mut out = Vec::new();
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            out.push(frame.buffer.to_vec());
        }
        out
    };
    let (with, without) = (frames(&results), frames(&clean));
    assert_eq!(with.len(), without.len());
    let differing = with.iter().zip(&without).filter(|(a, b)| a != b).count();
    assert!(
        differing > 0,
        "the captions after the violation reach the GIF"
    );
}
