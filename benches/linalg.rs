//! The dense factorisations of the engine on its own matrices, by three libraries: the one-sided
//! Jacobi SVD written in `crr_dynamics::linalg`, nalgebra's bidiagonal SVD, faer's thin (and full)
//! SVD and faer's column-pivoted QR; and Cholesky of M with one solve (the crate's plain loops,
//! what the engine runs — those loops below `FAER_CHOLESKY_MIN`, faer's from there on —, faer's
//! `llt` allocating and in place, nalgebra's). The table and the decision are in docs/performance.md
//! ("Dense factorisations").
//!
//! Matrices (built outside the timing, at consistent states):
//! - `B`: the equations of motion's B = Φ' L⁻ᵀ (row-scaled Φ_q, M = L Lᵀ), rows × DOF(1), solved
//!   for the minimum-norm B⁺ r at every right-hand side evaluation (`eom/closed_chain_path.rs`);
//! - `Phi`: the row-scaled Φ_q whose null space the impact laws and `mobility_after_step` take;
//! - `M`: the mass matrix of a serial chain of n bodies, n = 2 … 128, and of the models.
//!
//! Before timing, the accuracy of each decomposition on each matrix is printed: the
//! reconstruction error ‖U Σ Vᵀ − A‖/‖A‖, the rank at the engine's threshold, and the residual
//! ‖A x − b‖/‖b‖ of the minimum-norm solve of a consistent b = A x₀.

use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::Solve;
use faer::linalg::svd::ComputeSvdVectors;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{MatRef, Par, Side as FaerSide};
use nalgebra::{DMatrix, DVector};

use crr_dynamics::eom::constraint_row_scale;
use crr_dynamics::linalg::{
    JacobiSvd, RANK_TOLERANCE, cholesky_in_place, cholesky_in_place_unblocked, cholesky_solve,
};
use crr_dynamics::{InitialSpec, solve_initial};
use crr_kinematics::fixtures::{colonnade, four_hinge_arch, serial_chain, trilithon};
use crr_kinematics::{
    ActivePivots, Data, Model, Side, constraint_jacobian, forward_kinematics, mass_matrix,
};

/// The closed chains at a consistent state: name, model, q.
fn models() -> Vec<(&'static str, Model, DVector<f64>)> {
    let tilted = |model: &Model, coord: &str, angle: f64| {
        let spec = InitialSpec {
            angles: BTreeMap::from([(coord.to_string(), angle)]),
            rates: BTreeMap::new(),
        };
        let init = solve_initial(model, &spec).expect("consistent initial state");
        init.q
    };
    let mut out = Vec::new();
    for (name, spec, coord, angle) in [
        (
            "trilithon",
            trilithon(0.25, 1.5, 2.0, 0.5, 1.0),
            "base_left",
            0.05,
        ),
        (
            "four_hinge_arch",
            four_hinge_arch(4.0, 4.6, 1.0, false),
            "springing_right",
            0.02,
        ),
        // 2×2 colonnade: 10 coordinates, 12 closure rows of rank 8.
        ("colonnade", colonnade(0.2, 1.5, 1.2, 0.4), "base_1.1", 0.03),
    ] {
        let model = Model::from_spec(&spec).expect("valid closed chain");
        let q = tilted(&model, coord, angle);
        out.push((name, model, q));
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/baldachin.toml");
    let (file, model) = crr::load_model(&path).expect("bundled baldachin");
    let spec = file.initial.unwrap_or_default();
    let q = solve_initial(&model, &spec)
        .expect("consistent initial state")
        .q;
    out.push(("baldachin", model, q));
    out
}

/// (M, row-scaled Φ_q, B = Φ' L⁻ᵀ) of `model` at `q` (pivots following q).
fn matrices(model: &Model, q: &DVector<f64>) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    pivots.follow_coordinates(q);
    let mut kin = Data::new(model);
    forward_kinematics(model, &mut kin, q, &pivots);
    crr_kinematics::jacobians(model, &mut kin);
    mass_matrix(model, &mut kin);
    constraint_jacobian(model, &mut kin, &pivots);
    let scale = constraint_row_scale(model);
    let phi = DMatrix::from_fn(kin.phi_q.nrows(), kin.phi_q.ncols(), |i, j| {
        scale[i] * kin.phi_q[(i, j)]
    });
    let m = kin.mass_matrix.clone();
    let l = m.clone().cholesky().expect("M positive definite").unpack();
    // Bᵀ = L⁻¹ Φ'ᵀ.
    let bt = l
        .solve_lower_triangular(&phi.transpose())
        .expect("regular L");
    (m, phi, bt.transpose())
}

fn faer_ref(a: &DMatrix<f64>) -> MatRef<'_, f64> {
    MatRef::from_column_major_slice(a.as_slice(), a.nrows(), a.ncols())
}

fn to_nalgebra(a: MatRef<'_, f64>) -> DMatrix<f64> {
    DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)])
}

/// Thin factors (U, σ, V) of A by each SVD.
fn jacobi_factors(a: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>, DMatrix<f64>) {
    let svd = JacobiSvd::new(a);
    let s: Vec<f64> = svd.singular_values.iter().copied().collect();
    let u = DMatrix::from_fn(a.nrows(), s.len(), |i, j| {
        if s[j] > 0.0 {
            svd.w[(i, j)] / s[j]
        } else {
            0.0
        }
    });
    (u, s, svd.v.clone())
}

fn nalgebra_factors(a: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>, DMatrix<f64>) {
    let svd = a.clone().svd(true, true);
    let s = svd.singular_values.iter().copied().collect();
    (svd.u.expect("U"), s, svd.v_t.expect("Vᵀ").transpose())
}

fn faer_factors(a: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>, DMatrix<f64>) {
    let svd = faer_ref(a).thin_svd().expect("faer SVD converges");
    let s = svd.S().column_vector().iter().copied().collect();
    (to_nalgebra(svd.U()), s, to_nalgebra(svd.V()))
}

/// ‖U Σ Vᵀ − A‖/‖A‖, the rank at `relative`·σ_max, and ‖A x − b‖/‖b‖ for x = A⁺ b (b = A x₀).
fn accuracy(
    a: &DMatrix<f64>,
    (u, s, v): (DMatrix<f64>, Vec<f64>, DMatrix<f64>),
    relative: f64,
) -> (f64, usize, f64) {
    let sigma = DMatrix::from_diagonal(&DVector::from_vec(s.clone()));
    let recon = (&u * sigma * v.transpose() - a).norm() / a.norm();
    let tol = relative * s.iter().copied().fold(0.0, f64::max);
    let rank = s.iter().filter(|x| **x > tol).count();
    let x0 = DVector::from_fn(a.ncols(), |i, _| ((i * 7 + 3) % 5) as f64 - 2.0);
    let b = a * x0;
    let mut x = DVector::zeros(a.ncols());
    for (j, &sj) in s.iter().enumerate() {
        if sj > tol {
            x.axpy(u.column(j).dot(&b) / sj, &v.column(j), 1.0);
        }
    }
    let residual = (a * x - &b).norm() / b.norm();
    (recon, rank, residual)
}

fn report_accuracy(name: &str, what: &str, a: &DMatrix<f64>, relative: f64) {
    for (method, f) in [
        (
            "jacobi",
            jacobi_factors as fn(&DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>, DMatrix<f64>),
        ),
        ("nalgebra", nalgebra_factors),
        ("faer", faer_factors),
    ] {
        let (recon, rank, residual) = accuracy(a, f(a), relative);
        eprintln!(
            "accuracy {name} {what} {}x{} {method}: reconstruction {recon:.2e}, rank {rank}, solve residual {residual:.2e}",
            a.nrows(),
            a.ncols()
        );
    }
    let qr = faer_ref(a).col_piv_qr();
    let r = qr.R();
    let d = r.nrows().min(r.ncols());
    let r00 = if d > 0 { r[(0, 0)].abs() } else { 0.0 };
    let rank = (0..d).filter(|&k| r[(k, k)].abs() > relative * r00).count();
    eprintln!("accuracy {name} {what} faer col-piv QR: rank {rank} (|R_kk| > tol |R_00|)");
}

/// The minimum-norm solve of the equations of motion, by each method: decomposition, rank at the
/// engine's threshold, x = B⁺ r.
fn svd_group(c: &mut Criterion) {
    let mut group = c.benchmark_group("svd");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));
    for (name, model, q) in models() {
        let (_, phi, b) = matrices(&model, &q);
        let eom_rel = RANK_TOLERANCE.sqrt();
        report_accuracy(name, "B", &b, eom_rel);
        report_accuracy(name, "Phi", &phi, RANK_TOLERANCE);
        let rhs = DVector::from_fn(b.nrows(), |i, _| 1.0 + i as f64);
        let id = |what: &str| format!("{name}/{what}_{}x{}", b.nrows(), b.ncols());
        group.bench_function(BenchmarkId::new("jacobi_thin", id("B")), |bch| {
            bch.iter(|| {
                let svd = JacobiSvd::thin(black_box(&b));
                let tol = svd.tolerance_relative(eom_rel);
                black_box(svd.solve_with(&rhs, tol))
            })
        });
        group.bench_function(BenchmarkId::new("nalgebra", id("B")), |bch| {
            bch.iter(|| {
                let svd = black_box(&b).clone().svd(true, true);
                let tol = eom_rel * svd.singular_values.max();
                black_box(svd.solve(&rhs, tol).expect("U and V computed"))
            })
        });
        group.bench_function(BenchmarkId::new("faer_thin", id("B")), |bch| {
            bch.iter(|| {
                let svd = faer_ref(black_box(&b)).thin_svd().expect("converges");
                let s = svd.S().column_vector();
                let tol = eom_rel * s[0];
                let (u, v) = (svd.U(), svd.V());
                let mut x = DVector::<f64>::zeros(b.ncols());
                for j in 0..s.nrows() {
                    if s[j] > tol {
                        let coef = (0..u.nrows()).map(|i| u[(i, j)] * rhs[i]).sum::<f64>() / s[j];
                        for i in 0..x.nrows() {
                            x[i] += coef * v[(i, j)];
                        }
                    }
                }
                black_box(x)
            })
        });
        // The same with the workspace and factors allocated once (as a hot path would).
        let k = b.nrows().min(b.ncols());
        let scratch = faer::linalg::svd::svd_scratch::<f64>(
            b.nrows(),
            b.ncols(),
            ComputeSvdVectors::Thin,
            ComputeSvdVectors::Thin,
            Par::Seq,
            Default::default(),
        );
        let mut mem = MemBuffer::new(scratch);
        let mut u = faer::Mat::<f64>::zeros(b.nrows(), k);
        let mut v = faer::Mat::<f64>::zeros(b.ncols(), k);
        let mut s = faer::diag::Diag::<f64>::zeros(k);
        group.bench_function(BenchmarkId::new("faer_thin_in_place", id("B")), |bch| {
            bch.iter(|| {
                faer::linalg::svd::svd(
                    faer_ref(black_box(&b)),
                    s.as_mut(),
                    Some(u.as_mut()),
                    Some(v.as_mut()),
                    Par::Seq,
                    MemStack::new(&mut mem),
                    Default::default(),
                )
                .expect("converges");
                let sv = s.column_vector();
                let tol = eom_rel * sv[0];
                let mut x = DVector::<f64>::zeros(b.ncols());
                for j in 0..k {
                    if sv[j] > tol {
                        let coef = (0..u.nrows()).map(|i| u[(i, j)] * rhs[i]).sum::<f64>() / sv[j];
                        for i in 0..x.nrows() {
                            x[i] += coef * v[(i, j)];
                        }
                    }
                }
                black_box(x)
            })
        });
        group.bench_function(BenchmarkId::new("faer_col_piv_qr", id("B")), |bch| {
            bch.iter(|| {
                let qr = faer_ref(black_box(&b)).col_piv_qr();
                let r = qr.R();
                let d = r.nrows().min(r.ncols());
                let tol = eom_rel * r[(0, 0)].abs();
                black_box((0..d).filter(|&k| r[(k, k)].abs() > tol).count())
            })
        });
        // Null space of Φ' (the impact laws, `mobility_after_step`): the full V.
        let id = format!("{name}/Phi_{}x{}", phi.nrows(), phi.ncols());
        group.bench_function(BenchmarkId::new("jacobi_null_space", &id), |bch| {
            bch.iter(|| black_box(JacobiSvd::new(black_box(&phi)).null_space()))
        });
        group.bench_function(BenchmarkId::new("faer_full_null_space", &id), |bch| {
            bch.iter(|| {
                let svd = faer_ref(black_box(&phi)).svd().expect("converges");
                let s = svd.S().column_vector();
                let tol = RANK_TOLERANCE * s[0];
                let rank = (0..s.nrows()).filter(|&j| s[j] > tol).count();
                black_box(to_nalgebra(svd.V().subcols(rank, phi.ncols() - rank)))
            })
        });
    }
    group.finish();
}

/// L Lᵀ x = b by the plain loops (the substitutions of `linalg` below `FAER_CHOLESKY_MIN`).
fn substitute_unblocked(l: &DMatrix<f64>, b: &mut [f64]) {
    let n = l.nrows();
    for i in 0..n {
        let s = b[i] - (0..i).map(|k| l[(i, k)] * b[k]).sum::<f64>();
        b[i] = s / l[(i, i)];
    }
    for i in (0..n).rev() {
        let s = b[i] - (i + 1..n).map(|k| l[(k, i)] * b[k]).sum::<f64>();
        b[i] = s / l[(i, i)];
    }
}

/// Cholesky factorisation and one solve of M x = b.
fn cholesky_group(c: &mut Criterion) {
    let mut group = c.benchmark_group("cholesky");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));
    let mut cases: Vec<(String, DMatrix<f64>)> = [2usize, 4, 8, 16, 32, 64, 128]
        .into_iter()
        .map(|n| {
            let model = Model::from_spec(&serial_chain(n)).expect("valid serial chain");
            let q = DVector::from_fn(n, |k, _| 0.3 * ((k + 1) as f64).sin());
            let mut pivots = ActivePivots::uniform(&model, Side::Positive);
            pivots.follow_coordinates(&q);
            let mut kin = Data::new(&model);
            forward_kinematics(&model, &mut kin, &q, &pivots);
            crr_kinematics::jacobians(&model, &mut kin);
            mass_matrix(&model, &mut kin);
            (format!("chain_{n}"), kin.mass_matrix.clone())
        })
        .collect();
    for (name, model, q) in models() {
        cases.push((format!("{name}_{}", model.dof()), matrices(&model, &q).0));
    }
    for (name, m) in cases {
        let n = m.nrows();
        let rhs = DVector::from_fn(n, |i, _| 1.0 + i as f64);
        let mut work = m.clone();
        group.bench_function(BenchmarkId::new("hand_written", &name), |bch| {
            bch.iter(|| {
                work.copy_from(black_box(&m));
                cholesky_in_place_unblocked(&mut work).expect("positive definite");
                let mut x = rhs.clone();
                substitute_unblocked(&work, x.as_mut_slice());
                black_box(x)
            })
        });
        // What the engine runs: the loops below FAER_CHOLESKY_MIN, faer from there on.
        group.bench_function(BenchmarkId::new("crr", &name), |bch| {
            bch.iter(|| {
                work.copy_from(black_box(&m));
                cholesky_in_place(&mut work).expect("positive definite");
                let mut x = rhs.clone();
                cholesky_solve(&work, x.as_mut_slice());
                black_box(x)
            })
        });
        group.bench_function(BenchmarkId::new("faer_llt", &name), |bch| {
            bch.iter(|| {
                let llt = faer_ref(black_box(&m))
                    .llt(FaerSide::Lower)
                    .expect("positive definite");
                let mut x = rhs.clone();
                llt.solve_in_place(faer::MatMut::from_column_major_slice_mut(
                    x.as_mut_slice(),
                    n,
                    1,
                ));
                black_box(x)
            })
        });
        // faer's in-place factorisation and triangular solves on the caller's storage.
        let mut mem = MemBuffer::new(
            faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(
                n,
                Par::Seq,
                Default::default(),
            ),
        );
        group.bench_function(BenchmarkId::new("faer_llt_in_place", &name), |bch| {
            bch.iter(|| {
                work.copy_from(black_box(&m));
                let mut l = faer::MatMut::from_column_major_slice_mut(work.as_mut_slice(), n, n);
                faer::linalg::cholesky::llt::factor::cholesky_in_place(
                    l.as_mut(),
                    Default::default(),
                    Par::Seq,
                    MemStack::new(&mut mem),
                    Default::default(),
                )
                .expect("positive definite");
                let mut x = rhs.clone();
                let mut xm = faer::MatMut::from_column_major_slice_mut(x.as_mut_slice(), n, 1);
                let l = l.as_ref();
                solve_lower_triangular_in_place(l, xm.as_mut(), Par::Seq);
                solve_upper_triangular_in_place(l.transpose(), xm.as_mut(), Par::Seq);
                black_box(x)
            })
        });
        group.bench_function(BenchmarkId::new("nalgebra", &name), |bch| {
            bch.iter(|| {
                let chol = black_box(&m).clone().cholesky().expect("positive definite");
                black_box(chol.solve(&rhs))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, svd_group, cholesky_group);
criterion_main!(benches);
