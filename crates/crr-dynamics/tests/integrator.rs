//! Tests of the ODE integrators: convergence orders, dense output, adaptive
//! accuracy, event location, restart semantics, breakpoints and errors.

use crr_dynamics::integrator::{
    DenseStep, Direction, EventFunctions, Method, NoEvents, OdeSystem, Options, RhsError,
    SolveError, Solver, StepEnds, Stop,
};
use std::f64::consts::PI;

use crr_dynamics::Cancel;

// ------------------------------------------------------------------ systems

/// x' = v, v' = -x; from (1, 0): x = cos t, v = -sin t.
struct Oscillator;
impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        dydt[0] = y[1];
        dydt[1] = -y[0];
        Ok(())
    }
}

/// Non-autonomous scalar problem y' = y cos t with solution exp(sin t)
/// (for y(0) = 1): no special symmetry that could hide error terms.
struct ExpSin;
impl OdeSystem for ExpSin {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        dydt[0] = y[0] * t.cos();
        Ok(())
    }
}

/// Rocking block (Housner): θ'' = -p² sin(α sgn θ - θ), state (θ, θ').
struct Block {
    p: f64,
    alpha: f64,
}
impl OdeSystem for Block {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        let s = if y[0] > 0.0 {
            1.0
        } else if y[0] < 0.0 {
            -1.0
        } else {
            y[1].signum()
        };
        dydt[0] = y[1];
        dydt[1] = -self.p * self.p * (self.alpha * s - y[0]).sin();
        Ok(())
    }
}

/// One event function g = y[component].
struct Zero {
    component: usize,
    dir: Direction,
}
impl EventFunctions for Zero {
    fn count(&self) -> usize {
        1
    }
    fn eval(&mut self, _t: f64, y: &[f64], g: &mut [f64]) {
        g[0] = y[self.component];
    }
    fn direction(&self, _i: usize) -> Direction {
        self.dir
    }
}

// ------------------------------------------------------------------ helpers

/// Options that force a fixed step `h` on the adaptive methods: the
/// tolerance is so loose that every step is accepted and `h_max = h`.
fn fixed(h: f64) -> Options {
    Options {
        rtol: 1e6,
        atol: 1e6,
        h_init: Some(h),
        h_max: h,
        max_steps: 10_000_000,
    }
}

fn method_fixed(m: &str, h: f64) -> (Method, Options) {
    match m {
        "dop853" => (Method::Dop853, fixed(h)),
        "dopri5" => (Method::Dopri5, fixed(h)),
        _ => (Method::Rk4 { step: h }, Options::default()),
    }
}

/// Least-squares slope of log(err) against log(h).
fn slope(hs: &[f64], errs: &[f64]) -> f64 {
    let n = hs.len() as f64;
    let xs: Vec<f64> = hs.iter().map(|h| h.ln()).collect();
    let ys: Vec<f64> = errs.iter().map(|e| e.ln()).collect();
    let mx = xs.iter().sum::<f64>() / n;
    let my = ys.iter().sum::<f64>() / n;
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    sxy / sxx
}

fn ignore(_: &DenseStep) {}

/// Global error at t = 2 of y' = y cos t, y(0) = 1 with fixed step h.
fn global_error(m: &str, h: f64) -> f64 {
    let (method, opts) = method_fixed(m, h);
    let mut s = Solver::new(method, opts, 1).unwrap();
    s.reset(0.0, &[1.0]);
    let stop = s
        .advance(&mut ExpSin, 2.0, &mut NoEvents, &mut ignore)
        .unwrap();
    assert_eq!(stop, Stop::Reached);
    (s.y()[0] - 2f64.sin().exp()).abs()
}

// ------------------------------------------------------------------ orders

#[test]
fn observed_orders_of_the_methods() {
    // Step sizes chosen so the global errors stay well above round-off
    // (≥ 1e-13) and in the asymptotic regime; see the printed values.
    // All h divide the interval [0, 2] exactly (no shortened last step).
    let cases: [(&str, f64, [f64; 4]); 3] = [
        ("dop853", 8.0, [0.5, 0.4, 0.25, 0.2]),
        ("dopri5", 5.0, [0.2, 0.1, 0.05, 0.025]),
        ("rk4", 4.0, [0.1, 0.05, 0.025, 0.0125]),
    ];
    for (m, p, hs) in cases {
        let errs: Vec<f64> = hs.iter().map(|&h| global_error(m, h)).collect();
        let q = slope(&hs, &errs);
        println!("{m}: h = {hs:?}, err = {errs:?}, observed order = {q:.3}");
        assert!(
            errs.iter().all(|&e| e > 1e-13),
            "{m}: errors near round-off"
        );
        assert!((q - p).abs() < 0.3, "{m}: observed order {q} vs {p}");
    }
}

#[test]
fn dense_output_orders() {
    // One step of size h from t0 = 0.3; interpolation error at mid-step.
    // A dense output of order q has a local error O(h^{q+1}), which
    // dominates the step's own local error O(h^{p+1}) (p > q), so the
    // measured slope is q + 1: 8 (DOP853), 5 (Dopri5), 4 (cubic Hermite).
    let t0 = 0.3;
    let exact = |t: f64| t.sin().exp();
    let cases: [(&str, f64, [f64; 4]); 3] = [
        ("dop853", 7.0, [0.8, 0.4, 0.2, 0.1]),
        ("dopri5", 4.0, [0.2, 0.1, 0.05, 0.025]),
        ("rk4", 3.0, [0.2, 0.1, 0.05, 0.025]),
    ];
    for (m, q, hs) in cases {
        let mut errs = Vec::new();
        for &h in &hs {
            let (method, opts) = method_fixed(m, h);
            let mut s = Solver::new(method, opts, 1).unwrap();
            s.reset(t0, &[exact(t0)]);
            let mut mid = f64::NAN;
            let mut calls = 0;
            s.advance(&mut ExpSin, t0 + h, &mut NoEvents, &mut |d: &DenseStep| {
                calls += 1;
                mid = d.eval_component(0.5 * (d.t0() + d.t1()), 0);
            })
            .unwrap();
            assert_eq!(calls, 1);
            errs.push((mid - exact(t0 + 0.5 * h)).abs());
        }
        let obs = slope(&hs, &errs);
        println!("{m} dense: h = {hs:?}, mid-step err = {errs:?}, slope = {obs:.3}");
        assert!(errs.iter().all(|&e| e > 1e-14));
        assert!(
            (obs - (q + 1.0)).abs() < 0.3,
            "{m}: dense slope {obs} vs {}",
            q + 1.0
        );
    }
}

/// The three readings of a step's interpolant (the whole state, one component, one component's
/// gathered polynomial) are the same polynomial evaluated in the same order, so they agree to the
/// last bit; the samples and the peak bisection of a simulation rely on it. Each also stays within
/// the error control's tolerance of the exact solution cos t, sin t … (checked loosely, 1e-6, as
/// in `dense_output_interpolates_step_ends`).
#[test]
fn dense_output_readings_agree_to_the_last_bit() {
    for method in [Method::Dop853, Method::Dopri5, Method::Rk4 { step: 0.05 }] {
        let mut s = Solver::new(method, Options::default(), 2).unwrap();
        s.reset(0.0, &[1.0, 0.0]);
        let mut buf = [0.0; 2];
        let mut checked = 0usize;
        s.advance(&mut Oscillator, 3.0, &mut NoEvents, &mut |d: &DenseStep| {
            let polys = [d.component(0), d.component(1)];
            for f in [0.0, 0.13, 0.5, 0.77, 1.0] {
                let t = d.t0() + f * (d.t1() - d.t0());
                d.eval(t, &mut buf);
                for i in 0..2 {
                    assert_eq!(buf[i].to_bits(), d.eval_component(t, i).to_bits());
                    assert_eq!(buf[i].to_bits(), polys[i].eval(t).to_bits());
                }
                assert!((buf[0] - t.cos()).abs() < 1e-6 && (buf[1] + t.sin()).abs() < 1e-6);
                checked += 1;
            }
        })
        .unwrap();
        assert!(checked >= 5, "{method:?}");
    }
}

/// Pendulums θ̈ = −ωₖ² sin θ side by side, state [θ₀, θ̇₀, θ₁, θ̇₁, …]: each pair's right-hand
/// side reads only its own pair.
struct Pendulums(Vec<f64>);
impl OdeSystem for Pendulums {
    fn dim(&self) -> usize {
        2 * self.0.len()
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        for (k, w) in self.0.iter().enumerate() {
            dydt[2 * k] = y[2 * k + 1];
            dydt[2 * k + 1] = -w * w * y[2 * k].sin();
        }
        Ok(())
    }
}

/// The stage sums and the dense output of the small dimensions (4, 6 and 8, the systems of one
/// to three coordinates) run on code of their own, with the partial sums in registers; every
/// other dimension on the general loops. Component by component both make the same operations in
/// the same order, so at a fixed step a set of independent pendulums integrated together (4, 6,
/// 8 and 10 components) gives each pendulum's state, step ends and interpolant, to the last bit
/// of the same pendulum integrated alone (2 components, the general code).
#[test]
fn small_dimensions_agree_with_the_general_code_to_the_last_bit() {
    let omegas = [1.0, 1.7, 0.6, 2.3, 1.2];
    let starts = [0.9, -0.4, 1.3, 0.2, -1.1];
    let run = |ws: &[f64], y0: &[f64], method: Method, opts: Options| {
        let mut s = Solver::new(method, opts, y0.len()).unwrap();
        s.reset(0.0, y0);
        let mut readings = Vec::new();
        let mut buf = vec![0.0; y0.len()];
        s.advance(
            &mut Pendulums(ws.to_vec()),
            2.0,
            &mut NoEvents,
            &mut |d: &DenseStep| {
                for f in [0.0, 0.3, 0.71, 1.0] {
                    d.eval(d.t0() + f * (d.t1() - d.t0()), &mut buf);
                    readings.push(buf.clone());
                }
            },
        )
        .unwrap();
        (s.y().to_vec(), readings)
    };
    for m in ["dop853", "dopri5", "rk4"] {
        let (method, opts) = method_fixed(m, 0.1);
        for n in 2..=5 {
            let y0: Vec<f64> = starts[..n].iter().flat_map(|&x| [x, 0.0]).collect();
            let (together, readings) = run(&omegas[..n], &y0, method, opts);
            assert_eq!(readings.len(), 4 * 20, "{m}, {n} pendulums: 20 steps");
            for k in 0..n {
                let (alone, alone_readings) = run(&omegas[k..=k], &[starts[k], 0.0], method, opts);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    bits(&together[2 * k..2 * k + 2]),
                    bits(&alone),
                    "{m}, {n}: {k}"
                );
                for (r, a) in readings.iter().zip(&alone_readings) {
                    assert_eq!(bits(&r[2 * k..2 * k + 2]), bits(a), "{m}, {n}: {k}");
                }
            }
        }
    }
}

#[test]
fn dense_output_interpolates_step_ends() {
    // RK4 global error ≈ t·h⁴/120 ≈ 2e-7 for h = 0.05 on [0, 3].
    for method in [Method::Dop853, Method::Dopri5, Method::Rk4 { step: 0.05 }] {
        let mut s = Solver::new(method, Options::default(), 2).unwrap();
        s.reset(0.0, &[1.0, 0.0]);
        let mut worst: f64 = 0.0;
        let mut prev_end = vec![1.0, 0.0];
        let mut buf = [0.0; 2];
        s.advance(&mut Oscillator, 3.0, &mut NoEvents, &mut |d: &DenseStep| {
            d.eval(d.t0(), &mut buf);
            // Continuity: the start of this step's interpolant (the exact
            // state) equals the end of the previous one up to the rounding
            // of y0 + (y1 - y0).
            for (a, b) in buf.iter().zip(&prev_end) {
                assert!((a - b).abs() <= 4.0 * f64::EPSILON, "{a} vs {b}");
            }
            d.eval(d.t1(), &mut buf);
            prev_end = buf.to_vec();
            worst = worst.max((buf[0] - d.t1().cos()).abs());
        })
        .unwrap();
        // The end value of the interpolant equals the new state up to
        // rounding of (y0 + (y1 - y0)).
        assert!((prev_end[0] - s.y()[0]).abs() <= 4.0 * f64::EPSILON);
        assert!(worst < 1e-6, "{method:?}: {worst}");
    }
}

// ------------------------------------------------------------------ adaptive

#[test]
fn adaptive_accuracy_on_oscillator() {
    for method in [Method::Dop853, Method::Dopri5] {
        let opts = Options {
            rtol: 1e-10,
            atol: 1e-10,
            ..Options::default()
        };
        let mut s = Solver::new(method, opts, 2).unwrap();
        s.reset(0.0, &[1.0, 0.0]);
        let mut max_drift: f64 = 0.0;
        let mut buf = [0.0; 2];
        s.advance(
            &mut Oscillator,
            10.0,
            &mut NoEvents,
            &mut |d: &DenseStep| {
                d.eval(d.t1(), &mut buf);
                let e = 0.5 * (buf[0] * buf[0] + buf[1] * buf[1]);
                max_drift = max_drift.max((e - 0.5).abs());
            },
        )
        .unwrap();
        assert_eq!(s.t(), 10.0);
        let err = (s.y()[0] - 10f64.cos())
            .abs()
            .max((s.y()[1] + 10f64.sin()).abs());
        let st = s.stats();
        println!("{method:?}: err(10) = {err:e}, energy drift = {max_drift:e}, {st:?}");
        // Global error ~ (number of steps) × tolerance-level local errors.
        assert!(err < 1e-8, "{method:?}: {err}");
        assert!(max_drift < 1e-8, "{method:?}: {max_drift}");
        assert_eq!(st.steps, st.accepted + st.rejected);
    }
}

#[test]
fn dopri5_rhs_count_uses_fsal() {
    let mut s = Solver::new(Method::Dopri5, fixed(0.1), 2).unwrap();
    s.reset(0.0, &[1.0, 0.0]);
    s.advance(&mut Oscillator, 1.0, &mut NoEvents, &mut ignore)
        .unwrap();
    let st = s.stats();
    assert_eq!(st.accepted, 10);
    // 1 initial derivative + 6 new stages per step (the 7th is reused).
    assert_eq!(st.rhs_evals, 1 + 6 * 10);
}

// ------------------------------------------------------------------ events

#[test]
fn event_location_on_cosine() {
    let opts = Options {
        rtol: 1e-12,
        atol: 1e-14,
        ..Options::default()
    };
    let mut s = Solver::new(Method::Dop853, opts, 2).unwrap();
    s.reset(0.0, &[1.0, 0.0]);
    let mut ev = Zero {
        component: 0,
        dir: Direction::Falling,
    };
    let mut last_t1 = 0.0;
    let stop = s
        .advance(&mut Oscillator, 10.0, &mut ev, &mut |d: &DenseStep| {
            last_t1 = d.t1()
        })
        .unwrap();
    let Stop::Event { index, t } = stop else {
        panic!("no event: {stop:?}")
    };
    assert_eq!(index, 0);
    assert_eq!(s.t(), t);
    assert_eq!(
        last_t1, t,
        "the partial step ending at the event is emitted"
    );
    assert!(
        (t - PI / 2.0).abs() < 1e-12,
        "t* - π/2 = {:e}",
        t - PI / 2.0
    );
    // State from a real step: g(y(t*)) is at the root-finder resolution
    // (|Δt| ≤ 1e-13 times |g'| = 1) plus the global error (~1e-13).
    assert!(s.y()[0].abs() <= 1e-12, "g(y(t*)) = {:e}", s.y()[0]);
    assert!((s.y()[1] + 1.0).abs() < 1e-12);
}

#[test]
fn event_state_comes_from_a_real_step() {
    // Loose tolerance: the interpolant and a step differ noticeably; the
    // solver state at the event must be bitwise that of a genuine step of
    // the method from the last step's start to t*.
    let opts = Options {
        rtol: 1e-4,
        atol: 1e-6,
        ..Options::default()
    };
    for method in [Method::Dop853, Method::Dopri5, Method::Rk4 { step: 0.3 }] {
        let mut s = Solver::new(method, opts, 2).unwrap();
        s.reset(0.0, &[1.0, 0.0]);
        let mut ev = Zero {
            component: 0,
            dir: Direction::Any,
        };
        let mut start = (0.0, [0.0; 2]);
        let stop = s
            .advance(&mut Oscillator, 10.0, &mut ev, &mut |d: &DenseStep| {
                let mut y = [0.0; 2];
                d.eval(d.t0(), &mut y);
                start = (d.t0(), y);
            })
            .unwrap();
        let Stop::Event { t, .. } = stop else {
            panic!()
        };
        // The same step, taken by a fresh solver forced to one step.
        let h = t - start.0;
        let (m2, o2) = match method {
            Method::Rk4 { .. } => (Method::Rk4 { step: h }, Options::default()),
            m => (m, fixed(h)),
        };
        let mut fresh = Solver::new(m2, o2, 2).unwrap();
        fresh.reset(start.0, &start.1);
        fresh
            .advance(&mut Oscillator, t, &mut NoEvents, &mut ignore)
            .unwrap();
        assert_eq!(fresh.t(), t);
        assert_eq!(fresh.y(), s.y(), "{method:?}");
        assert!((t - PI / 2.0).abs() < 1e-3);
    }
}

/// Exact time for the block released at rest from θ0 (0 < θ0 < α) to reach
/// θ = 0: T = ∫_0^θ0 dθ / |θ'| with θ'² = 2p²(cos(α-θ0) - cos(α-θ)).
/// Substituting θ = θ0 - u² removes the endpoint singularity:
/// T = ∫_0^{√θ0} u du / (p √(sin(a + u²/2) sin(u²/2))), a = α - θ0,
/// using cos A - cos B = 2 sin((A+B)/2) sin((B-A)/2) to avoid cancellation.
/// The integrand is analytic; composite Gauss–Legendre converges fast.
fn block_quadrature(p: f64, alpha: f64, theta0: f64, panels: usize) -> f64 {
    let a = alpha - theta0;
    let f = |u: f64| {
        if u == 0.0 {
            (2.0 / a.sin()).sqrt() / p
        } else {
            u / (p * ((a + 0.5 * u * u).sin() * (0.5 * u * u).sin()).sqrt())
        }
    };
    let gl = gauss_legendre(20);
    let len = theta0.sqrt() / panels as f64;
    let mut sum = 0.0;
    for k in 0..panels {
        let (lo, hi) = (k as f64 * len, (k + 1) as f64 * len);
        for &(x, w) in &gl {
            sum += 0.5 * (hi - lo) * w * f(0.5 * (hi + lo) + 0.5 * (hi - lo) * x);
        }
    }
    sum
}

/// Nodes and weights of n-point Gauss–Legendre quadrature on [-1, 1].
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let k = k as f64;
                    let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

fn block_solver() -> Solver {
    let opts = Options {
        rtol: 1e-12,
        atol: 1e-14,
        ..Options::default()
    };
    Solver::new(Method::Dop853, opts, 2).unwrap()
}

#[test]
fn rocking_block_first_impact_matches_quadrature() {
    let (p, alpha) = (2.0, 0.2);
    let theta0 = alpha / 2.0;
    let t_exact = block_quadrature(p, alpha, theta0, 8);
    let t_check = block_quadrature(p, alpha, theta0, 16);
    assert!(
        (t_exact - t_check).abs() < 1e-14,
        "quadrature not converged"
    );
    let mut s = block_solver();
    s.reset(0.0, &[theta0, 0.0]);
    let mut ev = Zero {
        component: 0,
        dir: Direction::Falling,
    };
    let stop = s
        .advance(&mut Block { p, alpha }, 10.0, &mut ev, &mut ignore)
        .unwrap();
    let Stop::Event { index: 0, t } = stop else {
        panic!("{stop:?}")
    };
    println!("block impact: t* = {t:.15}, quadrature = {t_exact:.15}");
    assert!((t - t_exact).abs() < 1e-10, "Δt = {:e}", t - t_exact);
    // Energy: θ'² = 2p²(cos(α-θ0) - cos α) at θ = 0.
    let v_exact = -(2.0 * p * p * ((alpha - theta0).cos() - alpha.cos())).sqrt();
    assert!((s.y()[1] - v_exact).abs() < 1e-10);
}

/// Each step's record: its end time, its end state, and (where its dense output was read) the
/// interpolant at three fractions of the step, all as bits.
type StepRecord = (u64, Vec<u64>, Option<Vec<u64>>);

/// Reads three points of a step's interpolant (both states' components), as bits.
fn dense_readings(d: &DenseStep) -> Vec<u64> {
    let mut buf = [0.0; 2];
    let mut out = Vec::new();
    for f in [0.25, 0.5, 0.9] {
        d.eval(d.t0() + f * (d.t1() - d.t0()), &mut buf);
        out.extend(buf.iter().map(|x| x.to_bits()));
    }
    out
}

/// The lazy dense output changes nothing but the work: on the rocking block to its first impact
/// (an event located inside a step) and then on free flight of the oscillator, DOP853 with the
/// dense output read on every third step only gives the same steps, the same end states, the
/// same event time and the same interpolant on the steps read, to the last bit, as the solver
/// that computes it on every step; and each step not read and not holding an event saves
/// DOP853's three extra stages exactly (its dense output needs stages 14–16 of Hairer's 16,
/// which the error-controlled step does not).
#[test]
fn the_lazy_dense_output_changes_no_bit_and_saves_three_stages_per_unread_step() {
    let (p, alpha) = (2.0, 0.2);
    let run = |lazy: bool| {
        let mut s = block_solver();
        s.reset(0.0, &[alpha / 2.0, 0.0]);
        let mut ev = Zero {
            component: 0,
            dir: Direction::Falling,
        };
        let mut steps: Vec<StepRecord> = Vec::new();
        let mut count = 0usize;
        let mut wants = |_: &StepEnds| {
            count += 1;
            !lazy || count.is_multiple_of(3)
        };
        let mut record = |ends: &StepEnds, d: Option<&DenseStep>| {
            steps.push((
                ends.t1.to_bits(),
                ends.y1.iter().map(|x| x.to_bits()).collect(),
                d.map(dense_readings),
            ));
        };
        let block = &mut Block { p, alpha };
        let stop = s
            .advance_lazily(block, 10.0, &mut ev, &mut wants, &mut record)
            .unwrap();
        let Stop::Event { t: t_impact, .. } = stop else {
            panic!("{stop:?}")
        };
        // Free flight after it: no events, 3 s of the oscillator from the same start.
        let mut free = Solver::new(Method::Dop853, Options::default(), 2).unwrap();
        free.reset(0.0, &[1.0, 0.0]);
        free.advance_lazily(&mut Oscillator, 3.0, &mut NoEvents, &mut wants, &mut record)
            .unwrap();
        let free_y: Vec<u64> = free.y().iter().map(|x| x.to_bits()).collect();
        (t_impact.to_bits(), steps, free_y, s.stats(), free.stats())
    };
    let (t_every, steps_every, y_every, block_every, free_every) = run(false);
    let (t_lazy, steps_lazy, y_lazy, block_lazy, free_lazy) = run(true);
    assert_eq!(t_every, t_lazy, "the impact's time");
    assert_eq!(y_every, y_lazy, "the free flight's end state");
    assert_eq!(steps_every.len(), steps_lazy.len());
    let mut read = 0;
    for (every, lazy) in steps_every.iter().zip(&steps_lazy) {
        assert_eq!((every.0, &every.1), (lazy.0, &lazy.1), "a step's end");
        if let Some(readings) = &lazy.2 {
            assert_eq!(Some(readings), every.2.as_ref(), "a step's interpolant");
            read += 1;
        }
    }
    assert!(
        read >= 3 && read < steps_lazy.len() / 2,
        "{read} steps read"
    );
    // Free flight: no event, so every unread step saved exactly three evaluations.
    let unread = free_lazy.accepted
        - steps_lazy
            .iter()
            .rev()
            .take(free_lazy.accepted)
            .filter(|s| s.2.is_some())
            .count();
    assert_eq!(free_every.accepted, free_lazy.accepted);
    assert_eq!(free_every.rhs_evals - free_lazy.rhs_evals, 3 * unread);
    // The block: the step holding the impact computes its interpolant to locate it.
    assert_eq!(block_every.accepted, block_lazy.accepted);
    assert!(block_lazy.rhs_evals < block_every.rhs_evals);
}

#[test]
fn no_refire_after_restart_at_event() {
    // After the impact, restart with θ = 0 exactly and the velocity
    // reversed (perfectly elastic). By symmetry the block rises to θ0 and
    // falls back: the next crossing is at t* + 2T, not at t*.
    let (p, alpha) = (2.0, 0.2);
    let theta0 = alpha / 2.0;
    let big_t = block_quadrature(p, alpha, theta0, 8);
    for exact_zero in [true, false] {
        let mut s = block_solver();
        s.reset(0.0, &[theta0, 0.0]);
        let mut sys = Block { p, alpha };
        let mut ev = Zero {
            component: 0,
            dir: Direction::Any,
        };
        let Stop::Event { t: t1, .. } = s.advance(&mut sys, 10.0, &mut ev, &mut ignore).unwrap()
        else {
            panic!()
        };
        // Either θ = 0 exactly, or the solver's own (tiny, post-crossing)
        // θ: both must not re-fire at t1.
        let theta = if exact_zero { 0.0 } else { s.y()[0] };
        let v = -s.y()[1];
        s.reset(t1, &[theta, v]);
        let Stop::Event { t: t2, .. } = s.advance(&mut sys, 10.0, &mut ev, &mut ignore).unwrap()
        else {
            panic!()
        };
        println!(
            "restart (θ exactly 0: {exact_zero}): t2 - t1 = {:.15}",
            t2 - t1
        );
        assert!(t2 - t1 > big_t, "re-fired at {t2} after {t1}");
        assert!(
            (t2 - (t1 + 2.0 * big_t)).abs() < 1e-9,
            "t2 - t1 - 2T = {:e}",
            t2 - t1 - 2.0 * big_t
        );
    }
}

#[test]
fn no_refire_when_advancing_again_without_reset() {
    // Calling advance again at an event time must continue to the next
    // crossing of cos t (3π/2), not stop again at π/2.
    let mut s = Solver::new(Method::Dopri5, Options::default(), 2).unwrap();
    s.reset(0.0, &[1.0, 0.0]);
    let mut ev = Zero {
        component: 0,
        dir: Direction::Any,
    };
    let mut times = Vec::new();
    for _ in 0..3 {
        match s
            .advance(&mut Oscillator, 10.0, &mut ev, &mut ignore)
            .unwrap()
        {
            Stop::Event { t, .. } => times.push(t),
            Stop::Reached => break,
        }
    }
    for (k, t) in times.iter().enumerate() {
        let expect = PI / 2.0 + k as f64 * PI;
        assert!((t - expect).abs() < 1e-7, "event {k}: {t} vs {expect}");
    }
    assert_eq!(times.len(), 3);
}

/// Two event functions: g0 = x - 0.5 (falling), g1 = v + 0.9 (falling);
/// both cross within the same step at large tolerance. The earliest wins.
struct Two;
impl EventFunctions for Two {
    fn count(&self) -> usize {
        2
    }
    fn eval(&mut self, _t: f64, y: &[f64], g: &mut [f64]) {
        g[0] = y[1] + 0.9;
        g[1] = y[0] - 0.5;
    }
    fn direction(&self, _i: usize) -> Direction {
        Direction::Falling
    }
}

#[test]
fn earliest_of_several_events_wins() {
    // cos t = 0.5 at π/3 ≈ 1.047; -sin t = -0.9 at asin 0.9 ≈ 1.120.
    let mut s = Solver::new(Method::Rk4 { step: 0.5 }, Options::default(), 2).unwrap();
    s.reset(0.0, &[1.0, 0.0]);
    let stop = s
        .advance(&mut Oscillator, 10.0, &mut Two, &mut ignore)
        .unwrap();
    let Stop::Event { index, t } = stop else {
        panic!()
    };
    assert_eq!(index, 1);
    // RK4 with h = 0.5: the dense output's error is of order h⁴/24 of the solution's fourth
    // derivative, 0.0026 here (measured: 3.5e-4 on this root, 1.0e-3 on the next); 1e-2 bounds
    // it with room.
    assert!((t - PI / 3.0).abs() < 1e-2, "{t}");
    let stop = s
        .advance(&mut Oscillator, 10.0, &mut Two, &mut ignore)
        .unwrap();
    let Stop::Event { index, t } = stop else {
        panic!()
    };
    assert_eq!(index, 0);
    assert!((t - 0.9f64.asin()).abs() < 1e-2, "{t}");
}

/// g = x + `DIP_LEVEL` on the oscillator's x = cos t, falling: below zero only for
/// |t − π| < acos(`DIP_LEVEL`) ≈ 0.0316, a dip well inside one step of 0.5 ([3.0, 3.5], where
/// g = 0.0095 and 0.063) or of 0.25 ([3.0, 3.25], g = 0.0095 and 0.0055), whose ends are both
/// positive.
struct Dip {
    inside: bool,
}
const DIP_LEVEL: f64 = 0.9995;
impl EventFunctions for Dip {
    fn count(&self) -> usize {
        1
    }
    fn eval(&mut self, _t: f64, y: &[f64], g: &mut [f64]) {
        g[0] = y[0] + DIP_LEVEL;
    }
    fn direction(&self, _i: usize) -> Direction {
        Direction::Falling
    }
    fn checked_inside(&self, _i: usize) -> bool {
        self.inside
    }
}

#[test]
fn a_crossing_and_its_return_inside_one_step_fire_where_the_function_is_checked_inside() {
    // The first root of cos t + 0.9995 = 0, in closed form.
    let root = PI - DIP_LEVEL.acos();
    // RK4 with steps of 0.5 errs by about 1e-3 in x over these 3 s, more than the dip is deep
    // (5e-4): its solution does not dip at all; with 0.25 it errs 16 times less.
    for (m, h) in [("dop853", 0.5), ("dopri5", 0.5), ("rk4", 0.25)] {
        let run = |inside: bool| {
            let (method, opts) = method_fixed(m, h);
            let mut s = Solver::new(method, opts, 2).unwrap();
            s.reset(0.0, &[1.0, 0.0]);
            let stop = s
                .advance(&mut Oscillator, 4.0, &mut Dip { inside }, &mut ignore)
                .unwrap();
            (stop, s.y().to_vec())
        };
        // Read at the steps' ends only, the dip is stepped over.
        assert!(matches!(run(false).0, Stop::Reached), "{m}");
        let (stop, y) = run(true);
        let Stop::Event { index: 0, t } = stop else {
            panic!("{m}: {stop:?}")
        };
        // The interpolant's error in x over a step of 0.5 (DOP853's seventh-order dense output
        // about 1e-8, Dopri5's fourth-order one and RK4's cubic about 1e-4 of |x| ≤ 1) over the
        // slope |g'| = sin t* = 0.0316 at the root: at most 3e-7 s and 3e-3 s.
        let tolerance = if m == "dop853" { 3e-7 } else { 3e-3 };
        assert!(
            (t - root).abs() < tolerance,
            "{m}: t* − root = {:e}",
            t - root
        );
        // The state is a real step's (to t*): on the dip's falling side, g within the step's
        // error of 0.
        assert!(
            (y[0] + DIP_LEVEL).abs() < 1e-4,
            "{m}: g = {:e}",
            y[0] + DIP_LEVEL
        );
        // Before π, where x = cos t still falls (v = −sin t < 0): the first root, not the second.
        assert!(y[1] < 0.0, "{m}: v = {}", y[1]);
    }
}

// ------------------------------------------------------------------ breakpoints

#[test]
fn lands_exactly_on_breakpoints() {
    for method in [Method::Dop853, Method::Dopri5, Method::Rk4 { step: 0.003 }] {
        let mut s = Solver::new(method, Options::default(), 2).unwrap();
        s.reset(0.0, &[1.0, 0.0]);
        let mut last_t1 = 0.0;
        let mut prev_t1 = 0.0;
        for k in 1..=200 {
            let bp = 0.01 * k as f64 + if k % 7 == 0 { 1e-9 } else { 0.0 };
            let stop = s
                .advance(&mut Oscillator, bp, &mut NoEvents, &mut |d: &DenseStep| {
                    assert_eq!(d.t0(), prev_t1, "steps are contiguous");
                    assert!(d.t1() <= bp, "stepped past the breakpoint");
                    prev_t1 = d.t1();
                    last_t1 = d.t1();
                })
                .unwrap();
            assert_eq!(stop, Stop::Reached);
            assert_eq!(s.t(), bp);
            assert_eq!(last_t1, bp);
        }
        assert!((s.y()[0] - s.t().cos()).abs() < 1e-8, "{method:?}");
        // Advancing to the current time is a no-op.
        let before = s.stats();
        assert_eq!(
            s.advance(&mut Oscillator, s.t(), &mut NoEvents, &mut ignore),
            Ok(Stop::Reached)
        );
        assert_eq!(s.stats(), before);
    }
}

// ------------------------------------------------------------------ errors

struct NanAfter(f64);
impl OdeSystem for NanAfter {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, _y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        dydt[0] = if t > self.0 { f64::NAN } else { 1.0 };
        Ok(())
    }
}

struct FailAfter(f64);
impl OdeSystem for FailAfter {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, _y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        if t > self.0 {
            return Err(RhsError("mechanism locked".into()));
        }
        dydt[0] = 1.0;
        Ok(())
    }
}

#[test]
fn nan_rhs_is_an_error_naming_t() {
    for method in [Method::Dop853, Method::Dopri5, Method::Rk4 { step: 0.1 }] {
        let mut s = Solver::new(method, Options::default(), 1).unwrap();
        s.reset(0.0, &[0.0]);
        let err = s
            .advance(&mut NanAfter(1.0), 5.0, &mut NoEvents, &mut ignore)
            .unwrap_err();
        let SolveError::NonFinite { t, h } = err else {
            panic!("{err:?}")
        };
        // The failing step starts before t = 1 and reaches beyond it.
        assert!(t <= 1.0 && t + h > 1.0, "t = {t}, h = {h}");
        assert!(err.to_string().contains(&format!("t = {t}")));
        // The state was not overwritten by NaN.
        assert!(s.y()[0].is_finite());
    }
}

#[test]
fn rhs_error_is_reported_with_t() {
    let mut s = Solver::new(Method::Dop853, Options::default(), 1).unwrap();
    s.reset(0.0, &[0.0]);
    let err = s
        .advance(&mut FailAfter(0.5), 5.0, &mut NoEvents, &mut ignore)
        .unwrap_err();
    let SolveError::Rhs { t, ref source } = err else {
        panic!("{err:?}")
    };
    assert!(t > 0.5);
    assert_eq!(source.0, "mechanism locked");
    assert!(err.to_string().contains("mechanism locked"));
}

#[test]
fn max_steps_is_an_error() {
    let opts = Options {
        max_steps: 10,
        h_max: 0.01,
        ..Options::default()
    };
    let mut s = Solver::new(Method::Dopri5, opts, 2).unwrap();
    s.reset(0.0, &[1.0, 0.0]);
    let err = s
        .advance(&mut Oscillator, 1.0, &mut NoEvents, &mut ignore)
        .unwrap_err();
    assert!(
        matches!(err, SolveError::TooManySteps { max_steps: 10, t } if t > 0.0 && t < 1.0),
        "{err:?}"
    );
}

/// The oscillator, raising a flag when a stage reaches `at` (as another thread would).
struct FlagAt {
    at: f64,
    flag: Cancel,
}
impl OdeSystem for FlagAt {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        if t >= self.at {
            self.flag.cancel();
        }
        Oscillator.rhs(t, y, dydt)
    }
}

/// An interrupt stops an advance at the end of the accepted step in which it is seen, a state of
/// the solution (cos t, −sin t) to the tolerances; without it, the advance goes on to the end
/// as the uninterrupted one does.
#[test]
fn an_interrupt_stops_an_advance_at_an_accepted_step() {
    let opts = Options {
        h_max: 0.1,
        ..Options::default()
    };
    let flag = Cancel::new();
    let mut s = Solver::new(Method::Dop853, opts, 2).unwrap();
    s.set_interrupt(Some(flag.clone()));
    s.reset(0.0, &[1.0, 0.0]);
    let mut sys = FlagAt {
        at: 3.0,
        flag: flag.clone(),
    };
    let err = s
        .advance(&mut sys, 10.0, &mut NoEvents, &mut ignore)
        .unwrap_err();
    let SolveError::Interrupted { t } = err else {
        panic!("{err:?}")
    };
    // The flag rises in a step whose stages reach 3 (steps ≤ h_max = 0.1); the interrupt is
    // read at the end of that step, or of the shorter retry of a rejected one.
    assert!((2.9..=3.1).contains(&t), "interrupted at {t}");
    assert_eq!(s.t(), t);
    // The global error of DOP853 at rtol 1e-10 over 3 s stays far below 1e-8.
    assert!((s.y()[0] - t.cos()).abs() < 1e-8 && (s.y()[1] + t.sin()).abs() < 1e-8);
    s.set_interrupt(None);
    sys.at = f64::INFINITY;
    let stop = s
        .advance(&mut sys, 10.0, &mut NoEvents, &mut ignore)
        .unwrap();
    assert_eq!(stop, Stop::Reached);
    assert!((s.y()[0] - 10f64.cos()).abs() < 1e-8 && (s.y()[1] + 10f64.sin()).abs() < 1e-8);
}

/// A flag already set still lets each advance take one accepted step, so that a caller that
/// goes on advancing makes progress.
#[test]
fn an_advance_under_a_set_interrupt_takes_one_step() {
    let opts = Options {
        h_max: 0.1,
        ..Options::default()
    };
    let mut s = Solver::new(Method::Dopri5, opts, 2).unwrap();
    let cancelled = Cancel::new();
    cancelled.cancel();
    s.set_interrupt(Some(cancelled));
    s.reset(0.0, &[1.0, 0.0]);
    let mut t_prev = 0.0;
    for _ in 0..3 {
        let accepted = s.stats().accepted;
        let err = s
            .advance(&mut Oscillator, 10.0, &mut NoEvents, &mut ignore)
            .unwrap_err();
        assert_eq!(err, SolveError::Interrupted { t: s.t() });
        assert_eq!(s.stats().accepted, accepted + 1);
        assert!(s.t() > t_prev && s.t() <= t_prev + 0.1);
        t_prev = s.t();
    }
}

/// y' = y², y(0) = 1: y = 1/(1-t) blows up at t = 1.
struct BlowUp;
impl OdeSystem for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        dydt[0] = y[0] * y[0];
        Ok(())
    }
}

#[test]
fn singularity_gives_an_error_not_a_hang() {
    for method in [Method::Dop853, Method::Dopri5] {
        let mut s = Solver::new(method, Options::default(), 1).unwrap();
        s.reset(0.0, &[1.0]);
        let err = s
            .advance(&mut BlowUp, 2.0, &mut NoEvents, &mut ignore)
            .unwrap_err();
        println!("{method:?}: {err}");
        match err {
            SolveError::StepSizeUnderflow { t, .. }
            | SolveError::NonFinite { t, .. }
            | SolveError::TooManySteps { t, .. } => assert!((t - 1.0).abs() < 1e-3, "{t}"),
            e => panic!("{e:?}"),
        }
    }
}

#[test]
fn invalid_options_are_rejected() {
    let bad = Options {
        rtol: -1.0,
        ..Options::default()
    };
    assert!(Solver::new(Method::Dop853, bad, 1).is_err());
    assert!(Solver::new(Method::Rk4 { step: 0.0 }, Options::default(), 1).is_err());
    let mut s = Solver::new(Method::Dop853, Options::default(), 1).unwrap();
    s.reset(1.0, &[0.0]);
    assert!(matches!(
        s.advance(&mut ExpSin, 0.5, &mut NoEvents, &mut ignore),
        Err(SolveError::BackwardEnd { .. })
    ));
}

#[test]
fn options_deserialize_with_defaults_and_deny_unknown() {
    use serde::Deserialize;
    use serde::de::value::{Error, MapDeserializer};
    let m = MapDeserializer::<_, Error>::new([("rtol", 1e-6)].into_iter());
    let o = Options::deserialize(m).unwrap();
    assert_eq!(o.rtol, 1e-6);
    assert_eq!(o.atol, Options::default().atol);
    assert_eq!(o.max_steps, Options::default().max_steps);
    let m = MapDeserializer::<_, Error>::new([("rtoll", 1e-6)].into_iter());
    assert!(Options::deserialize(m).is_err());
}

// ------------------------------------------------------------------ narrow features

/// x' = v, v' = -v·|v|·ln 2·δ_w(x - 1): a unit-area raised cosine of width w halves v while x
/// crosses the band |x - 1| < w/2 and does nothing elsewhere, so smooth steps grow large and
/// can step over the band without a stage inside it.
struct Band {
    w: f64,
}
impl OdeSystem for Band {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        let u = y[0] - 1.0;
        let delta = if u.abs() < 0.5 * self.w {
            (1.0 + (2.0 * PI * u / self.w).cos()) / self.w
        } else {
            0.0
        };
        dydt[0] = y[1];
        dydt[1] = -std::f64::consts::LN_2 * y[1] * y[1].abs() * delta;
        Ok(())
    }
}

/// The band's edges and centre: g_k = x - 1 - (k - 1)·w/2.
struct BandEdges {
    w: f64,
}
impl EventFunctions for BandEdges {
    fn count(&self) -> usize {
        3
    }
    fn eval(&mut self, _t: f64, y: &[f64], g: &mut [f64]) {
        for (k, gk) in g.iter_mut().enumerate() {
            *gk = y[0] - 1.0 - (k as f64 - 1.0) * 0.5 * self.w;
        }
    }
    fn direction(&self, _i: usize) -> Direction {
        Direction::Rising
    }
}

#[test]
fn a_step_over_a_narrow_band_does_not_skip_its_events() {
    // Whatever the band width, the three roots fire in order, each at its own root, with the
    // state never past a later one: a long step whose stages missed the band has a meaningless
    // interpolant, and the landing step must expose it (error control, distance to the
    // interpolant) so that the step is redone rather than carried on past the other roots.
    let widths: Vec<f64> = (0..25)
        .map(|k| 1e-4 * 100f64.powf(k as f64 / 24.0))
        .collect();
    for method in [Method::Dop853, Method::Dopri5] {
        for &w in &widths {
            let mut s = Solver::new(method, Options::default(), 2).unwrap();
            s.reset(0.0, &[0.0, 1.0]);
            let (mut sys, mut ev) = (Band { w }, BandEdges { w });
            for k in 0..3 {
                let stop = s.advance(&mut sys, 10.0, &mut ev, &mut ignore).unwrap();
                assert!(
                    matches!(stop, Stop::Event { index, .. } if index == k),
                    "{method:?}, w = {w:e}: expected event {k}, got {stop:?} at x = {}",
                    s.y()[0]
                );
                let mut g = [0.0; 3];
                ev.eval(s.t(), s.y(), &mut g);
                assert!(
                    g[k].abs() < 1e-9,
                    "{method:?}, w = {w:e}: g{k} = {:e}",
                    g[k]
                );
                assert!(g[k + 1..].iter().all(|&x| x < 0.0), "{method:?}, w = {w:e}");
            }
            // The band halved the rate (to the integration tolerance).
            assert_eq!(
                s.advance(&mut sys, 10.0, &mut ev, &mut ignore).unwrap(),
                Stop::Reached
            );
            assert!(
                (s.y()[1] - 0.5).abs() < 1e-6,
                "{method:?}, w = {w:e}: {}",
                s.y()[1]
            );
        }
    }
}
