//! The event functions of an integration segment: impacts (a rocking angle through 0), collapse
//! (U through its threshold), uplift (a seated state that cannot hold), the edges of regularised
//! δ zones.

use super::*;
use crr_kinematics::{Parent, Role};

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
    /// Per slot, whether it is a rocking contact (two distinct pivots), not a pin
    /// ([`super::slots::is_contact`]): the toppling event watches these.
    pub(super) contacts: &'b [bool],
    /// Per rocking slot, its seat: where its impact is (sign(side)·φ at the seat), 0 except for an
    /// angle that starts the segment a little on the wrong side of its pivot ([`rocking_seats`]).
    pub(super) seats: Vec<f64>,
    pub(super) kin: Box<Data>,
    pub(super) pivots: ActivePivots,
    pub(super) angles: Vec<f64>,
    /// Present when some slot is seated: the dynamics to test releases with.
    /// Boxed: the segment's events are built and taken apart once per segment, and a
    /// [`Dynamics`] in place would make each of those moves a copy of about 1.7 kB.
    pub(super) uplift: Option<Box<Dynamics>>,
    /// Workspace of the uplift test (a copy of the dynamics, reused at every evaluation).
    pub(super) trial: Box<Dynamics>,
    /// The uplift test's factorisations at rest.
    pub(super) rest: RestCache,
    /// The part of each slot ([`crr_kinematics::Parts::of_slot`]).
    pub(super) slot_part: &'b [usize],
    /// q and q̇ of the state evaluated.
    pub(super) q: DVector<f64>,
    pub(super) qdot: DVector<f64>,
    pub(super) u_rest: f64,
    pub(super) energy_scale: f64,
    pub(super) collapse_drop: f64,
    /// Regularised-law zones |φ| < ε/2 (slot, ε/2): their edges stop the integration so that the
    /// narrow δ_ε is resolved by a fresh step-size selection.
    pub(super) zones: Vec<(usize, f64)>,
    /// The open faces ([`super::open_loops`]): each point's gap over the model size, plus
    /// [`ROCKING_EVENT_MARGIN`], falls through 0 when the point touches again.
    pub(super) open_faces: &'b [super::open_loops::OpenFace],
    /// Per gap event, its seat: 0, or where it starts when it starts below −margin (a snap of
    /// another landing or an impact left that point a hair inside its support), as
    /// [`rocking_seats`] does for angles: the event then fires when the point moves further in.
    pub(super) gap_seats: Vec<f64>,
    /// The faces rocking on a pivot (a corner, an edge or a hinge's line) that alone carry the
    /// bodies above them ([`pressing_faces`]), whose normal force is watched, by the tree slot of each (the first rocking
    /// slot of its interface). Each event is
    /// that force over W L, positive while the pivot presses, falling through 0 where it would
    /// pull: the face lifts off and every body it carries loses its only support (a flight).
    pub(super) pressing: Vec<usize>,
    /// The dynamics the pivots' forces are computed with (the current pivots and seats, solved
    /// as the run's own are; the subtree forces read the bias accelerations, which every solve
    /// fills); present when `pressing` is not empty.
    pub(super) pressing_trial: Option<Box<Dynamics>>,
}

impl SegmentEvents<'_> {
    pub(super) fn collapse_index(&self) -> usize {
        self.rocking.len()
    }
    pub(super) fn toppling_index(&self) -> usize {
        self.rocking.len() + 1
    }
    pub(super) fn uplift_index(&self) -> usize {
        self.rocking.len() + 2
    }
    pub(super) fn first_zone_index(&self) -> usize {
        self.rocking.len() + 2 + usize::from(self.uplift.is_some())
    }
    pub(super) fn first_gap_index(&self) -> usize {
        self.first_zone_index() + 2 * self.zones.len()
    }
    /// The (face, point) of gap event `j` (0-based over the gaps).
    pub(super) fn gap_point(&self, mut j: usize) -> (usize, usize) {
        for (f, face) in self.open_faces.iter().enumerate() {
            if j < face.len() {
                return (f, j);
            }
            j -= face.len();
        }
        unreachable!("a gap event's index is within the open faces' points")
    }
    fn gap_count(&self) -> usize {
        self.open_faces.iter().map(|f| f.len()).sum()
    }
    pub(super) fn first_pressing_index(&self) -> usize {
        self.first_gap_index() + self.gap_count()
    }
    /// The pivots' normal forces of [`Self::pressing`] at time t into `out` (needs
    /// [`Self::load_state`]): [`pressing_forces`].
    pub(super) fn pressing_values(&mut self, t: f64, out: &mut [f64]) {
        if let Some(trial) = self.pressing_trial.as_mut() {
            let state = (t, &self.q, &self.qdot);
            pressing_forces(
                self.model,
                self.ground,
                trial,
                &self.pivots,
                &self.pressing,
                state,
                out,
                None,
            );
        }
    }
    /// Gap event `j` (needs [`Self::load_state`]).
    fn gap_value(&self, j: usize) -> f64 {
        let (f, i) = self.gap_point(j);
        self.open_faces[f].gap(self.model, &self.kin, i) / self.model.size - self.gap_seats[j]
            + ROCKING_EVENT_MARGIN
    }
}

impl SegmentEvents<'_> {
    /// Loads q (and q̇) from y and the slot angles of q.
    fn load_state(&mut self, y: &[f64]) {
        let n = self.model.dof();
        copy_short(self.q.as_mut_slice(), &y[..n]);
        copy_short(self.qdot.as_mut_slice(), &y[n..2 * n]);
        slot_angles(
            self.model,
            &mut self.kin,
            &self.q,
            &self.pivots,
            &mut self.angles,
        );
    }

    /// The collapse function: U above its threshold, positive while standing (needs
    /// [`Self::load_state`]).
    fn collapse_value(&self) -> f64 {
        if self.rocking.is_empty() {
            1.0
        } else {
            (potential_energy(self.model, &self.kin) - self.u_rest) / self.energy_scale
                + self.collapse_drop
        }
    }

    /// The toppling function: π/2 less the largest rocking contact's angle on its pivot's side,
    /// positive while every body stands on its support (needs [`Self::load_state`]). A rocking
    /// joint turned to π/2 has laid its body on its support's plane, and beyond it the body
    /// would pass through its support (the initial states refused): that body has toppled,
    /// however light it is against the structure (whose U may not reach its threshold). A pin
    /// (one pivot line) is no contact: it turns through π/2 as a pendulum does. Its own event,
    /// not folded into the collapse function's: that one may stay below 0 after a crossing
    /// with the rotations shrinking, and a lesser of the two could then never fall through 0.
    fn toppling_value(&self) -> f64 {
        self.rocking
            .iter()
            .filter(|&&(s, _)| self.contacts[s])
            .map(|&(s, side)| std::f64::consts::FRAC_PI_2 - side.sign() * self.angles[s])
            .fold(1.0, f64::min)
    }

    /// The uplift function: +1 when the seated state cannot hold at t, −1 while it holds.
    fn uplift_value(&mut self, t: f64) -> f64 {
        let Some(template) = &self.uplift else {
            return -1.0;
        };
        let opens = opening_mode_in(
            self.model,
            self.ground,
            template,
            &mut self.trial,
            &mut self.rest,
            self.slot_part,
            t,
            &self.q,
            &self.qdot,
        )
        .is_some();
        if opens { 1.0 } else { -1.0 }
    }

    /// Every function but the uplift test at the state `y`: the impact angles, collapse, the
    /// δ zones' edges and the open faces' gaps.
    fn eval_distances(&mut self, y: &[f64], g: &mut [f64]) {
        self.load_state(y);
        for (i, &(s, side)) in self.rocking.iter().enumerate() {
            g[i] = side.sign() * self.angles[s] - self.seats[i] + ROCKING_EVENT_MARGIN;
        }
        g[self.collapse_index()] = self.collapse_value();
        g[self.toppling_index()] = self.toppling_value();
        let z0 = self.first_zone_index();
        for j in 0..2 * self.zones.len() {
            g[z0 + j] = self.zone_value(j);
        }
        let g0 = self.first_gap_index();
        for j in 0..self.gap_count() {
            g[g0 + j] = self.gap_value(j);
        }
    }

    /// Zone edge function `j` (0-based over the zones' two edges).
    fn zone_value(&self, j: usize) -> f64 {
        let (slot, half) = self.zones[j / 2];
        if j.is_multiple_of(2) {
            self.angles[slot] - half
        } else {
            self.angles[slot] + half
        }
    }
}

impl EventFunctions for SegmentEvents<'_> {
    fn count(&self) -> usize {
        self.first_pressing_index() + self.pressing.len()
    }

    fn eval(&mut self, t: f64, y: &[f64], g: &mut [f64]) {
        self.eval_distances(y, g);
        if self.uplift.is_some() {
            g[self.uplift_index()] = self.uplift_value(t);
        }
        let p0 = self.first_pressing_index();
        self.pressing_values(t, &mut g[p0..]);
    }

    /// After the projection of an accepted step: the angles, the collapse function, the zones
    /// and the gaps again; the uplift function keeps its value at the step's end before the
    /// projection. It is the sign of a decision (the contact program on the seated faces, the
    /// most costly evaluation of a step with loops): the projection moves the state by the
    /// loops' drift over one step, which cannot change that sign except at a threshold, and
    /// there the next step's end, on the projected trajectory, decides the crossing. Evaluating
    /// it twice per step doubled the contact program's cost (55 % of the 10 × 10 wall's run).
    fn eval_after_projection(&mut self, t: f64, y: &[f64], g: &mut [f64]) {
        self.eval_distances(y, g);
        let p0 = self.first_pressing_index();
        self.pressing_values(t, &mut g[p0..]);
    }

    /// One function alone: root location on an impact does not solve the uplift problem.
    fn eval_one(&mut self, i: usize, t: f64, y: &[f64], _g: &mut [f64]) -> f64 {
        // A tree slot's angle is its coordinate: no kinematics (root location on an impact
        // evaluates this function alone, a dozen times).
        if let Some(&(s, side)) = self.rocking.get(i)
            && s < self.model.dof()
        {
            return side.sign() * y[s] - self.seats[i] + ROCKING_EVENT_MARGIN;
        }
        self.load_state(y);
        if i < self.rocking.len() {
            let (s, side) = self.rocking[i];
            side.sign() * self.angles[s] - self.seats[i] + ROCKING_EVENT_MARGIN
        } else if i == self.collapse_index() {
            self.collapse_value()
        } else if i == self.toppling_index() {
            self.toppling_value()
        } else if self.uplift.is_some() && i == self.uplift_index() {
            self.uplift_value(t)
        } else if i < self.first_gap_index() {
            self.zone_value(i - self.first_zone_index())
        } else if i < self.first_pressing_index() {
            self.gap_value(i - self.first_gap_index())
        } else {
            // That pivot's force alone (root location evaluates it a dozen times).
            let j = i - self.first_pressing_index();
            let mut value = [1.0];
            if let Some(trial) = self.pressing_trial.as_mut() {
                let state = (t, &self.q, &self.qdot);
                let pivot = &self.pressing[j..=j];
                let (model, ground) = (self.model, self.ground);
                let pivots = &self.pivots;
                pressing_forces(model, ground, trial, pivots, pivot, state, &mut value, None);
            }
            value[0]
        }
    }

    /// The impact angles and the open faces' gaps: a joint can pass its pivot and come back
    /// within one step (the drum column under the restitution law, 0.9: a drum 5.7e-4 rad past
    /// its pivot and back within a step of 28 ms), an impact the steps' ends do not show.
    fn checked_inside(&self, i: usize) -> bool {
        i < self.rocking.len() || (self.first_gap_index()..self.first_pressing_index()).contains(&i)
    }

    /// The distances alone ([`Self::eval_distances`]): no decision of the uplift test, no
    /// pivot's force.
    fn eval_inside(&mut self, _t: f64, y: &[f64], g: &mut [f64]) {
        self.eval_distances(y, g);
    }

    fn direction(&self, i: usize) -> Direction {
        // Impacts (sign(side)·φ + margin), collapse (U past its threshold), toppling (a
        // contact's angle past π/2), the open faces' gaps and the pivots' normal forces fall
        // through 0.
        if i < self.rocking.len()
            || i == self.collapse_index()
            || i == self.toppling_index()
            || i >= self.first_gap_index()
        {
            Direction::Falling
        } else if self.uplift.is_some() && i == self.uplift_index() {
            Direction::Rising
        } else {
            Direction::Any
        }
    }
}

/// The seat of each rocking slot for its impact event: 0, except for an angle that starts the
/// segment on the wrong side of its pivot by more than [`ROCKING_EVENT_MARGIN`]
/// (`sign(side)·φ₀ < −margin`), whose seat is then where it starts. A loop-closing angle is
/// measured from the bodies' poses, so a seated one carries the loop's round-off (some 1e-10 rad)
/// that a release cannot set to 0 as it sets a tree coordinate; and an angle released at an
/// impact can pass its seat by round-off before the next impact of another joint ends the
/// segment (1e-10 rad at the next start). An event at 0 itself would then
/// start below its root and never fall through it: the joint would rock through its support
/// unseen, the run stopping later with the state on the wrong side of its pivot. A slot of a
/// regularised law (`regularised(slot)`) keeps its seat at 0: its δ zone is integrated through,
/// and a zone too narrow for the steps (refused when the model is built) is caught by the run's
/// invariant rather than healed by a pivot switch on a state the zone's force has ruined.
/// `angles` are the slot angles at the start of the segment.
pub(super) fn rocking_seats(
    rocking: &[(usize, Side)],
    angles: &[f64],
    regularised: impl Fn(usize) -> bool,
    seats: &mut Vec<f64>,
) {
    seats.clear();
    seats.extend(rocking.iter().map(|&(s, side)| {
        let start = side.sign() * angles[s];
        // Within the margin the event already starts above its root.
        if start < -ROCKING_EVENT_MARGIN && !regularised(s) {
            start
        } else {
            0.0
        }
    }));
}

/// The faces that rock on their pivot, can lift off it (two distinct pivots for the current
/// sides: a hinge's two pivot lines, a rocking base's corners or edges) and are the only
/// contact between the bodies they carry and the rest ([`only_support`]: every face of an open
/// chain; on loops a block hanging on one face, its others open): the first rocking tree slot
/// of each interface with one. A rocking base with a tilt seated turns on an edge, and its
/// rocking tilt's reaction about its other pivot is the edge's whole normal force times the
/// base's width (the seated tilt's reaction is about an axis across that lever, and the face's
/// tangential forces have no moment about a line in its plane). A pivot of such a face that
/// would pull means the bodies it carries fly. Not the faces a re-rooted chain turned round
/// (`turned`, per interface): their other pivot P′ moves with the file's child, whose face is
/// tilted from the supporting one by the angle, so the reaction about it would mix the
/// tangential force into the normal one. None unless `watched`: the file has no symmetry
/// rows (a symmetry row puts a torque on its coordinates, so the joint's reaction about its
/// other pivot is no longer its normal force alone) and no regularised impact law (its δ
/// zone's force is not in the solve of [`SegmentEvents::pressing_values`]).
pub(super) fn pressing_faces(
    model: &Model,
    pivots: &ActivePivots,
    seated: &[bool],
    turned: &[bool],
    watched: bool,
) -> Vec<usize> {
    if !watched || !model.symmetries.is_empty() {
        return Vec::new();
    }
    model
        .interfaces
        .iter()
        .zip(turned)
        .filter(|(iface, turned)| matches!(iface.role, Role::Tree { .. }) && !**turned)
        .filter_map(|(iface, _)| {
            let k = iface.slots.clone().find(|&s| !seated[s])?;
            let current = &pivots.sides[iface.slots.clone()];
            let mut other = current.to_vec();
            other[k - iface.slots.start] = other[k - iface.slots.start].flipped();
            let distinct =
                (iface.kind.pivot(current) - iface.kind.pivot(&other)).norm() > 1e-9 * model.size;
            (distinct && only_support(model, k)).then_some(k)
        })
        .collect()
}

/// Whether tree coordinate k's interface is the only contact between the bodies it carries
/// and the rest of the chain: no loop closure joins a body it carries to one it does not (or
/// to the ground). Then its subtree's load fₖ holds no closure force (those of loops within
/// the subtree enter it twice, with opposite signs), and its pivot's normal force is that of
/// the carried bodies' motion alone.
pub(super) fn only_support(model: &Model, k: usize) -> bool {
    let carried = |p: Parent| match p {
        Parent::Ground => false,
        Parent::Body(b) => model.carries(k, Some(model.body_coord[b])),
    };
    model.closures.iter().all(|cl| {
        let closing = &model.interfaces[cl.interface];
        carried(closing.parent) == carried(Parent::Body(closing.child))
    })
}

/// The normal force of each pivot of `pressing` (tree slots of faces rocking on a pivot,
/// [`pressing_faces`]) at the state (t, q, q̇), over W L, into `out`: σ′r′, r′ the joint's
/// reaction about its other pivot P′ of side σ′ while it carries no moment about its pivot P
/// (`seating::SubtreeLoads`, from a solve in `trial` with the current pivots and seats), as
/// the contact program reads a rocking face's lift (module `opening_qp`). Positive while the
/// pivot presses. Where the solve fails, +1 (no event) and false. `roundoff`, when given,
/// receives each value's round-off (that of the reaction's transfer to P′, over W L).
pub(super) fn pressing_forces(
    model: &Model,
    ground: &GroundMotion,
    trial: &mut Dynamics,
    pivots: &ActivePivots,
    pressing: &[usize],
    (t, q, qdot): (f64, &DVector<f64>, &DVector<f64>),
    out: &mut [f64],
    mut roundoff: Option<&mut [f64]>,
) -> bool {
    if trial.accelerations(model, ground, t, q, qdot).is_err() {
        out.fill(1.0);
        return false;
    }
    let loads = super::seating::SubtreeLoads::new(model, trial);
    let scale = model.total_mass() * model.gravity * model.size;
    for (j, &k) in pressing.iter().enumerate() {
        let (r_other, error) = loads.other_side_reaction(model, trial, pivots, k, 0.0);
        out[j] = pivots.sides[k].flipped().sign() * r_other / scale;
        if let Some(r) = roundoff.as_deref_mut() {
            r[j] = error / scale;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crr_kinematics::fixtures::{serial_chain, trilithon};

    /// A face is the only support of what it carries on an open chain (every tree coordinate of
    /// a hanging chain), and never in a loop: the trilithon's lintel closes its loop on the
    /// second post, so neither post's foot nor the first head carries alone; without that
    /// closure the first head carries the lintel alone, and each foot its post and what is on
    /// it.
    #[test]
    fn a_face_is_the_only_support_of_what_it_carries_outside_loops() {
        let chain = Model::from_spec(&serial_chain(4)).unwrap();
        assert!((0..chain.dof()).all(|k| only_support(&chain, k)));
        let frame = Model::from_spec(&trilithon(0.2, 1.0, 1.5, 0.3, 1.0)).unwrap();
        assert!(!frame.closures.is_empty());
        assert!((0..frame.dof()).all(|k| !only_support(&frame, k)));
        let closing: Vec<usize> = frame.closures.iter().map(|c| c.interface).collect();
        let open = frame.without_loop_closures(&closing).unwrap();
        assert!((0..open.dof()).all(|k| only_support(&open, k)));
    }
}
