//! The exhaustive pass over the sets of joints that may open and slide.
//!
//! **Why it is exact.** In a collapse state (an equilibrium at λ with forces only where a
//! mechanism keeps contact without sliding), an interface either carries load or carries none.
//! One that carries load has a point that neither separates nor slides; where it has two or
//! more such points, or a hinge's line, the relative motion is a rotation about them, which
//! moves every other point of the face along its normal only: the interface obeys the convex
//! program's rule (no tangential velocity at any point). One that carries none may separate
//! and slide anywhere, with only its gaps kept open (gₖ ≥ 0). So a collapse state is the
//! convex program with a set U of interfaces unloaded; its λ is the program's with U freed
//! (normal forces only, whose dual leaves U's slips free and keeps its gaps), and it exists
//! where that program's answer has an equilibrium with U and every moving point unloaded: the
//! physical test of [`super::physical`], which the optimal pair of a true collapse state
//! passes (any primal and dual optimum of one program are complementary). Every body carries
//! its weight, so the interfaces outside U still join every body to the ground: U holds no
//! bridge of the graph of bodies and interfaces, and at most as many interfaces as it has
//! independent loops. The least λ over those sets is the multiplier of the contact model with
//! joints that open and slide (a face that keeps a single loaded corner and twists about it in
//! a 3D model aside: its other corners slide while keeping contact, which neither rule holds).
//! A tree (no loop) has no such set: the convex program's answer is exact.
//!
//! "Exact" is in the sense of the convex program's closure: a joint that keeps contact may
//! carry shear with no compression left (the friction cone's closure as μ → ∞), and a hinge
//! that keeps one line carries its in-plane shear there (the same wrench at either line), and a
//! rocking base that keeps a single corner and does not twist carries the couple about its
//! normal of the no-twist constraint (`LumpedShear` in the parent module). An
//! answer that relies on shear across a joint its mechanism lifts off is the limit of
//! equilibria whose compression there vanishes: it needs unbounded friction, which
//! [`super::state_friction`] and `crr check` report ("needs μ > 1000"; an independent review
//! found 15 such answers on 134 directions of random walls with beds only, and no answer above
//! a collapse state it verified).
//!
//! **Cost.** The sets are counted first, without a program, keeping those that leave every body
//! joined to the ground and, under a load that presses every body down, resting on a face that
//! can push it up ([`Pass::holdable`]). Beyond the options' `exhaustive_sets` the pass does not run and
//! the search's answer stands, marked as not exhaustive (walls of many courses with every
//! contact a joint). Otherwise each set costs one to three programs.
use nalgebra::Vector3;

use super::{
    Collapse, HOLDS_FROM, StaticsError, StaticsOptions, UNLOADED_TOLERANCE, Unexhausted,
    moving_points, physical_test, solve_program, solve_to_precision,
};
use crr_kinematics::{ContactFace, Model, Parent};

/// The interfaces that may be unloaded in a collapse state: on a loop of the graph of bodies
/// and interfaces (not a bridge, whose removal leaves a body unsupported) and not pins (a pin
/// is bilateral). Empty for a tree.
pub(super) fn candidates(model: &Model, faces: &[ContactFace]) -> Vec<usize> {
    let all = vec![false; model.interfaces.len()];
    (0..model.interfaces.len())
        .filter(|&i| {
            !faces[i].pin && {
                let mut removed = all.clone();
                removed[i] = true;
                supported(model, &removed)
            }
        })
        .collect()
}

/// The number of independent loops of the graph of bodies and interfaces (ground included):
/// the most interfaces a set may unload while every body stays joined to the ground.
pub(super) fn loops(model: &Model) -> usize {
    // E − V + 1 with V = bodies + ground, for a connected graph.
    (model.interfaces.len() + 1).saturating_sub(model.bodies.len() + 1)
}

/// Whether a face can push body `b` upwards (against gravity): by compression where b is the
/// child on a normal with an upward part (or the parent on one with a downward part), by shear
/// where a tangent has a vertical part (the convex program's shear is unlimited).
fn lifts(face: &ContactFace, child: usize, b: usize) -> bool {
    let tilt = 1e-9;
    let n = face.normal.z * if child == b { 1.0 } else { -1.0 };
    n > tilt || face.tangents.iter().any(|t| t.z.abs() > tilt)
}

/// Per body, the interfaces whose face can push it up ([`lifts`]).
fn lifters(model: &Model, faces: &[ContactFace]) -> Vec<Vec<usize>> {
    let mut lifters = vec![Vec::new(); model.bodies.len()];
    for (i, interface) in model.interfaces.iter().enumerate() {
        let child = interface.child;
        if lifts(&faces[i], child, child) {
            lifters[child].push(i);
        }
        if let Parent::Body(b) = interface.parent
            && lifts(&faces[i], child, b)
        {
            lifters[b].push(i);
        }
    }
    lifters
}

/// Whether every body is joined to the ground through the interfaces not `removed`.
pub(super) fn supported(model: &Model, removed: &[bool]) -> bool {
    model.bodies_off_ground(removed).is_empty()
}

/// The least collapse over every set U that a collapse state may unload, below `best`
/// (λ = `best_lambda`, the search's answer): the lowest found (`best` itself where none lowers
/// it), or why not every set was tried: more sets than `options.exhaustive_sets`, or a program
/// that failed to solve.
///
/// A depth-first walk over the sets, each set's children adding one candidate after its last
/// (every set is met once). First, every candidate freed at once bounds every set's λ (freeing
/// more only removes equilibria): where that is not below the best, no set is tried. At a set U:
/// - it must be [`Pass::holdable`], else it and every set below it are dropped;
/// - its program with every point of U unloaded must have an equilibrium at some λ ≥ 0, else U
///   and every set below it are dropped (they unload more, so they hold less: a column hanging
///   from the lintel it carries once its base is unloaded). Its λ_u bounds U's own collapse
///   (λ = λ_u = λ_f there), so U is tried only where λ_u lies below the best;
/// - U is tried freed (normal forces only: λ_f) and, where that lowers the best, by the physical
///   test ([`physical`]).
pub(super) fn least_collapse(
    model: &Model,
    faces: &[ContactFace],
    candidates: &[usize],
    d: Vector3<f64>,
    options: &StaticsOptions,
    best: Collapse,
    best_lambda: f64,
) -> Result<Collapse, Unexhausted> {
    let mut pass = Pass::new(model, faces, candidates, d, options, best, best_lambda);
    pass.count_sets(options.exhaustive_sets)
        .ok_or(Unexhausted::TooManySets)?;
    if pass.below_best(candidates)? {
        pass.children(&[], 0)?;
    }
    Ok(pass.best)
}

/// How many sets [`least_collapse`] would try below `best` (λ = `best_lambda`), counted
/// without a program; None beyond `most`.
pub(super) fn count(
    model: &Model,
    faces: &[ContactFace],
    candidates: &[usize],
    d: Vector3<f64>,
    best: Collapse,
    best_lambda: f64,
    most: usize,
) -> Option<usize> {
    let options = StaticsOptions::default();
    Pass::new(model, faces, candidates, d, &options, best, best_lambda).count_sets(most)
}

/// The state of [`least_collapse`]'s depth-first walk.
struct Pass<'a> {
    model: &'a Model,
    faces: &'a [ContactFace],
    d: Vector3<f64>,
    options: &'a StaticsOptions,
    candidates: &'a [usize],
    /// The most interfaces a set may hold (the loops).
    depth: usize,
    /// Where the load presses every body down below the best λ, per body the interfaces that
    /// can push it up ([`lifters`]); None otherwise.
    lifters: Option<Vec<Vec<usize>>>,
    best: Collapse,
    best_lambda: f64,
}

impl<'a> Pass<'a> {
    fn new(
        model: &'a Model,
        faces: &'a [ContactFace],
        candidates: &'a [usize],
        d: Vector3<f64>,
        options: &'a StaticsOptions,
        best: Collapse,
        best_lambda: f64,
    ) -> Self {
        // The net load on every body points down for every λ below the best where gravity
        // wins over the load's vertical part: (1 + λ d_z) > 0 (the inertial load is −λ g d).
        let downward = 1.0 + best_lambda * d.z.min(0.0) > 0.0;
        Pass {
            model,
            faces,
            d,
            options,
            candidates,
            depth: loops(model),
            lifters: downward.then(|| lifters(model, faces)),
            best,
            best_lambda,
        }
    }

    fn lowers(&self, lambda: f64) -> bool {
        lambda < self.best_lambda * (1.0 - 1e-9)
    }

    /// Whether the interfaces not `removed` can hold every body: each is joined to the ground,
    /// and, where the load keeps pressing every body down, each keeps a face that can push it up
    /// ([`lifts`]). Necessary for an equilibrium with the removed interfaces unloaded, and it
    /// stays false when more are removed.
    fn holdable(&self, removed: &[bool]) -> bool {
        supported(self.model, removed)
            && self.lifters.as_ref().is_none_or(|lifters| {
                lifters
                    .iter()
                    .all(|interfaces| interfaces.iter().any(|&i| !removed[i]))
            })
    }

    /// The interfaces `set` as flags over the model's interfaces.
    fn flags(&self, set: &[usize]) -> Vec<bool> {
        let mut flags = vec![false; self.faces.len()];
        for &i in set {
            flags[i] = true;
        }
        flags
    }

    /// Whether the program with `set` freed answers below the best: a bound of the sets it
    /// holds. With no equilibrium at any λ ≥ 0 it bounds nothing (its subsets may hold).
    fn below_best(&mut self, set: &[usize]) -> Result<bool, Unexhausted> {
        let free = self.flags(set);
        match self.solve(&free, &[]) {
            Ok(c) => Ok(c.lambda.is_some_and(|l| self.lowers(l))),
            Err(StaticsError::DoesNotHold(_)) => Ok(true),
            Err(e) => Err(Unexhausted::failed(e)),
        }
    }

    /// The program with the interfaces `free` freed and the points `unloaded` unloaded, as
    /// written or at the model's precision ([`Precision`]).
    fn solve(&self, free: &[bool], unloaded: &[(usize, usize)]) -> Result<Collapse, StaticsError> {
        solve_program(self.model, self.faces, self.d, self.options, free, unloaded)
    }

    /// Whether the physical test of U's freed answer (λ_f = `lambda`) must fail, without its
    /// program: a collapse state with U unloaded has λ = λ_u = λ_f (its forces are feasible
    /// where U carries nothing, and optimal where U is freed). Where every point of U opens or
    /// slides in the freed mechanism, the test's program unloads them all, so it answers at most
    /// λ_u (`holding`): below λ_f, the test fails. On the bundled temple this is most sets (its
    /// columns standing free under an entablature that slides on them).
    fn unloads_below(&self, set: &[usize], freed: &Collapse, holding: f64, lambda: f64) -> bool {
        if holding >= lambda * (1.0 - UNLOADED_TOLERANCE) {
            return false;
        }
        let moving = moving_points(self.faces, freed);
        set.iter()
            .all(|&i| (0..self.faces[i].points.len()).all(|p| moving.contains(&(i, p))))
    }

    /// How many sets [`Pass::holdable`] keeps (None beyond `most`), without a program.
    fn count_sets(&self, most: usize) -> Option<usize> {
        let mut found = 0usize;
        let mut stack: Vec<(Vec<usize>, usize)> = vec![(Vec::new(), 0)];
        while let Some((set, from)) = stack.pop() {
            if set.len() >= self.depth {
                continue;
            }
            for k in from..self.candidates.len() {
                let mut trial = set.clone();
                trial.push(self.candidates[k]);
                if self.holdable(&self.flags(&trial)) {
                    found += 1;
                    if found > most {
                        return None;
                    }
                    stack.push((trial, k + 1));
                }
            }
        }
        Some(found)
    }

    /// Every set `set` + {candidates[k]} for k ≥ `from`, and the sets below each.
    fn children(&mut self, set: &[usize], from: usize) -> Result<(), Unexhausted> {
        if set.len() >= self.depth {
            return Ok(());
        }
        for k in from..self.candidates.len() {
            let mut trial = set.to_vec();
            trial.push(self.candidates[k]);
            if !self.holdable(&self.flags(&trial)) {
                continue;
            }
            // U unloaded: no equilibrium at λ ≥ 0 drops U and the sets below it.
            let unloaded: Vec<(usize, usize)> = trial
                .iter()
                .flat_map(|&i| (0..self.faces[i].points.len()).map(move |p| (i, p)))
                .collect();
            // As written first; where that has no equilibrium or does not solve, at the model's
            // precision (an upper block centred over the joint below balances on neither half
            // once rounded), unless the answer as written rules that out.
            let none = vec![false; self.faces.len()];
            let holding = solve_to_precision(
                self.model,
                self.faces,
                self.d,
                self.options,
                &none,
                &unloaded,
                &[],
                HOLDS_FROM,
            );
            let holding = match holding {
                Ok(c) => c.lambda.unwrap_or(self.options.lambda_max),
                Err(StaticsError::DoesNotHold(_)) => continue,
                Err(e) => return Err(Unexhausted::failed(e)),
            };
            if self.lowers(holding) {
                self.try_set(&trial, holding)?;
            }
            if trial.len() < self.depth {
                self.children(&trial, k + 1)?;
            }
        }
        Ok(())
    }

    /// U freed, kept as the best where it lowers λ and passes the physical test. `holding` is
    /// λ_u, U's program with every point of U unloaded. The physical test is tried as written
    /// and, where that falls short and its dual leaves room, at the model's precision
    /// ([`super::Precision`]).
    fn try_set(&mut self, set: &[usize], holding: f64) -> Result<(), Unexhausted> {
        let free = self.flags(set);
        let freed = match self.solve(&free, &[]) {
            Ok(freed) => freed,
            Err(StaticsError::DoesNotHold(_)) => return Ok(()),
            Err(e) => return Err(Unexhausted::failed(e)),
        };
        let Some(lambda) = freed.lambda.filter(|&l| self.lowers(l)) else {
            return Ok(());
        };
        if self.unloads_below(set, &freed, holding, lambda) {
            return Ok(());
        }
        let physical = physical_test(
            self.model,
            self.faces,
            self.d,
            self.options,
            &free,
            freed,
            true,
        )
        .map_err(Unexhausted::failed)?;
        if let Some(collapse) = physical {
            self.best = collapse;
            self.best_lambda = lambda;
        }
        Ok(())
    }
}
