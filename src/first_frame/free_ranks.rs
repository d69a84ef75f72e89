//! The vertices not numbered yet, counted below an index and found by rank, each in O(log n): a
//! Fenwick tree of ones. Written here because it is twenty lines; the crates that offer one
//! (`fenwick`, `ftree`) are small single-author crates that would add a dependency for it.

/// A set of indices `0..n`, all present at first.
pub(super) struct FreeRanks {
    /// `tree[i]` counts the present indices in `(i - lowbit(i), i]`, shifted by one.
    tree: Vec<u32>,
}

impl FreeRanks {
    /// All of `0..n` present.
    pub(super) fn full(n: usize) -> Self {
        let mut tree = vec![0u32; n + 1];
        for i in 1..=n {
            tree[i] += 1;
            let parent = i + (i & i.wrapping_neg());
            if parent <= n {
                tree[parent] += tree[i];
            }
        }
        Self { tree }
    }

    /// How many present indices lie below `t`.
    pub(super) fn below(&self, t: usize) -> usize {
        let mut i = t.min(self.tree.len() - 1);
        let mut sum = 0;
        while i > 0 {
            sum += self.tree[i] as usize;
            i &= i - 1;
        }
        sum
    }

    /// Removes `t`, which must be present.
    pub(super) fn remove(&mut self, t: usize) {
        let mut i = t + 1;
        while i < self.tree.len() {
            self.tree[i] -= 1;
            i += i & i.wrapping_neg();
        }
    }

    /// The present index with `rank` present indices below it, if there is one.
    pub(super) fn select(&self, rank: usize) -> Option<usize> {
        let n = self.tree.len() - 1;
        let (mut pos, mut left) = (0, rank);
        let mut step = n.checked_next_power_of_two()?;
        while step > 0 {
            if let Some(&count) = self.tree.get(pos + step) {
                if count as usize <= left {
                    pos += step;
                    left -= count as usize;
                }
            }
            step /= 2;
        }
        // `0..pos` is the longest prefix holding at most `rank` present indices: below `n`, the
        // next index is present and the prefix holds exactly `rank`; `n` when there are no more.
        (pos < n).then_some(pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranks_and_selection_agree_with_a_plain_list() {
        let n = 37;
        let mut ranks = FreeRanks::full(n);
        let mut plain: Vec<usize> = (0..n).collect();
        for t in [5, 0, 36, 17, 18, 2, 30] {
            ranks.remove(t);
            plain.retain(|&x| x != t);
            for (rank, &x) in plain.iter().enumerate() {
                assert_eq!(ranks.select(rank), Some(x));
                assert_eq!(ranks.below(x), rank);
            }
            assert_eq!(ranks.select(plain.len()), None);
            assert_eq!(ranks.below(n), plain.len());
        }
    }

    #[test]
    fn an_empty_set_selects_nothing() {
        assert_eq!(FreeRanks::full(0).select(0), None);
        let mut one = FreeRanks::full(1);
        one.remove(0);
        assert_eq!(one.select(0), None);
    }
}
