//! Disjoint sets of the numbers `0..n` (union-find), the one used wherever things are
//! joined into classes: corners into vertices, points into welds, faces into islands.

/// Disjoint sets of `0..n`. [`UnionFind::union`] keeps the smaller root, so a set's
/// root is its smallest member and does not depend on the order of the unions (nor on
/// path compression): the same classes give the same roots on any run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` sets of one member each.
    pub fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    /// The root of `x`'s set, halving the path walked.
    pub fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grand = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grand;
            x = grand;
        }
        x
    }

    /// The root of `x`'s set, for a shared borrow (no path is shortened).
    pub fn root(&self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            x = self.parent[x as usize];
        }
        x
    }

    /// Joins the sets of `a` and `b` under the smaller root; true when they were two.
    pub fn union(&mut self, a: u32, b: u32) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        self.parent[hi as usize] = lo;
        // Keep the paths from the two members short too.
        self.parent[a as usize] = lo;
        self.parent[b as usize] = lo;
        true
    }

    /// Joins the set of `a` onto the set of `onto`, whose root stays the root (for a
    /// caller that decides which member survives); true when they were two.
    pub fn join_onto(&mut self, a: u32, onto: u32) -> bool {
        let (ra, ro) = (self.root(a), self.root(onto));
        if ra == ro {
            return false;
        }
        self.parent[ra as usize] = ro;
        true
    }

    /// Every member's root, in member order.
    pub fn roots(&mut self) -> Vec<u32> {
        (0..self.parent.len() as u32)
            .map(|x| self.find(x))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sets_root_is_its_smallest_member_whatever_the_order() {
        let pairs = [(5, 3), (3, 7), (1, 7), (9, 8)];
        let mut forward = UnionFind::new(10);
        for &(a, b) in &pairs {
            forward.union(a, b);
        }
        let mut backward = UnionFind::new(10);
        for &(a, b) in pairs.iter().rev() {
            backward.union(b, a);
        }
        let roots = forward.roots();
        assert_eq!(roots, backward.roots());
        assert_eq!(roots, [0, 1, 2, 1, 4, 1, 6, 1, 8, 8]);
        assert_eq!(forward.root(7), 1);
        assert!(!forward.union(3, 5), "already one set");
    }

    #[test]
    fn join_onto_keeps_the_chosen_root() {
        let mut sets = UnionFind::new(4);
        assert!(sets.join_onto(0, 3));
        assert!(sets.join_onto(3, 2));
        assert_eq!(sets.root(0), 2);
        assert!(!sets.join_onto(2, 0));
        assert_eq!(sets.roots(), [2, 1, 2, 2]);
    }
}
