//! Disjoint sets (union–find) over the indices 0..n: which bodies a set of interfaces joins.
//!
//! Used for a structure's independent parts ([`crate::Model::parts`]), the bodies left without a
//! path to the ground when interfaces open ([`crate::Model::bodies_off_ground`]: the exhaustive
//! pass's sets and the flights of a run) and the domains no mechanism separates (the facade
//! crate's rigid domains).

/// A partition of 0..n into sets, each named by its smallest member.
#[derive(Clone, Debug)]
pub struct DisjointSets {
    root: Vec<usize>,
}

impl DisjointSets {
    /// n singletons.
    pub fn new(n: usize) -> Self {
        DisjointSets {
            root: (0..n).collect(),
        }
    }

    /// The smallest member of `a`'s set (its name), halving the path on the way.
    pub fn find(&mut self, mut a: usize) -> usize {
        while self.root[a] != a {
            self.root[a] = self.root[self.root[a]];
            a = self.root[a];
        }
        a
    }

    /// Joins the sets of `a` and `b`; the joined set is named by the smaller name.
    pub fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        let (lo, hi) = (a.min(b), a.max(b));
        self.root[hi] = lo;
    }

    /// Whether `a` and `b` are in one set.
    pub fn joined(&mut self, a: usize, b: usize) -> bool {
        self.find(a) == self.find(b)
    }
}

#[cfg(test)]
mod tests {
    use super::DisjointSets;

    /// Against the connected components of a graph found by a search written here: every pair is
    /// joined exactly when a path links them, and each set is named by its smallest member.
    #[test]
    fn the_sets_are_the_components_named_by_their_smallest_member() {
        let n = 12;
        // A fixed pseudo-random edge list (a linear congruence), some repeated, some self-loops.
        let mut state = 7u64;
        let mut edges = Vec::new();
        for _ in 0..9 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let a = (state >> 33) as usize % n;
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let b = (state >> 33) as usize % n;
            edges.push((a, b));
        }
        let mut sets = DisjointSets::new(n);
        for &(a, b) in &edges {
            sets.union(a, b);
        }
        // Components by a depth-first search over the same edges.
        let mut component = vec![usize::MAX; n];
        for start in 0..n {
            if component[start] != usize::MAX {
                continue;
            }
            let mut stack = vec![start];
            component[start] = start;
            while let Some(v) = stack.pop() {
                for &(a, b) in &edges {
                    for (x, y) in [(a, b), (b, a)] {
                        if x == v && component[y] == usize::MAX {
                            component[y] = start;
                            stack.push(y);
                        }
                    }
                }
            }
        }
        for a in 0..n {
            // `start` runs upwards, so each component is labelled by its smallest member.
            assert_eq!(sets.find(a), component[a], "{a}: {edges:?}");
            for b in 0..n {
                assert_eq!(sets.joined(a, b), component[a] == component[b], "{a} {b}");
            }
        }
    }
}
