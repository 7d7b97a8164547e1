//! Collapses certified as collapse states from first principles, with no code of the statics.
//!
//! Where a block turns about one support while it slides over another with no force on it (a
//! block against a pier turning about its far foot slides up the pier at its lowest edge; a wall's
//! end half block turning about its outer foot slides up its head joint), the program without
//! sliding cannot answer, and `statics::collapse_multiplier` searches for such mechanisms. Its
//! answer is not a bound by the static theorem (the sliding is not associated with friction), and
//! the program without sliding lets a contact carry shear with no compression, even across a
//! joint that opens. So each answer is checked here as what it claims to be, a collapse state:
//!
//! - **an admissible mechanism**: from the bodies' virtual velocities and the model's own corners
//!   and normals (`InterfaceKind`), no point penetrates, and a hinge that keeps contact turns
//!   about its axis only;
//! - **work**: the load's virtual power balances the weight's, λ_kin = −Σ mᵢ ẑ·vᵢ / Σ mᵢ d·vᵢ = λ;
//! - **an equilibrium on the points that hold**: an LP written here finds forces at λ acting only
//!   at the points the mechanism keeps in contact without sliding (a compressive normal force and
//!   any shear; a hinge that keeps contact also carries couples out of its plane, a pin any
//!   force), balancing every body's weight and the load −λ m g d (in a planar model the in-plane
//!   rows: the hinges carry the rest bilaterally). A point that separates or slides carries
//!   nothing. Such forces do no virtual work, so they exist at λ_kin alone.
//!
//! Together: at λ the structure has an equilibrium and a motion consistent with it, so it can move
//! from λ on. That makes λ an upper bound of the multiplier, not its value: a lower collapse state
//! may exist (docs/simulation.md, "Joints that open may slide"), and the hand values below are
//! those of the mechanisms named. Tolerances: the mechanism is scaled to unit speed and the solver's gaps are
//! 1e-12 of the weight, so rates are zero to 1e-7 and both λ agree to 1e-7 relative.
use std::path::Path;

use nalgebra::Vector3;

use crr::analysis::assemble::{AssemblyOptions, assemble, read_assembly};
use crr::impact::statics::{Collapse, StaticsOptions, collapse_multiplier};
use crr::kinematics::{InterfaceKind, Model, Parent};

use crate::common;
use crate::common::{BUNDLED_STATICS, box_body};
use crate::duality::point_velocity;
use crate::independent::Lp;

/// A body's virtual velocity (v at the centre of mass, ω).
type Velocity = (Vector3<f64>, Vector3<f64>);

/// The contact points and the normal (into the child) of interface `k`, from the model alone;
/// a pin (a hinge whose two pivots coincide) has no normal: `None`.
fn points_and_normal(model: &Model, k: usize) -> (Vec<Vector3<f64>>, Option<Vector3<f64>>) {
    match &model.interfaces[k].kind {
        InterfaceKind::RockingBase {
            corners, normal, ..
        } => (corners.to_vec(), Some(*normal)),
        InterfaceKind::Hinge {
            axis,
            pivot_positive,
            pivot_negative,
        } => {
            let n = axis.cross(&(pivot_negative - pivot_positive));
            let normal = (n.norm() > 1e-9 * model.size).then(|| n.normalize());
            (vec![*pivot_positive, *pivot_negative], normal)
        }
    }
}

/// A point that keeps contact without sliding in the mechanism, where forces may act: a
/// compressive normal force and any shear, or any force at a pin (`normal` None); and the
/// couples a hinge that keeps contact carries about the `couples` axes (normal to its axis, in a
/// model that is not planar: a line joint transmits them bilaterally).
struct Holding {
    body: usize,
    parent: Parent,
    point: Vector3<f64>,
    normal: Option<Vector3<f64>>,
    couples: Vec<Vector3<f64>>,
}

/// Checks that `c` is a collapse state of `model` along `d` (see the module's docs) and returns
/// λ_kin. In a planar model (hinges about one axis a) the in-plane rows only: what the hinges
/// carry along a and about axes normal to a is bilateral; elsewhere a hinge that keeps contact
/// carries any couple out of its plane (a line joint), and a pin any force.
fn certify(model: &Model, d: Vector3<f64>, c: &Collapse) -> f64 {
    let lambda = c.lambda.expect("a mechanism");
    let holding = holding_points(model, c);
    let bodies: Vec<Velocity> = c
        .bodies
        .iter()
        .map(|b| (Vector3::from(b.velocity), Vector3::from(b.angular)))
        .collect();
    let kinematic = kinematic_multiplier(model, d, &bodies);
    assert!(
        (kinematic - lambda).abs() <= 1e-7 * lambda,
        "static {lambda}, kinematic {kinematic}"
    );
    let statical = equilibrium_on(model, d, model.planar_axis(), &holding, None)
        .unwrap_or_else(|status| panic!("no equilibrium on the points that hold: {status:?}"));
    assert!(
        (statical - lambda).abs() <= 1e-7 * lambda,
        "engine {lambda}, equilibrium on the points that hold {statical}"
    );
    kinematic
}

/// The points the collapse's mechanism keeps in contact without sliding, after asserting the
/// mechanism admissible (from the bodies' velocities and the model's own geometry).
fn holding_points(model: &Model, c: &Collapse) -> Vec<Holding> {
    let rate_tol = 1e-7;
    let size = model.size;
    let planar = model.planar_axis();
    let bodies: Vec<Velocity> = c
        .bodies
        .iter()
        .map(|b| (Vector3::from(b.velocity), Vector3::from(b.angular)))
        .collect();
    // The mechanism: admissible, and the points that hold.
    let mut holding = Vec::new();
    for (k, interface) in model.interfaces.iter().enumerate() {
        let name = &interface.name;
        let (points, normal) = points_and_normal(model, k);
        let relative = |x: &Vector3<f64>| {
            point_velocity(model, &bodies, Parent::Body(interface.child), x)
                - point_velocity(model, &bodies, interface.parent, x)
        };
        let Some(normal) = normal else {
            // A pin turns about its point: no relative velocity there.
            assert!(relative(&points[0]).norm() < rate_tol, "{name}: pin");
            holding.push(Holding {
                body: interface.child,
                parent: interface.parent,
                point: points[0],
                normal: None,
                couples: hinge_couples(&interface.kind, planar),
            });
            continue;
        };
        let opens = points.iter().all(|p| normal.dot(&relative(p)) > rate_tol);
        if let InterfaceKind::Hinge { axis, .. } = &interface.kind
            && !opens
        {
            let parent_w = match interface.parent {
                Parent::Ground => Vector3::zeros(),
                Parent::Body(n) => bodies[n].1,
            };
            let w = bodies[interface.child].1 - parent_w;
            assert!(
                (w - axis * axis.dot(&w)).norm() * size < rate_tol,
                "{name}: {w}"
            );
        }
        let mut couples = if opens {
            Vec::new()
        } else {
            hinge_couples(&interface.kind, planar)
        };
        // A rocking base that keeps a single corner and does not turn about its normal (it cannot
        // twist) carries the couple about n of that constraint, which then does no virtual work.
        let holds = |p: &Vector3<f64>| {
            let v = relative(p);
            let gap = normal.dot(&v);
            gap <= rate_tol && (v - normal * gap).norm() <= rate_tol
        };
        if matches!(interface.kind, InterfaceKind::RockingBase { .. })
            && points.iter().filter(|p| holds(p)).count() == 1
        {
            let parent_w = match interface.parent {
                Parent::Ground => Vector3::zeros(),
                Parent::Body(n) => bodies[n].1,
            };
            let twist = normal.dot(&(bodies[interface.child].1 - parent_w));
            if twist.abs() * size < rate_tol {
                couples.push(normal);
            }
        }
        for p in points {
            let v = relative(&p);
            let gap = normal.dot(&v);
            assert!(gap > -rate_tol, "{name}: penetrates at {p}");
            let slip = v - normal * gap;
            let slip = planar.map_or(slip, |a| slip - a * a.dot(&slip)).norm();
            if gap <= rate_tol && slip <= rate_tol {
                holding.push(Holding {
                    body: interface.child,
                    parent: interface.parent,
                    point: p,
                    normal: Some(normal),
                    couples: std::mem::take(&mut couples),
                });
            }
        }
    }
    holding
}

/// The bodies a holding point's forces act on, with their signs (child +, parent −).
fn bodies_of(h: &Holding) -> Vec<(usize, f64)> {
    match h.parent {
        Parent::Body(parent) => vec![(h.body, 1.0), (parent, -1.0)],
        Parent::Ground => vec![(h.body, 1.0)],
    }
}

/// The axes of the couples a hinge carries out of its plane in a model that is not planar (two
/// unit vectors normal to its axis); none for a rocking base or in a planar model.
fn hinge_couples(kind: &InterfaceKind, planar: Option<Vector3<f64>>) -> Vec<Vector3<f64>> {
    match kind {
        InterfaceKind::Hinge { axis, .. } if planar.is_none() => {
            let e1 = if axis.cross(&Vector3::x()).norm() > 0.5 {
                axis.cross(&Vector3::x()).normalize()
            } else {
                axis.cross(&Vector3::y()).normalize()
            };
            vec![e1, axis.cross(&e1)]
        }
        _ => Vec::new(),
    }
}

/// λ_kin = −Σ mᵢ ẑ·vᵢ / Σ mᵢ d·vᵢ, the load doing positive work.
fn kinematic_multiplier(model: &Model, d: Vector3<f64>, bodies: &[Velocity]) -> f64 {
    let power = |along: Vector3<f64>| -> f64 {
        model
            .bodies
            .iter()
            .zip(bodies)
            .map(|(b, (v, _))| -b.mass * along.dot(v))
            .sum()
    };
    let load_power = power(d);
    assert!(load_power > 0.0, "the load does positive work");
    -power(Vector3::z()) / load_power
}

/// The largest λ (≤ 10) with an equilibrium of every body under its weight and −λ m g d whose
/// forces act at the points `holding` only (a compressive normal force, any shear; in a planar
/// model the in-plane rows), by an LP written here. Where the mechanism's points that hold carry
/// such an equilibrium, its forces do no virtual work, so it exists at λ_kin alone.
fn equilibrium_on(
    model: &Model,
    d: Vector3<f64>,
    planar: Option<Vector3<f64>>,
    holding: &[Holding],
    friction: Option<f64>,
) -> Result<f64, clarabel::solver::SolverStatus> {
    let weight = model.bodies.iter().map(|b| b.mass).sum::<f64>() * model.gravity;
    let size = model.size;
    // Rows kept: force components and moment components (of a body's 6).
    let (force_axes, moment_axes): (Vec<Vector3<f64>>, Vec<Vector3<f64>>) = match planar {
        Some(a) => {
            let e1 = a.cross(&Vector3::z()).normalize();
            (vec![e1, a.cross(&e1)], vec![a])
        }
        None => (
            vec![Vector3::x(), Vector3::y(), Vector3::z()],
            vec![Vector3::x(), Vector3::y(), Vector3::z()],
        ),
    };
    let rows_per_body = force_axes.len() + moment_axes.len();
    // Unknowns: λ, then per point three force components (units of the weight W) and the
    // couples of its hinge.
    let mut lp_le = Vec::new();
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); rows_per_body * model.bodies.len()];
    let mut rhs = vec![0.0; rows.len()];
    for (n, b) in model.bodies.iter().enumerate() {
        let share = b.mass * model.gravity / weight;
        for (k, e) in force_axes.iter().enumerate() {
            // Σ F − λ share d = share ẑ.
            rows[rows_per_body * n + k].push((0, -share * e.dot(&d)));
            rhs[rows_per_body * n + k] = share * e.z;
        }
    }
    let mut column = 1;
    for h in holding {
        // Forces: (direction, compressive only) at the point; couples: moment only.
        let forces: Vec<(Vector3<f64>, bool)> = match h.normal {
            Some(n) => {
                let t1 = if n.cross(&Vector3::x()).norm() > 0.5 {
                    n.cross(&Vector3::x()).normalize()
                } else {
                    n.cross(&Vector3::y()).normalize()
                };
                vec![(n, true), (t1, false), (n.cross(&t1), false)]
            }
            None => vec![
                (Vector3::x(), false),
                (Vector3::y(), false),
                (Vector3::z(), false),
            ],
        };
        let mut add =
            |column: usize, force: Vector3<f64>, moment: Vector3<f64>, body: usize, sign: f64| {
                for (k, e) in force_axes.iter().enumerate() {
                    rows[rows_per_body * body + k].push((column, sign * e.dot(&force)));
                }
                for (k, e) in moment_axes.iter().enumerate() {
                    rows[rows_per_body * body + force_axes.len() + k]
                        .push((column, sign * e.dot(&moment)));
                }
            };
        let normal_column = column;
        for (direction, compressive) in forces {
            for (body, sign) in bodies_of(h) {
                let arm = (h.point - model.bodies[body].com).cross(&direction) / size;
                add(column, direction, arm, body, sign);
            }
            if compressive {
                lp_le.push((vec![(column, -1.0)], 0.0));
            } else if let (Some(mu), Some(_)) = (friction, h.normal) {
                // Coulomb's pyramid on each tangent: |f_t| ≤ μ fₙ.
                lp_le.push((vec![(column, 1.0), (normal_column, -mu)], 0.0));
                lp_le.push((vec![(column, -1.0), (normal_column, -mu)], 0.0));
            }
            column += 1;
        }
        // A couple in units of W·L: its moment rows' entry is its axis.
        for &axis in &h.couples {
            for (body, sign) in bodies_of(h) {
                add(column, Vector3::zeros(), axis, body, sign);
            }
            column += 1;
        }
    }
    let mut lp = Lp::new(column);
    lp.cost[0] = -1.0;
    lp.le = lp_le;
    lp.eq = rows.into_iter().zip(rhs).collect();
    lp.le.push((vec![(0, 1.0)], 10.0));
    lp.solve().map(|solution| solution.x[0])
}

fn assembled(path: &Path, planar: bool) -> Model {
    let file = read_assembly(path).unwrap();
    let options = AssemblyOptions {
        planar,
        ..AssemblyOptions::default()
    }
    .with_all_contacts();
    assemble(path, &file, &options).unwrap().model
}

fn collapse(model: &Model, d: Vector3<f64>) -> Collapse {
    collapse_multiplier(model, d, &StaticsOptions::default()).unwrap()
}

/// A block 0.4 m (x) × 1 m (y) × 1 m high standing against the +x face of a pier 2 m high, every
/// contact an interface. Away from the pier (−x) it turns about its far foot and slides up the
/// pier at its lowest edge, which carries nothing: λ = b/h = 0.4/1 by the virtual work of the
/// block alone; the program without sliding forbids that slip and finds it holding up to the cap
/// (a fixed pier). Across (±y) it turns about its base's edge, its face sliding over the pier's:
/// λ = 1/1. Into a fixed pier (+x) it cannot move. With the pier a free block the same block
/// overturns away from it at 0.4 (the pier alone: 0.5/1, and pushing the block into it loads
/// both).
#[test]
fn a_block_against_a_pier_overturns_away_from_it_at_b_over_h() {
    let dir = common::scratch("statics_pier");
    for fixed in [true, false] {
        let text = format!(
            "name = \"infill\"\n{}{}{}",
            if fixed { "fixed = [\"pier\"]\n" } else { "" },
            box_body("pier", [-0.5, 0.0, 1.0], [1.0, 1.0, 2.0]),
            box_body("block", [0.2, 0.0, 0.5], [0.4, 1.0, 1.0]),
        );
        let path = dir.join(format!("pier_{fixed}.toml"));
        std::fs::write(&path, text).unwrap();
        let model = assembled(&path, false);
        let away = collapse(&model, -Vector3::x());
        assert!(away.from_sliding_search());
        certify(&model, -Vector3::x(), &away);
        let into = collapse(&model, Vector3::x());
        if fixed {
            assert_eq!(into.lambda, None);
            assert_eq!(away.convex_lambda, None, "holds without sliding");
            for d in [Vector3::y(), -Vector3::y()] {
                let across = collapse(&model, d);
                assert!((across.lambda.unwrap() - 1.0).abs() < 1e-7);
                certify(&model, d, &across);
            }
        } else {
            certify(&model, Vector3::x(), &into);
            // Across, the pier (1 × 1 × 2 m) tips alone about its base edge, its face sliding
            // past the block's with no force on it: b/h = 1/2.
            for d in [Vector3::y(), -Vector3::y()] {
                let across = collapse(&model, d);
                assert!(
                    (across.lambda.unwrap() - 0.5).abs() < 1e-7,
                    "{:?}",
                    across.lambda
                );
                certify(&model, d, &across);
            }
        }
    }
}

/// The same block between two fixed piers, touching both: along the line of the piers it cannot
/// turn (its diagonal would cut into one of them), and across it tips about its base edge with
/// both side faces sliding unloaded, λ = b/h = 1/1 (found holding up to the cap before the
/// search's rigid wedges, 2026-12-03).
#[test]
fn a_block_between_two_piers_tips_across_them_at_b_over_h() {
    let dir = common::scratch("statics_between_piers");
    let text = format!(
        "name = \"between\"\nfixed = [\"left\", \"right\"]\n{}{}{}",
        box_body("left", [-0.5, 0.0, 1.0], [1.0, 1.0, 2.0]),
        box_body("right", [0.9, 0.0, 1.0], [1.0, 1.0, 2.0]),
        box_body("block", [0.2, 0.0, 0.5], [0.4, 1.0, 1.0]),
    );
    let path = dir.join("between.toml");
    std::fs::write(&path, text).unwrap();
    let model = assembled(&path, false);
    for d in [Vector3::x(), -Vector3::x()] {
        assert_eq!(collapse(&model, d).lambda, None);
    }
    for d in [Vector3::y(), -Vector3::y()] {
        let across = collapse(&model, d);
        assert!(
            (across.lambda.unwrap() - 1.0).abs() < 1e-7,
            "{:?}",
            across.lambda
        );
        certify(&model, d, &across);
    }
}

/// The kinematic multiplier of a staircase wedge in running bond, by virtual work about the outer
/// foot of the end half block of course 1: courses k = 1…n above that foot, course k spanning
/// k·s from the wall's end (s the half block's length, the step of the bond) with its centre at
/// height (k − ½)h above the foot. Its weight ∝ k·s·h; the weight's virtual power ∝ Σ k s (k s/2)
/// and the load's ∝ Σ k s (k − ½) h, so
///
///   λ = (s/2) Σk² / (h (Σk² − Σk/2)) = (s/h)(2n + 1)/(4n − 1),
///
/// falling towards s/(2h) as the wedge deepens.
fn staircase(s: f64, h: f64, n: usize) -> f64 {
    let n = n as f64;
    s / h * (2.0 * n + 1.0) / (4.0 * n - 1.0)
}

/// The bodies the collapse's mechanism moves (speed above 1e-7 of the largest, which is 1).
fn moving(model: &Model, c: &Collapse) -> Vec<String> {
    c.bodies
        .iter()
        .zip(&model.bodies)
        .filter(|(m, _)| {
            Vector3::from(m.velocity).norm() > 1e-7
                || model.size * Vector3::from(m.angular).norm() > 1e-7
        })
        .map(|(_, b)| b.name.clone())
        .collect()
}

/// The bundled running-bond wall (8 courses of 0.25 m, blocks 0.6 m long), planar, with its head
/// joints as contacts: its corner wedge, the staircase of 16 blocks over the outer foot of course
/// 1's end half block (1, 1, 2, 2, 3, 3, 4 blocks in courses 1 to 7), turns about that foot, its
/// head and bed joints opening and sliding: λ = (0.3/0.25)(15/27) = 2/3 ([`staircase`], n = 7),
/// below the 1.5 of the whole wall overturning (the program without sliding) and the 1.2 of the
/// top course's end half block alone (the answer before the wedges, 2026-12-03).
#[test]
fn the_running_bond_wall_loses_its_corner_wedge() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assemblies/wall.toml");
    let model = assembled(&path, true);
    for (d, end) in [(Vector3::x(), "c1_b0"), (-Vector3::x(), "c1_b5")] {
        let c = collapse(&model, d);
        let hand = staircase(0.3, 0.25, 7);
        assert!((hand - 2.0 / 3.0).abs() < 1e-15);
        assert!((c.lambda.unwrap() - hand).abs() < 1e-7, "{:?}", c.lambda);
        assert!((c.convex_lambda.unwrap() - 1.5).abs() < 1e-7);
        let wedge = moving(&model, &c);
        assert_eq!(wedge.len(), 16, "{wedge:?}");
        assert!(wedge.iter().any(|b| b == end), "{wedge:?}");
        assert!(wedge.iter().all(|b| !b.starts_with("c0_")), "{wedge:?}");
        certify(&model, d, &c);
    }
}

/// The friction a collapse state relies on (`statics::state_friction`, the μ `crr check` reports
/// for an answer of the search): with Coulomb's pyramid μ at the points the wall's corner wedge
/// keeps in contact (and nothing elsewhere), the LP written here reaches its λ = 2/3 at 1.001 μ
/// and not at 0.999 μ (the engine's bisection stops at 1e-4 of μ). It is more than the friction
/// the convex program needs to reach 2/3 with every point loaded (`required_friction`, 0.7134):
/// an independent review's LP found 0.7468 for the wedge.
#[test]
fn the_corner_wedge_needs_the_friction_its_holding_points_carry() {
    use crr::impact::statics::{required_friction, state_friction};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assemblies/wall.toml");
    let model = assembled(&path, true);
    let d = Vector3::x();
    let c = collapse(&model, d);
    let lambda = c.lambda.unwrap();
    let mu = state_friction(&model, &c, 10.0).unwrap().unwrap();
    let convex = required_friction(&model, d, 10.0, lambda).unwrap();
    assert!(mu > convex + 0.02, "{mu} against {convex}");
    assert!((mu - 0.7468).abs() < 1e-3, "{mu}");
    let holding = holding_points(&model, &c);
    let equilibrium = |mu: f64| equilibrium_on(&model, d, model.planar_axis(), &holding, Some(mu));
    let target = lambda * (1.0 - 1e-6);
    assert!(equilibrium(mu * 1.001).is_ok_and(|l| l >= target));
    // Below, the LP proves it: infeasible (no equilibrium on those points at any λ ≥ 0) or a
    // lower λ, not a solver that stopped.
    match equilibrium(mu * 0.999) {
        Ok(l) => assert!(l < target, "{l} at 0.999 μ"),
        Err(status) => assert_eq!(status, clarabel::solver::SolverStatus::PrimalInfeasible),
    }
}

/// The bundled façade with a door, planar, every contact an interface: the corner wedge of 12
/// blocks over the outer foot of course 1's end half block (0.25 m, courses of 0.3 m) turns about
/// that foot: λ = (0.25/0.3)(13/23) = 65/138 = 0.471014 ([`staircase`], n = 6), below the 1.25 of
/// the program without sliding (the portal frame of its two piers and the lintel zone) and the
/// 25/42 of the top-corner wedge of two blocks the search answered before the wedges. It is a
/// collapse state, and the façade being symmetric about x = 0, both directions give it (1e-7).
/// (A search that only unloaded a freed joint's sliding points answered 1.000484 and 1.001462,
/// from mechanisms with no equilibrium on the points that hold.)
#[test]
fn the_facade_collapses_where_its_search_says() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assemblies/facade.toml");
    let model = assembled(&path, true);
    let hand = staircase(0.25, 0.3, 6);
    assert!((hand - 65.0 / 138.0).abs() < 1e-15);
    let lambdas: Vec<f64> = [Vector3::x(), -Vector3::x()]
        .into_iter()
        .map(|d| {
            let c = collapse(&model, d);
            let lambda = c.lambda.unwrap();
            assert!((lambda - hand).abs() < 1e-7, "{d:?}: {lambda}");
            assert!(c.from_sliding_search());
            assert!((c.convex_lambda.unwrap() - 1.25).abs() < 1e-7);
            assert_eq!(moving(&model, &c).len(), 12);
            certify(&model, d, &c)
        })
        .collect();
    assert!(
        (lambdas[0] - lambdas[1]).abs() <= 1e-7 * lambdas[0],
        "{lambdas:?}"
    );
}

/// A planar wall in running bond of `courses` courses of `blocks` blocks 0.6 × 0.3 × 0.25 m,
/// odd courses offset by half a block with half blocks at their ends, centred on x = 0.
fn running_bond(courses: usize, blocks: usize) -> String {
    let (length, height) = (0.6, 0.25);
    let half_width = blocks as f64 * length / 2.0;
    let mut text = format!("name = \"wall_{courses}x{blocks}\"\n");
    for c in 0..courses {
        let mut ends: Vec<f64> = (0..=blocks)
            .map(|i| -half_width + i as f64 * length)
            .collect();
        if c % 2 == 1 {
            ends = std::iter::once(-half_width)
                .chain((0..blocks).map(|i| -half_width + (i as f64 + 0.5) * length))
                .chain(std::iter::once(half_width))
                .collect();
        }
        for (i, w) in ends.windows(2).enumerate() {
            let centre = [(w[0] + w[1]) / 2.0, 0.0, (c as f64 + 0.5) * height];
            text += &box_body(&format!("c{c}_b{i}"), centre, [w[1] - w[0], 0.3, height]);
        }
    }
    text
}

/// Walls in running bond of 3 to 6 courses, every contact an interface (head joints included),
/// planar and, for two of them, in 3D: each loses the staircase wedge over its end half block of
/// course 1, λ = 1.2 (2n + 1)/(4n − 1) with n = courses − 1 ([`staircase`]): 6/7 for 3 courses,
/// 42/55 for 4, 18/25 for 5, 66/95 for 6, the same along ±x, each a collapse state. Before the
/// wedges (2026-12-03) the answers were those without sliding, with no caveat: 1.6 (3 × 2), 2.4
/// (3 × 3), 1.2 (4 × 2), 2.4 (5 × 5), which an independent review's LP showed to be above these
/// wedges.
#[test]
fn walls_in_running_bond_lose_the_staircase_over_their_end_half_block() {
    let dir = common::scratch("statics_running_bond");
    for (courses, blocks, planar) in [
        (3, 2, true),
        (3, 3, true),
        (4, 2, true),
        (4, 3, true),
        (5, 5, true),
        (6, 4, true),
        (3, 2, false),
        (4, 3, false),
    ] {
        let path = dir.join(format!("wall_{courses}x{blocks}.toml"));
        std::fs::write(&path, running_bond(courses, blocks)).unwrap();
        let model = assembled(&path, planar);
        let hand = staircase(0.3, 0.25, courses - 1);
        for d in [Vector3::x(), -Vector3::x()] {
            let c = collapse(&model, d);
            let lambda = c.lambda.unwrap();
            assert!(
                (lambda - hand).abs() < 1e-7,
                "{courses} × {blocks} (planar {planar}) along {d:?}: {lambda}, by hand {hand}"
            );
            certify(&model, d, &c);
        }
    }
}

/// The bundled wall in 3D with every contact an interface, out of its plane (±y): whatever the
/// search answers (a part of the wall turning about a base edge, its head joints sliding with no
/// force on them) is a collapse state, and at most the 0.15/1 = t/h of the wall overturning
/// whole about a base edge (its program without sliding).
#[test]
fn the_wall_out_of_its_plane_collapses_where_its_search_says() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/assemblies/wall.toml");
    let model = assembled(&path, false);
    for d in [Vector3::y(), -Vector3::y()] {
        let c = collapse(&model, d);
        let lambda = c.lambda.unwrap();
        assert!(lambda <= 0.15 * (1.0 + 1e-7), "{lambda}");
        assert!((c.convex_lambda.unwrap() - 0.15).abs() < 1e-7);
        certify(&model, d, &c);
    }
}

/// A slab on four columns (beds only), loaded obliquely along (0.3, 1, 0): the slab lifts off
/// one column, which stays at rest, and rests on a single corner of each of the other three,
/// which tip about their bases' −y edges. Its equilibrium on the points that hold needs, at each
/// single corner, the couple about the face normal that a rocking base's no-twist constraint
/// carries (without it there is none: checked here), so the state needs unbounded friction, as
/// the program without sliding's own answer 0.149064 does, which rests on the same reactions
/// and which the engine gave, marked exhaustive, until 2026-12-06. An independent review's
/// mixed-integer program (2026-12-06, its own code, HiGHS) found this state at 0.1408290185,
/// the least collapse of the contact model with that reaction: agreed here to 1e-9.
#[test]
fn a_slab_on_four_columns_rests_on_single_corners_of_three() {
    use crr::impact::statics::state_friction;
    let dir = common::scratch("statics_slab_on_columns");
    let mut text = String::from("name = \"frame\"\n");
    for (name, centre, size) in [
        ("c0", [-0.84, -0.55, 1.48], [0.34, 0.4, 2.96]),
        ("c1", [-0.84, 0.55, 1.48], [0.34, 0.36, 2.96]),
        ("c2", [0.84, -0.55, 1.48], [0.44, 0.42, 2.96]),
        ("c3", [0.84, 0.55, 1.48], [0.36, 0.48, 2.96]),
        ("slab", [-0.14, -0.06, 3.08], [2.28, 1.7, 0.24]),
    ] {
        text += &box_body(name, centre, size);
    }
    let path = dir.join("frame.toml");
    std::fs::write(&path, text).unwrap();
    let file = read_assembly(&path).unwrap();
    let model = assemble(&path, &file, &AssemblyOptions::default())
        .unwrap()
        .model;
    let d = Vector3::new(0.3, 1.0, 0.0).normalize();
    let c = collapse(&model, d);
    let lambda = c.lambda.unwrap();
    assert!((lambda - 0.1408290185).abs() < 1e-9, "{lambda}");
    assert!(c.exhaustive);
    assert!((c.convex_lambda.unwrap() - 0.149064).abs() < 1e-6);
    certify(&model, d, &c);
    // The slab lifts off c3, which stays at rest; it keeps one corner on each other column.
    let of = |name: &str| c.interfaces.iter().find(|i| i.name == name).unwrap();
    assert!(of("slab_on_c3").forces.iter().all(|f| f.normal == 0.0));
    assert!(c.bodies[3].velocity.iter().all(|v| v.abs() < 1e-9));
    for column in ["c0", "c1", "c2"] {
        assert_eq!(of(&format!("slab_on_{column}")).pivots.len(), 1, "{column}");
    }
    // Without the twist reactions the points that hold carry no equilibrium at λ.
    let point_forces_only: Vec<Holding> = holding_points(&model, &c)
        .into_iter()
        .map(|h| Holding {
            couples: Vec::new(),
            ..h
        })
        .collect();
    if let Ok(strict) = equilibrium_on(&model, d, None, &point_forces_only, None) {
        assert!(strict < 0.99 * lambda, "{strict}");
    }
    // Point forces cannot carry those couples, whatever the friction.
    let mu = state_friction(&model, &c, 10.0).unwrap().unwrap();
    assert!(mu.is_infinite(), "{mu}");
}

/// Every bundled model's multipliers along ±x and ±y are collapse states in the sense above:
/// the program without sliding's answers (most of them) and the search's (the 4 × 3 wall's
/// corner wedge, 7/11) alike have an equilibrium on the points their mechanism keeps in contact.
#[test]
fn every_bundled_multiplier_is_a_collapse_state() {
    for name in BUNDLED_STATICS {
        let model = common::bundled_model(name);
        for d in [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()] {
            let c = collapse(&model, d);
            if c.lambda.is_some() {
                certify(&model, d, &c);
            }
        }
    }
}
