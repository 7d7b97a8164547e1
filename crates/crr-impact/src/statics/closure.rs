//! The minimum-weight closure of a directed graph (Picard 1976) by one minimum cut.
//!
//! A closure is a set of nodes W with i ∈ W ⇒ j ∈ W for every arc (i, j). Its least weight
//! Σ_{i∈W} wᵢ is a maximum flow: the source feeds each node of negative weight with −wᵢ, each
//! node of positive weight drains wᵢ to the sink, arcs have unbounded capacity, and the nodes on
//! the source's side of a minimum cut are the closure. The flow is Dinic's (1970) on f64
//! capacities; written here because the max-flow crates at hand (`pathfinding`'s Edmonds–Karp)
//! take integer capacities and return the cut's arcs, not its side.

/// One arc of the residual network: its head, its residual capacity and the index of its
/// reverse arc in the head's list.
struct Arc {
    head: usize,
    residual: f64,
    reverse: usize,
}

struct Network {
    arcs: Vec<Vec<Arc>>,
    level: Vec<usize>,
    next: Vec<usize>,
    /// Residuals at or below this count as saturated (round-off of the sums).
    zero: f64,
}

impl Network {
    fn new(nodes: usize, zero: f64) -> Self {
        Network {
            arcs: (0..nodes).map(|_| Vec::new()).collect(),
            level: vec![0; nodes],
            next: vec![0; nodes],
            zero,
        }
    }

    fn add(&mut self, from: usize, to: usize, capacity: f64) {
        let (forward, backward) = (self.arcs[from].len(), self.arcs[to].len());
        self.arcs[from].push(Arc {
            head: to,
            residual: capacity,
            reverse: backward + usize::from(from == to),
        });
        self.arcs[to].push(Arc {
            head: from,
            residual: 0.0,
            reverse: forward,
        });
    }

    /// Breadth-first levels from `source`; whether `sink` is reached.
    fn levels(&mut self, source: usize, sink: usize) -> bool {
        self.level.fill(usize::MAX);
        self.level[source] = 0;
        let mut queue = std::collections::VecDeque::from([source]);
        while let Some(u) = queue.pop_front() {
            for arc in &self.arcs[u] {
                if arc.residual > self.zero && self.level[arc.head] == usize::MAX {
                    self.level[arc.head] = self.level[u] + 1;
                    queue.push_back(arc.head);
                }
            }
        }
        self.level[sink] != usize::MAX
    }

    /// One augmenting path's flow (at most `limit`) from `u` to `sink` along rising levels.
    fn augment(&mut self, u: usize, sink: usize, limit: f64) -> f64 {
        if u == sink {
            return limit;
        }
        while self.next[u] < self.arcs[u].len() {
            let k = self.next[u];
            let (head, residual) = (self.arcs[u][k].head, self.arcs[u][k].residual);
            if residual > self.zero && self.level[head] == self.level[u] + 1 {
                let pushed = self.augment(head, sink, limit.min(residual));
                if pushed > 0.0 {
                    self.arcs[u][k].residual -= pushed;
                    let reverse = self.arcs[u][k].reverse;
                    self.arcs[head][reverse].residual += pushed;
                    return pushed;
                }
            }
            self.next[u] += 1;
        }
        0.0
    }

    /// The nodes the source reaches in the residual network once the flow is maximal.
    fn source_side(&mut self, source: usize, sink: usize) -> Vec<bool> {
        while self.levels(source, sink) {
            self.next.fill(0);
            while self.augment(source, sink, f64::INFINITY) > 0.0 {}
        }
        self.levels(source, sink);
        self.level.iter().map(|&l| l != usize::MAX).collect()
    }
}

/// The closure of least weight under `arcs` ((i, j): i ∈ W ⇒ j ∈ W) with the node `included`
/// (if any) in and the nodes `excluded` out, where its weight is negative (below −1e-12 of
/// Σ|wᵢ|); None where no such closure exists.
pub(super) fn minimum_closure(
    weights: &[f64],
    arcs: &[(usize, usize)],
    included: Option<usize>,
    excluded: &[bool],
) -> Option<Vec<bool>> {
    let n = weights.len();
    let total: f64 = weights.iter().map(|w| w.abs()).sum();
    if !(total.is_finite() && total > 0.0) {
        return None;
    }
    let (source, sink) = (n, n + 1);
    let unbounded = 2.0 * total + 1.0;
    let mut network = Network::new(n + 2, 1e-15 * total);
    for (i, &w) in weights.iter().enumerate() {
        if w < 0.0 {
            network.add(source, i, -w);
        } else if w > 0.0 {
            network.add(i, sink, w);
        }
        if excluded[i] {
            network.add(i, sink, unbounded);
        }
    }
    if let Some(i) = included {
        network.add(source, i, unbounded);
    }
    for &(i, j) in arcs {
        network.add(i, j, unbounded);
    }
    let side = network.source_side(source, sink);
    let members: Vec<bool> = side[..n].to_vec();
    // Where no closure holds `included` without an excluded node, the minimum cut crosses an
    // unbounded arc, and its side breaks one of the constraints.
    let closed = arcs.iter().all(|&(i, j)| !members[i] || members[j])
        && (0..n).all(|i| !(excluded[i] && members[i]))
        && included.is_none_or(|i| members[i]);
    if !closed {
        return None;
    }
    let weight: f64 = (0..n).filter(|&i| members[i]).map(|i| weights[i]).sum();
    (weight < -1e-12 * total).then_some(members)
}

#[cfg(test)]
pub(super) mod tests {
    use super::minimum_closure;

    /// A deterministic sequence of numbers uniform in [0, 1) (a linear congruential generator),
    /// for the random graphs of the statics' unit tests.
    pub(in crate::statics) fn uniform_sequence(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as f64 / (1u64 << 31) as f64
        }
    }

    /// Every subset of a small graph, closed ones only: the least weight by enumeration.
    fn by_enumeration(
        weights: &[f64],
        arcs: &[(usize, usize)],
        included: Option<usize>,
        excluded: &[bool],
    ) -> Option<f64> {
        let n = weights.len();
        (0..1u32 << n)
            .filter(|&s| {
                let has = |i: usize| s & (1 << i) != 0;
                arcs.iter().all(|&(i, j)| !has(i) || has(j))
                    && (0..n).all(|i| !excluded[i] || !has(i))
                    && included.is_none_or(has)
            })
            .map(|s| {
                (0..n)
                    .filter(|&i| s & (1 << i) != 0)
                    .map(|i| weights[i])
                    .sum::<f64>()
            })
            .min_by(f64::total_cmp)
    }

    #[test]
    fn the_cut_finds_the_least_closure_of_every_small_graph() {
        // A deterministic family of graphs of 7 nodes: weights and arcs from a linear
        // congruential sequence, against the enumeration of all 128 subsets.
        let mut next = uniform_sequence(12345);
        for _ in 0..300 {
            let n = 7;
            let weights: Vec<f64> = (0..n).map(|_| next() * 2.0 - 1.0).collect();
            let mut arcs = Vec::new();
            for i in 0..n {
                for j in 0..n {
                    if i != j && next() < 0.2 {
                        arcs.push((i, j));
                    }
                }
            }
            let excluded: Vec<bool> = (0..n).map(|_| next() < 0.1).collect();
            let included = (next() < 0.5).then(|| (next() * n as f64) as usize);
            let least = by_enumeration(&weights, &arcs, included, &excluded);
            let negative = -1e-12 * weights.iter().map(|w| w.abs()).sum::<f64>();
            match minimum_closure(&weights, &arcs, included, &excluded) {
                Some(members) => {
                    assert!(arcs.iter().all(|&(i, j)| !members[i] || members[j]));
                    assert!((0..n).all(|i| !excluded[i] || !members[i]));
                    assert!(included.is_none_or(|i| members[i]));
                    let weight: f64 = (0..n).filter(|&i| members[i]).map(|i| weights[i]).sum();
                    let least = least.expect("a closure was found, so one exists");
                    assert!((weight - least).abs() <= 1e-12, "{weight} against {least}");
                }
                None => assert!(least.is_none_or(|l| l >= negative), "{least:?} missed"),
            }
        }
    }
}
