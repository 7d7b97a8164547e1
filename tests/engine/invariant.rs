//! The run's invariant (`Simulation::check_invariant`, checked after every step in every build):
//! a state that has left the model — a rocking angle past its active pivot, loops pulled open —
//! stops the run with an error that names the angle or the loops, the time and the setting to
//! change, never a silent result. The reproducer of the issue: `rtol = 1e-3` on the bundled
//! trilithon reported "collapse at 1.082 s" (the true run: 8 impacts, no collapse); it is now an
//! error, with the results until then kept ("completed": false).
use crate::common;

#[test]
fn a_loose_tolerance_is_an_error_not_a_false_collapse() {
    let text = common::bundled_text("trilithon") + "\n[analysis]\nrtol = 1e-3\n";
    let (err, out) = common::simulate_failing("trilithon_loose", &text);
    assert!(err.contains("tighten analysis.rtol"), "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["completed"], false);
    assert_eq!(summary["collapse"]["collapsed"], false, "{summary}");
}
