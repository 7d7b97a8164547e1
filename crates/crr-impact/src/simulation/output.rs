//! Taking an output sample: the state at the sample time with the seated coordinates held at 0,
//! the hypotheses monitor on it (contact forces against tension and sliding), its energies from
//! the bodies' motion, and its record in the [`Samples`] with the running peaks and energy
//! balance.

use super::*;

/// The scalars of a sample being taken ([`Simulation::sample_at`]); its q, q̇ and slot states
/// wait in the workspace.
#[derive(Clone, Copy, Debug)]
pub(super) struct Taken {
    t: f64,
    pub(super) kinetic: f64,
    pub(super) potential: f64,
    pub(super) work_in: f64,
    pub(super) dissipated: f64,
}

impl Simulation<'_> {
    /// Takes the sample of state `y` = [q, q̇, W, D] at `t`: checks the contact hypotheses on it
    /// (the monitor), leaves its q, q̇ and slot states in the workspace and returns its scalars,
    /// for [`Self::record_sample`].
    pub(super) fn sample_at(&mut self, t: f64, y: &[f64]) -> Taken {
        self.sample_under_load_at(t, t, y)
    }

    /// [`Self::sample_at`] for a sample recorded at `t` whose state is the one at `t_state`, and
    /// whose contacts are judged under the ground acceleration there: a sample instant up to
    /// round-off past a step that ends at a breakpoint is the step's end state, and at a jump
    /// (a pulse that ends at a sample instant, its end computed as start + duration one ulp
    /// before it) the load at the grid instant would be the one after the jump, on a chain
    /// decided under the one before. A sample deferred past an uplift event is judged under the
    /// load the release was decided with (`deferred_to`; later samples are past it).
    pub(super) fn sample_under_load_at(&mut self, t: f64, t_state: f64, y: &[f64]) -> Taken {
        let n = self.model.dof();
        let (mut q, mut qdot) = (
            std::mem::take(&mut self.spare.sample_q),
            std::mem::take(&mut self.spare.sample_qdot),
        );
        copy_short(q.as_mut_slice(), &y[..n]);
        copy_short(qdot.as_mut_slice(), &y[n..2 * n]);
        // A seated coordinate is held at 0 (the dense output between projections carries round-off).
        for k in 0..n {
            if self.seated[k] {
                q[k] = 0.0;
                qdot[k] = 0.0;
            }
        }
        // The monitor's solve leaves the kinematics of this state in its workspace: the energies
        // read them when it ran (the same q and pivots), else the output workspace's.
        let mut monitor_kin = false;
        let t_load = t_state.max(self.deferred_to);
        if self.violation.is_none() {
            let d = &mut self.spare.monitor;
            d.pivots.clone_from(&self.dynamics.pivots);
            d.seated.clone_from(&self.dynamics.seated);
            let work = &mut self.spare.forces;
            if crate::monitor::contact_forces_into(
                &self.model,
                d,
                self.ground,
                t_load,
                &q,
                &qdot,
                work,
            )
            .is_ok()
            {
                let (forces, edges) = (&work.forces, &work.edges);
                monitor_kin = true;
                let residual = d.loop_residual(&self.model);
                if residual > self.loop_residual.largest {
                    self.loop_residual = super::LoopResidual {
                        largest: residual,
                        t,
                    };
                }
                let tol = crate::monitor::TENSION_TOLERANCE
                    * self.model.total_mass()
                    * self.model.gravity;
                // A tension in the least-norm forces of a hyperstatic structure: is there a
                // compressive distribution? (One linear program on the faces, only then.)
                let tension = forces.iter().any(|f| f.is_some_and(|f| f.normal < -tol))
                    || edges.iter().any(|e| e.near.min(e.far) < -tol);
                let mut found = if tension && self.model.constraint_rows > 0 {
                    crate::monitor::check_distribution_at(
                        &mut self.spare.faces,
                        &self.model,
                        d,
                        work,
                        (&q, &qdot),
                        crr_dynamics::eom::effective_gravity(&self.model, self.ground, t_load),
                        t,
                        self.params.friction,
                        tol,
                    )
                } else {
                    crate::monitor::check(
                        &self.model,
                        forces,
                        edges,
                        None,
                        t,
                        self.params.friction,
                        tol,
                    )
                };
                found = crate::monitor::settle_sliding(
                    &self.model,
                    d,
                    work,
                    found,
                    self.params.friction,
                    tol,
                );
                let snaps = super::SnapsAndLosses {
                    t,
                    snaps: self.energy_at_snaps,
                    lost: self.lost_at_impacts() + self.dissipated_by_forces(),
                };
                // A pull at a face measured as a hop waits for its episode (module `hops`);
                // the other contacts are judged without it.
                let mut excused: Option<Vec<Option<crate::monitor::ContactForce>>> = None;
                while let Some(v) = found.take() {
                    if !self.defer_tension(&v, snaps) {
                        self.record_violation(v, snaps);
                        break;
                    }
                    let work = &self.spare.forces;
                    let forces = excused.get_or_insert_with(|| work.forces.clone());
                    if let Some(i) = self.model.interface_index(&v.interface) {
                        forces[i] = None;
                    }
                    found = crate::monitor::check(
                        &self.model,
                        forces,
                        &work.edges,
                        None,
                        t,
                        self.params.friction,
                        tol,
                    );
                    // (Hops are deferred on trees only, whose slides need no settling.)
                }
            }
        }
        // T from the bodies' velocities (no M): the monitor's solve filled them.
        let kin = if monitor_kin {
            &self.spare.monitor.kin
        } else {
            forward_kinematics(&self.model, &mut self.out_kin, &q, &self.dynamics.pivots);
            crr_kinematics::velocities(&self.model, &mut self.out_kin, &qdot);
            &self.out_kin
        };
        let taken = Taken {
            t,
            kinetic: crr_kinematics::body_kinetic_energy(&self.model, kin),
            potential: potential_energy(&self.model, kin) - self.u_rest,
            work_in: y[2 * n],
            dissipated: self.dissipated_at_impacts + y[2 * n + 1],
        };
        if !self.open.files_tree {
            self.file_coordinates(&q, &qdot);
        }
        self.sample_openings(&q);
        (self.spare.sample_q, self.spare.sample_qdot) = (q, qdot);
        let mut states = std::mem::take(&mut self.spare.sample_states);
        states.clear();
        states.extend((0..self.original.slot_count).map(|s| self.slot_state(s)));
        self.spare.sample_states = states;
        taken
    }

    /// Records the current state as the last sample when it is later than the last one: a run
    /// that its caller stops between output samples keeps the state it reached (the end of a
    /// run records it the same way).
    pub fn record_final_sample(&mut self) {
        if self.last_sample_t < self.t {
            self.record_current_sample(self.t);
        }
    }

    /// Takes and records the sample of the current state at `t`.
    pub(super) fn record_current_sample(&mut self, t: f64) {
        // The first sample of an instant is the state before its events
        // (angle_before_events).
        if self.pre_event.0 != t {
            self.pre_event.0 = t;
            self.pre_event.1.clear();
            let coords = &self.model.coords;
            let values = coords
                .iter()
                .zip(&self.y)
                .map(|(c, &q)| (c.name.clone(), q));
            self.pre_event.1.extend(values);
            self.pre_event.2.clone_from(&self.dynamics.pivots.sides);
        }
        let y = std::mem::take(&mut self.y);
        let s = self.sample_at(t, &y);
        self.y = y;
        self.record_sample(s);
    }

    /// Records the sample [`Self::sample_at`] has just taken (its scalars `s`, its q, q̇ and
    /// slot states from the workspace) and updates the running peaks and energy balance.
    pub(super) fn record_sample(&mut self, s: Taken) {
        // In the file's coordinates: the chain's own when its tree is the file's.
        let (q, qdot) = if self.open.files_tree {
            (
                self.spare.sample_q.as_slice(),
                self.spare.sample_qdot.as_slice(),
            )
        } else {
            (self.file_q.as_slice(), self.file_qdot.as_slice())
        };
        for (p, q) in self.peak_abs.iter_mut().zip(q) {
            *p = p.max(q.abs());
        }
        let balance =
            (s.kinetic + s.potential - s.work_in + s.dissipated - self.energy_start).abs();
        self.balance_error = self.balance_error.max(balance);
        self.last_sample_t = s.t;
        self.samples.push(Sample {
            t: s.t,
            q,
            qdot,
            kinetic: s.kinetic,
            potential: s.potential,
            work_in: s.work_in,
            dissipated: s.dissipated,
            states: &self.spare.sample_states,
            openings: &self.spare.sample_openings,
        });
    }
}
