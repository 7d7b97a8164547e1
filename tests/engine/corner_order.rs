//! A rocking base's corner list fixes the order of its two tilts (`.1` about the edge from its
//! corner 0 to corner 1, then `.2`). Seated and on an edge the orders describe the same
//! positions, and the runs agree to round-off; on a corner they differ by a twist of order φ₁φ₂,
//! an idealisation a run warns of from the first sample where a base rocks on a corner.

/// A 0.4 × 0.6 × 2 m block on a rocking base whose corner list starts from corner `first`, under
/// sines of `ax` and `ay` m/s² (T = 0.8 s, two cycles) for `duration` s.
fn block(first: usize, ax: f64, ay: f64, duration: f64) -> String {
    let corners = [[-0.2, -0.3], [0.2, -0.3], [0.2, 0.3], [-0.2, 0.3]];
    let list: Vec<String> = (0..4)
        .map(|i| {
            let [x, y] = corners[(first + i) % 4];
            format!("[{x}, {y}, 0.0]")
        })
        .collect();
    format!(
        "name = \"block_3d\"\n[[body]]\nname = \"block\"\ndensity = 2500.0\n\
         box = {{ center = [0.0, 0.0, 1.0], size = [0.4, 0.6, 2.0] }}\n[[interface]]\n\
         name = \"base\"\nparent = \"ground\"\nchild = \"block\"\n\
         rocking_base = {{ corners = [{}] }}\n[ground_motion]\n\
         x = {{ sine = {{ amplitude = {ax}, period = 0.8, cycles = 2 }} }}\n\
         y = {{ sine = {{ amplitude = {ay}, period = 0.8, cycles = 2 }} }}\n\
         [analysis]\nduration = {duration}\n",
        list.join(", ")
    )
}

fn run(tag: &str, text: &str) -> crr::Run {
    let path = crate::common::write_model(tag, text);
    let model = crr::ModelInput::read(&path).unwrap();
    crr::run(&model, &crr::RunOptions::default()).unwrap()
}

const CORNER: &str = "base rocked on a corner (both tilts turned)";

/// The block's tilts in the frame of the list from corner 0 (e₁ = +x, e₂ = +y): the list from
/// corner 1 has e₁ = +y, e₂ = −x, so its `.1` is the first list's `.2` and its `.2` is minus
/// the first list's `.1`. Returns (t, φ₁, φ₂) of every sample.
fn tilts(run: &crr::Run, first: usize) -> Vec<(f64, f64, f64)> {
    let s = &run.trajectory.samples;
    s.times()
        .iter()
        .zip(s.q().chunks_exact(2))
        .map(|(&t, q)| match first {
            0 => (t, q[0], q[1]),
            _ => (t, -q[1], q[0]),
        })
        .collect()
}

/// Along x alone the block rocks about its y edges (one tilt): the two lists give the same
/// history to round-off, impacts included, and no warning. Under both components it reaches a
/// corner at the same sample in both, after identical histories, and both runs warn from there.
#[test]
fn corner_order_changes_nothing_on_an_edge_and_is_warned_on_a_corner() {
    for (ax, ay) in [(4.8, 0.0), (4.8, 5.6)] {
        // Along x alone 2 s: impacts from 0.82 s; it overturns at 2.56 s.
        let duration = if ay == 0.0 { 2.0 } else { 1.0 };
        let runs = [0, 1].map(|first| {
            run(
                &format!("corner_{first}_{ay}"),
                &block(first, ax, ay, duration),
            )
        });
        let [a, b] = [tilts(&runs[0], 0), tilts(&runs[1], 1)];
        let corner = runs
            .iter()
            .map(|r| r.warnings().iter().find(|w| w.contains(CORNER)).cloned());
        let corner: Vec<Option<String>> = corner.collect();
        if ay == 0.0 {
            assert_eq!(corner, [None, None], "along x alone");
            assert_eq!(a.len(), b.len());
            assert_eq!(
                runs[0].trajectory.impacts.len(),
                runs[1].trajectory.impacts.len()
            );
            assert!(runs[0].trajectory.impacts.len() >= 2);
            for (x, y) in a.iter().zip(&b) {
                // Impacts located to round-off: the samples taken at them too.
                assert!((x.0 - y.0).abs() < 1e-12, "{x:?} vs {y:?}");
                // Angles of order 0.1 rad through impacts: round-off of the integration.
                assert!(
                    (x.1 - y.1).abs() < 1e-12 && (x.2 - y.2).abs() < 1e-12,
                    "{x:?} vs {y:?}"
                );
            }
            continue;
        }
        // Both warn, from the same sample: 0.08 s (it first rocks on an edge at 0.06 s).
        for w in &corner {
            assert!(
                w.as_deref()
                    .is_some_and(|w| w.starts_with("from t = 8e-2 s (an output sample) base")),
                "{w:?}"
            );
        }
        // Until then the same positions, to round-off.
        for (x, y) in a.iter().zip(&b).take_while(|(x, _)| x.0 < 0.0799) {
            assert_eq!(x.0, y.0);
            assert!(
                (x.1 - y.1).abs() < 1e-15 && (x.2 - y.2).abs() < 1e-15,
                "{x:?} vs {y:?}"
            );
        }
        // On the corner the two idealisations part (the twist between them is of order φ₁φ₂):
        // by 1e-4 rad at 0.26 s on tilts of 0.02 rad, far above round-off (samples of equal
        // times: no impact before 0.3 s).
        let part = a
            .iter()
            .zip(&b)
            .filter(|(x, y)| x.0 >= 0.26 && x.0 <= 0.3 && x.0 == y.0)
            .map(|(x, y)| (x.1 - y.1).abs().max((x.2 - y.2).abs()))
            .fold(0.0, f64::max);
        assert!(part > 1e-5, "{part}");
    }
}
