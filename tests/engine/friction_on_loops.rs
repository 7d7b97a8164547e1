//! The hypotheses monitor's sliding test on structures with loops. There the contact forces
//! are not fixed by the motion: the loops hold the bodies more times than their motion needs,
//! so the friction demand |F_t|/N of one distribution says nothing of whether another holds.
//! With `friction` set, a slide is reported only where no compressive distribution keeps every
//! contact's resultant within Coulomb's cone (`crr_impact::monitor::settle_sliding`), and its
//! demand is the least μ any distribution needs.
//!
//! An independent review (2026-12-06) found the bundled baldachin and a slab on four columns
//! reported sliding at rest under gravity alone ("needs friction |F_t|/N = 0.0395 above μ" with
//! μ = 0.1), from t = 0, where every column carries its share straight down: the tangential
//! forces of the least-norm distribution had been read against the normal forces of the most
//! compressive one.

use crate::common::{bundled_text, write_model};

/// A slab 3.4 × 2.4 × 0.4 m on four columns 0.4 × 0.4 × 3 m at (±1.5, ±1), as `crr assemble`
/// writes it: three loops. The blocks are written as `<tag>_blocks.toml` (each test its own).
fn slab_on_columns(tag: &str) -> String {
    slab_on_columns_listed(tag, false)
}

/// [`slab_on_columns`] with its blocks listed in reverse (the slab first) where `reversed`: the
/// same structure, its interfaces in another order.
fn slab_on_columns_listed(tag: &str, reversed: bool) -> String {
    use crr::analysis::assemble::{AssemblyOptions, assemble, read_assembly};
    let mut blocks: Vec<String> = [
        ("c1", -1.5, -1.0),
        ("c2", 1.5, -1.0),
        ("c3", -1.5, 1.0),
        ("c4", 1.5, 1.0),
    ]
    .iter()
    .map(|(name, x, y)| {
        format!(
            "\n[[body]]\nname = \"{name}\"\ndensity = 2500.0\n\
             box = {{ center = [{x}, {y}, 1.5], size = [0.4, 0.4, 3.0] }}\n"
        )
    })
    .collect();
    blocks.push(
        "\n[[body]]\nname = \"slab\"\ndensity = 2500.0\n\
         box = { center = [0.0, 0.0, 3.2], size = [3.4, 2.4, 0.4] }\n"
            .to_string(),
    );
    if reversed {
        blocks.reverse();
    }
    let text = String::from("name = \"slab_on_columns\"\n") + &blocks.concat();
    let path = write_model(&format!("{tag}_blocks"), &text);
    let file = read_assembly(&path).unwrap();
    let assembled = assemble(&path, &file, &AssemblyOptions::default()).unwrap();
    crr::output::assemble::model_toml(&assembled, &assembled.file)
}

fn run(tag: &str, text: &str, duration: f64) -> crr::Run {
    let path = write_model(tag, text);
    let model = crr::ModelInput::read(&path).unwrap_or_else(|e| panic!("{tag}: {e}"));
    let opts = crr::RunOptions {
        duration: Some(duration),
        ..Default::default()
    };
    crr::run(&model, &opts).unwrap_or_else(|e| panic!("{tag}: {e}"))
}

/// At rest under gravity alone no contact needs any tangential force: no slide is reported,
/// whatever μ, on the slab on four columns and on the bundled baldachin (a slab on four
/// columns of drums, written by hand). Both have loops.
#[test]
fn a_structure_with_loops_at_rest_does_not_slide() {
    let baldachin = bundled_text("baldachin");
    // The baldachin's own record removed: at rest.
    let baldachin = baldachin
        .split("[ground_motion]")
        .next()
        .unwrap()
        .to_string();
    for (name, text) in [
        ("slab", slab_on_columns("slab_at_rest")),
        ("baldachin", baldachin),
    ] {
        for mu in [0.02, 0.1, 0.6] {
            let tag = format!("{name}_rest_{mu}");
            let r = run(
                &tag,
                &format!("{text}\n[analysis]\nduration = 0.2\nfriction = {mu}\n"),
                0.2,
            );
            assert!(r.completed(), "{tag}: {:?}", r.summary.error);
            assert!(
                r.trajectory.violation.is_none(),
                "{tag}: {:?}",
                r.trajectory.violation
            );
        }
    }
}

/// Under a constant ground acceleration a = λ g d a structure of columns under a slab (rocking
/// only from λ = 2b/H = 0.1333 along x, the frame rule) stands, and its contacts need, by hand,
/// the friction of the whole: the slab takes λ W_s |d_h| along its seats over W_s (1 + λ d_z),
/// and so does every bed below, so μ* = λ |d_h| / (1 + λ d_z) bounds any distribution's largest
/// |F_t|/N from below (the triangle inequality over the beds of one level), and the
/// distribution with that ratio at every contact reaches it. Below μ* nothing is reported;
/// above it the slide is, at t = 0, with the demand μ* (to the monitor's bracket, 1e-3, and its
/// tolerances), never below the μ given. The slab on four columns along x and along (1, 2, 0.3)
/// (whose vertical part adds to the weight) with μ = 0.1 at 0.97 and 1.03 μ*, and with μ =
/// 0.05 also at 1.2 and 1.4 μ* (where an independent review found the program failing to solve
/// and the first distribution's demand, 0.0621 and 0.2986, reported); the bundled baldachin,
/// on columns of drums, along x and (1, 1, 0) with μ = 0.05 and 0.1.
#[test]
fn a_structure_with_loops_slides_where_no_distribution_holds() {
    let baldachin = bundled_text("baldachin")
        .split("[ground_motion]")
        .next()
        .unwrap()
        .to_string();
    // (structure, model, direction d, μ, [(λ/μ*, whether it slides)]).
    type Case<'a> = (&'a str, String, [f64; 3], f64, &'a [(f64, bool)]);
    let cases: [Case; 6] = [
        (
            "slab",
            slab_on_columns("slab_under_load"),
            [1.0, 0.0, 0.0],
            0.1,
            &[(0.97, false), (1.03, true)],
        ),
        (
            "slab",
            slab_on_columns("slab_under_oblique_load"),
            [1.0, 2.0, 0.3],
            0.1,
            &[(0.97, false), (1.03, true)],
        ),
        (
            "slab",
            slab_on_columns("slab_low_friction"),
            [1.0, 0.0, 0.0],
            0.05,
            &[(0.97, false), (1.03, true), (1.2, true), (1.4, true)],
        ),
        (
            "slab",
            slab_on_columns("slab_low_friction_y"),
            [0.0, 1.0, 0.0],
            0.05,
            &[(1.2, true), (1.4, true)],
        ),
        (
            "baldachin",
            baldachin.clone(),
            [1.0, 0.0, 0.0],
            0.1,
            &[(0.97, false), (1.03, true)],
        ),
        (
            "baldachin",
            baldachin,
            [1.0, 1.0, 0.0],
            0.05,
            &[(0.97, false), (1.2, true)],
        ),
    ];
    for (name, text, d, mu, factors) in cases {
        let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let (horizontal, vertical) = ((d[0] * d[0] + d[1] * d[1]).sqrt() / norm, d[2] / norm);
        let demand = |lambda: f64| lambda * horizontal / (1.0 + lambda * vertical);
        // The λ at which the demand is μ: λ (h − μ v) = μ.
        let at_mu = mu / (horizontal - mu * vertical);
        for &(factor, slides) in factors {
            let lambda = at_mu * factor;
            let a = lambda * 9.81;
            let tag = format!("{name}_{}_{}_{}_{mu}_{factor}", d[0], d[1], d[2]);
            let gm = format!(
                "\n[ground_motion]\nx = {{ constant = {{ value = {} }} }}\ny = {{ constant = {{ value = {} }} }}\nz = {{ constant = {{ value = {} }} }}\n\n[analysis]\nduration = 0.1\nfriction = {mu}\n",
                a * d[0] / norm,
                a * d[1] / norm,
                a * d[2] / norm
            );
            let r = run(&tag, &format!("{text}{gm}"), 0.1);
            match (&r.trajectory.violation, slides) {
                (None, false) => {}
                (Some(v), true) => {
                    assert_eq!(v.kind, "sliding", "{tag}: {v:?}");
                    assert_eq!(v.t, 0.0, "{tag}: {v:?}");
                    let expected = demand(lambda);
                    assert!(v.friction_demand > mu, "{tag}: {v:?}");
                    assert!(
                        (v.friction_demand - expected).abs() < 2e-3 * expected,
                        "{tag}: demand {} against {expected} by hand",
                        v.friction_demand
                    );
                }
                (v, _) => panic!("{tag}: λ = {lambda}: {v:?}"),
            }
        }
    }
}

/// The slide reported does not depend on the order in which the file lists the structure: the
/// least-friction distribution loads the four columns' bases (and the slab's seats) to the same
/// ratio, equal only to the interior point's accuracy, and the contact named is the one whose
/// name sorts first among them. The slab on four columns along x at 1.2 μ* with μ = 0.05,
/// written in order and in reverse (the slab first): the same interface, and the same demand
/// to the bracket's 1e-3.
#[test]
fn the_slide_reported_does_not_depend_on_the_order_of_the_file() {
    let mu = 0.05;
    let a = 1.2 * mu * 9.81;
    let gm = format!(
        "\n[ground_motion]\nx = {{ constant = {{ value = {a} }} }}\n\n[analysis]\nduration = 0.1\nfriction = {mu}\n"
    );
    let slides: Vec<crr::impact::monitor::Violation> = [false, true]
        .into_iter()
        .map(|reversed| {
            let tag = format!("slab_listed_{reversed}");
            let text = slab_on_columns_listed(&tag, reversed) + &gm;
            let r = run(&tag, &text, 0.1);
            r.trajectory.violation.expect("it slides")
        })
        .collect();
    assert_eq!(slides[0].interface, slides[1].interface, "{slides:?}");
    assert!(
        (slides[0].friction_demand - slides[1].friction_demand).abs()
            < 1e-3 * slides[0].friction_demand,
        "{slides:?}"
    );
}
