//! [`Loops`]: index loops in one buffer, owned, borrowed ([`LoopsRef`]) and walked in
//! order ([`LoopsIter`]).

/// Index loops (a panel's facets, a flat panel's cut loops) in one buffer. A panel has
/// a handful of short loops and a big job has millions of panels: one allocation per
/// loop would cost more memory than the indices themselves.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Loops {
    /// Every loop's indices, one loop after the other.
    indices: Vec<u32>,
    /// Where each loop ends in `indices`.
    ends: Vec<u32>,
}

impl Loops {
    /// No loops.
    pub fn new() -> Self {
        Self::default()
    }

    /// No loops, with room for `loops` loops of `indices` indices in all.
    pub fn with_capacity(loops: usize, indices: usize) -> Self {
        Loops {
            indices: Vec::with_capacity(indices),
            ends: Vec::with_capacity(loops),
        }
    }

    /// Appends a loop.
    pub fn push(&mut self, lp: impl IntoIterator<Item = u32>) {
        self.indices.extend(lp);
        self.ends.push(self.indices.len() as u32);
    }

    /// The same loops, borrowed.
    pub fn view(&self) -> LoopsRef<'_> {
        LoopsRef {
            indices: &self.indices,
            ends: &self.ends,
        }
    }

    /// Number of loops.
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// No loops at all.
    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// Loop `k`, if there is one.
    pub fn get(&self, k: usize) -> Option<&[u32]> {
        self.view().get(k)
    }

    /// The first loop.
    pub fn first(&self) -> Option<&[u32]> {
        self.get(0)
    }

    /// The loops in order.
    pub fn iter(&self) -> LoopsIter<'_> {
        self.view().iter()
    }

    /// Indices in all loops together.
    pub fn index_count(&self) -> usize {
        self.indices.len()
    }
}

impl std::ops::Index<usize> for Loops {
    type Output = [u32];
    fn index(&self, k: usize) -> &[u32] {
        self.view().loop_at(k)
    }
}

/// Loops kept in buffers owned elsewhere: a [`Loops`] borrowed, or one panel's loops
/// in a [`FlatPanels`](super::FlatPanels) arena. `ends` count from the start of `indices`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoopsRef<'a> {
    pub(super) indices: &'a [u32],
    pub(super) ends: &'a [u32],
}

impl<'a> LoopsRef<'a> {
    /// Number of loops.
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// No loops at all.
    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// Loop `k`, if there is one.
    pub fn get(&self, k: usize) -> Option<&'a [u32]> {
        let end = *self.ends.get(k)? as usize;
        let start = if k == 0 { 0 } else { self.ends[k - 1] as usize };
        Some(&self.indices[start..end])
    }

    /// The first loop.
    pub fn first(&self) -> Option<&'a [u32]> {
        self.get(0)
    }

    /// The loops in order.
    pub fn iter(&self) -> LoopsIter<'a> {
        LoopsIter {
            loops: *self,
            range: 0..self.len(),
        }
    }

    /// Indices in all loops together.
    pub fn index_count(&self) -> usize {
        self.indices.len()
    }

    /// Loop `k`; panics when there is none, as indexing does.
    fn loop_at(&self, k: usize) -> &'a [u32] {
        self.get(k)
            .unwrap_or_else(|| panic!("loop {k} of {}", self.len()))
    }
}

impl std::ops::Index<usize> for LoopsRef<'_> {
    type Output = [u32];
    fn index(&self, k: usize) -> &[u32] {
        self.loop_at(k)
    }
}

impl<'a> IntoIterator for &LoopsRef<'a> {
    type Item = &'a [u32];
    type IntoIter = LoopsIter<'a>;
    fn into_iter(self) -> LoopsIter<'a> {
        self.iter()
    }
}

impl<'a> IntoIterator for LoopsRef<'a> {
    type Item = &'a [u32];
    type IntoIter = LoopsIter<'a>;
    fn into_iter(self) -> LoopsIter<'a> {
        self.iter()
    }
}

/// The loops of a [`Loops`] or [`LoopsRef`], in order.
#[derive(Clone, Debug)]
pub struct LoopsIter<'a> {
    loops: LoopsRef<'a>,
    range: std::ops::Range<usize>,
}

impl<'a> Iterator for LoopsIter<'a> {
    type Item = &'a [u32];
    fn next(&mut self) -> Option<&'a [u32]> {
        self.range.next().map(|k| self.loops.loop_at(k))
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        self.range.size_hint()
    }
}

impl DoubleEndedIterator for LoopsIter<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        self.range.next_back().map(|k| self.loops.loop_at(k))
    }
}

impl ExactSizeIterator for LoopsIter<'_> {}

impl<'a> IntoIterator for &'a Loops {
    type Item = &'a [u32];
    type IntoIter = LoopsIter<'a>;
    fn into_iter(self) -> LoopsIter<'a> {
        self.iter()
    }
}

impl<L: IntoIterator<Item = u32>> FromIterator<L> for Loops {
    fn from_iter<I: IntoIterator<Item = L>>(loops: I) -> Self {
        let mut all = Loops::new();
        for lp in loops {
            all.push(lp);
        }
        all
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loops_keep_each_loop_apart_and_in_order() {
        let mut loops = Loops::new();
        assert!(loops.is_empty() && loops.first().is_none());
        loops.push([0, 1, 2]);
        loops.push(Vec::new());
        loops.push([3, 4, 5, 6]);
        assert_eq!(loops.len(), 3);
        assert_eq!(loops.index_count(), 7);
        assert_eq!(&loops[0], &[0, 1, 2]);
        assert_eq!(&loops[1], &[] as &[u32]);
        assert_eq!(loops.get(2), Some(&[3, 4, 5, 6][..]));
        assert_eq!(loops.get(3), None);
        let collected: Vec<Vec<u32>> = loops.iter().map(<[u32]>::to_vec).collect();
        assert_eq!(collected, [vec![0, 1, 2], vec![], vec![3, 4, 5, 6]]);
        assert_eq!(loops.iter().next_back(), Some(&[3, 4, 5, 6][..]));
        let rebuilt: Loops = collected.into_iter().collect();
        assert_eq!(rebuilt, loops);
        assert_eq!((&loops).into_iter().count(), 3);
    }
}
