//! The rows of a long history kept for drawing: the figures are [`super::SIZE`] pixels wide, so
//! a history of a million rows is cut into [`BUCKETS`] equal spans of time and each span keeps
//! its first and last rows and the rows where any plotted series reaches its least or greatest
//! value within the span. Every series' envelope over each span (what a line drawn at that width
//! shows) is then exactly that of the full history, and the memory is bounded by the number of
//! spans, not by the duration.

use std::rc::Rc;

/// Rows kept whole: a history of at most this many rows is drawn from every row.
pub const ROWS_KEPT_WHOLE: usize = 20_000;

/// Spans of time a longer history is cut into (4 per pixel of the figures' width).
pub const BUCKETS: usize = 4 * super::SIZE.0 as usize;

/// A row offered, with its index in the history.
type Row = Rc<(usize, Vec<f64>)>;

/// Keeps the rows of one span at a time (rows come in time order).
pub struct Decimator {
    start: f64,
    width: f64,
    bucket: Option<usize>,
    /// The current span's first and last rows, and each series' least and greatest.
    first: Option<Row>,
    last: Option<Row>,
    least: Vec<Row>,
    greatest: Vec<Row>,
    kept: Vec<Vec<f64>>,
}

impl Decimator {
    /// For rows whose times run from `first` to `last` (s).
    pub fn new(first: f64, last: f64) -> Self {
        Decimator {
            start: first,
            width: ((last - first) / BUCKETS as f64).max(f64::MIN_POSITIVE),
            bucket: None,
            first: None,
            last: None,
            least: Vec::new(),
            greatest: Vec::new(),
            kept: Vec::new(),
        }
    }

    /// Offers row `index` (its first value the time).
    pub fn push(&mut self, index: usize, row: Vec<f64>) {
        let bucket = (((row[0] - self.start) / self.width) as usize).min(BUCKETS - 1);
        if self.bucket != Some(bucket) {
            self.flush();
            self.bucket = Some(bucket);
        }
        let row = Rc::new((index, row));
        if self.first.is_none() {
            self.least = vec![row.clone(); row.1.len()];
            self.greatest = vec![row.clone(); row.1.len()];
            self.first = Some(row);
            return;
        }
        for (s, &v) in row.1.iter().enumerate() {
            if v < self.least[s].1[s] {
                self.least[s] = row.clone();
            }
            if v > self.greatest[s].1[s] {
                self.greatest[s] = row.clone();
            }
        }
        self.last = Some(row);
    }

    /// Ends the current span: its distinct kept rows, in time order.
    fn flush(&mut self) {
        let mut rows: Vec<Row> = self
            .first
            .take()
            .into_iter()
            .chain(self.last.take())
            .chain(self.least.drain(..))
            .chain(self.greatest.drain(..))
            .collect();
        rows.sort_by_key(|r| r.0);
        rows.dedup_by_key(|r| r.0);
        self.kept.extend(
            rows.into_iter()
                .map(|r| Rc::try_unwrap(r).map_or_else(|r| r.1.clone(), |r| r.1)),
        );
    }

    /// The rows kept, in time order.
    pub fn finish(mut self) -> Vec<Vec<f64>> {
        self.flush();
        self.kept
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Least and greatest value of series `s` over the rows whose time lies in span `b` of
    /// [0, 10] s cut into `BUCKETS` equal spans (the last one closed), from a list of rows.
    fn envelope(rows: &[Vec<f64>], b: usize, s: usize) -> (f64, f64) {
        let (lo_t, hi_t) = (
            10.0 * b as f64 / BUCKETS as f64,
            10.0 * (b + 1) as f64 / BUCKETS as f64,
        );
        rows.iter()
            .filter(|r| r[0] >= lo_t && (r[0] < hi_t || (b == BUCKETS - 1 && r[0] <= hi_t)))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
                (lo.min(r[s]), hi.max(r[s]))
            })
    }

    #[test]
    fn every_span_keeps_its_ends_and_the_envelope_of_every_series() {
        // A million rows of a fast oscillation, a slow ramp and a cosine, on times k/99 999.9 s
        // (away from the spans' bounds), and an impact: two rows at one time, the second with the
        // oscillation's value jumped by 1 (rates before and after).
        let n = 1_000_000;
        let mut rows: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                let t = (i as f64 + 0.5) / 100_000.0;
                vec![t, (997.0 * t).sin(), t * t, (31.0 * t).cos()]
            })
            .collect();
        let at = 500_000;
        let mut after = rows[at].clone();
        after[1] += 1.0;
        rows.insert(at + 1, after);
        let mut d = Decimator::new(0.0, 10.0);
        for (i, r) in rows.iter().enumerate() {
            d.push(i, r.clone());
        }
        let kept = d.finish();
        assert!(kept.len() < 10 * BUCKETS, "{} rows kept", kept.len());
        assert!(kept.windows(2).all(|w| w[0][0] <= w[1][0]), "in time order");
        assert_eq!(kept.first(), rows.first());
        assert_eq!(kept.last(), rows.last());
        // Both rows of the impact are kept here, so the jump is drawn.
        assert!(kept.contains(&rows[at]) && kept.contains(&rows[at + 1]));
        let impact_span = (rows[at][0] * BUCKETS as f64 / 10.0) as usize;
        for b in (0..BUCKETS).step_by(37).chain([impact_span]) {
            for s in 1..4 {
                assert_eq!(
                    envelope(&kept, b, s),
                    envelope(&rows, b, s),
                    "span {b}, series {s}"
                );
            }
        }
    }
}
