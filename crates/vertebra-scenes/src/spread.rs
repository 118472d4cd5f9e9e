//! How a figure spreads over seeded runs: mean, median, the 10th and 90th
//! percentiles, minimum and maximum.
//!
//! A pile of ragdolls is chaotic: a start moved by a millimetre ends in
//! another pile, so one run of a scene is one sample of its figures. Every
//! figure the project compares is given over `K` seeded starts
//! ([`crate::seed`]) as a [`Spread`].

/// A figure over `count` samples.
///
/// Percentiles interpolate linearly between order statistics (the
/// "type 7" definition of Hyndman and Fan 1996, NumPy's default): the
/// `p`-th percentile of `n` sorted samples `x_0 <= ... <= x_{n-1}` is
/// `x_i + f (x_{i+1} - x_i)` with `i + f = p (n - 1) / 100`. With fewer
/// than [`Spread::PERCENTILE_SAMPLES`] samples the 10th and 90th
/// percentiles are mostly interpolation, so reports give the minimum and
/// maximum instead ([`Spread::range`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Spread {
    /// Samples.
    pub count: usize,
    /// Arithmetic mean.
    pub mean: f64,
    /// 50th percentile.
    pub median: f64,
    /// 10th percentile.
    pub p10: f64,
    /// 90th percentile.
    pub p90: f64,
    /// Smallest sample.
    pub min: f64,
    /// Largest sample.
    pub max: f64,
}

impl Spread {
    /// From this many samples on, reports give the 10th-90th percentile
    /// range; below it, the minimum and maximum.
    pub const PERCENTILE_SAMPLES: usize = 10;

    /// The spread of `samples` (all zero for none). Non-finite samples are
    /// the caller's error: scenes only measure finite worlds.
    pub fn of(samples: impl IntoIterator<Item = f64>) -> Self {
        let mut x: Vec<f64> = samples.into_iter().collect();
        if x.is_empty() {
            return Self::default();
        }
        x.sort_by(f64::total_cmp);
        let n = x.len();
        Self {
            count: n,
            mean: x.iter().sum::<f64>() / n as f64,
            median: percentile(&x, 50.0),
            p10: percentile(&x, 10.0),
            p90: percentile(&x, 90.0),
            min: x[0],
            max: x[n - 1],
        }
    }

    /// The band reports give: the 10th to 90th percentile with at least
    /// [`Self::PERCENTILE_SAMPLES`] samples, else the minimum to maximum.
    pub fn range(&self) -> (f64, f64) {
        if self.count >= Self::PERCENTILE_SAMPLES {
            (self.p10, self.p90)
        } else {
            (self.min, self.max)
        }
    }

    /// What the band is: `"p10-p90"` or `"min-max"`.
    pub fn range_name(&self) -> &'static str {
        Self::band_name(self.count)
    }

    /// What the band of `count` samples is: `"p10-p90"` or `"min-max"`.
    pub fn band_name(count: usize) -> &'static str {
        if count >= Self::PERCENTILE_SAMPLES {
            "p10-p90"
        } else {
            "min-max"
        }
    }

    /// `median [low, high]` with `digits` decimals, for tables.
    pub fn display(&self, digits: usize) -> String {
        let (low, high) = self.range();
        format!(
            "{:.digits$} [{:.digits$}, {:.digits$}]",
            self.median, low, high
        )
    }
}

/// The `p`-th percentile of sorted, non-empty `x`.
fn percentile(x: &[f64], p: f64) -> f64 {
    let rank = p / 100.0 * (x.len() - 1) as f64;
    let i = rank.floor() as usize;
    let f = rank - i as f64;
    match x.get(i + 1) {
        Some(next) => x[i] + f * (next - x[i]),
        None => x[i],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_of_one_to_eleven_are_the_ranks() {
        // 1..=11: rank p (n - 1) / 100 = p / 10 lands on a sample exactly.
        let s = Spread::of((1..=11).map(f64::from));
        assert_eq!(
            (s.count, s.mean, s.median, s.p10, s.p90, s.min, s.max),
            (11, 6.0, 6.0, 2.0, 10.0, 1.0, 11.0)
        );
        assert_eq!(s.range(), (2.0, 10.0));
    }

    #[test]
    fn percentiles_interpolate_between_samples() {
        // Four samples: the 10th percentile sits 0.3 of the way from 10 to
        // 20, the median halfway between 20 and 40, the 90th 0.7 of the way
        // from 40 to 80.
        let s = Spread::of([40.0, 10.0, 80.0, 20.0]);
        assert_eq!((s.p10, s.median, s.p90), (13.0, 30.0, 68.0));
        assert_eq!(s.mean, 37.5);
        // Few samples: the band is the whole range.
        assert_eq!((s.range(), s.range_name()), ((10.0, 80.0), "min-max"));
    }

    #[test]
    fn one_sample_is_every_statistic_and_none_is_zero() {
        let s = Spread::of([2.5]);
        assert_eq!((s.mean, s.median, s.p10, s.p90), (2.5, 2.5, 2.5, 2.5));
        assert_eq!(Spread::of([]), Spread::default());
    }
}
