//! The same structure written in another order simulates the same motion. The bundled 3D arch
//! (one loop; in motion its openings are decided by the contact program, which does not depend
//! on the order of the file) is written with its bodies and its interfaces in reverse order: the
//! spanning tree lists its coordinates in another order, the solver works on permuted vectors,
//! and yet every angle (matched by name), the uplift time and every impact (time and interfaces)
//! agree to round-off over its first 2.6 s, which include the uplift, free rocking out of plane
//! and in-plane hinging with 32 impacts. (Later the two runs part where an impact leaves a joint's
//! rate within round-off of the seating threshold: a discontinuous decision, not an order.)

use crate::common;

/// `text` with its `[[body]]` and `[[interface]]` blocks each in reverse order (a block runs from
/// its header to the next header; other tables keep their place after them).
fn reversed(text: &str) -> String {
    let mut head = String::new();
    // (kind of block: 0 body, 1 interface, 2 other table; its text)
    let mut blocks: Vec<(usize, String)> = Vec::new();
    for line in text.lines() {
        let kind = match line.trim() {
            "[[body]]" => Some(0),
            "[[interface]]" => Some(1),
            l if l.starts_with('[') => Some(2),
            _ => None,
        };
        match (kind, blocks.last_mut()) {
            (Some(k), _) => blocks.push((k, format!("{line}\n"))),
            (None, Some((_, block))) => block.push_str(&format!("{line}\n")),
            (None, None) => head.push_str(&format!("{line}\n")),
        }
    }
    let of = |kind: usize| {
        blocks
            .iter()
            .filter(move |b| b.0 == kind)
            .map(|b| b.1.as_str())
    };
    let bodies: Vec<&str> = of(0).rev().collect();
    let interfaces: Vec<&str> = of(1).rev().collect();
    let rest: Vec<&str> = of(2).collect();
    format!(
        "{head}{}{}{}",
        bodies.concat(),
        interfaces.concat(),
        rest.concat()
    )
}

#[test]
fn the_3d_arch_written_in_reverse_order_moves_the_same() {
    let records = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/records");
    let text = common::bundled_text("arch_3d")
        .replace("\"../records/", &format!("\"{}/", records.display()));
    let other = reversed(&text);
    assert_ne!(text, other);
    let duration = Some(2.6);
    let (model_a, a) = common::run_model_text("arch_3d_order_a", &text, duration);
    let (model_b, b) = common::run_model_text("arch_3d_order_b", &other, duration);
    assert_ne!(
        model_a.bodies[0].name, model_b.bodies[0].name,
        "the bodies are listed in another order"
    );
    assert_eq!(a.uplift_time, b.uplift_time);
    assert_eq!(a.impacts.len(), b.impacts.len());
    assert!(a.impacts.len() > 20, "{} impacts", a.impacts.len());
    for (x, y) in a.impacts.iter().zip(&b.impacts) {
        assert!(
            (x.t - y.t).abs() < 1e-9,
            "impact at {} against {}",
            x.t,
            y.t
        );
        let (mut p, mut q) = (x.interfaces.clone(), y.interfaces.clone());
        p.sort();
        q.sort();
        assert_eq!(p, q, "at {}", x.t);
    }
    assert_eq!(a.samples.len(), b.samples.len());
    for (k, coord) in model_a.coords.iter().enumerate() {
        let j = model_b
            .coords
            .iter()
            .position(|c| c.name == coord.name)
            .unwrap_or_else(|| panic!("{} is a coordinate of one listing only", coord.name));
        for (s, r) in a.samples.iter().zip(b.samples.iter()) {
            assert!(
                (s.q[k] - r.q[j]).abs() < 1e-9,
                "{} at {}: {} against {}",
                coord.name,
                s.t,
                s.q[k],
                r.q[j]
            );
        }
    }
}
