//! The collapse multiplier is a property of the structure, not of how its file is written: the
//! global program gives equal multipliers in mirrored directions for structures that are
//! mirror-symmetric, and the same multiplier (and mechanism) when the bodies, the interfaces and
//! the corners of every rocking base are listed in another order or the structure is mirrored.
//! The former local search over pivot sides failed exactly these (its answer depended on the
//! starting sides, hence on the order of the file): arches of many voussoirs differed by factors
//! up to 50 between +x and −x.
//!
//! Tolerance 1e-9 relative: the interior-point solver stops at a duality gap of 1e-12 of the
//! structure's weight (the multipliers agree to a few 1e-12 in practice).
use nalgebra::Vector3;

use crr::impact::statics::{StaticsOptions, collapse_multiplier};
use crr::kinematics::fixtures::{SplitMix, running_bond_wall, running_bond_wall_3d, voussoir_arch};
use crr::kinematics::spec::StructureSpec;
use crr::kinematics::{Model, Role};

use crate::common::mirrored_x;

fn bundled_spec(name: &str) -> StructureSpec {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("examples/models/{name}.toml"));
    crr::load_model(&path)
        .expect("bundled model loads")
        .0
        .structure()
}

fn lambda(spec: &StructureSpec, d: Vector3<f64>) -> f64 {
    let model = Model::from_spec(spec).unwrap_or_else(|e| panic!("{}: {e}", spec.name));
    collapse_multiplier(&model, d, &StaticsOptions::default())
        .unwrap()
        .lambda
        .unwrap_or(f64::INFINITY)
}

fn same(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}

/// The structure with its bodies (and, with `interfaces`, its interfaces) in a random order and
/// the corners of every rocking base turned by a random number of places (the same rectangle,
/// the same orientation). The temple keeps its interfaces' order: its seats that may twist must
/// close loops, which the order of the file decides (the model refuses another).
fn shuffled(spec: &StructureSpec, seed: u64, interfaces: bool) -> StructureSpec {
    let mut rng = SplitMix(seed);
    let mut out = spec.clone();
    for i in (1..out.body.len()).rev() {
        let j = rng.below(i + 1);
        out.body.swap(i, j);
    }
    if interfaces {
        for i in (1..out.interface.len()).rev() {
            let j = rng.below(i + 1);
            out.interface.swap(i, j);
        }
    }
    for interface in &mut out.interface {
        if let Some(base) = &mut interface.rocking_base {
            let k = rng.below(4);
            base.corners.rotate_left(k);
        }
    }
    out
}

#[test]
fn symmetric_structures_have_equal_multipliers_in_mirrored_directions() {
    let mut cases: Vec<(String, StructureSpec, bool)> = [5, 9, 17, 25, 41]
        .into_iter()
        .map(|n| {
            (
                format!("arch of {n}"),
                voussoir_arch(n, 2.0, 2.5, 1.0),
                false,
            )
        })
        .collect();
    for (name, both) in [
        ("trilithon", false),
        ("baldachin", true),
        ("temple", true),
        ("wall", false),
    ] {
        cases.push((name.to_string(), bundled_spec(name), both));
    }
    cases.push((
        "wall 5×4".into(),
        running_bond_wall(5, 4, 1.0, 0.5, 0.5),
        false,
    ));
    cases.push((
        "3D wall 3×3".into(),
        running_bond_wall_3d(3, 3, 1.0, 0.5, 0.5),
        false,
    ));
    for (name, spec, both) in &cases {
        let mut axes = vec![Vector3::x()];
        if *both {
            axes.push(Vector3::y());
        }
        for d in axes {
            let (plus, minus) = (lambda(spec, d), lambda(spec, -d));
            println!("{name} along ±{d:?}: {plus} / {minus}");
            assert!(
                plus.is_finite() && same(plus, minus),
                "{name}: {plus} against {minus}"
            );
        }
    }
}

#[test]
fn the_order_of_the_file_changes_no_multiplier() {
    let mut cases: Vec<(String, StructureSpec)> = [9, 21]
        .into_iter()
        .map(|n| (format!("arch of {n}"), voussoir_arch(n, 2.0, 2.5, 1.0)))
        .collect();
    for name in [
        "trilithon",
        "baldachin",
        "temple",
        "wall",
        "two_block_stack",
    ] {
        cases.push((name.to_string(), bundled_spec(name)));
    }
    cases.push((
        "3D wall 3×3".into(),
        running_bond_wall_3d(3, 3, 1.0, 0.5, 0.5),
    ));
    for (name, spec) in &cases {
        for d in [Vector3::x(), -Vector3::y(), Vector3::new(0.6, 0.8, 0.0)] {
            let reference = lambda(spec, d);
            for seed in 1..=3 {
                let other = lambda(&shuffled(spec, seed, name != "temple"), d);
                assert!(
                    same(reference, other),
                    "{name} {d:?}, order {seed}: {reference} against {other}"
                );
            }
        }
    }
}

#[test]
fn a_mirrored_file_gives_the_mirrored_multipliers() {
    for name in ["trilithon", "baldachin", "two_block_stack", "wall"] {
        let spec = bundled_spec(name);
        let mirror = mirrored_x(&spec);
        for d in [Vector3::x(), -Vector3::x(), Vector3::new(0.6, 0.8, 0.0)] {
            let reflected = Vector3::new(-d.x, d.y, d.z);
            let (a, b) = (lambda(&spec, d), lambda(&mirror, reflected));
            assert!(same(a, b), "{name} {d:?}: {a} against the mirror's {b}");
        }
    }
}

/// The simulation keeps the rest statics' axis multipliers of a chain for any chain over the
/// same interfaces (`crr::impact::statics::AxisMemory`): a chain that a run returns to after
/// faces opened and landed may have another spanning tree (interfaces that closed loops now in
/// the tree, some turned round), but the same faces. The multiplier is a property of the faces
/// and the bodies, so it must not change with the tree: checked here by building chains with
/// other trees (every second tree interface pushed out of the tree, so that the tree grows
/// again through former loop closures, or only the first; each structure has a chain with
/// interfaces turned round, child and parent swapped) and solving each from scratch along the
/// six axes and an oblique direction.
#[test]
fn the_chain_s_tree_changes_no_multiplier() {
    let cases: Vec<(String, StructureSpec)> = vec![
        ("wall".into(), bundled_spec("wall")),
        (
            "running bond 5×4".into(),
            running_bond_wall(5, 4, 1.0, 0.5, 0.5),
        ),
        (
            "3D wall 3×3".into(),
            running_bond_wall_3d(3, 3, 1.0, 0.5, 0.5),
        ),
        ("arch of 9".into(), voussoir_arch(9, 2.0, 2.5, 1.0)),
    ];
    for (name, spec) in &cases {
        let model = Model::from_spec(spec).unwrap_or_else(|e| panic!("{name}: {e}"));
        let tree: Vec<usize> = (0..model.interfaces.len())
            .filter(|&k| matches!(model.interfaces[k].role, Role::Tree { .. }))
            .collect();
        let (mut moved_any, mut turned_any) = (false, false);
        let pushed_sets: [Vec<usize>; 2] =
            [tree.iter().copied().step_by(2).collect(), vec![tree[0]]];
        for (offset, pushed) in pushed_sets.iter().enumerate() {
            let (chain, turned) = model
                .with_open_interfaces(&[], pushed)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let moved = chain
                .interfaces
                .iter()
                .zip(&model.interfaces)
                .filter(|(a, b)| {
                    matches!(a.role, Role::Tree { .. }) != matches!(b.role, Role::Tree { .. })
                })
                .count();
            moved_any |= moved > 0;
            turned_any |= turned.iter().any(|&t| t);
            for d in [
                Vector3::x(),
                -Vector3::x(),
                Vector3::y(),
                -Vector3::y(),
                Vector3::z(),
                -Vector3::z(),
                Vector3::new(0.6, 0.8, 0.0),
            ] {
                let of = |m: &Model| {
                    collapse_multiplier(m, d, &StaticsOptions::default())
                        .unwrap_or_else(|e| panic!("{name}: {e}"))
                        .lambda
                        .unwrap_or(f64::INFINITY)
                };
                let (file, other) = (of(&model), of(&chain));
                assert!(
                    same(file, other),
                    "{name} {d:?}, tree {offset} ({moved} interfaces moved): {file} against {other}"
                );
            }
        }
        assert!(moved_any, "{name}: every chain kept the file's tree");
        assert!(turned_any, "{name}: no chain turned an interface round");
    }
}

/// Two blocks 0.5 × 0.3 × 0.25 m side by side along their wall's own x (see [`written`]).
fn two_blocks_written(degrees: f64, offset: [f64; 3], decimals: usize) -> Model {
    written(
        "two_blocks",
        &[[0.0, 0.5, 0.0], [0.5, 1.0, 0.0]],
        degrees,
        offset,
        decimals,
    )
}

/// Blocks 0.3 m deep and 0.25 m high, each [x₀, x₁, z₀] along their wall's own x, written as an
/// OBJ file turned by `degrees` about the vertical, moved by `offset`, with `decimals` decimals
/// (as CAD programs write them), assembled with every contact a joint (`crr assemble
/// --all-contacts`, the ground at the offset's height).
fn written(
    name: &str,
    blocks: &[[f64; 3]],
    degrees: f64,
    offset: [f64; 3],
    decimals: usize,
) -> Model {
    use crr::analysis::assemble::{AssemblyOptions, assemble, read_assembly};
    let (c, s) = (degrees.to_radians().cos(), degrees.to_radians().sin());
    let mut obj = String::new();
    for (k, &[x0, x1, z0]) in blocks.iter().enumerate() {
        obj += &format!("o b{k}\n");
        let z1 = z0 + 0.25;
        for (x, y, z) in [
            (x0, 0.0, z0),
            (x1, 0.0, z0),
            (x1, 0.3, z0),
            (x0, 0.3, z0),
            (x0, 0.0, z1),
            (x1, 0.0, z1),
            (x1, 0.3, z1),
            (x0, 0.3, z1),
        ] {
            let p = [
                c * x - s * y + offset[0],
                s * x + c * y + offset[1],
                z + offset[2],
            ];
            obj += &format!(
                "v {:.decimals$} {:.decimals$} {:.decimals$}\n",
                p[0], p[1], p[2]
            );
        }
        let b = 8 * k;
        for f in [
            [1, 4, 3, 2],
            [5, 6, 7, 8],
            [1, 2, 6, 5],
            [2, 3, 7, 6],
            [3, 4, 8, 7],
            [4, 1, 5, 8],
        ] {
            obj += &format!("f {} {} {} {}\n", b + f[0], b + f[1], b + f[2], b + f[3]);
        }
    }
    // A file of its own per call: tests run in parallel, and two that write the same placement
    // would truncate each other's file while it is read.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = format!(
        "{name}_{degrees}_{decimals}_{}_{}_{call}",
        offset[0] as i64,
        std::process::id()
    );
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("placements");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(format!("{name}.obj")), obj).unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(
        &path,
        format!("name = \"{name}\"\ngravity = 9.81\n\n[[obj]]\nfile = \"{name}.obj\"\ndensity = 2000.0\n"),
    )
    .unwrap();
    let file = read_assembly(&path).unwrap();
    let options = AssemblyOptions {
        ground_level: offset[2],
        ..AssemblyOptions::default().with_all_contacts()
    };
    assemble(&path, &file, &options).unwrap().model
}

/// The multiplier, found by the exhaustive pass, wherever and however the structure is
/// written. Two blocks of b/h = 0.5/0.25 = 2 side by side, the ground accelerating along their
/// row: the first tips away from the second about its outer foot at λ = b/h = 2 (the pair as one
/// would tip at 1.0/0.25 = 4). Written exactly, at the origin or turned, the exhaustive pass
/// finds 2. Turned 30° with six decimals, or 80° at survey coordinates (500 km east, 4500 km
/// north, 350 m up) with fifteen, round-off at the model's precision makes the blocks tip at λ
/// that differ by about 1e-6, so that no exact equilibrium has both on their edges: the pass
/// answered 4 marked exhaustive (an independent review of 1330 placements), then 4 marked not
/// exhaustive. Its physical test at the model's precision (each body in equilibrium to 1e-5 of
/// its weight) finds 2 again, exhaustively, both ways along the row.
#[test]
fn an_answer_marked_exhaustive_is_the_multiplier_wherever_the_structure_is_written() {
    let cases: [(f64, [f64; 3], usize); 5] = [
        (0.0, [0.0; 3], 15),
        (30.0, [0.0; 3], 15),
        (30.0, [0.0; 3], 6),
        (80.0, [0.0; 3], 15),
        (80.0, [500_000.0, 4_500_000.0, 350.0], 15),
    ];
    for (degrees, offset, decimals) in cases {
        let model = two_blocks_written(degrees, offset, decimals);
        for sign in [1.0, -1.0] {
            let along =
                sign * Vector3::new(degrees.to_radians().cos(), degrees.to_radians().sin(), 0.0);
            let c = collapse_multiplier(&model, along, &StaticsOptions::default()).unwrap();
            let lambda = c.lambda.unwrap();
            let case = format!(
                "{degrees}° at {offset:?}, {decimals} decimals, {sign:+} along the row: λ = {lambda}"
            );
            assert!(c.exhaustive, "{case}: {:?}", c.unexhausted);
            // The model's precision: its faces are planar to 1e-6 of its size, and its programs
            // at that precision hold each body to 1e-5 of its weight.
            assert!((lambda - 2.0).abs() < 1e-5, "{case}");
        }
    }
}

/// Two courses of running bond, 1.5 m long: three blocks under two and two half blocks, each
/// [x₀, x₁, z₀] along the wall's own x (see [`written`]).
const RUNNING_BOND: [[f64; 3]; 7] = [
    [0.0, 0.5, 0.0],
    [0.5, 1.0, 0.0],
    [1.0, 1.5, 0.0],
    [0.0, 0.25, 0.25],
    [0.25, 0.75, 0.25],
    [0.75, 1.25, 0.25],
    [1.25, 1.5, 0.25],
];

/// The horizontal unit vector square to a wall turned `degrees` about the vertical: its own y.
fn out_of_plane(degrees: f64) -> Vector3<f64> {
    let a = degrees.to_radians();
    Vector3::new(-a.sin(), a.cos(), 0.0)
}

/// A wall of two courses in running bond, 1.5 m long (three blocks under two and two half
/// blocks), loaded out of its plane: written exactly at the origin its multiplier is 0.514286,
/// found among the joints that open and slide (its middle lower block and the two blocks over
/// it turn out of the wall about the lower block's foot, sliding in the head joints on either
/// side); turned 40° at survey coordinates with fifteen decimals it answered 0.545455, marked
/// exhaustive: round-off left the middle block's two head joints 1e-10 rad from parallel, so
/// that it could not turn between them without closing one (an independent review). The
/// statics take the faces' directions at the model's precision: the same multiplier, to 1e-7.
#[test]
fn a_wall_at_survey_coordinates_turns_out_of_its_plane_as_written_exactly() {
    let exact = written("bond", &RUNNING_BOND, 0.0, [0.0; 3], 15);
    let reference =
        collapse_multiplier(&exact, out_of_plane(0.0), &StaticsOptions::default()).unwrap();
    let lambda = reference.lambda.unwrap();
    assert!(reference.exhaustive);
    assert!((lambda - 0.514286).abs() < 1e-6, "{lambda}");
    let survey = written(
        "bond",
        &RUNNING_BOND,
        40.0,
        [500_000.0, 4_500_000.0, 350.0],
        15,
    );
    let c = collapse_multiplier(&survey, out_of_plane(40.0), &StaticsOptions::default()).unwrap();
    let got = c.lambda.unwrap();
    assert!(c.exhaustive, "{got}");
    assert!(
        (got - lambda).abs() < 1e-7 * lambda,
        "{got} against {lambda}"
    );
}

/// The same wall turned 30° and written with six decimals, as CAD programs write it: its corners
/// are off by up to 5e-7 m, so each block of the upper course, centred over a head joint below,
/// no longer balances on either half. As written, the program with one half's joint unloaded has
/// no equilibrium, the pass dropped that set and every set below it (the wall's own collapse
/// among them), and answered 0.545455 marked exhaustive (an end block and the block over it),
/// both ways out of the plane, where the wall's multiplier is 0.514286. At the model's precision
/// (each body in equilibrium to 1e-5 of its weight) the pass finds the wall's own collapse, to
/// the model's precision, both ways.
#[test]
fn a_wall_written_with_six_decimals_turns_out_of_its_plane_as_written_exactly() {
    let exact = written("bond", &RUNNING_BOND, 0.0, [0.0; 3], 15);
    let rounded = written("bond", &RUNNING_BOND, 30.0, [0.0; 3], 6);
    for sign in [1.0, -1.0] {
        let reference =
            collapse_multiplier(&exact, sign * Vector3::y(), &StaticsOptions::default()).unwrap();
        let lambda = reference.lambda.unwrap();
        assert!(reference.exhaustive);
        let c = collapse_multiplier(
            &rounded,
            sign * out_of_plane(30.0),
            &StaticsOptions::default(),
        )
        .unwrap();
        let got = c.lambda.unwrap();
        assert!(c.exhaustive, "{sign:+}: {got}, {:?}", c.unexhausted);
        assert!(
            (got - lambda).abs() < 1e-5 * lambda,
            "{sign:+}: {got} against {lambda}"
        );
    }
}

/// Writing the blocks of a rounded wall in another order changes no multiplier. The statics
/// take each direction of the faces' frames at the model's precision from the first face that
/// meets it ([`crr_impact::statics`]'s precision module), so another order may choose another
/// representative, 1e-5 rad away at most; the multiplier must not follow. The six-decimal wall
/// above, its blocks written in three orders, out of its plane both ways (its mechanism slides
/// in the head joints, whose normals are the ones rounded): the same λ to 1e-9, exhaustive.
#[test]
fn the_order_of_a_rounded_file_changes_no_multiplier() {
    let orders: [[usize; 7]; 3] = [
        [0, 1, 2, 3, 4, 5, 6],
        [6, 5, 4, 3, 2, 1, 0],
        [3, 0, 6, 1, 5, 2, 4],
    ];
    for direction in [out_of_plane(30.0), -out_of_plane(30.0)] {
        let answers: Vec<(f64, bool)> = orders
            .iter()
            .map(|order| {
                let blocks: Vec<[f64; 3]> = order.iter().map(|&k| RUNNING_BOND[k]).collect();
                let model = written("ordered", &blocks, 30.0, [0.0; 3], 6);
                let c = collapse_multiplier(&model, direction, &StaticsOptions::default()).unwrap();
                (c.lambda.unwrap(), c.exhaustive)
            })
            .collect();
        for (order, &(lambda, exhaustive)) in orders.iter().zip(&answers) {
            assert!(exhaustive, "{order:?} along {direction:?}: {lambda}");
            assert!(
                same(lambda, answers[0].0),
                "{order:?} along {direction:?}: {lambda} against {}",
                answers[0].0
            );
        }
    }
}

/// DOF(2) at the model's precision is the mobility of the structure as meant. The wall above
/// (every contact a joint, 7 loops) turned 30°: written with fifteen decimals its loops close
/// exactly; with six (corners off by up to 5e-7 m) they no longer do, and DOF(2) as written
/// drops (to 0, "locked"), while at the model's precision it is the exact wall's.
#[test]
fn dof2_at_the_model_s_precision_is_the_exact_wall_s() {
    let at_rest = |model: &Model| {
        crr::dynamics::mobility(
            model,
            &nalgebra::DVector::zeros(model.dof()),
            &crr::kinematics::ActivePivots::uniform(model, crr::kinematics::Side::Positive),
        )
    };
    let rounded_model = written("mobile", &RUNNING_BOND, 30.0, [0.0; 3], 6);
    let exact = at_rest(&written("mobile", &RUNNING_BOND, 30.0, [0.0; 3], 15));
    let rounded = at_rest(&rounded_model);
    assert_eq!(exact.dof2_at_precision, exact.dof2);
    assert!(
        exact.dof2 > 0,
        "the exact wall moves: DOF(2) = {}",
        exact.dof2
    );
    assert!(
        rounded.dof2 < exact.dof2,
        "rounded {} against {}",
        rounded.dof2,
        exact.dof2
    );
    assert_eq!(rounded.dof2_at_precision, exact.dof2);
    // `crr check` says so beside DOF(2) as written.
    let report = crr::analysis::check::check_with(&rounded_model, &[], &Default::default())
        .expect("nothing asks it to stop");
    let text = crr::analysis::check::to_text(&report);
    let line = format!("DOF(2) at the model's precision = {}:", exact.dof2);
    assert!(text.contains(&line), "{text}");
}
