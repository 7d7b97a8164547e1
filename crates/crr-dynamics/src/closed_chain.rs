//! Closed kinematic chains: mobility (DOF(2)), projection onto Φ = 0 and Φ_q q̇ = 0, consistent
//! initial conditions, and coordinate partitioning for the reduced form.

use std::collections::BTreeMap;

use nalgebra::{DMatrix, DVector};

use crr_kinematics::{
    ActivePivots, Data, Model, Side, closure_angles, constraint_jacobian, constraint_residual,
    forward_kinematics,
};

use crate::eom::{
    DynamicsError, SelectedRowsWork, SparseRows, constraint_row_scale, slot_row,
    solve_selected_rows,
};
use crate::linalg::{JacobiSvd, RANK_TOLERANCE, pinv_solve_in, pivot_columns, rank};

/// Convergence threshold of the Newton projections, relative to the model size for point rows.
pub const CLOSURE_TOLERANCE: f64 = 1e-13;
const NEWTON_ITERATIONS: usize = 30;

/// Mobility of a structure at a configuration: DOF(2) = DOF(1) − rank Φ_q of the loop closures,
/// DOF(3) with the user/symmetry constraints too.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Mobility {
    /// DOF(1): tree coordinates.
    pub dof1: usize,
    /// Number of loop closures.
    pub closures: usize,
    /// Rows of Φ.
    pub constraint_rows: usize,
    /// Numerical rank of Φ_q (independent constraints).
    pub rank: usize,
    /// Redundant rows: rows − rank.
    pub redundant: usize,
    /// DOF(2) = DOF(1) − rank.
    pub dof2: usize,
    /// DOF(2) = 0: the mechanism is locked.
    pub locked: bool,
    /// User/symmetry constraints φₐ = ±φ_b.
    pub symmetries: usize,
    /// DOF(3) = DOF(1) − rank of Φ_q with the symmetry rows (equals DOF(2) without symmetries).
    pub dof3: usize,
    /// DOF(2) at the model's precision: DOF(1) minus the rank of Φ_q with its singular values
    /// at or below [`PRECISION_RANK_TOLERANCE`] of the largest counted as zero. Larger than
    /// [`Self::dof2`] where the loops close only to the round-off of the geometry (a wall in
    /// running bond turned 30° and written with six decimals: DOF(2) = 0 as written, 2 here, as
    /// written exactly). The dynamics follows the loops as written.
    pub dof2_at_precision: usize,
}

/// The share of Φ_q's largest singular value at or below which a singular value counts as zero
/// at the model's precision ([`Mobility::dof2_at_precision`]): ten times
/// [`crr_kinematics::GEOMETRY_TOLERANCE`]. Corners known to 1e-6 of the model's size move each
/// entry of the scaled Φ_q (lever arms over the size) by about as much; the loops of a wall
/// of two courses in running bond written with six decimals leave singular values of 1.6e-7
/// and 2.9e-8 beside 0.18 and more (exactly: 1e-13 and below).
pub const PRECISION_RANK_TOLERANCE: f64 = 10.0 * crr_kinematics::GEOMETRY_TOLERANCE;

/// Row-scaled Φ(q) and Φ_q at q (fills `kin`).
fn scaled(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    pivots: &ActivePivots,
) -> (DVector<f64>, DMatrix<f64>) {
    let s = constraint_row_scale(model);
    forward_kinematics(model, kin, q, pivots);
    constraint_residual(model, kin, pivots, q);
    constraint_jacobian(model, kin, pivots);
    let phi = kin.phi.component_mul(&s);
    let jac = DMatrix::from_fn(model.constraint_rows, model.dof(), |i, j| {
        s[i] * kin.phi_q[(i, j)]
    });
    (phi, jac)
}

/// [`scaled`] with one more row per held closure slot (slot ≥ DOF(1), target angle) in `held`:
/// ψ − target as the residual and the slot's rate row a (ψ̇ = aᵀq̇) as the Jacobian. A seated
/// closing joint keeps its angle only through these rows: without them a projection's
/// minimum-norm correction turns it like any free joint (on the voussoir arch of 9 under a pulse,
/// a joint "seated" 1e-6 rad past its seat, which a later release opened on the wrong side,
/// moving the bodies by ψ·|P⁺ − P⁻|).
fn scaled_holding(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    pivots: &ActivePivots,
    held: &[(usize, f64)],
) -> (DVector<f64>, DMatrix<f64>) {
    let (phi, jac) = scaled(model, kin, q, pivots);
    if held.is_empty() {
        return (phi, jac);
    }
    let (n, m) = (model.dof(), phi.len());
    let mut angles = vec![0.0; model.slot_count - n];
    closure_angles(model, kin, &mut angles);
    let mut phi = phi.resize_vertically(m + held.len(), 0.0);
    let mut jac = jac.resize_vertically(m + held.len(), 0.0);
    let mut row = DVector::zeros(n);
    for (i, &(s, target)) in held.iter().enumerate() {
        debug_assert!(s >= n, "held rows are closure slots");
        phi[m + i] = angles[s - n] - target;
        slot_row(model, kin, s, &mut row);
        jac.row_mut(m + i).tr_copy_from(&row);
    }
    (phi, jac)
}

/// The closure slots `held` (≥ DOF(1)) with their angles at q: the targets of
/// [`project_positions_holding`] that keep them where they are at a closed q (on an open one the
/// angle between the two frames also takes the loop's gap).
pub fn held_at(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    pivots: &ActivePivots,
    held: &[usize],
) -> Vec<(usize, f64)> {
    if held.is_empty() {
        return Vec::new();
    }
    let n = model.dof();
    forward_kinematics(model, kin, q, pivots);
    let mut angles = vec![0.0; model.slot_count - n];
    closure_angles(model, kin, &mut angles);
    held.iter().map(|&s| (s, angles[s - n])).collect()
}

/// DOF(1), closures, rank of Φ_q and DOF(2) at configuration q with the given pivots.
pub fn mobility(model: &Model, q: &DVector<f64>, pivots: &ActivePivots) -> Mobility {
    let mut kin = Data::new(model);
    let (_, jac) = scaled(model, &mut kin, q, pivots);
    let closures = jac.rows(0, model.closure_rows).into_owned();
    let (r, r_at_precision) = if closures.nrows() == 0 || closures.ncols() == 0 {
        (0, 0)
    } else {
        let svd = JacobiSvd::thin(&closures);
        let coarse = svd.tolerance_relative(PRECISION_RANK_TOLERANCE);
        let at_precision = svd.singular_values.iter().filter(|s| **s > coarse).count();
        (svd.rank(), at_precision)
    };
    let r3 = rank(&jac);
    let dof2 = model.dof() - r;
    Mobility {
        dof1: model.dof(),
        closures: model.closures.len(),
        constraint_rows: model.closure_rows,
        rank: r,
        redundant: model.closure_rows - r,
        dof2,
        locked: dof2 == 0,
        symmetries: model.symmetries.len(),
        dof3: model.dof() - r3,
        dof2_at_precision: model.dof() - r_at_precision,
    }
}

/// DOF(2) after a finite displacement along the mechanism: see [`mobility_after_step`].
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FiniteMobility {
    /// Largest |qₖ| of the displacement before projection (rad).
    pub step: f64,
    /// The closed configuration reached (rad), in the order of q.
    pub q: Vec<f64>,
    /// DOF(2) there.
    pub dof2: usize,
    /// Scaled closure residual left by the projection.
    pub residual: f64,
}

/// Mobility after a finite step: from rest, moves by `step` (rad, largest component) along a
/// generic combination of the first-order mechanism directions (the null space of Φ_q at rest),
/// projects back onto Φ = 0 with the pivots following the signs, and computes DOF(2) there.
///
/// DOF(2) at rest counts the first-order motions. Where the closures allow fewer finite motions
/// (a rocking-base loop whose tilts are applied in an order the loop cannot follow, or a loop
/// that only flexes infinitesimally), DOF(2) drops after the step: the rest value overstates the
/// mechanism, and the multiplier solve near rest is ill-conditioned. A locked structure
/// (DOF(2) = 0 at rest) returns at once.
pub fn mobility_after_step(model: &Model, step: f64) -> Result<FiniteMobility, DynamicsError> {
    // Closures only: symmetry rows would pull the step back towards rest.
    let mut closures_only = model.clone();
    closures_only.symmetries.clear();
    closures_only.constraint_rows = closures_only.closure_rows;
    let model = &closures_only;
    let n = model.dof();
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    let mut kin = Data::new(model);
    let zero = DVector::zeros(n);
    let (_, jac) = scaled(model, &mut kin, &zero, &pivots);
    let closure_rows = jac.rows(0, model.closure_rows).into_owned();
    let null = if model.closure_rows == 0 {
        DMatrix::identity(n, n)
    } else {
        crate::linalg::null_space(&closure_rows)
    };
    if null.ncols() == 0 {
        return Ok(FiniteMobility {
            step: 0.0,
            q: vec![0.0; n],
            dof2: 0,
            residual: 0.0,
        });
    }
    // Weights 1, 1/φ, 1/φ², … (φ the golden ratio): no two directions cancel or coincide.
    let golden = 0.5 * (1.0 + 5f64.sqrt());
    let mut d = DVector::zeros(n);
    for j in 0..null.ncols() {
        d.axpy(golden.powi(-(j as i32)), &null.column(j), 1.0);
    }
    let scale = step / d.amax().max(f64::EPSILON);
    let mut q = d * scale;
    let mut residual = 0.0;
    // The pivots follow the signs of the configuration; re-project until they stop changing.
    for _ in 0..4 {
        let before = pivots.sides.clone();
        follow_signs(model, &mut kin, &q, &mut pivots);
        residual = project_positions(model, &mut kin, &pivots, &mut q, None)?;
        follow_signs(model, &mut kin, &q, &mut pivots);
        if pivots.sides == before {
            break;
        }
    }
    if q.amax() < 0.1 * step {
        return Err(DynamicsError::Closure(format!(
            "the step of {step} rad along the first-order mechanism projected back to within \
             {:.1e} rad of rest: no finite motion found there",
            q.amax()
        )));
    }
    let dof2 = mobility(model, &q, &pivots).dof2;
    Ok(FiniteMobility {
        step,
        q: q.as_slice().to_vec(),
        dof2,
        residual,
    })
}

/// Newton projection of q onto Φ(q) = 0, changing only the coordinates in `free` (all when None)
/// by minimum-norm steps. Returns the final scaled residual norm.
pub fn project_positions(
    model: &Model,
    kin: &mut Data,
    pivots: &ActivePivots,
    q: &mut DVector<f64>,
    free: Option<&[usize]>,
) -> Result<f64, DynamicsError> {
    project_positions_holding(model, kin, pivots, q, free, &[])
}

/// [`project_positions`] that also holds the closure slots of `held` (seated closing joints,
/// slots ≥ DOF(1)) at their target angles (0 for a joint set on its seat; [`held_at`] a closed
/// state to keep them where they are): they take no share of the correction.
pub fn project_positions_holding(
    model: &Model,
    kin: &mut Data,
    pivots: &ActivePivots,
    q: &mut DVector<f64>,
    free: Option<&[usize]>,
    held: &[(usize, f64)],
) -> Result<f64, DynamicsError> {
    let cols = free_columns(model, free);
    let mut last = f64::INFINITY;
    for _ in 0..NEWTON_ITERATIONS {
        let (phi, jac) = scaled_holding(model, kin, q, pivots, held);
        let norm = phi.amax();
        if norm <= CLOSURE_TOLERANCE {
            return Ok(norm);
        }
        if !norm.is_finite() {
            return Err(DynamicsError::Closure(
                "the closure residual is not finite".into(),
            ));
        }
        if norm > 0.5 * last && last < 1e-9 {
            // Converged as far as round-off allows.
            return Ok(norm);
        }
        last = norm;
        min_norm_step(&jac, &phi, &cols, q);
    }
    let (phi, _) = scaled_holding(model, kin, q, pivots, held);
    let norm = phi.amax();
    if norm <= 1e-8 {
        Ok(norm)
    } else {
        Err(DynamicsError::Closure(format!(
            "Newton did not bring the closure residual below tolerance (still {norm:.3e} relative)"
        )))
    }
}

/// One Newton step on Φ(q) = 0 changing only the coordinates `cols`: q_cols −= (Φ_q,cols)⁺ Φ.
fn min_norm_step(jac: &DMatrix<f64>, phi: &DVector<f64>, cols: &[usize], q: &mut DVector<f64>) {
    // The rank threshold is that of the whole Jacobian (see `pinv_solve_in`).
    let (dx, _) = pinv_solve_in(&jac.select_columns(cols.iter()), phi, jac.norm());
    for (j, &c) in cols.iter().enumerate() {
        q[c] -= dx[j];
    }
}

/// Projects q̇ onto Φ_q q̇ = 0 (orthogonally, changing only `free` coordinates when given), at the q
/// last passed to the kinematics in `kin`. Returns the residual before projection.
pub fn project_velocities(
    model: &Model,
    kin: &mut Data,
    pivots: &ActivePivots,
    q: &DVector<f64>,
    qdot: &mut DVector<f64>,
    free: Option<&[usize]>,
) -> f64 {
    project_velocities_with(model, kin, pivots, q, qdot, free, None)
}

/// [`project_velocities`] that also holds the rates of the closure slots in `held` (seated
/// closing joints, slots ≥ DOF(1)) at 0: the minimum-norm correction over `free` of
/// [Φ_q; a_held] q̇ = 0 (one truncated pseudo-inverse solve, as a Newton step of
/// [`project_positions`]). Returns the residual |[Φ_q; a_held] q̇| before the projection and
/// the one left after it (what lies outside the range of the free columns).
pub fn project_velocities_holding(
    model: &Model,
    kin: &mut Data,
    pivots: &ActivePivots,
    q: &DVector<f64>,
    qdot: &mut DVector<f64>,
    free: Option<&[usize]>,
    held: &[usize],
) -> (f64, f64) {
    let held: Vec<(usize, f64)> = held.iter().map(|&s| (s, 0.0)).collect();
    let (_, jac) = scaled_holding(model, kin, q, pivots, &held);
    let cols = free_columns(model, free);
    let residual = &jac * &*qdot;
    min_norm_step(&jac, &residual, &cols, qdot);
    (residual.amax(), (&jac * &*qdot).amax())
}

/// The coordinates a projection may change: `free`, or every tree coordinate.
fn free_columns(model: &Model, free: Option<&[usize]>) -> Vec<usize> {
    free.map_or_else(|| (0..model.dof()).collect(), <[usize]>::to_vec)
}

/// Independent rows of the row-scaled Φ_q kept between velocity projections
/// ([`project_velocities_with`]): the integration projects after every step with the same
/// chain, and the rows that were independent at the last step almost always still are.
#[derive(Clone, Debug, Default)]
pub struct VelocityProjection {
    /// The columns (coordinates changed) and the rows selected for them.
    selection: Option<(Vec<usize>, Vec<usize>)>,
    work: SelectedRowsWork,
    /// Projections that ran the SVD (no selection for these columns, or its check failed).
    pub decompositions: usize,
    /// Projections solved on the selected rows.
    pub reused: usize,
}

/// [`project_velocities`] reusing independent rows from `cache`: the minimum-norm correction
/// δq̇ = −Φ_qᵀ(Φ_q Φ_qᵀ)⁺ Φ_q q̇ is, since Φ_q q̇ lies in the range of Φ_q, exactly
/// −Φ_Sᵀ(Φ_S Φ_Sᵀ)⁻¹ Φ_S q̇ on any independent rows S spanning the others: one Cholesky factor of
/// the (sparse) Gram matrix of S instead of a Jacobi SVD of Φ_q. The rows are kept only while
/// the SVD would make the same rank decision (same check and threshold, RANK_TOLERANCE·‖Φ_q‖, as
/// the equations of motion's selected rows); otherwise the SVD solves and selects them again.
pub fn project_velocities_with(
    model: &Model,
    kin: &mut Data,
    pivots: &ActivePivots,
    q: &DVector<f64>,
    qdot: &mut DVector<f64>,
    free: Option<&[usize]>,
    cache: Option<&mut VelocityProjection>,
) -> f64 {
    let (_, jac) = scaled(model, kin, q, pivots);
    let cols = free_columns(model, free);
    let res = &jac * &*qdot;
    let whole = jac.norm();
    // Φ_q over the columns changed, and its transpose (its rows as columns) for the kept rows.
    let sub = jac.select_columns(cols.iter());
    let bt = sub.transpose();
    let mut cache = cache;
    if let Some(cache) = cache.as_deref_mut()
        && let Some((for_cols, selected)) = &cache.selection
        && *for_cols == cols
    {
        let (mut dz, mut unused) = (DVector::zeros(cols.len()), DVector::zeros(0));
        if solve_selected_rows(
            &mut cache.work,
            &SparseRows::from_transposed(&bt),
            &res,
            selected,
            RANK_TOLERANCE,
            RANK_TOLERANCE * whole,
            false,
            &mut dz,
            &mut unused,
        ) {
            cache.reused += 1;
            for (j, &c) in cols.iter().enumerate() {
                qdot[c] += dz[j];
            }
            return res.amax();
        }
    }
    // The SVD (`pinv_solve_in`'s threshold), and the rows it keeps for the next projection.
    let svd = JacobiSvd::thin(&sub);
    let tol = svd.tolerance().max(RANK_TOLERANCE * whole);
    let dx = svd.solve_with(&res, tol);
    if let Some(cache) = cache {
        cache.decompositions += 1;
        let rank = svd.singular_values.iter().filter(|s| **s > tol).count();
        cache.selection = Some((cols.clone(), pivot_columns(&bt, rank)));
    }
    for (j, &c) in cols.iter().enumerate() {
        qdot[c] -= dx[j];
    }
    res.amax()
}

/// Whether every slot whose angle is clearly away from 0 (beyond 1e-9 rad, the Newton tolerance
/// on these angles) pivots on the side of its sign.
fn signs_agree(model: &Model, kin: &mut Data, q: &DVector<f64>, pivots: &ActivePivots) -> bool {
    forward_kinematics(model, kin, q, pivots);
    let mut angles: Vec<f64> = q.iter().copied().collect();
    angles.resize(model.slot_count, 0.0);
    closure_angles(model, kin, &mut angles[model.dof()..]);
    angles
        .iter()
        .zip(&pivots.sides)
        .all(|(&a, &s)| a.abs() <= 1e-9 || Side::of(a, s) == s)
}

/// Angles within this of 0 (rad) are ties for [`follow_signs`]: round-off of a Newton solve
/// (1e-17 rad) must not switch a pivot.
pub const SIGN_TIE: f64 = 1e-12;

/// Sets tree pivot sides from the signs of q and closure pivot sides from the current closure
/// angles; angles within [`SIGN_TIE`] of 0 keep their side.
pub fn follow_signs(model: &Model, kin: &mut Data, q: &DVector<f64>, pivots: &mut ActivePivots) {
    let side = |a: f64, s: Side| {
        if a.abs() <= SIGN_TIE {
            s
        } else {
            Side::of(a, s)
        }
    };
    for (k, &a) in q.iter().enumerate() {
        pivots.sides[k] = side(a, pivots.sides[k]);
    }
    forward_kinematics(model, kin, q, pivots);
    let mut ang = vec![0.0; model.slot_count - model.dof()];
    closure_angles(model, kin, &mut ang);
    for (k, a) in ang.iter().enumerate() {
        let s = &mut pivots.sides[model.dof() + k];
        *s = side(*a, *s);
    }
}

/// Initial conditions given by the user: some angles and rates by coordinate name; the others are
/// solved so that Φ = 0 and Φ_q q̇ = 0 hold.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InitialSpec {
    /// Angles (rad) by coordinate name.
    pub angles: BTreeMap<String, f64>,
    /// Rates (rad/s) by coordinate name.
    pub rates: BTreeMap<String, f64>,
}

/// A consistent initial state.
#[derive(Clone, Debug, PartialEq)]
pub struct InitialState {
    /// q (rad).
    pub q: DVector<f64>,
    /// q̇ (rad/s).
    pub qdot: DVector<f64>,
    /// Active pivots following the signs of q and of the closure angles.
    pub pivots: ActivePivots,
}

fn lookup(
    model: &Model,
    table: &BTreeMap<String, f64>,
    what: &str,
) -> Result<Vec<(usize, f64)>, DynamicsError> {
    table
        .iter()
        .map(|(name, v)| {
            let k = model.coord_index(name).ok_or_else(|| {
                let names: Vec<_> = model.coords.iter().map(|c| c.name.as_str()).collect();
                DynamicsError::Initial(format!(
                    "{what}: no coordinate named \"{name}\"; coordinates are: {}",
                    names.join(", ")
                ))
            })?;
            if !v.is_finite() {
                return Err(DynamicsError::Initial(format!(
                    "{what}.{name}: {v} is not a finite number"
                )));
            }
            Ok((k, *v))
        })
        .collect()
}

/// Newton steps on the free coordinates with the pivots following the signs of each iterate
/// (Φ is continuous across a pivot switch, only its slope changes). It finds the pivot sides of
/// the closed configuration when some free coordinates must become negative (a colonnade tilted in
/// both directions: the other columns' second tilts pivot on their negative side); from rest with
/// every pivot `+` the loops could not close. Falls back to rest on failure.
fn warm_start_following_signs(
    model: &Model,
    kin: &mut Data,
    pivots: &mut ActivePivots,
    q: &mut DVector<f64>,
    free: &[usize],
) {
    let start = q.clone();
    for _ in 0..NEWTON_ITERATIONS {
        follow_signs(model, kin, q, pivots);
        let (phi, jac) = scaled(model, kin, q, pivots);
        let norm = phi.amax();
        if !norm.is_finite() || norm <= CLOSURE_TOLERANCE {
            break;
        }
        min_norm_step(&jac, &phi, free, q);
    }
    if !q.iter().all(|x| x.is_finite()) {
        q.copy_from(&start);
        *pivots = ActivePivots::uniform(model, Side::Positive);
    }
}

/// Smallest fraction of the way from rest a step of [`continuation`] may take before it gives up.
const MIN_CONTINUATION_STEP: f64 = 1.0 / 4096.0;

/// The closed configuration connected to rest: the given angles raised from 0 to their values in
/// steps, each predicted along the tangent of the solution path (Φ_q,free dq_free =
/// −Φ_q,given dq_given, minimum norm) and closed by Newton with the pivots held, the pivots then
/// following the signs (a joint changes pivot only where its angle passes 0, where both pivots
/// give the same configuration). A step is accepted when Newton's correction is small against
/// the step itself (at most a tenth of the predicted change, or 1e-9 rad): a jump to another
/// branch of the loops' equations is refused, and the step halved. Returns the configuration and
/// its pivots, or why the path stopped (the fraction of the way reached and the residual).
fn continuation(
    model: &Model,
    kin: &mut Data,
    angles: &[(usize, f64)],
    free: &[usize],
) -> Result<(DVector<f64>, ActivePivots), DynamicsError> {
    let n = model.dof();
    let mut q = DVector::zeros(n);
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    for &(k, v) in angles {
        pivots.sides[k] = Side::of(v, Side::Positive);
    }
    let given: Vec<usize> = angles.iter().map(|a| a.0).collect();
    let mut done = 0.0_f64;
    let mut step = 1.0 / 16.0;
    while done < 1.0 {
        let next = (done + step).min(1.0);
        match continuation_step(model, kin, &q, &pivots, angles, &given, free, done, next) {
            Ok((q_next, pivots_next)) => {
                q = q_next;
                pivots = pivots_next;
                done = next;
                step = (2.0 * step).min(1.0 / 16.0);
            }
            Err(why) => {
                step *= 0.5;
                if step < MIN_CONTINUATION_STEP {
                    return Err(DynamicsError::Closure(format!(
                        "the loops could not be followed from rest beyond {:.1} % of the given \
                         angles: {why}",
                        100.0 * done
                    )));
                }
            }
        }
    }
    Ok((q, pivots))
}

/// One step of [`continuation`] from the fraction `from` of the given angles to `to`.
#[allow(clippy::too_many_arguments)]
fn continuation_step(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    pivots: &ActivePivots,
    angles: &[(usize, f64)],
    given: &[usize],
    free: &[usize],
    from: f64,
    to: f64,
) -> Result<(DVector<f64>, ActivePivots), String> {
    // Tangent predictor. A coordinate at 0 pivots on the side it moves to: its Jacobian column
    // depends on the pivot, so the tangent is taken again once the sides of those at 0 follow
    // the predicted motion (at the angle 0 both pivots give the same configuration).
    let n = model.dof();
    let at_zero: Vec<usize> = (0..n).filter(|&k| q[k].abs() <= SIGN_TIE).collect();
    // The closure angles at 0 likewise (a loop of rocking bases is a mechanism only when the
    // pivots of its closures and of its tree agree: with a corner on the wrong side the loop
    // closes to first order only, and Newton stalls at a residual of second order).
    forward_kinematics(model, kin, q, pivots);
    let mut closing = vec![0.0; model.slot_count - n];
    closure_angles(model, kin, &mut closing);
    let closures_at_zero: Vec<usize> = (0..closing.len())
        .filter(|&j| closing[j].abs() <= SIGN_TIE)
        .collect();
    let mut step_pivots = pivots.clone();
    let mut predicted = q.clone();
    for _ in 0..3 {
        let (_, jac) = scaled(model, kin, q, &step_pivots);
        let rhs = jac.select_columns(given.iter())
            * DVector::from_iterator(given.len(), angles.iter().map(|&(_, v)| v * (to - from)));
        let (dfree, _) = pinv_solve_in(&jac.select_columns(free.iter()), &rhs, jac.norm());
        predicted.copy_from(q);
        for &(k, v) in angles {
            predicted[k] = v * to;
        }
        for (j, &k) in free.iter().enumerate() {
            predicted[k] -= dfree[j];
        }
        let before = step_pivots.clone();
        for &k in &at_zero {
            if predicted[k].abs() > SIGN_TIE {
                step_pivots.sides[k] = Side::of(predicted[k], step_pivots.sides[k]);
            }
        }
        forward_kinematics(model, kin, &predicted, &step_pivots);
        closure_angles(model, kin, &mut closing);
        for &j in &closures_at_zero {
            if closing[j].abs() > SIGN_TIE {
                step_pivots.sides[n + j] = Side::of(closing[j], step_pivots.sides[n + j]);
            }
        }
        if step_pivots == before {
            break;
        }
    }
    let pivots = &step_pivots;
    let change = (&predicted - q).amax();
    let mut trial = predicted.clone();
    let mut trial_pivots = pivots.clone();
    for _ in 0..4 {
        project_positions(model, kin, &trial_pivots, &mut trial, Some(free))
            .map_err(|e| e.to_string())?;
        let before = trial_pivots.clone();
        follow_signs(model, kin, &trial, &mut trial_pivots);
        if trial_pivots == before {
            let correction = (&trial - &predicted).amax();
            if correction > (0.1 * change).max(1e-9) {
                return Err(format!(
                    "Newton moved {correction:.3e} rad away from the path's prediction (a step \
                     of {change:.3e} rad): another branch of the loops"
                ));
            }
            return Ok((trial, trial_pivots));
        }
    }
    Err("the pivot sides do not settle".into())
}

/// The solved configuration `q_end` with the free angles that only drifted (below 1e-6 rad: the
/// continuation's and Newton's steps leave such drift along a mechanism that the given angles do
/// not move, and it broke the symmetry of symmetric structures) set to exactly 0 and the loops closed again by
/// the other free angles, when that closes them (row-scaled |Φ| ≤ 1e-12) within 1e-6 rad of the
/// end with every angle still on the side of its pivot; else the end as it is.
fn without_drift(
    model: &Model,
    kin: &mut Data,
    pivots: &ActivePivots,
    q_end: DVector<f64>,
    free: &[usize],
) -> DVector<f64> {
    let drifted: Vec<usize> = free
        .iter()
        .copied()
        .filter(|&k| q_end[k] != 0.0 && q_end[k].abs() < 1e-6)
        .collect();
    if drifted.is_empty() {
        return q_end;
    }
    let others: Vec<usize> = free
        .iter()
        .copied()
        .filter(|k| !drifted.contains(k))
        .collect();
    let mut q = q_end.clone();
    for &k in &drifted {
        q[k] = 0.0;
    }
    let closed = project_positions(model, kin, pivots, &mut q, Some(&others)).is_ok()
        && scaled(model, kin, &q, pivots).0.amax() <= 1e-12
        && (&q - &q_end).amax() <= 1e-6
        && signs_agree(model, kin, &q, pivots);
    if closed { q } else { q_end }
}

/// Solves the initial state: the given angles and rates are kept, the other coordinates are found
/// so that Φ = 0 and Φ_q q̇ = 0, on the branch connected to rest (a continuation from 0); Newton from
/// the rest configuration (minimum-norm steps, the pivots following the signs of the solution
/// until they agree) gives the state where it lands on the path's end (within 1e-6 rad), and the
/// path's end is the state where it lands elsewhere or fails. Errors when the given values admit
/// no consistent state.
pub fn solve_initial(model: &Model, spec: &InitialSpec) -> Result<InitialState, DynamicsError> {
    let angles = lookup(model, &spec.angles, "initial.angles")?;
    let rates = lookup(model, &spec.rates, "initial.rates")?;
    let n = model.dof();
    let mut q = DVector::zeros(n);
    for &(k, v) in &angles {
        q[k] = v;
    }
    let given: Vec<usize> = angles.iter().map(|a| a.0).collect();
    let free: Vec<usize> = (0..n).filter(|k| !given.contains(k)).collect();
    let mut kin = Data::new(model);
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    let rest = ActivePivots::uniform(model, Side::Positive);
    let mob = mobility(model, &DVector::zeros(n), &rest);
    let explain = |extra: &str| {
        let over = if given.len() > mob.dof2 {
            format!(
                " ({} angle(s) given but the mechanism has DOF(2) = {}: give at most {})",
                given.len(),
                mob.dof2,
                mob.dof2
            )
        } else {
            String::new()
        };
        DynamicsError::Initial(format!(
            "the given angles admit no configuration that closes the loops{over}{extra}"
        ))
    };
    if model.constraint_rows > 0 {
        // The configuration connected to rest by a path, when the path can be followed: the
        // Newton solve below may land on a far root of the loops' equations (columns tilted
        // 0.3 rad about the other axis for a 0.01 rad release of the baldachin), and is kept
        // only where it agrees with the path's end.
        let path = if angles.is_empty() {
            None
        } else {
            continuation(model, &mut kin, &angles, &free).ok()
        };
        warm_start_following_signs(model, &mut kin, &mut pivots, &mut q, &free);
        // Re-solve with the pivots held until they agree with the signs of the solution. Two
        // candidates: Newton from rest (minimum-norm steps) and from the current solution; the
        // nearer to rest is kept and the pivots follow its signs in the next pass.
        let mut settled = false;
        for _ in 0..8 {
            let before = pivots.clone();
            follow_signs(model, &mut kin, &q, &mut pivots);
            let mut from_rest = q.clone();
            for &k in &free {
                from_rest[k] = 0.0;
            }
            let mut closed = Vec::new();
            let mut failure = None;
            for mut c in [from_rest, q.clone()] {
                match project_positions(model, &mut kin, &pivots, &mut c, Some(&free)) {
                    Ok(_) => closed.push(c),
                    Err(e) => failure = Some(e),
                }
            }
            q = match closed
                .into_iter()
                .min_by(|a, b| a.norm().total_cmp(&b.norm()))
            {
                Some(c) => c,
                // The path's end stands where Newton fails.
                None if path.is_some() => break,
                None => return Err(explain(&format!(": {}", failure.expect("both failed")))),
            };
            if signs_agree(model, &mut kin, &q, &pivots) && pivots == before {
                settled = true;
                break;
            }
        }
        if let Some((q_path, pivots_path)) = path
            && (!settled || (&q - &q_path).amax() > 1e-6)
        {
            q = q_path;
            pivots = pivots_path;
            settled = true;
        }
        q = without_drift(model, &mut kin, &pivots, q, &free);
        let (phi, _) = scaled(model, &mut kin, &q, &pivots);
        if phi.amax() > 1e-9 {
            return Err(explain(&format!(": residual {:.3e}", phi.amax())));
        }
        if !settled {
            return Err(explain(
                ": the pivot sides do not settle (the angles given put some joint on the \
                 boundary between its pivots)",
            ));
        }
    } else {
        pivots.follow_coordinates(&q);
    }
    let mut qdot = DVector::zeros(n);
    for &(k, v) in &rates {
        qdot[k] = v;
    }
    if model.constraint_rows > 0 {
        let given_r: Vec<usize> = rates.iter().map(|a| a.0).collect();
        let free_r: Vec<usize> = (0..n).filter(|k| !given_r.contains(k)).collect();
        for &k in &free_r {
            qdot[k] = 0.0;
        }
        project_velocities(model, &mut kin, &pivots, &q, &mut qdot, Some(&free_r));
        let (_, jac) = scaled(model, &mut kin, &q, &pivots);
        let res = (&jac * &qdot).amax();
        if res > 1e-9 * (1.0 + qdot.amax()) {
            return Err(DynamicsError::Initial(format!(
                "the given rates admit no velocity that keeps the loops closed (residual {res:.3e}); \
                 give at most DOF(2) = {} rate(s) that are compatible",
                mob.dof2
            )));
        }
    }
    // Rates so large that T overflows (1e155 rad/s on a 2 m block) would write an infinite
    // energy into the results: refused here, naming the rates.
    let energy = crate::energy::energies(model, &mut kin, &q, &qdot, &pivots, 0.0);
    if !(energy.kinetic.is_finite() && energy.potential.is_finite()) {
        let (what, energy) = if energy.kinetic.is_finite() {
            ("initial.angles: the potential energy", energy.potential)
        } else {
            ("initial.rates: the kinetic energy", energy.kinetic)
        };
        return Err(DynamicsError::Initial(format!(
            "{what} of the initial state is {energy} J, not a finite number"
        )));
    }
    Ok(InitialState { q, qdot, pivots })
}

/// Coordinate partitioning: the dependent coordinates (one per independent constraint, the
/// columns of a pivoted factorisation of Φ_q) and the independent ones (the reduced form's
/// coordinates, DOF(2) of them).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Partition {
    /// Independent coordinates, increasing.
    pub independent: Vec<usize>,
    /// Dependent coordinates, increasing.
    pub dependent: Vec<usize>,
}

/// Chooses the partition at configuration q: r = rank Φ_q dependent coordinates by column pivoting
/// (the best-conditioned dependent block), the rest independent.
pub fn partition(model: &Model, q: &DVector<f64>, pivots: &ActivePivots) -> Partition {
    let mut kin = Data::new(model);
    let (_, jac) = scaled(model, &mut kin, q, pivots);
    let r = rank(&jac);
    let mut dependent = pivot_columns(&jac, r);
    dependent.sort_unstable();
    let independent = (0..model.dof())
        .filter(|k| !dependent.contains(k))
        .collect();
    Partition {
        independent,
        dependent,
    }
}

/// Conditioning of the dependent block of a partition at q: σ_min/σ_max of the row-scaled
/// Φ_q restricted to the dependent columns (1 is perfect, 0 singular). Below
/// [`REPARTITION_THRESHOLD`] the reduced form chooses its coordinates again.
pub fn partition_condition(
    model: &Model,
    q: &DVector<f64>,
    pivots: &ActivePivots,
    part: &Partition,
) -> f64 {
    if part.dependent.is_empty() {
        return 1.0;
    }
    let mut kin = Data::new(model);
    let (_, jac) = scaled(model, &mut kin, q, pivots);
    let sub = DMatrix::from_fn(jac.nrows(), part.dependent.len(), |i, j| {
        jac[(i, part.dependent[j])]
    });
    let s = JacobiSvd::new(&sub).singular_values;
    let r = part.dependent.len();
    let mut v: Vec<f64> = s.iter().copied().collect();
    v.sort_by(|a, b| b.total_cmp(a));
    if v[0] <= 0.0 { 0.0 } else { v[r - 1] / v[0] }
}

/// The dependent block's conditioning below which the reduced form re-partitions.
pub const REPARTITION_THRESHOLD: f64 = 0.2;
