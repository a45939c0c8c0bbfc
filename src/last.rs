//! A value kept with the key it was computed for and recomputed only when the key changes:
//! what consecutive rows of a table share (ξ along a series) is computed once per run of equal
//! keys. The caches of the streaming commands are all of this kind: the text of repeated
//! numbers (`io::cells::Repeat`), the named laws' K of each `k` row (`pipeline::k`) and the
//! slope limits of the plausibility checks (`io::measurements`). A leaf module.

/// A value and the key it was last computed for (none at first).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Last<K, V> {
    key: Option<K>,
    value: V,
}

impl<K: PartialEq + Copy, V> Last<K, V> {
    /// The value for `key`: when `key` is not the last key, `update` first rewrites the value
    /// in place (so that a buffer keeps its allocation).
    #[inline]
    pub fn get(&mut self, key: K, update: impl FnOnce(&mut V)) -> &mut V {
        if self.key != Some(key) {
            update(&mut self.value);
            self.key = Some(key);
        }
        &mut self.value
    }
}

#[cfg(test)]
mod tests {
    use super::Last;

    #[test]
    fn the_value_is_recomputed_only_when_the_key_changes() {
        let mut calls = 0;
        let mut last: Last<u64, u64> = Last::default();
        for (key, want) in [(1, 10), (1, 10), (2, 20), (2, 20), (1, 10)] {
            let v = *last.get(key, |v| {
                calls += 1;
                *v = 10 * key;
            });
            assert_eq!(v, want);
        }
        assert_eq!(calls, 3);
    }
}
