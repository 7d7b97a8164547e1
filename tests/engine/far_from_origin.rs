//! A model written in survey coordinates. The dynamics sum spatial quantities about the world
//! origin, so a body far from it would lose digits of its inertia to round-off, as the square of
//! its distance in model sizes: an independent review placed the bundled block 5e5 m away (2.5e5
//! times its size) and its free rocking lost its energy balance with no warning, and a stack
//! there stalled the integrator for minutes; such models were then refused. The physics does not
//! depend on where the model sits (gravity and the ground's motion are the same everywhere), and
//! a structure farther than 10 sizes from the origin is now simulated moved near it: the bundled
//! block, trilithon (a loop) and baldachin (3D rocking bases, loops) written 5e5 m east, 4.5e6 m
//! north and 350 m up rock as they do at the origin, impact for impact. Beyond 1e9 sizes, where
//! the file's coordinates no longer resolve the geometry, the run is refused with the body named.
use crate::common;

/// Housner's block of the bundled `single_block.toml` (0.4 × 2 m) released from 0.1 rad, its
/// base centred at (`x`, `y`, `z`).
fn block_at(x: f64, y: f64, z: f64) -> String {
    format!(
        r#"name = "block_at"
gravity = 9.81

[[body]]
name = "block"
density = 2500.0
box = {{ center = [{x}, {y}, {zc}], size = [0.4, 0.4, 2.0] }}

[[interface]]
name = "base"
parent = "ground"
child = "block"
axis = [0.0, 1.0, 0.0]
pivot_positive = [{xp}, {y}, {z}]
pivot_negative = [{xn}, {y}, {z}]

[initial]
angles = {{ base = 0.1 }}

[analysis]
duration = 4.0
"#,
        xp = x + 0.2,
        xn = x - 0.2,
        zc = z + 1.0,
    )
}

/// The bundled model's text with every point moved by `d`: the numbers of each `[x, y, z]` in the
/// values of `center`, `pivot_positive`, `pivot_negative` and `corners` (axes and sizes are
/// directions and lengths, left as they are). Written out with Rust's shortest round-trip
/// formatting, so that the file holds the moved points to their last bit.
fn moved_text(text: &str, d: [f64; 3]) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let mut rest = line;
        let mut moved = String::new();
        while let Some(k) = ["center", "pivot_positive", "pivot_negative", "corners"]
            .iter()
            .filter_map(|key| rest.find(&format!("{key} = ")).map(|i| (i, key.len() + 3)))
            .min()
        {
            let (start, skip) = k;
            moved += &rest[..start + skip];
            rest = &rest[start + skip..];
            // The value: a bracket and everything to its matching close.
            let mut depth = 0;
            let end = rest
                .char_indices()
                .find(|&(_, c)| {
                    depth += match c {
                        '[' => 1,
                        ']' => -1,
                        _ => 0,
                    };
                    depth == 0
                })
                .map(|(i, _)| i + 1)
                .expect("a bracketed value");
            moved += &move_triples(&rest[..end], d);
            rest = &rest[end..];
        }
        out += &moved;
        out += rest;
        out.push('\n');
    }
    out
}

/// Every innermost `[a, b, c]` of `value` plus `d`.
fn move_triples(value: &str, d: [f64; 3]) -> String {
    let mut out = String::new();
    let mut rest = value;
    // The innermost bracket from here: the last '[' before the first ']'.
    while let Some(close) = rest.find(']') {
        let Some(open) = rest[..close].rfind('[') else {
            break;
        };
        let numbers: Vec<f64> = rest[open + 1..close]
            .split(',')
            .map(|x| x.trim().parse().expect("a number"))
            .collect();
        assert_eq!(numbers.len(), 3, "{value}");
        out += &rest[..open];
        out += &format!(
            "[{:?}, {:?}, {:?}]",
            numbers[0] + d[0],
            numbers[1] + d[1],
            numbers[2] + d[2]
        );
        rest = &rest[close + 1..];
    }
    out + rest
}

/// Where the file sits: 5e5 m east, 4.5e6 m north, 350 m up (survey coordinates).
const SURVEY: [f64; 3] = [5e5, 4.5e6, 350.0];

/// The run at the origin and in survey coordinates: the same impacts (interfaces and instants)
/// and the same angles at every sample. The points in the file are rounded to ulp(4.5e6) ≈ 1e-9
/// m, 5e-10 of these models' sizes, which moves the motion by as little: 1e-8 s and 1e-8 rad are
/// far above it and far below anything the motion resolves (the events are located to 1e-13 t,
/// the integrator's rtol is 1e-10).
fn agree(tag: &str, at_origin: &str, far: &str) {
    let (near_model, a) = common::run_model_text(&format!("{tag}_at_origin"), at_origin, None);
    let (far_model, b) = common::run_model_text(&format!("{tag}_far"), far, None);
    // The file is the same structure, moved.
    let survey = nalgebra::Vector3::from(SURVEY);
    for (x, y) in near_model.bodies.iter().zip(&far_model.bodies) {
        assert!((y.com - x.com - survey).norm() < 1e-8, "{tag}: {}", x.name);
    }
    assert!(a.impacts.len() >= 5, "{tag}: it rocks");
    assert_eq!(a.impacts.len(), b.impacts.len(), "{tag}");
    for (x, y) in a.impacts.iter().zip(&b.impacts) {
        assert_eq!(x.interfaces, y.interfaces, "{tag}");
        assert!(
            (x.t - y.t).abs() < 1e-8,
            "{tag}: impact at {} s at the origin, {} s far away",
            x.t,
            y.t
        );
    }
    let (sa, sb): (Vec<_>, Vec<_>) = (a.samples.iter().collect(), b.samples.iter().collect());
    assert_eq!(sa.len(), sb.len(), "{tag}");
    for (x, y) in sa.iter().zip(&sb) {
        // The grid's samples at the same instants, the impacts' at their instants.
        assert!(
            (x.t - y.t).abs() < 1e-8,
            "{tag}: {} s against {} s",
            x.t,
            y.t
        );
        for (p, q) in x.q.iter().zip(y.q) {
            assert!((p - q).abs() < 1e-8, "{tag} at {} s: {p} against {q}", x.t);
        }
        // The energies relative to rest do not depend on where the model sits either.
        let scale = 1e-8 * (x.kinetic.abs() + x.potential.abs() + x.dissipated.abs() + 1.0);
        assert!(
            (x.kinetic - y.kinetic).abs() < scale && (x.potential - y.potential).abs() < scale,
            "{tag} at {} s",
            x.t
        );
    }
}

#[test]
fn models_in_survey_coordinates_rock_as_at_the_origin() {
    agree(
        "block",
        &block_at(0.0, 0.0, 0.0),
        &block_at(SURVEY[0], SURVEY[1], SURVEY[2]),
    );
    for name in ["trilithon", "baldachin"] {
        let text = common::bundled_text(name);
        agree(name, &text, &moved_text(&text, SURVEY));
    }
}

#[test]
fn a_model_beyond_what_its_coordinates_resolve_is_refused() {
    // 1e10 m away: 5e9 sizes, where the coordinates resolve the block to 1e-6 of its size.
    let path = common::write_model("block_beyond_resolution", &block_at(1e10, 0.0, 0.0));
    let model = crr::ModelInput::read(&path).expect("the file is valid");
    let Err(error) = crr::run(&model, &crr::RunOptions::default()) else {
        panic!("a model 1e10 m from the origin is run");
    };
    let error = error.to_string();
    assert!(
        error.contains("\"block\"")
            && error.contains("world origin")
            && error.contains("translate"),
        "{error}"
    );
}

/// `crr inspect` of a model far from the origin: its mass matrix M(q) and generalized gravity
/// Q(q) are those of the model at the origin (computed moved near it), to 1e-9 relative: the
/// file's points are rounded to ulp(4.5e6 m) ≈ 1e-9 m, 5e-10 of the block's size (3e-12 seen).
/// Computed about the origin, at 4.5e6 m, 2.25e6 times the block's size, round-off would take
/// ε (D/L)² ≈ 1e-3 of M. The bodies' centres are reported where the file puts them.
#[test]
fn inspect_reports_a_far_model_s_mass_matrix_as_at_the_origin() {
    let load = |tag: &str, text: &str| crr::load_model(&common::write_model(tag, text)).unwrap().1;
    let near = load("inspect_near", &block_at(0.0, 0.0, 0.0));
    let far = load("inspect_far", &block_at(SURVEY[0], SURVEY[1], SURVEY[2]));
    let q = nalgebra::DVector::from_vec(vec![0.1]);
    let (a, b) = (
        crr::analysis::inspect::inspect(&near, &q),
        crr::analysis::inspect::inspect(&far, &q),
    );
    let (ma, mb) = (a.mass_matrix[0][0], b.mass_matrix[0][0]);
    assert!(
        (ma - mb).abs() <= 1e-9 * ma,
        "M = {ma} at the origin, {mb} far away"
    );
    let (qa, qb) = (a.generalized_gravity[0], b.generalized_gravity[0]);
    assert!(
        (qa - qb).abs() <= 1e-9 * qa.abs(),
        "Q = {qa} at the origin, {qb} far away"
    );
    // Housner's block about its edge: I_O = m (4/3) R² with R² = b² + h² (0.2, 1.0 m).
    let m = 2500.0 * 0.4 * 0.4 * 2.0;
    let i_o = m * 4.0 / 3.0 * (0.2f64.powi(2) + 1.0);
    assert!((mb - i_o).abs() <= 1e-9 * i_o, "M = {mb}, I_O = {i_o}");
    let centre = b.bodies[0].center;
    assert!((centre[1] - SURVEY[1]).abs() < 1.0, "{centre:?}");
}
