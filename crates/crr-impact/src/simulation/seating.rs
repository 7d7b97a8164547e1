//! Seating and uplift: the opening mode of seated joints (a small complementarity problem solved
//! by single releases and an active set), releasing them, and seating joints that come to rest.

use super::*;

/// Finds the interfaces that open from a seated state at (t, q, q̇): releasing a seated slot on a
/// side must give it an opening acceleration on that side. First every single release is tried
/// (the strongest opening wins); if none opens and the structure has loops, all seated slots are
/// released together and their sides adjusted to the signs of their accelerations (an active-set
/// iteration that finds one-DOF mechanisms such as a trilithon's or an arch's). Returns the slots
/// to release with their sides, or None when the seated state holds.
pub fn opening_mode(
    model: &Model,
    ground: &GroundMotion,
    template: &Dynamics,
    t: f64,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
) -> Option<Vec<(usize, Side)>> {
    let seated = template.seated.clone();
    if seated.is_empty() {
        return None;
    }
    let tol = 1e-9 * model.gravity / model.size;
    let mut row = DVector::zeros(model.dof());
    let mut trial = template.clone();
    let mut accel = |trial: &mut Dynamics, slot: usize| -> Option<f64> {
        trial.accelerations(model, ground, t, q, qdot).ok()?;
        let bias = slot_row(model, &trial.kin, slot, &mut row);
        Some(row.dot(&trial.qddot) + bias)
    };
    let mut best: Option<(usize, Side, f64)> = None;
    for &k in &seated {
        for side in [Side::Positive, Side::Negative] {
            trial.seated = seated.iter().copied().filter(|&s| s != k).collect();
            trial.pivots = template.pivots.clone();
            trial.pivots.sides[k] = side;
            if let Some(a) = accel(&mut trial, k) {
                let opening = side.sign() * a;
                if opening > tol && best.is_none_or(|b| opening > b.2) {
                    best = Some((k, side, opening));
                }
            }
        }
    }
    if let Some((k, side, _)) = best {
        return Some(vec![(k, side)]);
    }
    if model.constraint_rows == 0 || seated.len() < 2 {
        return None;
    }
    // Active set over the seated slots released together: a slot closing on its side is tried
    // once on the other side; closing on both, it stays seated (the tilts of a loop of rocking
    // bases that the excitation does not drive: under x only, the y tilts). Whenever a slot
    // goes back to its seat the mechanism changes, so the others get their second try again.
    // Each return to a seat shrinks the set, and between two of them each slot flips at most
    // once: the iteration ends within (|seated| + 1)² evaluations.
    let mut released: Vec<(usize, Side, bool)> = seated
        .iter()
        .map(|&s| (s, template.pivots.sides[s], false))
        .collect();
    let bound = (seated.len() + 1) * (seated.len() + 1);
    for _ in 0..bound {
        trial.seated = seated
            .iter()
            .copied()
            .filter(|s| !released.iter().any(|r| r.0 == *s))
            .collect();
        trial.pivots = template.pivots.clone();
        for &(s, side, _) in &released {
            trial.pivots.sides[s] = side;
        }
        trial.accelerations(model, ground, t, q, qdot).ok()?;
        let mut next = Vec::with_capacity(released.len());
        let mut reseated = false;
        for &(s, side, tried) in &released {
            let bias = slot_row(model, &trial.kin, s, &mut row);
            let a = row.dot(&trial.qddot) + bias;
            if side.sign() * a > tol {
                next.push((s, side, tried));
            } else if !tried && a.abs() > tol {
                next.push((s, side.flipped(), true));
            } else {
                reseated = true;
            }
        }
        if next.len() == released.len() && next.iter().zip(&released).all(|(a, b)| a.1 == b.1) {
            return Some(released.into_iter().map(|(s, side, _)| (s, side)).collect());
        }
        if next.is_empty() {
            return None;
        }
        if reseated {
            for r in &mut next {
                r.2 = false;
            }
        }
        released = next;
    }
    None
}

impl Simulation<'_> {
    /// Releases seated slots if the seated state cannot hold now.
    pub(super) fn release_if_opening(
        &mut self,
    ) -> Result<Option<Vec<(usize, Side)>>, SimulationError> {
        if self.dynamics.seated.is_empty() {
            return Ok(None);
        }
        let (q, qdot) = (self.q(), self.qdot());
        let mode = opening_mode(self.model, self.ground, &self.dynamics, self.t, &q, &qdot);
        if let Some(mode) = &mode {
            for &(s, side) in mode {
                self.seated[s] = false;
                self.dynamics.pivots.sides[s] = side;
            }
            self.dynamics.seated = (0..self.model.slot_count)
                .filter(|&s| self.seated[s])
                .collect();
            self.uplift_time.get_or_insert(self.t);
            self.reset_solver();
        }
        Ok(mode)
    }

    /// Seats rocking joints that sit at φ ≈ 0 with a negligible rate while their acceleration
    /// points into their closed side (they cannot open on that side; left alone they would slip
    /// through the contact without a crossing to detect). They may then uplift on the other side.
    pub(super) fn settle_resting_joints(&mut self) -> Result<Option<f64>, SimulationError> {
        let model = self.model;
        let (q, qdot) = (self.q(), self.qdot());
        let mut angles = vec![0.0; model.slot_count];
        let mut kin = Data::new(model);
        slot_angles(model, &mut kin, &q, &self.dynamics.pivots, &mut angles);
        let candidates: Vec<usize> = (0..model.slot_count)
            .filter(|&s| !self.seated[s] && angles[s].abs() <= self.params.simultaneity)
            .collect();
        if candidates.is_empty() {
            return Ok(None);
        }
        let mut d = self.dynamics.clone();
        d.accelerations(model, self.ground, self.t, &q, &qdot)
            .map_err(|e| SimulationError::Dynamics {
                t: self.t,
                source: e,
            })?;
        let mut rates = vec![0.0; model.slot_count];
        slot_rates(model, &d.kin, &qdot, &mut rates);
        let mut row = DVector::zeros(model.dof());
        // A joint leaving φ = 0 against its acceleration returns after τ = 2|φ̇|/|φ̈|: the
        // segment is capped at τ/2 (the turning point) so the return is a plain sign change.
        let mut cap: Option<f64> = None;
        for &s in &candidates {
            let bias = slot_row(model, &d.kin, s, &mut row);
            let acc = row.dot(&d.qddot) + bias;
            let side = self.dynamics.pivots.sides[s].sign();
            if side * rates[s] > 0.0 && side * acc < 0.0 {
                let tau = 2.0 * rates[s].abs() / acc.abs();
                cap = Some(cap.map_or(0.5 * tau, |c: f64| c.min(0.5 * tau)));
            }
        }
        let closing: Vec<usize> = candidates
            .into_iter()
            .filter(|&s| {
                let bias = slot_row(model, &d.kin, s, &mut row);
                let acc = row.dot(&d.qddot) + bias;
                let side = self.dynamics.pivots.sides[s].sign();
                rates[s].abs() < self.params.seat_rate
                    && side * rates[s] <= 1e-12
                    && side * acc <= 0.0
            })
            .collect();
        if closing.is_empty() {
            return Ok(cap);
        }
        let held: Vec<usize> = (0..model.slot_count)
            .filter(|&s| self.seated[s] || closing.contains(&s))
            .collect();
        let (qd, kinetic) = plastic_projection(
            model,
            &self.dynamics,
            self.ground,
            self.t,
            &q,
            &qdot,
            &self.dynamics.pivots,
            &held,
        );
        d.ensure_mass_matrix(model);
        let before = 0.5 * qdot.dot(&(&d.kin.mass_matrix * &qdot));
        let u_before = potential_energy(model, &d.kin);
        for &s in &closing {
            self.seated[s] = true;
            if s < model.dof() {
                self.y[s] = 0.0;
            }
        }
        // Seating removes the kinetic energy of the stopped joints and the potential energy of
        // their residual angle (below `simultaneity`): both are booked as dissipated.
        let u_after = {
            let q_new = self.q();
            forward_kinematics(model, &mut kin, &q_new, &self.dynamics.pivots);
            potential_energy(model, &kin)
        };
        self.dissipated_at_impacts += before - kinetic + u_before - u_after;
        let n = model.dof();
        self.y[n..2 * n].copy_from_slice(qd.as_slice());
        self.dynamics.seated = (0..model.slot_count).filter(|&s| self.seated[s]).collect();
        self.reset_solver();
        self.release_if_opening()?;
        Ok(None)
    }
}
