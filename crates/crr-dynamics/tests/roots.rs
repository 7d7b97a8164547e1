//! Tests of `roots::sign_change`, the locator of a step's turning points: the same adjacent
//! doubles as a plain bisection, in far fewer evaluations, on a rocking block's dense output and
//! on random smooth functions; a valid bracket whatever `f` does.

use std::cell::Cell;

use crr_dynamics::integrator::{DenseStep, Method, NoEvents, OdeSystem, Options, RhsError, Solver};
use crr_dynamics::roots::sign_change;
use crr_kinematics::fixtures::SplitMix;

/// The reference: halve [lo, hi], keep the half whose ends differ in sign (`signum`), until the
/// ends are adjacent doubles (or 60 halvings). Returns the bracket and the evaluations made.
fn bisection(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> ((f64, f64), usize) {
    let sign_lo = f(lo).signum();
    let mut evaluations = 0;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        evaluations += 1;
        if f(mid).signum() == sign_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    ((lo, hi), evaluations)
}

/// `sign_change` on `f` over [lo, hi], with the evaluations it made.
fn located(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> ((f64, f64), usize) {
    let count = Cell::new(0);
    let bracket = sign_change(
        |t| {
            count.set(count.get() + 1);
            f(t)
        },
        lo,
        f(lo),
        hi,
        f(hi),
    );
    (bracket, count.get())
}

/// Whether `(lo, hi)` are adjacent doubles across which `f` changes sign.
fn is_adjacent_crossing(f: impl Fn(f64) -> f64, (lo, hi): (f64, f64)) -> bool {
    lo < hi && lo.next_up() == hi && f(lo).signum() != f(hi).signum()
}

/// Housner's block (R = 1.02 m, α = 0.197: p² = 3g/4R), state (θ, θ̇).
struct Block;
impl OdeSystem for Block {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        let (p2, alpha) = (0.75 * 9.81 / 1.02, 0.197_f64);
        dydt[0] = y[1];
        dydt[1] = -p2 * (alpha * y[0].signum() - y[0]).sin();
        Ok(())
    }
}

/// The turning points of a rocking block, as a run finds them: θ̇ of each step's dense output
/// (DOP853 at rtol 1e-10, Dopri5, RK4) changes sign inside the step. The located brackets are
/// the bisection's to the last bit, with at most 20 evaluations where the bisection takes 40 or
/// more (a step of about 0.05 s halved down to ulps of t ≈ 1–10 s).
#[test]
fn turning_points_of_a_rocking_block_are_the_bisections() {
    for method in [Method::Dop853, Method::Dopri5, Method::Rk4 { step: 0.01 }] {
        let options = Options {
            rtol: 1e-10,
            atol: 1e-12,
            ..Options::default()
        };
        let mut solver = Solver::new(method, options, 2).unwrap();
        // Released at θ₀ = 0.1 > 0 from rest; the first turning point is at t = 0 itself, the
        // next ones (θ < 0 side, impacts are not modelled: θ rocks on one side through 0) later.
        solver.reset(0.0, &[0.1, 0.0]);
        let mut found = 0;
        solver
            .advance(&mut Block, 10.0, &mut NoEvents, &mut |step: &DenseStep| {
                let rate = step.component(1);
                let (a, b) = (rate.eval(step.t0()), rate.eval(step.t1()));
                if a == 0.0 || b == 0.0 || a.signum() == b.signum() {
                    return;
                }
                let f = |t: f64| rate.eval(t);
                let (expected, halvings) = bisection(f, step.t0(), step.t1());
                let (got, evaluations) = located(f, step.t0(), step.t1());
                assert_eq!(
                    (got.0.to_bits(), got.1.to_bits()),
                    (expected.0.to_bits(), expected.1.to_bits()),
                    "{method:?}: step [{}, {}]",
                    step.t0(),
                    step.t1()
                );
                assert!(is_adjacent_crossing(f, got));
                assert!(halvings >= 40, "{method:?}: {halvings} halvings");
                assert!(
                    evaluations <= 20,
                    "{method:?}: {evaluations} evaluations at t = {}",
                    got.0
                );
                found += 1;
            })
            .unwrap();
        // About 0.98 s between turning points of this block released at θ₀/α ≈ 0.5.
        assert!(found >= 8, "{method:?}: {found} turning points");
    }
}

/// Random smooth monotone crossings, f(t) = c₁(t − r) + c₃(t − r)³ + c₅ sin(t − r) scaled by up
/// to 1e±6, on brackets of 1e-4 to 0.1 s placed 0.5 to 50 s from 0: the bisection's bracket to
/// the last bit, in at most 20 evaluations.
#[test]
fn random_monotone_crossings_are_the_bisections() {
    let mut rng = SplitMix(7);
    for case in 0..2000 {
        let width = 10f64.powf(rng.uniform(-4.0, -1.0));
        let lo = rng.uniform(0.5, 50.0);
        let hi = lo + width;
        let r = lo + width * rng.uniform(0.02, 0.98);
        let scale = 10f64.powf(rng.uniform(-6.0, 6.0)) * if case % 2 == 0 { 1.0 } else { -1.0 };
        // c₁ > |c₅| keeps f' = c₁ + 3c₃x² + c₅cos x > 0.
        let (c1, c3) = (rng.uniform(0.5, 2.0), rng.uniform(0.0, 50.0));
        let c5 = rng.uniform(-0.4, 0.4);
        let f = |t: f64| {
            let x = t - r;
            scale * (c1 * x + c3 * x * x * x + c5 * x.sin())
        };
        let (expected, _) = bisection(f, lo, hi);
        let (got, evaluations) = located(f, lo, hi);
        assert_eq!(got, expected, "case {case}");
        assert!(is_adjacent_crossing(f, got), "case {case}");
        assert!(evaluations <= 20, "case {case}: {evaluations} evaluations");
    }
}

/// Brackets at or near t = 0, where 60 halvings of a step do not reach adjacent doubles (doubles
/// are dense there): the answer is still the bisection's, the bracket after its 60 halvings. The
/// first case is a run's first step from a state with a velocity, q̇ = 1e-6 − 5t on [0, 1e-3]
/// (the bisection ends 33 ulps wide there); then 2 000 random monotone crossings on brackets of
/// 1e-4 to 0.5 s starting at 0 or at 1e-9 to 1e-2 s.
#[test]
fn brackets_near_zero_are_the_bisections() {
    let first = |t: f64| 1e-6 - 5.0 * t;
    let (expected, _) = bisection(first, 0.0, 1e-3);
    assert_ne!(
        expected.0.next_up(),
        expected.1,
        "60 halvings reach adjacent doubles"
    );
    assert_eq!(located(first, 0.0, 1e-3).0, expected);
    let mut rng = SplitMix(11);
    for case in 0..2000 {
        let lo = if case % 4 == 0 {
            0.0
        } else {
            10f64.powf(rng.uniform(-9.0, -2.0))
        };
        let hi = lo + 10f64.powf(rng.uniform(-4.0, -0.3));
        let r = lo + (hi - lo) * rng.uniform(0.001, 0.999);
        let (c1, c3) = (rng.uniform(0.5, 2.0), rng.uniform(0.0, 50.0));
        let sign = if case % 2 == 0 { 1.0 } else { -1.0 };
        let f = |t: f64| {
            let x = t - r;
            sign * (c1 * x + c3 * x * x * x)
        };
        let (expected, _) = bisection(f, lo, hi);
        let (got, _) = located(f, lo, hi);
        assert_eq!(
            (got.0.to_bits(), got.1.to_bits()),
            (expected.0.to_bits(), expected.1.to_bits()),
            "case {case}: [{lo}, {hi}] crossing at {r}"
        );
    }
}

/// Whatever `f` is (several crossings, a jump, zeros of either sign, NaN), the result is a
/// bracket inside the given one whose ends differ in sign, and adjacent doubles.
#[test]
fn any_function_gives_a_valid_bracket() {
    type Case = (&'static str, fn(f64) -> f64, f64, f64);
    let cases: [Case; 5] = [
        (
            "three crossings",
            |t| (t - 1.1) * (t - 1.5) * (t - 1.9),
            1.0,
            2.0,
        ),
        ("a jump", |t| if t < 3.3 { -1.0 } else { 2.0 }, 3.0, 4.0),
        (
            "a flat zero",
            |t| if t < 2.5 { -1.0 } else { 0.0 },
            2.0,
            3.0,
        ),
        (
            "negative zero",
            |t| if t < 2.5 { 1.0 } else { -0.0 },
            2.0,
            3.0,
        ),
        (
            "NaN beyond",
            |t| if t < 5.2 { -(5.2 - t) } else { f64::NAN },
            5.0,
            6.0,
        ),
    ];
    for (what, f, lo, hi) in cases {
        let (got, _) = located(f, lo, hi);
        assert!(got.0 >= lo && got.1 <= hi, "{what}: {got:?}");
        assert_eq!(got.0.next_up(), got.1, "{what}: {got:?}");
        assert_eq!(f(got.0).signum(), f(lo).signum(), "{what}");
        assert_ne!(f(got.1).signum(), f(lo).signum(), "{what}");
    }
}
