//! Every invalid model description gives a `ModelError` naming the item and the problem (never a
//! panic). Each case edits a valid block model in one place.

use crr_kinematics::{Model, ModelError, StructureSpec};

const BLOCK: &str = r#"
name = "block"
[[body]]
name = "block"
density = 2500.0
box = { center = [0.0, 0.0, 1.0], size = [0.5, 0.5, 2.0] }
[[interface]]
name = "base"
parent = "ground"
child = "block"
axis = [0.0, 1.0, 0.0]
pivot_positive = [0.25, 0.0, 0.0]
pivot_negative = [-0.25, 0.0, 0.0]
"#;

fn build(toml_text: &str) -> Result<Model, ModelError> {
    let spec: StructureSpec = toml::from_str(toml_text).expect("the TOML itself parses");
    Model::from_spec(&spec)
}

/// Replaces `from` (which must occur) in the valid block model and returns the error.
fn error_with(from: &str, to: &str) -> ModelError {
    assert!(BLOCK.contains(from), "test edits text that exists: {from}");
    build(&BLOCK.replacen(from, to, 1)).expect_err("the edited model is invalid")
}

fn assert_mentions(e: &ModelError, item: &str, words: &[&str]) {
    let text = e.to_string();
    assert!(
        e.item.contains(item),
        "item {:?} should name {item:?}; message: {text}",
        e.item
    );
    for w in words {
        assert!(text.contains(w), "message should contain {w:?}: {text}");
    }
}

#[test]
fn the_unedited_block_is_valid() {
    let m = build(BLOCK).unwrap();
    assert_eq!(m.dof(), 1);
    // m = ρ V = 2500 × 0.5 × 0.5 × 2.
    assert!((m.bodies[0].mass - 1250.0).abs() < 1e-9);
}

#[test]
fn unknown_parent_and_child() {
    assert_mentions(
        &error_with("parent = \"ground\"", "parent = \"gound\""),
        "interface \"base\" (parent)",
        &["gound"],
    );
    assert_mentions(
        &error_with("child = \"block\"", "child = \"blok\""),
        "interface \"base\" (child)",
        &["blok"],
    );
}

#[test]
fn ground_as_child_is_explained() {
    assert_mentions(
        &error_with("child = \"block\"", "child = \"ground\""),
        "interface \"base\"",
        &["parent"],
    );
}

#[test]
fn duplicate_names() {
    let text = format!(
        "{BLOCK}\n[[body]]\nname = \"block\"\ndensity = 1.0\nbox = {{ center = [0.0, 0.0, 3.0], size = [1.0, 1.0, 1.0] }}\n"
    );
    assert_mentions(
        &build(&text).unwrap_err(),
        "body \"block\"",
        &["two bodies"],
    );
    let text = format!(
        "{BLOCK}\n[[interface]]\nname = \"base\"\nparent = \"ground\"\nchild = \"block\"\naxis = [0.0, 1.0, 0.0]\npivot_positive = [0.25, 0.0, 0.0]\npivot_negative = [-0.25, 0.0, 0.0]\n"
    );
    assert_mentions(
        &build(&text).unwrap_err(),
        "interface \"base\"",
        &["two interfaces"],
    );
}

#[test]
fn reserved_body_name() {
    let e = build(&BLOCK.replace("name = \"block\"", "name = \"ground\"")).unwrap_err();
    assert_mentions(&e, "body \"ground\"", &["reserved"]);
}

#[test]
fn zero_axis() {
    assert_mentions(
        &error_with("axis = [0.0, 1.0, 0.0]", "axis = [0.0, 0.0, 0.0]"),
        "interface \"base\" (axis)",
        &["zero"],
    );
}

#[test]
fn pivot_edge_not_parallel_to_axis() {
    let e = error_with(
        "pivot_positive = [0.25, 0.0, 0.0]",
        "pivot_positive = [[0.25, -0.25, 0.0], [0.25, 0.25, 0.01]]",
    );
    assert_mentions(
        &e,
        "interface \"base\" (pivot_positive)",
        &["not parallel", "°"],
    );
    // A parallel edge is accepted and equals the point form.
    let ok = build(&BLOCK.replace(
        "pivot_positive = [0.25, 0.0, 0.0]",
        "pivot_positive = [[0.25, -0.25, 0.0], [0.25, 0.25, 0.0]]",
    ));
    assert!(ok.is_ok());
}

#[test]
fn swapped_pivots_are_explained() {
    let swapped = BLOCK
        .replace(
            "pivot_positive = [0.25, 0.0, 0.0]",
            "pivot_positive = [-0.25, 0.0, 0.0]",
        )
        .replace(
            "pivot_negative = [-0.25, 0.0, 0.0]",
            "pivot_negative = [0.25, 0.0, 0.0]",
        );
    assert_mentions(
        &build(&swapped).unwrap_err(),
        "interface \"base\"",
        &["pivots swapped", "exchange"],
    );
    // Reversing the axis instead makes the swapped pair right again.
    let reversed = swapped.replace("axis = [0.0, 1.0, 0.0]", "axis = [0.0, -1.0, 0.0]");
    assert!(build(&reversed).is_ok());
}

#[test]
fn non_positive_density_and_mass() {
    assert_mentions(
        &error_with("density = 2500.0", "density = -1.0"),
        "body \"block\"",
        &["density", "-1"],
    );
    assert_mentions(
        &error_with("density = 2500.0", "density = 0.0"),
        "body \"block\"",
        &["density"],
    );
    assert_mentions(
        &error_with("density = 2500.0", "mass = 0.0"),
        "body \"block\"",
        &["mass"],
    );
    assert_mentions(
        &error_with("density = 2500.0\n", ""),
        "body \"block\"",
        &["density", "mass"],
    );
}

#[test]
fn mass_overrides_density() {
    let m = build(&BLOCK.replace("density = 2500.0", "density = 2500.0\nmass = 1000.0")).unwrap();
    let b = &m.bodies[0];
    assert!((b.mass - 1000.0).abs() < 1e-12);
    // The inertia follows the given mass: I_yy = m (w² + h²)/12.
    assert!((b.inertia[(1, 1)] - 1000.0 * (0.25 + 4.0) / 12.0).abs() < 1e-9);
}

#[test]
fn degenerate_shapes() {
    assert_mentions(
        &error_with("size = [0.5, 0.5, 2.0]", "size = [0.5, 0.0, 2.0]"),
        "body \"block\" (box)",
        &[],
    );
    let sector = r#"annular_sector = { center = [0.0, 0.0, 0.0], axis = [0.0, 1.0, 0.0], inner_radius = 2.0, outer_radius = 1.5, start = [1.0, 0.0, 0.0], from_angle = 0.0, to_angle = 1.0, thickness = 0.5 }"#;
    let e = error_with(
        "box = { center = [0.0, 0.0, 1.0], size = [0.5, 0.5, 2.0] }",
        sector,
    );
    assert_mentions(&e, "body \"block\" (annular_sector)", &["inner"]);
    let prism = r#"prism = { polygon = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.5], [0.0, 1.0, 0.0]], extrude = [0.0, 0.0, 1.0] }"#;
    let e = error_with(
        "box = { center = [0.0, 0.0, 1.0], size = [0.5, 0.5, 2.0] }",
        prism,
    );
    assert_mentions(&e, "body \"block\" (prism)", &["planar"]);
}

#[test]
fn no_shape_or_two_shapes() {
    assert_mentions(
        &error_with(
            "box = { center = [0.0, 0.0, 1.0], size = [0.5, 0.5, 2.0] }",
            "",
        ),
        "body \"block\"",
        &["no shape"],
    );
    let two = "box = { center = [0.0, 0.0, 1.0], size = [0.5, 0.5, 2.0] }\npolyhedron = { vertices = [[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0],[0.0,0.0,1.0]] }";
    assert_mentions(
        &error_with(
            "box = { center = [0.0, 0.0, 1.0], size = [0.5, 0.5, 2.0] }",
            two,
        ),
        "body \"block\"",
        &["2 shapes", "box", "polyhedron"],
    );
}

#[test]
fn nan_and_infinite_numbers() {
    assert_mentions(
        &error_with(
            "pivot_positive = [0.25, 0.0, 0.0]",
            "pivot_positive = [nan, 0.0, 0.0]",
        ),
        "interface \"base\"",
        &["NaN"],
    );
    assert_mentions(
        &error_with("axis = [0.0, 1.0, 0.0]", "axis = [0.0, inf, 0.0]"),
        "interface \"base\"",
        &["infinite"],
    );
    assert_mentions(
        &error_with("density = 2500.0", "density = nan"),
        "body \"block\"",
        &["density"],
    );
    let e = build(&format!("gravity = -9.81\n{BLOCK}")).unwrap_err();
    assert_mentions(&e, "gravity", &["positive"]);
}

#[test]
fn unreachable_body() {
    let text = format!(
        "{BLOCK}\n[[body]]\nname = \"loose\"\ndensity = 1.0\nbox = {{ center = [3.0, 0.0, 0.5], size = [1.0, 1.0, 1.0] }}\n"
    );
    assert_mentions(
        &build(&text).unwrap_err(),
        "body \"loose\"",
        &["no path from the ground"],
    );
}

#[test]
fn interface_joining_a_body_to_itself() {
    assert_mentions(
        &error_with("parent = \"ground\"", "parent = \"block\""),
        "interface \"base\"",
        &["itself"],
    );
}

#[test]
fn rocking_base_problems() {
    let hinge = "axis = [0.0, 1.0, 0.0]\npivot_positive = [0.25, 0.0, 0.0]\npivot_negative = [-0.25, 0.0, 0.0]";
    let rb = |c: &str| format!("rocking_base = {{ corners = {c} }}");
    let good =
        rb("[[-0.25, -0.25, 0.0], [0.25, -0.25, 0.0], [0.25, 0.25, 0.0], [-0.25, 0.25, 0.0]]");
    let m = build(&BLOCK.replace(hinge, &good)).unwrap();
    assert_eq!(m.dof(), 2);
    let not_rect =
        rb("[[-0.25, -0.25, 0.0], [0.25, -0.25, 0.0], [0.3, 0.25, 0.0], [-0.25, 0.25, 0.0]]");
    assert_mentions(
        &build(&BLOCK.replace(hinge, &not_rect)).unwrap_err(),
        "interface \"base\" (rocking_base.corners)",
        &["rectangle"],
    );
    let three = rb("[[-0.25, -0.25, 0.0], [0.25, -0.25, 0.0], [0.25, 0.25, 0.0]]");
    assert_mentions(
        &build(&BLOCK.replace(hinge, &three)).unwrap_err(),
        "rocking_base.corners",
        &["4 corners"],
    );
    let bent =
        rb("[[-0.25, -0.25, 0.0], [0.25, -0.25, 0.0], [0.25, 0.25, 0.0], [-0.25, 0.25, 0.1]]");
    assert_mentions(
        &build(&BLOCK.replace(hinge, &bent)).unwrap_err(),
        "rocking_base.corners",
        &["coplanar"],
    );
    let both = format!("{good}\naxis = [0.0, 1.0, 0.0]");
    assert_mentions(
        &build(&BLOCK.replace(hinge, &both)).unwrap_err(),
        "interface \"base\"",
        &["remove axis"],
    );
}

#[test]
fn impact_law_parameters() {
    let ok = build(&BLOCK.replace(
        "child = \"block\"",
        "child = \"block\"\nimpact = { dirac = { r = 0.9, c = 1.0 } }",
    ))
    .unwrap();
    assert!(matches!(
        ok.interfaces[0].impact,
        crr_kinematics::ImpactLaw::Dirac { .. }
    ));
    let e = build(&BLOCK.replace(
        "child = \"block\"",
        "child = \"block\"\nimpact = { restitution = 1.5 }",
    ))
    .unwrap_err();
    assert_mentions(&e, "interface \"base\" (impact)", &["(0, 1]", "1.5"]);
}

#[test]
fn unknown_fields_are_rejected_by_the_parser() {
    let e = toml::from_str::<StructureSpec>(&BLOCK.replace("density = 2500.0", "densty = 2500.0"))
        .unwrap_err();
    assert!(e.to_string().contains("densty"), "{e}");
}

/// Models beyond `MAX_COORDINATES` are refused naming the model and the count: by their number
/// of bodies before any per-body work (10 000 blocks), and by their coordinates once counted
/// (1 025 blocks on rocking bases have two tilts each: 2 050 coordinates). One under the limit
/// (1 024 blocks, 2 048 coordinates) builds.
#[test]
fn models_beyond_the_dense_size_are_refused() {
    use crr_kinematics::MAX_COORDINATES;
    use crr_kinematics::fixtures::{box_body, rocking_base};
    let blocks = |n: usize| StructureSpec {
        name: format!("field_{n}"),
        gravity: 9.81,
        body: (0..n)
            .map(|i| {
                box_body(
                    &format!("b{i}"),
                    2500.0,
                    [3.0 * i as f64, 0.0, 1.0],
                    [0.4, 0.4, 2.0],
                )
            })
            .collect(),
        interface: (0..n)
            .map(|i| {
                let x = 3.0 * i as f64;
                rocking_base(
                    &format!("base{i}"),
                    "ground",
                    &format!("b{i}"),
                    [
                        [x - 0.2, -0.2, 0.0],
                        [x + 0.2, -0.2, 0.0],
                        [x + 0.2, 0.2, 0.0],
                        [x - 0.2, 0.2, 0.0],
                    ],
                )
            })
            .collect(),
        symmetry: Vec::new(),
    };
    let e = Model::from_spec(&blocks(10_000)).expect_err("10 000 bodies");
    assert_eq!(e.item, "model \"field_10000\"");
    assert!(
        e.problem.contains("at least 10000 coordinates"),
        "{}",
        e.problem
    );
    let e = Model::from_spec(&blocks(1025)).expect_err("2 050 coordinates");
    assert!(
        e.problem.contains("DOF(1) = 2050 coordinates"),
        "{}",
        e.problem
    );
    assert!(e.problem.contains(&MAX_COORDINATES.to_string()));
    let model = Model::from_spec(&blocks(1024)).expect("2 048 coordinates build");
    assert_eq!(model.dof(), MAX_COORDINATES);
}

/// An interface's `normal` says which side of its face is the child's. It is refused where it
/// is not the face's normal within 1° (a hinge: across its axis, and normal to the face through
/// its pivot lines), zero or not finite, or where it points away from a convex child's centre
/// (a box lies wholly on its centre's side); a normal off by the rounding of a face's corners
/// (1e-5 rad) is the face's. With a normal along the hinge's lift the block is the same model as
/// without it, and pointing the other way the pivots are "swapped" against the normal.
#[test]
fn a_given_normal_is_the_face_s_within_a_degree() {
    let with = |normal: &str| {
        build(&BLOCK.replacen(
            "pivot_negative = [-0.25, 0.0, 0.0]",
            &format!("pivot_negative = [-0.25, 0.0, 0.0]\nnormal = {normal}"),
            1,
        ))
    };
    let plain = build(BLOCK).unwrap();
    assert_eq!(
        with("[0.0, 0.0, 2.0]").unwrap().interfaces,
        plain.interfaces
    );
    assert_eq!(
        with("[1e-5, 0.0, 1.0]").unwrap().interfaces,
        plain.interfaces
    );
    let e = with("[0.0, 0.0, -1.0]").unwrap_err();
    assert_mentions(
        &e,
        "base",
        &["points away from the centre of mass", "convex"],
    );
    let e = with("[0.0, 1.0, 0.02]").unwrap_err();
    assert_mentions(
        &e,
        "base",
        &["is not perpendicular to the axis", "makes 1.1458° with it"],
    );
    let e = with("[0.05, 0.0, 1.0]").unwrap_err();
    assert_mentions(
        &e,
        "base",
        &["is not the normal of the joint face", "2.8624°"],
    );
    let e = with("[0.0, 0.0, 0.0]").unwrap_err();
    assert_mentions(&e, "base", &["the zero vector"]);
    let e = with("[0.0, nan, 1.0]").unwrap_err();
    assert_mentions(&e, "base", &["normal"]);
    // A rocking base: the corners' plane, z = 0.
    let base = BLOCK.replacen(
        "axis = [0.0, 1.0, 0.0]\npivot_positive = [0.25, 0.0, 0.0]\npivot_negative = [-0.25, 0.0, 0.0]",
        "rocking_base = { corners = [[-0.25, -0.25, 0.0], [0.25, -0.25, 0.0], [0.25, 0.25, 0.0], [-0.25, 0.25, 0.0]] }",
        1,
    );
    let plain = build(&base).unwrap();
    let with = |normal: &str| build(&format!("{base}normal = {normal}\n"));
    assert_eq!(
        with("[0.0, 0.0, 1.0]").unwrap().interfaces,
        plain.interfaces
    );
    let e = with("[1.0, 0.0, 0.0]").unwrap_err();
    assert_mentions(
        &e,
        "base",
        &["is not the normal of the contact plane", "90.0000° from it"],
    );
}
