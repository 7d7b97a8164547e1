//! A seat on a loop near a singular configuration of its angles cannot be held by the plastic
//! impulse of an impact: the run stops naming it (`SimulationError::UnheldSeat`), where it
//! chattered 200 times within 7e-7 s, and the same structure turned about z stops at the same
//! instant with the same error (an independent check of the decision: the physics does not
//! depend on the frame).

use crr::impact::simulation::SimulationError;

/// One rocking base of the trilithon: its corners (x, y) at height `z`, turned.
struct Face<'a> {
    name: &'a str,
    parent: &'a str,
    child: &'a str,
    corners: [[f64; 2]; 4],
    z: f64,
}

/// The 3D trilithon of `crr assemble` (two 0.5 × 0.5 × 4 m columns 3 m apart under a 3.5 × 0.5 ×
/// 0.6 m architrave, every bed a rocking base with its corners in the order the assembly lists
/// them), turned by `theta` about z, under in-phase sines of 1.6 m/s² along its own x and
/// 1.2 m/s² along its own y (T = 0.8 s): both columns rock about one line along the frame (their
/// bases' y edges are collinear).
fn trilithon(theta: f64) -> String {
    let (c, s) = (theta.cos(), theta.sin());
    let turn = |[x, y, z]: [f64; 3]| format!("[{}, {}, {z}]", c * x - s * y, s * x + c * y);
    let body = |name: &str, center: [f64; 3], size: [f64; 3]| {
        format!(
            "[[body]]\nname = \"{name}\"\ndensity = 2500.0\n[body.box]\ncenter = {}\n\
             size = [{}, {}, {}]\nrotation = [0.0, 0.0, {theta}]\n\n",
            turn(center),
            size[0],
            size[1],
            size[2]
        )
    };
    let faces = [
        Face {
            name: "column_left_on_ground",
            parent: "ground",
            child: "column_left",
            corners: [[-1.25, -0.25], [-1.25, 0.25], [-1.75, 0.25], [-1.75, -0.25]],
            z: 0.0,
        },
        Face {
            name: "column_right_on_ground",
            parent: "ground",
            child: "column_right",
            corners: [[1.75, -0.25], [1.75, 0.25], [1.25, 0.25], [1.25, -0.25]],
            z: 0.0,
        },
        Face {
            name: "architrave_on_column_left",
            parent: "column_left",
            child: "architrave",
            corners: [[-1.75, -0.25], [-1.25, -0.25], [-1.25, 0.25], [-1.75, 0.25]],
            z: 4.0,
        },
        Face {
            name: "architrave_on_column_right",
            parent: "column_right",
            child: "architrave",
            corners: [[1.25, -0.25], [1.75, -0.25], [1.75, 0.25], [1.25, 0.25]],
            z: 4.0,
        },
    ];
    let interfaces: String = faces
        .iter()
        .map(|f| {
            let corners: Vec<String> = f.corners.iter().map(|&[x, y]| turn([x, y, f.z])).collect();
            format!(
                "[[interface]]\nname = \"{}\"\nparent = \"{}\"\nchild = \"{}\"\n\
                 impact = \"momentum\"\n[interface.rocking_base]\ncorners = [{}]\n\n",
                f.name,
                f.parent,
                f.child,
                corners.join(", ")
            )
        })
        .collect();
    let (ax, ay) = (1.6, 1.2);
    format!(
        "name = \"trilithon_3d\"\ngravity = 9.81\n\n{}{}{}{interfaces}\
         [ground_motion]\nx = {{ sine = {{ amplitude = {}, period = 0.8 }} }}\n\
         y = {{ sine = {{ amplitude = {}, period = 0.8 }} }}\n\n[analysis]\nduration = 1.0\n",
        body("column_left", [-1.5, 0.0, 2.0], [0.5, 0.5, 4.0]),
        body("column_right", [1.5, 0.0, 2.0], [0.5, 0.5, 4.0]),
        body("architrave", [0.0, 0.0, 4.3], [3.5, 0.5, 0.6]),
        c * ax - s * ay,
        s * ax + c * ay
    )
}

#[test]
fn a_seat_the_loop_fixes_to_second_order_stops_the_run_in_any_frame() {
    let mut stops = Vec::new();
    for (tag, theta) in [("along_x", 0.0), ("turned", 0.6457718232379019)] {
        let path = crate::common::write_model(&format!("unheld_seat_{tag}"), &trilithon(theta));
        let model = crr::ModelInput::read(&path).unwrap();
        let run = crr::run(&model, &crr::RunOptions::default()).unwrap();
        let Some(SimulationError::UnheldSeat { t, interface, rate }) = &run.failure else {
            panic!("{tag}: {:?}", run.summary.error);
        };
        assert_eq!(interface, "architrave_on_column_right", "{tag}");
        // The stop comes at the run's first impact, that of the four joints together.
        assert!(run.trajectory.impacts.is_empty(), "{tag}");
        assert!(
            run.summary.error.as_deref().unwrap().contains(
                "the seat of architrave_on_column_right cannot be held: the plastic impulse"
            ),
            "{tag}"
        );
        stops.push((*t, *rate));
    }
    let ((t0, r0), (t1, r1)) = (stops[0], stops[1]);
    // The frames' event times agree to the events' location (2e-9 s here), the rates to 1e-3.
    assert!((t0 - t1).abs() < 1e-8, "{t0} vs {t1}");
    assert!((r0 / r1 - 1.0).abs() < 1e-3, "{r0} vs {r1}");
    assert!(r0.abs() > 1e-6 && r0.abs() < 1e-4, "{r0}");
}
