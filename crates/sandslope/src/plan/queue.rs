//! The open list of the route search: unordered buckets of equal width over the A* key.
//!
//! The search ([`super::search`]) is label-correcting: it drains the lowest non-empty bucket in
//! any order, re-expands a cell whenever its distance improves, and stops once the lowest
//! bucket's floor reaches the goal's distance. No order inside a bucket is needed, so an entry
//! is 8 bytes (cell and its distance at push time, to recognise stale entries) appended to a
//! `Vec`, and popping is `Vec::pop`.
//!
//! It replaced a bucket queue whose current bucket was a binary heap (exact order): on the
//! 4096 x 4096 benchmark the heap's `pop` took 23 % of a profile (a few thousand entries per
//! bucket, one mispredicted branch per level).

/// Buckets kept at once; keys beyond them wait in an unsorted overflow list.
const BUCKETS: usize = 1 << 16;

/// An entry: the cell and its distance (`g`) when pushed, as `f32`.
pub(crate) type Entry = (u32, f32);

/// Unordered min-bucket queue of cells keyed by non-negative `f64` keys.
#[derive(Debug)]
pub(crate) struct BucketQueue {
    /// Bucket width; only ever grows (see [`BucketQueue::advance`]).
    width: f64,
    /// `1 / width`: a push multiplies (a division on every push was 4 % of the time search).
    inv_width: f64,
    origin: f64,
    current: usize,
    buckets: Vec<Vec<Entry>>,
    far: Vec<(f64, Entry)>,
    /// Times the buckets were restarted from the overflow list.
    #[cfg(test)]
    restarts: usize,
}

impl BucketQueue {
    /// An empty queue whose keys start at `origin`, with buckets `width` wide (positive).
    pub(crate) fn new(origin: f64, width: f64) -> BucketQueue {
        BucketQueue {
            width,
            inv_width: 1.0 / width,
            origin,
            current: 0,
            buckets: vec![Vec::new()],
            far: Vec::new(),
            #[cfg(test)]
            restarts: 0,
        }
    }

    /// A lower bound on the key of every entry not yet popped from the current bucket and of
    /// every entry in later buckets (entries pushed below it join the current bucket).
    #[inline(always)]
    pub(crate) fn floor(&self) -> f64 {
        self.origin + self.current as f64 * self.width
    }

    /// Adds `entry` with `key`; a key below [`BucketQueue::floor`] joins the current bucket.
    #[inline(always)]
    pub(crate) fn push(&mut self, key: f64, entry: Entry) {
        // Saturating cast: keys below `origin` give 0, then the current bucket.
        let b = (((key - self.origin) * self.inv_width) as usize).max(self.current);
        if b < BUCKETS {
            if b >= self.buckets.len() {
                self.buckets.resize_with(b + 1, Vec::new);
            }
            self.buckets[b].push(entry);
        } else {
            self.far.push((key, entry));
        }
    }

    /// The entry [`BucketQueue::pop`] would return next if nothing were pushed before it.
    #[inline(always)]
    pub(crate) fn peek(&self) -> Option<Entry> {
        self.buckets[self.current].last().copied()
    }

    /// Removes an entry of the current bucket, moving on to the next non-empty bucket when it
    /// is empty; `None` when the queue is empty.
    #[inline(always)]
    pub(crate) fn pop(&mut self) -> Option<Entry> {
        loop {
            if let Some(e) = self.buckets[self.current].pop() {
                return Some(e);
            }
            self.advance()?;
        }
    }

    /// Moves to the next non-empty bucket; `None` when the queue is empty.
    #[cold]
    fn advance(&mut self) -> Option<()> {
        // The drained bucket's allocation is freed: buckets are visited once.
        self.buckets[self.current] = Vec::new();
        while self.current + 1 < self.buckets.len() {
            self.current += 1;
            if !self.buckets[self.current].is_empty() {
                return Some(());
            }
        }
        if self.far.is_empty() {
            return None;
        }
        // Restart the buckets at the smallest far key. If the buckets are too narrow for the
        // keys (a heuristic near zero gives a width far below the edge costs, and then nearly
        // every push would land here), widen them so that the lower half of the far keys
        // spans about 1024 buckets: at least half of the list then moves into buckets, so an
        // entry passes through here O(log n) times at most.
        self.origin = self.far.iter().map(|e| e.0).fold(f64::INFINITY, f64::min);
        let mid = self.far.len() / 2;
        let (_, median, _) = self.far.select_nth_unstable_by(mid, |a, b| a.0.total_cmp(&b.0));
        self.width = self.width.max((median.0 - self.origin) / 1024.0);
        self.inv_width = 1.0 / self.width;
        #[cfg(test)]
        {
            self.restarts += 1;
        }
        self.current = 0;
        self.buckets.clear();
        self.buckets.push(Vec::new());
        for (k, e) in std::mem::take(&mut self.far) {
            self.push(k, e);
        }
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_comes_out_once_and_never_below_the_floor_it_was_pushed_above() {
        // A deterministic pseudo-random workload with keys mostly near the floor, some far
        // beyond the bucket range and some below the floor (they join the current bucket).
        let mut q = BucketQueue::new(0.0, 0.5);
        let mut state = 12345u64;
        let mut rand = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pushed = Vec::new();
        let mut popped = Vec::new();
        let mut keys = std::collections::HashMap::new();
        let mut last_floor = 0.0;
        for i in 0..20_000u32 {
            let f = q.floor();
            let key = match i % 97 {
                0 => f + 1e6 * rand(),
                1 => (f - 3.0 * rand()).max(0.0),
                _ => f + 10.0 * rand(),
            };
            q.push(key, (i, key as f32));
            keys.insert(i, key);
            pushed.push(i);
            if i % 3 == 0 {
                let (c, _) = q.pop().unwrap();
                popped.push(c);
            }
            // The floor never decreases, and no popped key is more than one bucket above it.
            assert!(q.floor() >= last_floor);
            last_floor = q.floor();
        }
        while let Some((c, _)) = q.pop() {
            assert!(keys[&c] < q.floor() + q.width, "{} vs floor {}", keys[&c], q.floor());
            popped.push(c);
        }
        popped.sort_unstable();
        assert_eq!(popped, pushed);
    }

    #[test]
    fn buckets_far_too_narrow_for_the_keys_widen_after_the_first_restart() {
        // A Dijkstra-like workload (keys grow by about 1 per step) in buckets 1e-300 wide:
        // every push lands in the overflow list until the first restart widens the buckets
        // to the keys' scale; then the overflow list is rarely used again.
        let mut q = BucketQueue::new(0.0, 1e-300);
        let mut state = 99u64;
        let mut rand = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut n, mut last) = (0u32, 0.0);
        q.push(0.0, (0, 0.0));
        while let Some((c, g)) = q.pop() {
            // Keys come out in bucket order: never below the previous bucket's floor.
            assert!(f64::from(g) >= last - q.width - 1e-3, "{g} after {last}");
            last = f64::from(g);
            if n < 100_000 {
                for _ in 0..2 {
                    n += 1;
                    let key = f64::from(g) + 0.5 + rand();
                    q.push(key, (n, key as f32));
                }
            }
            let _ = c;
        }
        assert!(q.width > 1e-4 && q.width < 1.0, "{}", q.width);
        assert!(q.restarts < 20, "{} restarts", q.restarts);
    }
}
