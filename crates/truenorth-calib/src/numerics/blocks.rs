//! Sums over the readings a block at a time, in the shape the compiler vectorises.

use nalgebra::SVector;

/// How many points the hot loops over the data (the refinement passes, the moments of the
/// 3-D direct fit, the quality reports) process at a time.
///
/// A loop first computes one quantity for every point of a block into an array, then the
/// sums are taken over the arrays. Loops of that shape — the same straight-line arithmetic
/// on consecutive array elements, nothing carried from one point to the next — are the ones
/// the compiler turns into SIMD code (two `f64` per SSE2 register on the x86-64 baseline;
/// the crate forbids `unsafe`, so intrinsics are not an option). 32 points keep a block's
/// arrays (a few kB) in the L1 cache and on a small stack.
pub(crate) const BLOCK: usize = 32;

/// `Σᵢ a[i]·b[i]` over a block, in four interleaved partial sums added pairwise at the end:
/// consecutive additions to one sum would wait for each other (an `f64` add has a latency
/// of several cycles), separate ones do not, and pairs of them fill SIMD registers.
/// Summing in this order instead of one running sum changes the result by rounding error
/// only (Higham 2002, *Accuracy and Stability of Numerical Algorithms*, §4.2: the error
/// bound of blocked and pairwise summation is no larger).
#[inline(always)]
pub(crate) fn dot_block(a: &[f64; BLOCK], b: &[f64; BLOCK]) -> f64 {
    let mut s = [0.0; 4];
    for (ca, cb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        for l in 0..4 {
            s[l] += ca[l] * cb[l];
        }
    }
    // (s0 + s2) + (s1 + s3), not (s0 + s1) + ...: it keeps (s0, s1) and (s2, s3) as the two
    // SIMD registers of the loop instead of shuffling lanes on every step.
    (s[0] + s[2]) + (s[1] + s[3])
}

/// `Σᵢ a[i]` over a block (see [`dot_block`]).
#[inline(always)]
pub(crate) fn sum_block(a: &[f64; BLOCK]) -> f64 {
    let mut s = [0.0; 4];
    for ca in a.chunks_exact(4) {
        for l in 0..4 {
            s[l] += ca[l];
        }
    }
    (s[0] + s[2]) + (s[1] + s[3])
}

/// The points of `points` a [`BLOCK`] at a time, with one array per coordinate (the last
/// block is padded with zeros) and the number of points the block holds.
#[inline(always)]
pub(crate) fn blocks<const D: usize>(
    points: &[SVector<f64, D>],
) -> impl Iterator<Item = ([[f64; BLOCK]; D], usize)> + '_ {
    points.chunks(BLOCK).map(|chunk| {
        let mut q = [[0.0; BLOCK]; D];
        for (i, p) in chunk.iter().enumerate() {
            for (d, qd) in q.iter_mut().enumerate() {
                qd[i] = p[d];
            }
        }
        (q, chunk.len())
    })
}
