//! The closed-chain solve on a cached selection of independent rows of B
//! ([`ClosedChainSolve::SelectedRows`]: chosen by Gram–Schmidt with pivoting at a new seated
//! set, certified by the solve, kept for the next calls) against the Jacobi SVD of B at every evaluation
//! ([`ClosedChainSolve::Svd`]), on the colonnade (12 closure rows of rank 8), the trilithon, the
//! arch and random closed chains, with and without seated slots (which add rows dependent on the
//! loops'), at rest and away from it.
//!
//! Tolerances: both paths solve the same consistent system B dz = −e of rank r, the selected one
//! through G = B_S B_Sᵀ (see [`Q_TOLERANCE`], [`LAMBDA_TOLERANCE`]). The constraint
//! residual Φ'q̈ + Φ̇'q̇ (row-scaled) is checked against 1e3·ε·(‖Φ'‖(‖q̈‖ + g/L) + ‖Φ̇'q̇‖), the size of
//! the round-off in forming its terms times a small factor for the solves.

use std::collections::BTreeMap;

use nalgebra::DVector;

use crr_dynamics::closed_chain::{
    InitialSpec, VelocityProjection, project_velocities, project_velocities_with, solve_initial,
};
use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::linalg::JacobiSvd;
use crr_dynamics::{ClosedChainSolve, Dynamics};
use crr_kinematics::fixtures::{
    SplitMix, colonnade, colonnade_row, four_hinge_arch, random_chain, trilithon,
};
use crr_kinematics::{ActivePivots, Model, StructureSpec};

/// A consistent state: q with `angle` on the first coordinate (rest when that does not close),
/// q̇ a random combination of the null space of Φ_q.
fn state(model: &Model, angle: f64, seed: u64) -> (DVector<f64>, DVector<f64>, ActivePivots) {
    let mut angles = BTreeMap::new();
    angles.insert(model.coords[0].name.clone(), angle);
    let spec = InitialSpec {
        angles,
        rates: BTreeMap::new(),
    };
    let init = solve_initial(model, &spec).unwrap_or_else(|_| {
        solve_initial(
            model,
            &InitialSpec {
                angles: BTreeMap::new(),
                rates: BTreeMap::new(),
            },
        )
        .expect("the rest state is consistent")
    });
    let mut d = Dynamics::new(model, init.pivots.clone());
    d.evaluate(
        model,
        &GroundMotion::none(),
        0.0,
        &init.q,
        &DVector::zeros(model.dof()),
    );
    let null = JacobiSvd::new(&d.kin.phi_q).null_space();
    let mut rng = SplitMix(seed);
    let coef = DVector::from_fn(null.ncols(), |_, _| rng.uniform(-1.0, 1.0));
    (init.q, &null * coef, init.pivots)
}

/// Which calls of the selected path took the selected rows: the first, on a new seated set
/// (rows chosen by Gram–Schmidt with pivoting and certified, or the SVD), and the second (the
/// rows kept).
#[derive(Clone, Copy, Debug)]
struct Taken {
    first: bool,
    second: bool,
}

/// Solves at (q, q̇) with both paths (the selected one twice: the first call chooses the rows,
/// the second uses them) and checks the agreement and the constraint residual after each.
fn compare(
    model: &Model,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    pivots: &ActivePivots,
    seated: &[usize],
    min_norm: bool,
    reused: Option<&mut Dynamics>,
) -> Taken {
    let ground = GroundMotion::none();
    let mut svd = Dynamics::new(model, pivots.clone());
    svd.closed_chain_solve = ClosedChainSolve::Svd;
    svd.seated = seated.to_vec();
    svd.min_norm_multipliers = min_norm;
    svd.accelerations(model, &ground, 0.0, q, qdot).unwrap();
    assert!(!svd.used_selected_rows());

    let mut own = Dynamics::new(model, pivots.clone());
    let fast = match reused {
        Some(d) => d,
        None => &mut own,
    };
    fast.seated = seated.to_vec();
    fast.min_norm_multipliers = min_norm;
    fast.accelerations(model, &ground, 0.0, q, qdot).unwrap();
    let first = fast.used_selected_rows();
    agree(model, &svd, fast, seated, min_norm, q);
    fast.accelerations(model, &ground, 0.0, q, qdot).unwrap();
    agree(model, &svd, fast, seated, min_norm, q);
    Taken {
        first,
        second: fast.used_selected_rows(),
    }
}

/// The selected path's q̈ (and, when `min_norm`, λ) against the SVD's, and its constraint
/// residual.
fn agree(
    model: &Model,
    svd: &Dynamics,
    fast: &Dynamics,
    seated: &[usize],
    min_norm: bool,
    q: &DVector<f64>,
) {
    let bound = Q_TOLERANCE;
    // At rest with every coordinate seated q̈ is 0 and both paths return round-off of the
    // natural acceleration scale g/L: relative to ‖q̈‖ + g/L.
    let scale = svd.qddot.norm() + model.gravity / model.size;
    let diff = (&fast.qddot - &svd.qddot).norm();
    assert!(
        diff <= bound * scale,
        "q̈ differs by {diff:e} relative {:e} (seated {seated:?}, min_norm {min_norm}, q {})",
        diff / scale,
        q.amax()
    );
    if min_norm {
        // The minimum-norm multipliers are unique.
        let ls = svd.lambda.norm() + svd.seat_reactions.norm();
        let dl = (&fast.lambda - &svd.lambda).norm()
            + (&fast.seat_reactions - &svd.seat_reactions).norm();
        assert!(
            dl <= LAMBDA_TOLERANCE * ls.max(1e-300),
            "λ differs by {dl:e} of {ls:e}"
        );
    }
    // Φ'q̈ + Φ̇'q̇ = 0 on the loop rows (scaled as the solver scales them).
    let scaled_bias = fast.kin.phi_bias.component_mul(fast.row_scale());
    let phi = fast.scaled_jacobian();
    let residual = (&phi * &fast.qddot + &scaled_bias).norm();
    let size = phi.norm() * scale + scaled_bias.norm();
    assert!(
        residual <= 1e3 * f64::EPSILON * size.max(1e-300),
        "constraint residual {residual:e} of {size:e}"
    );
}

/// Relative agreement of q̈: both paths solve the same consistent system of rank r, the selected
/// one through G = B_S B_Sᵀ, whose forward error is about κ(G)·ε = κ(B_S)²·ε; the bodies of
/// these fixtures have comparable sizes and masses (κ(B_S)² ≲ 1e2), hence ≲ 2e-14, and 1e-12
/// leaves a factor 50 for the differing orders of summation.
const Q_TOLERANCE: f64 = 1e-12;

/// Relative agreement of the minimum-norm multipliers: one more solve (I + C Cᵀ, C the
/// coefficients of the dependent rows) than q̈, and λ scales like the inverse of B's smallest
/// kept singular value rather than its largest, so a hundred times the q̈ tolerance.
const LAMBDA_TOLERANCE: f64 = 1e-10;

fn run(spec: &StructureSpec, angle: f64, seated_sets: &[Vec<usize>]) -> usize {
    let model = Model::from_spec(spec).expect("valid fixture");
    let mut reused = 0;
    for (seed, a) in [(1, 0.0), (2, angle)] {
        let (q, qdot, pivots) = state(&model, a, seed);
        for seated in seated_sets {
            for min_norm in [true, false] {
                let taken = compare(&model, &q, &qdot, &pivots, seated, min_norm, None);
                // Rows chosen by Gram–Schmidt are certified on every fixture: the SVD is only
                // the fallback.
                assert!(
                    taken.first,
                    "{}: seated {seated:?}: the SVD chose",
                    spec.name
                );
                if taken.second {
                    reused += 1;
                }
            }
        }
    }
    reused
}

#[test]
fn selected_rows_agree_with_the_svd_on_the_colonnade() {
    // Seated slots add rows: the bases of both front columns (rows dependent on the loops').
    let spec = colonnade(0.2, 1.5, 1.0, 0.3);
    let n = Model::from_spec(&spec).unwrap().dof();
    let reused = run(
        &spec,
        0.02,
        &[vec![], vec![0], vec![0, 1], (0..n).collect()],
    );
    assert!(reused > 0, "the selected rows were never reused");
}

#[test]
fn selected_rows_agree_with_the_svd_on_the_trilithon() {
    let reused = run(
        &trilithon(0.25, 1.5, 2.0, 0.5, 1.0),
        0.05,
        &[vec![], vec![0], vec![0, 2]],
    );
    assert!(reused > 0, "the selected rows were never reused");
}

#[test]
fn selected_rows_agree_with_the_svd_on_the_arch() {
    let reused = run(
        &four_hinge_arch(4.0, 4.6, 1.0, false),
        0.01,
        &[vec![], vec![1]],
    );
    assert!(reused > 0, "the selected rows were never reused");
}

#[test]
fn selected_rows_agree_with_the_svd_on_random_closed_chains() {
    let mut reused = 0;
    for seed in 0..12 {
        let spec = random_chain(seed, 4 + (seed as usize % 4), 1 + (seed as usize % 2));
        let Ok(model) = Model::from_spec(&spec) else {
            continue;
        };
        let n = model.dof();
        reused += run(&spec, 0.01, &[vec![], vec![0], vec![n - 1], vec![0, n]]);
    }
    assert!(reused > 0, "the selected rows were never reused");
}

/// A selection made at one state is checked, not trusted, at another: carried from the rest of
/// the colonnade (where the seated rows make a different set dependent) to a tilted state and
/// back, the solve still agrees with the SVD.
#[test]
fn a_selection_carried_to_another_state_is_checked() {
    let spec = colonnade(0.2, 1.5, 1.0, 0.3);
    let model = Model::from_spec(&spec).unwrap();
    let (q0, qd0, p0) = state(&model, 0.0, 3);
    let (q1, qd1, p1) = state(&model, 0.05, 4);
    let mut d = Dynamics::new(&model, p0.clone());
    for (q, qd, p) in [(&q0, &qd0, &p0), (&q1, &qd1, &p1), (&q0, &qd0, &p0)] {
        d.pivots = p.clone();
        compare(&model, q, qd, p, &[0], true, Some(&mut d));
    }
}

/// A planar row of columns under architraves: each loop's out-of-plane closure rows are zero
/// rows of B (left out of the products and of the multipliers), the mass matrix is block
/// diagonal (one block per column and its architrave: factorised on its tree pattern), and the
/// loops couple only neighbouring columns (G banded). Same q̈ and λ as the SVD, seated or not.
#[test]
fn selected_rows_agree_with_the_svd_on_a_planar_row_of_loops() {
    let spec = colonnade_row(5, 3);
    let n = Model::from_spec(&spec).unwrap().dof();
    let reused = run(
        &spec,
        0.01,
        &[vec![], vec![0], vec![0, 4, 8], (0..n).step_by(2).collect()],
    );
    assert!(reused > 0, "the selected rows were never reused");
    // Every coordinate seated: consistent only at rest (q̇ = 0; with rates the loops' bias
    // Φ̇'q̇ asks for a q̈ the seats forbid, and the two solves settle that conflict differently).
    let model = Model::from_spec(&spec).unwrap();
    let (q, _, pivots) = state(&model, 0.0, 1);
    let all: Vec<usize> = (0..n).collect();
    for min_norm in [true, false] {
        compare(
            &model,
            &q,
            &DVector::zeros(n),
            &pivots,
            &all,
            min_norm,
            None,
        );
    }
}

/// A running-bond wall held on every seat (every slot seated, at rest): the selected rows
/// constrain every free coordinate (r = n_f) and most rows depend on them (a hyperstatic wall:
/// on the 4 × 3 wall B has 56 rows, the loops' and the seated slots', of rank r = n_f = 14, and
/// 21 of the dependent rows are not zero rows), where the
/// minimum-norm multipliers come from BᵀB instead of I + C Cᵀ over the dependent rows, and the
/// dependent rows' part outside the selected ones' span is zero by dimension (not computed). Same
/// q̈ and λ as the SVD, from the first call (rows chosen by Gram–Schmidt), and the selected rows
/// reused.
#[test]
fn selected_rows_agree_with_the_svd_on_a_wall_held_on_every_seat() {
    let spec = crr_kinematics::fixtures::running_bond_wall(4, 3, 0.6, 0.25, 0.3);
    let model = Model::from_spec(&spec).unwrap();
    let all: Vec<usize> = (0..model.slot_count).collect();
    let (q, _, pivots) = state(&model, 0.0, 1);
    let zero = DVector::zeros(model.dof());
    let mut d = Dynamics::new(&model, pivots.clone());
    let mut reused = 0;
    for min_norm in [true, false, true] {
        let taken = compare(&model, &q, &zero, &pivots, &all, min_norm, Some(&mut d));
        assert!(taken.first, "the SVD chose the wall's rows");
        if taken.second {
            reused += 1;
        }
    }
    assert!(reused > 0, "the selected rows were never reused");
}

/// The velocity projection on kept rows is the SVD's: at states whose rates are perturbed off
/// Φ_q q̇ = 0, both give the same q̇ to round-off (the correction is the same minimum-norm one,
/// δq̇ = −Φ_q⁺Φ_q q̇, through Φ_S Φ_Sᵀ instead of the SVD), the projected rates satisfy the
/// constraints, and the rows chosen at the first state are reused at the next ones.
#[test]
fn the_velocity_projection_on_kept_rows_is_the_svd_projection() {
    for spec in [
        colonnade_row(5, 3),
        colonnade(0.2, 1.5, 1.0, 0.3),
        trilithon(0.25, 1.5, 2.0, 0.5, 1.0),
    ] {
        let model = Model::from_spec(&spec).unwrap();
        let n = model.dof();
        let mut cache = VelocityProjection::default();
        for (seed, angle) in [(5, 0.0), (6, 0.01), (7, 0.012)] {
            let (q, qdot, pivots) = state(&model, angle, seed);
            let mut rng = SplitMix(seed + 100);
            let off = DVector::from_fn(n, |_, _| 1e-3 * rng.uniform(-1.0, 1.0));
            let start = &qdot + off;
            let mut kin = crr_kinematics::Data::new(&model);
            let (mut by_svd, mut kept) = (start.clone(), start.clone());
            project_velocities(&model, &mut kin, &pivots, &q, &mut by_svd, None);
            project_velocities_with(
                &model,
                &mut kin,
                &pivots,
                &q,
                &mut kept,
                None,
                Some(&mut cache),
            );
            // Both are the orthogonal projection of the same vector on the same null space:
            // round-off of ε κ(Φ_S) ‖q̇‖ (κ ≲ 1e2 on these fixtures), 1e-12 relative.
            let diff = (&by_svd - &kept).norm();
            assert!(
                diff <= 1e-12 * start.norm(),
                "{}: projections differ by {diff:e}",
                spec.name
            );
            let mut d = Dynamics::new(&model, pivots.clone());
            d.evaluate(&model, &GroundMotion::none(), 0.0, &q, &kept);
            let phi = d.scaled_jacobian();
            let residual = (&phi * &kept).norm();
            assert!(
                residual <= 1e3 * f64::EPSILON * phi.norm() * start.norm(),
                "{}: Φ_q q̇ = {residual:e} after the projection",
                spec.name
            );
        }
        assert_eq!(cache.decompositions, 1, "{}: rows chosen once", spec.name);
        assert_eq!(cache.reused, 2, "{}: and kept twice", spec.name);
    }
}

/// The closed-chain solve, whose rows are built on their structural patterns (a closure row on
/// its frames' paths to the ground, a seated slot's rate row on its interface's paths, a
/// symmetry row on its two coordinates), against Gauss' principle written densely here from the
/// kinematics alone: q̈ = M⁻¹r − M⁻¹Cᵀ(CM⁻¹Cᵀ)⁺(CM⁻¹r + c), r = Q − h, C the row-scaled Φ_q
/// and the seated slots' rate rows (`slot_row`), c their biases, with nalgebra's Cholesky and
/// SVD pseudo-inverse (threshold 1e-10 of ‖CM⁻¹Cᵀ‖, the redundant rows' singular values being
/// round-off). Seated tree coordinates (eliminated by the solve when the multipliers are not
/// wanted, rows when they are), seated closure angles and a symmetry row; both solve paths.
/// Agreement to 1e-9 of ‖q̈‖ + g/L: the systems' condition numbers stay below 1e5 here.
#[test]
fn the_solve_on_the_rows_patterns_is_gauss_principle_written_densely() {
    use crr_dynamics::eom::{constraint_row_scale, slot_row};
    use crr_kinematics::{SymmetryRelation, SymmetrySpec};
    let mut symmetric = colonnade(0.2, 1.5, 1.0, 0.3);
    symmetric.symmetry.push(SymmetrySpec {
        coordinates: ["base_1.1".into(), "base_1.2".into()],
        relation: SymmetryRelation::Opposite,
    });
    let cases: Vec<(StructureSpec, f64)> = vec![
        (symmetric, 0.0),
        (colonnade_row(4, 3), 0.01),
        (random_chain(7, 6, 2), 0.02),
        (random_chain(23, 8, 3), 0.02),
    ];
    let ground = GroundMotion::none();
    for (spec, angle) in &cases {
        let model = Model::from_spec(spec).expect("valid fixture");
        let n = model.dof();
        let (q, qdot, pivots) = state(&model, *angle, 3);
        // Seated: a tree coordinate, a second one, and the first closure slot.
        let mut seated = vec![n - 1, n / 2];
        if model.slot_count > n {
            seated.push(n);
        }
        seated.sort_unstable();
        seated.dedup();
        for (min_norm, solve) in [
            (false, ClosedChainSolve::SelectedRows),
            (true, ClosedChainSolve::SelectedRows),
            (false, ClosedChainSolve::Svd),
        ] {
            let mut d = Dynamics::new(&model, pivots.clone());
            d.seated = seated.clone();
            d.min_norm_multipliers = min_norm;
            d.closed_chain_solve = solve;
            for _ in 0..2 {
                d.accelerations(&model, &ground, 0.0, &q, &qdot).unwrap();
            }
            // The dense reference from the same state's kinematics.
            let m = d.kin.mass_matrix.clone();
            let r = &d.load - &d.kin.velocity_product;
            let scale = constraint_row_scale(&model);
            let rows = model.constraint_rows + seated.len();
            let mut c = nalgebra::DMatrix::zeros(rows, n);
            let mut bias = DVector::zeros(rows);
            for i in 0..model.constraint_rows {
                for j in 0..n {
                    c[(i, j)] = scale[i] * d.kin.phi_q[(i, j)];
                }
                bias[i] = scale[i] * d.kin.phi_bias[i];
            }
            let mut row = DVector::zeros(n);
            for (k, &s) in seated.iter().enumerate() {
                bias[model.constraint_rows + k] = slot_row(&model, &d.kin, s, &mut row);
                c.row_mut(model.constraint_rows + k)
                    .copy_from(&row.transpose());
            }
            let chol = m.clone().cholesky().expect("M is positive definite");
            let free = chol.solve(&r);
            let y = chol.solve(&c.transpose());
            let schur = &c * &y;
            let threshold = 1e-10 * schur.norm();
            let pinv = schur.pseudo_inverse(threshold).expect("SVD converges");
            let expected = &free - &y * (pinv * (&c * &free + &bias));
            let size = expected.norm() + model.gravity / model.size;
            let gap = (&d.qddot - &expected).norm();
            assert!(
                gap <= 1e-9 * size,
                "{n} coordinates, min_norm {min_norm}, {solve:?}: |Δq̈| = {gap:e} of {size:e}"
            );
        }
    }
}
