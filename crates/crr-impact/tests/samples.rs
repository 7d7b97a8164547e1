//! The output samples of a run (`Samples`, stored by columns): what a caller streaming them with
//! `Simulation::drain_samples` receives, batch after batch, is the run's samples, and the rows and
//! the columns read the same numbers.

mod common;

use crr_dynamics::ground_motion::GroundMotion;
use crr_impact::{Parameters, Samples, Simulation, SlotState, StopReason};
use crr_kinematics::Model;
use crr_kinematics::fixtures::single_block;

/// Housner's block (b = 0.2, h = 1 m) released from α/2, 6 s.
fn setup() -> (Model, crr_dynamics::InitialState, Parameters) {
    let model = Model::from_spec(&single_block(0.2, 1.0, 2500.0)).unwrap();
    let alpha = (0.2f64).atan();
    let init = common::released_at(&model, "base", alpha / 2.0);
    let params = Parameters {
        duration: 6.0,
        ..Parameters::default()
    };
    (model, init, params)
}

/// Drained batch after batch and joined again (`Samples::append`), the samples equal those of
/// the same run kept whole, to the last bit; every batch has the model's dimensions.
#[test]
fn drained_batches_join_into_the_whole_run() {
    let (model, init, params) = setup();
    let ground = GroundMotion::none();
    let whole = Simulation::new(&model, &ground, &init, params.clone())
        .unwrap()
        .run()
        .map_err(|f| f.error)
        .unwrap();
    let mut sim = Simulation::new(&model, &ground, &init, params).unwrap();
    let mut joined = Samples::new(model.dof(), model.slot_count);
    let mut batches = 0;
    loop {
        let stop = sim.step().unwrap();
        let batch = sim.drain_samples();
        assert_eq!((batch.dof(), batch.slots()), (1, model.slot_count));
        batches += usize::from(!batch.is_empty());
        joined.append(&batch);
        if matches!(stop, StopReason::End(_) | StopReason::Collapse(_)) {
            break;
        }
    }
    assert!(sim.samples.is_empty());
    assert!(batches >= 10, "{batches} batches");
    assert!(whole.impacts.len() >= 10, "{} impacts", whole.impacts.len());
    assert_eq!(joined, whole.samples);
}

/// Rows and columns read the same numbers; the regular samples fall on multiples of the output
/// interval, and each impact gives two samples at its time with the pivot switched between them.
#[test]
fn rows_and_columns_agree_and_impacts_give_two_samples() {
    let (model, init, params) = setup();
    let dt = params.output_interval;
    let ground = GroundMotion::none();
    let traj = Simulation::new(&model, &ground, &init, params)
        .unwrap()
        .run()
        .map_err(|f| f.error)
        .unwrap();
    let s = &traj.samples;
    assert_eq!(s.len(), s.iter().len());
    for (i, x) in s.iter().enumerate() {
        assert_eq!(x.t, s.times()[i]);
        assert_eq!(x.q, &s.q()[i..i + 1]);
        assert_eq!(x.qdot, &s.qdot()[i..i + 1]);
        assert_eq!(
            (x.kinetic, x.potential, x.work_in, x.dissipated),
            (
                s.kinetic()[i],
                s.potential()[i],
                s.work_in()[i],
                s.dissipated()[i]
            )
        );
        assert_eq!(x.states, &s.states()[i..i + 1]);
    }
    assert!(s.times().windows(2).all(|w| w[0] <= w[1]));
    let regular = s
        .times()
        .iter()
        .filter(|&&t| ((t / dt).round() * dt - t).abs() < 1e-9)
        .count();
    // 0, 0.01, …, 6.0 s (an impact falling on a multiple would only add rows).
    assert!(regular >= 601, "{regular} regular samples");
    for imp in &traj.impacts {
        let rows: Vec<_> = s.iter().filter(|x| x.t == imp.t).collect();
        assert_eq!(rows.len(), 2, "impact at {}", imp.t);
        let (pre, post) = (rows[0], rows[1]);
        assert_ne!(pre.states[0], post.states[0]);
        assert!(pre.states[0] != SlotState::Seated && post.states[0] != SlotState::Seated);
        // The law lowers T and leaves U (the pivot switch happens at φ = 0).
        assert!(post.kinetic < pre.kinetic);
        assert!((post.potential - pre.potential).abs() < 1e-9 * pre.kinetic.max(1.0));
    }
}
