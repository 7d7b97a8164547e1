//! The equations of motion integrated: energy conservation without excitation, and agreement of
//! the constrained (multi-DOF, multipliers, projection) and reduced (coordinate partitioning)
//! forms on closed chains.

use std::collections::BTreeMap;

use crr_dynamics::energy::energies;
use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::integrator::{Method, Options};
use crr_dynamics::{Form, InitialSpec, Sample, integrate_smooth, solve_initial};
use crr_kinematics::fixtures::{double_pendulum, four_hinge_arch, serial_chain, trilithon};
use crr_kinematics::{Data, Model, StructureSpec};

fn tight() -> Options {
    Options {
        rtol: 1e-12,
        atol: 1e-12,
        ..Options::default()
    }
}

fn initial(model: &Model, angles: &[(&str, f64)]) -> crr_dynamics::InitialState {
    let spec = InitialSpec {
        angles: angles
            .iter()
            .map(|(k, v)| (k.to_string(), *v))
            .collect::<BTreeMap<_, _>>(),
        rates: BTreeMap::new(),
    };
    solve_initial(model, &spec).expect("consistent initial state")
}

/// Largest drift of T + U − W over the run, relative to the scale m g L of the structure.
fn energy_drift(spec: &StructureSpec, angles: &[(&str, f64)], t_end: f64) -> f64 {
    let model = Model::from_spec(spec).unwrap();
    let init = initial(&model, angles);
    let ground = GroundMotion::none();
    let run = integrate_smooth(
        &model,
        &ground,
        &init,
        t_end,
        0.05,
        Method::Dop853,
        Options {
            rtol: 1e-10,
            atol: 1e-10,
            ..Options::default()
        },
        Form::Constrained,
    )
    .unwrap();
    let mut kin = Data::new(&model);
    let mut e = |s: &Sample| energies(&model, &mut kin, &s.q, &s.qdot, &init.pivots, s.work_in);
    let e0 = e(&run[0]).mechanical();
    let scale = model.total_mass() * model.gravity * model.size;
    let mut peak_t: f64 = 0.0;
    let drift = run
        .iter()
        .map(|s| {
            let en = e(s);
            peak_t = peak_t.max(en.kinetic);
            (en.mechanical() - en.work_in - e0).abs()
        })
        .fold(0.0, f64::max);
    // The motion is real: kinetic energy reaches a sizeable share of the scale.
    assert!(peak_t > 1e-2 * scale, "peak T {peak_t} vs scale {scale}");
    drift / scale
}

/// Without excitation T + U is conserved over 10 s to the integration tolerance (rtol 1e-10: the
/// global error of a chaotic 10 s run stays within ~1e-7 of the energy scale).
#[test]
fn energy_is_conserved_on_a_3d_chain_with_non_parallel_axes() {
    let d = energy_drift(
        &serial_chain(4),
        &[("j0", 0.9), ("j1", -0.7), ("j2", 0.5), ("j3", 1.1)],
        10.0,
    );
    eprintln!("3d chain: relative energy drift {d:e}");
    assert!(d < 1e-7, "relative drift {d:e}");
}

#[test]
fn energy_is_conserved_on_a_double_pendulum() {
    let d = energy_drift(
        &double_pendulum(),
        &[("shoulder", 2.0), ("elbow", -1.0)],
        10.0,
    );
    eprintln!("double pendulum: relative energy drift {d:e}");
    assert!(d < 1e-7, "relative drift {d:e}");
}

fn max_difference(a: &[Sample], b: &[Sample]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            assert_eq!(x.t, y.t);
            (&x.q - &y.q).amax().max((&x.qdot - &y.qdot).amax() * 0.1)
        })
        .fold(0.0, f64::max)
}

fn forms_agree(spec: &StructureSpec, angles: &[(&str, f64)]) -> (f64, f64) {
    forms_agree_over(spec, angles, 3.0)
}

fn forms_agree_over(spec: &StructureSpec, angles: &[(&str, f64)], duration: f64) -> (f64, f64) {
    let model = Model::from_spec(spec).unwrap();
    let init = initial(&model, angles);
    let ground = GroundMotion::none();
    let a = integrate_smooth(
        &model,
        &ground,
        &init,
        duration,
        0.01,
        Method::Dop853,
        tight(),
        Form::Constrained,
    )
    .unwrap();
    let b = integrate_smooth(
        &model,
        &ground,
        &init,
        duration,
        0.01,
        Method::Dop853,
        tight(),
        Form::Reduced,
    )
    .unwrap();
    let travel = a
        .iter()
        .map(|s| (&s.q - &a[0].q).amax())
        .fold(0.0, f64::max);
    (max_difference(&a, &b), travel)
}

/// Trilithon from just below its unstable top (θ₀ = α − 10⁻³): over 3 s it falls back through
/// ~0.4 rad. Both forms agree to 1e-8 rad (and 1e-7 rad/s).
#[test]
fn constrained_and_reduced_forms_agree_on_the_trilithon() {
    let alpha = (0.25f64 / 1.5).atan();
    let (diff, travel) = forms_agree(
        &trilithon(0.25, 1.5, 2.0, 0.5, 1.0),
        &[("base_left", alpha - 1e-3)],
    );
    eprintln!("trilithon: constrained vs reduced {diff:e} rad over a travel of {travel:.3} rad");
    assert!(travel > 0.1, "the trilithon moves: {travel}");
    assert!(diff < 1e-8, "difference {diff:e}");
}

/// Four-hinge arch released from 0.02 rad at its right springing swings through its mechanism.
#[test]
fn constrained_and_reduced_forms_agree_on_the_arch() {
    let (diff, travel) = forms_agree(
        &four_hinge_arch(4.0, 4.6, 1.0, false),
        &[("springing_right", 0.02)],
    );
    eprintln!("arch: constrained vs reduced {diff:e} rad over a travel of {travel:.3} rad");
    assert!(travel > 0.01, "the arch moves: {travel}");
    assert!(diff < 1e-8, "difference {diff:e}");
}

/// The 2×2 colonnade (two DOF, 4 redundant closure rows of 12) released with its columns tilted in
/// both directions: the constrained form (minimum-norm multipliers of the redundant rows) and the
/// reduced form (8 dependent coordinates by Newton) agree over 1 s while the colonnade swings on
/// its corners (the pivots are held: a smooth-motion test, no impacts).
#[test]
fn constrained_and_reduced_forms_agree_on_the_colonnade() {
    let (diff, travel) = forms_agree_over(
        &crr_kinematics::fixtures::colonnade(0.2, 1.5, 1.0, 0.3),
        &[("base_1.1", 0.12), ("base_1.2", -0.05)],
        1.0,
    );
    eprintln!("colonnade: constrained vs reduced {diff:e} rad over a travel of {travel:.3} rad");
    assert!(travel > 0.1, "the colonnade moves: {travel}");
    assert!(diff < 1e-8, "difference {diff:e}");
}

/// Under ground motion the balance T + U − W stays constant (W the work of the effective-gravity
/// pseudo-force, integrated along the solution), for an analytic sine on a 3D chain and for a
/// recorded (piecewise-linear, breakpoints at every sample) accelerogram on the trilithon.
#[test]
fn energy_balance_closes_under_ground_motion() {
    use crr_dynamics::ground_motion::{Axis, ComponentSpec, Record, SignalSpec, SineSpec};
    let sine = ComponentSpec::new(SignalSpec::Sine(SineSpec {
        amplitude: 3.0,
        period: Some(0.7),
        frequency: None,
        phase: 0.3,
        cycles: None,
        start: 0.0,
    }));
    let ground = GroundMotion::none()
        .with_component(Axis::X, &sine, std::path::Path::new("."))
        .unwrap();
    let ground = ground
        .with_component(Axis::Y, &sine, std::path::Path::new("."))
        .unwrap();
    let model = Model::from_spec(&serial_chain(3)).unwrap();
    let init = initial(&model, &[("j0", 0.3), ("j1", -0.2)]);
    check_balance(&model, &ground, &init, 5.0);

    // A deterministic pseudo-random record at 100 samples/s, peak 2 m/s².
    let accel: Vec<f64> = (0..301)
        .map(|i| 2.0 * ((i as f64 * 0.37).sin() * (i as f64 * 0.011).cos()))
        .collect();
    let ground =
        GroundMotion::from_record(Axis::X, Record::uniform(0.01, accel).unwrap(), 1.0).unwrap();
    let model = Model::from_spec(&trilithon(0.25, 1.5, 2.0, 0.5, 1.0)).unwrap();
    let alpha = (0.25f64 / 1.5).atan();
    // Near its top, where the frame stays within |θ| < 1.5 rad (it flips through singular
    // configurations of the loop only long after it has collapsed).
    let init = initial(&model, &[("base_left", alpha - 1e-3)]);
    check_balance(&model, &ground, &init, 3.0);
    let model = Model::from_spec(&serial_chain(3)).unwrap();
    let init = initial(&model, &[("j0", 0.3), ("j1", -0.2)]);
    check_balance(&model, &ground, &init, 3.0);
}

fn check_balance(
    model: &Model,
    ground: &GroundMotion,
    init: &crr_dynamics::InitialState,
    t_end: f64,
) {
    let run = integrate_smooth(
        model,
        ground,
        init,
        t_end,
        0.05,
        Method::Dop853,
        tight(),
        Form::Constrained,
    )
    .unwrap();
    let mut kin = Data::new(model);
    let mut e = |s: &Sample| energies(model, &mut kin, &s.q, &s.qdot, &init.pivots, s.work_in);
    let e0 = e(&run[0]);
    let scale = model.total_mass() * model.gravity * model.size;
    let mut worst: f64 = 0.0;
    let mut max_work: f64 = 0.0;
    for s in &run {
        assert!(
            model.closures.is_empty() || s.q.amax() < 1.5,
            "the run stays in the physical range: {:?}",
            s.q.as_slice()
        );
        let en = e(s);
        max_work = max_work.max(en.work_in.abs());
        worst = worst.max((en.mechanical() - en.work_in - e0.mechanical()).abs());
    }
    eprintln!(
        "{}: energy balance error {:e} of m g L, |W| up to {:.3e} J",
        model.name,
        worst / scale,
        max_work
    );
    // The ground does real work, and the balance closes to the integration tolerance.
    assert!(max_work > 1e-3 * scale);
    assert!(
        worst < 1e-8 * scale,
        "balance error {worst:e} J vs scale {scale:e} J"
    );
}
