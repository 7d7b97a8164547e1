//! The faces' certificate (`face_forces::PressingCertificate`: a compressive distribution of the
//! locked motion's contact forces, carried from one step end to the next) checked beside whole
//! runs. Wherever the uplift test in motion lets it decide that nothing opens, the audit
//! (`Simulation::audit_certificate`) also solves the contact program, Gauss' principle over the
//! seated faces as one convex program, a derivation that shares nothing with the faces' linear
//! program but the state, and confirms what it opens by the chain's own exact solve, as the run
//! would. The certificate is sound only if the two never part: no certified state at which the
//! program opens a slot on its side by more than the run's tolerance or lifts a face off.
//!
//! Runs: the bundled 3D arch under its record (bases rocking on an edge: the states the
//! certificate covers since it was extended to them), the bundled temple with its seats made
//! rigid (`twist = false`, the model on which a wider rule was found unsound) and as it is (seats
//! that may twist), both at 0.8 of its record, and running-bond walls under a
//! pulse above their collapse multiplier.
//!
//! The check has teeth: with the certificate not bounded by the locked solve's closure residual
//! (`CERTIFIED_CLOSURE_RESIDUAL`), it found 7 749 disagreements in 9 791 certified step ends on
//! the rigid temple and 140 in 3 138 on the temple at 0.8 of its record; with the faces of bases
//! turned on their first tilt posed on the parent's axes instead of the child's, 66 on the arch
//! (the first at 6.334 s, four second tilts released), at round-off residuals (2026-11-30).
//!
//! Why those two part on the temple: at 2.4136 s every neck and entablature seat sits a few
//! 1e-8 to 3e-7 rad from its seat, where the loops through the entablature are dependent to
//! about that angle. The closed-chain solve takes rows dependent below √1e-9 of its largest
//! singular value as dependent, so its locked motion leaves the front capitals' closures open
//! by 1.49e-7 m/s² along their edges (Φ_q q̈ + Φ̇_q q̇, the audit's `closure_residual`), with
//! coordinate accelerations up to 8.1 rad/s² while the bodies barely move. The certificate's
//! distribution (in equilibrium with the locked motion's loads to 7e-11 W) does positive power
//! on the change to the released motion (2.508e-3 N·m/s², equal to the loads' own power summed
//! body by body), so Gauss' function rises on that release; yet the chain's released solve opens
//! the neck, at 4.9e-8 rad/s², below the locked solve's error: the two solves keep different
//! rows (the released one closes `entablature_on_c13`, which the locked one leaves open), so at
//! that level they do not compare. Over the rigid temple's certified
//! states that residual reached 1.3e-3 m/s²; the certificate now decides only where it is
//! below `CERTIFIED_CLOSURE_RESIDUAL` g (1e-11 g), and the program elsewhere. On the 3D arch and
//! the walls it stays at round-off (1.5e-14 or less), which `assert_closed` asserts.

use std::path::Path;

use crr::dynamics::ground_motion::{Axis, ComponentSpec, GroundMotion, PulseSpec, SignalSpec};
use crr::dynamics::{InitialSpec, solve_initial};
use crr::impact::simulation::{CertificateAudit, StopReason};
use crr::impact::statics::{StaticsOptions, collapse_multiplier};
use crr::impact::{Parameters, Simulation};
use crr::kinematics::{Model, fixtures::running_bond_wall};

use crate::common;

/// The impacts' instants of a run.
type Instants = Vec<f64>;

/// Runs to the end, a collapse or an error with the certificate audited when `audit`; returns
/// the audit (empty when not audited), the time reached, the error, if any, and the impacts'
/// instants.
fn run(
    model: &Model,
    ground: &GroundMotion,
    initial: &crr::dynamics::InitialState,
    params: Parameters,
    audit: bool,
) -> (CertificateAudit, f64, Option<String>, Instants) {
    let mut sim = Simulation::new(model, ground, initial, params).unwrap();
    if audit {
        sim.audit_certificate();
    }
    let error = loop {
        match sim.step() {
            Ok(StopReason::End(_) | StopReason::Collapse(_)) => break None,
            Ok(_) => {}
            Err(e) => break Some(e.to_string()),
        }
    };
    let instants = sim.impacts.iter().map(|i| i.t).collect();
    let report = sim.certificate_audit().cloned().unwrap_or_default();
    (report, sim.time(), error, instants)
}

/// Runs with the certificate audited: the audit, the time reached and the error, if any.
fn audited(
    model: &Model,
    ground: &GroundMotion,
    initial: &crr::dynamics::InitialState,
    params: Parameters,
) -> (CertificateAudit, f64, Option<String>) {
    let (report, t, error, _) = run(model, ground, initial, params, true);
    (report, t, error)
}

/// The audit of a model file's run (its own ground motion and analysis), `duration` s.
fn audited_file(tag: &str, path: &Path, duration: f64) -> (CertificateAudit, f64, Option<String>) {
    let opts = crr::RunOptions {
        duration: Some(duration),
        ..Default::default()
    };
    let input = crr::ModelInput::read(path).unwrap_or_else(|e| panic!("{tag}: {e}"));
    let p = crr::analysis::simulation::prepare(&input, &opts).unwrap();
    audited(&p.model, &p.ground, &p.initial, p.params)
}

fn assert_sound(tag: &str, (audit, t, error): &(CertificateAudit, f64, Option<String>)) {
    eprintln!(
        "{tag}: to {t:.4} s ({error:?}): {} certified, {} disagreements, {} unsolved, \
         closure residual up to {:.3e}",
        audit.certified,
        audit.disagreements.len(),
        audit.unsolved,
        audit.largest_closure_residual
    );
    assert!(
        audit.disagreements.is_empty(),
        "{tag}: the certificate held where the program opens: {:?}",
        &audit.disagreements[..audit.disagreements.len().min(5)]
    );
    assert_eq!(
        audit.unsolved, 0,
        "{tag}: programs failed at certified states"
    );
}

/// The locked solves at the certified states keep the loops closed at acceleration level:
/// Φ_q q̈ + Φ̇_q q̇ of every closure row (from the kinematics' rows, not the solve) within
/// 1e-10 m/s² (1e-11 g; measured at most 1.5e-14, round-off). The bundled temple's loops are not
/// (see the module's doc), which is why it is not asked this.
fn assert_closed(tag: &str, audit: &CertificateAudit) {
    assert!(
        audit.largest_closure_residual <= 1e-10,
        "{tag}: the locked solve leaves a loop open by {:.3e} m/s²",
        audit.largest_closure_residual
    );
}

#[test]
fn the_certificate_holds_only_where_the_program_opens_nothing_on_the_3d_arch() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let run = audited_file("arch_3d", &root.join("examples/models/arch_3d.toml"), 20.0);
    assert_sound("arch_3d", &run);
    assert!(run.0.certified > 6000, "{} certified", run.0.certified);
    assert_closed("arch_3d", &run.0);
}

#[test]
fn the_certificate_holds_only_where_the_program_opens_nothing_on_the_rigid_seated_temple() {
    // At 0.8 of its record, which the bay rocks through for the whole 6 s. Under the whole
    // record the rigid bay's decisions from 2.0385 s rest on closed-chain solves left open by
    // 3.7e-3 to 8.8e-3 m/s² (docs/simulation.md, Limitations, "Decisions checked on loops left
    // open"): with `max_step = 1e-4` the capital c13 flies at 2.0541 s, while the default steps
    // go on into a chatter of the necks at 2.667 s whose steps take minutes.
    let text = common::bundled_text_with_records("temple")
        .replace("twist = true", "twist = false")
        .replace(
            "format = \"peer-at2\" }",
            "format = \"peer-at2\" }, scale = 0.8",
        );
    assert_eq!(text.matches("scale = 0.8").count(), 2, "both components");
    let path = common::write_model("temple_rigid_seats_audit", &text);
    let run = audited_file("temple at 0.8, rigid seats", &path, 6.0);
    assert_sound("temple at 0.8, rigid seats", &run);
    // Measured 2 949 (2026-12-05).
    assert!(run.0.certified > 2000, "{} certified", run.0.certified);
    assert_eq!(run.1, 6.0, "the run ends at 6 s");
}

#[test]
fn the_certificate_holds_only_where_the_program_opens_nothing_on_walls() {
    for (n, factor) in [(4, 1.2), (6, 1.5), (8, -2.0)] {
        let model = Model::from_spec(&running_bond_wall(n, n, 1.0, 0.5, 0.5)).unwrap();
        let x = nalgebra::Vector3::x();
        let lambda = collapse_multiplier(&model, x, &StaticsOptions::default())
            .unwrap()
            .lambda
            .unwrap();
        let pulse = SignalSpec::OneSinePulse(PulseSpec {
            amplitude: factor * lambda * model.gravity,
            period: 0.5,
            start: 0.0,
        });
        let ground = GroundMotion::none()
            .with_component(Axis::X, &ComponentSpec::new(pulse), Path::new("."))
            .unwrap();
        let init = solve_initial(&model, &InitialSpec::default()).unwrap();
        let params = Parameters {
            duration: 3.0,
            ..Parameters::default()
        };
        let tag = format!("{n} x {n} wall, {factor} λ g");
        let (report, t, error, instants) = run(&model, &ground, &init, params.clone(), true);
        assert_closed(&tag, &report);
        assert_sound(&tag, &(report, t, error));
        // The audit solves on a copy: the run it watches is the run unaudited, impact for
        // impact, to the last bit.
        let (_, t_plain, _, plain) = run(&model, &ground, &init, params, false);
        assert_eq!(
            (t, &instants),
            (t_plain, &plain),
            "{tag}: the audit changed the run"
        );
        assert!(!instants.is_empty(), "{tag}: nothing rocked");
    }
}

#[test]
fn the_certificate_holds_only_where_the_program_opens_nothing_on_the_temple_with_twisting_seats() {
    // The bundled temple (its entablature on seats that may twist) at 0.8 of its record, which
    // it rocks through for the whole 6 s (at 1.0 it stops at 2.054 s).
    let text = common::bundled_text_with_records("temple").replace(
        "format = \"peer-at2\" }",
        "format = \"peer-at2\" }, scale = 0.8",
    );
    assert_eq!(
        text.matches("scale = 0.8").count(),
        2,
        "both components scaled"
    );
    let path = common::write_model("temple_twisting_seats_audit", &text);
    let run = audited_file("temple at 0.8, twisting seats", &path, 6.0);
    assert_sound("temple at 0.8, twisting seats", &run);
    assert!(run.0.certified > 1500, "{} certified", run.0.certified);
    assert_eq!(run.1, 6.0, "the run ends at 6 s");
}
