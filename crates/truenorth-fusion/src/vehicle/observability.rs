//! Which learned states the data have not yet separated: read off the covariance.
//!
//! A state is determined once its uncertainty has fallen to half its prior's: the data,
//! not the prior, then say most of what is known of it. Two states the data see only in
//! combination (a gyro bias and a wheel-size difference on a steady circle turn the heading
//! alike) can each keep most of their prior's uncertainty while the sum is known exactly;
//! their correlation then nears ±1, which marks both as not yet determined too.

use truenorth_core::Unobserved;

use super::nav_filter::{
    BIAS, DIM, GAIN_NEG, GAIN_POS, NavFilter, SPEED_COEFF, TRACK_SCALE, WHEEL_DIFF, WHEEL_LAG,
    WHEEL_SCALE,
};

/// A state whose standard deviation is above this share of its prior's is not yet
/// determined.
const DETERMINED_SHARE: f64 = 0.5;

/// Two states whose correlation is beyond this are seen only in combination.
const COMBINED_CORRELATION: f64 = 0.95;

/// The learned states, in the order of [`Unobserved`]'s fields.
const LEARNED: [usize; 8] = [
    BIAS,
    GAIN_POS,
    GAIN_NEG,
    WHEEL_DIFF,
    TRACK_SCALE,
    SPEED_COEFF,
    WHEEL_SCALE,
    WHEEL_LAG,
];

/// Which of `filter`'s learned states are not yet determined, against the prior standard
/// deviations `prior_sigma` (a state with a zero prior is not learned, and never reported).
pub fn unobserved(filter: &NavFilter, prior_sigma: &[f64; DIM]) -> Unobserved {
    let open = |i: usize| {
        let prior = prior_sigma[i];
        if prior <= 0.0 {
            return false;
        }
        let sigma = filter.sigma(i);
        if sigma > DETERMINED_SHARE * prior {
            return true;
        }
        LEARNED.iter().any(|&j| {
            let sj = filter.sigma(j);
            j != i
                && prior_sigma[j] > 0.0
                && sigma > 0.0
                && sj > 0.0
                && (filter.p[i][j] / (sigma * sj)).abs() > COMBINED_CORRELATION
        })
    };
    Unobserved {
        gyro_bias: open(BIAS),
        gyro_gain_right: open(GAIN_POS),
        gyro_gain_left: open(GAIN_NEG),
        wheel_diff: open(WHEEL_DIFF),
        track_scale: open(TRACK_SCALE),
        speed_coeff: open(SPEED_COEFF),
        wheel_scale: open(WHEEL_SCALE),
        wheel_lag: open(WHEEL_LAG),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_state_is_open_until_the_data_halve_its_prior_or_while_it_moves_with_another() {
        let mut prior = [0.0; DIM];
        prior[BIAS] = 0.05;
        prior[WHEEL_DIFF] = 0.01;
        let mut f = NavFilter::new([0.0; DIM], prior);
        let u = unobserved(&f, &prior);
        assert!(u.gyro_bias && u.wheel_diff && !u.speed_coeff);
        // Both learned to a fifth, independently: determined.
        f.p[BIAS][BIAS] = (0.01f64).powi(2);
        f.p[WHEEL_DIFF][WHEEL_DIFF] = (0.002f64).powi(2);
        let u = unobserved(&f, &prior);
        assert!(!u.gyro_bias && !u.wheel_diff);
        // Known only in combination.
        let c = 0.99 * 0.01 * 0.002;
        f.p[BIAS][WHEEL_DIFF] = c;
        f.p[WHEEL_DIFF][BIAS] = c;
        let u = unobserved(&f, &prior);
        assert!(u.gyro_bias && u.wheel_diff && u.any());
    }
}
