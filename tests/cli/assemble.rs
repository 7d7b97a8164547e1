//! `crr assemble`: an assembly of blocks (bodies only) in, the model whose rocking interfaces are
//! its bed contacts out. Checked against what is known without the code under test: the bundled
//! running-bond wall was written by hand from the same bodies (the generated model must have the
//! same bed joints and pivots, and its multiplier is 7/11 by the virtual work of the corner
//! wedge); a panel cut into courses rocks whole on its base edge, λ = b/h.

use std::collections::BTreeSet;

use nalgebra::Vector3;

use crr::analysis::assemble::{AssemblyOptions, assemble, read_assembly};
use crr::impact::statics::{StaticsOptions, collapse_multiplier};
use crr::kinematics::spec::PivotSpec;

use crate::common;
use crate::common::box_body;

/// The bodies of a model file (its text up to the first interface) written as an assembly.
fn assembly_of(model: &str, tag: &str) -> std::path::PathBuf {
    let text = common::bundled_text(model);
    let head = &text[..text.find("[[interface]]").unwrap()];
    common::write_model(tag, head)
}

fn lambda(model: &crr::kinematics::Model, d: Vector3<f64>) -> f64 {
    collapse_multiplier(model, d, &StaticsOptions::default())
        .unwrap()
        .lambda
        .unwrap()
}

/// A bed joint as (parent, child, axis, the x and z of its two pivot lines along y): a point
/// pivot (the hand-written wall) and a segment along y (the assembled one) are the same line.
fn joints(spec_interfaces: &[crr::kinematics::spec::InterfaceSpec]) -> BTreeSet<String> {
    let seg = |p: &Option<PivotSpec>| {
        let (a, b) = match p.as_ref().expect("a pivot") {
            PivotSpec::Point(a) => (*a, *a),
            PivotSpec::Segment([a, b]) => (*a, *b),
        };
        assert!(
            (a[0] - b[0]).abs() < 1e-12 && (a[2] - b[2]).abs() < 1e-12,
            "along y"
        );
        format!("x {:.9} z {:.9}", a[0], a[2])
    };
    spec_interfaces
        .iter()
        .map(|i| {
            format!(
                "{} -> {}: {:?} + {} - {}",
                i.parent,
                i.child,
                i.axis,
                seg(&i.pivot_positive),
                seg(&i.pivot_negative)
            )
        })
        .collect()
}

#[test]
fn the_wall_assembled_from_its_blocks_is_the_hand_written_wall() {
    let path = assembly_of("wall", "wall_assembly");
    let file = read_assembly(&path).unwrap();
    let planar = assemble(&path, &file, &AssemblyOptions::default().in_plane()).unwrap();
    let (hand, _) = crr::load_model(&common::bundled_path("wall")).unwrap();
    assert_eq!(joints(&planar.file.interface), joints(&hand.interface));
    // 4 courses of 3 blocks (half blocks at the ends of the odd ones): 3 on the ground, and the
    // other 9 + 9 (one or two supports each) bed joints; 10 head joints touch but are no interface.
    let beds = planar.contacts.iter().filter(|c| c.bed).count();
    let sides = planar.contacts.len() - beds;
    assert_eq!((beds, sides), (21, 10));
    let bed_area: f64 = planar
        .contacts
        .iter()
        .filter(|c| c.bed)
        .map(|c| c.area)
        .sum();
    // Every block's base is in contact with what lies below: 12 + 1 (half blocks) blocks of
    // 0.5 m depth on 3 m of length per course, 4 courses.
    assert!((bed_area - 4.0 * 3.0 * 0.5).abs() < 1e-12, "{bed_area}");
    let seven_elevenths = 7.0 / 11.0;
    for m in [
        &planar.model,
        &assemble(&path, &file, &AssemblyOptions::default())
            .unwrap()
            .model,
    ] {
        for d in [Vector3::x(), -Vector3::x()] {
            let l = lambda(m, d);
            assert!((l - seven_elevenths).abs() < 1e-9, "{l}");
        }
    }
}

#[test]
fn a_panel_cut_into_courses_rocks_whole_on_its_base_edge() {
    // 5 courses of 0.4 × 0.3 × 0.5 m, 2.5 m in all: the whole panel rocks on a base edge when
    // λ = b/h, b the half-width and h = 1.25 m the centre's height: 0.2/1.25 = 0.16 along ±x and
    // 0.15/1.25 = 0.12 along ±y for rocking bases; 0.16 for the planar hinges.
    let mut text = String::from("name = \"panel\"\n");
    for k in 0..5 {
        text += &format!(
            "[[body]]\nname = \"course_{k}\"\ndensity = 2000.0\nbox = {{ center = [0.0, 0.0, {}], size = [0.4, 0.3, 0.5] }}\n",
            0.25 + 0.5 * k as f64
        );
    }
    let path = common::write_model("panel_assembly", &text);
    let file = read_assembly(&path).unwrap();
    let bases = assemble(&path, &file, &AssemblyOptions::default()).unwrap();
    assert_eq!(bases.model.dof(), 10);
    assert!(bases.model.closures.is_empty());
    for (d, expected) in [
        (Vector3::x(), 0.16),
        (-Vector3::x(), 0.16),
        (Vector3::y(), 0.12),
        (-Vector3::y(), 0.12),
    ] {
        let l = lambda(&bases.model, d);
        assert!((l - expected).abs() < 1e-9, "{d:?}: {l}");
    }
    let hinges = assemble(&path, &file, &AssemblyOptions::default().in_plane()).unwrap();
    assert!((lambda(&hinges.model, Vector3::x()) - 0.16).abs() < 1e-9);
    // The model file written loads back into the same model.
    let out = common::scratch("panel_model").join("panel.toml");
    let o = common::crr(&[
        "assemble",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--force",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (_, back) = crr::load_model(&out).unwrap();
    assert_eq!(back.dof(), 10);
    assert!((lambda(&back, Vector3::y()) - 0.12).abs() < 1e-9);
}

#[test]
fn a_floating_block_a_non_convex_footprint_and_an_assembly_with_interfaces_are_refused_naming_them()
{
    let text = "name = \"gap\"\n[[body]]\nname = \"low\"\ndensity = 2000.0\nbox = { center = [0.0, 0.0, 0.5], size = [1.0, 1.0, 1.0] }\n[[body]]\nname = \"high\"\ndensity = 2000.0\nbox = { center = [0.0, 0.0, 1.51], size = [1.0, 1.0, 1.0] }\n";
    let path = common::write_model("gap_assembly", text);
    let o = common::crr(&["assemble", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("body \"high\": rests on nothing"), "{err}");
    // An L-shaped block standing on the ground: its footprint is not convex (clipping it would
    // keep a unit square of its 3 m²), refused by name.
    let text = "name = \"l\"\n[[body]]\nname = \"ell\"\ndensity = 2000.0\nprism = { polygon = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [1.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 2.0, 0.0]], extrude = [0.0, 0.0, 1.0] }\n";
    let path = common::write_model("ell_assembly", text);
    let o = common::crr(&["assemble", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(
            "body \"ell\": touches another body (or the ground) with a face that is not convex"
        ),
        "{err}"
    );
    let model = common::bundled_path("trilithon");
    let o = common::crr(&["assemble", model.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("an assembly lists bodies only"), "{err}");
}

/// Blocks that interpenetrate, or reach below the ground, are errors of the geometry, refused
/// naming them, with the depth. Two boxes standing 5 cm into each other: the separating-axis
/// depth is 0.05 m. Two voussoirs of an arch (annular sectors, whose intrados is concave) cut at
/// 1.0 rad and at π/3 rad overlap by the wedge between: the centroid of one's radial face lies
/// inside the other at the distance r_mid·sin(π/3 − 1) from its joint plane. A block whose base
/// is at z = −0.05 m reaches below the ground.
#[test]
fn overlapping_blocks_and_a_block_below_the_ground_are_refused_naming_them() {
    let refusal = |tag: &str, text: &str| {
        let path = common::write_model(tag, text);
        let o = common::crr(&["assemble", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(2), "{err}");
        err
    };
    let depth = |err: &str| -> f64 {
        let from = err.find("interpenetrate by ").expect(err) + "interpenetrate by ".len();
        err[from..].split(' ').next().unwrap().parse().unwrap()
    };
    let boxes = "name = \"pair\"\n[[body]]\nname = \"a\"\ndensity = 2000.0\nbox = { center = [0.0, 0.0, 0.5], size = [1.0, 1.0, 1.0] }\n[[body]]\nname = \"b\"\ndensity = 2000.0\nbox = { center = [0.95, 0.0, 0.5], size = [1.0, 1.0, 1.0] }\n";
    let err = refusal("overlapping_boxes", boxes);
    assert!(err.contains("bodies \"a\" and \"b\": overlap"), "{err}");
    assert!((depth(&err) - 0.05).abs() < 1e-6, "{err}");
    let sector = |name: &str, from: f64, to: f64| {
        format!(
            "[[body]]\nname = \"{name}\"\ndensity = 2200.0\nannular_sector = {{ center = [0.0, 0.0, 0.0], axis = [0.0, -1.0, 0.0], start = [1.0, 0.0, 0.0], inner_radius = 2.0, outer_radius = 2.5, thickness = 1.0, from_angle = {from}, to_angle = {to} }}\n"
        )
    };
    let third = std::f64::consts::FRAC_PI_3;
    let arch = format!(
        "name = \"arch\"\n{}{}",
        sector("v1", 0.0, third),
        sector("v2", 1.0, 2.0 * third)
    );
    let err = refusal("overlapping_voussoirs", &arch);
    assert!(err.contains("bodies \"v1\" and \"v2\": overlap"), "{err}");
    let expected = 2.25 * (third - 1.0).sin();
    assert!(
        (depth(&err) - expected).abs() < 1e-6,
        "{err} against {expected}"
    );
    let sunk = "name = \"sunk\"\n[[body]]\nname = \"a\"\ndensity = 2000.0\nbox = { center = [0.0, 0.0, 0.45], size = [1.0, 1.0, 1.0] }\n";
    let err = refusal("sunk_block", sunk);
    assert!(
        err.contains("body \"a\": reaches 0.050000 m below the ground"),
        "{err}"
    );
}

/// `text` with the value of every `center = [x, y, z]` replaced: `write(centre, rest)` gives the
/// new text from the coordinates on, `rest` being what followed the closing bracket (numbers in
/// Rust's shortest round-trip formatting hold the new centres to their last bit).
fn rewrite_centres(text: &str, write: impl Fn([f64; 3], &str) -> String) -> String {
    let key = "center = [";
    text.lines()
        .map(|line| match line.find(key) {
            Some(i) => {
                let from = i + key.len();
                let to = from + line[from..].find(']').expect("a closing bracket");
                let c: Vec<f64> = line[from..to]
                    .split(',')
                    .map(|x| x.trim().parse().expect("a number"))
                    .collect();
                format!(
                    "{}{}\n",
                    &line[..from],
                    write([c[0], c[1], c[2]], &line[to..])
                )
            }
            None => format!("{line}\n"),
        })
        .collect()
}

/// The text of an assembly of boxes with every box centre moved by `d`.
fn boxes_moved(text: &str, d: [f64; 3]) -> String {
    rewrite_centres(text, |c, rest| {
        format!(
            "{:?}, {:?}, {:?}{rest}",
            c[0] + d[0],
            c[1] + d[1],
            c[2] + d[2]
        )
    })
}

/// A site elevation is the ground's level. The bundled wall's blocks written in a survey's
/// coordinates (5e5 m east, 4.5e6 m north, 350 m up):
/// - on the default ground (z = 0) nothing rests: refused, naming the first block and where the
///   lowest stands, with the option that fixes it;
/// - with `--ground-level 350` the command line writes the model, and the library gives the
///   same bed joints as at the origin (parents, children, pivot lines moved by the offset, to
///   1e-9 m: the survey coordinates hold the points to ulp(4.5e6) ≈ 1e-9 m) and the wall's
///   multiplier 7/11 of the corner wedge's virtual work along ±x, to 1e-9;
/// - a block sunk 0.05 m below the level is refused with that depth.
#[test]
fn a_wall_in_survey_coordinates_stands_on_the_ground_level_given() {
    const SURVEY: [f64; 3] = [5e5, 4.5e6, 350.0];
    let head = {
        let text = common::bundled_text("wall");
        text[..text.find("[[interface]]").unwrap()].to_string()
    };
    // `crr assemble FILE --planar` with more arguments.
    let planar_cli = |path: &std::path::Path, more: &[&str]| {
        let mut args = vec!["assemble", path.to_str().unwrap(), "--planar"];
        args.extend_from_slice(more);
        common::crr(&args)
    };
    let path = common::write_model("wall_survey_assembly", &boxes_moved(&head, SURVEY));
    let o = planar_cli(&path, &[]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("rests on nothing")
            && err.contains("the lowest stands at z = 350.000000 m")
            && err.contains("--ground-level 350`"),
        "{err}"
    );

    let model = common::scratch("wall_survey_model").join("model.toml");
    let o = planar_cli(
        &path,
        &["--ground-level", "350", "--out", model.to_str().unwrap()],
    );
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let planar = AssemblyOptions::default().in_plane();
    let origin_path = assembly_of("wall", "wall_origin_assembly");
    let at_origin = assemble(&origin_path, &read_assembly(&origin_path).unwrap(), &planar).unwrap();
    assert!(
        text.contains(&format!("({} interfaces,", at_origin.file.interface.len())),
        "{text}"
    );
    // The model written records the ground it stands on.
    let written = std::fs::read_to_string(&model).unwrap();
    assert!(
        written.contains("# The ground is the plane z = 350 m (`crr assemble --ground-level 350`)"),
        "{written}"
    );

    let survey = assemble(
        &path,
        &read_assembly(&path).unwrap(),
        &AssemblyOptions {
            ground_level: 350.0,
            ..planar
        },
    )
    .unwrap();
    assert_eq!(survey.file.interface.len(), at_origin.file.interface.len());
    let line = |p: &Option<PivotSpec>| match p.as_ref().expect("a pivot") {
        PivotSpec::Point(a) => [*a, *a],
        PivotSpec::Segment(ends) => *ends,
    };
    for (far, near) in survey.file.interface.iter().zip(&at_origin.file.interface) {
        assert_eq!(
            (&far.name, &far.parent, &far.child),
            (&near.name, &near.parent, &near.child)
        );
        for (a, b) in [
            (line(&far.pivot_positive), line(&near.pivot_positive)),
            (line(&far.pivot_negative), line(&near.pivot_negative)),
        ] {
            for (pa, pb) in a.iter().zip(&b) {
                for k in 0..3 {
                    assert!(
                        (pa[k] - SURVEY[k] - pb[k]).abs() < 1e-9,
                        "{}: {pa:?} against {pb:?}",
                        far.name
                    );
                }
            }
        }
    }
    for d in [Vector3::x(), -Vector3::x()] {
        let l = lambda(&survey.model, d);
        assert!((l - 7.0 / 11.0).abs() < 1e-9, "{l}");
    }

    let sunk = boxes_moved(&head, [SURVEY[0], SURVEY[1], SURVEY[2] - 0.05]);
    let path = common::write_model("wall_survey_sunk", &sunk);
    let o = planar_cli(&path, &["--ground-level", "350"]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("reaches 0.050000 m below the ground (z = 350 m)"),
        "{err}"
    );
}

/// The text of an assembly of boxes (`box = { center = …, size = … }` lines) turned by `angle`
/// about the vertical through the origin (each centre turned, each box given that rotation) and
/// then moved by `d`.
fn boxes_turned(text: &str, angle: f64, d: [f64; 3]) -> String {
    let (sin, cos) = angle.sin_cos();
    rewrite_centres(text, |c, rest| {
        let rest = rest.trim_end().strip_suffix('}').expect("an inline table");
        format!(
            "{:?}, {:?}, {:?}{}, rotation = [0.0, 0.0, {angle:?}] }}",
            cos * c[0] - sin * c[1] + d[0],
            sin * c[0] + cos * c[1] + d[1],
            c[2] + d[2],
            rest.trim_end()
        )
    })
}

/// Faces at a bearing are found in survey coordinates as at the origin: the bundled façade
/// (`examples/assemblies/facade.toml`, 52 blocks) turned to a 30° bearing, at the origin and 5e5
/// m east, 4.5e6 m north, 350 m up (ground level 350), has the same contacts (beds and head
/// joints, with their areas to 1e-9 m²: the survey file holds its points to ulp(4.5e6) ≈ 1e-9 m)
/// and, with every contact an interface, the same multiplier along its length to 1e-7.
/// Compared at their absolute coordinates, the faces' planes carried the normals' round-off
/// times 4.5e6 m, and 7 of the 127 contacts were lost (measured).
#[test]
fn a_facade_at_a_bearing_in_survey_coordinates_keeps_every_contact() {
    let source =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assemblies/facade.toml");
    let text = std::fs::read_to_string(source).unwrap();
    let bearing = std::f64::consts::FRAC_PI_6;
    let assembled = |tag: &str, d: [f64; 3]| {
        let path = common::write_model(tag, &boxes_turned(&text, bearing, d));
        let options = AssemblyOptions {
            ground_level: d[2],
            ..Default::default()
        }
        .with_all_contacts();
        assemble(&path, &read_assembly(&path).unwrap(), &options).unwrap()
    };
    let near = assembled("facade_bearing_origin", [0.0; 3]);
    let far = assembled("facade_bearing_survey", [5e5, 4.5e6, 350.0]);
    let areas = |a: &crr::analysis::assemble::Assembled| {
        let mut areas: Vec<(bool, f64)> = a.contacts.iter().map(|c| (c.bed, c.area)).collect();
        areas.sort_by(|x, y| x.partial_cmp(y).unwrap());
        areas
    };
    let (near_areas, far_areas) = (areas(&near), areas(&far));
    assert_eq!(near_areas.len(), 127);
    assert_eq!(far_areas.len(), near_areas.len());
    for (a, b) in far_areas.iter().zip(&near_areas) {
        assert!(
            a.0 == b.0 && (a.1 - b.1).abs() < 1e-9,
            "{a:?} against {b:?}"
        );
    }
    let along = Vector3::new(bearing.cos(), bearing.sin(), 0.0);
    let (l_near, l_far) = (lambda(&near.model, along), lambda(&far.model, along));
    assert!(
        (l_far - l_near).abs() < 1e-7 * l_near,
        "{l_far} against {l_near}"
    );
}

/// The trilithon bundled as three stones (`examples/assemblies/trilithon.toml`) gives, with
/// `--planar`, the hand-written trilithon's four joints (`examples/models/trilithon.toml`: the same
/// parents, children and pivot lines) and its multiplier b/h = 0.5/4 = 0.125 along ±x.
#[test]
fn the_trilithon_of_stones_is_the_hand_written_trilithon() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assemblies/trilithon.toml");
    let file = read_assembly(&path).unwrap();
    let planar = assemble(&path, &file, &AssemblyOptions::default().in_plane()).unwrap();
    let (hand, _) = crr::load_model(&common::bundled_path("trilithon")).unwrap();
    assert_eq!(joints(&planar.file.interface), joints(&hand.interface));
    for d in [Vector3::x(), -Vector3::x()] {
        let l = lambda(&planar.model, d);
        assert!((l - 0.125).abs() < 1e-9, "{l}");
    }
}

/// Every bundled assembly goes from stones to a simulation through the command line, as
/// `examples/assemblies/README.md` shows: `crr assemble` writes a model (the arch with
/// `--all-contacts`: its ten joints, one loop), `crr check` reports its multipliers and
/// `crr simulate` runs it; a record given relative to the assembly's folder is found from the
/// model's folder (here a scratch folder elsewhere).
#[test]
fn the_bundled_assemblies_go_from_stones_to_a_simulation() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assemblies");
    for (name, flags, interfaces, loops) in [
        ("arch", &["--all-contacts", "--planar"][..], 10, 1),
        ("wall", &["--planar"][..], 75, 31),
        ("facade", &["--planar"][..], 86, 34),
        ("trilithon", &["--planar"][..], 4, 1),
        ("segmental_arch", &["--all-contacts", "--planar"][..], 8, 1),
    ] {
        let out = common::scratch(&format!("assembled_{name}"));
        let model = out.join("model.toml");
        let source = dir.join(format!("{name}.toml"));
        let mut args = vec!["assemble", source.to_str().unwrap()];
        args.extend_from_slice(flags);
        args.extend(["--out", model.to_str().unwrap()]);
        let o = common::crr(&args);
        let text = String::from_utf8_lossy(&o.stdout).to_string();
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            text.contains(&format!("({interfaces} interfaces,"))
                && text.contains(&format!("{loops} loop closure(s)")),
            "{name}: {text}"
        );
        let o = common::crr(&["check", model.to_str().unwrap()]);
        let report = String::from_utf8_lossy(&o.stdout).to_string();
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(report.contains("d = +x: λ = "), "{name}: {report}");
        let results = out.join("run");
        let o = common::crr(&[
            "simulate",
            model.to_str().unwrap(),
            "--duration",
            "1.0",
            "--out",
            results.to_str().unwrap(),
            "--quiet",
        ]);
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(results.join("summary.json").exists(), "{name}");
    }
}

/// The OBJ text of a box [lo, hi] as object `name`, its vertices numbered from `first` (OBJ
/// indices are global to the file): six quadrilaterals, counter-clockwise seen from outside;
/// `skip` leaves one face out.
fn box_obj(name: &str, lo: [f64; 3], hi: [f64; 3], first: usize, skip: Option<usize>) -> String {
    let mut s = format!("o {name}\n");
    for k in 0..8 {
        let x = if matches!(k % 4, 1 | 2) { hi[0] } else { lo[0] };
        let y = if matches!(k % 4, 2 | 3) { hi[1] } else { lo[1] };
        let z = if k >= 4 { hi[2] } else { lo[2] };
        s += &format!("v {x} {y} {z}\n");
    }
    let faces = [
        [0, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 4, 7, 3],
        [1, 2, 6, 5],
    ];
    for (i, f) in faces.iter().enumerate() {
        if Some(i) != skip {
            let f: Vec<String> = f.iter().map(|&v| (v + first).to_string()).collect();
            s += &format!("f {}\n", f.join(" "));
        }
    }
    s
}

/// An assembly whose blocks come from an OBJ file written beside it.
fn obj_assembly(tag: &str, obj: &str, table: &str) -> std::path::PathBuf {
    let dir = common::scratch(tag);
    std::fs::write(dir.join("blocks.obj"), obj).unwrap();
    let path = dir.join("assembly.toml");
    std::fs::write(
        &path,
        format!("name = \"{tag}\"\n[[obj]]\nfile = \"blocks.obj\"\ndensity = 2000.0\n{table}"),
    )
    .unwrap();
    path
}

/// Blocks from a Wavefront OBJ file: a column of two stones 0.4 × 0.4 × 1 m stacked on the
/// ground rocks whole on a base edge at λ = b/h = 0.2/1.0 along x and y, and weighs
/// 2 × 0.16 m³ × 2000 kg/m³, whether the file is in metres with z up, in millimetres, or in
/// metres with y up; an open mesh and a non-convex block are refused naming the object, and
/// `crr simulate` refuses a file with `[[obj]]` (an assembly, not a model).
#[test]
fn blocks_from_an_obj_file() {
    let column = |k: f64, y_up: bool| {
        let p = |x: f64, y: f64, z: f64| {
            if y_up {
                [k * x, k * z, -k * y]
            } else {
                [k * x, k * y, k * z]
            }
        };
        let (a0, a1) = (p(-0.2, -0.2, 0.0), p(0.2, 0.2, 1.0));
        let (b0, b1) = (p(-0.2, -0.2, 1.0), p(0.2, 0.2, 2.0));
        let sorted = |u: [f64; 3], v: [f64; 3]| {
            let lo = [u[0].min(v[0]), u[1].min(v[1]), u[2].min(v[2])];
            let hi = [u[0].max(v[0]), u[1].max(v[1]), u[2].max(v[2])];
            (lo, hi)
        };
        let ((la, ha), (lb, hb)) = (sorted(a0, a1), sorted(b0, b1));
        box_obj("lower", la, ha, 1, None) + &box_obj("upper", lb, hb, 9, None)
    };
    for (tag, obj, table) in [
        ("obj_m", column(1.0, false), ""),
        ("obj_mm", column(1000.0, false), "units = \"mm\"\n"),
        ("obj_y_up", column(1.0, true), "up = \"y\"\n"),
    ] {
        let path = obj_assembly(tag, &obj, table);
        let file = read_assembly(&path).unwrap();
        let names: Vec<&str> = file.body.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["lower", "upper"], "{tag}");
        let a = assemble(&path, &file, &AssemblyOptions::default()).unwrap();
        let mass = a.model.total_mass();
        assert!(
            (mass - 2.0 * 0.16 * 2000.0).abs() < 1e-9 * mass,
            "{tag}: {mass}"
        );
        for d in [Vector3::x(), -Vector3::y()] {
            let l = lambda(&a.model, d);
            assert!((l - 0.2).abs() < 1e-9, "{tag}: {l}");
        }
    }
    // A model file is not an assembly: its [[obj]] blocks are refused by `crr simulate`.
    let path = obj_assembly("obj_as_model", &column(1.0, false), "");
    let o = common::crr(&["simulate", path.to_str().unwrap(), "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("[[obj]] lists blocks of an assembly"), "{err}");
    let open = obj_assembly(
        "obj_open",
        &box_obj("a", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0], 1, Some(1)),
        "",
    );
    let o = common::crr(&["assemble", open.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("object \"a\": the mesh is not a closed surface"),
        "{err}"
    );
    // An L-shaped prism (a reflex corner at (1, 1)): not the convex hull of its vertices.
    let l_shape = [
        [0.0, 0.0],
        [2.0, 0.0],
        [2.0, 1.0],
        [1.0, 1.0],
        [1.0, 2.0],
        [0.0, 2.0],
    ];
    let mut obj = String::from("o ell\n");
    for z in [0.0, 1.0] {
        for [x, y] in l_shape {
            obj += &format!("v {x} {y} {z}\n");
        }
    }
    obj += "f 6 5 4 3 2 1\nf 7 8 9 10 11 12\n";
    for i in 0..6 {
        let j = (i + 1) % 6;
        obj += &format!("f {} {} {} {}\n", i + 1, j + 1, j + 7, i + 7);
    }
    let path = obj_assembly("obj_ell", &obj, "");
    let o = common::crr(&["assemble", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("object \"ell\": the block is not convex"),
        "{err}"
    );
}

/// As CAD programs write them: the column of two stones of `blocks_from_an_obj_file` with the
/// lower stone's faces in two material groups inside its object (`g stone`, `g polished`), and
/// the upper stone's top face wound the other way. tobj starts a block at every group, and the
/// lower stone was refused as "not a closed surface" in two pieces; the reversed face was
/// refused as an edge met twice one way. Now: two blocks, `lower` and `upper`, weighing
/// 2 × 0.16 m³ × 2000 kg/m³, rocking whole at λ = b/h = 0.2 as the clean file. A file of groups
/// and no objects keeps its groups as its blocks; a stone with a face missing is still refused.
#[test]
fn an_obj_stone_in_material_groups_and_a_face_wound_back_are_blocks() {
    let lower = box_obj("lower", [-0.2, -0.2, 0.0], [0.2, 0.2, 1.0], 1, None);
    let mut lines: Vec<String> = lower.lines().map(String::from).collect();
    // After `o lower` and the 8 vertices (lines 1–8): the bottom face, the top, the four sides;
    // the bottom and sides as stone, the top polished.
    for (at, line) in [
        (9, "g stone"),
        (11, "usemtl polished"),
        (12, "g polished"),
        (14, "usemtl stone"),
        (15, "g stone"),
    ] {
        lines.insert(at, line.into());
    }
    assert_eq!(lines[13], "f 5 6 7 8");
    let lower = lines.join("\n") + "\n";
    assert_eq!(lower.matches("\nf ").count(), 6);
    let upper = box_obj("upper", [-0.2, -0.2, 1.0], [0.2, 0.2, 2.0], 9, None);
    let top = "f 13 14 15 16";
    assert!(upper.contains(top));
    let upper = upper.replace(top, "f 16 15 14 13");
    let obj = format!("mtllib stones.mtl\n{lower}{upper}");
    let path = obj_assembly("obj_groups", &obj, "");
    let file = read_assembly(&path).unwrap();
    let names: Vec<&str> = file.body.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["lower", "upper"]);
    let a = assemble(&path, &file, &AssemblyOptions::default()).unwrap();
    let mass = a.model.total_mass();
    assert!((mass - 2.0 * 0.16 * 2000.0).abs() < 1e-9 * mass, "{mass}");
    for d in [Vector3::x(), -Vector3::y()] {
        let l = lambda(&a.model, d);
        assert!((l - 0.2).abs() < 1e-9, "{l}");
    }
    // Groups without objects are the blocks.
    let grouped = box_obj("lower", [-0.2, -0.2, 0.0], [0.2, 0.2, 1.0], 1, None)
        .replace("o lower", "g lower")
        + &box_obj("upper", [-0.2, -0.2, 1.0], [0.2, 0.2, 2.0], 9, None)
            .replace("o upper", "g upper");
    let path = obj_assembly("obj_only_groups", &grouped, "");
    let file = read_assembly(&path).unwrap();
    let names: Vec<&str> = file.body.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["lower", "upper"]);
    // A face wound back is turned; a face left out is still a hole.
    let open = box_obj("a", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0], 1, Some(1))
        .replace("f 1 4 3 2", "f 2 3 4 1");
    let path = obj_assembly("obj_open_wound", &open, "");
    let o = common::crr(&["assemble", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("object \"a\": the mesh is not a closed surface"),
        "{err}"
    );
}

/// OBJ files as exporters write them, where the old reading went wrong (an independent
/// review): groups before the first object stay blocks (`g base` then `o upper`: the new reading
/// first merged the group into nothing, an "unnamed_object"); an object without a name is
/// `object_N` as documented, N its number among the blocks with faces, skipping a name the file
/// gives (two were "unnamed_object" twice, refused; faces before any object were another
/// "unnamed_object"); a single object
/// wrapping two stones' groups is refused with what its groups are and what to write; and an
/// open stone with a face wound back names its hole, the same edge at every run (the message
/// came from a hash map's order, and named an edge of the reversed face in 8 runs of 12).
#[test]
fn obj_groups_before_objects_unnamed_objects_and_holes() {
    let lower = |name: &str, keyword: &str| {
        box_obj(name, [-0.2, -0.2, 0.0], [0.2, 0.2, 1.0], 1, None).replacen(
            &format!("o {name}"),
            &format!("{keyword} {name}"),
            1,
        )
    };
    let upper = |name: &str| box_obj(name, [-0.2, -0.2, 1.0], [0.2, 0.2, 2.0], 9, None);
    let names_of = |tag: &str, obj: &str| -> Vec<String> {
        let path = obj_assembly(tag, obj, "");
        read_assembly(&path)
            .unwrap()
            .body
            .iter()
            .map(|b| b.name.clone())
            .collect()
    };
    assert_eq!(
        names_of("obj_group_first", &(lower("base", "g") + &upper("upper"))),
        ["base", "upper"]
    );
    let unnamed = lower("x", "o").replacen("o x", "o", 1) + &upper("y").replacen("o y", "o", 1);
    assert_eq!(names_of("obj_unnamed", &unnamed), ["object_1", "object_2"]);
    // Faces before any object are block 1; a generated name skips one the file gives; an
    // object without faces is no block and takes no number.
    let leading = lower("x", "o").replacen("o x\n", "", 1) + &upper("upper");
    assert_eq!(
        names_of("obj_leading_faces", &leading),
        ["object_1", "upper"]
    );
    let clash = lower("x", "o").replacen("o x", "o", 1) + &upper("object_1");
    assert_eq!(
        names_of("obj_name_clash", &clash),
        ["object_1_2", "object_1"]
    );
    let ghost = format!("o ghost\n{unnamed}");
    assert_eq!(names_of("obj_ghost", &ghost), ["object_1", "object_2"]);
    // One object around two stones' groups.
    let scene = format!(
        "o Scene\n{}{}",
        lower("lower", "g"),
        upper("upper").replacen("o upper", "g upper", 1)
    );
    let path = obj_assembly("obj_scene", &scene, "");
    let o = common::crr(&["assemble", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("object \"Scene\""), "{err}");
    assert!(
        err.contains("the groups \"lower\", \"upper\" inside object \"Scene\""),
        "{err}"
    );
    // Top face left out, bottom face wound back: the hole is an edge of the top.
    let open = box_obj("a", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0], 1, Some(1))
        .replace("f 1 4 3 2", "f 2 3 4 1");
    let path = obj_assembly("obj_open_reversed", &open, "");
    for _ in 0..4 {
        let o = common::crr(&["assemble", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("belongs to 1 face(s)"), "{err}");
        assert!(
            err.contains(", 1.000000) to ("),
            "an edge of the top: {err}"
        );
    }
}

/// Two blocks meeting in two planes name their second interface `…_2`, unless another pair has
/// that name: an L-shaped stone `ell` with a block on its foot against its upright, the block
/// also resting on a box named `ell_2` (an independent review: "interface "block_on_ell_2": the
/// name is used by two interfaces"). Every name is distinct and the model loads.
#[test]
fn a_second_interface_of_a_pair_takes_a_free_name() {
    let dir = common::scratch("name_collision");
    let path = dir.join("coll.toml");
    std::fs::write(
        &path,
        "name = \"coll\"\n\
         [[body]]\nname = \"ell\"\ndensity = 2000.0\n\
         prism = { polygon = [[-0.5, -0.2, 0.0], [0.5, -0.2, 0.0], [0.5, -0.2, 0.4], \
         [-0.2, -0.2, 0.4], [-0.2, -0.2, 1.5], [-0.5, -0.2, 1.5]], extrude = [0.0, 0.4, 0.0] }\n\
         [[body]]\nname = \"ell_2\"\ndensity = 2000.0\n\
         box = { center = [0.75, 0.0, 0.2], size = [0.5, 0.4, 0.4] }\n\
         [[body]]\nname = \"block\"\ndensity = 2000.0\n\
         box = { center = [0.3, 0.0, 0.9], size = [1.0, 0.4, 1.0] }\n",
    )
    .unwrap();
    let file = read_assembly(&path).unwrap();
    let a = assemble(
        &path,
        &file,
        &AssemblyOptions::default().with_all_contacts(),
    )
    .unwrap();
    let names: BTreeSet<&str> = a.file.interface.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(names.len(), a.file.interface.len(), "{names:?}");
    for expected in ["block_on_ell", "block_on_ell_2", "block_on_ell_3"] {
        assert!(names.contains(expected), "{names:?}");
    }
}

/// The OBJ text `obj` with every vertex (`v x y z` line) turned by `angle` about the vertical
/// through the origin and then moved by `d`; faces and names as they are.
fn obj_turned(obj: &str, angle: f64, d: [f64; 3]) -> String {
    let (sin, cos) = angle.sin_cos();
    obj.lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(xyz) => {
                let c: Vec<f64> = xyz.split_whitespace().map(|t| t.parse().unwrap()).collect();
                format!(
                    "v {:?} {:?} {:?}",
                    cos * c[0] - sin * c[1] + d[0],
                    sin * c[0] + cos * c[1] + d[1],
                    c[2] + d[2]
                )
            }
            None => line.to_string(),
        })
        .map(|line| line + "\n")
        .collect()
}

/// Blocks of an OBJ file in survey coordinates are blocks: the column of two stones
/// 0.4 × 0.4 × 1 m of `blocks_from_an_obj_file` turned to a 30° bearing and written 5e5 m east,
/// 4.5e6 m north, 350 m up (its points then resolved to ulp(4.5e6) ≈ 1e-9 m) assembles on the
/// ground level 350 as at the origin: 2 × 0.16 m³ × 2000 kg/m³, and it rocks whole on a base
/// edge at λ = b/h = 0.2 along its own faces' normal, to 1e-7 (the points' resolution over the
/// width). Checked for convexity at their absolute coordinates, the stones' face planes carried
/// the normals' round-off times 4.5e6 m and the first was refused as not convex (measured).
#[test]
fn an_obj_column_in_survey_coordinates_assembles_as_at_the_origin() {
    let column = box_obj("lower", [-0.2, -0.2, 0.0], [0.2, 0.2, 1.0], 1, None)
        + &box_obj("upper", [-0.2, -0.2, 1.0], [0.2, 0.2, 2.0], 9, None);
    let bearing = std::f64::consts::FRAC_PI_6;
    for (tag, d) in [
        ("obj_bearing_origin", [0.0; 3]),
        ("obj_bearing_survey", [5e5, 4.5e6, 350.0]),
    ] {
        let path = obj_assembly(tag, &obj_turned(&column, bearing, d), "");
        let options = AssemblyOptions {
            ground_level: d[2],
            ..Default::default()
        };
        let file = read_assembly(&path).unwrap_or_else(|e| panic!("{tag}: {e}"));
        let a = assemble(&path, &file, &options).unwrap_or_else(|e| panic!("{tag}: {e}"));
        let mass = a.model.total_mass();
        assert!(
            (mass - 2.0 * 0.16 * 2000.0).abs() < 1e-9 * mass,
            "{tag}: {mass}"
        );
        let across = Vector3::new(-bearing.sin(), bearing.cos(), 0.0);
        for d in [Vector3::new(bearing.cos(), bearing.sin(), 0.0), -across] {
            let l = lambda(&a.model, d);
            assert!((l - 0.2).abs() < 1e-7, "{tag}: {l}");
        }
    }
}

/// Blocks that are part of the ground (`fixed`): the bundled arch of 9 voussoirs
/// (`examples/assemblies/arch.toml`) raised 1 m onto two fixed abutments (1 × 2 × 1 m boxes
/// under its springings, wider than them) is the arch on the ground raised 1 m: the same 10
/// joints (names, parents, children) with every corner 1 m higher to 1e-12 m, no abutment in the
/// model, and the same multipliers along ±x (the ground's and the abutments' faces are one
/// support; gravity and the load do not depend on the height) to 1e-9.
#[test]
fn an_arch_on_fixed_abutments_is_the_arch_on_the_ground_raised() {
    let source =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assemblies/arch.toml");
    let text = std::fs::read_to_string(source).unwrap();
    let blocks = &text[..text.find("[ground_motion]").unwrap()];
    let all = AssemblyOptions::default().with_all_contacts();
    let on_ground_path = common::write_model("arch_on_ground", blocks);
    let on_ground = assemble(
        &on_ground_path,
        &read_assembly(&on_ground_path).unwrap(),
        &all,
    )
    .unwrap();
    let raised = boxes_moved(blocks, [0.0, 0.0, 1.0])
        + "fixed = [\"abutment_left\", \"abutment_right\"]\n"
        + "[[body]]\nname = \"abutment_left\"\ndensity = 2200.0\n"
        + "box = { center = [-2.25, 0.0, 0.5], size = [1.0, 2.0, 1.0] }\n"
        + "[[body]]\nname = \"abutment_right\"\ndensity = 2200.0\n"
        + "box = { center = [2.25, 0.0, 0.5], size = [1.0, 2.0, 1.0] }\n";
    // `fixed` is a key of the file's top level: before the first table.
    let raised = {
        let at = raised.find("[[body]]").unwrap();
        let (head, tail) = raised.split_at(at);
        let fixed_line = "fixed = [\"abutment_left\", \"abutment_right\"]\n";
        format!("{head}{fixed_line}{}", tail.replacen(fixed_line, "", 1))
    };
    let on_abutments_path = common::write_model("arch_on_abutments", &raised);
    let on_abutments = assemble(
        &on_abutments_path,
        &read_assembly(&on_abutments_path).unwrap(),
        &all,
    )
    .unwrap();
    assert_eq!(on_abutments.file.body.len(), 9);
    assert_eq!(on_abutments.file.interface.len(), 10);
    assert_eq!(
        on_abutments.file.interface.len(),
        on_ground.file.interface.len()
    );
    for (a, g) in on_abutments
        .file
        .interface
        .iter()
        .zip(&on_ground.file.interface)
    {
        assert_eq!(
            (&a.name, &a.parent, &a.child),
            (&g.name, &g.parent, &g.child)
        );
        let (ca, cg) = (
            &a.rocking_base.as_ref().unwrap().corners,
            &g.rocking_base.as_ref().unwrap().corners,
        );
        assert_eq!(ca.len(), cg.len(), "{}", a.name);
        for (p, q) in ca.iter().zip(cg) {
            let moved = [q[0], q[1], q[2] + 1.0];
            assert!(
                (0..3).all(|k| (p[k] - moved[k]).abs() < 1e-12),
                "{}: {p:?} against {q:?}",
                a.name
            );
        }
    }
    for d in [Vector3::x(), -Vector3::x()] {
        let (la, lg) = (lambda(&on_abutments.model, d), lambda(&on_ground.model, d));
        assert!((la - lg).abs() < 1e-9 * lg, "{la} against {lg}");
    }
}

/// A stepped site: a block 0.4 × 0.4 × 1 m on the ground (λ = b/h = 0.4) and a block
/// 0.3 × 0.3 × 1.5 m on a fixed step 0.5 m high that reaches 0.3 m below the ground level
/// (a foundation: fixed blocks may) rock on their own: the structure's multiplier is the
/// tall block's b/h = 0.2 along ±x and ±y, its model has the two blocks and two ground joints,
/// and the model written names the step. Refused, each naming the item: a fixed name that is no
/// block; a model file with `fixed` given to `crr simulate`.
#[test]
fn blocks_on_a_fixed_step_rock_on_the_ground_it_makes() {
    let site = |fixed: &str, extra: &str| {
        format!("name = \"stepped\"\nfixed = [{fixed}]\n")
            + &box_body("low", [-1.0, 0.0, 0.5], [0.4, 0.4, 1.0])
            + &box_body("step", [1.0, 0.0, 0.1], [1.0, 1.0, 0.8])
            + &box_body("high", [1.0, 0.0, 1.25], [0.3, 0.3, 1.5])
            + extra
    };
    let path = common::write_model("stepped_site", &site("\"step\"", ""));
    let a = assemble(
        &path,
        &read_assembly(&path).unwrap(),
        &AssemblyOptions::default(),
    )
    .unwrap();
    let names: Vec<&str> = a.file.body.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["low", "high"]);
    let joints: Vec<(&str, &str)> = a
        .file
        .interface
        .iter()
        .map(|i| (i.parent.as_str(), i.child.as_str()))
        .collect();
    assert_eq!(joints, [("ground", "low"), ("ground", "high")]);
    for d in [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()] {
        let l = lambda(&a.model, d);
        assert!((l - 0.2).abs() < 1e-9, "{d:?}: {l}");
    }
    let model = common::scratch("stepped_site_model").join("model.toml");
    let o = common::crr(&[
        "assemble",
        path.to_str().unwrap(),
        "--out",
        model.to_str().unwrap(),
        "--force",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let written = std::fs::read_to_string(&model).unwrap();
    assert!(
        written.contains("# Fixed blocks, part of the ground and not in the model: step."),
        "{written}"
    );
    let o = common::crr(&["simulate", model.to_str().unwrap(), "--quiet", "--force"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let refused = |tag: &str, text: &str, command: &str| {
        let path = common::write_model(tag, text);
        let o = common::crr(&[command, path.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{tag}");
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let err = refused("stepped_unknown", &site("\"stair\"", ""), "assemble");
    assert!(err.contains("fixed: no block is named \"stair\""), "{err}");
    let err = refused("stepped_as_model", &site("\"step\"", ""), "simulate");
    assert!(err.contains("`fixed` names blocks of an assembly"), "{err}");
}

/// A block on two fixed slabs rests on the convex hull of its two faces on them: a block
/// 0.4 × 0.4 × 1 m centred over the joint of two slabs 0.2 m thick (its base half on each), and
/// over a gap of 0.1 m between them, rocks on its base's outer edges as on the ground: λ = b/h
/// = 0.4 along ±x and ±y, one ground joint whose corners are the base's (to 1e-12 m). A block
/// on one slab and against the side of a higher one meets the ground on faces in two planes:
/// with every contact an interface, a ground joint on each.
#[test]
fn a_block_on_two_fixed_slabs_rocks_on_the_hull_of_its_faces() {
    let site = |gap: f64| {
        let w = 1.0 - gap / 2.0;
        "name = \"slabs\"\nfixed = [\"west\", \"east\"]\n".to_string()
            + &box_body("west", [-0.5 - gap / 4.0, 0.0, 0.1], [w, 2.0, 0.2])
            + &box_body("east", [0.5 + gap / 4.0, 0.0, 0.1], [w, 2.0, 0.2])
            + &box_body("block", [0.0, 0.0, 0.7], [0.4, 0.4, 1.0])
    };
    for gap in [0.0, 0.1] {
        let path = common::write_model(&format!("slabs_gap_{gap}"), &site(gap));
        let a = assemble(
            &path,
            &read_assembly(&path).unwrap(),
            &AssemblyOptions::default(),
        )
        .unwrap_or_else(|e| panic!("gap {gap}: {e}"));
        assert_eq!(a.file.interface.len(), 1, "gap {gap}");
        let mut corners = a.file.interface[0]
            .rocking_base
            .as_ref()
            .unwrap()
            .corners
            .clone();
        corners.sort_by(|p, q| p.partial_cmp(q).unwrap());
        let base = [
            [-0.2, -0.2, 0.2],
            [-0.2, 0.2, 0.2],
            [0.2, -0.2, 0.2],
            [0.2, 0.2, 0.2],
        ];
        for (p, q) in corners.iter().zip(&base) {
            assert!(
                (0..3).all(|k| (p[k] - q[k]).abs() < 1e-12),
                "gap {gap}: {corners:?}"
            );
        }
        for d in [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()] {
            let l = lambda(&a.model, d);
            assert!((l - 0.4).abs() < 1e-9, "gap {gap}, {d:?}: {l}");
        }
    }
    // A block beside a step: its base on the west slab, its east side against the east slab,
    // 0.1 m higher. With every contact an interface it meets the ground on two faces in two
    // planes: two ground joints, the side's normal −x, out of the east slab.
    let text = "name = \"step\"\nfixed = [\"west\", \"east\"]\n".to_string()
        + &box_body("west", [-0.5, 0.0, 0.1], [1.0, 2.0, 0.2])
        + &box_body("east", [0.5, 0.0, 0.15], [1.0, 2.0, 0.3])
        + &box_body("block", [-0.2, 0.0, 0.7], [0.4, 0.4, 1.0]);
    let path = common::write_model("slabs_step", &text);
    let a = assemble(
        &path,
        &read_assembly(&path).unwrap(),
        &AssemblyOptions::default().with_all_contacts(),
    )
    .unwrap();
    let names: Vec<&str> = a.file.interface.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(names, ["block_on_ground", "block_on_ground_2"]);
    let side = a.contacts.iter().find(|c| !c.bed).expect("the step's face");
    assert!(
        (side.normal + Vector3::x()).norm() < 1e-12,
        "{:?}",
        side.normal
    );
}

/// A column of drums (`--inscribed`): three drums, regular 16-gon prisms of radius R = 0.45 m
/// (a vertex on x) and 1.3 m high, stacked on the ground. Their beds are 16-gons, which a
/// rocking base (a rectangle) cannot be: refused, naming the contact and the option. With
/// `--inscribed` each bed is the square inscribed in the 16-gon, half-side b = R cos 45° (its
/// corners are vertices at 45°, 135°, …), to 1e-12 m, and the column rocks whole on its base at
/// λ = 2b/(3 × 1.3) = 0.163178 along ±x and ±y (the block's b/h; the bundled temple's drum
/// shafts use the same squares), to 1e-9; the same in survey coordinates (5e5 m east, 4.5e6 m
/// north, 350 m up), to the points' resolution (computed at absolute coordinates, the square of
/// a drum 1e5 m away shrank to a third: an independent review).
#[test]
fn a_column_of_drums_rocks_on_the_squares_inscribed_in_its_beds() {
    let (radius, height) = (0.45f64, 1.3f64);
    // The column standing at o (its base's centre).
    let column = |o: [f64; 3]| {
        let mut text = String::from("name = \"drums\"\n");
        for k in 0..3 {
            let polygon: Vec<[f64; 3]> = (0..16)
                .map(|i| {
                    let a = 2.0 * std::f64::consts::PI * i as f64 / 16.0;
                    [
                        o[0] + radius * a.cos(),
                        o[1] + radius * a.sin(),
                        o[2] + k as f64 * height,
                    ]
                })
                .collect();
            text += &format!(
                "[[body]]\nname = \"d{}\"\ndensity = 2500.0\nprism = {{ polygon = {polygon:?}, \
                 extrude = [0.0, 0.0, {height:?}] }}\n",
                k + 1
            );
        }
        text
    };
    let path = common::write_model("drum_column_assembly", &column([0.0; 3]));
    let o = common::crr(&["assemble", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("contact \"d1_on_ground\": its face is a polygon of 16 corners")
            && err.contains("--inscribed"),
        "{err}"
    );
    let b = radius * std::f64::consts::FRAC_PI_4.cos();
    // At the origin (1e-12 m), and in survey coordinates, its points resolved to
    // ulp(4.5e6) ≈ 1e-9 m (1e-8 m; λ to 1e-7).
    for (tag, o, tol) in [
        ("drum_column_origin", [0.0; 3], 1e-12),
        ("drum_column_survey", [5e5, 4.5e6, 350.0], 1e-8),
    ] {
        let path = common::write_model(tag, &column(o));
        let options = AssemblyOptions {
            inscribed: true,
            ground_level: o[2],
            ..Default::default()
        };
        let a = assemble(&path, &read_assembly(&path).unwrap(), &options).unwrap();
        assert_eq!(a.file.interface.len(), 3);
        for (k, interface) in a.file.interface.iter().enumerate() {
            let corners = &interface.rocking_base.as_ref().unwrap().corners;
            assert_eq!(corners.len(), 4);
            for p in corners {
                assert!(
                    ((p[0] - o[0]).abs() - b).abs() < tol
                        && ((p[1] - o[1]).abs() - b).abs() < tol
                        && (p[2] - o[2] - k as f64 * height).abs() < tol,
                    "{tag}, {}: {p:?}",
                    interface.name
                );
            }
        }
        for d in [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()] {
            let l = lambda(&a.model, d);
            let expected = 2.0 * b / (3.0 * height);
            assert!(
                (l - expected).abs() < 1e3 * tol,
                "{tag}, {d:?}: {l} against {expected}"
            );
        }
    }
}

/// Fixed blocks beside, over and overlapping the free ones (from an independent review):
/// - a column 0.4 × 0.4 × 2 m between the ground and a fixed beam resting on its top has two
///   ground joints (`column_on_ground`, `column_on_ground_2`, the second's normal down, out of
///   the beam) and cannot move: a rectangle between two plates its height apart cannot turn
///   (its diagonal is longer) and, with no sliding, cannot slide: it holds along ±x and ±y;
/// - a block against a fixed pier, with every contact an interface, has a ground joint on the
///   ground and one on the pier's face, its normal +x out of the pier;
/// - a stepped site written as two overlapping fixed boxes is one ground: the blocks on it rock
///   as on the step of one box (λ = b/h = 0.2 of the tall one);
/// - a block named twice in `fixed` is refused, naming it; the ground-level hint names where
///   the free blocks stand, not a fixed footing below the ground.
#[test]
fn fixed_blocks_beside_over_and_overlapping_free_ones() {
    let built = |tag: &str, text: &str, options: &AssemblyOptions| {
        let path = common::write_model(tag, text);
        assemble(&path, &read_assembly(&path).unwrap(), options)
    };
    let clamped = "name = \"clamped\"\nfixed = [\"beam\"]\n".to_string()
        + &box_body("column", [0.0, 0.0, 1.0], [0.4, 0.4, 2.0])
        + &box_body("beam", [0.0, 0.0, 2.25], [3.0, 1.0, 0.5]);
    let a = built("fixed_clamped", &clamped, &AssemblyOptions::default()).unwrap();
    let names: Vec<&str> = a.file.interface.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(names, ["column_on_ground", "column_on_ground_2"]);
    let top = a
        .contacts
        .iter()
        .find(|c| c.normal.z < 0.0)
        .expect("the beam's face");
    assert!(
        (top.normal + Vector3::z()).norm() < 1e-12,
        "{:?}",
        top.normal
    );
    for d in [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()] {
        let c = collapse_multiplier(&a.model, d, &StaticsOptions::default()).unwrap();
        assert_eq!(c.lambda, None, "{d:?}: {:?}", c.lambda);
    }

    let infill = "name = \"infill\"\nfixed = [\"pier\"]\n".to_string()
        + &box_body("pier", [-0.5, 0.0, 1.0], [1.0, 1.0, 2.0])
        + &box_body("block", [0.2, 0.0, 0.5], [0.4, 1.0, 1.0]);
    let a = built(
        "fixed_infill",
        &infill,
        &AssemblyOptions::default().with_all_contacts(),
    )
    .unwrap();
    let names: Vec<&str> = a.file.interface.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(names, ["block_on_ground", "block_on_ground_2"]);
    let side = a.contacts.iter().find(|c| !c.bed).expect("the pier's face");
    assert!(
        (side.normal - Vector3::x()).norm() < 1e-12,
        "{:?}",
        side.normal
    );
    assert!(side.corners.iter().all(|p| p.x.abs() < 1e-12));
    // The contacts report names the fixed block a ground contact rests against.
    let report = crr::output::assemble::contacts_text(&a);
    assert!(
        report.contains("ground (fixed pier) | block: side")
            && report.contains("ground | block: bed"),
        "{report}"
    );

    // A block under a fixed roof and on nothing else hangs: refused, naming it.
    let hanging = "name = \"hanging\"\nfixed = [\"roof\"]\n".to_string()
        + &box_body("roof", [0.0, 0.0, 2.25], [3.0, 1.0, 0.5])
        + &box_body("block", [0.0, 0.0, 1.5], [0.4, 0.4, 1.0]);
    let err = built(
        "fixed_hanging",
        &hanging,
        &AssemblyOptions::default().with_all_contacts(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("body \"block\": hangs: every contact of it pushes it down"),
        "{err}"
    );

    // The step of the stepped site as two overlapping fixed boxes (x from 0.5 to 1.5).
    let site = "name = \"overlapping\"\nfixed = [\"step_a\", \"step_b\"]\n".to_string()
        + &box_body("low", [-1.0, 0.0, 0.5], [0.4, 0.4, 1.0])
        + &box_body("step_a", [0.8, 0.0, 0.1], [0.6, 1.0, 0.8])
        + &box_body("step_b", [1.2, 0.0, 0.1], [0.6, 1.0, 0.8])
        + &box_body("high", [1.0, 0.0, 1.25], [0.3, 0.3, 1.5]);
    let a = built("fixed_overlapping", &site, &AssemblyOptions::default()).unwrap();
    assert_eq!(a.file.body.len(), 2);
    for d in [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()] {
        let l = lambda(&a.model, d);
        assert!((l - 0.2).abs() < 1e-9, "{d:?}: {l}");
    }
    let twice = site.replace(
        "[\"step_a\", \"step_b\"]",
        "[\"step_a\", \"step_b\", \"step_a\"]",
    );
    let path = common::write_model("fixed_twice", &twice);
    let err = read_assembly(&path).unwrap_err().to_string();
    assert!(
        err.contains("fixed: \"step_a\" is named twice (entries 1 and 3)"),
        "{err}"
    );

    // A footing fixed below the ground and two blocks 350 m up, one on the footing.
    let survey = "name = \"footing\"\nfixed = [\"footing\"]\n".to_string()
        + &box_body("footing", [0.0, 0.0, 349.0], [1.0, 1.0, 2.0])
        + &box_body("on_footing", [0.0, 0.0, 350.5], [0.4, 0.4, 1.0])
        + &box_body("on_ground", [3.0, 0.0, 350.5], [0.4, 0.4, 1.0]);
    let err = built("fixed_footing", &survey, &AssemblyOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("body \"on_ground\": rests on nothing")
            && err.contains("the lowest stands at z = 350.000000 m")
            && err.contains("--ground-level 350`"),
        "{err}"
    );
}

/// The OBJ text `obj` with every vertex turned by `tilt` about x, then by `bearing` about z,
/// written with `decimals` decimals (as CAD programs export, six by default in most).
fn obj_tilted_rounded(obj: &str, tilt: f64, bearing: f64, decimals: usize) -> String {
    let (st, ct) = tilt.sin_cos();
    let (sb, cb) = bearing.sin_cos();
    obj.lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(xyz) => {
                let c: Vec<f64> = xyz.split_whitespace().map(|t| t.parse().unwrap()).collect();
                let (x, y, z) = (c[0], ct * c[1] - st * c[2], st * c[1] + ct * c[2]);
                let (x, y) = (cb * x - sb * y, sb * x + cb * y);
                format!("v {x:.decimals$} {y:.decimals$} {z:.decimals$}")
            }
            None => line.to_string(),
        })
        .map(|line| line + "\n")
        .collect()
}

/// Rounded coordinates, as CAD programs export them: two stones 0.4 × 0.4 × 1 m on a fixed
/// slab, all tilted 5° and turned to a 30° bearing, written with six decimals (vertices up to
/// 0.87e-6 m off their faces' planes). The hull split their faces in pieces and the assembly
/// was refused ("meets … on more than one face", whatever the tolerance; an OBJ block "not
/// convex"); now it gives the model of the same stones written exactly (17 significant digits):
/// the same interfaces, corners within 2e-6 m, mass within 1e-5 and the multipliers within 1e-5
/// (the rounding over the stones' size) along the slope and across it.
#[test]
fn stones_with_rounded_coordinates_assemble_as_written_exactly() {
    let stones = box_obj("slab", [-1.0, -1.0, -0.5], [1.0, 1.0, 0.0], 1, None)
        + &box_obj("lower", [-0.2, -0.2, 0.0], [0.2, 0.2, 1.0], 9, None)
        + &box_obj("upper", [-0.2, -0.2, 1.0], [0.2, 0.2, 2.0], 17, None);
    let (tilt, bearing) = (5f64.to_radians(), std::f64::consts::FRAC_PI_6);
    let model = |tag: &str, decimals: usize| {
        let dir = common::scratch(tag);
        std::fs::write(
            dir.join("blocks.obj"),
            obj_tilted_rounded(&stones, tilt, bearing, decimals),
        )
        .unwrap();
        let path = dir.join("assembly.toml");
        std::fs::write(
            &path,
            format!(
                "name = \"{tag}\"\nfixed = [\"slab\"]\n[[obj]]\nfile = \"blocks.obj\"\n\
                 density = 2000.0\n"
            ),
        )
        .unwrap();
        let file = read_assembly(&path).unwrap_or_else(|e| panic!("{tag}: {e}"));
        // The ground far below: the stones stand on the tilted slab only.
        let options = AssemblyOptions {
            ground_level: -10.0,
            ..Default::default()
        };
        assemble(&path, &file, &options).unwrap_or_else(|e| panic!("{tag}: {e}"))
    };
    let exact = model("obj_rounded_exact", 17);
    let rounded = model("obj_rounded_6", 6);
    assert_eq!(exact.model.interfaces.len(), 2);
    let names = |a: &crr::analysis::assemble::Assembled| -> Vec<String> {
        a.file.interface.iter().map(|i| i.name.clone()).collect()
    };
    assert_eq!(names(&exact), names(&rounded));
    for (e, r) in exact.file.interface.iter().zip(&rounded.file.interface) {
        let (ce, cr) = (
            &e.rocking_base.as_ref().unwrap().corners,
            &r.rocking_base.as_ref().unwrap().corners,
        );
        for (p, q) in ce.iter().zip(cr) {
            let d = (Vector3::from(*p) - Vector3::from(*q)).norm();
            assert!(d < 2e-6, "{}: {p:?} {q:?}", e.name);
        }
    }
    let (me, mr) = (exact.model.total_mass(), rounded.model.total_mass());
    assert!((me - mr).abs() < 1e-5 * me, "{me} {mr}");
    let down_slope = Vector3::new(-bearing.sin(), bearing.cos(), 0.0);
    let along = Vector3::new(bearing.cos(), bearing.sin(), 0.0);
    for d in [down_slope, -down_slope, along, -along] {
        let (le, lr) = (lambda(&exact.model, d), lambda(&rounded.model, d));
        assert!((le - lr).abs() < 1e-5 * le, "{d:?}: {le} {lr}");
    }
    // Along the beds' horizontal edges the column rocks whole on a base edge when the line of
    // gravity plus the load, from the centre of mass 1 m up the column's axis, leaves the bed
    // through that edge: x = λ/cos 5° reaches b = 0.2 (across, it meets the bed at
    // tan 5° = 0.087 < 0.2), λ = 0.2 cos 5°.
    for d in [along, -along] {
        let l = lambda(&exact.model, d);
        assert!((l - 0.2 * tilt.cos()).abs() < 1e-9, "{l}");
    }
}

/// A stone seated askew by 0.01° on another (1e-4 m of gap across its 0.6 m, as a survey or a
/// scan gives) touches it within a tolerance of 2e-4 m, and the column of two 0.6 × 0.6 × 1 m
/// stones then rocks whole at λ = b/h = 0.3 (to the 1e-4 the askew seat moves the upper
/// centre); faces opposite to 1e-9 only were required, whatever the tolerance.
#[test]
fn a_stone_seated_askew_touches_within_the_tolerance() {
    let text = "name = \"askew\"\n\n[[body]]\nname = \"lower\"\ndensity = 2000.0\n\
                box = { center = [0.0, 0.0, 0.5], size = [0.6, 0.6, 1.0] }\n\n[[body]]\n\
                name = \"upper\"\ndensity = 2000.0\n\
                box = { center = [0.0, 0.0, 1.50006], size = [0.6, 0.6, 1.0], rotation = [0.0, 0.00017453292519943296, 0.0] }\n";
    let path = common::write_model("assemble_askew", text);
    let file = read_assembly(&path).unwrap();
    let strict = assemble(&path, &file, &AssemblyOptions::default());
    assert!(strict.is_err(), "touched within 1e-6 m");
    let options = AssemblyOptions {
        tolerance: 2e-4,
        ..Default::default()
    };
    let a = assemble(&path, &file, &options).unwrap();
    assert_eq!(a.model.interfaces.len(), 2);
    for d in [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()] {
        let l = lambda(&a.model, d);
        assert!((l - 0.3).abs() < 1e-4, "{d:?}: {l}");
    }
}

/// A drawing's slip: the bundled trilithon of stones with its right column 0.5 mm short
/// (3.9995 m, centred 0.25 mm lower) is written with the architrave on the left column alone;
/// `crr assemble` now warns that the architrave's bed faces the column's top 5e-4 m away and
/// gives the tolerance that joins them, with which the four joints of the frame come back and
/// no warning. A block resting on nothing is told how far below its bed the nearest face lies.
#[test]
fn a_column_drawn_short_is_a_near_miss_with_the_tolerance_that_joins_it() {
    let source =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assemblies/trilithon.toml");
    let text = std::fs::read_to_string(source).unwrap();
    let old = "box = { center = [1.5, 0.0, 2.0], size = [0.5, 0.5, 4.0] }";
    assert!(text.contains(old));
    let short = text
        .replace(
            old,
            "box = { center = [1.5, 0.0, 1.99975], size = [0.5, 0.5, 3.9995] }",
        )
        .replace("../records/", "/no/records/");
    let path = common::write_model("assemble_short_column", &short);
    let run = |extra: &[&str]| {
        let out = path.with_file_name(format!("model{}.toml", extra.len()));
        let mut args = vec![
            "assemble",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--force",
        ];
        args.extend_from_slice(extra);
        let o = common::crr(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let written = std::fs::read_to_string(&out).unwrap();
        (
            String::from_utf8_lossy(&o.stderr).to_string(),
            written.matches("[[interface]]").count(),
        )
    };
    let (err, interfaces) = run(&[]);
    assert_eq!(interfaces, 3, "{err}");
    assert!(
        err.contains(
            "blocks \"column_right\" and \"architrave\" have faces facing each other 5.000e-4 m \
             apart, more than the tolerance (0.000001 m)"
        ) && err.contains("`--tolerance 5.50e-4` makes it one"),
        "{err}"
    );
    let (err, interfaces) = run(&["--tolerance", "5.5e-4"]);
    assert_eq!(interfaces, 4, "{err}");
    assert!(!err.contains("warning"), "{err}");
    // The architrave 1 mm above both columns rests on nothing, 1e-3 m above them.
    let floating = text.replace("center = [0.0, 0.0, 4.3]", "center = [0.0, 0.0, 4.301]");
    let path = common::write_model("assemble_floating_architrave", &floating);
    let o = common::crr(&["assemble", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("body \"architrave\": rests on nothing")
            && err.contains(
                "the nearest face under it is 1.000e-3 m below its bed (on \"column_left\")"
            ),
        "{err}"
    );
}

/// What squaring and merging must not do (a review of the rounded-geometry change): a stele
/// whose bed is a trapezoid (1.0 m wide at one end, 0.6 m at the other) is still refused as no
/// rectangle (squared, it was written as a rectangle reaching 0.2 m beyond its footprint, and
/// its multiplier along +x was 0.533 where its inscribed rectangle gives 0.454); and a portal
/// cut from one stone, its legs on two fixed pads and a free sill on the ground flush with them
/// in the doorway, rests on the pads alone (on the hull of its feet, as a block on two fixed
/// slabs does) and the sill on the ground: no contact between the portal and the sill (its
/// legs' feet, in one plane but apart, were merged into one face, and the sill became a
/// support of the portal where the portal has no stone: a third interface and a loop).
#[test]
fn squaring_and_merging_keep_to_pieces_of_one_rectangle() {
    let trapezoid = "name = \"trap\"\n[[body]]\nname = \"stele\"\ndensity = 2400.0\n\
        polyhedron = { vertices = [[-0.5, -0.3, 0.0], [0.5, -0.3, 0.0], [0.3, 0.3, 0.0], \
        [-0.3, 0.3, 0.0], [-0.5, -0.3, 1.5], [0.5, -0.3, 1.5], [0.3, 0.3, 1.5], [-0.3, 0.3, 1.5]] }\n";
    let path = common::write_model("assemble_trapezoid", trapezoid);
    let file = read_assembly(&path).unwrap();
    let err = assemble(&path, &file, &AssemblyOptions::default())
        .expect_err("a trapezoid is no rectangle")
        .to_string();
    assert!(
        err.contains("polygon of 4 corners, not a rectangle"),
        "{err}"
    );
    let portal = "name = \"portal\"\nfixed = [\"pad_left\", \"pad_right\"]\n\
        [[body]]\nname = \"pad_left\"\ndensity = 2400.0\nbox = { center = [-0.8, 0.0, -0.3], size = [0.4, 0.5, 0.6] }\n\
        [[body]]\nname = \"pad_right\"\ndensity = 2400.0\nbox = { center = [0.8, 0.0, -0.3], size = [0.4, 0.5, 0.6] }\n\
        [[body]]\nname = \"sill\"\ndensity = 2400.0\nbox = { center = [0.0, 0.0, -0.15], size = [1.2, 0.5, 0.3] }\n\
        [[body]]\nname = \"portal\"\ndensity = 2400.0\nprism = { polygon = [[-1.0, -0.25, 0.0], \
        [-0.6, -0.25, 0.0], [-0.6, -0.25, 1.5], [0.6, -0.25, 1.5], [0.6, -0.25, 0.0], \
        [1.0, -0.25, 0.0], [1.0, -0.25, 2.0], [-1.0, -0.25, 2.0]], extrude = [0.0, 0.5, 0.0] }\n";
    let path = common::write_model("assemble_portal", portal);
    let file = read_assembly(&path).unwrap();
    let options = AssemblyOptions {
        ground_level: -0.3,
        ..Default::default()
    };
    let a = assemble(&path, &file, &options).unwrap();
    let mut names: Vec<&str> = a.file.interface.iter().map(|i| i.name.as_str()).collect();
    names.sort();
    assert_eq!(names, ["portal_on_ground", "sill_on_ground"]);
    assert!(a.model.closures.is_empty());
    let (sill, portal) = (2, 3);
    let between = |c: &crr::kinematics::assembly::ContactFace| {
        (c.upper == portal && c.lower == Some(sill)) || (c.upper == sill && c.lower == Some(portal))
    };
    assert!(!a.contacts.iter().any(between), "{:?}", a.contacts);
}
