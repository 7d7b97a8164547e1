//! An impact whose impulse needs tension is reported (docs/simulation.md, "Impulses at landings
//! and impacts"), checked by hand on the bundled two-block stack: the impulse the stack's
//! impact needs at its base's bed, from the bodies' velocities before and after it and the
//! statics of the impulses on each block, independently of the engine's linear program.

use crr::impact::SlotState;

/// The two-block stack (`examples/models/two_block_stack.toml`: a 0.6 × 0.6 × 1.5 m base on the
/// ground, pivots at x = ±0.3 m; a 0.4 × 0.4 × 1.6 m block on it, pivots at x = ±0.2 m, z = 1.5 m)
/// rocks on its top block after the pulse; the base stays seated through the top block's
/// impacts (the engine holds it: "the other hinges persist"). At the impact of 1.8045 s the
/// top block's impulse on the base's top face presses the base's edge under the new pivot and
/// would lift the other one: the ground can balance it only by pulling at that far edge.
///
/// By hand, from the samples just before and after the impact (the base at rest in both, the
/// stack at its rest pose, the top block turning about its old pivot P before and its new one
/// P′ after): the impulse on the top block is J = m(v⁺ − v⁻) at P′ (its centre's velocities
/// ω × (c − P)), and the momentum law keeps its angular momentum about P′:
/// (P′ − c) × J = I(ω⁺ − ω⁻) to 1e-9. The base receives −J at P′ and, staying at rest, the ground
/// gives it J through its two pivot lines G± = (±0.3, 0, 0): the normal impulses n± with
/// n⁺ + n⁻ = J_z and moments about G⁻, 0.6 n⁺ = r_x J_z − r_z J_x (r = P′ − G⁻). The engine's
/// record is the least of these normal impulses (and J_z at P′), to 1e-6 of it (the linear
/// program's impulses are of order one in its units of W √(L/g), solved to 1e-8 there), below
/// the tolerance of 1e-3 W √(L/g).
#[test]
fn the_two_block_stack_s_impact_pulls_at_its_base_as_computed_by_hand() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/models/two_block_stack.toml");
    let input = crr::ModelInput::read(&path).unwrap();
    let run = crr::run(&input, &crr::RunOptions::default()).unwrap();
    let (model, traj) = (&run.model, &run.trajectory);
    let v = traj.violation.as_ref().expect("the impact pulls");
    assert_eq!(
        (v.kind.as_str(), v.interface.as_str()),
        ("impulse_tension", "base")
    );
    assert!((v.t - 1.8045).abs() < 1e-4, "at {} s", v.t);
    assert!(traj.impacts.iter().any(|i| i.t == v.t), "at an impact");
    let at: Vec<_> = traj.samples.iter().filter(|s| s.t == v.t).collect();
    let (before, after) = (at.first().unwrap(), at.last().unwrap());
    let (base, joint) = (0, 1);
    for s in [before, after] {
        assert_eq!(s.states[base], SlotState::Seated);
        assert_eq!(s.qdot[base], 0.0);
        assert!(s.q[joint].abs() < 1e-9, "at the rest pose: {}", s.q[joint]);
    }
    let pivot = |state: SlotState| match state {
        SlotState::Positive => nalgebra::Vector3::new(0.2, 0.0, 1.5),
        SlotState::Negative => nalgebra::Vector3::new(-0.2, 0.0, 1.5),
        other => panic!("the top block rocks: {other:?}"),
    };
    let (p, p_new) = (pivot(before.states[joint]), pivot(after.states[joint]));
    assert_ne!(p, p_new, "the top block switches pivot");
    let top = &model.bodies[1];
    let y = nalgebra::Vector3::y();
    let (w_minus, w_plus) = (y * before.qdot[joint], y * after.qdot[joint]);
    let j = top.mass * (w_plus.cross(&(top.com - p_new)) - w_minus.cross(&(top.com - p)));
    let angular = top.inertia * (w_plus - w_minus);
    let moment = (p_new - top.com).cross(&j);
    assert!(
        (moment - angular).norm() < 1e-9 * angular.norm(),
        "the momentum law about the new pivot: {moment} against {angular}"
    );
    let r = p_new - nalgebra::Vector3::new(-0.3, 0.0, 0.0);
    let n_plus = (r.x * j.z - r.z * j.x) / 0.6;
    let n_minus = j.z - n_plus;
    let least = n_plus.min(n_minus).min(j.z);
    assert!(
        (v.normal - least).abs() < 1e-6 * least.abs(),
        "recorded {} N s, by hand {least} N s (n⁺ {n_plus}, n⁻ {n_minus}, J_z {})",
        v.normal,
        j.z
    );
    let unit = model.total_mass() * model.gravity * (model.size / model.gravity).sqrt();
    assert!(least < -1e-3 * unit, "{least} N s of W √(L/g) = {unit} N s");
}
