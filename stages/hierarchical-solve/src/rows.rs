//! Compressed rows: many short lists of `(index, value)` pairs (a link's
//! sender parts, a leaf's couplings through mirrors) in three flat
//! vectors, so a Jacobi sweep reads them without a pointer per list.

/// Row `r` holds the pairs `(index[k], value[k])` for `k` in
/// `start[r]..start[r + 1]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rows<T> {
    start: Vec<usize>,
    index: Vec<usize>,
    value: Vec<T>,
}

impl<T> Rows<T> {
    /// The rows of `lists`, in order.
    pub fn from_lists(lists: impl IntoIterator<Item = Vec<(usize, T)>>) -> Self {
        let mut rows = Rows { start: vec![0], index: Vec::new(), value: Vec::new() };
        for list in lists {
            for (index, value) in list {
                rows.index.push(index);
                rows.value.push(value);
            }
            rows.start.push(rows.index.len());
        }
        rows
    }

    /// Row `r`'s pairs; none for a row past the last.
    pub fn row(&self, r: usize) -> impl Iterator<Item = (usize, &T)> {
        let range = self.start.get(r..=r + 1).map_or(0..0, |s| s[0]..s[1]);
        self.index[range.clone()].iter().copied().zip(&self.value[range])
    }

    /// Number of pairs in all rows.
    pub fn len(&self) -> usize {
        self.index.len()
    }

    /// Whether no row holds a pair.
    pub fn is_empty(&self) -> bool {
        self.index.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_keep_their_pairs_in_order_and_rows_past_the_end_are_empty() {
        let rows = Rows::from_lists([vec![(3, 'a'), (1, 'b')], vec![], vec![(0, 'c')]]);
        assert_eq!(rows.row(0).collect::<Vec<_>>(), [(3, &'a'), (1, &'b')]);
        assert_eq!(rows.row(1).count(), 0);
        assert_eq!(rows.row(2).collect::<Vec<_>>(), [(0, &'c')]);
        assert_eq!(rows.row(3).count(), 0);
        assert_eq!((rows.len(), Rows::<char>::default().row(0).count()), (3, 0));
    }
}
