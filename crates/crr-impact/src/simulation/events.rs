//! The event functions of an integration segment: impacts (a rocking angle through 0), collapse
//! (U through its threshold), uplift (a seated state that cannot hold), the edges of regularised
//! δ zones.

use super::*;

/// The impact event of a rocking slot is g = sign(side)·φ + this margin (rad), falling through 0.
/// A slot that starts a segment at φ = 0 exactly (just released, or just impacted) then starts
/// with g > 0 rather than at its root: the integrator takes the sign of a function that starts at
/// its root from its first values, so a joint released by a pulse too short to open it, sinking
/// back through its seat, would never have fired and would have rocked through its support. The
/// impact is located 1e-13 rad past φ = 0 (1e-12 s at 0.1 rad/s), and the impact sets φ = 0.
pub(super) const ROCKING_EVENT_MARGIN: f64 = 10.0 * crr_dynamics::integrator::EVENT_ZERO_TOL;

/// Event functions of one integration segment.
pub(super) struct SegmentEvents<'b> {
    pub(super) model: &'b Model,
    pub(super) ground: &'b GroundMotion,
    /// Rocking slots watched for a zero crossing, with their sides.
    pub(super) rocking: Vec<(usize, Side)>,
    pub(super) kin: Data,
    pub(super) pivots: ActivePivots,
    pub(super) angles: Vec<f64>,
    /// Present when some slot is seated: the dynamics to test releases with.
    pub(super) uplift: Option<Dynamics>,
    pub(super) u_rest: f64,
    pub(super) energy_scale: f64,
    pub(super) collapse_drop: f64,
    /// Regularised-law zones |φ| < ε/2 (slot, ε/2): their edges stop the integration so that the
    /// narrow δ_ε is resolved by a fresh step-size selection.
    pub(super) zones: Vec<(usize, f64)>,
}

impl SegmentEvents<'_> {
    pub(super) fn collapse_index(&self) -> usize {
        self.rocking.len()
    }
    pub(super) fn uplift_index(&self) -> usize {
        self.rocking.len() + 1
    }
    pub(super) fn first_zone_index(&self) -> usize {
        self.rocking.len() + 1 + usize::from(self.uplift.is_some())
    }
}

impl EventFunctions for SegmentEvents<'_> {
    fn count(&self) -> usize {
        self.first_zone_index() + 2 * self.zones.len()
    }

    fn eval(&mut self, t: f64, y: &[f64], g: &mut [f64]) {
        let n = self.model.dof();
        let q = DVector::from_column_slice(&y[..n]);
        slot_angles(
            self.model,
            &mut self.kin,
            &q,
            &self.pivots,
            &mut self.angles,
        );
        for (i, &(s, side)) in self.rocking.iter().enumerate() {
            g[i] = side.sign() * self.angles[s] + ROCKING_EVENT_MARGIN;
        }
        let ci = self.collapse_index();
        g[ci] = if self.rocking.is_empty() {
            1.0
        } else {
            (potential_energy(self.model, &self.kin) - self.u_rest) / self.energy_scale
                + self.collapse_drop
        };
        if let Some(template) = &self.uplift {
            let qdot = DVector::from_column_slice(&y[n..2 * n]);
            let opens = opening_mode(self.model, self.ground, template, t, &q, &qdot).is_some();
            g[self.uplift_index()] = if opens { 1.0 } else { -1.0 };
        }
        let z0 = self.first_zone_index();
        for (i, &(slot, half)) in self.zones.iter().enumerate() {
            g[z0 + 2 * i] = self.angles[slot] - half;
            g[z0 + 2 * i + 1] = self.angles[slot] + half;
        }
    }

    fn direction(&self, i: usize) -> Direction {
        // Impacts (sign(side)·φ + margin) and collapse (U past its threshold) fall through 0.
        if i < self.rocking.len() || i == self.collapse_index() {
            Direction::Falling
        } else if self.uplift.is_some() && i == self.uplift_index() {
            Direction::Rising
        } else {
            Direction::Any
        }
    }
}
