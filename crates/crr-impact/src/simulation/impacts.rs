//! Impacts in the simulation: which law applies, the plastic impulse that keeps seated joints
//! seated, the regularised Dirac force, and the impact event itself (pivot switch, law, seating of
//! the joints that come to rest, bookkeeping).

use super::*;

/// Rate a joint seated at an impact may keep after the plastic impulse, as a fraction of
/// `seat_rate`: the impulse holds the rows it acts on to round-off (1e-12 of the rates or
/// better), so a joint left turning faster had its row dropped as dependent on the loops'.
const UNSTOPPED_RATE: f64 = 1e-3;

/// Regularised Dirac-delta laws acting as a continuous generalized force.
pub(super) struct Regularised {
    pub(super) slots: Vec<RegularisedSlot>,
    pub(super) angles: Vec<f64>,
}

impl Regularised {
    /// The regularised Dirac laws of `model`'s slots (None when it has none).
    pub(super) fn of(model: &Model) -> Option<Self> {
        let slots: Vec<RegularisedSlot> = (0..model.slot_count)
            .filter_map(
                |slot| match model.interfaces[slot_interface(model, slot)].impact {
                    ImpactLaw::DiracRegularised { r, c, width } => {
                        Some(RegularisedSlot { slot, r, c, width })
                    }
                    _ => None,
                },
            )
            .collect();
        (!slots.is_empty()).then(|| Regularised {
            slots,
            angles: vec![0.0; model.slot_count],
        })
    }
}

impl GeneralizedForce for Regularised {
    fn add(
        &mut self,
        model: &Model,
        kin: &Data,
        _t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        out: &mut DVector<f64>,
    ) {
        let n = model.dof();
        self.angles[..n].copy_from_slice(q.as_slice());
        closure_angles(model, kin, &mut self.angles[n..]);
        let mut f = DVector::zeros(n);
        dirac_regularised_force(model, kin, qdot, &self.angles, &self.slots, &mut f);
        *out += f;
    }
}

/// The plastic impulse that stops the given slots (and keeps the loops closed):
/// q̇⁺ = q̇ − M⁻¹Cᵀ(C M⁻¹ Cᵀ)⁺ C q̇ with C the closure rows and the slots' rate rows, i.e. the
/// impulse along those constraints only, with the smallest kinetic-energy loss: Gauss' principle
/// of impulsive motion for the momentum M q̇ ([`Dynamics::solve_impulse`], on the factor of M
/// and the selected independent rows). Dependent rows (slots locked together in a loop) are
/// harmless. Returns q̇⁺ and T⁺. `work` is a workspace for `model` (its pivots and seated slots
/// are overwritten).
#[allow(clippy::too_many_arguments)]
pub(super) fn plastic_projection(
    model: &Model,
    work: &mut Dynamics,
    ground: &GroundMotion,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    pivots: &ActivePivots,
    slots: &[usize],
) -> Result<(DVector<f64>, f64), SimulationError> {
    let d = work;
    d.pivots.clone_from(pivots);
    d.seated.clear();
    d.evaluate(model, ground, t, q, qdot);
    let kinetic = |m: &nalgebra::DMatrix<f64>, v: &DVector<f64>| 0.5 * v.dot(&(m * v));
    // Nothing to hold and no loop: q̇ stands. With loops the rows are applied even with no slot
    // held (a face that lands closes its loop on a velocity that leaves it).
    if slots.is_empty() && model.constraint_rows == 0 {
        return Ok((qdot.clone(), kinetic(&d.kin.mass_matrix, qdot)));
    }
    d.seated.extend_from_slice(slots);
    d.seated.sort_unstable();
    d.seated.dedup();
    let momentum = &d.kin.mass_matrix * qdot;
    let out = d
        .solve_impulse(model, t, &momentum)
        .map_err(|source| SimulationError::Dynamics { t, source })?
        .clone();
    let k = kinetic(&d.kin.mass_matrix, &out);
    Ok((out, k))
}

/// Applies the impact laws of the impacting slots: the momentum law if any of their interfaces
/// uses it; otherwise one rate law ([`restitution_law`]) with a factor per slot: r for
/// restitution, r^C for the exact Dirac law, and 1 for a regularised Dirac law (an elastic pivot
/// switch: its force does the dissipation on either side of the switch).
#[allow(clippy::too_many_arguments)]
pub(super) fn apply_law(
    model: &Model,
    kin: &mut Data,
    ws: &mut LawWorkspace,
    work: &mut Dynamics,
    ground: &GroundMotion,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
    impacting: &[usize],
    held: &[usize],
) -> Result<crate::laws::ImpactResult, ImpactError> {
    let law = |s: usize| model.interfaces[slot_interface(model, s)].impact;
    if impacting
        .iter()
        .any(|&s| matches!(law(s), ImpactLaw::Momentum))
    {
        return momentum_law_projected(model, kin, ws, work, ground, t, q, qdot, before, after);
    }
    if let Some(dirac) = impacting
        .iter()
        .map(|&s| match law(s) {
            ImpactLaw::Dirac { r, c } => Some((s, r, c)),
            _ => None,
        })
        .collect::<Option<Vec<_>>>()
    {
        return dirac_law_holding(model, kin, q, qdot, before, after, &dirac, held);
    }
    let factors: Vec<(usize, f64)> = impacting
        .iter()
        .map(|&s| match law(s) {
            ImpactLaw::Restitution(r) => (s, r),
            ImpactLaw::Dirac { r, c } => (s, r.powf(c)),
            _ => (s, 1.0),
        })
        .collect();
    restitution_law_holding(model, kin, q, qdot, before, after, &factors, held)
}

/// Scratch of [`Simulation::impact`], kept by the run: the state before the impact (q, q̇) and
/// at φ = 0 (q), the pivots before and after, the slot angles and rates (before the impact, and
/// of the trial velocities after it), and the lists of held, wrongly moving, seating candidate
/// and newly seated slots.
#[derive(Clone, Debug, Default)]
pub(super) struct ImpactBuffers {
    q: DVector<f64>,
    qdot: DVector<f64>,
    q_at: DVector<f64>,
    before: ActivePivots,
    after: ActivePivots,
    angles: Vec<f64>,
    rates_before: Vec<f64>,
    rates: Vec<f64>,
    held: Vec<usize>,
    wrong: Vec<usize>,
    candidates: Vec<usize>,
    pending: Vec<usize>,
}

impl Simulation<'_> {
    /// Before an impact: the run stops when it has had `max_impacts`, or when its last
    /// [`CHATTER_IMPACTS`] impacts came less than `min_impact_interval` apart on average among
    /// at most a tenth as many interfaces ([`SimulationError::Chatter`]).
    pub(super) fn check_impact_room(&self) -> Result<(), SimulationError> {
        if self.impacts.len() >= self.params.max_impacts {
            return Err(SimulationError::TooManyImpacts(self.params.max_impacts));
        }
        let Some(first) = self.impacts.len().checked_sub(CHATTER_IMPACTS) else {
            return Ok(());
        };
        let span = self.t - self.impacts[first].t;
        if span >= CHATTER_IMPACTS as f64 * self.params.min_impact_interval {
            return Ok(());
        }
        let mut interfaces: Vec<String> = Vec::new();
        for name in self.impacts[first..].iter().flat_map(|i| &i.interfaces) {
            if !interfaces.contains(name) {
                interfaces.push(name.clone());
            }
        }
        // Many joints ending their rocking together (each seats after one impact within the
        // interval) are no chatter: the same few interfaces must come back again and again.
        if interfaces.len() > CHATTER_IMPACTS / 10 {
            return Ok(());
        }
        Err(SimulationError::Chatter {
            t: self.t,
            count: CHATTER_IMPACTS,
            span,
            interfaces,
        })
    }

    /// Handles an impact fired by `slot` at the current time.
    pub(super) fn impact(&mut self, slot: usize) -> Result<usize, SimulationError> {
        self.check_impact_room()?;
        let model = Arc::clone(&self.model);
        let model = &*model;
        let (t, n) = (self.t, model.dof());
        // Workspaces of the run (given back below; an error return only costs a reallocation).
        let mut kin = self
            .spare
            .events_kin
            .take()
            .unwrap_or_else(|| Box::new(Data::new(model)));
        let mut work = self.take_trial();
        // Scratch of the run (given back below, or reallocated after an error return).
        let mut laws = std::mem::take(&mut self.spare.laws);
        let ImpactBuffers {
            mut q,
            mut qdot,
            mut q_at,
            mut before,
            mut after,
            mut angles,
            mut rates_before,
            mut rates,
            mut held,
            mut wrong,
            mut candidates,
            mut pending,
        } = std::mem::take(&mut self.spare.impact);
        assign(&mut q, &self.y[..n]);
        assign(&mut qdot, &self.y[n..2 * n]);
        before.clone_from(&self.dynamics.pivots);
        angles.clear();
        angles.resize(model.slot_count, 0.0);
        slot_angles(model, &mut kin, &q, &before, &mut angles);
        // U at the located state, for the snap of the impacting angles to 0 (booked below).
        let u_located = potential_energy(model, &kin);
        crr_kinematics::velocities(model, &mut kin, &qdot);
        rates_before.clear();
        rates_before.resize(model.slot_count, 0.0);
        slot_rates(model, &kin, &qdot, &mut rates_before);
        rates.clone_from(&rates_before);
        let mut impacting: Vec<usize> = (0..model.slot_count)
            .filter(|&s| {
                s == slot
                    || (!self.seated[s]
                        && angles[s].abs() <= self.params.simultaneity
                        && rates_before[s] * before.sides[s].sign() < 0.0)
                    // A joint already past its pivot by more than `simultaneity` (it crossed
                    // φ = 0 between two impacts of its neighbours without an event of its own)
                    // switches pivot now too, instead of rocking on past it.
                    || (!self.seated[s]
                        && before.sides[s].sign() * angles[s] < -self.params.simultaneity)
            })
            .collect();
        held.clear();
        held.extend((0..model.slot_count).filter(|&s| self.seated[s]));
        // A rocking joint at φ ≈ 0 that the impact sends into its closed side impacts too (its
        // pivot switches): enlarge the impacting set until no joint penetrates.
        // Each round leaves its pivots in `after` and its configuration in `q_at`.
        let (mut result, mut qdot_after, mut kinetic_after) = loop {
            after.clone_from(&before);
            for &s in &impacting {
                after.sides[s] = before.sides[s].flipped();
            }
            // The impact happens at φ = 0: the located state is within the event tolerance of it
            // (and a joint impacting with it within `simultaneity`). The laws act at φ = 0
            // exactly, where the two chains place every body identically; at the located
            // angle the pivot switch would move the bodies above by φ·|P⁺ − P⁻|.
            assign(&mut q_at, q.as_slice());
            for &s in &impacting {
                if s < n {
                    q_at[s] = 0.0;
                }
            }
            let q = &q_at;
            let mut result = apply_law(
                model,
                &mut kin,
                &mut laws,
                &mut work,
                self.ground,
                t,
                q,
                &qdot,
                &before,
                &after,
                &impacting,
                &held,
            )
            .map_err(|source| SimulationError::Impact { t, source })?;
            // Joints that were seated stay seated through the impact: a plastic impulse on them
            // (booked as dissipation), as "all other hinges persisting". With none, the law's
            // q̇⁺ and T⁺ = ½q̇⁺ᵀM⁺q̇⁺ (the same M⁺, at the same q) stand.
            let (qd, k) = if held.is_empty() {
                (std::mem::take(&mut result.qdot), result.kinetic_after)
            } else {
                plastic_projection(
                    model,
                    &mut work,
                    self.ground,
                    t,
                    q,
                    &result.qdot,
                    &after,
                    &held,
                )?
            };
            forward_kinematics(model, &mut kin, q, &after);
            crr_kinematics::velocities(model, &mut kin, &qd);
            slot_rates(model, &kin, &qd, &mut rates);
            wrong.clear();
            wrong.extend((0..model.slot_count).filter(|&s| {
                !self.seated[s]
                    && !impacting.contains(&s)
                    && angles[s].abs() <= self.params.simultaneity
                    && after.sides[s].sign() * rates[s] < -1e-12
            }));
            if wrong.is_empty() {
                break (result, qd, k);
            }
            impacting.extend_from_slice(&wrong);
        };
        // Seated joints the impact opens, where holding them through a momentum-law impact
        // would pull (module `impact_releases`: Moreau's impact, confirmed on the chain).
        let momentum_law = impacting.iter().any(|&s| {
            matches!(
                model.interfaces[slot_interface(model, s)].impact,
                ImpactLaw::Momentum
            )
        });
        let mut released: Vec<usize> = Vec::new();
        // Open chains only: on loops, following Moreau's impact led to flights and to states
        // past their pivots at the next impacts (arches and walls, docs/simulation.md).
        if momentum_law
            && !held.is_empty()
            && model.closures.is_empty()
            && !self.params.hold_seated_at_impacts
        {
            let recent: Vec<usize> = impacting
                .iter()
                .copied()
                .filter(|&s| t - self.last_impact[s] < self.params.min_impact_interval)
                .collect();
            let state = super::impact_releases::ImpactState {
                t,
                q: &q_at,
                before: (&before, &qdot),
                impacting: &impacting,
                recent: &recent,
                open_faces: !self.open.faces.is_empty(),
                seat_rate: self.params.seat_rate,
                simultaneity: self.params.simultaneity,
            };
            let opened = super::impact_releases::seated_joints_opened(
                model,
                &mut kin,
                &mut laws,
                &mut work,
                self.ground,
                &state,
                (&after, &held),
                (&result.qdot, &qdot_after),
            )?;
            if let Some(opened) = opened {
                after = opened.after;
                held = opened.held;
                released = opened.slots;
                result = opened.result;
                q_at = opened.q;
                qdot_after = opened.qdot;
                kinetic_after = opened.kinetic;
                forward_kinematics(model, &mut kin, &q_at, &after);
                crr_kinematics::velocities(model, &mut kin, &qdot_after);
                slot_rates(model, &kin, &qdot_after, &mut rates);
            }
        }
        let rates_after: Vec<f64> = impacting.iter().map(|&s| rates[s]).collect();
        // Seating of the impacting interfaces that come to rest. Seating one joint of a loop can
        // lock the others: seat, recompute the rates, and seat every impacting slot brought below
        // the threshold, until nothing changes.
        // Candidates: the impacting slots, and rocking slots resting at φ ≈ 0 with a negligible rate.
        candidates.clear();
        candidates.extend((0..model.slot_count).filter(|&s| {
            impacting.contains(&s)
                || (!self.seated[s] && angles[s].abs() <= self.params.simultaneity)
        }));
        let mut to_seat: Vec<usize> = candidates
            .iter()
            .copied()
            .filter(|&s| {
                rates[s].abs() < self.params.seat_rate
                    || (impacting.contains(&s) && t - self.last_impact[s] < self.params.min_impact_interval)
                    // A joint the law sends back into its closed side cannot open: it stays closed.
                    || after.sides[s].sign() * rates[s] < 0.0
            })
            .collect();
        pending.clone_from(&to_seat);
        while !pending.is_empty() {
            let all: Vec<usize> = held.iter().chain(&to_seat).copied().collect();
            (qdot_after, kinetic_after) = plastic_projection(
                model,
                &mut work,
                self.ground,
                t,
                &q_at,
                &qdot_after,
                &after,
                &all,
            )?;
            forward_kinematics(model, &mut kin, &q_at, &after);
            crr_kinematics::velocities(model, &mut kin, &qdot_after);
            slot_rates(model, &kin, &qdot_after, &mut rates);
            pending.clear();
            pending.extend(candidates.iter().copied().filter(|&s| {
                !to_seat.contains(&s)
                    && (rates[s].abs() < self.params.seat_rate
                        || after.sides[s].sign() * rates[s] < 0.0)
            }));
            to_seat.extend_from_slice(&pending);
        }
        // The plastic impulse holds every seated row it can act on to round-off: a seat left
        // turning is one whose row the loops make dependent (`SimulationError::UnheldSeat`).
        if let Some(&s) = to_seat
            .iter()
            .find(|&&s| rates[s].abs() > UNSTOPPED_RATE * self.params.seat_rate)
        {
            return Err(SimulationError::UnheldSeat {
                t,
                interface: model.interfaces[slot_interface(model, s)].name.clone(),
                rate: rates[s],
            });
        }
        // Every tree joint seated after the impact goes to exactly 0 (the joints seated with the
        // impacting ones had residual angles within `simultaneity`) and the loops close again,
        // positions then velocities, holding the impacting joints at the 0 they leave from on
        // their new pivots: the change of T + U this costs is booked with the snap below.
        let (t_snapped, u_snapped) = snap_to_seats(
            model,
            &mut kin,
            &after,
            &mut q_at,
            &mut qdot_after,
            |k| held.contains(&k) || to_seat.contains(&k),
            |k| impacting.contains(&k),
        )
        .map_err(|source| SimulationError::Dynamics { t, source })?;
        // Whether the impact's whole impulse pulls at a contact (module `landing_check`), on
        // the chain after it: its new pivots, the joints seated through it or at it. The
        // momentum law (applied when any impacting interface uses it) acts at the new pivots,
        // which are checked with the rest. The restitution and Dirac laws set the impacting
        // rates, not an impulse at a point: the impacting slots then touch on both pivots and
        // their interfaces take whatever impulse the law needs there (its own hypothesis), and
        // the contacts the impact holds besides (seated joints, other pivots, loops) are
        // checked; where every interface is the impact's, nothing is left to check.
        let set_by_law: &[usize] = if momentum_law { &[] } else { &impacting };
        let left_to_check = (0..model.interfaces.len()).any(|i| {
            !model.interfaces[i]
                .slots
                .clone()
                .any(|s| set_by_law.contains(&s))
        });
        if self.violation.is_none() && left_to_check {
            work.pivots.clone_from(&after);
            work.seated.clear();
            work.seated.extend(held.iter().chain(&to_seat).copied());
            work.seated.sort_unstable();
            work.seated.dedup();
            work.evaluate(model, self.ground, t, &q_at, &qdot_after);
            self.check_impulse(&work, &q_at, (&before, &qdot), &qdot_after, set_by_law);
        }
        let before_rates: Vec<f64> = impacting.iter().map(|&s| rates_before[s]).collect();
        let lost = result.kinetic_before - kinetic_after;
        let record = ImpactRecord {
            t,
            interfaces: {
                let mut names: Vec<String> = impacting
                    .iter()
                    .map(|&s| model.interfaces[slot_interface(model, s)].name.clone())
                    .collect();
                names.dedup();
                names
            },
            slots: impacting,
            rates_before: before_rates,
            rates_after,
            energy_lost: lost,
            energy_gain: result.kinetic_after > result.kinetic_before * (1.0 + 1e-9) + 1e-12,
            seated: to_seat,
            released,
        };
        // Sample just before the impact, then switch.
        self.record_current_sample(t);
        for &s in &record.slots {
            self.last_impact[s] = t;
        }
        // The switch; the pivots before go back to the scratch.
        std::mem::swap(&mut self.dynamics.pivots, &mut after);
        self.set_seated(
            record
                .seated
                .iter()
                .map(|&s| (s, true))
                .chain(record.released.iter().map(|&s| (s, false))),
        );
        // The snaps (the impacting angles to 0 before the law, the seated ones and the loops
        // after it) change T + U: booked too.
        let u_snap = u_located - u_snapped + kinetic_after - t_snapped;
        self.spare.events_kin = Some(kin);
        self.spare.trial = Some(work);
        self.spare.laws = laws;
        self.y[..n].copy_from_slice(q_at.as_slice());
        self.y[n..2 * n].copy_from_slice(qdot_after.as_slice());
        self.spare.impact = ImpactBuffers {
            q,
            qdot,
            q_at,
            before,
            after,
            angles,
            rates_before,
            rates,
            held,
            wrong,
            candidates,
            pending,
        };
        self.dissipated_at_impacts += lost;
        self.book_snap(u_snap);
        self.push_impact(record);
        self.reset_solver();
        // The joints that open right after the impact open before the post-impact sample, so
        // that its contact forces are those of the motion that follows (with the impact's
        // mode alone, a joint that must open at once shows a spurious tension).
        let released = self.release_if_opening();
        self.hops.after_impact = true;
        self.record_current_sample(t);
        self.hops.after_impact = false;
        released?;
        Ok(self.impacts.len() - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crr_kinematics::fixtures::{colonnade_row, random_chain, single_block, voussoir_arch};
    use nalgebra::DMatrix;

    /// The plastic projection on the sparse factors is the textbook formula
    /// q̇⁺ = q̇ − M⁻¹Cᵀ(C M⁻¹ Cᵀ)⁺ C q̇ evaluated densely with nalgebra's own Cholesky and SVD
    /// pseudo-inverse (C: the row-scaled closure rows and the held slots' rate rows, built here
    /// from Φ_q and [`slot_row`]), to 1e-10 of |q̇| (condition numbers below 1e4 here); the held
    /// slots and the loops end at rate 0 and T never grows. Held slots include tree coordinates
    /// (eliminated by the sparse form, rows in the dense one) and closure angles, or none (the
    /// loops' rows alone).
    #[test]
    fn the_plastic_projection_is_the_dense_pseudo_inverse_formula() {
        let cases: [(_, &[usize]); 6] = [
            (single_block(0.2, 1.0, 2500.0), &[0]),
            (voussoir_arch(7, 2.0, 2.4, 0.6), &[1, 3]),
            // Nothing held: the loops' rows alone (a face landing with no joint seated).
            (voussoir_arch(7, 2.0, 2.4, 0.6), &[]),
            (colonnade_row(3, 3), &[0, 4, 9]),
            (random_chain(5, 6, 2), &[2]),
            (random_chain(17, 7, 3), &[1, 5]),
        ];
        let ground = GroundMotion::none();
        for (spec, held) in &cases {
            let model = Model::from_spec(spec).expect("valid fixture");
            let n = model.dof();
            let pivots = ActivePivots::uniform(&model, Side::Positive);
            let mut kin = Data::new(&model);
            let mut q = DVector::from_fn(n, |i, _| 0.01 * (i as f64 * 1.3).cos());
            if model.constraint_rows > 0 {
                crr_dynamics::closed_chain::project_positions(
                    &model, &mut kin, &pivots, &mut q, None,
                )
                .expect("the loops close near the reference");
            }
            let qdot = DVector::from_fn(n, |i, _| 0.2 + 0.11 * i as f64);
            let mut work = Dynamics::new(&model, pivots.clone());
            let (out, kinetic) =
                plastic_projection(&model, &mut work, &ground, 0.0, &q, &qdot, &pivots, held)
                    .expect("the projection solves");
            // The dense reference, from the kinematics alone.
            forward_kinematics(&model, &mut kin, &q, &pivots);
            crr_kinematics::mass_matrix(&model, &mut kin);
            crr_kinematics::velocities(&model, &mut kin, &qdot);
            let rows = model.constraint_rows + held.len();
            let mut c = DMatrix::zeros(rows, n);
            if model.constraint_rows > 0 {
                crr_kinematics::constraint_jacobian(&model, &mut kin, &pivots);
                let scale = crr_dynamics::eom::constraint_row_scale(&model);
                for i in 0..model.constraint_rows {
                    for j in 0..n {
                        c[(i, j)] = scale[i] * kin.phi_q[(i, j)];
                    }
                }
            }
            let mut row = DVector::zeros(n);
            for (k, &s) in held.iter().enumerate() {
                slot_row(&model, &kin, s, &mut row);
                c.row_mut(model.constraint_rows + k)
                    .copy_from(&row.transpose());
            }
            let m = kin.mass_matrix.clone();
            let y = m
                .clone()
                .cholesky()
                .expect("M is positive definite")
                .solve(&c.transpose());
            let schur = &c * &y;
            let threshold = 1e-10 * schur.norm();
            let pinv = schur.pseudo_inverse(threshold).expect("SVD converges");
            let expected = &qdot - &y * (pinv * (&c * &qdot));
            let gap = (&out - &expected).norm();
            assert!(
                gap <= 1e-10 * qdot.norm(),
                "{n} coordinates: |Δq̇⁺| = {gap:e}"
            );
            let stopped = (&c * &out).amax();
            assert!(stopped <= 1e-10 * qdot.norm(), "{n}: C q̇⁺ = {stopped:e}");
            let t_before = 0.5 * qdot.dot(&(&m * &qdot));
            assert!((kinetic - 0.5 * out.dot(&(&m * &out))).abs() <= 1e-12 * t_before);
            assert!(kinetic <= t_before * (1.0 + 1e-12), "{n}: T grew");
        }
    }
}
