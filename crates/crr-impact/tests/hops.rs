//! A pull at a pivot where a segment starts is measured by the motion with that face released
//! (`simulation::hops`). Checked against closed forms on Housner's block thrown off its corner
//! at θ = 0 with rate θ̇ (half-width b, half-height h, R² = b² + h², sin²α = b²/R²):
//!
//! - on its corner the ground presses with N = m g (1 − ¾ sin²α) − m h θ̇² (the centre of mass
//!   turning about the corner, I_O = 4/3 m R²), so a pull needs h θ̇² > g (1 − ¾ sin²α);
//! - released, the block flies freely: its centre rises at b θ̇ and falls at g, it turns at θ̇,
//!   and its corner's height is z(t) = h (1 − cos θ̇t) + b (θ̇t − sin θ̇t) − ½ g t², whose
//!   acceleration at t = 0 is h θ̇² − g: the face opens only if h θ̇² > g. Between the two
//!   thresholds the pull has no answer without sliding (the block would slide), and above the second the
//!   corner keeps rising (z grows like ½(hθ̇² − g)t² + bθ̇³t³/6): a flight, whatever tolerance.

use std::collections::BTreeMap;

use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::{InitialSpec, solve_initial};
use crr_impact::{Parameters, Simulation, Trajectory};
use crr_kinematics::Model;
use crr_kinematics::fixtures::single_block;

const B: f64 = 0.2;
const H: f64 = 1.0;

fn block() -> Model {
    Model::from_spec(&single_block(B, H, 2500.0)).unwrap()
}

/// sin²α of the block.
fn sin2_alpha() -> f64 {
    B * B / (B * B + H * H)
}

/// The block thrown at θ = 0 with rate `rate` (rad/s), run for `duration` s.
fn thrown(rate: f64, hop_tolerance: f64, duration: f64) -> Trajectory {
    let model = block();
    let spec = InitialSpec {
        angles: BTreeMap::new(),
        rates: BTreeMap::from([(model.coords[0].name.clone(), rate)]),
    };
    let init = solve_initial(&model, &spec).unwrap();
    let params = Parameters {
        duration,
        output_interval: 1e-3,
        hop_tolerance,
        ..Parameters::default()
    };
    match Simulation::new(&model, &GroundMotion::none(), &init, params)
        .unwrap()
        .run()
    {
        Ok(t) => t,
        Err(stop) => stop.partial,
    }
}

/// N at θ = 0 with rate θ̇ (N), by the closed form.
fn normal_force(model: &Model, rate: f64) -> f64 {
    let m = model.total_mass();
    m * model.gravity * (1.0 - 0.75 * sin2_alpha()) - m * H * rate * rate
}

/// The free corner's height at t (m), by the closed form.
fn free_corner_height(g: f64, rate: f64, t: f64) -> f64 {
    let phi = rate * t;
    H * (1.0 - phi.cos()) + B * (phi - phi.sin()) - 0.5 * g * t * t
}

#[test]
fn a_block_that_presses_on_its_corner_does_not_hop() {
    let model = block();
    let g = model.gravity;
    // 1 % below the pull's threshold: N = 1 % of (1 − ¾ sin²α) W, above the monitor's 1e-3 W.
    let rate = (0.99 * g * (1.0 - 0.75 * sin2_alpha()) / H).sqrt();
    assert!(normal_force(&model, rate) > 5e-3 * model.total_mass() * g);
    let t = thrown(rate, 0.0, 0.02);
    assert!(t.hops.is_empty(), "{:?}", t.hops);
    assert!(t.violation.is_none(), "{:?}", t.violation);
}

#[test]
fn a_pull_the_released_block_would_not_lift_off_is_a_violation_whatever_the_tolerance() {
    let model = block();
    let g = model.gravity;
    // 1 % above the pull's threshold, still below the free corner's: h θ̇² = 0.981 g.
    let rate = (1.01 * g * (1.0 - 0.75 * sin2_alpha()) / H).sqrt();
    assert!(H * rate * rate < g);
    let n = normal_force(&model, rate);
    for tolerance in [0.0, 1.0] {
        let t = thrown(rate, tolerance, 0.02);
        let v = t.violation.as_ref().expect("a violation");
        assert_eq!(
            (v.kind.as_str(), v.interface.as_str(), v.t),
            ("tension", "base", 0.0)
        );
        // The monitor's N against the closed form (round-off of the solve).
        assert!(
            (v.normal - n).abs() <= 1e-9 * n.abs(),
            "{} vs {n}",
            v.normal
        );
        let hop = v.hop.as_deref().expect("the pull measured");
        assert!(!hop.opens && !hop.within(tolerance), "{hop:?}");
        assert_eq!(hop.start, 0.0);
        // The episode's own reading of N: Newton–Euler on the block against the closed form.
        assert!(
            (hop.largest_pull + n).abs() <= 1e-9 * n.abs(),
            "{hop:?} vs {n}"
        );
        assert_eq!(t.hops.len(), 1);
    }
}

#[test]
fn a_block_whose_corner_keeps_rising_is_a_flight_whatever_the_tolerance() {
    let model = block();
    let g = model.gravity;
    // 0.1 % above the free corner's threshold: the corner's acceleration starts at 1e-3 g.
    let rate = (1.001 * g / H).sqrt();
    let tolerance = 1e-6;
    let t = thrown(rate, tolerance, 0.02);
    let v = t.violation.as_ref().expect("a violation");
    assert_eq!((v.kind.as_str(), v.t), ("tension", 0.0));
    let hop = v.hop.as_deref().expect("the pull measured");
    assert!(hop.opens && !hop.within(tolerance), "{hop:?}");
    // The free flight it stands for: the corner is above the tolerance before the episode ends
    // and still rising there.
    // The gap's bound has not closed by the end of the run (20 ms), and it bounds the free
    // corner's height there, which is above the tolerance and still rising.
    let end = hop.end;
    assert!(!hop.closed && end == 0.02, "{hop:?}");
    let height = free_corner_height(g, rate, end);
    assert!(height > tolerance && free_corner_height(g, rate, end + 1e-3) > height);
    assert!(
        hop.separation >= height,
        "{hop:?}: the free corner is at {height:e} m"
    );
    assert!(hop.departure >= hop.separation, "{hop:?}");
    println!("{hop:?}; the free corner at {height:e} m");
}

/// The face opens where the free corner's acceleration h θ̇² − g is positive: 0.1 % on either
/// side of h θ̇² = g, the episode's reading of the released block's gap changes sign.
#[test]
fn the_released_face_opens_where_the_free_corner_rises() {
    let g = block().gravity;
    for (factor, opens) in [(0.999, false), (1.001, true)] {
        let rate = (factor * g / H).sqrt();
        let t = thrown(rate, 0.0, 0.005);
        let hop = &t.hops[0];
        assert_eq!((hop.start, hop.opens), (0.0, opens), "{factor}: {hop:?}");
    }
}
