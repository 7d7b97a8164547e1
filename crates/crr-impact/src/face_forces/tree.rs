//! The contact impulses of an open chain, interface by interface.
//!
//! Where the interfaces form a tree (every body the child of exactly one interface, no loop),
//! the impulse an interface transmits is fixed by statics: summing the equilibrium rows of the
//! bodies above it (its child's subtree) cancels every interface inside the subtree, so the
//! interface gives that subtree its whole momentum change, the wrench
//! (Σ m_b Δċ_b, Σ [I_b Δω_b + (c_b − o) × m_b Δċ_b]) about a point o. The program of
//! [`super::most_compressive_impulses`] then splits into one small program per interface:
//! max s over its touching points' forces and couples that give that wrench, with fₙ ≥ s at its
//! unilateral points. Its free columns (tangential forces, couples, a pin's force, the normal
//! forces of slots set by law) are eliminated by projecting the six rows onto the complement of
//! their span; what is left, B fₙ = c, fixes the normal forces when B has full column rank (a
//! seated hinge: its two pivot lines' normal forces from the force along n and the moment about
//! the hinge's axis, a 2 × 2 solve) or leaves one free parameter (a base seated on its four
//! corners: three rows, the force along n and the two tilting moments), where
//! max over α of minᵢ (f₀ᵢ + α vᵢ) is reached where two of the lines cross. s* is the least of
//! the interfaces' optima (capped at 0, as the global program's), the global program's answer
//! without its proximal term: a few 6 × 6 eigenproblems instead of an interior point.

use nalgebra::{DMatrix, DVector, Matrix6, SymmetricEigen, Vector3, Vector6};

use crr_dynamics::eom::Dynamics;
use crr_kinematics::{Model, Parent};

use super::{FaceAxes, Unknown, interface_columns};

/// Eigenvalues of the projected systems' Gram matrices below this fraction of the largest (and
/// below this in absolute value for the free columns' span, whose columns are of order one)
/// count as zero: the directions they belong to are a null space.
const RANK_TOLERANCE: f64 = 1e-12;

/// The residual of an interface's rows, relative to the larger of its wrench and the impulse
/// unit, beyond which the wrench is taken as not carried (the global program's equality rows
/// would not hold): the caller then asks the global program.
const CONSISTENCY_TOLERANCE: f64 = 1e-8;

/// The answer of [`least_normal_impulse_on_tree`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeastNormal {
    /// s* (N s, at most 0), as [`super::MostCompressive::min_normal`].
    pub min_normal: f64,
    /// The interface whose touching points reach the least normal impulse of all (the lowest
    /// index among equals), None when no interface has a unilateral point: the contact that
    /// limits s*, as [`super::MostCompressive::limiting`] names it.
    pub limiting: Option<usize>,
}

/// s*, the largest smallest normal impulse (N s, at most 0) of the most compressive
/// distribution that changes each body's momentum by `momentum_change[b]` = (m_b Δċ_b, I_b Δω_b)
/// on the touching points of the state in `dynamics`, the slots `set_by_law` touching on both
/// pivots with impulses of either sign, when the interfaces form a tree (see the module's
/// docs); the answer of [`super::most_compressive_impulses`]'s `min_normal` up to its proximal
/// term. None where the interfaces do not form a tree, where an interface's normal impulses
/// are free in more than one direction, or where an interface cannot carry its wrench: the
/// caller then asks the global program.
pub fn least_normal_impulse_on_tree(
    model: &Model,
    dynamics: &Dynamics,
    momentum_change: &[(Vector3<f64>, Vector3<f64>)],
    set_by_law: &[usize],
) -> Option<LeastNormal> {
    let wrenches = subtree_wrenches(model, dynamics, momentum_change)?;
    let mut is_seated = vec![false; model.slot_count];
    for &k in dynamics.seated.iter().chain(set_by_law) {
        is_seated[k] = true;
    }
    let unit = model.total_mass() * model.gravity * (model.size / model.gravity).sqrt();
    let mut least = LeastNormal {
        min_normal: 0.0,
        limiting: None,
    };
    let mut columns = Vec::new();
    for (index, wrench) in wrenches.iter().enumerate() {
        columns.clear();
        interface_columns(
            model,
            dynamics,
            index,
            (&is_seated, set_by_law),
            FaceAxes::Parent,
            &mut columns,
        );
        let Some(s) = interface_least_normal(&columns, wrench, model.size, unit)? else {
            continue;
        };
        if least.limiting.is_none() || s < least.min_normal {
            least = LeastNormal {
                min_normal: s.min(0.0),
                limiting: Some(index),
            };
        }
    }
    Some(least)
}

/// The wrench every interface gives its child's subtree (force; moment about the world's
/// origin), from the bodies' momentum changes; None where the interfaces do not form a tree
/// rooted on the ground.
fn subtree_wrenches(
    model: &Model,
    dynamics: &Dynamics,
    momentum_change: &[(Vector3<f64>, Vector3<f64>)],
) -> Option<Vec<Vector6<f64>>> {
    if !model.closures.is_empty() || momentum_change.len() != model.bodies.len() {
        return None;
    }
    let mut below: Vec<Option<usize>> = vec![None; model.bodies.len()];
    for (index, iface) in model.interfaces.iter().enumerate() {
        if below[iface.child].replace(index).is_some() {
            return None;
        }
    }
    let mut wrenches = vec![Vector6::zeros(); model.interfaces.len()];
    for (b, (linear, angular)) in momentum_change.iter().enumerate() {
        let moment = angular + dynamics.kin.com[b].cross(linear);
        let wrench = Vector6::new(linear.x, linear.y, linear.z, moment.x, moment.y, moment.z);
        // Down the chain from body b to the ground: every interface on the way carries it.
        // A path longer than the bodies is a cycle.
        let mut body = b;
        let mut grounded = false;
        for _ in 0..model.bodies.len() {
            let index = below[body]?;
            wrenches[index] += wrench;
            match model.interfaces[index].parent {
                Parent::Ground => {
                    grounded = true;
                    break;
                }
                Parent::Body(parent) => body = parent,
            }
        }
        if !grounded {
            return None;
        }
    }
    Some(wrenches)
}

/// max s over the forces of `columns` that give `wrench` (moment about the world's origin), with
/// every unilateral column at least s (N s; Some(None) where no column is unilateral); None
/// where the normal impulses are free in more than one direction or the columns cannot give the
/// wrench.
fn interface_least_normal(
    columns: &[Unknown],
    wrench: &Vector6<f64>,
    size: f64,
    unit: f64,
) -> Option<Option<f64>> {
    // Moments about the interface's first point, over `size`, so that the rows are of one scale.
    let origin = columns
        .iter()
        .find_map(|u| u.point)
        .unwrap_or_else(Vector3::zeros);
    let force = wrench.fixed_rows::<3>(0).into_owned();
    let moment = wrench.fixed_rows::<3>(3) - origin.cross(&force);
    let mut rhs = Vector6::zeros();
    rhs.fixed_rows_mut::<3>(0).copy_from(&(force / unit));
    rhs.fixed_rows_mut::<3>(3)
        .copy_from(&(moment / (unit * size)));
    let column = |u: &Unknown| {
        let turn = match u.point {
            Some(p) => (p - origin).cross(&u.direction) / size,
            None => u.direction,
        };
        let force = if u.point.is_some() {
            u.direction
        } else {
            Vector3::zeros()
        };
        Vector6::new(force.x, force.y, force.z, turn.x, turn.y, turn.z)
    };
    // The complement Z of the free columns' span (an orthonormal basis, 6 × r).
    let mut gram = Matrix6::zeros();
    for u in columns.iter().filter(|u| !u.unilateral) {
        let a = column(u);
        gram += a * a.transpose();
    }
    let free = SymmetricEigen::new(gram);
    let largest = free.eigenvalues.max().max(1.0);
    let kept: Vec<usize> = (0..6)
        .filter(|&i| free.eigenvalues[i] <= RANK_TOLERANCE * largest)
        .collect();
    let normals: Vec<Vector6<f64>> = columns
        .iter()
        .filter(|u| u.unilateral)
        .map(column)
        .collect();
    // B fₙ = c on the complement.
    let b = DMatrix::from_fn(kept.len(), normals.len(), |r, j| {
        free.eigenvectors.column(kept[r]).dot(&normals[j])
    });
    let c = DVector::from_iterator(
        kept.len(),
        kept.iter().map(|&i| free.eigenvectors.column(i).dot(&rhs)),
    );
    let scale = rhs.norm().max(1.0);
    if normals.is_empty() {
        // Nothing unilateral (a pin, a face set by law): the wrench need only be carried.
        return (c.norm() <= CONSISTENCY_TOLERANCE * scale).then_some(None);
    }
    // The least-norm solution f₀ = B⁺c and the null space of B, from BᵀB's eigenvectors.
    let normal = SymmetricEigen::new(b.transpose() * &b);
    let largest = normal.eigenvalues.max();
    if largest <= 0.0 {
        return None;
    }
    let btc = b.transpose() * &c;
    let mut f0 = DVector::zeros(normals.len());
    let mut null = Vec::new();
    for i in 0..normals.len() {
        let v = normal.eigenvectors.column(i);
        let lambda = normal.eigenvalues[i];
        if lambda <= RANK_TOLERANCE * largest {
            null.push(v.into_owned());
        } else {
            f0 += v * (v.dot(&btc) / lambda);
        }
    }
    if (&b * &f0 - &c).norm() > CONSISTENCY_TOLERANCE * scale {
        return None;
    }
    let best = match null.as_slice() {
        [] => f0.min(),
        [v] => max_of_min_lines(f0.as_slice(), v.as_slice()),
        _ => return None,
    };
    Some(Some(best * unit))
}

/// max over α of minᵢ (aᵢ + α vᵢ): a concave piecewise-linear function whose maximum lies where
/// two lines of different slopes cross, or at infinity where no line falls that way (then the
/// least of the level lines, +∞ if there is none).
fn max_of_min_lines(a: &[f64], v: &[f64]) -> f64 {
    let flat = 1e-12 * v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let at = |alpha: f64| {
        a.iter()
            .zip(v)
            .map(|(&ai, &vi)| {
                if vi.abs() <= flat {
                    ai
                } else {
                    ai + alpha * vi
                }
            })
            .fold(f64::INFINITY, f64::min)
    };
    let level = a
        .iter()
        .zip(v)
        .filter(|(_, vi)| vi.abs() <= flat)
        .map(|(&ai, _)| ai)
        .fold(f64::INFINITY, f64::min);
    let mut best = f64::NEG_INFINITY;
    if v.iter().all(|&vi| vi >= -flat) || v.iter().all(|&vi| vi <= flat) {
        best = level;
    }
    for i in 0..a.len() {
        for j in i + 1..a.len() {
            if (v[i] - v[j]).abs() > flat {
                best = best.max(at((a[j] - a[i]) / (v[i] - v[j])));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crr_dynamics::ground_motion::GroundMotion;
    use crr_kinematics::fixtures::{SplitMix, random_chain, stacked_panel};
    use crr_kinematics::{ActivePivots, Data, Side, forward_kinematics};

    /// Each body's momentum change (m Δċ, I Δω) from its own velocities: ċ = J_c q̇, ω = J_ω q̇.
    fn momentum_changes(
        model: &Model,
        d: &Dynamics,
        q: &DVector<f64>,
        change: &DVector<f64>,
    ) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let mut kin = Data::new(model);
        forward_kinematics(model, &mut kin, q, &d.pivots);
        crr_kinematics::jacobians(model, &mut kin);
        let (dv, dw) = (&kin.com_jacobian * change, &kin.angular_jacobian * change);
        model
            .bodies
            .iter()
            .enumerate()
            .map(|(b, body)| {
                let inertia = crr_kinematics::mass_matrix::world_inertia(
                    body,
                    &kin.rot_ops[model.body_coord[b]],
                );
                (
                    body.mass * dv.fixed_rows::<3>(3 * b).into_owned(),
                    inertia * dw.fixed_rows::<3>(3 * b),
                )
            })
            .collect()
    }

    /// The interface-by-interface answer against the global program
    /// ([`super::super::most_compressive_impulses`], clarabel's interior point on every body's
    /// equilibrium at once) on plastic impulses of open chains: 3D random chains of six boxes on
    /// non-parallel hinges and rocking bases (seeds 1 to 8) and a planar panel of five courses.
    /// At each of 60 random states per model the slots are seated with probability 0.5
    /// (otherwise rocking on a random side, turned by up to 0.05 rad), one to three coordinates
    /// turn before the impulse (0.1 to 1 √(g/L)), and the impulse is the plastic one that holds
    /// the chain (every body's momentum change from its own velocities); at one state in four a
    /// random slot is set by a rate law (its interface's impulses of either sign, as the
    /// restitution and Dirac laws' impacting slots are checked). The two s* agree to
    /// 1e-6 W·√(L/g): the global program's proximal term lowers its s* by about 1e-7 of that unit,
    /// its interior point stops at a relative gap of about 1e-8. Every state is answered by the
    /// tree (none left to the global program), both tension and compression occur, and where the
    /// impulse pulls both name the same limiting contact.
    /// Measured: 7.8e-9 at most; 349 states pulling, 191 pushing; seated bases answered on
    /// their one free parameter.
    #[test]
    fn the_interfaces_of_an_open_chain_give_the_global_programs_answer() {
        let mut models: Vec<Model> = (1..=8)
            .map(|seed| Model::from_spec(&random_chain(seed, 6, 0)).unwrap())
            .collect();
        models.push(Model::from_spec(&stacked_panel(5, 0.3, 1.5, 0.5)).unwrap());
        let ground = GroundMotion::none();
        let mut rng = SplitMix(20_261_201);
        let (mut pulling, mut pushing, mut worst) = (0, 0, 0.0_f64);
        for model in &models {
            let n = model.dof();
            let rate = (model.gravity / model.size).sqrt();
            let unit = model.total_mass() * model.gravity / rate;
            for _ in 0..60 {
                let mut pivots = ActivePivots::uniform(model, Side::Positive);
                let mut seated = Vec::new();
                let mut q = DVector::zeros(n);
                for s in 0..model.slot_count {
                    if rng.uniform(0.0, 1.0) < 0.5 {
                        seated.push(s);
                        continue;
                    }
                    if rng.uniform(0.0, 1.0) < 0.5 {
                        pivots.sides[s] = Side::Negative;
                    }
                    if s < n {
                        q[s] = pivots.sides[s].sign() * rng.uniform(0.0, 0.05);
                    }
                }
                // One slot in four set by a rate law, at its impact (φ = 0): its faces take
                // impulses of either sign.
                let by_law: Vec<usize> = if rng.uniform(0.0, 1.0) < 0.25 {
                    vec![rng.below(model.slot_count)]
                } else {
                    Vec::new()
                };
                for &k in by_law.iter().filter(|&&k| k < n) {
                    q[k] = 0.0;
                }
                let mut qdot = DVector::zeros(n);
                for _ in 0..1 + rng.below(3) {
                    qdot[rng.below(n)] += rate * rng.uniform(-1.0, 1.0);
                }
                let mut d = Dynamics::new(model, pivots);
                d.seated = seated;
                d.evaluate(model, &ground, 0.0, &q, &qdot);
                let momentum = &d.kin.mass_matrix * &qdot;
                let after = d.solve_impulse(model, 0.0, &momentum).unwrap().clone();
                let changes = momentum_changes(model, &d, &q, &(after - &qdot));
                let global = super::super::most_compressive_impulses(model, &d, &changes, &by_law)
                    .expect("the global program solves");
                let tree = least_normal_impulse_on_tree(model, &d, &changes, &by_law)
                    .expect("an open chain is answered interface by interface");
                worst = worst.max((tree.min_normal - global.min_normal).abs() / unit);
                if global.min_normal < -1e-3 * unit {
                    pulling += 1;
                    assert_eq!(
                        tree.limiting, global.limiting,
                        "{}: the contact that limits s* = {:e}",
                        model.name, global.min_normal
                    );
                } else {
                    pushing += 1;
                }
            }
        }
        assert!(
            worst <= 1e-6,
            "the tree and the global program differ by {worst:e}"
        );
        assert!(
            pulling >= 20 && pushing >= 20,
            "{pulling} pulling, {pushing} pushing"
        );
    }

    /// max over α of min(α, 1 − α) is ½ at α = ½ (two lines crossing); min(2 + α, 3) with the
    /// second line level is 3 (α → ∞, the level line bounds it); min(α, 2α) has no maximum (+∞,
    /// every line rising); min(1 − α, 4, −1 + α) is 0 at α = 1 (a level line above the crossing).
    #[test]
    fn the_best_of_the_least_of_lines_is_where_two_cross_or_at_infinity() {
        assert!((max_of_min_lines(&[0.0, 1.0], &[1.0, -1.0]) - 0.5).abs() < 1e-15);
        assert_eq!(max_of_min_lines(&[2.0, 3.0], &[1.0, 0.0]), 3.0);
        assert_eq!(max_of_min_lines(&[0.0, 0.0], &[1.0, 2.0]), f64::INFINITY);
        assert!(max_of_min_lines(&[1.0, 4.0, -1.0], &[-1.0, 0.0, 1.0]).abs() < 1e-15);
    }
}
