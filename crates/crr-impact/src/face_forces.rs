//! The contact forces of a structure in motion, posed on its contact faces: the most compressive
//! distribution of a hyperstatic structure's contact forces as one linear program (the hypotheses
//! monitor's question when the least-norm forces show a tension).
//!
//! **Loads.** At a state whose accelerations are solved, body b needs from its contacts the net
//! force Fᵦ = mᵦ(a_b − g_eff) (its centre's acceleration a_b, the effective gravity g_eff of the
//! ground's frame) and the net moment about its centre of mass Mᵦ = I_b α_b + ω_b × I_b ω_b
//! (Euler; I_b = R I_rest Rᵀ in world axes). The loops and seated joints of a hyperstatic
//! structure hold it more times than its motion needs, so these loads fix a family of contact
//! forces, not one.
//!
//! **Contacts.** Each interface touches on the points of its face ([`crr_kinematics::ContactFace`])
//! that its state keeps closed: a seated angle offers both of its pivots, a rocking one only its
//! current pivot. So a seated hinge touches on its two pivot lines, a rocking hinge on one; a
//! rocking base on one corner (both tilts free), on an edge (one tilt seated) or on its four
//! corners. Each touching point carries f = fₙn + f₁t₁ + f₂t₂ from the parent on the child (the
//! face's axes turned with the parent; the pressing certificate turns them with the child on a
//! base rocking on an edge of its first tilt, [`PressingCertificate`]), unilateral: fₙ ≥ s. A
//! hinge also carries its bilateral couples about n and t₁ (it is a line); a rocking base on one
//! corner the couple about n that its two tilts leave no freedom for (the CRR base does not
//! twist); a seat that may twist carries no torsion, so only its current pivot takes tangential
//! forces. A plain hinge (one pivot line) is a pin: its force is free.
//!
//! **Program.** max s subject to every body's equilibrium Σ f = Fᵦ, Σ (p − c_b) × f + couples = Mᵦ,
//! w fₙ ≥ s at every unilateral point, s ≤ 0 (with a small proximal term on the forces,
//! [`PROXIMAL`]); w is 1, or for the monitor's and the impulses' programs the point's face's
//! [`touching_points_per_edge`], which measures each point's force per edge. Its optimum s* is
//! the largest smallest (weighted) normal force any distribution reaches: s* = 0 when a
//! compressive one exists, and s* < 0 is the least tension the motion needs somewhere. One linear program with one global answer, whatever the order of
//! the bodies, interfaces and corners; solved by `clarabel`'s interior point, on the sparse
//! equilibrium of the bodies (six rows each, a few columns per contact point) rather than on the
//! dense self-stress states of the tree coordinates.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::{Matrix3, Vector3};

use crr_dynamics::eom::Dynamics;
use crr_kinematics::kinematics::frame_point;
use crr_kinematics::{ContactFace, InterfaceKind, Model, Parent, Role, Side};

use crate::least_norm::LeastNorm;
use crate::monitor::ForceWork;

mod tree;
pub use tree::{LeastNormal, least_normal_impulse_on_tree};

/// Weight ε of the proximal term ½ε‖f‖² added to the program (forces in units of the weight W).
/// It makes the program strictly convex in the forces, so that among the optimal distributions
/// it takes the least-norm one and the interior point's systems stay well conditioned on
/// degenerate optima: without it `clarabel` stopped with a numerical error on the temple near its
/// stop, where the optimal distributions form a wide face. It lowers s* by at most ½ε‖f₀‖² W
/// (f₀ the least-norm optimal forces, ‖f₀‖² of order one in these units): about 1e-7 W, far
/// below the monitor's tolerance of 5e-4 W.
pub const PROXIMAL: f64 = 1e-7;

/// The answer of the program at one state.
#[derive(Clone, Debug, PartialEq)]
pub struct MostCompressive {
    /// s*, the largest smallest normal force at a touching point that any distribution in
    /// equilibrium reaches (N; an impulse in N s for [`most_compressive_impulses`]), each point's
    /// measured per edge ([`touching_points_per_edge`]: a hinge's pivot line as it is, a corner
    /// of a rocking base times the corners it shares an edge with); 0 when a compressive
    /// distribution exists.
    pub min_normal: f64,
    /// The interface whose point holds s* with the largest dual price (the contact that limits
    /// it; the lowest index among equals), None when no point is unilateral.
    pub limiting: Option<usize>,
    /// The normal force of every interface under that distribution (N, the sum over its
    /// touching points), in interface order.
    pub normals: Vec<f64>,
}

/// A column of the program: a force along `direction` at `point`, or a couple.
#[derive(Clone, Debug)]
struct Unknown {
    interface: usize,
    /// Whether it is a normal force that must push (fₙ ≥ s).
    unilateral: bool,
    /// The point (world, current), None for a couple.
    point: Option<Vector3<f64>>,
    /// Direction (world, current).
    direction: Vector3<f64>,
    /// What the column is, whatever the state: its interface, its point at rest (None for a
    /// couple) and the place of its direction among the point's or the couples.
    key: UnknownKey,
}

/// A column's identity across states ([`Unknown::key`]): a distribution found at one state is
/// carried to another with other touching points by the columns they share.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct UnknownKey {
    interface: usize,
    rest: Option<[u64; 3]>,
    along: usize,
}

/// The most compressive distribution of the contact forces at the state solved in `dynamics`
/// (its kinematics, seated slots and pivots) with the bodies' accelerations in `work` (from
/// [`crate::monitor::contact_forces_into`] at the same state, general path). None when the
/// program does not solve (the caller then judges the least-norm forces).
pub fn most_compressive(
    model: &Model,
    dynamics: &Dynamics,
    work: &ForceWork,
) -> Option<MostCompressive> {
    let program = FaceProgram::build(model, dynamics).per_edge();
    let loads = program.loads(model, dynamics, work)?;
    let (x, z) = program.solve(&loads, 0.0)?;
    Some(program.answer(&x, Some(&z)))
}

/// What Coulomb friction the contact forces of a hyperstatic structure need at one state
/// ([`least_friction`]): their resultants are not fixed by the motion, so the friction demand
/// |F_t|/N of one distribution (the least-norm one) says nothing of whether some other holds.
#[derive(Clone, Debug, PartialEq)]
pub enum FrictionNeed {
    /// Some distribution in equilibrium with the motion presses at every touching point (to
    /// −tolerance/2, per edge) and keeps every contact's resultant within Coulomb's cone of the
    /// μ asked, |F_t| ≤ μ N plus its share of the tolerance.
    Holds,
    /// None does: the least μ for which one does (to [`FRICTION_DIGITS`] of it; infinite
    /// beyond [`MOST_FRICTION`]), and, where it is finite, in the distribution found there the
    /// contact whose resultant asks the most of it with a normal force above the tolerance.
    Slides {
        /// The least μ some compressive distribution needs.
        least: f64,
        /// That contact (None beyond [`MOST_FRICTION`], or where none carries more than the
        /// tolerance): its interface, its normal force (N) and its |F_t|/N.
        limiting: Option<(usize, f64, f64)>,
    },
}

/// Relative width of the bracket of [`least_friction`]'s μ.
pub const FRICTION_DIGITS: f64 = 1e-3;

/// Largest μ [`least_friction`] tries: beyond it the contacts need a friction no joint has.
pub const MOST_FRICTION: f64 = 1e3;

/// The excess τ (W) over every cone below which a distribution counts as within the cones of a
/// μ in [`least_friction`]'s bisection: the interior point's accuracy on forces of order one.
const WITHIN_CONES: f64 = 1e-7;

/// Whether the contact forces at the state solved in `dynamics` (the bodies' accelerations in
/// `work`, [`crate::monitor::contact_forces_into`]) can keep every contact within Coulomb's
/// cone of `mu`: one second-order cone program on the faces, min τ ≥ 0 over the distributions
/// in equilibrium with the motion whose touching points press to −tolerance/2 (measured per
/// edge, as the monitor's program [`most_compressive`]) and whose contacts' resultants (over
/// their touching points, as the monitor's sliding test reads them) keep |F_t| ≤ μ N + τ. It
/// holds where τ* is within a share of `tolerance` (the shares add up to the `tolerance` one
/// contact of a tree is allowed). Where it does not, the least μ with τ* = 0, by bisection on
/// the same program. The program is feasible wherever a compressive distribution exists (τ is
/// free), so an infeasibility is no verdict: None then, and where the solver fails on the μ
/// asked (the caller keeps its own verdict); a failure inside the bisection counts as not
/// holding, which can only raise the least μ.
pub fn least_friction(
    model: &Model,
    dynamics: &Dynamics,
    work: &ForceWork,
    mu: f64,
    tolerance: f64,
) -> Option<FrictionNeed> {
    let program = FaceProgram::build(model, dynamics).per_edge();
    let loads = program.loads(model, dynamics, work)?;
    let floor = 0.5 * tolerance / program.weight;
    let cones = program.cone_columns();
    let share = tolerance / (program.weight * cones.len().max(1) as f64);
    let (tau, _) = program.least_cone_excess(&loads, &cones, mu, floor)?;
    if tau <= share {
        return Some(FrictionNeed::Holds);
    }
    let within = |mu: f64| {
        program
            .least_cone_excess(&loads, &cones, mu, floor)
            .filter(|(tau, _)| *tau <= WITHIN_CONES)
            .map(|(_, x)| x)
    };
    let (mut low, mut high) = (mu, (2.0 * mu).max(0.01));
    let mut found = loop {
        if let Some(x) = within(high) {
            break x;
        }
        if high > MOST_FRICTION {
            return Some(FrictionNeed::Slides {
                least: f64::INFINITY,
                limiting: None,
            });
        }
        low = high;
        high *= 2.0;
    };
    while high - low > FRICTION_DIGITS * high {
        let mid = 0.5 * (low + high);
        match within(mid) {
            Some(x) => {
                high = mid;
                found = x;
            }
            None => low = mid,
        }
    }
    Some(FrictionNeed::Slides {
        least: high,
        limiting: program.most_demanding(&found, tolerance, &model.interfaces),
    })
}

/// The most compressive distribution of contact impulses that changes each body's momentum by
/// `momentum_change[b]` = (m_b Δċ_b, I_b Δω_b) (N s; N m s about its centre of mass: the impulse
/// body b needs from its contacts in an instant, where gravity and the ground's motion give
/// none), on the touching points of the state in `dynamics` (its kinematics, seated slots and
/// pivots, as [`most_compressive`]). `min_normal` is then in N s, each point's impulse measured
/// per edge ([`touching_points_per_edge`]): below 0 when the contacts can give that change only
/// by pulling somewhere. None when the program does not solve.
///
/// The slots listed in `set_by_law` (those of an impact whose law sets their rates, the
/// restitution and Dirac laws) touch on both of their pivots, and their interfaces take on the
/// points that touch whatever impulse the law needs, of either sign: the law's own hypothesis,
/// not checked. Only the other contacts are.
pub fn most_compressive_impulses(
    model: &Model,
    dynamics: &Dynamics,
    momentum_change: &[(Vector3<f64>, Vector3<f64>)],
    set_by_law: &[usize],
) -> Option<MostCompressive> {
    compressive_impulses_at_least(model, dynamics, momentum_change, set_by_law, None)
}

/// [`most_compressive_impulses`], answered without its program where a cheaper distribution
/// already presses enough: the least-norm distribution of the same impulses over the same
/// touching points (one least-squares solve, the correction that carries distributions, from no
/// impulse) is one of the program's feasible points, so s* is at least its least normal impulse.
/// Where that impulse is at least `floor` (N s; None: the program always), the answer is that
/// distribution: its least normal impulse capped at 0 as `min_normal` (a lower bound of s*),
/// `limiting` None (no program, no dual price), its `normals`. Otherwise, the program's answer.
///
/// The impulses of impacts and landings are mostly carried by faces that press everywhere, and
/// there the least-norm split already does: on the bundled temple at 0.8 of its record it
/// answered 378 of the 379 checks of its impulses with a least impulse of −3e-6 to −1e-8
/// W·√(L/g), against −1e-3 for a violation (docs/performance.md).
pub fn compressive_impulses_at_least(
    model: &Model,
    dynamics: &Dynamics,
    momentum_change: &[(Vector3<f64>, Vector3<f64>)],
    set_by_law: &[usize],
    floor: Option<f64>,
) -> Option<MostCompressive> {
    let program =
        FaceProgram::build_setting(model, dynamics, set_by_law, FaceAxes::Parent).per_edge();
    // Impulses in W·√(L/g), the structure's weight over its time unit, so that the program's
    // unknowns are of order one as its forces are (its tolerances and proximal term assume it).
    let time = (model.size / model.gravity).sqrt();
    let unit = program.weight * time;
    let mut loads = vec![0.0; 6 * program.bodies];
    for (b, (linear, angular)) in momentum_change.iter().enumerate() {
        for i in 0..3 {
            loads[6 * b + i] = linear[i] / unit;
            loads[6 * b + 3 + i] = angular[i] / (unit * model.size);
        }
    }
    let least_norm = floor.and_then(|floor| {
        program
            .least_norm(&loads, &mut LeastNorm::default())
            .filter(|x| program.smallest(x) * unit >= floor)
    });
    let mut answer = match least_norm {
        Some(x) => program.answer(&x, None),
        None => {
            let (x, z) = program.solve(&loads, 0.0)?;
            program.answer(&x, Some(&z))
        }
    };
    answer.min_normal *= time;
    for n in &mut answer.normals {
        *n *= time;
    }
    Some(answer)
}

/// The program's matrix at one state: the equilibrium rows of the bodies over the touching
/// points' forces and the couples, which depend on the configuration, the seated slots and the
/// pivots, not on the loads.
#[derive(Clone, Debug)]
struct FaceProgram {
    unknowns: Vec<Unknown>,
    /// Columns (1-based: column 0 is s) of the unilateral points' normal forces.
    unilateral: Vec<usize>,
    /// Per unilateral column, the factor its normal force is measured with against s: 1, or
    /// with [`Self::per_edge`] its face's [`touching_points_per_edge`].
    unilateral_weight: Vec<f64>,
    /// The equilibrium rows' entries (row, column ≥ 1, value), forces in units of the weight W
    /// and moments in W·size.
    entries: Vec<(usize, usize, f64)>,
    bodies: usize,
    weight: f64,
    interfaces: usize,
    /// Per unilateral column, its face's [`touching_points_per_edge`].
    edge_points: Vec<f64>,
}

/// The axes a face's point forces are posed on.
#[derive(Clone, Copy, PartialEq)]
enum FaceAxes {
    /// The parent's face axes, turned with the parent: the normal force is the one across the
    /// parent's face (the monitor's question, as the subtree recursion of `monitor` asks it).
    Parent,
    /// The axes of the normal along which the touching points leave under the contact program's
    /// openings ([`leaves_along_child_normal`]): the certificate's, which must price exactly
    /// the program's motions.
    Leaving,
}

impl FaceProgram {
    fn build(model: &Model, dynamics: &Dynamics) -> FaceProgram {
        Self::build_setting(model, dynamics, &[], FaceAxes::Parent)
    }

    /// [`Self::build`] with the slots `set_by_law` touching on both pivots (as if seated), and
    /// every touching point of their interfaces carrying a normal force of either sign, posed on
    /// the axes `posed_on`.
    fn build_setting(
        model: &Model,
        dynamics: &Dynamics,
        set_by_law: &[usize],
        posed_on: FaceAxes,
    ) -> FaceProgram {
        let size = model.size;
        let mut is_seated = vec![false; model.slot_count];
        for &k in dynamics.seated.iter().chain(set_by_law) {
            is_seated[k] = true;
        }
        let mut unknowns = Vec::new();
        let mut unilateral = Vec::new();
        let mut edge_points = Vec::new();
        for index in 0..model.interfaces.len() {
            let first = unknowns.len();
            interface_columns(
                model,
                dynamics,
                index,
                (&is_seated, set_by_law),
                posed_on,
                &mut unknowns,
            );
            let before = unilateral.len();
            unilateral.extend(
                (first..unknowns.len())
                    .filter(|&j| unknowns[j].unilateral)
                    .map(|j| 1 + j),
            );
            let points = unilateral.len() - before;
            let per_edge = touching_points_per_edge(&model.interfaces[index].kind, points);
            edge_points.extend(std::iter::repeat_n(per_edge, points));
        }
        // Six rows per body: force / W, moment about the centre / (W·size); every entry kept
        // (zeros too), so that the pattern depends on the touching points only.
        let mut entries = Vec::new();
        for (j, u) in unknowns.iter().enumerate() {
            let iface = &model.interfaces[u.interface];
            let mut on = |body: usize, sign: f64| {
                let row = 6 * body;
                match u.point {
                    Some(p) => {
                        let arm = (p - dynamics.kin.com[body]).cross(&u.direction) / size;
                        for k in 0..3 {
                            entries.push((row + k, 1 + j, sign * u.direction[k]));
                            entries.push((row + 3 + k, 1 + j, sign * arm[k]));
                        }
                    }
                    None => {
                        for k in 0..3 {
                            entries.push((row + 3 + k, 1 + j, sign * u.direction[k] / size));
                        }
                    }
                }
            };
            on(iface.child, 1.0);
            if let Parent::Body(parent) = iface.parent {
                on(parent, -1.0);
            }
        }
        FaceProgram {
            unknowns,
            unilateral,
            unilateral_weight: vec![1.0; edge_points.len()],
            edge_points,
            entries,
            bodies: model.bodies.len(),
            weight: model.total_mass() * model.gravity,
            interfaces: model.interfaces.len(),
        }
    }

    /// The equilibrium rows' right-hand side: every body's net force and moment about its
    /// centre of mass (scaled like the rows), from the accelerations in `work`; None when `work`
    /// does not hold them (the one-coordinate path).
    fn loads(&self, model: &Model, dynamics: &Dynamics, work: &ForceWork) -> Option<Vec<f64>> {
        if work.acc.len() != model.dof() || work.body_force.len() != model.bodies.len() {
            return None;
        }
        let mut b = vec![0.0; 6 * self.bodies];
        for (n, body) in model.bodies.iter().enumerate() {
            let k = model.body_coord[n];
            let rot = dynamics.kin.rot_ops[k];
            let inertia = rot * body.inertia * rot.transpose();
            let omega = top(&dynamics.kin.spatial_velocity[k]);
            let alpha = top(&work.acc[k]);
            let moment = inertia * alpha + omega.cross(&(inertia * omega));
            for i in 0..3 {
                b[6 * n + i] = work.body_force[n][i] / self.weight;
                b[6 * n + 3 + i] = moment[i] / (self.weight * model.size);
            }
        }
        Some(b)
    }

    /// max s subject to the equilibrium rows with right-hand side `loads`, w fₙ ≥ s at every
    /// unilateral point (w its weight, [`Self::per_edge`]) and s ≤ `cap` (W), with the proximal
    /// term: the primal x (column 0 is s, forces in W) and the duals z of the inequality rows
    /// (one per unilateral point, then the cap's).
    fn solve(&self, loads: &[f64], cap: f64) -> Option<(Vec<f64>, Vec<f64>)> {
        let equilibrium = 6 * self.bodies;
        let (mut ri, mut ci, mut vi) = self.triplets();
        let mut b = loads.to_vec();
        // w fₙ ≥ s at every unilateral point (s − w fₙ ≤ 0), and s ≤ cap.
        let mut row = equilibrium;
        for (&c, &w) in self.unilateral.iter().zip(&self.unilateral_weight) {
            ri.extend([row, row]);
            ci.extend([0, c]);
            vi.extend([1.0, -w]);
            b.push(0.0);
            row += 1;
        }
        ri.push(row);
        ci.push(0);
        vi.push(1.0);
        b.push(cap);
        row += 1;
        let columns = 1 + self.unknowns.len();
        let a = CscMatrix::new_from_triplets(row, columns, ri, ci, vi);
        let p = self.proximal();
        let mut q = vec![0.0; columns];
        q[0] = -1.0;
        let cones = [
            SupportedConeT::ZeroConeT(equilibrium),
            SupportedConeT::NonnegativeConeT(row - equilibrium),
        ];
        let solution = solve_clarabel(&p, &q, &a, &b, &cones)?;
        Some((solution.x, solution.z[equilibrium..].to_vec()))
    }

    /// min τ + the proximal term over the distributions in equilibrium with `loads` whose
    /// unilateral points press to −`floor` (W, each times its weight) and whose every contact of
    /// `cones` ([`Self::cone_columns`]) keeps its resultant within Coulomb's cone widened by
    /// τ ≥ 0: ‖(T₁, T₂)‖ ≤ μ N + τ (W), N the sum of its normal forces and Tₖ of its forces along
    /// tangent k. (τ*, the primal x); None where the solver does not solve (after the retry
    /// with looser settings), or finds no such distribution at all.
    fn least_cone_excess(
        &self,
        loads: &[f64],
        cones_of: &[Vec<(usize, usize)>],
        mu: f64,
        floor: f64,
    ) -> Option<(f64, Vec<f64>)> {
        let equilibrium = 6 * self.bodies;
        let (mut ri, mut ci, mut vi) = self.triplets();
        let mut b = loads.to_vec();
        let mut row = equilibrium;
        // −w fₙ ≤ floor at every unilateral point, −τ ≤ 0.
        for (&c, &w) in self.unilateral.iter().zip(&self.unilateral_weight) {
            ri.push(row);
            ci.push(c);
            vi.push(-w);
            b.push(floor);
            row += 1;
        }
        ri.push(row);
        ci.push(0);
        vi.push(-1.0);
        b.push(0.0);
        row += 1;
        let mut cones = vec![
            SupportedConeT::ZeroConeT(equilibrium),
            SupportedConeT::NonnegativeConeT(row - equilibrium),
        ];
        // (μ N + τ, T₁, T₂) in the second-order cone, t first: s = b − A x.
        for columns in cones_of {
            ri.push(row);
            ci.push(0);
            vi.push(-1.0);
            for &(c, along) in columns {
                ri.push(row + along);
                ci.push(c);
                vi.push(if along == 0 { -mu } else { -1.0 });
            }
            b.extend([0.0, 0.0, 0.0]);
            row += 3;
            cones.push(SupportedConeT::SecondOrderConeT(3));
        }
        let columns = 1 + self.unknowns.len();
        let a = CscMatrix::new_from_triplets(row, columns, ri, ci, vi);
        let p = self.proximal();
        let mut q = vec![0.0; columns];
        q[0] = 1.0;
        let loose = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_iter(1000)
            .tol_gap_abs(1e-7)
            .tol_gap_rel(1e-7)
            .tol_feas(1e-7)
            .iterative_refinement_max_iter(50)
            .build()
            .ok()?;
        let solved = solve_clarabel(&p, &q, &a, &b, &cones)
            .or_else(|| solve_clarabel_with(&p, &q, &a, &b, &cones, loose))?;
        Some((solved.x[0].max(0.0), solved.x))
    }

    /// Per contact that touches (an interface with a unilateral point), the columns of its
    /// touching points' forces with their place along (n, t₁, t₂): the contacts whose
    /// resultants a friction cone bounds.
    fn cone_columns(&self) -> Vec<Vec<(usize, usize)>> {
        let mut per_interface: Vec<Vec<(usize, usize)>> = vec![Vec::new(); self.interfaces];
        let mut touches = vec![false; self.interfaces];
        for (j, u) in self.unknowns.iter().enumerate() {
            if u.point.is_some() {
                per_interface[u.interface].push((1 + j, u.key.along));
                touches[u.interface] |= u.unilateral;
            }
        }
        per_interface
            .into_iter()
            .zip(touches)
            .filter_map(|(columns, touches)| touches.then_some(columns))
            .collect()
    }

    /// The proximal term ½ε‖f‖² of the programs ([`PROXIMAL`]; column 0, s or τ, left out).
    fn proximal(&self) -> CscMatrix<f64> {
        let columns = 1 + self.unknowns.len();
        CscMatrix::new_from_triplets(
            columns,
            columns,
            (1..columns).collect(),
            (1..columns).collect(),
            vec![PROXIMAL; columns - 1],
        )
    }

    /// The contact of the distribution `x` whose resultant has the largest |F_t|/N among those
    /// whose normal force N exceeds `tolerance` (N; a contact that carries next to nothing
    /// would turn round-off into a ratio): its interface, N and |F_t|/N. The least-friction
    /// distribution loads many contacts to the same ratio, which the interior point leaves
    /// equal only to its accuracy: of the contacts within [`FRICTION_DIGITS`] of the largest,
    /// the one whose name (of `interfaces`) sorts first, whatever order the file lists them in.
    /// None when no contact carries more.
    fn most_demanding(
        &self,
        x: &[f64],
        tolerance: f64,
        interfaces: &[crr_kinematics::Interface],
    ) -> Option<(usize, f64, f64)> {
        let mut resultant = vec![[0.0; 3]; self.interfaces];
        let mut touches = vec![false; self.interfaces];
        for (j, u) in self.unknowns.iter().enumerate() {
            if u.point.is_some() {
                touches[u.interface] |= u.unilateral;
                resultant[u.interface][u.key.along] += x[1 + j];
            }
        }
        let loaded: Vec<(usize, f64, f64)> = resultant
            .iter()
            .enumerate()
            .filter(|&(i, r)| touches[i] && r[0] * self.weight > tolerance)
            .map(|(i, r)| (i, r[0] * self.weight, r[1].hypot(r[2]) / r[0]))
            .collect();
        let largest = loaded.iter().map(|l| l.2).fold(f64::NEG_INFINITY, f64::max);
        loaded
            .into_iter()
            .filter(|l| l.2 >= largest * (1.0 - FRICTION_DIGITS))
            .min_by(|a, b| interfaces[a.0].name.cmp(&interfaces[b.0].name))
    }

    /// A distribution in equilibrium with `loads`, the least-norm one (min ½‖f‖² subject to the
    /// equilibrium rows; column 0 unused, left 0).
    fn particular(&self, loads: &[f64]) -> Option<Vec<f64>> {
        let columns = 1 + self.unknowns.len();
        let (ri, ci, vi) = self.triplets();
        let a = CscMatrix::new_from_triplets(6 * self.bodies, columns, ri, ci, vi);
        let p = CscMatrix::new_from_triplets(
            columns,
            columns,
            (0..columns).collect(),
            (0..columns).collect(),
            vec![1.0; columns],
        );
        let cones = [SupportedConeT::ZeroConeT(6 * self.bodies)];
        solve_clarabel(&p, &vec![0.0; columns], &a, loads, &cones).map(|s| s.x)
    }

    /// The least-norm change δ with A δ = `imbalance` (column 0 left 0): δ = Aᵀy with
    /// (AAᵀ + εI) y = imbalance by a dense Cholesky factorisation up to
    /// [`DENSE_CORRECTION_ROWS`] rows (ε = 1e-12 of its largest diagonal entry, for rows that
    /// depend on each other: the caller checks the equilibrium of the result), by the sparse
    /// factorisation kept in `sparse` beyond ([`crate::least_norm`]; [`Self::particular`] if it
    /// fails).
    fn least_norm_change(&self, imbalance: &[f64], sparse: &mut LeastNorm) -> Option<Vec<f64>> {
        let rows = 6 * self.bodies;
        if rows > DENSE_CORRECTION_ROWS {
            return sparse
                .solve(rows, 1 + self.unknowns.len(), &self.entries, imbalance)
                .or_else(|| self.particular(imbalance));
        }
        // The columns of A as lists of (row, value), for AAᵀ = Σ over columns of a aᵀ.
        let columns = 1 + self.unknowns.len();
        let mut by_column: Vec<Vec<(usize, f64)>> = vec![Vec::new(); columns];
        for &(r, c, v) in &self.entries {
            if v != 0.0 {
                by_column[c].push((r, v));
            }
        }
        let mut aat = nalgebra::DMatrix::<f64>::zeros(rows, rows);
        for column in &by_column {
            for &(i, vi) in column {
                for &(j, vj) in column {
                    aat[(i, j)] += vi * vj;
                }
            }
        }
        let epsilon = 1e-12 * aat.diagonal().max();
        for i in 0..rows {
            aat[(i, i)] += epsilon;
        }
        // The engine's Cholesky (faer's blocked factorisation from 32 rows).
        crr_dynamics::linalg::cholesky_in_place(&mut aat).ok()?;
        let mut y = imbalance.to_vec();
        crr_dynamics::linalg::cholesky_solve(&aat, &mut y);
        Some(
            by_column
                .iter()
                .map(|column| column.iter().map(|&(r, v)| v * y[r]).sum())
                .collect(),
        )
    }

    /// The distribution `x` found at another state over the columns `keys`, put on this
    /// program's columns ([`Self::on_columns`]), plus the least-norm change that restores
    /// equilibrium with `loads`; None unless the result is in equilibrium to
    /// [`CARRIED_RESIDUAL`].
    fn carried(
        &self,
        (x, keys): &(Vec<f64>, Vec<UnknownKey>),
        loads: &[f64],
        sparse: &mut LeastNorm,
    ) -> Option<Vec<f64>> {
        let last = self.on_columns(x, keys);
        let mut imbalance = loads.to_vec();
        for &(row, c, v) in &self.entries {
            imbalance[row] -= v * last[c];
        }
        let change = self.least_norm_change(&imbalance, sparse)?;
        let carried: Vec<f64> = last.iter().zip(&change).map(|(x, d)| x + d).collect();
        (self.residual(&carried, loads) <= CARRIED_RESIDUAL).then_some(carried)
    }

    /// The least-norm distribution in equilibrium with `loads` ([`Self::least_norm_change`]
    /// from no forces); None unless it is in equilibrium to [`CARRIED_RESIDUAL`].
    fn least_norm(&self, loads: &[f64], sparse: &mut LeastNorm) -> Option<Vec<f64>> {
        let x = self.least_norm_change(loads, sparse)?;
        (self.residual(&x, loads) <= CARRIED_RESIDUAL).then_some(x)
    }

    /// The columns' keys, in order.
    fn keys(&self) -> Vec<UnknownKey> {
        self.unknowns.iter().map(|u| u.key.clone()).collect()
    }

    /// A distribution `x` over the columns `keys` (another state's) on this program's columns:
    /// the value of each column found there, 0 for the others (column 0, s, left 0).
    fn on_columns(&self, x: &[f64], keys: &[UnknownKey]) -> Vec<f64> {
        let column: std::collections::HashMap<&UnknownKey, usize> =
            keys.iter().enumerate().map(|(i, k)| (k, i)).collect();
        let mut out = vec![0.0; 1 + self.unknowns.len()];
        for (j, u) in self.unknowns.iter().enumerate() {
            if let Some(&i) = column.get(&u.key) {
                out[1 + j] = x[1 + i];
            }
        }
        out
    }

    /// The equilibrium rows' entries as (rows, columns, values).
    fn triplets(&self) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let rows = self.entries.iter().map(|e| e.0).collect();
        let columns = self.entries.iter().map(|e| e.1).collect();
        let values = self.entries.iter().map(|e| e.2).collect();
        (rows, columns, values)
    }

    /// Largest violation of the equilibrium rows by `x` (W).
    fn residual(&self, x: &[f64], loads: &[f64]) -> f64 {
        let mut r = loads.to_vec();
        for &(row, c, v) in &self.entries {
            r[row] -= v * x[c];
        }
        r.iter().fold(0.0, |m, e| m.max(e.abs()))
    }

    /// The smallest unilateral point force of `x` (W), each times its weight.
    fn smallest(&self, x: &[f64]) -> f64 {
        self.unilateral
            .iter()
            .zip(&self.unilateral_weight)
            .map(|(&c, &w)| w * x[c])
            .fold(f64::INFINITY, f64::min)
    }

    /// The program with each point's normal measured per edge: times its face's
    /// [`touching_points_per_edge`].
    fn per_edge(mut self) -> Self {
        self.unilateral_weight.clone_from(&self.edge_points);
        self
    }

    /// The answer for the distribution `x` (W) with the duals `z` of its program (None: a
    /// distribution not from the program, no limiting contact named).
    fn answer(&self, x: &[f64], z: Option<&[f64]>) -> MostCompressive {
        let mut normals = vec![0.0; self.interfaces];
        for &c in &self.unilateral {
            normals[self.unknowns[c - 1].interface] += x[c] * self.weight;
        }
        // The limiting contact: the point row with the largest dual price (ties: lowest interface).
        let mut limiting: Option<(usize, f64)> = None;
        if let Some(z) = z {
            for (r, &c) in self.unilateral.iter().enumerate() {
                let interface = self.unknowns[c - 1].interface;
                if limiting.is_none_or(|(i, best)| z[r] > best || (z[r] == best && interface < i)) {
                    limiting = Some((interface, z[r]));
                }
            }
        }
        let min_normal = match z {
            Some(_) => x[0],
            None => self.smallest(x).min(0.0),
        };
        MostCompressive {
            min_normal: min_normal * self.weight,
            limiting: limiting.map(|(i, _)| i),
            normals,
        }
    }
}

/// Iterative-refinement steps of `clarabel`'s KKT solves in the faces' programs (its default is
/// 10). Every answer these programs give is checked by its reader (a certificate's equilibrium to
/// [`CARRIED_RESIDUAL`] and its margins, the monitor's tolerance of 5e-4 W, the impulses'
/// threshold), and the interior point's own stopping test is on the unregularised residuals: one
/// step gives the same histories as ten on every bundled model, the 82 runs of the walls' sweep
/// that end (two stall with either) and the temple at 0.8 of its record, whose 6 s it runs about
/// a tenth faster (docs/performance.md).
const REFINEMENT_STEPS: u32 = 1;

/// `clarabel` on the problem min ½xᵀPx + qᵀx subject to Ax + s = b, s ∈ cones; None unless it
/// solves.
fn solve_clarabel(
    p: &CscMatrix<f64>,
    q: &[f64],
    a: &CscMatrix<f64>,
    b: &[f64],
    cones: &[SupportedConeT<f64>],
) -> Option<clarabel::solver::DefaultSolution<f64>> {
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(200)
        .iterative_refinement_max_iter(REFINEMENT_STEPS)
        .build()
        .ok()?;
    solve_clarabel_with(p, q, a, b, cones, settings)
}

/// [`solve_clarabel`] with the given settings.
fn solve_clarabel_with(
    p: &CscMatrix<f64>,
    q: &[f64],
    a: &CscMatrix<f64>,
    b: &[f64],
    cones: &[SupportedConeT<f64>],
    settings: clarabel::solver::DefaultSettings<f64>,
) -> Option<clarabel::solver::DefaultSolution<f64>> {
    let mut solver = DefaultSolver::new(p, q, a, b, cones, settings).ok()?;
    solver.solve();
    matches!(
        solver.solution.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    )
    .then(|| solver.solution)
}

/// The monitor's program from sample to sample: the last distribution found answers again,
/// carried to the new state, while every point of it keeps more than the floor (a certificate:
/// any distribution in equilibrium with the loads whose points all carry more than the floor
/// shows that s* does too; its equilibrium residual is checked to 1e-9 W).
///
/// - **At rest** (every slot seated, q and the pivots the same) the matrix does not change and
///   the loads are −mᵦ g_eff, linear in g_eff: the last distribution plus three distributions
///   for a unit effective gravity along x, y and z, times its change, is in equilibrium with the
///   new loads, with no solve at all. A structure at rest under a record is sampled hundreds of
///   times with the same matrix.
/// - **In motion** the last distribution plus the least-norm change that restores the
///   equilibrium of the new state (a dense factorisation of AAᵀ up to 240 rows, the sparse
///   solver beyond), when the touching points are the same.
///
/// Otherwise the program is solved.
#[derive(Clone, Debug, Default)]
pub struct RestFaces {
    entry: Option<RestEntry>,
    /// The last distribution found (W), whatever the state: in motion it is carried by the
    /// least-norm correction that restores equilibrium at the new state.
    last: Option<(Vec<f64>, Vec<UnknownKey>)>,
    /// The factorisation of the carried distributions' least-norm changes.
    sparse: LeastNorm,
}

#[derive(Clone, Debug)]
struct RestEntry {
    seated: Vec<usize>,
    sides: Vec<Side>,
    q: nalgebra::DVector<f64>,
    program: FaceProgram,
    unit: [Vec<f64>; 3],
    g_eff: Vector3<f64>,
    x: Vec<f64>,
}

/// Most equilibrium rows (six per body) for which a carried distribution is corrected by a dense
/// factorisation (about 0.1 ms at 240 rows); larger structures use the sparse solver.
const DENSE_CORRECTION_ROWS: usize = 240;

/// Equilibrium residual (W) under which a carried distribution counts as in equilibrium.
const CARRIED_RESIDUAL: f64 = 1e-9;

impl RestFaces {
    /// [`most_compressive`] at a state with effective gravity `g_eff` (m/s²), position `q` and
    /// rates `qdot`: the last distribution carried to the new state answers when its smallest
    /// point force, measured per edge, is at least `floor` (N; then `limiting` is None and
    /// `min_normal` is that force capped at 0); otherwise the program is solved with s ≤ `cap`
    /// (N), and its answer kept for the next samples.
    #[allow(clippy::too_many_arguments)]
    pub fn most_compressive(
        &mut self,
        model: &Model,
        dynamics: &Dynamics,
        work: &ForceWork,
        q: &nalgebra::DVector<f64>,
        qdot: &nalgebra::DVector<f64>,
        g_eff: Vector3<f64>,
        (floor, cap): (f64, f64),
    ) -> Option<MostCompressive> {
        let at_rest = qdot.iter().all(|&v| v == 0.0) && dynamics.seated.len() == model.slot_count;
        let same = self.entry.as_ref().is_some_and(|e| {
            e.seated == dynamics.seated && e.sides == dynamics.pivots.sides && &e.q == q
        });
        if !at_rest || !same {
            self.entry = None;
        }
        if let Some(entry) = self.entry.as_mut() {
            let program = &entry.program;
            let loads = program.loads(model, dynamics, work)?;
            let change = g_eff - entry.g_eff;
            let carried: Vec<f64> = (0..entry.x.len())
                .map(|i| entry.x[i] + (0..3).map(|k| change[k] * entry.unit[k][i]).sum::<f64>())
                .collect();
            if program.residual(&carried, &loads) <= CARRIED_RESIDUAL
                && program.smallest(&carried) * program.weight >= floor
            {
                let answer = program.answer(&carried, None);
                self.last = Some((carried.clone(), program.keys()));
                entry.x = carried;
                entry.g_eff = g_eff;
                return Some(answer);
            }
        }
        let program = match self.entry.take() {
            Some(entry) => entry.program,
            None => FaceProgram::build(model, dynamics).per_edge(),
        };
        let loads = program.loads(model, dynamics, work)?;
        // In motion: the last distribution plus the least-norm change that restores the
        // equilibrium of the new state (one equality-constrained least-squares solve, cheaper
        // than the program), accepted like a carried one at rest.
        if let Some(carried) = self
            .last
            .as_ref()
            .and_then(|last| program.carried(last, &loads, &mut self.sparse))
            .filter(|carried| program.smallest(carried) * program.weight >= floor)
        {
            let answer = program.answer(&carried, None);
            self.last = Some((carried, program.keys()));
            return Some(answer);
        }
        // A positive cap can leave the interior point without convergence where the optimal
        // distributions form a wide face (the 3D arch once in its 20 s): the program with s ≤ 0
        // is solved then.
        let (x, z) = program
            .solve(&loads, cap / program.weight)
            .or_else(|| program.solve(&loads, 0.0))?;
        let answer = program.answer(&x, Some(&z));
        self.last = Some((x.clone(), program.keys()));
        if at_rest {
            // A unit effective gravity along each axis at rest: −mᵦ eₖ on every body.
            let total = model.total_mass();
            let unit_load = |k: usize| {
                let mut b = vec![0.0; 6 * program.bodies];
                for (n, body) in model.bodies.iter().enumerate() {
                    b[6 * n + k] = -body.mass / total / model.gravity;
                }
                b
            };
            if let (Some(ux), Some(uy), Some(uz)) = (
                program.particular(&unit_load(0)),
                program.particular(&unit_load(1)),
                program.particular(&unit_load(2)),
            ) {
                self.entry = Some(RestEntry {
                    seated: dynamics.seated.clone(),
                    sides: dynamics.pivots.sides.clone(),
                    q: q.clone(),
                    program,
                    unit: [ux, uy, uz],
                    g_eff,
                    x,
                });
            }
        }
        Some(answer)
    }
}

/// A certificate that a motion needs no contact to let go: a distribution of the contact forces
/// on the touching points of the state in equilibrium with that motion, every unilateral point
/// pressing by at least a margin. Where one exists the motion satisfies the optimality conditions
/// of Gauss' principle over the unilateral contacts (its forces do non-negative power on every
/// motion the contacts allow), so it is the contact program's minimum: nothing opens and no face
/// lifts off. The uplift test asks it in motion before it solves that program
/// (`simulation::seating`), which is hyperstatic on loops: the locked solve's own reactions
/// are one split among many and certify almost nothing there.
///
/// The last distribution found is carried to the next state by the least-norm change that
/// restores equilibrium ([`RestFaces`]), over the columns the two states share (a face that
/// changed its pivot keeps its other points' forces), and answers when its points all keep the
/// margin ([`Self::carries`]). The linear program, s ≤ [`PRESSING_CAP`] so that the distribution
/// it keeps has room to be carried, is solved where the caller asks ([`Self::refresh`]): the
/// simulation asks it only where the contact program has found that nothing opens, since it
/// costs about twice that program and finds no certificate where something opens.
#[derive(Clone, Debug, Default)]
pub struct PressingCertificate {
    /// The last distribution found (W, column 0 unused) and its columns' keys.
    last: Option<(Vec<f64>, Vec<UnknownKey>)>,
    /// The program and loads of the last state [`Self::carries`] did not certify, for
    /// [`Self::refresh`].
    pending: Option<(FaceProgram, Vec<f64>)>,
    /// The distribution of the last program solved by [`Self::refresh_paced`] has certified no
    /// state yet.
    unpaid: bool,
    /// Refreshes [`Self::refresh_paced`] skips before it solves again, and the length of the
    /// last such pause.
    skip: u32,
    pause: u32,
    sparse: LeastNorm,
}

/// The longest pause of [`PressingCertificate::refresh_paced`] (refreshes skipped).
pub const LONGEST_PAUSE: u32 = 32;

/// The margin (in units of the structure's weight W) by which every unilateral point of a
/// certifying distribution presses: far above the equilibrium residual accepted (1e-9 W) and the
/// program's proximal term (about 1e-7 W), so that the certificate holds for the exact loads;
/// and wide enough that the contact program still decides near a threshold, as it did before the
/// certificate. With 1e-6 W the 6 × 6 wall of `examples/wall_pulse.rs` under 1.5 λ g was
/// certified at 0.33555 s (least force 1.07e-6 W) where the program lifts two faces off at rates
/// of 1e-6 g/size, its own tolerance 1e-7: the two formulations part by that much at the
/// threshold, and the run's history moved by 1e-4 s.
pub const PRESSING_MARGIN: f64 = 1e-4;

/// The cap (W) on the least point force the certificate's program seeks: a distribution that
/// presses everywhere by this much is carried over many states before it needs the program again.
pub const PRESSING_CAP: f64 = 1e-2;

impl PressingCertificate {
    /// Whether the motion solved in `dynamics` (its kinematics, seated slots and pivots), with
    /// the bodies' loads in `work` ([`crate::monitor::body_loads_into`] at that state), has a
    /// distribution whose unilateral points all press by at least [`PRESSING_MARGIN`] W: the
    /// last one carried ([`Self::carries`]), or the program's ([`Self::refresh`]). None when the
    /// loads are not known or the program does not solve.
    pub fn holds(&mut self, model: &Model, dynamics: &Dynamics, work: &ForceWork) -> Option<bool> {
        if self.carries(model, dynamics, work)? {
            return Some(true);
        }
        self.refresh()
    }

    /// Whether the last distribution found, carried to this state by the least-norm change that
    /// restores equilibrium, presses by the margin at every unilateral point (then it is kept).
    /// No linear program: false where nothing is kept yet or the carried one does not press.
    /// None when the loads are not known.
    pub fn carries(
        &mut self,
        model: &Model,
        dynamics: &Dynamics,
        work: &ForceWork,
    ) -> Option<bool> {
        self.pending = None;
        let program = FaceProgram::build_setting(model, dynamics, &[], FaceAxes::Leaving);
        let loads = program.loads(model, dynamics, work)?;
        // The last distribution on this state's columns (those it shares with the last state's,
        // the others 0): any start serves, what certifies is the result's equilibrium (checked
        // in `carried`) and signs (here).
        let carried = self
            .last
            .as_ref()
            .and_then(|last| program.carried(last, &loads, &mut self.sparse))
            .filter(|carried| program.smallest(carried) >= PRESSING_MARGIN);
        let holds = carried.is_some();
        match carried {
            Some(carried) => {
                self.last = Some((carried, program.keys()));
                // A distribution that pays ends the pause of `refresh_paced`.
                self.unpaid = false;
                self.pause = 0;
                self.skip = 0;
            }
            None => self.pending = Some((program, loads)),
        }
        Some(holds)
    }

    /// The program's distribution at the state [`Self::carries`] last did not certify (s ≤
    /// [`PRESSING_CAP`], so that it has room to be carried), kept for the next states, and
    /// whether it presses by the margin everywhere. None when there is no such state or the
    /// program does not solve.
    pub fn refresh(&mut self) -> Option<bool> {
        let (program, loads) = self.pending.take()?;
        let (x, _) = program
            .solve(&loads, PRESSING_CAP)
            .or_else(|| program.solve(&loads, 0.0))?;
        let holds = program.residual(&x, &loads) <= CARRIED_RESIDUAL
            && program.smallest(&x) >= PRESSING_MARGIN;
        self.last = Some((x, program.keys()));
        Some(holds)
    }

    /// [`Self::refresh`] paced by what the distributions it finds are worth: where the last one
    /// it solved certified no state before the next refresh is asked (the motion changes faster
    /// than a distribution carries, as on the bundled temple's rattling bay), the next 1, 2, 4 …
    /// [`LONGEST_PAUSE`] refreshes are skipped, and a distribution that certifies a state ends
    /// the pause. A skipped refresh leaves the decisions to the contact program until a
    /// distribution is found again; the certificate stays sound whatever it carries (each state
    /// checks its own equilibrium and margins), but which distribution it carries decides where
    /// it answers instead of the program, and near a threshold the two part by the margin.
    pub fn refresh_paced(&mut self) {
        if self.unpaid {
            self.pause = (2 * self.pause).clamp(1, LONGEST_PAUSE);
            self.skip = self.pause;
            self.unpaid = false;
        }
        if self.skip > 0 {
            self.skip -= 1;
            self.pending = None;
            return;
        }
        if self.refresh().is_some() {
            self.unpaid = true;
        }
    }
}

/// Whether the touching points of interface `kind`, with its slots seated as `seated`, leave
/// along the child's face normal rather than the parent's: a rocking base turned on its first
/// tilt (about the parent's e₁, through the edge it rocks on) with its second seated. Opening
/// the second tilt turns the child about an end of that edge, about R(e₁, θ₁)e₂, which lies in
/// the child's face plane: the other end leaves along the child's normal, tilted by θ₁ from the
/// parent's, and so does the lift (the contact program's τ = σ w × (P′ − P)). Posed on the
/// child's axes, the points' tangential forces do no work on any opening the program offers
/// (on the parent's they would, θ₁ times their size). Every other face leaves along the
/// parent's normal: a hinge and a base with its first tilt seated turn about axes in the
/// parent's face plane, and a base on one corner lifts along the parent's normal.
fn leaves_along_child_normal(kind: &InterfaceKind, seated: &[bool]) -> bool {
    matches!(kind, InterfaceKind::RockingBase { .. }) && seated == [false, true]
}

/// The axis of the couple a rocking base on one corner transmits: the one its two tilts leave no
/// rotation about, w₁ × w₂ of the tilts' world axes (the parent's e₁ turned with the parent, e₂
/// turned with the child: the face's normal only while the first tilt is 0).
fn torsion_axis(model: &Model, kin: &crr_kinematics::Data, index: usize) -> Vector3<f64> {
    let iface = &model.interfaces[index];
    let (w1, w2) = match iface.role {
        Role::Tree { first_coord } => (kin.axis[first_coord], kin.axis[first_coord + 1]),
        Role::Closure { .. } => {
            let rot = |k: Option<usize>| k.map_or_else(Matrix3::identity, |k| kin.rot_ops[k]);
            let child = rot(Some(model.body_coord[iface.child]));
            (
                rot(model.frame_of(iface.parent)) * iface.kind.axis(0),
                child * iface.kind.axis(1),
            )
        }
    };
    w1.cross(&w2).normalize()
}

/// Appends to `unknowns` the columns of interface `index` at the state in `dynamics`: a force
/// along each of the face's axes at every touching point (a normal one `unilateral` unless the
/// face is a pin or its slots are `set_by_law`), then its bilateral couples. `is_seated` marks
/// the seated slots (and those set by law), every slot of the model.
fn interface_columns(
    model: &Model,
    dynamics: &Dynamics,
    index: usize,
    (is_seated, set_by_law): (&[bool], &[usize]),
    posed_on: FaceAxes,
    unknowns: &mut Vec<Unknown>,
) {
    let iface = &model.interfaces[index];
    let face = ContactFace::of_interface(model, index);
    let frame = model.frame_of(iface.parent);
    let rot = if posed_on == FaceAxes::Leaving
        && leaves_along_child_normal(&iface.kind, &is_seated[iface.slots.clone()])
    {
        dynamics.kin.rot_ops[model.body_coord[iface.child]]
    } else {
        frame.map_or_else(Matrix3::identity, |k| dynamics.kin.rot_ops[k])
    };
    let axes = [
        rot * face.normal,
        rot * face.tangents[0],
        rot * face.tangents[1],
    ];
    let by_law = iface.slots.clone().any(|k| set_by_law.contains(&k));
    let points = touching_points(
        &iface.kind,
        &is_seated[iface.slots.clone()],
        dynamics.pivots.of_interface(model, index),
    );
    let twist = matches!(iface.kind, InterfaceKind::RockingBase { twist: true, .. });
    for (p, rest) in points.iter().enumerate() {
        let point = frame_point(&dynamics.kin, frame, rest);
        let along = if twist && p > 0 {
            &axes[..1]
        } else {
            &axes[..]
        };
        for (k, &direction) in along.iter().enumerate() {
            unknowns.push(Unknown {
                interface: index,
                unilateral: k == 0 && !face.pin && !by_law,
                point: Some(point),
                direction,
                key: UnknownKey {
                    interface: index,
                    rest: Some([rest.x.to_bits(), rest.y.to_bits(), rest.z.to_bits()]),
                    along: k,
                },
            });
        }
    }
    let mut couples: Vec<Vector3<f64>> = face.bilateral_couples.iter().map(|c| rot * c).collect();
    if !twist && points.len() == 1 && matches!(iface.kind, InterfaceKind::RockingBase { .. }) {
        couples.push(torsion_axis(model, &dynamics.kin, index));
    }
    unknowns.extend(
        couples
            .into_iter()
            .enumerate()
            .map(|(k, direction)| Unknown {
                interface: index,
                unilateral: false,
                point: None,
                direction,
                key: UnknownKey {
                    interface: index,
                    rest: None,
                    along: k,
                },
            }),
    );
}

/// How many touching points of a face of `kind` touching on `points` unilateral points share an
/// edge of it: a hinge's pivot line is a whole edge (1); a rocking base touches on one corner
/// (1), on an edge's two corners (2) or on its four corners, two on each edge (2). An impulse is
/// measured per edge, a point's times this count: the impulse of an edge whose touching points
/// each carry that point's. A face is then judged the same whether it is written as lines or as
/// corners: a planar hinge's pivot line carries an edge's whole impulse, which a 3D base's two
/// corners on that edge share, and measured point by point the 3D form of a stack pulled half as
/// hard as its planar twin at the same impact (an independent review found a 3D stack held
/// through a 17.7 N s pull on one edge that the planar stack released: its corners took 8.9 N s
/// each, under the 10 N s tolerance). The planar measure is the point's own. A base rocking on
/// an edge (two corners) weighs each corner by 2: the edge's share as above, while a moment
/// across that edge (out of the rocking plane) loads its two corners apart, and each is then
/// judged at twice its own force, more strictly than the seat's edge split of the
/// tree-coordinate family judges it (that family asks the program only where its own split
/// pulls beyond the tolerance).
pub fn touching_points_per_edge(kind: &InterfaceKind, points: usize) -> f64 {
    match kind {
        InterfaceKind::Hinge { .. } => 1.0,
        InterfaceKind::RockingBase { .. } => points.min(2) as f64,
    }
}

/// The points (world at rest) on which interface `kind` touches with its slots seated as
/// `seated` and on the pivot sides `sides`: the pivots of every side choice that keeps the free
/// slots' current side (a seated slot offers both), each once.
fn touching_points(kind: &InterfaceKind, seated: &[bool], sides: &[Side]) -> Vec<Vector3<f64>> {
    let choices = |k: usize| {
        if seated[k] {
            vec![Side::Positive, Side::Negative]
        } else {
            vec![sides[k]]
        }
    };
    let mut points: Vec<Vector3<f64>> = Vec::new();
    let mut add = |p: Vector3<f64>| {
        if !points.contains(&p) {
            points.push(p);
        }
    };
    match kind {
        InterfaceKind::Hinge { .. } => {
            for s in choices(0) {
                add(kind.pivot(&[s]));
            }
        }
        InterfaceKind::RockingBase { .. } => {
            // The current pivot first (a twisting seat's tangential forces act there).
            add(kind.pivot(sides));
            for s0 in choices(0) {
                for s1 in choices(1) {
                    add(kind.pivot(&[s0, s1]));
                }
            }
        }
    }
    points
}

fn top(v: &nalgebra::Vector6<f64>) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}
