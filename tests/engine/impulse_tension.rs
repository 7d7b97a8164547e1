//! A momentum-law impact that would pull at a seated joint opens it instead (docs/simulation.md,
//! "Impulses at landings and impacts"), checked by hand on the bundled two-block stack: from the
//! bodies' velocities before the impact, their masses and their box inertias, independently of
//! the engine's mass matrix, its impulse program and its linear program. With
//! `hold_seated_at_impacts` (the paper's law) the joint is held and the pull is recorded, checked
//! by hand against the statics of the impulses on each block.

use crr::impact::SlotState;

/// y-component of r × v for vectors in the xz-plane.
fn cross_y(r: [f64; 2], v: [f64; 2]) -> f64 {
    r[1] * v[0] - r[0] * v[1]
}

/// Velocity (x, z) of point `x` of a body turning at ω about y through `pivot`: ω ŷ × (x − p).
fn turning(omega: f64, x: [f64; 2], pivot: [f64; 2]) -> [f64; 2] {
    [omega * (x[1] - pivot[1]), -omega * (x[0] - pivot[0])]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// A body's angular momentum about y through `a`: I_c ω + m (c − a) × v_c.
fn momentum_about(a: [f64; 2], (m, i, c): (f64, f64, [f64; 2]), omega: f64, v: [f64; 2]) -> f64 {
    i * omega + m * cross_y(sub(c, a), v)
}

/// The two-block stack (`examples/models/two_block_stack.toml`: a 0.6 × 0.6 × 1.5 m base on the
/// ground, pivots at x = ±0.3 m; a 0.4 × 0.4 × 1.6 m block on it, pivots at x = ±0.2 m, z = 1.5 m;
/// 2400 kg/m³) rocks on its top block after the pulse, the base seated. At the impact of
/// 1.8045 s the top block switches from its pivot P to P′ on the base's top face.
///
/// Holding the base (the momentum law with "the other hinges persisting") would pull: the top
/// block's angular momentum about P′ kept gives its rate ω_h, its momentum change m(v⁺ − v⁻) is
/// the impulse J it takes at P′, and the base, at rest, can pass J to the ground only through
/// its pivot lines G± = (±0.3, 0): n⁺ + n⁻ = J_z and 0.6 n⁺ = r_x J_z − r_z J_x (r = P′ − G⁻),
/// one of them below −1e-3 W √(L/g).
///
/// The engine opens the base instead (Moreau's impact): after it the base turns about one ground
/// pivot G, the top block about P′. The impulses act at P′ (on the top block) and at G (on the
/// structure) only, so the top block's angular momentum about P′ and the whole stack's about G are
/// kept: two equations for the two rates (ω_b, ω_j), solved here, which the engine's rates match
/// to 1e-9 of the rate before. Then the impulse at G pushes up, the top block is pushed up at P′,
/// the base's other corner and the top block's old pivot rise, and T falls.
#[test]
fn the_two_block_stack_s_impact_opens_its_base_as_computed_by_hand() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/models/two_block_stack.toml");
    let input = crr::ModelInput::read(&path).unwrap();
    let run = crr::run(&input, &crr::RunOptions::default()).unwrap();
    let (model, traj) = (&run.model, &run.trajectory);
    let impact = traj
        .impacts
        .iter()
        .find(|i| (i.t - 1.8045).abs() < 1e-4)
        .expect("the top block's impact at 1.8045 s");
    assert_eq!(impact.interfaces, ["joint"]);
    assert_eq!(impact.released, [0], "the base opens at the impact");
    // No tension recorded up to and at that impact.
    if let Some(v) = &traj.violation {
        assert!(v.t > impact.t, "{} at {} s", v.kind, v.t);
    }
    let at: Vec<_> = traj.samples.iter().filter(|s| s.t == impact.t).collect();
    let (before, after) = (at.first().unwrap(), at.last().unwrap());
    let (base, joint) = (0, 1);
    assert_eq!(before.states[base], SlotState::Seated);
    assert_eq!(before.qdot[base], 0.0);
    assert_ne!(after.states[base], SlotState::Seated);
    for s in [before, after] {
        assert!(s.q[base].abs() < 1e-12 && s.q[joint].abs() < 1e-9);
    }

    // The bodies by hand: (mass, I_yy about the centre, centre (x, z)).
    let lower = (2400.0 * 0.6 * 0.6 * 1.5, 0.0, [0.0, 0.75]);
    let lower = (lower.0, lower.0 * (0.36 + 2.25) / 12.0, lower.2);
    let upper = (2400.0 * 0.4 * 0.4 * 1.6, 0.0, [0.0, 2.3]);
    let upper = (upper.0, upper.0 * (0.16 + 2.56) / 12.0, upper.2);
    let top_pivot = |state: SlotState| match state {
        SlotState::Positive => [0.2, 1.5],
        SlotState::Negative => [-0.2, 1.5],
        other => panic!("the top block rocks: {other:?}"),
    };
    let (p, p_new) = (
        top_pivot(before.states[joint]),
        top_pivot(after.states[joint]),
    );
    assert_ne!(p, p_new, "the top block switches pivot");
    let g = match after.states[base] {
        SlotState::Positive => [0.3, 0.0],
        SlotState::Negative => [-0.3, 0.0],
        other => panic!("the base rocks: {other:?}"),
    };
    let g_other = [-g[0], 0.0];

    // Before: the base at rest, the top block turning about P.
    let w = before.qdot[joint];
    let v_top_minus = turning(w, upper.2, p);
    let kinetic_minus =
        0.5 * upper.0 * (v_top_minus[0].powi(2) + v_top_minus[1].powi(2)) + 0.5 * upper.1 * w * w;
    assert!((kinetic_minus - before.kinetic).abs() < 1e-9 * kinetic_minus);
    let h_top_minus = momentum_about(p_new, upper, w, v_top_minus);
    let h_all_minus = momentum_about(g, upper, w, v_top_minus);

    // After, for rates (ω_b, ω_j): the base about G, the top block about P′ carried by the base.
    let velocities = |wb: f64, wj: f64| {
        let v_low = turning(wb, lower.2, g);
        let v_top = {
            let a = turning(wb, upper.2, g);
            let b = turning(wj, upper.2, p_new);
            [a[0] + b[0], a[1] + b[1]]
        };
        (v_low, v_top)
    };
    let conserved = |wb: f64, wj: f64| {
        let (v_low, v_top) = velocities(wb, wj);
        (
            momentum_about(p_new, upper, wb + wj, v_top),
            momentum_about(g, upper, wb + wj, v_top) + momentum_about(g, lower, wb, v_low),
        )
    };
    let (a11, a21) = conserved(1.0, 0.0);
    let (a12, a22) = conserved(0.0, 1.0);
    let det = a11 * a22 - a12 * a21;
    let wb = (h_top_minus * a22 - a12 * h_all_minus) / det;
    let wj = (a11 * h_all_minus - a21 * h_top_minus) / det;
    println!(
        "by hand ω_b = {wb}, ω_j = {wj}; engine {} and {}",
        after.qdot[base], after.qdot[joint]
    );
    assert!((after.qdot[base] - wb).abs() < 1e-9 * w.abs(), "ω_b");
    assert!((after.qdot[joint] - wj).abs() < 1e-9 * w.abs(), "ω_j");

    // Moreau's conditions, by hand: compressive impulses where contacts stay, contacts that
    // leave rise, and energy lost.
    let (v_low, v_top) = velocities(wb, wj);
    let on_top = [
        upper.0 * (v_top[0] - v_top_minus[0]),
        upper.0 * (v_top[1] - v_top_minus[1]),
    ];
    let from_ground = [
        on_top[0] + lower.0 * v_low[0],
        on_top[1] + lower.0 * v_low[1],
    ];
    assert!(on_top[1] > 0.0, "P′ pushes the top block up: {on_top:?}");
    assert!(from_ground[1] > 0.0, "G pushes up: {from_ground:?}");
    assert!(
        turning(wb, g_other, g)[1] > 0.0,
        "the base's other corner rises"
    );
    let p_relative = turning(wj, p, p_new);
    assert!(p_relative[1] > 0.0, "the old pivot P rises off the base");
    let kinetic_plus = 0.5 * lower.0 * (v_low[0].powi(2) + v_low[1].powi(2))
        + 0.5 * lower.1 * wb * wb
        + 0.5 * upper.0 * (v_top[0].powi(2) + v_top[1].powi(2))
        + 0.5 * upper.1 * (wb + wj).powi(2);
    assert!((kinetic_plus - after.kinetic).abs() < 1e-9 * kinetic_minus);
    assert!(kinetic_plus < kinetic_minus);

    // Holding the base would have pulled at the ground: the top block alone turning about P′,
    // its angular momentum about P′ kept.
    let (h11, _) = conserved(0.0, 1.0);
    let w_held = h_top_minus / h11;
    let v_held = turning(w_held, upper.2, p_new);
    let j = [
        upper.0 * (v_held[0] - v_top_minus[0]),
        upper.0 * (v_held[1] - v_top_minus[1]),
    ];
    let r = sub(p_new, [-0.3, 0.0]);
    let n_plus = (r[0] * j[1] - r[1] * j[0]) / 0.6;
    let n_minus = j[1] - n_plus;
    let unit = model.total_mass() * model.gravity * (model.size / model.gravity).sqrt();
    println!("held: n⁺ = {n_plus} N s, n⁻ = {n_minus} N s (unit {unit} N s)");
    assert!(n_plus.min(n_minus) < -1e-3 * unit);
}

/// The two-block stack (`examples/models/two_block_stack.toml`: a 0.6 × 0.6 × 1.5 m base on the
/// ground, pivots at x = ±0.3 m; a 0.4 × 0.4 × 1.6 m block on it, pivots at x = ±0.2 m, z = 1.5 m)
/// rocks on its top block after the pulse; with `hold_seated_at_impacts` the base stays seated
/// through the top block's impacts ("the other hinges persist", the paper's law). At the impact
/// of 1.8045 s the top block's impulse on the base's top face presses the base's edge under the
/// new pivot and would lift the other one: the ground can balance it only by pulling at that
/// far edge, which the run records.
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
fn held_through_the_impact_the_base_pulls_as_computed_by_hand() {
    let text = crate::common::bundled_text("two_block_stack").replace(
        "duration = 6.0",
        "duration = 6.0\nhold_seated_at_impacts = true",
    );
    assert!(text.contains("hold_seated_at_impacts = true"));
    let path = crate::common::write_model("two_block_stack_held", &text);
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

/// The bundled drum column (eight drums 0.6 × 0.6 × 0.5 m and a capital 1 × 1 × 0.4 m, 2500 kg/m³;
/// every bed a hinge about y with pivots at x = ±0.3 m, z = 0, 0.5, …, 4 m) under its pulse: the
/// impact of 0.4021 s would pull at the beds held seated through it, and opens three of them
/// instead. Moreau's impact, by hand: every joint that turns after the impact (released,
/// impacting or rocking on) takes its impulse at its pivot only, so the bodies above it keep
/// their angular momentum about that pivot; the bodies' poses and velocities are rebuilt here
/// from the sampled angles and rates by planar kinematics (each body turning about its bed's
/// active pivot, carried by the one below), with the boxes' masses and inertias, not from the
/// engine's mass matrix. Conserved to 1e-9 of the largest momentum (round-off of the solve;
/// the held joints' impulses, which no equation here sees, would break them by their size).
#[test]
fn the_drum_column_s_impact_opens_three_beds_keeping_every_turning_joint_s_momentum() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/drum_column.toml");
    let input = crr::ModelInput::read(&path).unwrap();
    let run = crr::run(&input, &crr::RunOptions::default()).unwrap();
    let (model, traj) = (&run.model, &run.trajectory);
    let names = [
        "bed_1", "bed_2", "bed_3", "bed_4", "bed_5", "bed_6", "bed_7", "bed_8", "capital",
    ];
    for (k, name) in names.iter().enumerate() {
        assert_eq!(model.coords[k].name, *name, "coordinate {k}");
    }
    let impact = traj
        .impacts
        .iter()
        .find(|i| (i.t - 0.4021).abs() < 1e-4)
        .expect("the impact at 0.4021 s");
    assert_eq!(impact.released, [2, 3, 4], "bed_3, bed_4 and bed_5 open");
    let at: Vec<_> = traj.samples.iter().filter(|s| s.t == impact.t).collect();
    let (before, after) = (at.first().unwrap(), at.last().unwrap());
    for &k in &impact.released {
        assert_eq!(before.states[k], SlotState::Seated);
        let sign = match after.states[k] {
            SlotState::Positive => 1.0,
            SlotState::Negative => -1.0,
            other => panic!("bed {k} is released: {other:?}"),
        };
        assert!(sign * after.qdot[k] > 0.0, "bed {k} opens on its pivot");
    }

    // The bodies by hand: (mass, I_yy about the centre, centre at rest (x, z)).
    let drum = 2500.0 * 0.6 * 0.6 * 0.5;
    let capital = 2500.0 * 0.4;
    let bodies: Vec<(f64, f64, [f64; 2])> = (0..9)
        .map(|k| {
            if k < 8 {
                (
                    drum,
                    drum * (0.36 + 0.25) / 12.0,
                    [0.0, 0.25 + 0.5 * k as f64],
                )
            } else {
                (capital, capital * (1.0 + 0.16) / 12.0, [0.0, 4.2])
            }
        })
        .collect();
    // Planar kinematics: body k turns by φₖ about its bed's active pivot Pₖ, carried by body
    // k − 1: X ↦ Tₖ(X) = Tₖ₋₁(Pₖ + R(φₖ)(X − Pₖ)), R about +y: (x, z) ↦ (x cos φ + z sin φ,
    // −x sin φ + z cos φ). Returns each body's centre, absolute rate and centre velocity, and
    // each bed's pivot in the world.
    let kinematics = |s: &crr::impact::Sample| {
        let rot = |phi: f64, v: [f64; 2]| {
            [
                v[0] * phi.cos() + v[1] * phi.sin(),
                -v[0] * phi.sin() + v[1] * phi.cos(),
            ]
        };
        // Each transform as (total angle, the image of the origin).
        let mut frames: Vec<(f64, [f64; 2])> = Vec::new();
        let (mut angle, mut origin) = (0.0, [0.0, 0.0]);
        let mut pivots = Vec::new();
        for k in 0..9 {
            let x = match s.states[k] {
                SlotState::Negative => -0.3,
                _ => 0.3,
            };
            let p = [x, 0.5 * k as f64];
            // Tₖ(X) = Tₖ₋₁(P + R(φ)(X − P)) with Tₖ₋₁(Y) = origin + R(angle) Y.
            let image = |y: [f64; 2]| {
                let r = rot(angle, y);
                [origin[0] + r[0], origin[1] + r[1]]
            };
            pivots.push(image(p));
            let phi = s.q[k];
            let shifted = rot(phi, [-p[0], -p[1]]);
            let new_origin = image([p[0] + shifted[0], p[1] + shifted[1]]);
            angle += phi;
            origin = new_origin;
            frames.push((angle, origin));
        }
        let centre = |k: usize| {
            let r = rot(frames[k].0, bodies[k].2);
            [frames[k].1[0] + r[0], frames[k].1[1] + r[1]]
        };
        let mut rates = Vec::new();
        let mut velocities: Vec<[f64; 2]> = Vec::new();
        let mut omega = 0.0;
        for k in 0..9 {
            omega += s.qdot[k];
            rates.push(omega);
            // v(c) = Σ_{j ≤ k} φ̇ⱼ ŷ × (c − pⱼ).
            let c = centre(k);
            let mut v = [0.0, 0.0];
            for (j, p) in pivots.iter().enumerate().take(k + 1) {
                let w = turning(s.qdot[j], c, *p);
                v = [v[0] + w[0], v[1] + w[1]];
            }
            velocities.push(v);
        }
        (
            (0..9).map(centre).collect::<Vec<_>>(),
            rates,
            velocities,
            pivots,
        )
    };
    let (c_minus, w_minus, v_minus, _) = kinematics(before);
    let (c_plus, w_plus, v_plus, pivots_after) = kinematics(after);
    for k in 0..9 {
        let shift = sub(c_plus[k], c_minus[k]);
        assert!(
            shift[0].abs() + shift[1].abs() < 1e-9,
            "body {k} moved at the impact"
        );
    }
    let momentum_above = |k: usize, a: [f64; 2], w: &[f64], v: &[[f64; 2]], c: &[[f64; 2]]| {
        (k..9)
            .map(|b| momentum_about(a, (bodies[b].0, bodies[b].1, c[b]), w[b], v[b]))
            .sum::<f64>()
    };
    let scale = (0..9)
        .map(|k| momentum_above(k, pivots_after[k], &w_minus, &v_minus, &c_minus).abs())
        .fold(0.0, f64::max);
    let mut turning_joints = 0;
    for k in 0..9 {
        if after.states[k] == SlotState::Seated {
            assert_eq!(after.qdot[k], 0.0, "bed {k} held");
            continue;
        }
        turning_joints += 1;
        let a = pivots_after[k];
        let h_minus = momentum_above(k, a, &w_minus, &v_minus, &c_minus);
        let h_plus = momentum_above(k, a, &w_plus, &v_plus, &c_plus);
        println!("joint {k}: H⁻ = {h_minus}, H⁺ = {h_plus}");
        assert!(
            (h_plus - h_minus).abs() <= 1e-9 * scale,
            "joint {k}: H⁺ − H⁻ = {:e} of {scale}",
            h_plus - h_minus
        );
    }
    assert!(turning_joints >= 4, "{turning_joints}");
}
