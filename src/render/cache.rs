//! [`Lru`]: a map of bounded size that forgets its least recently used
//! entry, for the process-wide program cache.

use std::collections::HashMap;
use std::hash::Hash;

/// At most `capacity` entries; looking a key up makes it the most recently
/// used, and inserting into a full map first removes the least recently
/// used entry. Eviction scans the entries (`O(capacity)`), which is cheap
/// for the small capacities it is meant for and happens only on a miss.
#[derive(Debug)]
pub(crate) struct Lru<K, V> {
    capacity: usize,
    /// Incremented on every use; an entry's stamp is its last use.
    clock: u64,
    entries: HashMap<K, (u64, V)>,
}

impl<K: Eq + Hash + Clone, V> Lru<K, V> {
    /// An empty map holding at most `capacity` entries (at least 1).
    pub(crate) fn new(capacity: usize) -> Self {
        Lru {
            capacity: capacity.max(1),
            clock: 0,
            entries: HashMap::new(),
        }
    }

    /// The value of `key`, inserting `make()` first if there is none (and
    /// evicting the least recently used entry if the map is full).
    pub(crate) fn get_or_insert_with(&mut self, key: K, make: impl FnOnce() -> V) -> &mut V {
        self.clock += 1;
        let now = self.clock;
        if !self.entries.contains_key(&key) && self.entries.len() >= self.capacity {
            let oldest = self
                .entries
                .iter()
                .min_by_key(|(_, (stamp, _))| *stamp)
                .map(|(k, _)| k.clone());
            if let Some(oldest) = oldest {
                self.entries.remove(&oldest);
            }
        }
        let entry = self.entries.entry(key).or_insert_with(|| (now, make()));
        entry.0 = now;
        &mut entry.1
    }

    /// Whether `key` is held (without making it recently used).
    #[cfg(test)]
    pub(crate) fn contains(&self, key: &K) -> bool {
        self.entries.contains_key(key)
    }

    /// The number of entries.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.entries.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_recently_used_entry_goes_first() {
        let mut lru = Lru::new(3);
        let mut made = 0;
        let mut get = |lru: &mut Lru<&str, u32>, key| {
            *lru.get_or_insert_with(key, || {
                made += 1;
                made
            })
        };
        assert_eq!(get(&mut lru, "a"), 1);
        assert_eq!(get(&mut lru, "b"), 2);
        assert_eq!(get(&mut lru, "c"), 3);
        // A hit makes nothing and refreshes "a".
        assert_eq!(get(&mut lru, "a"), 1);
        // Full: "b" is the least recently used.
        assert_eq!(get(&mut lru, "d"), 4);
        assert_eq!(lru.len(), 3);
        assert!(!lru.contains(&"b"));
        assert!(lru.contains(&"a") && lru.contains(&"c") && lru.contains(&"d"));
        // An evicted key is made again, evicting "c" now.
        assert_eq!(get(&mut lru, "b"), 5);
        assert!(!lru.contains(&"c"));
    }

    #[test]
    fn size_never_exceeds_the_capacity() {
        let mut lru = Lru::new(64);
        for i in 0..400u32 {
            lru.get_or_insert_with(i, || i);
            // A hot key used every turn survives everything.
            lru.get_or_insert_with(1_000_000, || 0);
            assert!(lru.len() <= 64);
        }
        assert_eq!(lru.len(), 64);
        assert!(lru.contains(&1_000_000));
        assert!(lru.contains(&399) && !lru.contains(&300));
        // The last 63 distinct keys stay, with the hot one.
        assert!((337..400).all(|i| lru.contains(&i)));
        assert_eq!(Lru::<u8, u8>::new(0).capacity, 1);
    }
}
