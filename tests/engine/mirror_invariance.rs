//! A structure written mirrored (x → −x) under the mirrored ground motion moves as the mirror
//! image of the original: the engine's decisions (uplift from rest and in motion, which joints
//! open and to which side, seating, impacts) do not depend on how the file orients the
//! structure. Compared without any coordinate convention: the kinetic and potential energies at
//! every sample (scalars a reflection leaves unchanged), the uplift time, and every impact's time
//! and interfaces (the mirror keeps the names).

use crr::dynamics::ground_motion::{Axis, Record};
use crr::input::model_file::{ModelFile, load_model};
use crr::input::synthetic::{DT, accelerogram};
use crr::{ModelInput, RecordSamples, RunOptions};

use crate::common;

/// The bundled model `name` and its mirror (x → −x), as model inputs without their own ground
/// motion.
fn original_and_mirror(name: &str) -> (ModelInput, ModelInput) {
    let (file, _) = load_model(&common::bundled_path(name)).unwrap();
    // From rest: the mirror of an initial tilt of a rocking base is not the same named angle.
    let strip = |f: &ModelFile| ModelFile {
        ground_motion: None,
        initial: None,
        ..f.clone()
    };
    let mirrored = common::mirrored_x(&file.structure());
    let mirror = ModelFile {
        body: mirrored.body,
        interface: mirrored.interface,
        ..strip(&file)
    };
    let input = |f: ModelFile, tag: &str| {
        let json = serde_json::to_string(&f).unwrap();
        ModelInput::parse(format!("{name}_{tag}.json"), &json, true).unwrap()
    };
    (input(strip(&file), "original"), input(mirror, "mirror"))
}

/// The bundled synthetic accelerogram scaled to `pga_g`, on x (sign `sx`) and on y.
fn records(pga_g: f64, sx: f64, with_y: bool) -> Vec<RecordSamples> {
    let g = 9.80665;
    let a: Vec<f64> = accelerogram().iter().map(|v| v * g).collect();
    let record = Record::uniform(DT, a).unwrap();
    let scale = pga_g / crr::input::synthetic::PGA_G;
    let mut out = vec![RecordSamples {
        component: Axis::X,
        record: record.clone(),
        scale: sx * scale,
    }];
    if with_y {
        // Reversed in time on y, so that the two components differ.
        let rev: Vec<f64> = accelerogram().iter().rev().map(|v| v * g).collect();
        out.push(RecordSamples {
            component: Axis::Y,
            record: Record::uniform(DT, rev).unwrap(),
            scale,
        });
    }
    out
}

#[test]
fn mirrored_files_under_the_mirrored_record_move_as_mirror_images() {
    // (model, PGA in g, a y component too): PGAs above each model's multiplier, so that it
    // uplifts, rocks and impacts.
    for (name, pga, with_y) in [
        ("trilithon", 0.3, false),
        ("two_block_stack", 0.4, false),
        ("wall", 1.0, false),
        ("baldachin", 0.35, true),
    ] {
        let (original, mirror) = original_and_mirror(name);
        let run = |input: &ModelInput, sx: f64| {
            let opts = RunOptions {
                records: records(pga, sx, with_y),
                duration: Some(8.0),
                ..Default::default()
            };
            crr::run(input, &opts).unwrap()
        };
        let (a, b) = (run(&original, 1.0), run(&mirror, -1.0));
        let (ta, tb) = (&a.trajectory, &b.trajectory);
        println!(
            "{name}: {} impacts, uplift {:?}, end {} s, collapse {:?}, error {:?}",
            ta.impacts.len(),
            ta.uplift_time,
            ta.end_time,
            ta.collapse,
            a.summary.error
        );
        assert_eq!(
            a.summary.error, b.summary.error,
            "{name}: both runs end alike"
        );
        if name == "wall" {
            // The running-bond wall's corner wedge lifts blocks off one of their supports: both
            // runs take those faces out of the chain (docs/simulation.md, "Faces that open") and
            // go on to the same end.
            assert!(a.summary.error.is_none(), "{name}: {:?}", a.summary.error);
            for t in [ta, tb] {
                assert!(
                    t.samples
                        .iter()
                        .any(|s| s.states.contains(&crr::impact::SlotState::Open)),
                    "{name}: a face opens"
                );
            }
            assert!((ta.end_time - tb.end_time).abs() <= 1e-9, "{name}: end");
        } else {
            assert!(
                ta.impacts.len() >= 2,
                "{name}: {} impacts",
                ta.impacts.len()
            );
            assert!(ta.uplift_time.is_some(), "{name}: it uplifts");
            // Under these records the three rock and then overturn, in both runs (so the
            // comparison covers the collapse decision as well).
            assert!(ta.collapse.is_some(), "{name}: it overturns");
        }
        assert_eq!(
            ta.impacts.len(),
            tb.impacts.len(),
            "{name}: impact counts differ"
        );
        for (i, j) in ta.impacts.iter().zip(&tb.impacts) {
            assert!(
                (i.t - j.t).abs() <= 1e-8,
                "{name}: impact at {} against {}",
                i.t,
                j.t
            );
            let (mut x, mut y) = (i.interfaces.clone(), j.interfaces.clone());
            x.sort();
            y.sort();
            assert_eq!(x, y, "{name}: impact at {}", i.t);
        }
        match (ta.uplift_time, tb.uplift_time) {
            (Some(x), Some(y)) => assert!((x - y).abs() <= 1e-9, "{name}: uplift {x} against {y}"),
            (x, y) => assert_eq!(x, y, "{name}: uplift"),
        }
        assert_eq!(
            ta.collapse.is_some(),
            tb.collapse.is_some(),
            "{name}: collapse"
        );
        let (sa, sb) = (&ta.samples, &tb.samples);
        // The samples at impacts fall at the impact times, equal to round-off only.
        assert_eq!(sa.len(), sb.len(), "{name}: sample counts");
        for (x, y) in sa.times().iter().zip(sb.times()) {
            assert!((x - y).abs() <= 1e-8, "{name}: sample at {x} against {y}");
        }
        let scale = sa
            .kinetic()
            .iter()
            .chain(sa.potential())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        for (series, (x, y)) in [
            ("T", (sa.kinetic(), sb.kinetic())),
            ("U", (sa.potential(), sb.potential())),
        ] {
            let worst = x
                .iter()
                .zip(y)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0f64, f64::max);
            assert!(
                worst <= 1e-7 * scale,
                "{name}: {series} differs by {worst:.3e} J of {scale:.3e} J"
            );
        }
        println!("{name}: {} samples, peak energy {scale:.3e} J", sa.len());
    }
}
