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
//! without its proximal term: a few Gram–Schmidt steps and a small QR factorisation per
//! interface instead of an interior point.

use nalgebra::allocator::Allocator;
use nalgebra::{DMatrix, DVector, DefaultAllocator, Dim, Dyn, OVector, U1, U6, Vector3, Vector6};

use crr_dynamics::eom::Dynamics;
use crr_kinematics::{Model, Parent};

use super::{FaceAxes, Unknown, interface_columns};

/// A vector whose part off the span of the ones taken before it is below this fraction of the
/// longest counts as dependent on them: the free columns' span and the rank of the normal
/// impulses' rows are decided with it. The longest parts are taken first
/// ([`orthonormal_basis`]), so a dependent vector's part is round-off of its own length (about
/// 1e-16, and ulp(|p|)/size of the coordinates of a point p: 1e-14 at 100 sizes from the
/// origin), and an independent one's is what the face gives: the rows of a hinge whose two
/// pivot lines are `GEOMETRY_TOLERANCE` (1e-6 of the model's size) apart have a part of about
/// 7e-7 off each other.
const RANK_TOLERANCE: f64 = 1e-9;

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
    /// index among equals), None when no interface has a unilateral point: where s* < 0 the
    /// contact that limits it, as [`super::MostCompressive::limiting`] names it.
    pub limiting: Option<usize>,
}

/// s*, the largest smallest normal impulse (N s, at most 0, each point's measured per edge,
/// [`super::touching_points_per_edge`]) of the most compressive
/// distribution that changes each body's momentum by `momentum_change[b]` = (m_b Δċ_b, I_b Δω_b)
/// on the touching points of the state in `dynamics`, the slots `set_by_law` touching on both
/// pivots with impulses of either sign, when the interfaces form a tree (see the module's
/// docs); the answer of [`super::most_compressive_impulses`]'s `min_normal` up to its proximal
/// term. None where the interfaces do not form a tree, where an interface's normal impulses
/// are free in more than one direction, where an interface cannot carry its wrench, or where a
/// number is not finite: the caller then asks the global program.
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
    // The least of the faces' optima, uncapped, and its interface.
    let mut least: Option<(f64, usize)> = None;
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
        let at = (wrench, reference(dynamics));
        let Some(s) = interface_least_normal(&columns, at, model.size, unit)? else {
            continue;
        };
        // Per edge, as the global program measures impulses: for one face the best of the
        // weighted least is the weight times the best of the least.
        let points = columns.iter().filter(|u| u.unilateral).count();
        let s = s * super::touching_points_per_edge(&model.interfaces[index].kind, points);
        if least.is_none_or(|(m, _)| s < m) {
            least = Some((s, index));
        }
    }
    Some(LeastNormal {
        min_normal: least.map_or(0.0, |(s, _)| s.min(0.0)),
        limiting: least.map(|(_, index)| index),
    })
}

/// The wrench every interface gives its child's subtree (force; moment about [`reference`]),
/// from the bodies' momentum changes; None where the interfaces do not form a tree rooted on
/// the ground.
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
        let moment = angular + (dynamics.kin.com[b] - reference(dynamics)).cross(linear);
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

/// The point the subtrees' moments are taken about: the first body's centre of mass, near the
/// structure (about the world's origin a structure far from it would lose digits).
fn reference(dynamics: &Dynamics) -> Vector3<f64> {
    dynamics
        .kin
        .com
        .first()
        .copied()
        .unwrap_or_else(Vector3::zeros)
}

/// max s over the forces of `columns` that give `wrench` (moment about `reference`), with every
/// unilateral column at least s (N s; Some(None) where no column is unilateral, Some(+∞) where
/// the normal impulses can all grow without bound); None where they are free in more than one
/// direction, where the columns cannot give the wrench, or where the wrench or a column is not
/// finite.
fn interface_least_normal(
    columns: &[Unknown],
    (wrench, reference): (&Vector6<f64>, Vector3<f64>),
    size: f64,
    unit: f64,
) -> Option<Option<f64>> {
    // Moments about the interface's first point, over `size`, so that the rows are of one scale.
    let origin = columns.iter().find_map(|u| u.point).unwrap_or(reference);
    let force = wrench.fixed_rows::<3>(0).into_owned();
    let moment = wrench.fixed_rows::<3>(3) - (origin - reference).cross(&force);
    let mut rhs = Vector6::zeros();
    rhs.fixed_rows_mut::<3>(0).copy_from(&(force / unit));
    rhs.fixed_rows_mut::<3>(3)
        .copy_from(&(moment / (unit * size)));
    if !rhs.iter().all(|x| x.is_finite())
        || !columns.iter().all(|u| {
            u.direction
                .iter()
                .chain(u.point.iter().flatten())
                .all(|x| x.is_finite())
        })
    {
        return None;
    }
    let column = |u: &Unknown| match u.point {
        Some(p) => {
            let turn = (p - origin).cross(&u.direction) / size;
            let d = u.direction;
            Vector6::new(d.x, d.y, d.z, turn.x, turn.y, turn.z)
        }
        None => Vector6::new(0.0, 0.0, 0.0, u.direction.x, u.direction.y, u.direction.z),
    };
    // The complement Z of the free columns' span (an orthonormal basis), and B fₙ = c on it.
    let free: Vec<Vector6<f64>> = columns
        .iter()
        .filter(|u| !u.unilateral)
        .map(column)
        .collect();
    let complement = completion(&orthonormal_basis(&free), U6);
    let normals: Vec<Vector6<f64>> = columns
        .iter()
        .filter(|u| u.unilateral)
        .map(column)
        .collect();
    let b = DMatrix::from_fn(complement.len(), normals.len(), |r, j| {
        complement[r].dot(&normals[j])
    });
    let c = DVector::from_iterator(complement.len(), complement.iter().map(|z| z.dot(&rhs)));
    let scale = rhs.norm().max(1.0);
    let consistent = |residual: f64| residual <= CONSISTENCY_TOLERANCE * scale;
    if normals.is_empty() {
        // Nothing unilateral (a pin, a face set by law): the wrench need only be carried.
        return consistent(c.norm()).then_some(None);
    }
    // The least-norm solution f₀ of B fₙ = c lies in B's row space R (orthonormal basis as the
    // columns of Q): f₀ = Q y with (B Q) y = c in the least-squares sense, B Q of full column
    // rank; the null space of B is R's completion.
    let rows: Vec<DVector<f64>> = (0..b.nrows()).map(|r| b.row(r).transpose()).collect();
    let row_space = orthonormal_basis(&rows);
    if row_space.is_empty() {
        return None;
    }
    let q = DMatrix::from_columns(&row_space);
    let bq = &b * &q;
    // B Q has as many rows as B, at least its rank, its columns' count.
    let qr = bq.qr();
    let y = qr.r().solve_upper_triangular(&(qr.q().transpose() * &c))?;
    let f0 = &q * y;
    if !consistent((&b * &f0 - &c).norm()) {
        return None;
    }
    let null = completion(&row_space, Dyn(normals.len()));
    let best = match null.as_slice() {
        [] => f0.min(),
        [v] => max_of_min_lines(f0.as_slice(), v.as_slice()),
        _ => return None,
    };
    (!best.is_nan()).then_some(Some(best * unit))
}

/// An orthonormal basis of the span of `vectors`, by modified Gram–Schmidt applied twice with
/// pivoting: each step takes the vector with the longest part off the basis so far, and stops
/// when that part is below [`RANK_TOLERANCE`] of the longest vector (the rest depend on the
/// basis). Pivoting keeps a nearly dependent vector, whose part off the others is mostly
/// round-off, from entering the basis before the vectors it nearly depends on. Each step
/// computes every remaining vector's part afresh from the vector itself (not updated from the
/// step before), in two work vectors: no allocation but the basis and the indices left.
fn orthonormal_basis<D: Dim>(vectors: &[OVector<f64, D>]) -> Vec<OVector<f64, D>>
where
    DefaultAllocator: Allocator<D>,
{
    let mut basis: Vec<OVector<f64, D>> = Vec::with_capacity(vectors.len());
    let Some(first) = vectors.first() else {
        return basis;
    };
    let longest = vectors.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let mut left: Vec<usize> = (0..vectors.len()).collect();
    let (mut part, mut longest_part) = (first.clone(), first.clone());
    while !left.is_empty() {
        // The first of the longest parts (a part of length 0 is never taken).
        let (mut pick, mut norm) = (0, 0.0);
        for (i, &v) in left.iter().enumerate() {
            part.copy_from(&vectors[v]);
            off_basis(&mut part, &basis);
            let n = part.norm();
            if n > norm {
                (pick, norm) = (i, n);
                std::mem::swap(&mut part, &mut longest_part);
            }
        }
        if norm <= RANK_TOLERANCE * longest {
            break;
        }
        basis.push(&longest_part / norm);
        left.swap_remove(pick);
    }
    basis
}

/// An orthonormal basis of the orthogonal complement of the span of the orthonormal `basis` in
/// dimension `dim`: the unit axes' parts off it, the longest first (each at least 1/√dim long
/// while a direction is missing).
fn completion<D: Dim>(basis: &[OVector<f64, D>], dim: D) -> Vec<OVector<f64, D>>
where
    DefaultAllocator: Allocator<D>,
{
    let n = dim.value();
    let mut all: Vec<OVector<f64, D>> = Vec::with_capacity(n);
    all.extend_from_slice(basis);
    let mut axis = OVector::<f64, D>::zeros_generic(dim, U1);
    let mut longest_part = axis.clone();
    while all.len() < n {
        let mut norm = 0.0;
        longest_part.fill(0.0);
        for i in 0..n {
            axis.fill(0.0);
            axis[i] = 1.0;
            off_basis(&mut axis, &all);
            let r = axis.norm();
            if r > norm {
                norm = r;
                std::mem::swap(&mut axis, &mut longest_part);
            }
        }
        all.push(&longest_part / norm);
    }
    all.split_off(basis.len())
}

/// Takes from `v` its projections on the orthonormal `basis`, twice (modified Gram–Schmidt with
/// one reorthogonalisation, accurate to round-off).
fn off_basis<D: Dim>(v: &mut OVector<f64, D>, basis: &[OVector<f64, D>])
where
    DefaultAllocator: Allocator<D>,
{
    for _ in 0..2 {
        for q in basis {
            let along = q.dot(v);
            v.axpy(-along, q, 1.0);
        }
    }
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

    /// The basis of a span and its completion, on vectors with a dependence: in R⁶, v₁, v₂, v₄
    /// random, v₃ = 2v₁ − 3v₂ and v₅ = 1e-12 v₁ + v₄ (in the span of v₁ and v₄, though nearly
    /// parallel to v₄ alone); the basis has three vectors,
    /// orthonormal to 1e-14, every vᵢ lies in their span to 1e-13 of its length, and with the
    /// completion they make an orthonormal basis of R⁶. In R³ (a dynamic dimension, as the normal
    /// impulses' rows are), two parallel vectors give one direction and a completion of two.
    #[test]
    fn the_basis_spans_the_vectors_and_its_completion_the_rest() {
        let mut rng = SplitMix(7);
        let random = |rng: &mut SplitMix| Vector6::from_fn(|_, _| rng.uniform(-1.0, 1.0));
        let (v1, v2, v4) = (random(&mut rng), random(&mut rng), random(&mut rng));
        let vectors = [v1, v2, 2.0 * v1 - 3.0 * v2, v4, 1e-12 * v1 + v4];
        let basis = orthonormal_basis(&vectors);
        assert_eq!(basis.len(), 3);
        let off_span = |v: &Vector6<f64>, basis: &[Vector6<f64>]| {
            let mut r = *v;
            for b in basis {
                r -= b * b.dot(v);
            }
            r.norm()
        };
        for v in &vectors {
            assert!(
                off_span(v, &basis) <= 1e-13 * v.norm(),
                "{}",
                off_span(v, &basis)
            );
        }
        let complement = completion(&basis, U6);
        assert_eq!(complement.len(), 3);
        let all: Vec<Vector6<f64>> = basis.iter().chain(&complement).copied().collect();
        for (i, a) in all.iter().enumerate() {
            for (j, b) in all.iter().enumerate() {
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (a.dot(b) - expected).abs() <= 1e-14,
                    "{i} {j}: {}",
                    a.dot(b)
                );
            }
        }
        let parallel = [
            DVector::from_vec(vec![1.0, 2.0, 2.0]),
            DVector::from_vec(vec![-2.0, -4.0, -4.0]),
        ];
        let line = orthonormal_basis(&parallel);
        assert_eq!(line.len(), 1);
        assert!((line[0].dot(&parallel[0]).abs() - 3.0).abs() <= 1e-15);
        let rest = completion(&line, Dyn(3));
        assert_eq!(rest.len(), 2);
        for r in &rest {
            assert!((r.norm() - 1.0).abs() <= 1e-15 && line[0].dot(r).abs() <= 1e-15);
        }
        assert!(rest[0].dot(&rest[1]).abs() <= 1e-15);
    }

    /// max over α of min(α, 1 − α) is ½ at α = ½ (two lines crossing); min(2 + α, 3) with the
    /// second line level is 3 (α → ∞, the level line bounds it); min(α, 2α) has no maximum (+∞,
    /// every line rising), nor min(1 − α, 2 − 3α); min(1 − α, 4, −1 + α) is 0 at α = 1 (a level
    /// line above the crossing); min(α, 1 + α, 2 − α) is 1 at α = 1 (two lines of one slope).
    #[test]
    fn the_best_of_the_least_of_lines_is_where_two_cross_or_at_infinity() {
        assert!((max_of_min_lines(&[0.0, 1.0], &[1.0, -1.0]) - 0.5).abs() < 1e-15);
        assert_eq!(max_of_min_lines(&[2.0, 3.0], &[1.0, 0.0]), 3.0);
        assert_eq!(max_of_min_lines(&[0.0, 0.0], &[1.0, 2.0]), f64::INFINITY);
        assert!(max_of_min_lines(&[1.0, 4.0, -1.0], &[-1.0, 0.0, 1.0]).abs() < 1e-15);
        // Every line falling: no maximum either (α → −∞).
        assert_eq!(max_of_min_lines(&[1.0, 2.0], &[-1.0, -3.0]), f64::INFINITY);
        // Equal slopes and a crossing: min(α, 1 + α, 2 − α) is 1 at α = 1.
        assert!((max_of_min_lines(&[0.0, 1.0, 2.0], &[1.0, 1.0, -1.0]) - 1.0).abs() < 1e-15);
    }

    /// The columns of a hinge about u = R y at `centre` whose pivot lines are `gap` apart along
    /// t₁ = R x (face normal n = R z): at each point a normal force (unilateral) and two
    /// tangential ones, and the couples about n and t₁; `both` false keeps the + line alone
    /// (rocking on it).
    fn hinge_columns(
        centre: Vector3<f64>,
        turn: &nalgebra::Rotation3<f64>,
        gap: f64,
        both: bool,
    ) -> Vec<Unknown> {
        let (x, y, z) = (
            turn * Vector3::x(),
            turn * Vector3::y(),
            turn * Vector3::z(),
        );
        let key = |along| super::super::UnknownKey {
            interface: 0,
            rest: None,
            along,
        };
        let mut columns = Vec::new();
        let sides: &[f64] = if both { &[0.5, -0.5] } else { &[0.5] };
        for &side in sides {
            for (k, d) in [z, x, y].into_iter().enumerate() {
                columns.push(Unknown {
                    interface: 0,
                    unilateral: k == 0,
                    point: Some(centre + x * (side * gap)),
                    direction: d,
                    key: key(k),
                });
            }
        }
        for (k, d) in [z, x].into_iter().enumerate() {
            columns.push(Unknown {
                interface: 0,
                unilateral: false,
                point: None,
                direction: d,
                key: key(k),
            });
        }
        columns
    }

    /// A seated hinge about u whose pivot lines are a gap d apart along t₁ (normal n), under a
    /// wrench (F, M) taken about a point r away from the hinge's middle m: by hand, the normal
    /// impulses are f± = (F_n ∓ 2 M_u / d) / 2 with F_n = n·F and M_u = u·(M − (m − r) × F) the
    /// moment about the axis at the middle, so s* = min(f₊, f₋) whatever the other components
    /// (the tangential impulses and the couples take them). For gaps from 1.5e-6 of the size
    /// (just above `GEOMETRY_TOLERANCE`, where M_u/d is some 1e5 times the wrench) to the size
    /// itself, 50 wrenches each, on the axes and near the origin and also turned by a generic
    /// rotation 100 sizes from the origin (where the columns are built in that order, a nearly
    /// dependent free column before the couples it nearly depends on: the pivoting of
    /// [`orthonormal_basis`] keeps it out): agreement to 1e-9 of the largest normal impulse, plus
    /// the round-off of the points' coordinates over the gap (8 ε |m| / d). A hinge rocking on
    /// its + line alone carries no moment about its axis: a wrench with one is refused (None,
    /// for the global program to judge), one without gives s* = F_n. A wrench that is not finite
    /// is refused.
    #[test]
    fn a_seated_hinge_shares_its_impulse_between_its_two_pivot_lines_by_statics() {
        let (size, unit) = (2.0, 10.0);
        let reference = Vector3::new(0.0, 0.0, 0.5);
        let mut rng = SplitMix(7);
        let generic = nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.7, -1.3, 0.4));
        for (middle, turn) in [
            (
                Vector3::new(0.3, -0.2, 1.1),
                nalgebra::Rotation3::identity(),
            ),
            (Vector3::new(150.0, -120.0, 60.0), generic),
        ] {
            let (n, u) = (turn * Vector3::z(), turn * Vector3::y());
            for gap in [1.5e-6 * size, 1e-4 * size, 0.05 * size, size] {
                let columns = hinge_columns(middle, &turn, gap, true);
                let tolerance = 1e-9 + 8.0 * f64::EPSILON * middle.norm() / gap;
                for _ in 0..50 {
                    let w = Vector6::from_fn(|_, _| rng.uniform(-1.0, 1.0) * unit);
                    let force = w.fixed_rows::<3>(0).into_owned();
                    let at_middle = w.fixed_rows::<3>(3) - (middle - reference).cross(&force);
                    let (f_n, m_u) = (n.dot(&force), u.dot(&at_middle));
                    let plus = (f_n - 2.0 * m_u / gap) / 2.0;
                    let minus = (f_n + 2.0 * m_u / gap) / 2.0;
                    let s = interface_least_normal(&columns, (&w, reference), size, unit)
                        .expect("a seated hinge carries any wrench")
                        .expect("its normal impulses are unilateral");
                    assert!(
                        (s - plus.min(minus)).abs() <= tolerance * plus.abs().max(minus.abs()),
                        "gap {gap} at {middle:?}: {s} against {}",
                        plus.min(minus)
                    );
                }
            }
        }
        let middle = Vector3::new(0.3, -0.2, 1.1);
        let rocking = hinge_columns(middle, &nalgebra::Rotation3::identity(), 0.1, false);
        let plus = middle + Vector3::x() * 0.05;
        let pushing = Vector6::new(0.5, -0.3, 4.0, 0.2, 0.0, -0.7);
        // The same force and moment about the + line, then taken about the reference point.
        let about_reference = |w: Vector6<f64>| {
            let force = w.fixed_rows::<3>(0).into_owned();
            let moment = w.fixed_rows::<3>(3) + (plus - reference).cross(&force);
            Vector6::new(force.x, force.y, force.z, moment.x, moment.y, moment.z)
        };
        let s =
            interface_least_normal(&rocking, (&about_reference(pushing), reference), size, unit)
                .expect("no moment about the axis: carried")
                .expect("unilateral");
        assert!((s - 4.0).abs() <= 1e-12, "{s}");
        let turning = pushing + Vector6::new(0.0, 0.0, 0.0, 0.0, 0.3, 0.0);
        assert_eq!(
            interface_least_normal(&rocking, (&about_reference(turning), reference), size, unit),
            None
        );
        let columns = hinge_columns(middle, &nalgebra::Rotation3::identity(), 0.1, true);
        let broken = Vector6::new(0.0, 0.0, f64::NAN, 0.0, 0.0, 0.0);
        assert_eq!(
            interface_least_normal(&columns, (&broken, reference), size, unit),
            None
        );
    }
}
