//! A line over time gathered one point at a time in bounded memory, for a plot of a
//! recording of any length.
//!
//! Up to [`KEPT_WHOLE`] points every point is kept, so the figure of a recording that long
//! is the one drawn from all its points. Past that the points are gathered in buckets of
//! consecutive samples, at most [`BUCKETS`] of them (two buckets merge, and the bucket
//! length doubles, when there would be more): a bucket keeps its first and last finite
//! points and those with the least and the greatest value, in time order, so that the
//! plot's extent (from the first to the last time, from the least to the greatest value)
//! is the whole recording's and a spike shorter than a bucket still shows; a bucket with a
//! non-finite point ends with one, where the pen is lifted. A plot 900 pixels wide shows no
//! more than its columns, a few points each.

/// Points kept one for one before they are gathered in buckets.
pub const KEPT_WHOLE: usize = 1 << 16;

/// Most buckets kept once the points no longer fit whole: about four per pixel column of
/// a plot 900 pixels wide.
pub const BUCKETS: usize = 4096;

/// One point with its place in the line (for the time order of a merged bucket).
#[derive(Debug, Clone, Copy)]
struct Indexed {
    k: u64,
    x: f64,
    y: f64,
}

impl Indexed {
    fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
}

/// Consecutive points: the first and last finite ones, the least and greatest by value,
/// and whether a non-finite one was among them (`gap`, its place).
#[derive(Debug, Clone, Copy)]
struct Bucket {
    first: Option<Indexed>,
    last: Option<Indexed>,
    lo: Option<Indexed>,
    hi: Option<Indexed>,
    gap: Option<Indexed>,
}

impl Bucket {
    fn of(p: Indexed) -> Self {
        if p.is_finite() {
            Self {
                first: Some(p),
                last: Some(p),
                lo: Some(p),
                hi: Some(p),
                gap: None,
            }
        } else {
            Self {
                first: None,
                last: None,
                lo: None,
                hi: None,
                gap: Some(p),
            }
        }
    }

    /// This bucket followed by `b`.
    fn then(self, b: Self) -> Self {
        let pick = |a: Option<Indexed>,
                    c: Option<Indexed>,
                    take_c: fn(&Indexed, &Indexed) -> bool| {
            match (a, c) {
                (Some(a), Some(c)) => Some(if take_c(&a, &c) { c } else { a }),
                (a, c) => a.or(c),
            }
        };
        Self {
            first: self.first.or(b.first),
            last: b.last.or(self.last),
            lo: pick(self.lo, b.lo, |a, c| c.y < a.y),
            hi: pick(self.hi, b.hi, |a, c| c.y > a.y),
            gap: b.gap.or(self.gap),
        }
    }

    /// The points kept, in time order, each once.
    fn points(&self, out: &mut Vec<(f64, f64)>) {
        let mut kept: Vec<Indexed> = [self.first, self.lo, self.hi, self.last, self.gap]
            .into_iter()
            .flatten()
            .collect();
        kept.sort_by_key(|p| p.k);
        kept.dedup_by_key(|p| p.k);
        out.extend(kept.iter().map(|p| (p.x, p.y)));
    }
}

/// A line gathered one point at a time (see the module documentation).
#[derive(Debug, Clone, Default)]
pub struct Envelope {
    whole: Vec<(f64, f64)>,
    buckets: Vec<Bucket>,
    /// Points per bucket once gathered.
    stride: u64,
    count: u64,
}

impl Envelope {
    /// An empty line.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends the point `(x, y)`.
    pub fn push(&mut self, x: f64, y: f64) {
        let p = Indexed {
            k: self.count,
            x,
            y,
        };
        self.count += 1;
        if self.buckets.is_empty() && self.whole.len() < KEPT_WHOLE {
            self.whole.push((x, y));
            return;
        }
        if self.buckets.is_empty() {
            // The first point that does not fit whole: gather the others in buckets.
            self.stride = (KEPT_WHOLE / BUCKETS) as u64;
            let whole = std::mem::take(&mut self.whole);
            self.buckets.reserve(BUCKETS);
            for (j, chunk) in whole.chunks(self.stride as usize).enumerate() {
                let start = j as u64 * self.stride;
                let b = chunk
                    .iter()
                    .zip(start..)
                    .map(|(&(x, y), k)| Bucket::of(Indexed { k, x, y }));
                let merged = b.reduce(Bucket::then);
                self.buckets.extend(merged);
            }
        }
        if p.k.is_multiple_of(self.stride) {
            if self.buckets.len() == BUCKETS {
                // Halve: merge neighbours, and buckets twice as long from now on.
                let merged: Vec<Bucket> = self
                    .buckets
                    .chunks(2)
                    .map(|c| c.iter().copied().reduce(Bucket::then).unwrap_or(c[0]))
                    .collect();
                self.buckets.clear();
                self.buckets.extend(merged);
                self.stride *= 2;
            }
            if p.k.is_multiple_of(self.stride) {
                self.buckets.push(Bucket::of(p));
                return;
            }
        }
        if let Some(last) = self.buckets.last_mut() {
            *last = last.then(Bucket::of(p));
        }
    }

    /// The points to draw, in time order.
    pub fn points(&self) -> Vec<(f64, f64)> {
        if self.buckets.is_empty() {
            return self.whole.clone();
        }
        let mut out = Vec::with_capacity(4 * self.buckets.len());
        for b in &self.buckets {
            b.points(&mut out);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_lines_are_kept_whole() {
        let mut e = Envelope::new();
        let pts: Vec<(f64, f64)> = (0..1000).map(|k| (k as f64, (k as f64).sin())).collect();
        for &(x, y) in &pts {
            e.push(x, y);
        }
        assert_eq!(e.points(), pts);
    }

    #[test]
    fn long_lines_keep_their_extent_and_spikes_in_bounded_memory() {
        let n = 40 * KEPT_WHOLE + 123;
        let spike = 3 * KEPT_WHOLE + 17;
        let mut e = Envelope::new();
        for k in 0..n {
            let y = if k == spike {
                50.0
            } else if k == n / 2 {
                f64::NAN
            } else {
                (k as f64 * 1e-4).sin()
            };
            e.push(k as f64 * 0.01, y);
        }
        let p = e.points();
        assert!(p.len() <= 5 * BUCKETS, "{}", p.len());
        assert!(e.buckets.len() <= BUCKETS);
        assert_eq!(p[0], (0.0, 0.0));
        assert_eq!(p.last().unwrap().0, (n - 1) as f64 * 0.01);
        assert!(p.contains(&(spike as f64 * 0.01, 50.0)));
        assert!(p.iter().any(|q| q.1.is_nan()));
        assert!(p.windows(2).all(|w| w[1].0 > w[0].0));
        let least = p
            .iter()
            .map(|q| q.1)
            .filter(|y| y.is_finite())
            .fold(f64::MAX, f64::min);
        assert!((least + 1.0).abs() < 1e-6, "{least}");
    }
}
