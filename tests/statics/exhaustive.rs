//! The exhaustive pass over the joints that open and slide (`collapse_multiplier`, marked
//! `exhaustive`) against an enumeration written here from the blocks' geometry.
//!
//! **The independent value.** A planar wall of boxes (courses 0.5 m high, 1 m long, 0.5 m deep)
//! has contact points at both ends of every overlap: its bed joints (with the block below or the
//! ground) and, with every contact a joint, its head joints. A collapse state is an equilibrium
//! at λ with forces only where a mechanism keeps contact without sliding. For every set U of
//! joints that leaves every block joined to the ground (at most as many as the wall has loops),
//! a program written here from the boxes gives λ_f(U), the largest λ with U's points carrying
//! normal forces only, and its dual the mechanism (each block's virtual velocity), from which the
//! relative velocity of every joint's two points is computed here. U is a collapse state where
//! an equilibrium at λ_f(U) exists with U unloaded, every joint whose two points both move
//! unloaded, and every joint that turns about one point loaded there only (its shear is the same
//! wrench at either point). The multiplier is the least such λ_f, U = ∅ (the convex program)
//! included. The engine builds its model through `crr assemble` (`--planar`, with or without
//! `--all-contacts`) and its programs on its own contact faces; nothing of its statics is used
//! here.
//!
//! **The walls.** Drawn at random (2026-12-05, 120 walls of two or three courses, beds only and
//! with every contact, 240 directions), the engine answered 12 directions above the least
//! collapse before the exhaustive pass, by up to 103 % (0.666667 against 0.328658): its search
//! had found no lower mechanism, and `crr check` printed no caveat on 4 of them. The walls below
//! are five of those; the search alone (`exhaustive_sets` 0) still answers above the least
//! collapse on each.
//!
//! Tolerance: both sides solve linear programs of O(1) data to gaps of 1e-11 or less; 1e-7
//! relative, as the other independent statics tests.

use nalgebra::Vector3;

use crr::analysis::assemble::{AssemblyOptions, assemble, read_assembly};
use crr::impact::statics::{
    COUNTED_SETS, EXHAUSTIVE_SETS, StaticsOptions, Unexhausted, collapse_multiplier,
    exhaustive_sets_needed,
};
use crr::kinematics::Model;

use super::independent::Lp;

const LAMBDA_CAP: f64 = 10.0;
const RTOL: f64 = 1e-7;
const COURSE: f64 = 0.5;

/// A block: [x₀, x₁] × [z₀, z₁].
#[derive(Clone, Copy)]
struct Block {
    x: [f64; 2],
    z: [f64; 2],
}

/// A joint: the first body (None: the ground), the second, its contact points (x, z), the unit
/// normal from the first into the second and the tangent.
struct Joint {
    first: Option<usize>,
    second: usize,
    points: [[f64; 2]; 2],
    normal: [f64; 2],
    tangent: [f64; 2],
}

/// The blocks of a wall whose course c has the lengths `courses[c]` from x = 0.
fn blocks(courses: &[&[f64]]) -> Vec<Block> {
    let mut out = Vec::new();
    for (c, lengths) in courses.iter().enumerate() {
        let mut x = 0.0;
        for &len in lengths.iter() {
            out.push(Block {
                x: [x, x + len],
                z: [c as f64 * COURSE, (c + 1) as f64 * COURSE],
            });
            x += len;
        }
    }
    out
}

/// The wall's joints: every bed-joint overlap (and the ground under course 0) and, with
/// `heads`, every head joint between neighbours of a course.
fn joints(blocks: &[Block], heads: bool) -> Vec<Joint> {
    let mut out = Vec::new();
    for (a, above) in blocks.iter().enumerate() {
        if above.z[0] == 0.0 {
            out.push(Joint {
                first: None,
                second: a,
                points: [[above.x[0], 0.0], [above.x[1], 0.0]],
                normal: [0.0, 1.0],
                tangent: [1.0, 0.0],
            });
        }
        for (b, below) in blocks.iter().enumerate() {
            if (below.z[1] - above.z[0]).abs() < 1e-12 {
                let (lo, hi) = (below.x[0].max(above.x[0]), below.x[1].min(above.x[1]));
                if hi - lo > 1e-9 {
                    out.push(Joint {
                        first: Some(b),
                        second: a,
                        points: [[lo, above.z[0]], [hi, above.z[0]]],
                        normal: [0.0, 1.0],
                        tangent: [1.0, 0.0],
                    });
                }
            }
            if heads && below.z == above.z && (below.x[1] - above.x[0]).abs() < 1e-12 {
                out.push(Joint {
                    first: Some(b),
                    second: a,
                    points: [[above.x[0], above.z[0]], [above.x[0], above.z[1]]],
                    normal: [1.0, 0.0],
                    tangent: [0.0, 1.0],
                });
            }
        }
    }
    out
}

/// How a joint enters a program.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    /// Normal forces ≥ 0 and free shear at both points.
    Holds,
    /// Normal forces ≥ 0 only.
    Freed,
    /// No force.
    Unloaded,
    /// Shear (free) and a normal force ≥ 0 at its second point only: a joint that turns about
    /// that point while the other opens (the shear is the same wrench at either point, which lie
    /// apart along the tangent).
    PressesAt(usize),
    /// Shear and a normal force ≥ 0 at its first point only.
    PressesAtFirst,
}

/// The largest λ ≤ [`LAMBDA_CAP`] with every block in equilibrium under its weight (∝ area,
/// down) and −λ·weight·dx horizontally at its centre, the joints as `modes` say, and the
/// equilibrium rows' multipliers (each block's virtual velocity (u_x, u_z, ω)); None where no
/// λ ≥ 0 has an equilibrium.
fn largest_lambda(
    blocks: &[Block],
    joints: &[Joint],
    modes: &[Mode],
    dx: f64,
) -> Option<(f64, Vec<[f64; 3]>)> {
    // Variables: λ, then (joint, point, shear?) as the modes carry them.
    let mut columns: Vec<(usize, usize, bool)> = Vec::new();
    for (j, mode) in modes.iter().enumerate() {
        for p in 0..2 {
            let (normal, shear) = match mode {
                Mode::Holds => (true, true),
                Mode::Freed => (true, false),
                Mode::Unloaded => (false, false),
                Mode::PressesAt(q) => (p == *q, p == *q),
                Mode::PressesAtFirst => (p == 0, p == 0),
            };
            if normal {
                columns.push((j, p, false));
            }
            if shear {
                columns.push((j, p, true));
            }
        }
    }
    let mut lp = Lp::new(1 + columns.len());
    lp.cost[0] = -1.0;
    let mut rows: Vec<[Vec<(usize, f64)>; 3]> = vec![Default::default(); blocks.len()];
    let mut rhs = vec![[0.0; 3]; blocks.len()];
    for (k, b) in blocks.iter().enumerate() {
        let w = (b.x[1] - b.x[0]) * (b.z[1] - b.z[0]);
        rows[k][0].push((0, -w * dx));
        rhs[k][1] = w;
    }
    for (c, &(j, p, shear)) in columns.iter().enumerate() {
        let joint = &joints[j];
        let dir = if shear { joint.tangent } else { joint.normal };
        for (body, sign) in [(Some(joint.second), 1.0), (joint.first, -1.0)] {
            let Some(k) = body else { continue };
            let r = arm(&blocks[k], joint.points[p]);
            let f = [sign * dir[0], sign * dir[1]];
            rows[k][0].push((1 + c, f[0]));
            rows[k][1].push((1 + c, f[1]));
            // Moment about y of (f_x, f_z) at r: r_z f_x − r_x f_z.
            rows[k][2].push((1 + c, r[1] * f[0] - r[0] * f[1]));
        }
        if !shear {
            lp.le.push((vec![(1 + c, -1.0)], 0.0));
        }
    }
    for (row, b) in rows.into_iter().zip(rhs) {
        for (r, v) in row.into_iter().zip(b) {
            lp.eq.push((r, v));
        }
    }
    lp.le.push((vec![(0, 1.0)], LAMBDA_CAP));
    let sol = lp.solve().ok()?;
    let velocities = (0..blocks.len())
        .map(|k| [sol.y_eq[3 * k], sol.y_eq[3 * k + 1], sol.y_eq[3 * k + 2]])
        .collect();
    (sol.x[0] >= -1e-9).then_some((sol.x[0], velocities))
}

/// The point `point` relative to the block's centre.
fn arm(b: &Block, point: [f64; 2]) -> [f64; 2] {
    [
        point[0] - (b.x[0] + b.x[1]) / 2.0,
        point[1] - (b.z[0] + b.z[1]) / 2.0,
    ]
}

/// The relative velocity (second less first) at each point of each joint in the mechanism
/// `velocities`, as (gap rate along the normal, slip along the tangent). A block's multipliers
/// (a, b, c) weigh a force f at r by a f_x + b f_z + c (r_z f_x − r_x f_z): the point moves at
/// (a + c r_z, b − c r_x).
fn relative(blocks: &[Block], joints: &[Joint], velocities: &[[f64; 3]]) -> Vec<[[f64; 2]; 2]> {
    let at = |k: Option<usize>, point: [f64; 2]| -> [f64; 2] {
        k.map_or([0.0, 0.0], |k| {
            let [a, b, c] = velocities[k];
            let r = arm(&blocks[k], point);
            [a + c * r[1], b - c * r[0]]
        })
    };
    joints
        .iter()
        .map(|j| {
            let rel = |p: usize| -> [f64; 2] {
                let (s, f) = (at(Some(j.second), j.points[p]), at(j.first, j.points[p]));
                let v = [s[0] - f[0], s[1] - f[1]];
                [
                    v[0] * j.normal[0] + v[1] * j.normal[1],
                    v[0] * j.tangent[0] + v[1] * j.tangent[1],
                ]
            };
            [rel(0), rel(1)]
        })
        .collect()
}

/// Whether the joints not in `removed` join every block to the ground.
fn joined(blocks: &[Block], joints: &[Joint], removed: &[bool]) -> bool {
    let mut reached = vec![false; blocks.len()];
    let mut changed = true;
    while changed {
        changed = false;
        for (j, joint) in joints.iter().enumerate() {
            if removed[j] {
                continue;
            }
            let first = joint.first.is_none_or(|b| reached[b]);
            let second = reached[joint.second];
            if first && !second {
                reached[joint.second] = true;
                changed = true;
            }
            if let Some(b) = joint.first
                && second
                && !reached[b]
            {
                reached[b] = true;
                changed = true;
            }
        }
    }
    reached.iter().all(|&r| r)
}

/// The collapse state of the set `removed` (unloaded, free to slide), if any: λ_f of the
/// program with those joints freed, where an equilibrium at λ_f carries forces only where its
/// mechanism (the program's dual) keeps contact without sliding: a joint whose points both move
/// carries nothing, one that turns about a point carries its forces there.
fn collapse_state(blocks: &[Block], joints: &[Joint], removed: &[bool], dx: f64) -> Option<f64> {
    let freed: Vec<Mode> = removed
        .iter()
        .map(|&r| if r { Mode::Freed } else { Mode::Holds })
        .collect();
    let (lambda, velocities) = largest_lambda(blocks, joints, &freed, dx)?;
    let rel = relative(blocks, joints, &velocities);
    let scale = rel
        .iter()
        .flatten()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let moves = |v: &[f64; 2]| v[0].abs() > 1e-6 * scale || v[1].abs() > 1e-6 * scale;
    let modes: Vec<Mode> = (0..joints.len())
        .map(|j| match (moves(&rel[j][0]), moves(&rel[j][1])) {
            (true, true) => Mode::Unloaded,
            (true, false) if removed[j] => Mode::Unloaded,
            (false, true) if removed[j] => Mode::Unloaded,
            (true, false) => Mode::PressesAt(1),
            (false, true) => Mode::PressesAtFirst,
            (false, false) => freed[j],
        })
        .collect();
    let (spared, _) = largest_lambda(blocks, joints, &modes, dx)?;
    (spared >= lambda * (1.0 - 1e-8)).then_some(lambda)
}

/// The least collapse over every set of joints that leaves every block joined to the ground
/// (see the module's docs).
fn least_collapse(blocks: &[Block], joints: &[Joint], dx: f64) -> f64 {
    let loops = joints.len() - blocks.len();
    let mut best = f64::INFINITY;
    for mask in 0u32..(1 << joints.len()) {
        if mask.count_ones() as usize > loops {
            continue;
        }
        let removed: Vec<bool> = (0..joints.len()).map(|j| mask >> j & 1 == 1).collect();
        if !joined(blocks, joints, &removed) {
            continue;
        }
        if let Some(lambda) = collapse_state(blocks, joints, &removed, dx) {
            best = best.min(lambda);
        }
    }
    best
}

/// The engine's model of the wall, through `crr assemble --planar` (and `--all-contacts` with
/// `heads`).
fn engine_model(name: &str, blocks: &[Block], heads: bool) -> Model {
    let mut text = format!("name = \"{name}\"\ngravity = 9.81\n");
    for (k, b) in blocks.iter().enumerate() {
        text += &format!(
            "\n[[body]]\nname = \"b{k}\"\ndensity = 2000.0\nbox = {{ center = [{}, 0.0, {}], size = [{}, 0.5, {}] }}\n",
            (b.x[0] + b.x[1]) / 2.0,
            (b.z[0] + b.z[1]) / 2.0,
            b.x[1] - b.x[0],
            b.z[1] - b.z[0]
        );
    }
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("assemblies");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let file = read_assembly(&path).unwrap();
    let mut options = AssemblyOptions::default().in_plane();
    if heads {
        options = options.with_all_contacts();
    }
    assemble(&path, &file, &options).unwrap().model
}

/// Walls the search alone answers above the least collapse (module docs): the course lengths,
/// whether every contact is a joint, and the direction that differs.
const WALLS: [(&[&[f64]], bool, f64); 5] = [
    (&[&[0.54, 0.46], &[0.69, 0.31]], true, 1.0),
    (&[&[0.41, 0.59], &[0.74, 0.26]], true, 1.0),
    (&[&[1.0], &[0.18, 0.36, 0.46], &[1.0]], true, 1.0),
    (&[&[0.51, 0.49], &[0.38, 0.45, 0.17]], true, 1.0),
    (&[&[0.46, 0.21, 0.33], &[0.5, 0.5], &[1.0]], false, -1.0),
];

/// The first wall, [0.54 | 0.46] under [0.69 | 0.31] with every contact a joint, along +x: the
/// lower end block and the whole upper course turn as one about the end block's outer foot
/// (0, 0), the upper course lifting off the other lower block while the head joint between the
/// lower blocks slides at its foot, which keeps contact and carries nothing. Virtual work of a
/// rotation about (0, 0), areas as weights: gravity's Σ A x against the load's Σ A z, with
/// (A, x, z) = (0.27, 0.27, 0.25), (0.345, 0.345, 0.75), (0.155, 0.845, 0.75):
/// λ = 0.3229/0.4425 = 3229/4425 = 0.729718, where the search alone answered the convex
/// program's 1.
#[test]
fn the_first_wall_turns_about_its_outer_foot_at_its_virtual_work_multiplier() {
    let (courses, heads, dx) = WALLS[0];
    let blocks = blocks(courses);
    let model = engine_model("exhaustive_wall_by_hand", &blocks, heads);
    let wedge = [
        (0.27, 0.27, 0.25),
        (0.345, 0.345, 0.75),
        (0.155, 0.845, 0.75),
    ];
    let gravity: f64 = wedge.iter().map(|(a, x, _)| a * x).sum();
    let load: f64 = wedge.iter().map(|(a, _, z)| a * z).sum();
    let by_hand = gravity / load;
    assert!((by_hand - 3229.0 / 4425.0).abs() < 1e-15);
    let c = collapse_multiplier(
        &model,
        Vector3::new(dx, 0.0, 0.0),
        &StaticsOptions::default(),
    )
    .unwrap();
    let got = c.lambda.expect("a multiplier");
    assert!(
        (got - by_hand).abs() <= RTOL * by_hand,
        "engine {got} against {by_hand} by hand"
    );
    assert_eq!(c.convex_lambda.map(|l| (l * 1e6).round() / 1e6), Some(1.0));
}

/// Each wall's multiplier along ±x is the enumeration's (1e-7) and marked exhaustive; along the
/// direction that differed, the search alone (`exhaustive_sets` 0) answers above it and is
/// marked as not exhaustive.
#[test]
fn the_exhaustive_pass_finds_the_least_collapse_of_small_walls() {
    for (w, &(courses, heads, differed)) in WALLS.iter().enumerate() {
        let blocks = blocks(courses);
        let joints = joints(&blocks, heads);
        let model = engine_model(&format!("exhaustive_wall_{w}"), &blocks, heads);
        assert_eq!(model.interfaces.len(), joints.len(), "wall {w}: the joints");
        for dx in [1.0, -1.0] {
            let expected = least_collapse(&blocks, &joints, dx);
            let d = Vector3::new(dx, 0.0, 0.0);
            let c = collapse_multiplier(&model, d, &StaticsOptions::default()).unwrap();
            let got = c.lambda.expect("the wall has a multiplier");
            println!("wall {w}, dx {dx:+}: engine {got:.12}, enumeration {expected:.12}");
            assert!(c.exhaustive, "wall {w}, dx {dx:+}: not exhaustive");
            assert_eq!(c.unexhausted, None, "wall {w}, dx {dx:+}");
            assert!(
                (got - expected).abs() <= RTOL * expected,
                "wall {w}, dx {dx:+}: engine {got} against the enumeration's {expected}"
            );
            if dx == differed {
                let search = StaticsOptions {
                    exhaustive_sets: 0,
                    ..StaticsOptions::default()
                };
                let alone = collapse_multiplier(&model, d, &search).unwrap();
                let above = alone.lambda.expect("the search has an answer");
                assert!(
                    !alone.exhaustive,
                    "wall {w}: the search alone is not exhaustive"
                );
                assert_eq!(
                    alone.unexhausted,
                    Some(Unexhausted::TooManySets),
                    "wall {w}"
                );
                assert!(
                    above > expected * (1.0 + 1e-6),
                    "wall {w}: the search alone gives {above}, not above {expected}"
                );
            }
        }
    }
}

/// A wall whose sets of joints that may open and slide outnumber the default budget
/// (`EXHAUSTIVE_SETS`): [0.53 | 0.18 | 0.29] under [0.29 | 0.39 | 0.32] under [1], every contact
/// a joint, along −x, where the search alone answered 0.666667 and the least collapse opens at
/// 0.328658 (module docs). With the default budget the answer is the search's, marked
/// `TooManySets`, and `exhaustive_sets_needed` counts the sets the pass would try; with exactly
/// that budget the pass runs and gives the enumeration's least collapse (1e-7), and with one
/// set less it still does not (the count is the pass's own).
#[test]
fn a_budget_of_the_counted_sets_makes_a_larger_wall_exhaustive() {
    let courses: &[&[f64]] = &[&[0.53, 0.18, 0.29], &[0.29, 0.39, 0.32], &[1.0]];
    let blocks = blocks(courses);
    let joints = joints(&blocks, true);
    let model = engine_model("exhaustive_budget_wall", &blocks, true);
    let d = Vector3::new(-1.0, 0.0, 0.0);
    let expected = least_collapse(&blocks, &joints, -1.0);
    let default = collapse_multiplier(&model, d, &StaticsOptions::default()).unwrap();
    assert_eq!(default.unexhausted, Some(Unexhausted::TooManySets));
    let searched = default.lambda.expect("the search has an answer");
    assert!(
        searched > expected * (1.0 + 1e-6),
        "the search alone gives {searched}, not above the least collapse {expected}"
    );
    let needed = exhaustive_sets_needed(&model, &default, COUNTED_SETS)
        .expect("fewer sets than COUNTED_SETS");
    assert!(needed > EXHAUSTIVE_SETS, "{needed} sets");
    let budget = |sets: usize| StaticsOptions {
        exhaustive_sets: sets,
        ..StaticsOptions::default()
    };
    let short = collapse_multiplier(&model, d, &budget(needed - 1)).unwrap();
    assert_eq!(short.unexhausted, Some(Unexhausted::TooManySets));
    let full = collapse_multiplier(&model, d, &budget(needed)).unwrap();
    assert!(full.exhaustive, "{:?}", full.unexhausted);
    let got = full.lambda.expect("a multiplier");
    println!("{needed} sets: search {searched:.9}, pass {got:.12}, enumeration {expected:.12}");
    assert!(
        (got - expected).abs() <= RTOL * expected,
        "engine {got} against the enumeration's {expected}"
    );
}
