//! Uplift of a structure with loops, by Gauss' principle over the pivot sides of its seated
//! joints (at rest, and in motion with some joints seated).
//!
//! At rest (q̇ = 0) the accelerations of a structure whose seated joints may open are the
//! admissible q̈ nearest to the free one in the kinetic metric (Gauss' principle):
//! min ½(q̈ − q̈_free)ᵀM(q̈ − q̈_free) over Φ_q q̈ = 0 and, for every seated slot k on its pivot
//! side σₖ, σₖψ̈ₖ ≥ 0 (it opens on that side or stays). For a fixed choice of sides σ this is a
//! convex problem; in the coordinates z = Lᵀq̈ (M = LLᵀ) restricted to the closures' null space,
//! z = N y (N orthonormal), it reads min ½‖y − y_free‖² subject to Gᵀy ≥ 0, whose dual is a
//! non-negative least-squares problem, min_{μ≥0} ‖y_free + Gμ‖², solved exactly by
//! Lawson–Hanson; then y = y_free + Gμ. A hyperstatic locked structure (an arch, a colonnade)
//! makes the seat reactions indeterminate, which defeats any test built on them, but not this
//! one: μ may be indeterminate, y is not.
//!
//! The sides are a discrete choice (a joint pivots on one edge or the other), searched from the
//! current ones ([`opening_from_rest`]).

use nalgebra::{DMatrix, DVector};

use crr_dynamics::eom::{Dynamics, slot_row};
use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::linalg::{JacobiSvd, RANK_TOLERANCE, pinv_solve};

use crate::nnls::nnls;
use crr_kinematics::{ActivePivots, Model, Side};

/// The closures' null space N and particular solution z_p of [`solve_for_sides`] for the states
/// and pivot sides solved before. At rest they depend on q, q̇ and the sides only, not on the
/// time (the ground motion changes Q alone), and the uplift test at rest runs on a time grid and
/// by bisection at one state: their SVD is made once per choice of sides instead of at every
/// instant.
#[derive(Clone, Debug, Default)]
pub(super) struct RestCache {
    entries: Vec<RestEntry>,
    /// The global statics of the structure at rest with every joint seated (the contact faces'
    /// linear program), which decides where the local search over sides finds no opening.
    pub(super) global: crate::statics::RestStatics,
    /// Set by the uplift test when the load exceeds the collapse multiplier in a mechanism where
    /// blocks lift off a support (outside the CRR chain): those interfaces' names.
    pub(super) lift_off: Option<Vec<String>>,
    /// Set with `lift_off` when it is a structure thrown off the ground (a flight of every body,
    /// `seating::thrown_off`): no face of it may be held for a pivot event.
    pub(super) thrown_off: bool,
    /// Faces (interfaces of the chain) the contact program keeps on their pivots, their lifts
    /// left out, until the next impact, landing or change of chain (a release of another joint
    /// does not clear them): faces rocking on one pivot whose lift-off the chain without them
    /// contradicted, faces that tie (still on the block under them), so that the program's
    /// answer can turn back to "holds" and the uplift event fire again for the other joints;
    /// and faces whose flight the chain's exact solve finds early (their pivots still press:
    /// `Simulation::early_flight`, a rocking base on an edge among them), whose pivot events
    /// then locate the flight.
    pub(super) held_faces: Vec<usize>,
    /// The certificate that a motion needs no contact to let go, carried from one step end to
    /// the next, and the bodies' loads it is posed on.
    pub(super) pressing: crate::face_forces::PressingCertificate,
    pub(super) loads: crate::monitor::ForceWork,
    /// The certificate's audit, when the run is audited
    /// ([`super::Simulation::audit_certificate`]).
    pub(super) audit: Option<super::CertificateAudit>,
    /// The checks of the contact program's releases made on a solve that left the loops open
    /// ([`super::seating::confirmed_releases`]) since the run last collected them.
    pub(super) doubtful: Vec<super::DoubtfulCheck>,
    /// The instants at which the structure at rest was held against a load beyond a mechanism
    /// whose joints slide while keeping contact (`seating::opening_mode_in`), with those
    /// interfaces, since the run last collected them.
    pub(super) sliding_unloaded: Vec<(f64, Vec<String>)>,
    /// The joints of the mechanism exceeded at rest that slide while keeping contact, carrying
    /// nothing (`seating::followable_collapse`), offered with `lift_off` as faces that open
    /// entirely: where the chain without them does not confirm it, the structure is held at rest
    /// and the instant recorded in `sliding_unloaded`, as before such faces were offered.
    pub(super) grazing: Vec<String>,
    /// The sets of such joints whose opening the chain without them contradicted, each with the
    /// state at rest it was asked at (q as bits): held there without asking again.
    pub(super) grazing_refused: Vec<(Vec<String>, Vec<u64>)>,
    /// The instants at which the structure at rest was held on a multiplier that is not
    /// exhaustive (`statics::RestStatics::held_on_search`), with the load, since the run last
    /// collected them.
    pub(super) held_on_search: Vec<super::HeldOnSearch>,
}

#[derive(Clone, Debug)]
struct RestEntry {
    sides: Vec<Side>,
    state: Vec<u64>,
    null: DMatrix<f64>,
    z_p: DVector<f64>,
}

/// Most entries of a [`RestCache`] (the oldest is dropped beyond).
const REST_CACHE: usize = 64;

impl RestCache {
    /// The exact state (q, q̇) as bits, the second half of an entry's key.
    fn state_key(q: &DVector<f64>, qdot: &DVector<f64>) -> Vec<u64> {
        q.iter().chain(qdot.iter()).map(|x| x.to_bits()).collect()
    }

    fn get(&self, sides: &ActivePivots, state: &[u64]) -> Option<(&DMatrix<f64>, &DVector<f64>)> {
        self.entries
            .iter()
            .find(|e| e.sides == sides.sides && e.state == state)
            .map(|e| (&e.null, &e.z_p))
    }

    fn insert(
        &mut self,
        sides: &ActivePivots,
        state: Vec<u64>,
        null: DMatrix<f64>,
        z_p: DVector<f64>,
    ) {
        if self.entries.len() >= REST_CACHE {
            self.entries.remove(0);
        }
        self.entries.push(RestEntry {
            sides: sides.sides.clone(),
            state,
            null,
            z_p,
        });
    }
}

/// The opening mode at rest for one choice of pivot sides.
struct SidesSolution {
    /// The Gauss function relative to staying at rest, ½‖y − y_free‖² − ½‖y_free‖² (≤ 0).
    gauss: f64,
    /// The dual multipliers μ of the seated slots (in the order of `seated`).
    mu: DVector<f64>,
    /// σₖψ̈ₖ of every seated slot (in the order of `seated`).
    opening: Vec<f64>,
    /// σₖψ̈ₖ with every seated slot free on both sides (y = y_free).
    free_opening: Vec<f64>,
    /// σₖψ̈ₖ of that free motion under the ground motion's inertial load alone (no gravity).
    load_opening: Vec<f64>,
}

impl SidesSolution {
    fn opens(&self, tol: f64) -> bool {
        self.opening.iter().any(|&o| o > tol)
    }
}

/// The opening accelerations below this fraction of the opening threshold are round-off of the
/// solve, not motion (the threshold is 1e-9 g/L; round-off is some 1e-14 g/L).
const ROUND_OFF_OPENING: f64 = 1e-2;

/// Largest number of choices of sides tried from one start of the search.
const MAX_SIDE_CHOICES: usize = 12;

/// The seated slots that open from rest, with their sides (`Some(Some(mode))`), `Some(None)`
/// when the structure holds, or None when the test cannot be made (a singular mass matrix).
/// `tol` is the opening threshold on σψ̈ (rad/s²).
///
/// The sides are searched locally from three starts in turn: the current sides, every seated
/// slot on its positive side, every one on its negative side. From a start, while the structure
/// holds, the next choice is the one each slot would open on if every seated slot were free (the
/// signs of the unconstrained accelerations), then the slots that push on their seat (μₖ > 0)
/// flipped one at a time and all together; the first choice on which it opens is kept, and
/// improved by the same flips while the Gauss function decreases. At most [`MAX_SIDE_CHOICES`]
/// choices are solved from each start; the first start on which the structure opens decides.
#[allow(clippy::too_many_arguments)]
pub(super) fn opening_from_rest(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    trial: &mut Dynamics,
    cache: &mut RestCache,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    tol: f64,
) -> Option<Option<Vec<(usize, Side)>>> {
    let seated = &template.seated;
    if seated.is_empty() {
        return Some(None);
    }
    let key = |p: &ActivePivots| sides_key(seated, p);
    // Starts of the local search: the current sides, then every seated slot on its positive
    // side, then on its negative one (a structure that is symmetric in fact need not be in its
    // coordinates, and the search from one start can miss the mirror image of a mechanism that it
    // finds from another). The first start on which the structure opens is kept.
    let mut starts = vec![template.pivots.clone()];
    for side in [Side::Positive, Side::Negative] {
        let mut p = template.pivots.clone();
        for &k in seated {
            p.sides[k] = side;
        }
        starts.push(p);
    }
    let mut visited: Vec<Vec<bool>> = Vec::new();
    let mut best: Option<(ActivePivots, SidesSolution)> = None;
    for start in starts {
        if visited.contains(&key(&start)) {
            continue;
        }
        let Some(found) = local_search(
            model,
            ground,
            trial,
            cache,
            t,
            q,
            qdot,
            tol,
            seated,
            start,
            &mut visited,
        ) else {
            continue;
        };
        let opens = found.1.opens(tol);
        best = Some(found);
        if opens {
            break;
        }
    }
    let (sides, current) = best?;
    if !current.opens(tol) {
        return Some(None);
    }
    // Every slot the mechanism moves opens, also those whose acceleration is still below the
    // threshold just above the activation (it grows in proportion to the others'), but not
    // those at the round-off of the solve: at the located uplift instant the mechanism's
    // accelerations are about `tol` and the slots it does not move show some 1e-14 g/L (a
    // temple's drum beds), which must not open them.
    let largest = current.opening.iter().fold(0.0_f64, |a, &o| a.max(o));
    let floor = (ROUND_OFF_OPENING * tol).max(tol.min(1e-6 * largest));
    Some(Some(
        seated
            .iter()
            .zip(&current.opening)
            .filter(|&(_, &o)| o > floor)
            .map(|(&k, _)| (k, sides.sides[k]))
            .collect(),
    ))
}

/// A choice of sides as the seated slots' sides (true: positive), to recognise it when seen again.
fn sides_key(seated: &[usize], p: &ActivePivots) -> Vec<bool> {
    seated
        .iter()
        .map(|&k| p.sides[k] == Side::Positive)
        .collect()
}

/// The local search of [`opening_from_rest`] from the sides `start`: returns the last choice
/// reached with its solution (None if its first solve fails). `visited` holds the choices
/// solved so far, over every start.
#[allow(clippy::too_many_arguments)]
fn local_search(
    model: &Model,
    ground: &GroundMotion,
    trial: &mut Dynamics,
    cache: &mut RestCache,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    tol: f64,
    seated: &[usize],
    start: ActivePivots,
    visited: &mut Vec<Vec<bool>>,
) -> Option<(ActivePivots, SidesSolution)> {
    let key = |p: &ActivePivots| sides_key(seated, p);
    let mut sides = start;
    let mut current = solve_for_sides(model, ground, trial, cache, &sides, seated, t, q, qdot)?;
    visited.push(key(&sides));
    let mut solved = 1;
    while solved < MAX_SIDE_CHOICES {
        let opens = current.opens(tol);
        // Candidate flips, as index sets into `seated`.
        let mut candidates: Vec<Vec<usize>> = Vec::new();
        if !opens {
            for guide in [&current.load_opening, &current.free_opening] {
                let flip: Vec<usize> = (0..seated.len()).filter(|&i| guide[i] < -tol).collect();
                if !flip.is_empty() {
                    candidates.push(flip);
                }
            }
        }
        let push_tol = 1e-9 * current.mu.amax();
        let mut pushing: Vec<usize> = (0..seated.len())
            .filter(|&i| current.mu[i] > push_tol && current.opening[i].abs() <= tol)
            .collect();
        pushing.sort_by(|&a, &b| current.mu[b].total_cmp(&current.mu[a]));
        candidates.extend(pushing.iter().map(|&i| vec![i]));
        if pushing.len() > 1 {
            candidates.push(pushing);
        }
        let mut moved = false;
        for flip in candidates {
            if solved >= MAX_SIDE_CHOICES {
                break;
            }
            let mut next_sides = sides.clone();
            for &i in &flip {
                let k = seated[i];
                next_sides.sides[k] = next_sides.sides[k].flipped();
            }
            let next_key = key(&next_sides);
            if visited.contains(&next_key) {
                continue;
            }
            visited.push(next_key);
            solved += 1;
            let Some(next) =
                solve_for_sides(model, ground, trial, cache, &next_sides, seated, t, q, qdot)
            else {
                continue;
            };
            // Holding: move to the first choice that opens. Opening: to a lower Gauss function
            // (by more than round-off).
            let better = if opens {
                next.opens(tol) && next.gauss < current.gauss * (1.0 + 1e-9)
            } else {
                next.opens(tol)
            };
            if better {
                sides = next_sides;
                current = next;
                moved = true;
                break;
            }
        }
        if !moved {
            break;
        }
    }
    Some((sides, current))
}

/// Gauss' principle on the pivot sides `sides`: every seated slot free to open on its side or
/// stay. In z = Lᵀq̈ the closures read A z = −c (A = Φ_q L⁻ᵀ, c the bias Φ̇_q q̇), so
/// z = z_p + N y with z_p = −A⁺c; seated slot k reads ψ̈ₖ = gₖᵀz + bₖ (gₖ = L⁻¹sₖ, bₖ its bias),
/// σₖψ̈ₖ = Gₖᵀy + hₖ. The locked motion y_p (every seated slot held: Gᵀy_p = −h, which exists
/// whenever the seated state is one the structure can be in) shifts the cone to the origin,
/// y = y_p + y′ with Gᵀy′ ≥ 0, and the problem is the projection of y_free − y_p onto that cone,
/// whose dual is the non-negative least-squares problem. At rest c, b, h and y_p vanish.
#[allow(clippy::too_many_arguments)]
fn solve_for_sides(
    model: &Model,
    ground: &GroundMotion,
    trial: &mut Dynamics,
    cache: &mut RestCache,
    sides: &ActivePivots,
    seated: &[usize],
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Option<SidesSolution> {
    let n = model.dof();
    trial.pivots.clone_from(sides);
    trial.seated.clear();
    trial.evaluate(model, ground, t, q, qdot);
    let l = trial.kin.mass_matrix.clone().cholesky()?;
    let l = l.l();
    // z_free = L⁻¹ (Q − h).
    let r = &trial.load - &trial.kin.velocity_product;
    let z_free = l.solve_lower_triangular(&r)?;
    // Closures in z: Φ_q L⁻ᵀ, rows normalised for the rank decision; N its null space.
    let state = RestCache::state_key(q, qdot);
    let (null, z_p) = if model.constraint_rows == 0 {
        (DMatrix::identity(n, n), DVector::zeros(n))
    } else if let Some((null, z_p)) = cache.get(sides, &state) {
        (null.clone(), z_p.clone())
    } else {
        let mut a = DMatrix::zeros(model.constraint_rows, n);
        let mut c = DVector::zeros(model.constraint_rows);
        for i in 0..model.constraint_rows {
            let row = l.solve_lower_triangular(&trial.kin.phi_q.row(i).transpose())?;
            let norm = row.norm();
            if norm > 0.0 {
                a.row_mut(i).copy_from(&(row / norm).transpose());
                c[i] = trial.kin.phi_bias[i] / norm;
            }
        }
        let svd = JacobiSvd::new(&a);
        let tol = svd.tolerance_relative(RANK_TOLERANCE.sqrt());
        let cols: Vec<usize> = (0..svd.singular_values.len())
            .filter(|&j| svd.singular_values[j] <= tol)
            .collect();
        let null = DMatrix::from_fn(n, cols.len(), |i, k| svd.v[(i, cols[k])]);
        let z_p = -svd.solve_with(&c, tol);
        cache.insert(sides, state, null.clone(), z_p.clone());
        (null, z_p)
    };
    let d = null.ncols();
    let y_free = null.tr_mul(&(&z_free - &z_p));
    let mut row = DVector::zeros(n);
    let mut g = DMatrix::zeros(d, seated.len());
    let mut h = DVector::zeros(seated.len());
    for (i, &k) in seated.iter().enumerate() {
        let bias = slot_row(model, &trial.kin, k, &mut row);
        let gk = l.solve_lower_triangular(&row)?;
        let sign = sides.sides[k].sign();
        g.column_mut(i).copy_from(&(null.tr_mul(&gk) * sign));
        h[i] = sign * (gk.dot(&z_p) + bias);
    }
    // The locked motion: Gᵀy_p = −h (least squares; it must be solved exactly).
    let y_p = if h.amax() == 0.0 {
        DVector::zeros(d)
    } else {
        let (y_p, _) = pinv_solve(&g.transpose(), &(-&h));
        let residual = (g.tr_mul(&y_p) + &h).amax();
        if residual > 1e-8 * h.amax().max(1e-12 * y_free.amax()) {
            return None;
        }
        y_p
    };
    let target = &y_free - &y_p;
    let mu = nnls(&g, &(-&target));
    let y_shift = &target + &g * &mu;
    let y = &y_p + &y_shift;
    let opening = (0..seated.len())
        .map(|i| g.column(i).dot(&y_shift))
        .collect();
    let free_opening = (0..seated.len())
        .map(|i| g.column(i).dot(&y_free) + h[i])
        .collect();
    let y_load = null.tr_mul(&l.solve_lower_triangular(&trial.ground_force)?);
    let load_opening = (0..seated.len())
        .map(|i| g.column(i).dot(&y_load))
        .collect();
    let z = &z_p + &null * &y;
    let gauss = 0.5 * (&z - &z_free).norm_squared() - 0.5 * z_free.norm_squared();
    Some(SidesSolution {
        gauss,
        mu,
        opening,
        free_opening,
        load_opening,
    })
}
