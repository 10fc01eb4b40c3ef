//! The seed's ellipse parameters of a binned-ellipse full set (EP 0634001 claims 7–9): the
//! search for Ω_e minimising `S(θ)`, then the weighted sums that give the ratio and `|E_L|`,
//! one evaluation of `S(θ)` at a time so that a refresh can run it in bounded slices.

use core::f64::consts::{PI, TAU};

use nalgebra::Vector2;
use truenorth_compass::EllipsePhasors;
use truenorth_core::{Error, Result, check_finite2};

use crate::seed::binned::bins::MAX_BINS;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Number of `S(θ)` evaluations of the parameter search: a 1° scan of [0, π), the two
/// starting points and 60 steps of the golden section, and the two weighted sums.
pub(crate) const EVALUATIONS: usize = 180 + 2 + 60 + 2;

/// Steps of the golden-section search.
const GOLDEN_STEPS: usize = 60;

/// `∫₀ˣ |cos t| dt = 2k + (−1)ᵏ sin x` with `k = round(x/π)`: continuous and exact. The
/// caller gives `sin x` (computed by the angle-difference formula from values it keeps).
#[inline]
fn int_abs_cos(x: f64, sin_x: f64) -> f64 {
    let k = (x / PI).round();
    let sign = if (k as i64) % 2 == 0 { 1.0 } else { -1.0 };
    2.0 * k + sign * sin_x
}

/// Where the search for the ellipse parameters stands.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Search {
    /// The 1° scan of [0, π): next step and the best so far.
    Scan { k: usize, best: f64, best_s: f64 },
    /// The golden section on the bracket around the best scan point (before its two
    /// starting evaluations when `sc`/`sd` are `None`).
    Golden {
        step: usize,
        a: f64,
        b: f64,
        c: f64,
        d: f64,
        sc: Option<f64>,
        sd: Option<f64>,
    },
    /// The two weighted sums about Ω.
    Sums { omega: f64, sx: Option<f64> },
}

/// The seed's ellipse parameters of a full set (claims 7–9), one `S(θ)` evaluation at a time
/// (see [`ellipse_parameters`] for the method).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ParamSearch {
    origin: Vector2<f64>,
    n: usize,
    /// `R_i²` and `R_i³` of the full set about the origin.
    r2: [f64; MAX_BINS],
    r3: [f64; MAX_BINS],
    /// The bin boundaries `β_j = j·Δ` (`Δ = 2π/N`, `j = 0..=N`) with their sines and
    /// cosines, so that each evaluation of `S(θ)` needs one `sin_cos` instead of two sines
    /// per bin.
    edge: [f64; MAX_BINS + 1],
    edge_sin: [f64; MAX_BINS + 1],
    edge_cos: [f64; MAX_BINS + 1],
    sum_w: f64,
    search: Search,
}

impl ParamSearch {
    /// Checks the full set and prepares the search.
    pub(crate) fn new(full: &[Vector2<f64>], origin: &Vector2<f64>) -> Result<Self> {
        let n = full.len();
        let mut sum_w = 0.0;
        let (mut r2, mut r3) = ([0.0; MAX_BINS], [0.0; MAX_BINS]);
        for (i, p) in full.iter().enumerate() {
            check_finite2("binned-ellipse full set", p)?;
            sum_w += (p - origin).norm_squared();
            let r = (p - origin).norm();
            r2[i] = r.powi(2);
            r3[i] = r.powi(3);
        }
        if !(sum_w > 0.0 && sum_w.is_finite()) || n < 4 {
            return Err(Error::Degenerate {
                reason: "all binned readings coincide with the origin; the compass did not turn",
            });
        }
        let half = PI / n as f64;
        let mut edge = [0.0; MAX_BINS + 1];
        let (mut edge_sin, mut edge_cos) = ([0.0; MAX_BINS + 1], [0.0; MAX_BINS + 1]);
        for j in 0..=n {
            edge[j] = j as f64 * 2.0 * half;
            (edge_sin[j], edge_cos[j]) = edge[j].sin_cos();
        }
        Ok(Self {
            origin: *origin,
            n,
            r2,
            r3,
            edge,
            edge_sin,
            edge_cos,
            sum_w,
            search: Search::Scan {
                k: 0,
                best: 0.0,
                best_s: f64::INFINITY,
            },
        })
    }

    /// `Σ R_i^power · mean_bin |cos(φ − θ)|` (`power` 2 or 3), the mean over bin `i`
    /// being `(G(β_{i+1} − θ) − G(β_i − θ))/Δ` with `G(x) = ∫₀ˣ |cos t| dt`; neighbouring
    /// bins share a boundary, so `G` is evaluated once per boundary, and
    /// `sin(β − θ) = sin β cos θ − cos β sin θ`.
    fn weighted(&self, theta: f64, cubed: bool) -> f64 {
        let width = TAU / self.n as f64;
        let r = if cubed { &self.r3 } else { &self.r2 };
        let (st, ct) = theta.sin_cos();
        let g = |j: usize| {
            int_abs_cos(
                self.edge[j] - theta,
                self.edge_sin[j] * ct - self.edge_cos[j] * st,
            )
        };
        let mut sum = 0.0;
        let mut lower = g(0);
        for (i, ri) in r[..self.n].iter().enumerate() {
            let upper = g(i + 1);
            sum += ri * (upper - lower);
            lower = upper;
        }
        sum / width
    }

    /// One evaluation's worth of the search; `Some` with the parameters (or the refusal)
    /// when it is over.
    pub(crate) fn step(&mut self) -> Option<Result<EllipsePhasors>> {
        self.search = match self.search {
            Search::Scan { k, best, best_s } => self.scan_step(k, best, best_s),
            golden @ Search::Golden { .. } => self.golden_step(golden),
            Search::Sums { omega, sx } => {
                let sx = sx.unwrap_or_else(|| self.weighted(omega, true));
                // Σ R²|Y'| = Σ R³|sin(φ − Ω)| = Σ R³|cos(φ − Ω − π/2)|.
                let sy = self.weighted(omega + 0.5 * PI, true);
                return Some(self.finish(omega, sx, sy));
            }
        };
        None
    }

    /// Step `k` of the 1° scan (best angle and sum so far `best`, `best_s`); after the
    /// last, the golden section on the bracket around the best.
    fn scan_step(&self, k: usize, best: f64, best_s: f64) -> Search {
        let step = PI / 180.0;
        let g = golden_ratio();
        let t = k as f64 * step;
        let v = self.weighted(t, false);
        let (best, best_s) = if v < best_s { (t, v) } else { (best, best_s) };
        if k + 1 < 180 {
            Search::Scan {
                k: k + 1,
                best,
                best_s,
            }
        } else {
            let (a, b) = (best - step, best + step);
            Search::Golden {
                step: 0,
                a,
                b,
                c: b - g * (b - a),
                d: a + g * (b - a),
                sc: None,
                sd: None,
            }
        }
    }

    /// One evaluation of the golden section `search` (its two inner points first, then
    /// one per step); after [`GOLDEN_STEPS`], the sums at the middle of the bracket.
    fn golden_step(&self, search: Search) -> Search {
        let Search::Golden {
            step: k,
            a,
            b,
            c,
            d,
            sc,
            sd,
        } = search
        else {
            return search;
        };
        let g = golden_ratio();
        let s = |me: &Self, t: f64| me.weighted(t, false);
        match (sc, sd) {
            (None, _) => Search::Golden {
                step: k,
                a,
                b,
                c,
                d,
                sc: Some(s(self, c)),
                sd,
            },
            (Some(sc), None) => Search::Golden {
                step: k,
                a,
                b,
                c,
                d,
                sc: Some(sc),
                sd: Some(s(self, d)),
            },
            (Some(sc), Some(sd)) if k < GOLDEN_STEPS => {
                let (a, b, c, d, sc, sd) = if sc < sd {
                    let (b, d, sd) = (d, c, sc);
                    let c = b - g * (b - a);
                    (a, b, c, d, s(self, c), sd)
                } else {
                    let (a, c, sc) = (c, d, sd);
                    let d = a + g * (b - a);
                    (a, b, c, d, sc, s(self, d))
                };
                Search::Golden {
                    step: k + 1,
                    a,
                    b,
                    c,
                    d,
                    sc: Some(sc),
                    sd: Some(sd),
                }
            }
            (Some(_), Some(_)) => {
                // Σ R²|X'| = Σ R³|cos(φ − Ω)|.
                let omega = 0.5 * (a + b);
                Search::Sums {
                    omega,
                    sx: Some(self.weighted(omega, true)),
                }
            }
        }
    }

    fn finish(&self, omega: f64, sx: f64, sy: f64) -> Result<EllipsePhasors> {
        if !(sy > 0.0 && sx > 0.0) {
            return Err(Error::NotAnEllipse {
                detail: " (the binned readings lie on a line through the origin)",
            });
        }
        let k = sx / sy;
        let ratio = (k - 1.0) / (k + 1.0);
        let e_l = 0.25 * PI * (sx + sy) / self.sum_w;
        if ratio.abs() >= 0.95 {
            return Err(Error::NotAnEllipse {
                detail: " (axis ratio above 39: the readings are nearly a line)",
            });
        }
        EllipsePhasors::new(self.origin, omega, ratio, e_l)
    }
}

/// The seed's ellipse parameters of a full set about `origin` (claims 7–9). `full[i]` must
/// be the locus at the centre direction `(i + ½)·2π/N` of bin `i`, as the calibrator's full
/// set is; at most [`MAX_BINS`] of them.
///
/// - Ω_e minimises `S(θ) = Σ R_i² |cos(θ_i − θ)|` (a 1° scan of [0, π) refined by golden
///   section). It finds the minor axis (see the `binned_ellipse` module documentation), so
///   the ratio comes out negative about it.
/// - Ratio: with `X'`, `Y'` the readings rotated by Ω_e (claim 9),
///   `k = Σ R_i²|X'_i| / Σ R_i²|Y'_i|` and `E_R/E_L = (k − 1)/(k + 1)`; and
///   `|E_L| = (π/4) Σ R_i²(|X'_i| + |Y'_i|) / Σ R_i²`.
///
/// Each bin stands for the arc of directions it covers: `|cos(θ_i − θ)|` is replaced by its
/// mean over the bin. With a plain sum the kinks of `|cos|` make `S(θ)` ripple with the bin
/// spacing (relative ripple ≈ (π/N)²/8, against a signal of only ≈ r(θ − Ω_e)² near the
/// minimum), which moved Ω_e by about 1° for N = 64 and r = 0.13; the bin means are smooth.
pub fn ellipse_parameters(full: &[Vector2<f64>], origin: &Vector2<f64>) -> Result<EllipsePhasors> {
    if full.len() > MAX_BINS {
        return Err(Error::OutOfRange {
            what: "binned-ellipse full set length",
            value: full.len() as f64,
            min: 4.0,
            max: MAX_BINS as f64,
        });
    }
    let mut search = ParamSearch::new(full, origin)?;
    loop {
        if let Some(r) = search.step() {
            return r;
        }
    }
}

/// The golden section's ratio (√5 − 1)/2.
fn golden_ratio() -> f64 {
    0.5 * (5f64.sqrt() - 1.0)
}
