//! A model written in survey coordinates. The dynamics sum spatial quantities about the world
//! origin, so a body far from it loses digits of its inertia to round-off, as the square of its
//! distance in model sizes: an independent review placed the bundled block 5e5 m away (2.5e5
//! times its size) and its free rocking lost its energy balance with no warning, and a stack
//! there stalled the integrator for minutes. The physics does not depend on where the model
//! sits: translated by 2 km (1e3 sizes) the block rocks as at the origin, and beyond 1e4 sizes
//! the run is refused with the body named and the remedy, before any step.
use crate::common;

/// Housner's block of the bundled `single_block.toml` (0.4 × 2 m) released from 0.1 rad, its
/// base centred at (`x`, `y`, 0).
fn block_at(x: f64, y: f64) -> String {
    format!(
        r#"name = "block_at"
gravity = 9.81

[[body]]
name = "block"
density = 2500.0
box = {{ center = [{x}, {y}, 1.0], size = [0.4, 0.4, 2.0] }}

[[interface]]
name = "base"
parent = "ground"
child = "block"
axis = [0.0, 1.0, 0.0]
pivot_positive = [{xp}, {y}, 0.0]
pivot_negative = [{xn}, {y}, 0.0]

[initial]
angles = {{ base = 0.1 }}

[analysis]
duration = 4.0
"#,
        xp = x + 0.2,
        xn = x - 0.2,
    )
}

#[test]
fn a_model_far_from_the_origin_rocks_as_at_the_origin_or_is_refused() {
    let (_, at_origin) = common::run_model_text("block_at_origin", &block_at(0.0, 0.0), None);
    let (_, moved) = common::run_model_text("block_at_2km", &block_at(2000.0, 0.0), None);
    assert!(at_origin.impacts.len() >= 5, "the block rocks");
    assert_eq!(at_origin.impacts.len(), moved.impacts.len());
    // Translated by 1e3 sizes, round-off takes ε·1e6 ≈ 2e-10 of M(q): the impact instants agree
    // far inside 1e-7 s.
    for (a, b) in at_origin.impacts.iter().zip(&moved.impacts) {
        assert!(
            (a.t - b.t).abs() < 1e-7,
            "impact at {} s at the origin, {} s 2 km away",
            a.t,
            b.t
        );
    }
    // In survey coordinates (5e5 m east, 4.5e6 m north): refused before any step.
    let path = common::write_model("block_in_survey_coordinates", &block_at(5e5, 4.5e6));
    let model = crr::ModelInput::read(&path).expect("the file is valid");
    let Err(error) = crr::run(&model, &crr::RunOptions::default()) else {
        panic!("a model 4.5e6 m from the origin is run");
    };
    let error = error.to_string();
    assert!(
        error.contains("\"block\"")
            && error.contains("world origin")
            && error.contains("translate"),
        "{error}"
    );
}
