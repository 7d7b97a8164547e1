//! Faces that open in motion: an interface whose whole face lifts off (a block leaving one of
//! its supports while others hold it) is dropped from the dynamic chain, and its face is watched
//! until a point touches again (docs/simulation.md, "Faces that open").
//!
//! - **Release.** When the contact program finds faces that open entirely, every body keeps a
//!   support through the others, and the chain without them confirms it
//!   ([`Simulation::faces_separate`]), the run goes on with the file's model without those
//!   interfaces ([`Model::with_open_interfaces`]): the same tree where they closed loops, a tree
//!   grown again (interfaces turned round) where they were in it. The state is mapped through
//!   the slots' angles and rates; their slots are reported `open`. A body left with no support,
//!   or a tree that would need a twisting seat, stops the run with [`SimulationError::LiftOff`].
//! - **Gap.** Each open face's contact points (a hinge's two pivot lines, a rocking base's four
//!   corners) carry the normal gap g = n_p·(x_c − x_p): the child's point less the parent's,
//!   along the parent's face normal turned with it. g is an event function of the segments;
//!   g < 0 beyond the event's overshoot is a missed contact, caught by the run's invariant.
//! - **Landing.** When a point's gap falls through 0 the face closes again on the pivot at that
//!   point, as a loop closure of the same tree: the positions are closed by the least change of
//!   the tree coordinates not seated (a snap, its change of T + U booked like the impacts'
//!   snaps), and the velocities by a plastic impulse on the loops' rows and the seated slots
//!   (Gauss' principle of impulsive motion), recorded as an impact of that interface.

use super::*;
use crr_dynamics::closed_chain::project_positions;
use crr_kinematics::ContactFace;
use nalgebra::Vector3;

/// Largest penetration of an open face's point (a fraction of the model size) the run's
/// invariant accepts: above the gap event's location error (1e-13 of the size at its margin),
/// far below any visible overlap.
pub(super) const GAP_TOLERANCE: f64 = 1e-6;

/// What became of faces the contact program lifts off ([`Simulation::release_faces`]).
pub(super) enum FaceRelease {
    /// They are out of the chain.
    Released,
    /// The chain without them drives one into its support: they stay closed.
    Contradicted,
    /// In motion, none of them moves in the chain without them: each child is still relative to
    /// its parent (every coordinate on the tree path between the two seated or at q̇ = q̈ = 0.0), so its
    /// gaps keep their values whatever the two bodies' common motion. They stay closed, carrying no
    /// force, and the program leaves their lift out until the next impact or landing: the
    /// lift-off is one of its equal answers, which a mirrored file's program need not return,
    /// and an open face that does not move would only land again later.
    Ties,
    /// The chain without them could not be solved at this state: they stay closed, undecided.
    Unsolved,
    /// No chain of the CRR model is left without them (why).
    Impossible(String),
}

/// Whether body `child` does not move relative to `parent` (a body, or None: the ground) in
/// `model`'s tree, `still[k]` telling whether coordinate k is still (seated, or q̇ and q̈
/// exactly 0.0): every coordinate on the path between their frames (the coordinates carrying
/// exactly one of the two) is. Exact, whatever the bodies' common motion: the path from their
/// common ancestor to the ground is not looked at, so a block at rest on a block that moves is
/// still on it (its gap's central differences there are round-off, not 0.0).
fn child_still_on_parent(
    model: &Model,
    parent: Option<usize>,
    child: usize,
    still: &[bool],
) -> bool {
    let (child_frame, parent_frame) = (
        Some(model.body_coord[child]),
        parent.map(|b| model.body_coord[b]),
    );
    (0..model.dof())
        .filter(|&k| model.carries(k, child_frame) != model.carries(k, parent_frame))
        .all(|k| still[k])
}

/// How a face that the contact program lifts off moves relative to its support in the chain
/// without it ([`Simulation::faces_separate`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Separation {
    /// A point that touches approaches its support: the face would be driven into it.
    Approaches,
    /// Points touch and the child does not move relative to its parent: every coordinate on
    /// the tree path between the two bodies is seated or has q̇ and q̈ exactly 0.0.
    Still,
    /// Otherwise: it leaves (or is not driven into its support).
    Leaves,
}

/// One open face: an interface of the file's model whose loop is released.
#[derive(Clone, Debug)]
pub(super) struct OpenFace {
    /// Index into the file's model's interfaces.
    pub(super) interface: usize,
    /// The parent body (None: the ground) and the child.
    parent: Option<usize>,
    child: usize,
    /// The face's normal at rest, into the child.
    normal: Vector3<f64>,
    /// The contact points at rest, and for each the sides of the interface's angles whose pivot
    /// it is.
    points: Vec<Vector3<f64>>,
    pub(super) point_sides: Vec<Vec<Side>>,
    /// The face's tangents at rest (t₁, t₂) and its extent along each, the least and greatest
    /// tᵢ · x over its points (None: unbounded, a hinge's t₂ = u out of its plane of motion).
    tangents: [Vector3<f64>; 2],
    extent: [Option<(f64, f64)>; 2],
    /// How far (m) a point may lie outside the extent and still face the face: 1e-12 of the
    /// model's size, round-off of the poses. (A corner that has moved past the edge by δ with
    /// a tilt θ = δ/w reads a false penetration of about δθ/2 from the extended plane: below
    /// 1e-24 of the size within this tolerance.)
    extent_tolerance: f64,
}

impl OpenFace {
    fn of(model: &Model, k: usize) -> Self {
        let iface = &model.interfaces[k];
        let face = ContactFace::of_interface(model, k);
        let count = iface.kind.angle_count();
        let choices: Vec<Vec<Side>> = (0..1usize << count)
            .map(|bits| {
                (0..count)
                    .map(|c| {
                        if bits >> c & 1 == 0 {
                            Side::Positive
                        } else {
                            Side::Negative
                        }
                    })
                    .collect()
            })
            .collect();
        let point_sides = face
            .points
            .iter()
            .map(|p| {
                choices
                    .iter()
                    .min_by(|a, b| {
                        let d = |s: &Vec<Side>| (iface.kind.pivot(s) - p).norm();
                        d(a).total_cmp(&d(b))
                    })
                    .expect("at least one choice of sides")
                    .clone()
            })
            .collect();
        Self {
            interface: k,
            parent: match iface.parent {
                crr_kinematics::Parent::Body(b) => Some(b),
                crr_kinematics::Parent::Ground => None,
            },
            child: iface.child,
            normal: face.normal,
            tangents: face.tangents,
            extent: [0, 1].map(|k| {
                // A hinge's face is a line: out of its plane (t₂ = u) it has no edge.
                (k == 0 || face.friction_tangents == 2).then(|| {
                    let along = face.points.iter().map(|x| face.tangents[k].dot(x));
                    along.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                        (lo.min(v), hi.max(v))
                    })
                })
            }),
            extent_tolerance: 1e-12 * model.size,
            points: face.points,
            point_sides,
        }
    }

    /// Whether the point `x` of a body, given in that body's rest frame, lies over the face as
    /// the body carries it: its tangential coordinates within the face's extent.
    fn over_face(&self, x: &Vector3<f64>) -> bool {
        self.tangents.iter().zip(&self.extent).all(|(t, extent)| {
            extent.is_none_or(|(lo, hi)| {
                let v = t.dot(x);
                v >= lo - self.extent_tolerance && v <= hi + self.extent_tolerance
            })
        })
    }

    /// Number of contact points.
    pub(super) fn len(&self) -> usize {
        self.points.len()
    }

    /// The normal gap of point `i` (m) in the poses of `kin` ([`forward_kinematics`] of a chain
    /// with the same tree as `model`).
    ///
    /// Point i is a corner of the face on either body, x_c on the child and x_p on the parent
    /// (the same point at rest). Either may be the one that meets the other body's face: the
    /// child's corner is measured from the parent's face plane, n_p · (x_c − x_p), where it lies
    /// over the parent's face, and the parent's corner from the child's face plane,
    /// n_c · (x_c − x_p), where it lies over the child's; the gap is the least of those that
    /// apply (the two agree to first order in the motion). A corner that has moved past the
    /// other face's edge meets nothing there: a block that tips away from its neighbour about
    /// its far foot takes its face's lower edge up and away from the neighbour's face, while the
    /// neighbour's corner, measured from the tipped face's plane extended past that edge, would
    /// read a penetration of w(1 − cos θ) (w the block's width, θ its tilt). Where neither
    /// applies (the faces twisted apart about their normal), the child's corner from the
    /// parent's plane.
    pub(super) fn gap(&self, model: &Model, kin: &Data, i: usize) -> f64 {
        let p = &self.points[i];
        let child_coord = model.body_coord[self.child];
        let (child, child_rot) = (
            crr_kinematics::body_point(model, kin, self.child, p),
            kin.rot_ops[child_coord],
        );
        let (parent, parent_rot) = match self.parent {
            None => (*p, nalgebra::Matrix3::identity()),
            Some(b) => (
                crr_kinematics::body_point(model, kin, b, p),
                kin.rot_ops[model.body_coord[b]],
            ),
        };
        let apart = child - parent;
        let from_parent = (parent_rot * self.normal).dot(&apart);
        // Each corner in the other body's rest frame: x_p + Γ_pᵀ(x_c − x_p), and back.
        let child_over_parent = self.over_face(&(p + parent_rot.transpose() * apart));
        let parent_over_child = self.over_face(&(p - child_rot.transpose() * apart));
        let from_child = (child_rot * self.normal).dot(&apart);
        match (child_over_parent, parent_over_child) {
            (true, true) => from_parent.min(from_child),
            (false, true) => from_child,
            _ => from_parent,
        }
    }
}

/// The faces open now: which interfaces of the file's model are open, and the slots' maps
/// between it and the chain integrated.
#[derive(Clone, Debug)]
pub(super) struct OpenLoops {
    /// The open faces, in the file's interface order.
    pub(super) faces: Vec<OpenFace>,
    /// The chain's tree coordinates are the file's (q needs no mapping for the outputs).
    pub(super) files_tree: bool,
    /// Slot of the chain → slot of the file's model.
    to_original: Vec<usize>,
    /// Slot of the file's model → slot of the chain (None: its interface is open).
    to_active: Vec<Option<usize>>,
    /// Per interface of the chain, whether it was turned round (its child is the file's parent).
    pub(super) turned: Vec<bool>,
}

impl OpenLoops {
    /// No face open.
    pub(super) fn none(model: &Model) -> Self {
        Self {
            faces: Vec::new(),
            files_tree: true,
            to_original: (0..model.slot_count).collect(),
            to_active: (0..model.slot_count).map(Some).collect(),
            turned: vec![false; model.interfaces.len()],
        }
    }

    /// The interfaces `open` of `original` released, those in `last_resort` kept out of the
    /// tree where the others reach every body: the maps and the chain
    /// ([`Model::with_open_interfaces`]). A rocking base turned round has its tilts in the other
    /// order.
    fn with(
        original: &Model,
        open: &[usize],
        last_resort: &[usize],
    ) -> Result<(Self, Model), crr_kinematics::ModelError> {
        let (chain, turned) = original.with_open_interfaces(open, last_resort)?;
        let mut to_active = vec![None; original.slot_count];
        let mut to_original = vec![0; chain.slot_count];
        let kept = (0..original.interfaces.len()).filter(|k| !open.contains(k));
        for (new, old) in kept.enumerate() {
            let file_slots: Vec<usize> = original.interfaces[old].slots.clone().collect();
            for (c, b) in chain.interfaces[new].slots.clone().enumerate() {
                let a = file_slots[if turned[new] {
                    file_slots.len() - 1 - c
                } else {
                    c
                }];
                to_active[a] = Some(b);
                to_original[b] = a;
            }
        }
        let mut sorted = open.to_vec();
        sorted.sort_unstable();
        let faces = sorted.iter().map(|&k| OpenFace::of(original, k)).collect();
        let files_tree =
            chain.dof() == original.dof() && (0..chain.dof()).all(|k| to_original[k] == k);
        Ok((
            Self {
                faces,
                files_tree,
                to_original,
                to_active,
                turned,
            },
            chain,
        ))
    }

    /// The chain's slot of the file's slot `s` (None: open).
    pub(super) fn active_slot(&self, s: usize) -> Option<usize> {
        self.to_active[s]
    }

    /// Whether the chain's interface `i` is the file's turned round (its parent here is the
    /// file's child).
    pub(super) fn turned(&self, i: usize) -> bool {
        self.turned.get(i).copied().unwrap_or(false)
    }

    /// The file's slot of the chain's slot `s`.
    pub(super) fn original_slot(&self, s: usize) -> usize {
        self.to_original[s]
    }

    /// The open interfaces of the file's model.
    pub(super) fn interfaces(&self) -> Vec<usize> {
        self.faces.iter().map(|f| f.interface).collect()
    }
}

impl Simulation<'_> {
    /// Appends an impact of the chain integrated, its slots numbered as the file's.
    pub(super) fn push_impact(&mut self, mut record: ImpactRecord) {
        for s in record
            .slots
            .iter_mut()
            .chain(record.seated.iter_mut())
            .chain(record.released.iter_mut())
        {
            *s = self.open.original_slot(*s);
        }
        self.lost_at_impacts += record.energy_lost;
        self.impacts.push(record);
        // Faces kept on their pivots after a contradicted lift-off are offered it again, and
        // so are joints sliding in contact whose opening was refused at rest.
        self.spare.rest.held_faces.clear();
        self.spare.rest.grazing_refused.clear();
        // An impact ends a row of uplift events without a release (SimulationError::Undecided).
        self.undecided.end();
    }

    /// The faces `lifting` (names of the chain's interfaces) open entirely: the chain goes on
    /// without them, its spanning tree grown again where one of them was in it
    /// ([`FaceRelease::Released`]) — when the chain without them confirms it
    /// ([`Self::faces_separate`]). Otherwise the faces stay closed
    /// ([`FaceRelease::Contradicted`]), or no spanning tree is left (a twisting seat would have
    /// to enter it: [`FaceRelease::Impossible`] with why). In motion, faces that do not move
    /// ([`FaceRelease::Ties`]) stay closed, and the others are released without them (checked
    /// again on the chain that keeps them).
    ///
    /// `grazing`: where the faces are offered because their joints slide in contact in the
    /// mechanism exceeded at rest (`seating::followable_collapse`), that mechanism's sides (the
    /// file's slots), which move the chain without the faces where it makes no release of its
    /// own (at the multiplier itself) ([`Self::faces_separate`]); empty otherwise.
    pub(super) fn release_faces(
        &mut self,
        lifting: &[String],
        grazing: &[(usize, Side)],
    ) -> FaceRelease {
        let mut open = self.open.interfaces();
        let opening: Vec<usize> = lifting
            .iter()
            .filter_map(|name| self.original.interface_index(name))
            .collect();
        open.extend(&opening);
        let built = match OpenLoops::with(&self.original, &open, &[]) {
            Ok(built) => built,
            Err(e) => return FaceRelease::Impossible(e.to_string()),
        };
        let verdicts = match self.faces_separate(&built, &opening, grazing) {
            Ok(verdicts) => verdicts,
            Err(_) => return FaceRelease::Unsolved,
        };
        if verdicts.contains(&Separation::Approaches) {
            return FaceRelease::Contradicted;
        }
        // At rest every acceleration vanishes at the load's threshold, where lift-offs are
        // decided: only in motion does a face that does not move tie.
        let ties = |v: &Separation| *v == Separation::Still && !self.at_rest();
        if verdicts.iter().any(ties) {
            let moving: Vec<String> = lifting
                .iter()
                .zip(&verdicts)
                .filter(|(_, v)| !ties(v))
                .map(|(name, _)| name.clone())
                .collect();
            return if moving.is_empty() {
                FaceRelease::Ties
            } else {
                self.release_faces(&moving, grazing)
            };
        }
        match self.switch_chain(built, &[]) {
            Ok(()) => FaceRelease::Released,
            Err(e) => FaceRelease::Impossible(e.to_string()),
        }
    }

    /// Whether each of the faces `opening` (interfaces of the file, in that order) leaves its
    /// support in the motion of the chain without them (`built`), by its own equations at the
    /// current state, with the other slots as that chain's own uplift test sets them (its
    /// releases, outside faces it would lift off too, where its exact solve opens them; seated
    /// slots it does not release held) ([`Separation`]): it does not approach where every point
    /// that touches (gap within 1e-9 of the model size) has a gap rate above −1e-9 √(g L) and a
    /// gap acceleration above −1e-6 g, and it is still where a point touches and its child does
    /// not move relative to its parent ([`child_still_on_parent`]: exact, where the gaps' rates
    /// on blocks carried by a moving one are round-off). The gap's rate and acceleration are its
    /// central differences over the states q ± h q̇ + ½h² q̈ (h = 1e-4 √(L/g), q̈ of the chain
    /// without the faces).
    ///
    /// The program's own motion cannot be trusted for this: a face it lifts off keeps its slip
    /// rows there (no tangential acceleration relative to its support, module `opening_qp`), a
    /// force the face cannot carry once it is off. A face that the chain without it drives into
    /// its support stays closed: opening it would make it land at once, over and over. A chain
    /// whose equations cannot be solved is an error here ([`FaceRelease::Unsolved`]: the faces
    /// stay closed, undecided).
    ///
    /// Faces offered because their joints slide in contact (`grazing`, the mechanism's sides,
    /// not empty) must leave from rest: where the chain without them releases nothing (at the
    /// multiplier itself, within its test's margin) the mechanism's sides move it, each checked
    /// by the chain's exact solve without the margin (as [`Self::release_mechanism`] does); a
    /// face whose bodies still do not move, or a point that enters its support at first order
    /// along the motion however slow, counts as approaching.
    fn faces_separate(
        &mut self,
        (loops, chain): &(OpenLoops, Model),
        opening: &[usize],
        grazing: &[(usize, Side)],
    ) -> Result<Vec<Separation>, SimulationError> {
        let (q, qdot) = self.state_on(chain, loops);
        let (mut d, _, _) = self.dynamics_on(chain, loops, &[]);
        // The chain's own decision at this state: the releases of its uplift test, those of
        // faces it would lift off too left out (decided once it integrates), kept where its
        // exact solve opens them. From rest it is asked again with them released until it
        // releases nothing more: its test opens the strongest single release of an open chain
        // (the others follow at the next step's test), and every part that opens at t = 0 moves
        // in the motion that decides whether a face grazing between two of them opens.
        let mut rest = super::uplift_from_rest::RestCache::default();
        rest.global = self.axis_memory.statics_for(chain);
        let parts = chain.parts();
        let rounds = if self.at_rest() { chain.slot_count } else { 1 };
        for _ in 0..rounds {
            let releases = self.chain_releases(chain, &d, &mut rest, &parts.of_slot, (&q, &qdot));
            let Some(releases) = releases.filter(|r| !r.is_empty()) else {
                break;
            };
            release_in(&mut d, &releases);
        }
        self.axis_memory.remember(chain, &rest.global);
        let grazing_at_rest = self.at_rest() && !grazing.is_empty();
        if grazing_at_rest && d.seated.len() == chain.slot_count {
            let proposed: Vec<(usize, Side)> = grazing
                .iter()
                .filter_map(|&(file_slot, side)| Some((loops.active_slot(file_slot)?, side)))
                .filter(|(s, _)| d.seated.contains(s))
                .collect();
            let mut trial = d.clone();
            let released = super::seating::confirmed_releases(
                chain,
                self.ground,
                &d,
                &mut trial,
                proposed,
                self.t,
                &q,
                &qdot,
                0.0,
                &mut self.spare.rest.doubtful,
            )
            .flatten();
            release_in(&mut d, released.as_deref().unwrap_or_default());
        }
        d.accelerations(chain, self.ground, self.t, &q, &qdot)
            .map_err(|source| SimulationError::Dynamics { t: self.t, source })?;
        let (g, size) = (chain.gravity, chain.size);
        let faces: Vec<&OpenFace> = opening
            .iter()
            .map(|&k| {
                loops
                    .faces
                    .iter()
                    .find(|f| f.interface == k)
                    .expect("a face lifting off is open in the chain built without it")
            })
            .collect();
        let mut kin = Data::new(chain);
        let motion = gap_motion(chain, &mut kin, &d.pivots, &faces, (&q, &qdot, &d.qddot));
        // From rest, a point that moves along its support at first order grazes (a block's
        // lowest edge rising along its neighbour's face): its gap's curvature along the motion
        // decides.
        let along_motion = if self.at_rest() {
            gap_along_motion(chain, &mut kin, &d, &faces, &q)
        } else {
            None
        };
        // Still: seated (held at its seat: a coordinate that closed a loop in the chain before
        // maps its rate from the poses, round-off rather than 0.0), or q̇ and q̈ exactly 0.0.
        let still: Vec<bool> = (0..chain.dof())
            .map(|k| d.seated.contains(&k) || (qdot[k] == 0.0 && d.qddot[k] == 0.0))
            .collect();
        Ok(motion
            .iter()
            .zip(&faces)
            .enumerate()
            .map(|(f, (points, face))| {
                let touching = || points.iter().filter(|p| p.gap <= 1e-9 * size);
                let grazing_in = || {
                    along_motion.as_ref().is_some_and(|c| {
                        points.iter().zip(&c[f]).any(|(p, along)| {
                            p.gap <= 1e-9 * size
                                && if grazing_at_rest {
                                    along.enters(size)
                                } else {
                                    along.slope.abs() <= GRAZING_SLOPE * size
                                        && along.curvature < -GRAZING_CURVATURE * size
                                }
                        })
                    })
                };
                let still_here = touching().next().is_some()
                    && child_still_on_parent(chain, face.parent, face.child, &still);
                if still_here && grazing_at_rest {
                    // Offered to leave from rest, it does not move: not confirmed.
                    Separation::Approaches
                } else if still_here {
                    Separation::Still
                } else if touching()
                    .any(|p| p.rate <= -1e-9 * (g * size).sqrt() || p.acceleration <= -1e-6 * g)
                    || grazing_in()
                {
                    Separation::Approaches
                } else {
                    Separation::Leaves
                }
            })
            .collect())
    }

    /// The releases the uplift test of `chain` (its dynamics `d`, its rest cache `rest`) makes
    /// at (q, q̇), those of faces it would lift off too left out (decided once it integrates),
    /// kept where its exact solve opens them ([`super::seating::confirmed_releases`], whose
    /// checks are kept with the run's own); None where it releases nothing.
    fn chain_releases(
        &mut self,
        chain: &Model,
        d: &Dynamics,
        rest: &mut super::uplift_from_rest::RestCache,
        slot_part: &[usize],
        (q, qdot): (&DVector<f64>, &DVector<f64>),
    ) -> Option<Vec<(usize, Side)>> {
        let mut trial = d.clone();
        rest.lift_off = None;
        let decided = super::seating::opening_mode_in(
            chain,
            self.ground,
            d,
            &mut trial,
            rest,
            slot_part,
            self.t,
            q,
            qdot,
        );
        let lifting_further = rest.lift_off.take().unwrap_or_default();
        let candidates: Vec<(usize, Side)> = decided?
            .into_iter()
            .filter(|&(k, _)| {
                let name = &chain.interfaces[slot_interface(chain, k)].name;
                !lifting_further.contains(name)
            })
            .collect();
        let tol = 1e-9 * chain.gravity / chain.size;
        let releases = super::seating::confirmed_releases(
            chain,
            self.ground,
            d,
            &mut trial,
            candidates,
            self.t,
            q,
            qdot,
            tol,
            &mut rest.doubtful,
        )
        .flatten();
        self.spare.rest.doubtful.append(&mut rest.doubtful);
        releases
    }

    /// The dynamics of `chain` (its maps `loops`) at the current state: every slot keeps its
    /// side and seat, a slot that was open takes its side from `closing` (file slot, side);
    /// also the seats and last impacts per slot.
    fn dynamics_on(
        &self,
        chain: &Model,
        loops: &OpenLoops,
        closing: &[(usize, Side)],
    ) -> (Dynamics, Vec<bool>, Vec<f64>) {
        let mut pivots = ActivePivots::uniform(chain, Side::Positive);
        let mut seated = vec![false; chain.slot_count];
        let mut last_impact = vec![self.t; chain.slot_count];
        for (b, side) in pivots.sides.iter_mut().enumerate() {
            let file_slot = loops.original_slot(b);
            if let Some(a) = self.open.active_slot(file_slot) {
                *side = self.dynamics.pivots.sides[a];
                seated[b] = self.seated[a];
                last_impact[b] = self.last_impact[a];
            } else if let Some(&(_, s)) = closing.iter().find(|c| c.0 == file_slot) {
                *side = s;
            }
        }
        let mut dynamics = Dynamics::new(chain, pivots);
        dynamics.min_norm_multipliers = false;
        dynamics.seated = (0..chain.slot_count).filter(|&s| seated[s]).collect();
        (dynamics, seated, last_impact)
    }

    /// Integrates from now on `chain`, the file's model with the faces of `loops` open: the
    /// state is mapped through the slots' angles and rates; every slot keeps its side, seat and
    /// last impact, and a slot that was open takes its side from `closing` (file slot, side)
    /// and rocks.
    /// A tree grown again can have another number of coordinates (a hinge, one angle, in the
    /// place of a rocking base, two): the state vector [q, q̇, W, D] and the integrator are then
    /// made anew for it, W and D carried over.
    fn switch_chain(
        &mut self,
        (loops, chain): (OpenLoops, Model),
        closing: &[(usize, Side)],
    ) -> Result<(), SimulationError> {
        // The hops being measured name the old chain's slots: they end here, not landed.
        self.finish_hops();
        let (q, qdot) = self.state_on(&chain, &loops);
        let n_old = self.model.dof();
        let (work_in, dissipated) = (self.y[2 * n_old], self.y[2 * n_old + 1]);
        let (dynamics, seated, last_impact) = self.dynamics_on(&chain, &loops, closing);
        let trial = dynamics.clone();
        self.axis_memory
            .remember(&self.model, &self.spare.rest.global);
        let audit = self.spare.rest.audit.take();
        let doubtful = std::mem::take(&mut self.spare.rest.doubtful);
        self.spare = Workspaces::new(&chain, trial, &dynamics.pivots);
        self.spare.rest.global = self.axis_memory.statics_for(&chain);
        self.spare.rest.audit = audit;
        self.spare.rest.doubtful = doubtful;
        self.dynamics = dynamics;
        self.regularised = Regularised::of(&chain);
        self.contact_slots = super::slots::contact_slots(&chain);
        self.parts = chain.parts();
        self.seated = seated;
        self.last_impact = last_impact;
        self.out_kin = Data::new(&chain);
        self.model = Arc::new(chain);
        self.open = loops;
        self.chain_changes += 1;
        let n = self.model.dof();
        if n != n_old {
            self.y = vec![0.0; 2 * n + 2];
            let interrupt = self.solver.interrupt().cloned();
            self.solver = Solver::new(self.params.method, self.params.options, 2 * n + 2)?;
            self.solver.set_interrupt(interrupt);
        }
        self.y[..n].copy_from_slice(q.as_slice());
        self.y[n..2 * n].copy_from_slice(qdot.as_slice());
        (self.y[2 * n], self.y[2 * n + 1]) = (work_in, dissipated);
        self.set_seated(std::iter::empty());
        self.reset_solver();
        Ok(())
    }

    /// The current state in the coordinates of `chain` (its maps `loops`): each of its tree
    /// coordinates is the angle (rate) of the same file slot in the chain integrated now, where
    /// it is closed (a landing keeps the tree, and a release grows it from interfaces that stay
    /// closed).
    fn state_on(&mut self, chain: &Model, loops: &OpenLoops) -> (DVector<f64>, DVector<f64>) {
        let model = Arc::clone(&self.model);
        let (q, qdot) = (self.chain_q(), self.chain_qdot());
        let mut angles = vec![0.0; model.slot_count];
        let mut rates = vec![0.0; model.slot_count];
        slot_angles(
            &model,
            &mut self.out_kin,
            &q,
            &self.dynamics.pivots,
            &mut angles,
        );
        crr_kinematics::velocities(&model, &mut self.out_kin, &qdot);
        slot_rates(&model, &self.out_kin, &qdot, &mut rates);
        let old = |k: usize| {
            self.open
                .active_slot(loops.original_slot(k))
                .expect("a tree interface of the new chain is closed in the old one")
        };
        (
            DVector::from_fn(chain.dof(), |k, _| angles[old(k)]),
            DVector::from_fn(chain.dof(), |k, _| rates[old(k)]),
        )
    }

    /// Open faces touch, each at one point (`landings`: (face, point)): their loops close again
    /// on the pivots there, positions by the least change (booked as a snap) and velocities by a
    /// plastic impulse (recorded as one impact). Returns the impact's index.
    ///
    /// A face's gap event lands it with every other face touching then, as does a rocking
    /// joint's impact ([`Simulation::open_faces_touching`]); faces resting on their supports at
    /// rest land together ([`Simulation::settled_open_faces`]). The decision that follows (which
    /// joints and faces open again) is taken once, on the structure with all of them closed.
    pub(super) fn recontact(
        &mut self,
        landings: &[(usize, usize)],
    ) -> Result<usize, SimulationError> {
        self.recontact_sampled(landings, true)
    }

    /// [`Self::recontact`], with the sample before the landing taken when `sample_before` (not
    /// for faces a landing's snap has just pushed in: that state is not one of the motion).
    fn recontact_sampled(
        &mut self,
        landings: &[(usize, usize)],
        sample_before: bool,
    ) -> Result<usize, SimulationError> {
        self.check_impact_room()?;
        let t = self.t;
        let original = Arc::clone(&self.original);
        let landing: Vec<usize> = landings
            .iter()
            .map(|&(face, _)| self.open.faces[face].interface)
            .collect();
        let closing: Vec<(usize, Side)> = landings
            .iter()
            .flat_map(|&(face, point)| {
                let face = &self.open.faces[face];
                original.interfaces[face.interface]
                    .slots
                    .clone()
                    .zip(face.point_sides[point].iter().copied())
            })
            .collect();
        if sample_before {
            self.record_current_sample(t);
        }
        let energy_before = self.mechanical_energy();
        let mut open = self.open.interfaces();
        open.retain(|k| !landing.contains(k));
        // The tree stays: every interface outside it (the landing one too) only closes loops.
        let chain = Arc::clone(&self.model);
        let outside_tree: Vec<usize> = (0..original.interfaces.len())
            .filter(|&k| {
                chain
                    .interfaces
                    .iter()
                    .find(|i| i.name == original.interfaces[k].name)
                    .is_none_or(|i| !matches!(i.role, crr_kinematics::Role::Tree { .. }))
            })
            .collect();
        let built = OpenLoops::with(&original, &open, &outside_tree).map_err(|e| {
            SimulationError::Invariant(format!("cannot close the landing face's loop: {e}"))
        })?;
        self.switch_chain(built, &closing)?;
        let model = Arc::clone(&self.model);
        let model = &*model;
        let n = model.dof();
        let slots: Vec<usize> = closing
            .iter()
            .filter_map(|&(s, _)| self.open.active_slot(s))
            .collect();
        // Positions: the loop closed by the least change of the tree coordinates not seated.
        let mut q = self.chain_q();
        let qdot = self.chain_qdot();
        let free: Vec<usize> = (0..n).filter(|&k| !self.seated[k]).collect();
        let mut kin = Data::new(model);
        project_positions(model, &mut kin, &self.dynamics.pivots, &mut q, Some(&free))
            .map_err(|source| SimulationError::Dynamics { t, source })?;
        let (t_minus, u_snapped) =
            state_energies(model, &mut kin, &self.dynamics.pivots, &q, &qdot);
        let mut rates_before = vec![0.0; model.slot_count];
        slot_rates(model, &kin, &qdot, &mut rates_before);
        // Velocities: the plastic impulse on the loop's rows and the seated slots.
        let held: Vec<usize> = (0..model.slot_count).filter(|&s| self.seated[s]).collect();
        let mut work = self.take_trial();
        let pivots = self.dynamics.pivots.clone();
        let (mut qdot_after, mut t_plus) =
            plastic_projection(model, &mut work, self.ground, t, &q, &qdot, &pivots, &held)?;
        // The landing slots' angles and rates: a slot brought to rest, or sent into its closed
        // side, seats (as at an impact). So does a joint rocking at φ ≈ 0 that the landing
        // locks (a block rocking on one support whose face lands on its other: the closed loop
        // leaves it no motion, its rate round-off). Left unseated, at an angle of round-off
        // and no rate, it kept the structure out of the test at rest with every joint seated,
        // and so out of the collapse multiplier's decision: the 6 × 6 wall of
        // `examples/wall_pulse.rs` under 1.5 λ g stayed at rest from 0.346 s under 0.81 g,
        // λ = 0.58. Seating one joint can lock others: seat, recompute the rates, until nothing
        // changes.
        let mut angles = vec![0.0; model.slot_count];
        slot_angles(model, &mut kin, &q, &pivots, &mut angles);
        crr_kinematics::velocities(model, &mut kin, &qdot_after);
        let mut rates = vec![0.0; model.slot_count];
        slot_rates(model, &kin, &qdot_after, &mut rates);
        let locked_rate = LOCKED_RATE * (model.gravity / model.size).sqrt();
        let candidates: Vec<usize> = (0..model.slot_count)
            .filter(|&s| {
                (slots.contains(&s) || !self.seated[s])
                    && angles[s].abs() <= self.params.simultaneity
            })
            .collect();
        let mut to_seat: Vec<usize> = Vec::new();
        loop {
            let pending: Vec<usize> = candidates
                .iter()
                .copied()
                .filter(|&s| {
                    !to_seat.contains(&s)
                        && if slots.contains(&s) {
                            rates[s].abs() < self.params.seat_rate
                                || pivots.sides[s].sign() * rates[s] < 0.0
                        } else {
                            rates[s].abs() <= locked_rate
                        }
                })
                .collect();
            if pending.is_empty() {
                break;
            }
            to_seat.extend(pending);
            let all: Vec<usize> = held.iter().chain(&to_seat).copied().collect();
            (qdot_after, t_plus) = plastic_projection(
                model,
                &mut work,
                self.ground,
                t,
                &q,
                &qdot_after,
                &pivots,
                &all,
            )?;
            crr_kinematics::velocities(model, &mut kin, &qdot_after);
            slot_rates(model, &kin, &qdot_after, &mut rates);
        }
        // Whether the landing's impulse pulls at a contact (module `landing_check`): `work` is
        // evaluated at the landing with the slots seated after it.
        self.check_impulse(&work, &q, (&pivots, &qdot), &qdot_after, &[]);
        self.spare.trial = Some(work);
        // The joints the landing locked go to exactly 0, as those an impact seats do: their
        // angles are round-off within `simultaneity`, where the outputs read a seated joint at
        // 0. The joints seated before stay at their seats (never freed, their closure angles
        // held) and the landing slots where they land, as an impact's impacting slots. The
        // change of T + U is a snap.
        let locked: Vec<usize> = to_seat
            .iter()
            .copied()
            .filter(|s| !slots.contains(s))
            .collect();
        if !locked.is_empty() {
            let before = state_energies(model, &mut kin, &pivots, &q, &qdot_after);
            let after = snap_to_seats(
                model,
                &mut kin,
                &pivots,
                &mut q,
                &mut qdot_after,
                |k| held.contains(&k) || locked.contains(&k),
                |k| to_seat.contains(&k),
            )
            .map_err(|source| SimulationError::Dynamics { t, source })?;
            self.book_snap((before.0 + before.1) - (after.0 + after.1));
        }
        self.y[..n].copy_from_slice(q.as_slice());
        self.y[n..2 * n].copy_from_slice(qdot_after.as_slice());
        let lost = t_minus - t_plus;
        // The snap: T + U before the positions moved less T + U after them (with q̇⁻).
        self.book_snap(energy_before - (t_minus + u_snapped));
        self.dissipated_at_impacts += lost;
        self.set_seated(to_seat.iter().map(|&s| (s, true)));
        let record = ImpactRecord {
            t,
            interfaces: landing
                .iter()
                .map(|&k| original.interfaces[k].name.clone())
                .collect(),
            slots: slots.clone(),
            rates_before: slots.iter().map(|&s| rates_before[s]).collect(),
            rates_after: slots.iter().map(|&s| rates[s]).collect(),
            energy_lost: lost,
            energy_gain: lost < -1e-12 * t_minus.abs().max(1e-300),
            seated: to_seat,
            released: Vec::new(),
        };
        for &s in &slots {
            self.last_impact[s] = t;
        }
        self.push_impact(record);
        self.reset_solver();
        // The snap puts the landing point back on its pivot. An open face's child turns about a
        // pivot on another support, so its point lands displaced along the face (a slip of
        // second order in the angle: the snap moved q by 1.6e-4 rad on the 4 × 4 wall under
        // 1.8 λ g at 0.4028 s), and the bodies' move can push another open face into its
        // support: it lands now too, on its own impulse, before anything opens (as does a face
        // the impulse left touching and not leaving).
        let pushed = self.open_faces_touching(None)?;
        if !pushed.is_empty() {
            return self.recontact_sampled(&pushed, false);
        }
        // A face that lands and must open again, or joints the landing releases, open before
        // the sample after it.
        self.release_if_opening()?;
        self.hops.after_impact = true;
        self.record_current_sample(t);
        self.hops.after_impact = false;
        Ok(self.impacts.len() - 1)
    }

    /// The open faces touching their supports now, other than `except`: each whose lowest point
    /// is within `simultaneity` × the model size of its support and not leaving it, or inside
    /// it by more than that whatever its rate (a landing's snap pushed it in), with that
    /// point. Not leaving: its gap rate below −1e-12 √(g L), or within ±1e-12 √(g L) with a gap
    /// acceleration at most 1e-9 g (q̈ of the chain now): a face that has just opened leaves with
    /// a zero rate and a positive acceleration, and closing it again would repeat at the same
    /// instant. They land with a face whose gap event fires, and with a rocking joint's impact: a
    /// rigid wedge rocking back about its toe closes every joint of its crack, and its toe, at
    /// one instant. Their events fire one at a time, and an impulse on the first alone, the
    /// others a hair inside their supports (1e-13 m on the 7 × 7 wall under 1.01 λ g at
    /// 0.1587 s), threw the blocks along the crack off their other supports.
    pub(super) fn open_faces_touching(
        &mut self,
        except: Option<usize>,
    ) -> Result<Vec<(usize, usize)>, SimulationError> {
        let model = Arc::clone(&self.model);
        let tol = self.params.simultaneity * model.size;
        let q = self.chain_q();
        // The lowest point of each face; most impacts have none near: no solve then.
        forward_kinematics(&model, &mut self.out_kin, &q, &self.dynamics.pivots);
        let lowest: Vec<Option<(usize, bool)>> = self
            .open
            .faces
            .iter()
            .enumerate()
            .map(|(f, face)| {
                let gaps: Vec<f64> = (0..face.len())
                    .map(|i| face.gap(&model, &self.out_kin, i))
                    .collect();
                let i = (0..gaps.len()).min_by(|&a, &b| gaps[a].total_cmp(&gaps[b]))?;
                (Some(f) != except && gaps[i] <= tol).then_some((i, gaps[i] < -tol))
            })
            .collect();
        if lowest.iter().all(Option::is_none) {
            return Ok(Vec::new());
        }
        let qdot = self.chain_qdot();
        let mut d = self.take_trial();
        d.pivots.clone_from(&self.dynamics.pivots);
        d.seated.clone_from(&self.dynamics.seated);
        let solved = d.accelerations(&model, self.ground, self.t, &q, &qdot);
        let qddot = d.qddot.clone();
        self.spare.trial = Some(d);
        solved.map_err(|source| SimulationError::Dynamics { t: self.t, source })?;
        let faces: Vec<&OpenFace> = self.open.faces.iter().collect();
        let motion = gap_motion(
            &model,
            &mut self.out_kin,
            &self.dynamics.pivots,
            &faces,
            (&q, &qdot, &qddot),
        );
        let still = 1e-12 * (model.gravity * model.size).sqrt();
        Ok(lowest
            .iter()
            .enumerate()
            .filter_map(|(f, &lowest)| {
                let (i, inside) = lowest?;
                let p = motion[f][i];
                let not_leaving =
                    p.rate < -still || (p.rate <= still && p.acceleration <= 1e-9 * model.gravity);
                (inside || not_leaving).then_some((f, i))
            })
            .collect())
    }

    /// An open face resting on its support: every slot of the chain seated and still (the
    /// seating snaps set the tree coordinates to exactly 0, which can put a lifted block back
    /// on its support without its gap event: the face is touching, with no relative velocity).
    /// Returns (face, point) of each such face's lowest point, gap within 1e-9 of the model
    /// size.
    pub(super) fn settled_open_faces(&mut self) -> Vec<(usize, usize)> {
        if self.open.faces.is_empty() || !self.at_rest() {
            return Vec::new();
        }
        let model = Arc::clone(&self.model);
        let q = self.chain_q();
        forward_kinematics(&model, &mut self.out_kin, &q, &self.dynamics.pivots);
        let kin = &self.out_kin;
        self.open
            .faces
            .iter()
            .enumerate()
            .filter_map(|(f, face)| {
                let (point, gap) = (0..face.len())
                    .map(|i| (i, face.gap(&model, kin, i)))
                    .min_by(|a, b| a.1.total_cmp(&b.1))?;
                (gap <= 1e-9 * model.size).then_some((f, point))
            })
            .collect()
    }

    /// Fills `file_q`, `file_qdot` with the state (q, q̇ of the chain) in the file's
    /// coordinates ([`file_coordinates`]).
    pub(super) fn file_coordinates(&mut self, q: &DVector<f64>, qdot: &DVector<f64>) {
        file_coordinates(
            &self.original,
            &self.model,
            &self.open,
            &mut self.out_kin,
            &self.dynamics.pivots,
            (q, qdot),
            (&mut self.file_q, &mut self.file_qdot),
        );
    }

    /// The open faces' offsets at the current state ([`FaceOpening`]), into
    /// `self.spare.sample_openings`.
    pub(super) fn sample_openings(&mut self, q: &DVector<f64>) {
        let mut out = std::mem::take(&mut self.spare.sample_openings);
        out.clear();
        if !self.open.faces.is_empty() {
            forward_kinematics(&self.model, &mut self.out_kin, q, &self.dynamics.pivots);
            face_openings(
                &self.original,
                &self.model,
                &self.out_kin,
                &self.open,
                &mut out,
            );
        }
        self.spare.sample_openings = out;
    }

    /// The open faces' offsets at the current state ([`FaceOpening`]; empty when none is open).
    pub fn face_openings(&self) -> Vec<FaceOpening> {
        let mut out = Vec::new();
        if !self.open.faces.is_empty() {
            let mut kin = Data::new(&self.model);
            forward_kinematics(
                &self.model,
                &mut kin,
                &self.chain_q(),
                &self.dynamics.pivots,
            );
            face_openings(&self.original, &self.model, &kin, &self.open, &mut out);
        }
        out
    }

    /// The current state in the file's coordinates.
    pub(super) fn file_state(&self) -> (DVector<f64>, DVector<f64>) {
        let (q, qdot) = (self.chain_q(), self.chain_qdot());
        if self.open.files_tree {
            return (q, qdot);
        }
        let n = self.original.dof();
        let (mut fq, mut fqdot) = (vec![0.0; n], vec![0.0; n]);
        let mut kin = Data::new(&self.model);
        file_coordinates(
            &self.original,
            &self.model,
            &self.open,
            &mut kin,
            &self.dynamics.pivots,
            (&q, &qdot),
            (&mut fq, &mut fqdot),
        );
        (DVector::from_vec(fq), DVector::from_vec(fqdot))
    }

    /// The seats of the open faces' gap events at the current state ([`SegmentEvents::gap_seats`]).
    pub(super) fn gap_seats(&mut self) -> Vec<f64> {
        if self.open.faces.is_empty() {
            return Vec::new();
        }
        let model = Arc::clone(&self.model);
        let model = &*model;
        let q = self.chain_q();
        forward_kinematics(model, &mut self.out_kin, &q, &self.dynamics.pivots);
        let kin = &self.out_kin;
        self.open
            .faces
            .iter()
            .flat_map(|f| (0..f.len()).map(move |i| f.gap(model, kin, i) / model.size))
            .map(|start| {
                if start < -events::ROCKING_EVENT_MARGIN {
                    start
                } else {
                    0.0
                }
            })
            .collect()
    }

    /// T + U at the current state on the chain integrated (J).
    fn mechanical_energy(&mut self) -> f64 {
        let model = Arc::clone(&self.model);
        let (q, qdot) = (self.chain_q(), self.chain_qdot());
        let (t, u) = state_energies(&model, &mut self.out_kin, &self.dynamics.pivots, &q, &qdot);
        t + u
    }

    /// The open faces' largest penetration (m) at q, with the face's interface name: the run's
    /// invariant ([`GAP_TOLERANCE`]).
    pub(super) fn deepest_open_point(&mut self, q: &DVector<f64>) -> Option<(f64, String)> {
        if self.open.faces.is_empty() {
            return None;
        }
        let model = Arc::clone(&self.model);
        forward_kinematics(&model, &mut self.out_kin, q, &self.dynamics.pivots);
        let mut deepest: Option<(f64, String)> = None;
        for face in &self.open.faces {
            for i in 0..face.len() {
                let g = face.gap(&model, &self.out_kin, i);
                if deepest.as_ref().is_none_or(|d| g < d.0) {
                    deepest = Some((g, self.original.interfaces[face.interface].name.clone()));
                }
            }
        }
        deepest
    }
}

/// A rate below this (in √(g/L)) is round-off: a joint rocking at φ ≈ 0 that a landing leaves
/// with it is locked by the loops the landing closed, and seats with the landing
/// ([`Simulation::recontact`]). Far below the seat rate of an impact (1e-4 rad/s), which would
/// stop joints that are still turning slowly.
const LOCKED_RATE: f64 = 1e-9;

/// The angles of the relative rotation of an open interface's child to its parent (the file's
/// convention, [`crr_kinematics::relative_angles`]) and their rates from the relative angular
/// velocity ω = ω_c − ω_p, in the parent's rest frame Γ_pᵀω = θ̇₁a₁ (+ θ̇₂a₂): a₁ = u for a
/// hinge (θ̇ = uᵀΓ_pᵀω), a₁ = e₁ and a₂ = R(e₁, θ₁)e₂ for a rocking base (least squares: an open
/// face turns freely, also about its normal). `kin` holds the chain's poses and velocities.
fn open_face_motion(
    model: &Model,
    kin: &Data,
    iface: &crr_kinematics::Interface,
) -> ([f64; 2], [f64; 2]) {
    let frame = |b: usize| model.body_coord[b];
    let spin = |b: usize| -> Vector3<f64> {
        kin.spatial_velocity[frame(b)]
            .fixed_rows::<3>(0)
            .into_owned()
    };
    let (rc, wc) = (kin.rot_ops[frame(iface.child)], spin(iface.child));
    let (rp, wp) = match iface.parent {
        crr_kinematics::Parent::Ground => (nalgebra::Matrix3::identity(), Vector3::zeros()),
        crr_kinematics::Parent::Body(b) => (kin.rot_ops[frame(b)], spin(b)),
    };
    let mut angles = [0.0; 2];
    crr_kinematics::relative_angles(&iface.kind, &(rp.transpose() * rc), &mut angles);
    let w = rp.transpose() * (wc - wp);
    let mut rates = [0.0; 2];
    if iface.kind.angle_count() == 1 {
        rates[0] = iface.kind.axis(0).dot(&w);
    } else {
        let a1 = iface.kind.axis(0);
        let turn =
            nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(a1), angles[0]);
        let a = nalgebra::Matrix3x2::from_columns(&[a1, turn * iface.kind.axis(1)]);
        if let Some(inv) = (a.transpose() * a).try_inverse() {
            let r = inv * (a.transpose() * w);
            rates = [r[0], r[1]];
        }
    }
    (angles, rates)
}

/// The state (q, q̇ of `chain`, the file's model `original` with the faces of `open` open) in the
/// file's coordinates: a coordinate whose interface is closed is that slot's angle and rate in
/// the chain; one whose face is open is the angle of the relative rotation of its bodies
/// ([`crr_kinematics::relative_angles`], the translation off the pivot left out) and its rate
/// from their relative angular velocity ([`open_face_motion`]).
fn file_coordinates(
    original: &Model,
    chain: &Model,
    open: &OpenLoops,
    kin: &mut Data,
    pivots: &ActivePivots,
    (q, qdot): (&DVector<f64>, &DVector<f64>),
    (file_q, file_qdot): (&mut [f64], &mut [f64]),
) {
    let mut angles = vec![0.0; chain.slot_count];
    let mut rates = vec![0.0; chain.slot_count];
    slot_angles(chain, kin, q, pivots, &mut angles);
    crr_kinematics::velocities(chain, kin, qdot);
    slot_rates(chain, kin, qdot, &mut rates);
    for k in 0..original.dof() {
        if let Some(a) = open.active_slot(k) {
            file_q[k] = angles[a];
            file_qdot[k] = rates[a];
        }
    }
    for face in &open.faces {
        let iface = &original.interfaces[face.interface];
        let crr_kinematics::Role::Tree { first_coord } = iface.role else {
            continue;
        };
        let (angles, rates) = open_face_motion(chain, kin, iface);
        let count = iface.kind.angle_count();
        file_q[first_coord..first_coord + count].copy_from_slice(&angles[..count]);
        file_qdot[first_coord..first_coord + count].copy_from_slice(&rates[..count]);
    }
}

/// The offset of every face of `open` ([`FaceOpening`]) in the poses of `kin`
/// ([`forward_kinematics`] of `chain`, the chain integrated), into `out` (cleared first).
fn face_openings(
    original: &Model,
    chain: &Model,
    kin: &Data,
    open: &OpenLoops,
    out: &mut Vec<FaceOpening>,
) {
    out.clear();
    out.extend(open.faces.iter().map(|face| {
        let kind = &original.interfaces[face.interface].kind;
        let reference = kind.pivot(&vec![Side::Positive; kind.angle_count()]);
        let child = crr_kinematics::body_point(chain, kin, face.child, &reference);
        let parent = face.parent.map_or(reference, |b| {
            crr_kinematics::body_point(chain, kin, b, &reference)
        });
        let d = child - parent;
        FaceOpening {
            interface: face.interface,
            offset: [d.x, d.y, d.z],
        }
    }));
}

/// Each body's translation from where the file's coordinates alone put it: the sum of the
/// offsets of the open faces of the file's spanning tree on its path to the ground. The file's
/// coordinates give an open face of the tree as its bodies' relative rotation, its child turned
/// about P⁺ ([`FaceOpening`]); the rotations are exact, so the bodies below it are off by its
/// offset only, and by the offsets of the open faces above it. Adding these to the poses of
/// [`forward_kinematics`] of `model` at the sample's q (an open slot on its positive side) puts
/// every body where it is. Faces that close loops move no body of the file's tree.
pub fn body_offsets(model: &Model, openings: &[FaceOpening]) -> Vec<Vector3<f64>> {
    // Frame by frame in the order of [`forward_kinematics`] (a parent's frame before its
    // children's): a frame carries its parent frame's offset, and the first frame of an open
    // face of the tree adds the face's own.
    let mut frames: Vec<Vector3<f64>> = Vec::with_capacity(model.dof());
    for (k, c) in model.coords.iter().enumerate() {
        let mut offset = c.parent.map_or_else(Vector3::zeros, |p| frames[p]);
        if matches!(model.interfaces[c.interface].role,
            crr_kinematics::Role::Tree { first_coord } if first_coord == k)
            && let Some(o) = openings.iter().find(|o| o.interface == c.interface)
        {
            offset += Vector3::from(o.offset);
        }
        frames.push(offset);
    }
    model.body_coord.iter().map(|&k| frames[k]).collect()
}

/// A point's normal gap with its rate and acceleration ([`gap_motion`]).
#[derive(Clone, Copy, Debug)]
struct GapMotion {
    gap: f64,
    rate: f64,
    acceleration: f64,
}

/// A gap's slope along the motion within this (× the model's size, per rad) grazes: the point
/// moves along its support at first order, and its curvature decides; below −this it enters its
/// support. Far above the one-sided difference's error (ε² g‴/3 with ε = [`GRAZING_STEP`], about
/// 3e-7 of the lever, and the loops' closure to 1e-13 over ε) and far below a lifting corner's
/// slope (its lever, a fraction of the size).
const GRAZING_SLOPE: f64 = 1e-5;

/// A gap curvature along the motion below −this (× the model's size, per rad²) enters the other
/// body: far above the second difference's errors (ε g‴, about 1e-3 of the lever, and the loops'
/// closure to 1e-13 of the size over ε² = 1e-6, about 4e-7) and far below a block's own,
/// −w(1 − cos θ)″ = −w.
const GRAZING_CURVATURE: f64 = 1e-2;

/// The largest angle (rad) of the steps along q̈ of [`gap_along_motion`].
const GRAZING_STEP: f64 = 1e-3;

/// A point's gap along the motion from rest, per unit of the largest coordinate's turn.
#[derive(Clone, Copy, Debug)]
struct AlongMotion {
    /// Its first derivative (m/rad).
    slope: f64,
    /// Its second derivative (m/rad²).
    curvature: f64,
}

impl AlongMotion {
    /// The point moves into its support: at first order, or along it at first order and into
    /// it at second.
    fn enters(&self, size: f64) -> bool {
        self.slope < -GRAZING_SLOPE * size
            || (self.slope.abs() <= GRAZING_SLOPE * size
                && self.curvature < -GRAZING_CURVATURE * size)
    }
}

/// The slope and curvature of each point's gap along the motion from rest at q: the states
/// q + σq̈ at σ = 0, s, 2s (s turns the coordinate of largest q̈ by ε = [`GRAZING_STEP`]), their
/// loops closed again by the least change of the coordinates that are not seated, and the
/// differences (4g(s) − g(2s) − 3g(0))/2ε and (g(2s) − 2g(s) + g(0))/ε². The motion's own
/// magnitude drops out: the slope says whether the point leaves or enters its support at first
/// order in the displacement, whatever the load's margin (at the multiplier itself q̈ is of
/// order 1e-9 g/L), and the curvature, which the first-order part does not reach, decides where
/// it does neither. From rest the motion is q + ½t²q̈ + O(t⁴): the gap of a point that grazes
/// (J q̈ = 0) is ⅛t⁴ q̈ᵀ(∂²g/∂q²)q̈ plus the fourth-order part of the motion itself, which this
/// leaves out (exact where the face's two bodies move relative to each other in one coordinate,
/// a block tipping away from its neighbour, two equal blocks tipping together). None where
/// q̈ = 0 or the loops cannot be closed again.
fn gap_along_motion(
    model: &Model,
    kin: &mut Data,
    dynamics: &Dynamics,
    faces: &[&OpenFace],
    q: &DVector<f64>,
) -> Option<Vec<Vec<AlongMotion>>> {
    let qddot = &dynamics.qddot;
    let largest = qddot.amax();
    if !(largest > 0.0 && largest.is_finite()) {
        return None;
    }
    let n = model.dof();
    let free: Vec<usize> = (0..n).filter(|k| !dynamics.seated.contains(k)).collect();
    let held: Vec<(usize, f64)> = dynamics
        .seated
        .iter()
        .filter(|&&s| s >= n)
        .map(|&s| (s, 0.0))
        .collect();
    let step = GRAZING_STEP / largest;
    let mut gaps = |sigma: f64| -> Option<Vec<Vec<f64>>> {
        let mut at = q + qddot * sigma;
        if model.constraint_rows > 0 {
            crr_dynamics::closed_chain::project_positions_holding(
                model,
                kin,
                &dynamics.pivots,
                &mut at,
                Some(&free),
                &held,
            )
            .ok()?;
        }
        forward_kinematics(model, kin, &at, &dynamics.pivots);
        Some(
            faces
                .iter()
                .map(|f| (0..f.len()).map(|i| f.gap(model, kin, i)).collect())
                .collect(),
        )
    };
    let (g0, g1, g2) = (gaps(0.0)?, gaps(step)?, gaps(2.0 * step)?);
    let eps = GRAZING_STEP;
    Some(
        g0.iter()
            .zip(&g1)
            .zip(&g2)
            .map(|((a, b), c)| {
                a.iter()
                    .zip(b)
                    .zip(c)
                    .map(|((a, b), c)| AlongMotion {
                        slope: (4.0 * b - c - 3.0 * a) / (2.0 * eps),
                        curvature: (c - 2.0 * b + a) / (eps * eps),
                    })
                    .collect()
            })
            .collect(),
    )
}

/// The slots `releases` of `d` released on their sides.
fn release_in(d: &mut Dynamics, releases: &[(usize, Side)]) {
    for &(k, side) in releases {
        d.pivots.sides[k] = side;
        d.seated.retain(|&s| s != k);
    }
}

/// The normal gap of every point of `faces` at q, with its rate and acceleration: central
/// differences over the states q ± h q̇ + ½h² q̈ (h = 1e-4 √(L/g)), on `model` with `pivots`.
fn gap_motion(
    model: &Model,
    kin: &mut Data,
    pivots: &ActivePivots,
    faces: &[&OpenFace],
    (q, qdot, qddot): (&DVector<f64>, &DVector<f64>, &DVector<f64>),
) -> Vec<Vec<GapMotion>> {
    let h = 1e-4 * (model.size / model.gravity).sqrt();
    let mut gaps = |q: &DVector<f64>| -> Vec<Vec<f64>> {
        forward_kinematics(model, kin, q, pivots);
        faces
            .iter()
            .map(|f| (0..f.len()).map(|i| f.gap(model, kin, i)).collect())
            .collect()
    };
    let step = |sign: f64| q + qdot * (sign * h) + qddot * (0.5 * h * h);
    let (before, now, after) = (gaps(&step(-1.0)), gaps(q), gaps(&step(1.0)));
    now.iter()
        .enumerate()
        .map(|(f, points)| {
            points
                .iter()
                .enumerate()
                .map(|(i, &gap)| GapMotion {
                    gap,
                    rate: (after[f][i] - before[f][i]) / (2.0 * h),
                    acceleration: (after[f][i] - 2.0 * gap + before[f][i]) / (h * h),
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hanging chain ground → link0 → link1 → link2, one coordinate each: whether link2 moves
    /// relative to a body depends on the coordinates between the two alone, however the bodies
    /// below them move.
    #[test]
    fn a_child_is_still_on_its_parent_when_the_coordinates_between_them_are() {
        let model = Model::from_spec(&crr_kinematics::fixtures::serial_chain(3)).unwrap();
        let (link0, link1, link2) = (Some(0), Some(1), 2);
        // link0 and link1 move; link2 keeps its angle to link1.
        let still = [false, false, true];
        assert!(child_still_on_parent(&model, link1, link2, &still));
        // Relative to link0, to the ground: link1's turn lies between them.
        assert!(!child_still_on_parent(&model, link0, link2, &still));
        assert!(!child_still_on_parent(&model, None, link2, &still));
        // Its own coordinate moving: not still.
        assert!(!child_still_on_parent(
            &model,
            link1,
            link2,
            &[true, true, false]
        ));
        // Everything still: still relative to the ground too.
        assert!(child_still_on_parent(&model, None, link2, &[true; 3]));
        // The path read from the other end (the upper body as the parent): link1 turns between
        // link0 and link2; link1 on link2 is still when only link0 turns.
        assert!(!child_still_on_parent(&model, Some(2), 0, &still));
        assert!(child_still_on_parent(
            &model,
            Some(2),
            1,
            &[false, true, true]
        ));
    }
}

#[cfg(test)]
mod gap_tests {
    use super::*;
    use crr_kinematics::Role;
    use crr_kinematics::fixtures::{box_body, rocking_base};
    use crr_kinematics::spec::StructureSpec;
    use nalgebra::{Rotation3, Vector3};

    /// Width w (x), depth (y) and height (z) of the two blocks.
    const W: f64 = 0.5;
    const DEPTH: f64 = 0.5;
    const H: f64 = 1.0;

    /// Two blocks side by side on the ground, `a` on x ∈ [−w, 0] and `b` on x ∈ [0, w], their
    /// head joint x = 0 a rocking base (b on a) that closes the loop through the ground.
    fn pair() -> Model {
        let (d, h) = (DEPTH / 2.0, H);
        let spec = StructureSpec {
            name: "pair".into(),
            gravity: 9.81,
            body: vec![
                box_body("a", 2000.0, [-W / 2.0, 0.0, h / 2.0], [W, DEPTH, h]),
                box_body("b", 2000.0, [W / 2.0, 0.0, h / 2.0], [W, DEPTH, h]),
            ],
            interface: vec![
                rocking_base(
                    "a_on_ground",
                    "ground",
                    "a",
                    [[-W, -d, 0.0], [0.0, -d, 0.0], [0.0, d, 0.0], [-W, d, 0.0]],
                ),
                rocking_base(
                    "b_on_ground",
                    "ground",
                    "b",
                    [[0.0, -d, 0.0], [W, -d, 0.0], [W, d, 0.0], [0.0, d, 0.0]],
                ),
                rocking_base(
                    "b_on_a",
                    "a",
                    "b",
                    [[0.0, -d, 0.0], [0.0, d, 0.0], [0.0, d, h], [0.0, -d, h]],
                ),
            ],
            symmetry: Vec::new(),
        };
        Model::from_spec(&spec).unwrap()
    }

    /// The head face's four gaps with `a` turned by `turn_a` and `b` by `turn_b` (rad, about
    /// +y, each on the edge of its base at its least x: the blocks tip towards −x).
    fn head_gaps(model: &Model, turn_a: f64, turn_b: f64) -> Vec<f64> {
        let mut pivots = ActivePivots::uniform(model, Side::Positive);
        let mut q = DVector::zeros(model.dof());
        for (name, turn) in [("a_on_ground", turn_a), ("b_on_ground", turn_b)] {
            let iface = &model.interfaces[model.interface_index(name).unwrap()];
            let Role::Tree { first_coord } = iface.role else {
                panic!("{name} is in the tree");
            };
            // Tilt about e₂ = +y, its second angle; negative: the pivot at the least x.
            pivots.sides[iface.slots.start + 1] = Side::Negative;
            q[first_coord + 1] = -turn;
        }
        let mut kin = Data::new(model);
        forward_kinematics(model, &mut kin, &q, &pivots);
        let face = OpenFace::of(model, model.interface_index("b_on_a").unwrap());
        (0..face.len()).map(|i| face.gap(model, &kin, i)).collect()
    }

    /// A point at rest turned by `turn` about +y through `pivot` (the block tipping towards −x).
    fn tipped(x: Vector3<f64>, pivot: Vector3<f64>, turn: f64) -> Vector3<f64> {
        pivot + Rotation3::from_axis_angle(&Vector3::y_axis(), -turn) * (x - pivot)
    }

    /// A block that tips away from its neighbour about its far foot takes the lower edge of its
    /// face up and away from the neighbour's face: the gap there is the distance of that edge
    /// from the neighbour's plane x = 0, w(1 − cos θ) > 0, by the rotation written here. At the
    /// upper edge, which leaves at first order, each corner lies over the other block's face and
    /// the gap is the nearer of the two, a's corner from b's plane and b's corner from a's
    /// turned plane. (Measured from the tipped face's plane extended past its lower edge, the
    /// neighbour's lower corner would read −w(1 − cos θ), a landing at once.)
    #[test]
    fn a_block_tipping_away_from_its_neighbour_opens_their_face() {
        let model = pair();
        let face = OpenFace::of(&model, 2);
        for turn in [1e-6, 1e-3, 0.1] {
            let gaps = head_gaps(&model, turn, 0.0);
            let foot = Vector3::new(-W, 0.0, 0.0);
            let a_normal = Rotation3::from_axis_angle(&Vector3::y_axis(), -turn) * Vector3::x();
            for (i, gap) in gaps.iter().enumerate() {
                let corner = face.points[i];
                // a's corner from b's face plane x = 0 (b does not move), and b's corner from
                // a's turned face plane.
                let a_corner = tipped(corner, foot, turn);
                let from_b = -a_corner.x;
                let from_a = a_normal.dot(&(corner - a_corner));
                let expected = if corner.z == 0.0 {
                    from_b
                } else {
                    from_b.min(from_a)
                };
                assert!(
                    (gap - expected).abs() <= 1e-15,
                    "θ = {turn}: gap {gap:e} at corner {i}, expected {expected:e}"
                );
                assert!(*gap > 0.0, "θ = {turn}: corner {i} reads {gap:e}");
            }
            let lower = W * (1.0 - turn.cos());
            assert!((gaps[0] - lower).abs() <= 1e-15 && (gaps[1] - lower).abs() <= 1e-15);
        }
    }

    /// Both blocks tipping together by the same θ (each about its −x foot): a's lower corner
    /// enters b, behind b's turned face by w(1 − cos θ) while it lies over that face, a
    /// penetration the gap must read (b's corner, its pivot, stays below a's lifted base).
    #[test]
    fn blocks_tipping_together_press_their_face_at_second_order() {
        let model = pair();
        for turn in [1e-3, 0.1] {
            let gaps = head_gaps(&model, turn, turn);
            let inside = W * (1.0 - turn.cos());
            for i in [0, 1] {
                // The distance of a's turned corner from b's turned plane, by the rotations.
                let corner = OpenFace::of(&model, 2).points[i];
                let a_corner = tipped(corner, Vector3::new(-W, 0.0, 0.0), turn);
                let b_normal = Rotation3::from_axis_angle(&Vector3::y_axis(), -turn) * Vector3::x();
                let expected = b_normal.dot(&(corner - a_corner));
                assert!(
                    (expected + inside).abs() <= 1e-15,
                    "{expected:e} against −{inside:e}"
                );
                assert!(
                    (gaps[i] - expected).abs() <= 1e-15,
                    "θ = {turn}: gap {:e} at corner {i}, expected {expected:e}",
                    gaps[i]
                );
            }
        }
    }
}
