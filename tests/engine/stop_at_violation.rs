//! `[analysis] stop_at_violation`: a run that ends at the first failure of the rigid-contact
//! hypotheses is the run that goes on, cut there. Checked against the same model run without
//! the setting (the reference computed independently, to its end): the same violation, the same
//! samples and impacts bit for bit up to the stop, and nothing integrated much beyond it.

use crate::common;

#[test]
fn a_run_stopped_at_its_first_violation_is_the_full_run_cut_there() {
    // The bundled drum column: its first violation (a hop of bed_7, 1.1e-8 m) at 0.5028 s.
    let text = common::bundled_text_with_records("drum_column");
    assert_eq!(text.matches("\n[analysis]\n").count(), 1);
    let stopping = text.replace("\n[analysis]\n", "\n[analysis]\nstop_at_violation = true\n");
    let run = |tag: &str, text: &str| {
        let path = common::write_model(tag, text);
        let input = crr::ModelInput::read(&path).unwrap();
        crr::run(&input, &crr::RunOptions::default()).unwrap()
    };
    let full = run("drum_column_full", &text);
    let cut = run("drum_column_stop_at_violation", &stopping);

    let duration = 4.0;
    let violation = full.trajectory.violation.clone().expect("a violation");
    assert_eq!(full.trajectory.end_time, duration);
    assert!(!full.summary.solver.stop_at_violation);
    assert!(cut.summary.solver.stop_at_violation);
    assert!(cut.completed(), "{:?}", cut.summary.error);
    assert_eq!(cut.trajectory.violation.as_ref(), Some(&violation));
    let end = cut.trajectory.end_time;
    // Within a step or two of it (its hop measured to its end): well before the duration.
    assert!(
        end >= violation.t && end < violation.t + 0.05,
        "{end} against {violation:?}"
    );

    // The cut run's samples before its end are the full run's first ones (the instants just
    // before and after each impact included), bit for bit; its last is the state at the stop.
    let (a, b) = (&cut.trajectory.samples, &full.trajectory.samples);
    let n = a.dof();
    let mut compared = 0;
    for i in (0..a.len()).take_while(|&i| a.times()[i] < end) {
        let t = a.times()[i];
        assert_eq!(t, b.times()[i], "sample {i}");
        assert_eq!(
            a.q()[i * n..(i + 1) * n],
            b.q()[i * n..(i + 1) * n],
            "q at {t}"
        );
        assert_eq!(
            a.qdot()[i * n..(i + 1) * n],
            b.qdot()[i * n..(i + 1) * n],
            "q̇ at {t}"
        );
        assert_eq!(a.kinetic()[i], b.kinetic()[i], "T at {t}");
        compared += 1;
    }
    assert!(compared > 40, "{compared} samples compared");
    assert_eq!(
        a.times().last(),
        Some(&end),
        "the state at the stop is kept"
    );
    // The impacts up to the stop are the full run's first ones; none is integrated past it.
    let k = cut.trajectory.impacts.len();
    assert!(k > 0 && k < full.trajectory.impacts.len());
    assert_eq!(cut.trajectory.impacts[..], full.trajectory.impacts[..k]);
    assert!(cut.trajectory.impacts.iter().all(|i| i.t <= end));
    assert!(full.trajectory.impacts[k].t > end);
}
