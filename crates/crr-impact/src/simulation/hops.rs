//! Hops: a pivot that pulls where a segment starts, and how far its face would open.
//!
//! A face rocking on a pivot that alone carries the bodies above it ([`pressing_faces`]) is
//! watched by an event for the instant its normal force N falls through 0 (a flight). Just after
//! an impact or a release the chain's new motion can make that force a pull from the segment's
//! first instant: the event cannot fire (it starts below its zero), and the rigid-contact model
//! holds a contact that, in fact, lets go. Such pulls are short (the next impact follows
//! microseconds to a millisecond later on the bundled drum column) and small, so the bodies
//! they would lift move apart by far less than a micrometre; or they are the start of a real
//! flight. This module measures which, as an episode per face.
//!
//! **The gap of the face released.** Let S be the bodies the face carries and L the rest of the
//! chain. At the state of the chain (q, q̇, and its q̈ from the solve), Newton–Euler on S gives
//! the wrench F = (f, m_P) the face transmits to S at its pivot P: f = Σ_S mᵢ(aᵢ − g_eff),
//! m_P = Σ_S [(cᵢ − P) × mᵢ(aᵢ − g_eff) + Iᵢαᵢ + ωᵢ × Iᵢωᵢ]; N = f·n, n the face's normal
//! (from L into S). Released, the same bodies have the coordinates of L, a free twist of S's
//! lowest body at P (6) and the coordinates inside S, with mass matrix M′ = Σ mᵢJ_cᵢᵀJ_cᵢ +
//! J_ωᵢᵀIᵢJ_ωᵢ; G maps them to the twist of S's lowest body at P less that of the body under the
//! face. The chain's motion is that system's under the constraint force Gᵀ F, and the free
//! motion has the same velocities at that instant, so the free motion's accelerations differ by
//! −M′⁻¹GᵀF and the gap's acceleration is a = −n·(G M′⁻¹ Gᵀ F)_linear. Both the normal and the
//! tangential parts of F go when the face lets go: on a block turning about a corner of the
//! ground at θ = 0 with rate θ̇, a = h θ̇² − g, the corner's own acceleration in free flight,
//! while N = m g (1 − ¾ sin²α) − m h θ̇².
//!
//! **The episode.** The face is read (N, a, and A: the largest |Δa_c| + ρ|Δα| of a body, ρ its
//! largest distance from its centre of mass) where each segment starts and at eight points of
//! every accepted step while an episode is open (a solve of the chain and one of M′ each). Over
//! each interval between readings, with the larger of its ends' a, A and Ω (the fastest
//! rotation of a body plus √(g/ρ_min)), the gap g and the departure D, both 0 with their rates
//! where the pull starts, follow g̈ = a + 2ΩḊ + Ω²D and D̈ = A + 2ΩḊ + Ω²D ([`Episode::read`]):
//! a and A are read on the chain's state, not the released one's, and the feedback terms bound
//! what that changes. The episode ends where the bound on the gap comes back to 0 (the face
//! lands, located within its interval), where an impact at the face itself turns it onto its
//! other pivot or seats it (it has landed), or, not landed (`closed` false), where D passes the
//! larger of `hop_tolerance` and 1e-3 of the model's size, where the dynamic chain changes or
//! where the run ends (a gap that closes while the chain still pulls has not landed either). An impact at another
//! face carries g and D on unchanged (the impulse the face transmits to S is compressive unless
//! the impact records an `impulse_tension`; removed, it would close the gap faster). A pull
//! where the released motion would not open the gap (a ≤ 0 with N < 0: the tangential part of
//! F holds the face down) has no answer without sliding.
//!
//! With `hop_tolerance` (m) above 0, a hop that opens, lands and departs by no more than it is
//! not a violation of the hypotheses (the monitor's `tension` at that face, sampled after the
//! impact, is deferred until the episode ends); any other is a `tension` at the episode's start,
//! as the monitor would have recorded it. With the default 0 every pull is a violation, and the
//! run's first violation, if a pull, carries its hop. Chains with
//! loops are not measured (their faces' pulls stay the monitor's).

use super::*;
use crr_kinematics::kinematics::{body_rotation, frame_point};
use crr_kinematics::rotation::skew;
use nalgebra::{DMatrix, Matrix3, Vector3, Vector6};

/// A pull at a pivot where a segment started, measured to its end ([`Trajectory::hops`]).
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct Hop {
    /// Interface name.
    pub interface: String,
    /// Where the pull started (s): an impact's or a release's instant.
    pub start: f64,
    /// The first reading at which the pivot pressed again (s), None if it never did.
    pub pull_end: Option<f64>,
    /// Where the face landed again (s: the bound on its gap back at 0, or an impact at the face
    /// itself), or where the measure stopped (`closed` false).
    pub end: f64,
    /// The largest pull read (N, positive).
    pub largest_pull: f64,
    /// How far the face would open (m): the largest gap of the motion released, to first order.
    pub separation: f64,
    /// The bound on how far any point of the bodies departs from crr's motion until the face
    /// lands again (m): a body's centre of mass plus its rotation times the model's size, and
    /// at least the separation.
    pub departure: f64,
    /// False when the face was not shown to land: the bound on its gap had not closed again
    /// when the run ended, the dynamic chain changed or the departure passed the larger of
    /// `hop_tolerance` and 1e-3 of the model's size, or it closed while the chain still pulled;
    /// beyond any tolerance. True for a pull that does not open (`opens` false).
    pub closed: bool,
    /// False when the motion released would not open the face where the pull started (its
    /// tangential force holds it down): no answer without sliding, beyond any tolerance.
    pub opens: bool,
}

impl Hop {
    /// Whether the hop stays within `tolerance` (m): it opens, lands again, and departs from
    /// crr's motion by no more than that.
    pub fn within(&self, tolerance: f64) -> bool {
        self.opens && self.closed && self.departure <= tolerance
    }
}

/// Readings per accepted step while an episode is open, evenly spaced, the last at the step's
/// end: the bound takes the larger acceleration of each interval's two ends, so the finer the
/// readings the closer it is to the motion released.
pub(super) const READINGS_PER_STEP: usize = 8;

/// The departure past which an episode stops, over the model's size ([`Simulation::hop_cut`]).
const HOP_CUT: f64 = 1e-3;

/// One reading of a face released ([`released_face`]).
#[derive(Clone, Copy, Debug)]
struct Reading {
    /// The pivot's normal force (N, positive pressing).
    normal: f64,
    /// The gap's acceleration in the motion released (m/s²).
    gap: f64,
    /// The largest |Δa_c| + L |Δα| of a body, the motion released against the chain's (m/s²).
    departure: f64,
    /// Ω: the fastest rotation of a body plus √(|g_eff| / L) (rad/s).
    omega: f64,
}

/// One open episode.
#[derive(Clone, Debug)]
pub(super) struct Episode {
    slot: usize,
    side: Side,
    start: f64,
    last_t: f64,
    /// The last reading.
    last: Reading,
    gap: f64,
    rate: f64,
    largest_gap: f64,
    /// The departure's bound D and its rate.
    departure: f64,
    departure_rate: f64,
    largest_pull: f64,
    pull_end: Option<f64>,
    /// The monitor's `tension` at this face, deferred (`hop_tolerance` > 0).
    deferred: Option<Deferred>,
    /// N where the pull started, and the snaps and losses then: the violation's, if the monitor
    /// had none to defer.
    first_normal: f64,
    snaps: SnapsAndLosses,
}

/// A violation the monitor found at a face pulling, waiting for its episode's separation.
#[derive(Clone, Debug)]
pub(super) struct Deferred {
    slot: usize,
    violation: crate::monitor::Violation,
    snaps: SnapsAndLosses,
}

/// The episodes of a run.
#[derive(Clone, Debug, Default)]
pub(super) struct Hops {
    open: Vec<Episode>,
    /// Deferred violations whose episode has not opened yet (the monitor's sample at an impact
    /// comes before the segment that follows it).
    waiting: Vec<Deferred>,
    pub(super) done: Vec<Hop>,
    /// [t, q, q̇] of the readings a segment's steps pass while an episode is open.
    pub(super) log: Vec<f64>,
    /// Each face read.
    readings: Vec<Reading>,
    /// Each body's largest distance from its centre of mass ([`body_radii`]), once per run.
    radii: Vec<f64>,
    /// (slot, start, end) of the episodes ended since the current segment started: the
    /// monitor's samples within one are that pull's.
    windows: Vec<(usize, f64, f64)>,
    /// Set while the sample after an impact or a landing is taken: the state the next segment
    /// starts from, whose pulls that segment measures.
    pub(super) after_impact: bool,
    slots: Vec<usize>,
    /// The violation [`Simulation::attach_hop`] last looked for without finding its hop (its
    /// time and interface, all its test reads) and how many hops of `done` it had looked at: a
    /// hop that did not cover it then never will, so each look reads only the hops ended since,
    /// not every hop of the run.
    attach_looked: Option<(f64, String, usize)>,
}

impl Hops {
    /// Whether an episode is open (a segment then logs its steps' states).
    pub(super) fn logging(&self) -> bool {
        !self.open.is_empty()
    }

    /// Whether no pull is being measured and no tension waits for one: the run's first
    /// violation is then final up to the time reached (an episode that ends records its
    /// violation at its start, which can be earlier than one recorded meanwhile).
    pub(super) fn settled(&self) -> bool {
        self.open.is_empty() && self.waiting.is_empty()
    }
}

impl Episode {
    fn new(
        slot: usize,
        side: Side,
        t: f64,
        r: Reading,
        deferred: Option<Deferred>,
        snaps: SnapsAndLosses,
    ) -> Self {
        Self {
            slot,
            side,
            start: t,
            last_t: t,
            last: r,
            gap: 0.0,
            rate: 0.0,
            largest_gap: 0.0,
            departure: 0.0,
            departure_rate: 0.0,
            largest_pull: -r.normal,
            pull_end: None,
            deferred,
            first_normal: r.normal,
            snaps,
        }
    }

    /// Adds the reading `r` at t; returns Some(true) when the gap's bound has closed again (the
    /// face lands: the episode is over), Some(false) when the departure has passed `cut` (the
    /// bodies are flying: the episode stops, not landed), None while it goes on. Over each interval, with the larger of its two ends' Ω, gap
    /// acceleration a and departure acceleration A:
    /// D̈ = A + 2ΩḊ + Ω²D bounds how far the motion released departs from the chain's (a point
    /// whose velocity is off by Ḋ and position by D has its centripetal, Coriolis and weight's
    /// terms off by at most about 2ΩḊ + Ω²D), and g̈ = a + 2ΩḊ + Ω²D bounds the gap, whose own
    /// acceleration a is read on the chain's state, not the released one's.
    fn read(&mut self, t: f64, r: Reading, cut: f64) -> Option<bool> {
        let h = t - self.last_t;
        if h > 0.0 {
            let a = r.gap.max(self.last.gap);
            let big_a = r.departure.max(self.last.departure);
            let omega = r.omega.max(self.last.omega);
            let opened = self.gap > 0.0;
            // RK4 on (g, ġ, D, Ḋ), linear with constant coefficients over the interval.
            let y0 = [self.gap, self.rate, self.departure, self.departure_rate];
            let mut y = bound_step(y0, h, a, big_a, omega);
            if opened && y[0] <= 0.0 {
                // The face lands within the interval: where, by bisection on its length.
                let (mut lo, mut hi) = (0.0, h);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if bound_step(y0, mid, a, big_a, omega)[0] > 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                for i in 1..16 {
                    let top = bound_step(y0, hi * i as f64 / 16.0, a, big_a, omega)[0];
                    self.largest_gap = self.largest_gap.max(top);
                }
                y = bound_step(y0, hi, a, big_a, omega);
                (self.gap, self.rate, self.departure, self.departure_rate) =
                    (y[0], y[1], y[2], y[3]);
                self.last_t += hi;
                // Landed while the chain still pulls: the face would lift again at once.
                return Some(r.normal >= 0.0);
            }
            if y0[1] > 0.0 && y[1] < 0.0 {
                // The gap's top lies within the interval.
                for i in 1..16 {
                    let top = bound_step(y0, h * i as f64 / 16.0, a, big_a, omega)[0];
                    self.largest_gap = self.largest_gap.max(top);
                }
            }
            (self.gap, self.rate, self.departure, self.departure_rate) = (y[0], y[1], y[2], y[3]);
            self.largest_gap = self.largest_gap.max(self.gap);
            if self.departure > cut {
                self.last_t = t;
                return Some(false);
            }
        }
        self.largest_pull = self.largest_pull.max(-r.normal);
        if r.normal >= 0.0 && self.pull_end.is_none() {
            self.pull_end = Some(t);
        }
        self.last_t = t;
        self.last = r;
        None
    }
}

/// (g, ġ, D, Ḋ) after `h` s of g̈ = a + 2ΩḊ + Ω²D, D̈ = A + 2ΩḊ + Ω²D from `y0` (one RK4 step:
/// the coefficients are constant over a reading's interval, and h Ω ≪ 1).
fn bound_step(y0: [f64; 4], h: f64, a: f64, big_a: f64, omega: f64) -> [f64; 4] {
    let f = |y: [f64; 4]| {
        let feedback = 2.0 * omega * y[3] + omega * omega * y[2];
        [y[1], a + feedback, y[3], big_a + feedback]
    };
    let add =
        |y: [f64; 4], k: [f64; 4], c: f64| -> [f64; 4] { std::array::from_fn(|i| y[i] + c * k[i]) };
    let k1 = f(y0);
    let k2 = f(add(y0, k1, 0.5 * h));
    let k3 = f(add(y0, k2, 0.5 * h));
    let k4 = f(add(y0, k3, h));
    std::array::from_fn(|i| y0[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// The largest distance of each body's points from its centre of mass (m), from its surface's
/// vertices, 0.1 % over (an annular sector's arcs are inscribed polygons, within 5e-4 of them).
fn body_radii(model: &Model) -> Vec<f64> {
    model
        .bodies
        .iter()
        .map(|body| {
            body.shape.surface().map_or(model.size, |surface| {
                let far = surface
                    .vertices
                    .iter()
                    .map(|v| (v - body.com).norm())
                    .fold(0.0, f64::max);
                1.001 * far
            })
        })
        .collect()
}

/// The coordinates carrying frame `frame`, from the ground up.
fn path(model: &Model, frame: Option<usize>) -> Vec<usize> {
    let mut p = Vec::new();
    let mut j = frame;
    while let Some(jj) = j {
        p.push(jj);
        j = model.coords[jj].parent;
    }
    p.reverse();
    p
}

/// The face of tree slot k (a face of [`pressing_faces`]) released at the solve in `trial`
/// (q̈ and the kinematics of the state, q̇ given): its pivot's normal force N (N, positive
/// pressing) and the acceleration of its gap in the motion released (m/s²), as the module's
/// documentation derives them. `seated` by slot. None where M′ is singular.
fn released_face(
    model: &Model,
    trial: &Dynamics,
    pivots: &ActivePivots,
    seated: &[bool],
    qdot: &DVector<f64>,
    k: usize,
    (g_eff, radii, forces): (&Vector3<f64>, &[f64], &[Vector3<f64>]),
    screen: Option<f64>,
) -> Option<Reading> {
    let kin = &trial.kin;
    let coord = &model.coords[k];
    let iface = &model.interfaces[coord.interface];
    let p = kin.pivot[k];
    let other = frame_point(
        kin,
        coord.parent,
        &super::seating::other_pivot_rest(iface, pivots, k),
    );
    let shift = kin.axis[k].cross(&(p - other));
    // The face's normal, from L into S: the line of the pivot's pressing force.
    let normal = pivots.sides[k].flipped().sign() * shift / shift.norm();
    let qddot = &trial.qddot;
    let face = |j: usize| iface.slots.contains(&j);
    let in_s = |frame: usize| model.carries(k, Some(frame));
    // N first (the carried bodies' forces along the normal): a face screened for a pull that
    // presses beyond `screen` needs no more.
    let pull: Vector3<f64> = (0..model.bodies.len())
        .filter(|&b| in_s(model.body_coord[b]))
        .map(|b| forces[b])
        .sum();
    let n = normal.dot(&pull);
    if screen.is_some_and(|tol| n >= -tol) {
        return Some(Reading {
            normal: n,
            gap: 0.0,
            departure: 0.0,
            omega: 0.0,
        });
    }
    // The released coordinates: L's free ones, the twist (ω, v_P) of S's lowest body, S's own.
    let dof = model.dof();
    let mut column = vec![usize::MAX; dof];
    let mut count = 0;
    for j in (0..dof).filter(|&j| !seated[j] && !in_s(j)) {
        column[j] = count;
        count += 1;
    }
    let base = count;
    count += 6;
    for j in (0..dof).filter(|&j| !seated[j] && in_s(j) && !face(j)) {
        column[j] = count;
        count += 1;
    }
    let mut jacobians = Vec::with_capacity(model.bodies.len());
    let mut fastest: f64 = 0.0;
    let mut mass = DMatrix::<f64>::zeros(count, count);
    let (mut jc, mut jw) = (DMatrix::zeros(3, count), DMatrix::zeros(3, count));
    let mut wrench = Vector6::zeros();
    for (b, body) in model.bodies.iter().enumerate() {
        let frame = model.body_coord[b];
        let c = kin.com[b];
        let rot = body_rotation(model, kin, b);
        let inertia = rot * body.inertia * rot.transpose();
        jc.fill(0.0);
        jw.fill(0.0);
        let (mut omega, mut alpha) = (Vector3::zeros(), Vector3::zeros());
        for j in path(model, Some(frame)) {
            let u = kin.axis[j];
            alpha += u * qddot[j] + omega.cross(&u) * qdot[j];
            omega += u * qdot[j];
            if column[j] != usize::MAX {
                jc.set_column(column[j], &u.cross(&(c - kin.pivot[j])));
                jw.set_column(column[j], &u);
            }
        }
        if in_s(frame) {
            let f = forces[b];
            let moment = (c - p).cross(&f) + inertia * alpha + omega.cross(&(inertia * omega));
            wrench += Vector6::new(f.x, f.y, f.z, moment.x, moment.y, moment.z);
            // v = v_P + ω × (c − P) = v_P − [c − P]× ω.
            jc.fixed_view_mut::<3, 3>(0, base)
                .copy_from(&(-skew(&(c - p))));
            jc.fixed_view_mut::<3, 3>(0, base + 3)
                .copy_from(&Matrix3::identity());
            jw.fixed_view_mut::<3, 3>(0, base)
                .copy_from(&Matrix3::identity());
        }
        mass += jc.transpose() * &jc * body.mass + jw.transpose() * inertia * &jw;
        fastest = fastest.max(omega.norm());
        jacobians.push((jc.clone(), jw.clone()));
    }
    // G: the twist at P of S's lowest body ([v; ω]) less that of the body under the face. L's
    // coordinates carry S as they carry the body under the face (the columns above), so the
    // six base coordinates are that relative twist, and G is their identity.
    let mut g = DMatrix::<f64>::zeros(6, count);
    g.fixed_view_mut::<3, 3>(0, base + 3)
        .copy_from(&Matrix3::identity());
    g.fixed_view_mut::<3, 3>(3, base)
        .copy_from(&Matrix3::identity());
    // Released, the accelerations change by −M′⁻¹GᵀF.
    let change = -(mass.cholesky()?.solve(&g.transpose()) * wrench);
    let relative = &g * &change;
    let departure = jacobians
        .iter()
        .zip(radii)
        .map(|((jc, jw), radius)| (jc * &change).norm() + radius * (jw * &change).norm())
        .fold(0.0, f64::max);
    let smallest = radii.iter().copied().fold(f64::INFINITY, f64::min);
    Some(Reading {
        normal: n,
        gap: normal.dot(&Vector3::new(relative[0], relative[1], relative[2])),
        departure,
        omega: fastest + (g_eff.norm() / smallest).sqrt(),
    })
}

impl Simulation<'_> {
    /// Reads each face of `slots` released at (t, q, q̇) ([`released_face`]) into
    /// `self.hops.readings`. False where the chain's solve or a face's M′ fails.
    fn read_faces(
        &mut self,
        slots: &[usize],
        (t, q, qdot): (f64, &DVector<f64>, &DVector<f64>),
        screen: Option<f64>,
    ) -> bool {
        let model = Arc::clone(&self.model);
        let model = &*model;
        if self.hops.radii.len() != model.bodies.len() {
            self.hops.radii = body_radii(model);
        }
        let mut trial = self.take_pressing_trial();
        self.hops.readings.clear();
        let mut solved = trial.accelerations(model, self.ground, t, q, qdot).is_ok();
        let g_eff = trial.effective_gravity();
        if solved {
            let forces = super::seating::body_forces(model, &trial);
            let loads = (&g_eff, self.hops.radii.as_slice(), forces.as_slice());
            for &k in slots {
                // An open episode's face is read in full; another only if it pulls.
                let screen = screen.filter(|_| !self.hops.open.iter().any(|e| e.slot == k));
                let pivots = &self.dynamics.pivots;
                match released_face(model, &trial, pivots, &self.seated, qdot, k, loads, screen) {
                    Some(r) => self.hops.readings.push(r),
                    None => {
                        solved = false;
                        break;
                    }
                }
            }
        }
        self.spare.pressing = Some(trial);
        solved
    }

    /// At a segment's start, with `pressing` the faces watched in it: ends the episodes whose
    /// face is no longer watched on the same pivot, reads the others at this state, and opens an
    /// episode at each watched face whose pivot pulls here beyond the monitor's tolerance. A
    /// violation deferred at a face that does not pull here after all is recorded. Chains with
    /// loops are not measured.
    pub(super) fn hops_at_segment_start(&mut self, pressing: &[usize]) {
        let t = self.t;
        self.hops.windows.clear();
        let measured = self.model.constraint_rows == 0 && !pressing.is_empty();
        if !measured && self.hops.open.is_empty() && self.hops.waiting.is_empty() {
            return;
        }
        let mut i = 0;
        while i < self.hops.open.len() {
            let e = &self.hops.open[i];
            if pressing.contains(&e.slot) && self.dynamics.pivots.sides[e.slot] == e.side {
                i += 1;
            } else {
                // An impact at the face itself turned it onto its other pivot or seated it:
                // the face has landed.
                let e = self.hops.open.remove(i);
                self.finish_hop(e, true, true);
            }
        }
        let mut slots = std::mem::take(&mut self.hops.slots);
        slots.clear();
        slots.extend_from_slice(pressing);
        let (q, qdot) = (self.chain_q(), self.chain_qdot());
        let tol = crate::monitor::TENSION_TOLERANCE * self.model.total_mass() * self.model.gravity;
        let cut = self.hop_cut();
        if measured && self.read_faces(&slots, (t, &q, &qdot), Some(tol)) {
            let mut over = Vec::new();
            for (j, &k) in slots.iter().enumerate() {
                let r = self.hops.readings[j];
                if let Some(e) = self.hops.open.iter_mut().find(|e| e.slot == k) {
                    if let Some(closed) = e.read(t, r, cut) {
                        over.push((k, closed, true));
                    }
                } else if r.normal < -tol {
                    let deferred = self
                        .hops
                        .waiting
                        .iter()
                        .position(|d| d.slot == k && d.violation.t == t)
                        .map(|i| self.hops.waiting.remove(i));
                    let snaps = SnapsAndLosses {
                        t,
                        snaps: self.energy_at_snaps,
                        lost: self.lost_at_impacts() + self.dissipated_by_forces(),
                    };
                    let side = self.dynamics.pivots.sides[k];
                    let e = Episode::new(k, side, t, r, deferred, snaps);
                    self.hops.open.push(e);
                    if r.gap <= 0.0 {
                        // Released, the face would not open: no answer without sliding.
                        over.push((k, true, false));
                    }
                }
            }
            for (k, closed, opens) in over {
                let i = self.hops.open.iter().position(|e| e.slot == k).unwrap();
                let e = self.hops.open.remove(i);
                self.finish_hop(e, closed, opens);
            }
        }
        self.hops.slots = slots;
        // A deferral no episode took: the monitor's word stands.
        for d in std::mem::take(&mut self.hops.waiting) {
            self.record_violation(d.violation, d.snaps);
        }
    }

    /// The departure past which an episode stops, not landed: the larger of `hop_tolerance`
    /// and 1e-3 of the model's size (a flight, whose reading every step would otherwise go on).
    fn hop_cut(&self) -> f64 {
        self.params.hop_tolerance.max(HOP_CUT * self.model.size)
    }

    /// Reads the open episodes' faces at the states a segment logged ([t, q, q̇] each).
    pub(super) fn hops_read_log(&mut self) {
        let n = self.model.dof();
        let cut = self.hop_cut();
        let log = std::mem::take(&mut self.hops.log);
        let mut slots = std::mem::take(&mut self.hops.slots);
        let (mut q, mut qdot) = (DVector::zeros(n), DVector::zeros(n));
        for state in log.chunks_exact(1 + 2 * n) {
            if self.hops.open.is_empty() {
                break;
            }
            slots.clear();
            slots.extend(self.hops.open.iter().map(|e| e.slot));
            q.as_mut_slice().copy_from_slice(&state[1..=n]);
            qdot.as_mut_slice().copy_from_slice(&state[1 + n..]);
            for k in 0..n {
                if self.seated[k] {
                    q[k] = 0.0;
                    qdot[k] = 0.0;
                }
            }
            if !self.read_faces(&slots, (state[0], &q, &qdot), None) {
                continue;
            }
            for (j, &k) in slots.iter().enumerate() {
                let r = self.hops.readings[j];
                let i = self.hops.open.iter().position(|e| e.slot == k).unwrap();
                if let Some(closed) = self.hops.open[i].read(state[0], r, cut) {
                    let e = self.hops.open.remove(i);
                    self.finish_hop(e, closed, true);
                }
            }
        }
        self.hops.slots = slots;
        let mut log = log;
        log.clear();
        self.hops.log = log;
    }

    /// Ends every open episode (the end of the run, a change of chain) and records any
    /// deferral left.
    pub(super) fn finish_hops(&mut self) {
        for e in std::mem::take(&mut self.hops.open) {
            self.finish_hop(e, false, true);
        }
        for d in std::mem::take(&mut self.hops.waiting) {
            self.record_violation(d.violation, d.snaps);
        }
        self.hops.windows.clear();
        self.attach_hop();
    }

    /// Records episode `e`'s hop, and decides its violation: beyond `hop_tolerance` (with the
    /// default 0, any pull), or where the face would not open, the face let go: recorded at the
    /// episode's start, with the separation.
    fn finish_hop(&mut self, e: Episode, closed: bool, opens: bool) {
        let interface = self.model.interfaces[self.model.coords[e.slot].interface]
            .name
            .clone();
        let separation = e.largest_gap;
        let hop = Hop {
            interface: interface.clone(),
            start: e.start,
            pull_end: e.pull_end,
            end: e.last_t,
            largest_pull: e.largest_pull,
            separation,
            departure: e.departure.max(separation),
            closed,
            opens,
        };
        let within = hop.within(self.params.hop_tolerance);
        self.hops.windows.push((e.slot, e.start, e.last_t));
        if !within {
            // Beyond the tolerance: the monitor's deferred word, or this pull's own (the monitor
            // took no sample where it started, or one whose solve failed).
            let (mut v, snaps) = match e.deferred {
                Some(d) => (d.violation, d.snaps),
                None => (
                    crate::monitor::Violation {
                        t: e.start,
                        interface: interface.clone(),
                        kind: "tension".into(),
                        normal: e.first_normal,
                        friction_demand: f64::INFINITY,
                        hop: None,
                    },
                    e.snaps,
                ),
            };
            v.hop = Some(Box::new(hop.clone()));
            self.record_violation(v, snaps);
        }
        self.hops.done.push(hop);
        // The monitor's own `tension` in this window (recorded first, at the same instant or
        // inside the pull) carries the hop too.
        self.attach_hop();
    }

    /// Gives the run's first violation, a `tension` without its hop, the hop that ended and
    /// covers it (the monitor's sample inside an episode already ended when it was judged).
    pub(super) fn attach_hop(&mut self) {
        let Some(v) = self.violation.as_mut() else {
            return;
        };
        if v.kind != "tension" || v.hop.is_some() {
            return;
        }
        let looked_at = self.hops.done.len();
        let from = match &mut self.hops.attach_looked {
            Some((t, interface, count)) if *t == v.t && *interface == v.interface => {
                std::mem::replace(count, looked_at)
            }
            other => {
                *other = Some((v.t, v.interface.clone(), looked_at));
                0
            }
        };
        if let Some(h) = self.hops.done[from..]
            .iter()
            .rev()
            .find(|h| h.interface == v.interface && h.start <= v.t && v.t <= h.end)
        {
            v.hop = Some(Box::new(h.clone()));
            // A violation that replaces this one at the same instant and face looks from the
            // start again: this hop covers it too.
            self.hops.attach_looked = None;
        }
    }

    /// Keeps `v` as the run's first violation if it is earlier than the one recorded; at the
    /// same instant, the graver ([`crate::monitor::Violation::graver_than`]: the same face
    /// whatever order the file lists them in, or the order the monitor and the hops find them
    /// in).
    pub(super) fn record_violation(&mut self, v: crate::monitor::Violation, snaps: SnapsAndLosses) {
        let first = |w: &crate::monitor::Violation| v.t < w.t || (v.t == w.t && v.graver_than(w));
        if self.violation.as_ref().is_none_or(first) {
            self.violation = Some(v);
            self.snaps_at_violation = Some(snaps);
        }
    }

    /// Whether the monitor's `tension` `v` is at a face whose pull is measured as a hop
    /// (`hop_tolerance` > 0, a chain without loops, the face watched now): a sample within one
    /// of that face's episodes (open, or ended since the segment started) is that pull's; a
    /// sample of the state where the next segment starts (an impact's end) waits for the episode
    /// that segment opens. Returns true when `v` is deferred or excused so; a pull the monitor
    /// finds anywhere else is recorded at once.
    pub(super) fn defer_tension(
        &mut self,
        v: &crate::monitor::Violation,
        snaps: SnapsAndLosses,
    ) -> bool {
        if self.params.hop_tolerance <= 0.0 || v.kind != "tension" || self.model.constraint_rows > 0
        {
            return false;
        }
        let Some(i) = self.model.interface_index(&v.interface) else {
            return false;
        };
        let Some(k) = self
            .pressing_faces_now()
            .into_iter()
            .find(|&k| self.model.coords[k].interface == i)
        else {
            return false;
        };
        let within =
            |&(slot, start, end): &(usize, f64, f64)| slot == k && start <= v.t && v.t <= end;
        if self.hops.open.iter().any(|e| e.slot == k && e.start <= v.t)
            || self.hops.windows.iter().any(within)
        {
            return true;
        }
        if !(self.hops.after_impact && v.t == self.t) {
            return false;
        }
        if !self.hops.waiting.iter().any(|d| d.slot == k) {
            self.hops.waiting.push(Deferred {
                slot: k,
                violation: v.clone(),
                snaps,
            });
        }
        true
    }
}

#[cfg(test)]
mod attach_tests {
    //! `attach_hop` remembers how far it has looked: after any sequence of hops ending and
    //! first violations replacing one another it attaches what a look through every hop of the
    //! run, newest first, finds.
    use super::*;
    use crr_dynamics::InitialSpec;
    use crr_kinematics::fixtures::single_block;

    fn hop(interface: &str, start: f64, end: f64) -> Hop {
        Hop {
            interface: interface.into(),
            start,
            pull_end: Some(end),
            end,
            largest_pull: 1.0,
            separation: start * 1e-6,
            departure: end * 1e-6,
            closed: true,
            opens: true,
        }
    }

    fn tension(interface: &str, t: f64, normal: f64) -> crate::monitor::Violation {
        crate::monitor::Violation {
            t,
            interface: interface.into(),
            kind: "tension".into(),
            normal,
            friction_demand: 0.0,
            hop: None,
        }
    }

    /// The newest hop of `done` at the violation's face whose episode holds its instant.
    fn covering(done: &[Hop], v: &crate::monitor::Violation) -> Option<Hop> {
        done.iter()
            .rev()
            .find(|h| h.interface == v.interface && h.start <= v.t && v.t <= h.end)
            .cloned()
    }

    #[test]
    fn the_hop_attached_is_the_one_a_look_through_every_hop_finds() {
        let model = Model::from_spec(&single_block(0.2, 1.0, 2500.0)).unwrap();
        let initial = crr_dynamics::solve_initial(&model, &InitialSpec::default()).unwrap();
        let ground = GroundMotion::none();
        let mut sim = Simulation::new(&model, &ground, &initial, Parameters::default()).unwrap();
        let snaps = SnapsAndLosses::default();
        enum Step {
            Ends(Hop),
            Violation(crate::monitor::Violation),
        }
        let steps = [
            Step::Violation(tension("base", 1.0, -5.0)),
            Step::Ends(hop("other", 0.9, 1.1)),
            Step::Ends(hop("base", 0.2, 0.5)),
            // Covers t = 1.0: attached.
            Step::Ends(hop("base", 0.95, 1.05)),
            // A graver tension at the same instant and face replaces the first: covered by the
            // same hop, which ended before it was recorded.
            Step::Violation(tension("base", 1.0, -9.0)),
            Step::Ends(hop("base", 1.2, 1.3)),
            // An earlier tension: only the hop that ended long ago covers it.
            Step::Violation(tension("base", 0.3, -1.0)),
            Step::Ends(hop("base", 1.4, 1.5)),
            // Earlier still, at a face no hop has covered yet; then one that does ends.
            Step::Violation(tension("other", 0.1, -2.0)),
            Step::Ends(hop("base", 0.0, 0.2)),
            Step::Ends(hop("other", 0.05, 0.15)),
            Step::Ends(hop("other", 0.08, 0.12)),
        ];
        // The reference: a look through every hop of the run, newest first, at each call, as
        // before; a hop once attached stays with its violation.
        let mut reference: Option<Hop> = None;
        let key = |h: &Hop| (h.interface.clone(), h.start, h.end);
        let mut attached = 0;
        for (i, step) in steps.into_iter().enumerate() {
            match step {
                Step::Ends(h) => sim.hops.done.push(h),
                Step::Violation(v) => {
                    let normal = v.normal;
                    sim.record_violation(v, snaps);
                    let first = sim.violation.as_ref().unwrap();
                    assert_eq!(first.normal, normal, "step {i}: the first violation now");
                    reference = None;
                }
            }
            sim.attach_hop();
            let v = sim.violation.as_ref().unwrap();
            if reference.is_none() {
                reference = covering(&sim.hops.done, v);
            }
            let got = v.hop.as_deref().map(key);
            assert_eq!(got, reference.as_ref().map(key), "step {i}: {v:?}");
            attached += usize::from(got.is_some());
        }
        // Steps 3 to 7 (t = 1.0, then 0.3) and 10 to 11 (the first hop at `other` that covers
        // t = 0.1 stays when a later one covers it too).
        assert_eq!(attached, 7);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crr_dynamics::eom::ForwardSolver;
    use crr_kinematics::fixtures::{box_body, hinge};
    use crr_kinematics::spec::StructureSpec;
    use nalgebra::{DMatrix, DVector};

    /// A block on a rocking block, both turning: the released upper face read by
    /// [`released_face`] (relative coordinates: the lower block's angle and the upper block's
    /// twist relative to it) against the same release in absolute coordinates written here (the
    /// lower block's angle and the upper block's own twist (ω, v_G), G the upper block's twist
    /// at P less the lower block's): the same change of the bodies' motion, so the same gap's
    /// acceleration and normal force, to round-off. The wrench the face carries is written here
    /// too, from the upper block's centre-of-mass acceleration by the classical kinematics of two
    /// turning bodies (and checked against the engine's `body_forces`, after a solve by M and
    /// after one by the articulated-body algorithm); q̈ and the bodies' poses are the engine's.
    #[test]
    fn the_released_gap_does_not_depend_on_the_coordinates_it_is_read_in() {
        let spec = StructureSpec {
            name: "stack".into(),
            gravity: 9.81,
            body: vec![
                box_body("a", 2400.0, [0.0, 0.0, 0.5], [0.4, 0.4, 1.0]),
                box_body("b", 2600.0, [0.0, 0.0, 1.3], [0.3, 0.3, 0.6]),
            ],
            interface: vec![
                hinge(
                    "bed",
                    "ground",
                    "a",
                    [0.0, 1.0, 0.0],
                    [0.2, 0.0, 0.0],
                    [-0.2, 0.0, 0.0],
                ),
                hinge(
                    "joint",
                    "a",
                    "b",
                    [0.0, 1.0, 0.0],
                    [0.15, 0.0, 1.0],
                    [-0.15, 0.0, 1.0],
                ),
            ],
            symmetry: Vec::new(),
        };
        let model = Model::from_spec(&spec).unwrap();
        let q = DVector::from_vec(vec![0.05, -0.02]);
        let qdot = DVector::from_vec(vec![0.7, -1.3]);
        let mut pivots = ActivePivots::uniform(&model, Side::Positive);
        pivots.sides[1] = Side::Negative;
        let mut d = Dynamics::new(&model, pivots.clone());
        d.solver = ForwardSolver::Cholesky;
        d.accelerations(&model, &GroundMotion::none(), 0.0, &q, &qdot)
            .unwrap();
        let g_eff = d.effective_gravity();
        let forces = super::super::seating::body_forces(&model, &d);
        // The run's own solver on open chains, the articulated-body algorithm (which never forms
        // M), leaves the same bias accelerations and q̈: the same forces to round-off.
        let mut by_aba = Dynamics::new(&model, pivots.clone());
        by_aba.solver = ForwardSolver::ArticulatedBody;
        by_aba
            .accelerations(&model, &GroundMotion::none(), 0.0, &q, &qdot)
            .unwrap();
        assert!(by_aba.used_articulated_body());
        for (f, g) in forces
            .iter()
            .zip(super::super::seating::body_forces(&model, &by_aba))
        {
            assert!((f - g).norm() <= 1e-12 * f.norm().max(1.0), "{f} vs {g}");
        }
        let radii = body_radii(&model);
        let loads = (&g_eff, radii.as_slice(), forces.as_slice());
        let r = released_face(&model, &d, &pivots, &[false, false], &qdot, 1, loads, None).unwrap();

        // Absolute coordinates: (θ̇₁, ω_b, v_b).
        let kin = &d.kin;
        let (a, b) = (0, 1);
        let (u1, u2) = (kin.axis[0], kin.axis[1]);
        let p = kin.pivot[1];
        let inertia = |i: usize| {
            let rot = body_rotation(&model, kin, i);
            rot * model.bodies[i].inertia * rot.transpose()
        };
        let (ia, ib) = (inertia(a), inertia(b));
        let (ma, mb) = (model.bodies[a].mass, model.bodies[b].mass);
        let va = u1.cross(&(kin.com[a] - kin.pivot[0]));
        let mut mass = DMatrix::<f64>::zeros(7, 7);
        mass[(0, 0)] = ma * va.norm_squared() + u1.dot(&(ia * u1));
        mass.view_mut((1, 1), (3, 3)).copy_from(&ib);
        mass.view_mut((4, 4), (3, 3))
            .copy_from(&(Matrix3::identity() * mb));
        let mut g = DMatrix::<f64>::zeros(6, 7);
        let vp = u1.cross(&(p - kin.pivot[0]));
        g.view_mut((0, 1), (3, 3))
            .copy_from(&(-skew(&(p - kin.com[b]))));
        g.view_mut((0, 4), (3, 3)).copy_from(&Matrix3::identity());
        g.view_mut((3, 1), (3, 3)).copy_from(&Matrix3::identity());
        for i in 0..3 {
            g[(i, 0)] = -vp[i];
            g[(3 + i, 0)] = -u1[i];
        }
        // The wrench on b at P from its motion in the chain, f = m(a_c − g_eff) and the moment,
        // with a_c by the classical kinematics of the two turning bodies (not the engine's
        // spatial algebra): the upper joint's pivot O₂ is fixed in a, which turns about O₁.
        let (o1, o2) = (kin.pivot[0], kin.pivot[1]);
        let (omega_a, alpha_a) = (u1 * qdot[0], u1 * d.qddot[0]);
        let omega = omega_a + u2 * qdot[1];
        let alpha = alpha_a + u2 * d.qddot[1] + omega_a.cross(&u2) * qdot[1];
        let turning = |w: &Vector3<f64>, dw: &Vector3<f64>, r: Vector3<f64>| {
            dw.cross(&r) + w.cross(&w.cross(&r))
        };
        let a_o2 = turning(&omega_a, &alpha_a, o2 - o1);
        let a_c = a_o2 + turning(&omega, &alpha, kin.com[b] - o2);
        let f = mb * (a_c - Vector3::new(0.0, 0.0, -model.gravity));
        assert!(
            (f - forces[b]).norm() <= 1e-9 * f.norm(),
            "{f} vs {}",
            forces[b]
        );
        let m = (kin.com[b] - p).cross(&f) + ib * alpha + omega.cross(&(ib * omega));
        let wrench = DVector::from_vec(vec![f.x, f.y, f.z, m.x, m.y, m.z]);
        let change = -(mass.cholesky().unwrap().solve(&g.transpose()) * wrench);
        let relative = &g * change;
        // The bed's normal: the lower block's face, +z at rest.
        let normal = body_rotation(&model, kin, a) * Vector3::z();
        let gap = normal.dot(&Vector3::new(relative[0], relative[1], relative[2]));
        assert!(
            (r.gap - gap).abs() <= 1e-9 * gap.abs().max(1.0),
            "{} vs {gap}",
            r.gap
        );
        assert!((r.normal - normal.dot(&f)).abs() <= 1e-9 * f.norm());
        assert!(
            gap.abs() > 0.1,
            "a gap's acceleration of {gap} m/s² tests little"
        );
    }
}
