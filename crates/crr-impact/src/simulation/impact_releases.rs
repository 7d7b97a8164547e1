//! Seated joints that an impact opens.
//!
//! The momentum law acts at the impacting joints' new pivots, and the joints seated before the
//! impact stay seated through it ("all other hinges persisting"): a plastic impulse holds them
//! (`impacts`, `plastic_projection`). Physically a seated joint's contacts can only push. Where
//! holding them needs a pull (the most compressive distribution of the contact impulses over the
//! touching points has a normal impulse below −`IMPULSE_TENSION_TOLERANCE` W √(L/g), module
//! `landing_check`), the impact is Moreau's perfectly inelastic impact instead (Moreau 1988):
//! the contacts that stay closed take compressive impulses and those that open take none. Its
//! answer is the impulse program ([`super::impulse_qp`]) from the law's velocities with nothing
//! held. Where that program opens seated joints onto one of their pivots (rocking, a CRR
//! motion) and lifts no face off, the chain with those joints released on those pivots is the
//! motion that follows: the law is applied again on it, the remaining seated joints held. The
//! answer is taken only when it meets Moreau's conditions, checked on the bodies' velocities
//! and the contact points' impulses, not on the program's own numbers: every released joint
//! opens (its rate on its new pivot above `seat_rate`), no other joint near its seat turns into
//! it, and the impulse now pushes at every contact ([`least_normal_impulse`] within the tolerance).
//! Where the momentum law's hinges persist with compressive impulses, the two laws agree
//! (Moreau's optimality conditions hold at the plastic impulse exactly when compressive contact
//! impulses give it) and nothing here runs.
//!
//! Left to the monitor (`impulse_tension`), as before: the restitution and Dirac laws (they set
//! rates, not a point impulse), impacts whose program lifts a face off entirely (a block
//! leaving a support while its faces would have to slide, see the contact program), and the
//! loop-closing seats that may twist (a flip of their pivot moves their loop's rows).

use super::*;
use landing_check::{least_normal_impulse, pulls_beyond_tolerance};

/// The chain after an impact with seated joints opened (see the module's docs).
pub(super) struct Released {
    /// The pivots after the impact, the released joints on their new sides.
    pub after: ActivePivots,
    /// The joints seated before the impact and still held through it (the impacting or rocking
    /// joints it brings to rest are at rate 0 in `qdot`, and the impact seats them).
    pub held: Vec<usize>,
    /// The released slots.
    pub slots: Vec<usize>,
    /// The law's result on that chain (T⁻ and the free velocities).
    pub result: crate::laws::ImpactResult,
    /// q at the impact with the released tree joints at exactly 0 (a seated angle can carry the
    /// round-off of the step that seated it, which on the other pivot is its wrong side).
    pub q: DVector<f64>,
    /// q̇⁺ with `held` held, and T⁺.
    pub qdot: DVector<f64>,
    /// T⁺ (J).
    pub kinetic: f64,
}

/// What a momentum-law impact needs to be re-posed: the state at φ = 0 and before it.
#[derive(Clone, Copy)]
pub(super) struct ImpactState<'a> {
    pub t: f64,
    /// q at the impact (the impacting angles at 0).
    pub q: &'a DVector<f64>,
    /// The pivots and velocities before it.
    pub before: (&'a ActivePivots, &'a DVector<f64>),
    /// The impacting slots.
    pub impacting: &'a [usize],
    /// The impacting slots that impacted within `min_impact_interval` (they seat at this one).
    pub recent: &'a [usize],
    /// The chain has faces lifted off (a structure with loops, opened): nothing is released.
    pub open_faces: bool,
    /// The minimum rate of a joint that opens (rad/s).
    pub seat_rate: f64,
    /// The angle within which joints count as at their seats (rad).
    pub simultaneity: f64,
}

/// Whether `qdot_after` on the chain `after` with `held` seated needs a pull at some contact
/// beyond `IMPULSE_TENSION_TOLERANCE` W √(L/g).
fn pulls(
    model: &Model,
    work: &mut Dynamics,
    ground: &GroundMotion,
    s: &ImpactState,
    after: &ActivePivots,
    held: &[usize],
    qdot_after: &DVector<f64>,
) -> Option<bool> {
    work.pivots.clone_from(after);
    work.seated.clear();
    work.seated.extend_from_slice(held);
    work.seated.sort_unstable();
    work.seated.dedup();
    work.evaluate(model, ground, s.t, s.q, qdot_after);
    let least = least_normal_impulse(model, work, s.q, s.before, qdot_after, &[])?;
    Some(pulls_beyond_tolerance(model, least.min_normal))
}

/// The chain after a momentum-law impact whose held joints would pull, with the seated joints
/// Moreau's impact opens released (see the module's docs); None where holding them pushes, where
/// the impulse program opens none, lifts a face off or fails, or where its release is not
/// confirmed. `after`, `held` and `qdot_after` are the impact as the momentum law with every
/// seated joint held gives it; `free` the law's velocities before the held joints' projection.
#[allow(clippy::too_many_arguments)]
pub(super) fn seated_joints_opened(
    model: &Model,
    kin: &mut Data,
    laws: &mut LawWorkspace,
    work: &mut Dynamics,
    ground: &GroundMotion,
    s: &ImpactState,
    (after, held): (&ActivePivots, &[usize]),
    (free, qdot_after): (&DVector<f64>, &DVector<f64>),
) -> Result<Option<Released>, SimulationError> {
    // A chain with faces lifted off (a structure with loops, opened): the joints stay held
    // (see the module's docs).
    if held.is_empty()
        || s.open_faces
        || pulls(model, work, ground, s, after, held, qdot_after) != Some(true)
    {
        return Ok(None);
    }
    // Moreau's impact from the law's free velocities: `work` holds the chain after the impact
    // with the held joints seated (each offered both pivots).
    if !offers_both_pivots(model, work) {
        return Ok(None);
    }
    let Ok(decision) = impulse_qp(model, work, free) else {
        return Ok(None);
    };
    if decision.releases.is_empty()
        || !decision.lifting_off.is_empty()
        || !decision.complete
        || decision
            .releases
            .iter()
            .any(|&(k, _)| !held.contains(&k) || seating::is_twisting_closure_slot(model, k))
    {
        return Ok(None);
    }
    // The program's releases, less those the chain sends back into their seats (a release
    // slower than `seat_rate`, as the program's tolerance allows, is held again); and the
    // impact's seating candidates (the impacting joints, those rocking near their seats) that
    // the chain brings to rest or sends into their seats, seated with it as the impact does
    // (held here, seated by the impact after this). Each round holds at least one more joint.
    let mut releases = decision.releases;
    let mut seating: Vec<usize> = s.recent.to_vec();
    let (before, qdot) = s.before;
    let mut q = s.q.clone();
    let mut angles = vec![0.0; model.slot_count];
    let mut rates = vec![0.0; model.slot_count];
    let (opened, still, slots, result, qdot_released, kinetic) = loop {
        if releases.is_empty() {
            return Ok(None);
        }
        let mut opened = after.clone();
        for &(k, side) in &releases {
            opened.sides[k] = side;
        }
        let slots: Vec<usize> = releases.iter().map(|&(k, _)| k).collect();
        q.clone_from(s.q);
        for &k in slots.iter().filter(|&&k| k < model.dof()) {
            q[k] = 0.0;
        }
        let still: Vec<usize> = held
            .iter()
            .copied()
            .filter(|k| !slots.contains(k))
            .collect();
        let holding: Vec<usize> = still.iter().chain(&seating).copied().collect();
        // The law again, on the chain with the released joints on their new pivots (at φ = 0
        // both pivots place the bodies alike), and the joints still seated held.
        let Ok(result) = apply_law(
            model,
            kin,
            laws,
            work,
            ground,
            s.t,
            &q,
            qdot,
            before,
            &opened,
            s.impacting,
            &holding,
        ) else {
            return Ok(None);
        };
        let Ok((qdot_released, kinetic)) = plastic_projection(
            model,
            work,
            ground,
            s.t,
            &q,
            &result.qdot,
            &opened,
            &holding,
        ) else {
            return Ok(None);
        };
        slot_angles(model, kin, &q, &opened, &mut angles);
        crr_kinematics::velocities(model, kin, &qdot_released);
        slot_rates(model, kin, &qdot_released, &mut rates);
        let count = releases.len() + seating.len();
        releases.retain(|&(k, side)| side.sign() * rates[k] >= s.seat_rate);
        seating.extend((0..model.slot_count).filter(|&k| {
            !holding.contains(&k)
                && !slots.contains(&k)
                && (s.impacting.contains(&k) || angles[k].abs() <= s.simultaneity)
                && (rates[k].abs() < s.seat_rate || opened.sides[k].sign() * rates[k] < 0.0)
        }));
        if releases.len() + seating.len() == count {
            break (opened, holding, slots, result, qdot_released, kinetic);
        }
    };
    // Moreau's conditions on the answer: each released joint opens on its new pivot and no
    // joint near its seat turns into it (above), T does not grow, and every contact that stays
    // pushes.
    if kinetic > result.kinetic_before * (1.0 + 1e-9)
        || pulls(
            model,
            work,
            ground,
            &ImpactState { q: &q, ..*s },
            &opened,
            &still,
            &qdot_released,
        ) != Some(false)
    {
        return Ok(None);
    }
    let still: Vec<usize> = still.into_iter().filter(|k| held.contains(k)).collect();
    Ok(Some(Released {
        after: opened,
        held: still,
        slots,
        result,
        q,
        qdot: qdot_released,
        kinetic,
    }))
}
