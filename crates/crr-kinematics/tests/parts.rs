//! The connected parts of a model (`Model::parts`): checked against the part counts of known
//! structures and, on random forests of chains, against a breadth-first search over the bodies'
//! interface graph (an independent route), and against the physical fact that makes them
//! useful: M(q) and Φ_q do not couple coordinates of different parts.

use crr_kinematics::fixtures::{
    SplitMix, forest, random_chain, serial_chain, single_block, trilithon,
};
use crr_kinematics::*;
use nalgebra::DVector;

fn model(spec: &spec::StructureSpec) -> Model {
    Model::from_spec(spec).expect("fixture is valid")
}

/// Part of each body by breadth-first search over the interfaces joining two bodies (tree or
/// closure), plus the symmetry rows' coordinates' bodies; interfaces to the ground join nothing.
fn body_parts_by_search(m: &Model) -> Vec<usize> {
    let nb = m.bodies.len();
    let mut adj = vec![Vec::new(); nb];
    for i in &m.interfaces {
        if let Parent::Body(p) = i.parent {
            adj[p].push(i.child);
            adj[i.child].push(p);
        }
    }
    let child_of = |k: usize| m.interfaces[m.coords[k].interface].child;
    for &(a, b, _) in &m.symmetries {
        let (x, y) = (child_of(a), child_of(b));
        adj[x].push(y);
        adj[y].push(x);
    }
    let mut part = vec![usize::MAX; nb];
    let mut count = 0;
    for start in 0..nb {
        if part[start] != usize::MAX {
            continue;
        }
        let mut stack = vec![start];
        part[start] = count;
        while let Some(b) = stack.pop() {
            for &c in &adj[b] {
                if part[c] == usize::MAX {
                    part[c] = count;
                    stack.push(c);
                }
            }
        }
        count += 1;
    }
    part
}

#[test]
fn known_structures() {
    let chain = model(&serial_chain(5));
    let parts = chain.parts();
    assert_eq!(parts.len(), 1);
    assert_eq!(parts.coords[0], (0..chain.dof()).collect::<Vec<_>>());

    let blocks: Vec<_> = (0..7)
        .map(|i| single_block(0.2 + 0.01 * i as f64, 1.0, 2000.0))
        .collect();
    let m = model(&forest(&blocks, 3.0));
    let parts = m.parts();
    assert_eq!(parts.len(), 7);
    for (p, coords) in parts.coords.iter().enumerate() {
        assert_eq!(coords, &vec![p]);
        assert_eq!(parts.bodies[p], vec![p]);
    }

    // A trilithon's three coordinates are two trees from the ground joined by the closure.
    let t = model(&trilithon(0.3, 1.5, 3.0, 0.6, 0.5));
    assert_eq!(t.closures.len(), 1);
    let parts = t.parts();
    assert_eq!(parts.len(), 1);
    assert!(parts.of_slot.iter().all(|&p| p == 0));
    // Two trilithons side by side: two parts.
    let spec = trilithon(0.3, 1.5, 3.0, 0.6, 0.5);
    let two = model(&forest(&[spec.clone(), spec], 10.0));
    assert_eq!(two.parts().len(), 2);
}

#[test]
fn random_forests_match_a_graph_search_and_decouple_m_and_phi() {
    let mut rng = SplitMix(0x5EED);
    for case in 0..40 {
        let chains: Vec<_> = (0..1 + rng.below(5))
            .map(|i| random_chain(1000 * case + i as u64, 1 + rng.below(6), rng.below(3)))
            .collect();
        let m = model(&forest(&chains, 20.0));
        let parts = m.parts();
        let by_search = body_parts_by_search(&m);
        // The same partition: bodies b, c share a part iff the search put them together.
        for b in 0..m.bodies.len() {
            for c in 0..m.bodies.len() {
                let same = parts.of_coord[m.body_coord[b]] == parts.of_coord[m.body_coord[c]];
                assert_eq!(same, by_search[b] == by_search[c], "case {case}: {b}, {c}");
            }
        }
        // Bookkeeping: the lists partition coordinates and bodies, closed under parents.
        let total: usize = parts.coords.iter().map(Vec::len).sum();
        assert_eq!(total, m.dof());
        assert_eq!(
            parts.bodies.iter().map(Vec::len).sum::<usize>(),
            m.bodies.len()
        );
        for (p, coords) in parts.coords.iter().enumerate() {
            assert!(coords.windows(2).all(|w| w[0] < w[1]));
            for &k in coords {
                assert_eq!(parts.of_coord[k], p);
                if let Some(a) = m.coords[k].parent {
                    assert_eq!(parts.of_coord[a], p);
                }
            }
        }
        // M(q) and Φ_q at a random state: no entry couples two parts (exact zeros, since the
        // recursions never combine quantities of different trees), every row lies in one part.
        let mut data = Data::new(&m);
        let q = DVector::from_fn(m.dof(), |_, _| rng.uniform(-0.4, 0.4));
        let pivots = ActivePivots::uniform(&m, Side::Positive);
        forward_kinematics(&m, &mut data, &q, &pivots);
        mass_matrix(&m, &mut data);
        constraint_jacobian(&m, &mut data, &pivots);
        for i in 0..m.dof() {
            for j in 0..m.dof() {
                if parts.of_coord[i] != parts.of_coord[j] {
                    assert_eq!(data.mass_matrix[(i, j)], 0.0, "case {case}: M[{i},{j}]");
                }
            }
        }
        for r in 0..m.constraint_rows {
            let touched: Vec<usize> = (0..m.dof())
                .filter(|&k| data.phi_q[(r, k)] != 0.0)
                .map(|k| parts.of_coord[k])
                .collect();
            assert!(
                touched.windows(2).all(|w| w[0] == w[1]),
                "case {case}: row {r}"
            );
        }
    }
}
