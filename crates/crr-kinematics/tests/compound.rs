//! Compound bodies (`[[body.block]]`): a rigid domain's mass properties are the exact sums of its
//! blocks'. Checked against closed forms written here (a box's mass and inertia, the
//! parallel-axis theorem), not against the engine's summation; and every invalid compound body
//! is refused by name.

use crr_kinematics::{Body, Model, StructureSpec};
use nalgebra::{Matrix3, Vector3};

fn build(toml_text: &str) -> Result<Model, crr_kinematics::ModelError> {
    let spec: StructureSpec = toml::from_str(toml_text).expect("the TOML itself parses");
    Model::from_spec(&spec)
}

/// A body named `pier` standing on the ground on a hinge about y at x = ±`half`, with the given
/// `[[body]]` text.
fn pier(body: &str, half: f64) -> String {
    format!(
        r#"
name = "compound"
{body}
[[interface]]
name = "base"
parent = "ground"
child = "pier"
axis = [0.0, 1.0, 0.0]
pivot_positive = [{half}, 0.0, 0.0]
pivot_negative = [-{half}, 0.0, 0.0]
"#
    )
}

/// Closed form of a box a × b × c of density ρ centred at `c0`: its mass, centre and inertia
/// about the centre, m/12 diag(b² + c², a² + c², a² + b²).
fn box_closed_form(rho: f64, size: [f64; 3], c0: [f64; 3]) -> (f64, Vector3<f64>, Matrix3<f64>) {
    let [a, b, c] = size;
    let m = rho * a * b * c;
    let i = Matrix3::from_diagonal(&Vector3::new(b * b + c * c, a * a + c * c, a * a + b * b))
        * (m / 12.0);
    (m, Vector3::from(c0), i)
}

/// The inertia of a point-mass offset d from the centre: m (|d|² 1 − d dᵀ) (parallel axes).
fn steiner(m: f64, d: Vector3<f64>) -> Matrix3<f64> {
    (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * m
}

fn assert_body(b: &Body, m: f64, c: Vector3<f64>, i: Matrix3<f64>) {
    // Sums of a few terms of size m, m·L, m·L²: 1e-12 relative is ten times their round-off.
    assert!((b.mass - m).abs() <= 1e-12 * m, "mass {} vs {m}", b.mass);
    let size = c.norm().max(1.0);
    assert!(
        (b.com - c).norm() <= 1e-12 * size,
        "centre {:?} vs {c:?}",
        b.com
    );
    let scale = i.norm();
    assert!(
        (b.inertia - i).norm() <= 1e-12 * scale,
        "inertia {:?} vs {i:?}",
        b.inertia
    );
}

#[test]
fn a_box_cut_in_two_blocks_has_the_whole_box_mass_properties() {
    // A 0.4 × 0.6 × 2.0 m pier cut at z = 1.2 m: the two blocks as one compound body.
    let text = pier(
        r#"
[[body]]
name = "pier"
density = 2400.0
[[body.block]]
name = "lower"
box = { center = [0.1, 0.0, 0.6], size = [0.4, 0.6, 1.2] }
[[body.block]]
name = "upper"
box = { center = [0.1, 0.0, 1.6], size = [0.4, 0.6, 0.8] }
"#,
        0.1,
    );
    let model = build(&text).expect("a valid compound body");
    let (m, c, i) = box_closed_form(2400.0, [0.4, 0.6, 2.0], [0.1, 0.0, 1.0]);
    let body = &model.bodies[0];
    assert_body(body, m, c, i);
    assert!((body.volume - 0.48).abs() < 1e-15);
    assert!((body.density - 2400.0).abs() < 1e-12);
    assert_eq!(body.shape.kind(), "compound");
    // Its surface is the union of the two blocks' (12 faces) and encloses the whole volume.
    let surface = body.shape.surface().expect("boxes have surfaces");
    assert_eq!(surface.face_count(), 12);
    let (v, centroid) = surface.volume_centroid();
    assert!((v - 0.48).abs() < 1e-14 && (centroid - c).norm() < 1e-14);
}

#[test]
fn blocks_of_two_densities_sum_by_the_parallel_axis_theorem() {
    // A plinth of 1 × 1 × 0.5 m at ρ = 2400 and a shaft of 0.6 × 0.6 × 2 m at ρ = 2600 on it.
    let text = pier(
        r#"
[[body]]
name = "pier"
density = 2400.0
[[body.block]]
box = { center = [0.0, 0.0, 0.25], size = [1.0, 1.0, 0.5] }
[[body.block]]
density = 2600.0
box = { center = [0.0, 0.0, 1.5], size = [0.6, 0.6, 2.0] }
"#,
        0.5,
    );
    let model = build(&text).expect("a valid compound body");
    let (m1, c1, i1) = box_closed_form(2400.0, [1.0, 1.0, 0.5], [0.0, 0.0, 0.25]);
    let (m2, c2, i2) = box_closed_form(2600.0, [0.6, 0.6, 2.0], [0.0, 0.0, 1.5]);
    let m = m1 + m2;
    let c = (c1 * m1 + c2 * m2) / m;
    let i = i1 + steiner(m1, c1 - c) + i2 + steiner(m2, c2 - c);
    assert_body(&model.bodies[0], m, c, i);
    // Hand values: m = 1200 + 1872 = 3072 kg, z_c = (1200·0.25 + 1872·1.5)/3072 = 1.01172 m.
    assert!((m - 3072.0).abs() < 1e-9);
    assert!((c.z - 3108.0 / 3072.0).abs() < 1e-12);
}

#[test]
fn a_compound_of_other_shapes_equals_the_sum_of_the_same_blocks_as_bodies() {
    // A voussoir and a prism as one body, against the two as separate bodies of another model
    // (each body's closed forms), summed here by the parallel-axis theorem.
    let sector = r#"annular_sector = { center = [0.0, 0.0, 0.0], axis = [0.0, -1.0, 0.0], inner_radius = 2.0, outer_radius = 2.5, start = [1.0, 0.0, 0.0], from_angle = 0.0, to_angle = 0.3, thickness = 1.0 }"#;
    let prism = r#"prism = { polygon = [[3.0, -0.5, 0.0], [3.5, -0.5, 0.0], [3.4, -0.5, 0.4], [3.1, -0.5, 0.4]], extrude = [0.0, 1.0, 0.0] }"#;
    let compound = build(&pier(
        &format!(
            "[[body]]\nname = \"pier\"\nmass = 5000.0\n[[body.block]]\n{sector}\n[[body.block]]\n{prism}\n"
        ),
        2.25,
    ))
    .expect("a valid compound body");
    let separate = build(&format!(
        r#"
name = "separate"
[[body]]
name = "pier"
density = 1.0
{sector}
[[body]]
name = "foot"
density = 1.0
{prism}
[[interface]]
name = "base"
parent = "ground"
child = "pier"
axis = [0.0, 1.0, 0.0]
pivot_positive = [2.5, 0.0, 0.0]
pivot_negative = [2.0, 0.0, 0.0]
[[interface]]
name = "foot_on_ground"
parent = "ground"
child = "foot"
axis = [0.0, 1.0, 0.0]
pivot_positive = [3.5, 0.0, 0.0]
pivot_negative = [3.0, 0.0, 0.0]
"#
    ))
    .expect("the blocks as bodies");
    let (a, b) = (&separate.bodies[0], &separate.bodies[1]);
    // A given mass is spread at one density over the volume.
    let rho = 5000.0 / (a.volume + b.volume);
    let (ma, mb) = (a.mass * rho, b.mass * rho);
    let c = (a.com * ma + b.com * mb) / (ma + mb);
    let i = a.inertia * rho + steiner(ma, a.com - c) + b.inertia * rho + steiner(mb, b.com - c);
    assert_body(&compound.bodies[0], 5000.0, c, i);
}

#[test]
fn invalid_compound_bodies_are_refused_by_name() {
    let cases = [
        (
            "[[body]]\nname = \"pier\"\ndensity = 2400.0\nbox = { center = [0.0, 0.0, 0.5], size = [0.2, 0.2, 1.0] }\n[[body.block]]\nbox = { center = [0.0, 0.0, 1.5], size = [0.2, 0.2, 1.0] }\n",
            "has blocks and a shape of its own (box)",
        ),
        (
            "[[body]]\nname = \"pier\"\ndensity = 2400.0\n[[body.block]]\nbox = { center = [0.0, 0.0, 0.5], size = [0.2, 0.2, 1.0] }\n[[body.block]]\n",
            "has in block 2 no shape",
        ),
        (
            "[[body]]\nname = \"pier\"\n[[body.block]]\ndensity = 2400.0\nbox = { center = [0.0, 0.0, 0.5], size = [0.2, 0.2, 1.0] }\n[[body.block]]\nbox = { center = [0.0, 0.0, 1.5], size = [0.2, 0.2, 1.0] }\n",
            "block 2 needs a density",
        ),
        (
            "[[body]]\nname = \"pier\"\nmass = 100.0\n[[body.block]]\ndensity = 2400.0\nbox = { center = [0.0, 0.0, 0.5], size = [0.2, 0.2, 1.0] }\n",
            "gives a mass and block 1 a density",
        ),
        (
            "[[body]]\nname = \"pier\"\ndensity = 2400.0\n[[body.block]]\ndensity = -1.0\nbox = { center = [0.0, 0.0, 0.5], size = [0.2, 0.2, 1.0] }\n",
            "the density of block 1 must be a positive number",
        ),
        (
            "[[body]]\nname = \"pier\"\ndensity = 2400.0\n[[body.block]]\nbox = { center = [0.0, 0.0, 0.5], size = [0.2, -0.2, 1.0] }\n",
            "box size must be positive",
        ),
    ];
    for (body, words) in cases {
        let e = build(&pier(body, 0.1)).expect_err("an invalid compound body");
        assert!(e.item.contains("body \"pier\""), "{e}");
        assert!(e.to_string().contains(words), "{e} should say {words:?}");
    }
}

#[test]
fn a_compound_body_written_back_reads_the_same() {
    let text = pier(
        r#"
[[body]]
name = "pier"
density = 2400.0
[[body.block]]
name = "lower"
box = { center = [0.1, 0.0, 0.6], size = [0.4, 0.6, 1.2] }
[[body.block]]
density = 2000.0
box = { center = [0.1, 0.0, 1.6], size = [0.4, 0.6, 0.8] }
"#,
        0.1,
    );
    let spec: StructureSpec = toml::from_str(&text).unwrap();
    let again: StructureSpec = toml::from_str(&toml::to_string(&spec).unwrap()).unwrap();
    assert_eq!(spec, again);
    let json: StructureSpec = serde_json::from_str(&serde_json::to_string(&spec).unwrap()).unwrap();
    assert_eq!(spec, json);
}

/// A bridge-shaped rigid domain (two legs 1 m wide at the ends of a 10 m lintel) standing on a
/// plinth, with a plug of the domain set in a notch of the plinth under its middle: the legs'
/// beds, written as one interface on their convex hull (as `crr assemble` writes coplanar faces
/// of two domains), have their centre at x = 5, on the plug's top face, across the bed's plane
/// from the rest of the domain. The child lies above the bed, so its normal points up (+z), as
/// it does for the same domain without the plug; taken from the part at the hull's centre it
/// pointed down into the plinth (the rule until 2026-12-04).
#[test]
fn a_bed_on_the_hull_of_two_legs_faces_the_legs_not_a_part_under_its_centre() {
    let domain = |plug: &str| {
        format!(
            r#"
name = "bridge on a plinth"
[[body]]
name = "plinth"
density = 2400.0
[[body.block]]
name = "left"
box = {{ center = [2.0, 0.0, -0.5], size = [4.0, 1.0, 1.0] }}
[[body.block]]
name = "right"
box = {{ center = [8.0, 0.0, -0.5], size = [4.0, 1.0, 1.0] }}
[[body.block]]
name = "bottom"
box = {{ center = [5.0, 0.0, -1.5], size = [10.0, 1.0, 1.0] }}
[[body]]
name = "bridge"
density = 2400.0
[[body.block]]
name = "leg_left"
box = {{ center = [0.5, 0.0, 0.5], size = [1.0, 1.0, 1.0] }}
[[body.block]]
name = "leg_right"
box = {{ center = [9.5, 0.0, 0.5], size = [1.0, 1.0, 1.0] }}
[[body.block]]
name = "lintel"
box = {{ center = [5.0, 0.0, 1.5], size = [10.0, 1.0, 1.0] }}
{plug}
[[interface]]
name = "plinth_on_ground"
parent = "ground"
child = "plinth"
rocking_base = {{ corners = [[0.0, -0.5, -2.0], [10.0, -0.5, -2.0], [10.0, 0.5, -2.0], [0.0, 0.5, -2.0]] }}
[[interface]]
name = "bridge_on_plinth"
parent = "plinth"
child = "bridge"
rocking_base = {{ corners = [[0.0, -0.5, 0.0], [10.0, -0.5, 0.0], [10.0, 0.5, 0.0], [0.0, 0.5, 0.0]] }}
"#
        )
    };
    let plug = r#"
[[body.block]]
name = "plug"
box = { center = [5.0, 0.0, -0.5], size = [2.0, 1.0, 1.0] }
"#;
    let normal = |text: &str| {
        let model = build(text).expect("the model builds");
        let bed = model
            .interfaces
            .iter()
            .find(|i| i.name == "bridge_on_plinth")
            .expect("the bed is an interface");
        match &bed.kind {
            crr_kinematics::InterfaceKind::RockingBase { normal, .. } => *normal,
            other => panic!("the bed is a rocking base, not {other:?}"),
        }
    };
    // Unit vectors from the corners' cross products: exact to a few ulps.
    let up = Vector3::z();
    let without = normal(&domain(""));
    assert!(
        (without - up).norm() <= 1e-12,
        "without the plug: {without:?}"
    );
    let with = normal(&domain(plug));
    assert!((with - up).norm() <= 1e-12, "with the plug: {with:?}");
}
