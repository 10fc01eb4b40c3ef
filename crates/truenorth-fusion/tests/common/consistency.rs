//! Consistency of a reported σ with the error it describes, as estimation people test it
//! (Bar-Shalom, Li & Kirubarajan, *Estimation with Applications to Tracking and
//! Navigation*, 2001, §5.4: the normalised estimation error squared over an ensemble):
//! `z = error/σ` per axis should be standard normal, so a share of about 0.27 % of the
//! samples lies beyond 3σ and none far beyond.
//!
//! Samples of one run are correlated (an error lasts as long as the loop that removes it),
//! so the limits count independent draws, not samples: the integrated autocorrelation
//! time of `z` (Sokal, *Monte Carlo methods in statistical mechanics*, 1997, §3: the sum of
//! the autocorrelation up to its first non-positive value) gives the effective number of
//! draws `N_eff = T / τ_int`. Under the Gaussian, the exceedances beyond 3σ among them are
//! binomial with `p = 0.27 %` (taken as Poisson, `N p` being small), and the largest `|z|`
//! of `N_eff` draws exceeds `Q⁻¹(α / 2N_eff)` with probability `α`.

/// Share of a standard normal beyond ±3.
pub const GAUSS_BEYOND_3: f64 = 0.002_699_796;
/// False-alarm probability of each limit.
pub const ALPHA: f64 = 1e-3;

/// `z` statistics of one axis over an ensemble of runs.
#[derive(Debug, Clone, Default)]
pub struct AxisTally {
    /// Samples.
    pub n: usize,
    /// Samples beyond 3σ.
    pub beyond: usize,
    /// Largest |z|.
    pub max_z: f64,
    /// Sum of z² (mean: the normalised error squared per axis).
    sum_z2: f64,
    /// Sums of the error² and σ², for their RMS.
    sum_e2: f64,
    sum_s2: f64,
    /// `z` once a second per series, for the autocorrelation.
    series: Vec<Vec<f64>>,
    /// Seconds of data.
    duration_s: f64,
}

impl AxisTally {
    /// Starts a new series (a run, or one axis of a run).
    pub fn start_series(&mut self) {
        self.series.push(Vec::new());
    }

    /// One sample `dt_s` after the previous one; `second` says whether it is the first of a
    /// new second (kept for the autocorrelation).
    pub fn add(&mut self, error: f64, sigma: f64, dt_s: f64, second: bool) {
        let z = error / sigma;
        self.n += 1;
        self.beyond += usize::from(z.abs() > 3.0);
        self.max_z = self.max_z.max(z.abs());
        self.sum_z2 += z * z;
        self.sum_e2 += error * error;
        self.sum_s2 += sigma * sigma;
        self.duration_s += dt_s;
        if second {
            if self.series.is_empty() {
                self.start_series();
            }
            self.series.last_mut().unwrap().push(z);
        }
    }

    /// Takes in another tally's samples and series (the two inclination axes as one).
    pub fn merge(&mut self, other: AxisTally) {
        self.n += other.n;
        self.beyond += other.beyond;
        self.max_z = self.max_z.max(other.max_z);
        self.sum_z2 += other.sum_z2;
        self.sum_e2 += other.sum_e2;
        self.sum_s2 += other.sum_s2;
        self.duration_s += other.duration_s;
        self.series.extend(other.series);
    }

    /// Share of samples beyond 3σ.
    pub fn share_beyond(&self) -> f64 {
        self.beyond as f64 / self.n as f64
    }

    /// Mean of z².
    pub fn nees(&self) -> f64 {
        self.sum_z2 / self.n as f64
    }

    /// RMS error and RMS σ, degrees.
    pub fn rms_deg(&self) -> (f64, f64) {
        let n = self.n as f64;
        (
            (self.sum_e2 / n).sqrt().to_degrees(),
            (self.sum_s2 / n).sqrt().to_degrees(),
        )
    }

    /// Integrated autocorrelation time of z, s, from its once-a-second series:
    /// `τ(M) = 1 + 2 Σ_{lag ≤ M} ρ(lag)` with Sokal's window, the smallest `M ≥ 5 τ(M)`
    /// (beyond it the estimate gathers only the noise of the long lags).
    pub fn correlation_time_s(&self) -> f64 {
        let count = self.series.iter().map(Vec::len).sum::<usize>() as f64;
        let variance = self.series.iter().flatten().map(|z| z * z).sum::<f64>() / count;
        let longest = self.series.iter().map(Vec::len).max().unwrap_or(0);
        let mut tau = 1.0;
        for lag in 1..longest {
            if lag as f64 >= 5.0 * tau {
                break;
            }
            let (mut sum, mut pairs) = (0.0, 0usize);
            for s in &self.series {
                for t in lag..s.len() {
                    sum += s[t] * s[t - lag];
                    pairs += 1;
                }
            }
            tau += 2.0 * sum / pairs as f64 / variance;
        }
        tau.max(1.0)
    }

    /// Effective number of independent draws: data time over correlation time, at least 1.
    pub fn effective_draws(&self) -> f64 {
        (self.duration_s / self.correlation_time_s()).max(1.0)
    }

    /// The largest share beyond 3σ a Gaussian error gives with probability 1 − [`ALPHA`].
    pub fn share_limit(&self) -> f64 {
        let n = self.effective_draws();
        poisson_quantile(n * GAUSS_BEYOND_3, ALPHA) as f64 / n
    }

    /// The largest |z| a Gaussian error gives with probability 1 − [`ALPHA`].
    pub fn max_limit(&self) -> f64 {
        normal_upper_quantile(ALPHA / (2.0 * self.effective_draws()))
    }

    /// One line: share beyond 3σ (limit), largest |z| (limit), mean z², RMS error and σ.
    pub fn line(&self, name: &str) -> String {
        let (e, s) = self.rms_deg();
        format!(
            "{name:<11} {:>8} samples, N_eff {:7.0}: beyond 3σ {:5.2} % (limit {:5.2} %), max |err|/σ {:5.2} (limit {:4.2}), mean (err/σ)² {:4.2}, RMS err {:5.2}° σ {:5.2}°",
            self.n,
            self.effective_draws(),
            100.0 * self.share_beyond(),
            100.0 * self.share_limit(),
            self.max_z,
            self.max_limit(),
            self.nees(),
            e,
            s
        )
    }
}

/// The smallest count `c` with `P(Poisson(λ) ≥ c) ≤ alpha`.
pub fn poisson_quantile(lambda: f64, alpha: f64) -> usize {
    let mut term = (-lambda).exp();
    let mut below = 0.0;
    let mut c = 0;
    while 1.0 - below > alpha {
        below += term;
        c += 1;
        term *= lambda / c as f64;
    }
    c
}

/// `P(Z > x)` of a standard normal, by Simpson's rule over [x, x + 12].
pub fn normal_tail(x: f64) -> f64 {
    let n = 4000;
    let h = 12.0 / n as f64;
    let f = |t: f64| (-0.5 * t * t).exp();
    let mut s = f(x) + f(x + 12.0);
    for i in 1..n {
        s += f(x + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0 / (2.0 * core::f64::consts::PI).sqrt()
}

/// The `x` with `P(Z > x) = p`, by bisection.
pub fn normal_upper_quantile(p: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 40.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if normal_tail(mid) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}
