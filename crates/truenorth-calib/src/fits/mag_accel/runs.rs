//! Runs of shots that share a pointing direction: consecutive readings in which the
//! pointing axis keeps its direction (within a tolerance) while the instrument rolls about
//! it, found without being told where they are.

extern crate alloc;

use alloc::collections::VecDeque;
use alloc::vec::Vec;
use core::ops::Range;

use nalgebra::{Matrix3, Vector3};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// How runs are recognised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RunRule {
    /// Largest angle between the pointing directions of a run's first and any later shot,
    /// radians.
    pub tolerance_rad: f64,
    /// Smallest roll a run must span (the largest rotation between its first and any later
    /// shot), radians: a run that does not roll does not determine the pointing axis.
    pub min_roll_rad: f64,
    /// Fewest shots in a run.
    pub min_shots: usize,
}

/// The angle of the rotation `a · bᵀ` between two orthonormal frames (rows), radians.
fn rotation_angle(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    let c = ((a * b.transpose()).trace() - 1.0) * 0.5;
    c.clamp(-1.0, 1.0).acos()
}

/// The runs among the shots' frames (each shot's level frame, rows north-ish, west-ish, up,
/// as in `level_direction`; `None` where it is undefined) for the pointing axis `p`,
/// given one at a time in order: maximal stretches of consecutive shots whose pointing
/// directions stay within the tolerance of the first's and whose roll spans at least the
/// minimum.
///
/// A stretch that does not roll enough is searched again from its middle, for a run that
/// starts later in it; so the finder keeps the frames from the middle of the stretch at
/// hand on, up to `cap` of them. A stretch longer than that loses its frames: the search
/// then asks for the shots again from where it starts over ([`Self::end_pass`]), and the
/// caller passes over them once more. The runs are those of every frame at hand at once.
#[derive(Debug, Clone)]
pub(crate) struct RunFinder {
    p: Vector3<f64>,
    rule: RunRule,
    cap: usize,
    /// The frames from shot `base` on, as far as they have come.
    window: VecDeque<Option<Matrix3<f64>>>,
    base: usize,
    /// The first shot of the stretch at hand.
    start: usize,
    /// The scan of that stretch so far, once it has begun.
    scan: Option<Scan>,
    /// Whether the frames from `start` on must be given again.
    rewind: bool,
    runs: Vec<Range<usize>>,
}

/// A stretch being scanned: its first frame and pointing direction, the next shot to look
/// at, and the largest roll from the first so far.
#[derive(Debug, Clone, Copy)]
struct Scan {
    first: Matrix3<f64>,
    w0: Vector3<f64>,
    next: usize,
    roll: f64,
}

impl RunFinder {
    /// A finder of runs for the pointing axis `p` keeping up to `cap` frames (at least
    /// one), before any shot.
    pub fn new(p: Vector3<f64>, rule: RunRule, cap: usize) -> Self {
        Self {
            p,
            rule,
            cap: cap.max(1),
            window: VecDeque::new(),
            base: 0,
            start: 0,
            scan: None,
            rewind: false,
            runs: Vec::new(),
        }
    }

    /// Whether the finder takes the frame of shot `k` in this pass (the shots are given
    /// in order; one it does not take need not have its frame computed).
    pub fn wants(&self, k: usize) -> bool {
        !self.rewind && k == self.base + self.window.len()
    }

    /// The frame of the next shot it wants (see [`Self::wants`]).
    pub fn push(&mut self, frame: Option<Matrix3<f64>>) {
        if !self.rewind {
            self.window.push_back(frame);
            self.advance(false);
        }
    }

    /// Ends a pass over every shot: `true` when the finder wants another (the shots it
    /// wants, [`Self::wants`], begin further back), `false` when it has found every run.
    pub fn end_pass(&mut self) -> bool {
        if !self.rewind {
            self.advance(true);
        }
        if self.rewind {
            self.rewind = false;
            self.window.clear();
            self.base = self.start;
            true
        } else {
            false
        }
    }

    /// The runs found.
    pub fn runs(self) -> Vec<Range<usize>> {
        self.runs
    }

    fn frame(&self, k: usize) -> Option<Matrix3<f64>> {
        self.window[k - self.base]
    }

    /// Forgets the frames before shot `k`.
    fn forget_before(&mut self, k: usize) {
        while self.base < k && self.window.pop_front().is_some() {
            self.base += 1;
        }
    }

    /// Scans as far as the frames at hand allow (to the last shot when `at_end`).
    fn advance(&mut self, at_end: bool) {
        let n = self.base + self.window.len();
        while self.start < n {
            let i = self.start;
            let mut s = match self.scan {
                Some(s) => s,
                None => {
                    let Some(first) = self.frame(i) else {
                        self.start += 1;
                        self.forget_before(self.start);
                        continue;
                    };
                    Scan {
                        first,
                        w0: first * self.p,
                        next: i + 1,
                        roll: 0.0,
                    }
                }
            };
            let mut ended = false;
            while s.next < n {
                let Some(f) = self.frame(s.next) else {
                    ended = true;
                    break;
                };
                if (f * self.p).angle(&s.w0) > self.rule.tolerance_rad {
                    ended = true;
                    break;
                }
                s.roll = s.roll.max(rotation_angle(&f, &s.first));
                s.next += 1;
            }
            if !ended && !at_end {
                // The stretch goes on past the frames at hand. Whatever it turns out to be,
                // the next start is at least halfway along it; past the cap the frames go,
                // and the next start's are asked for again.
                self.scan = Some(s);
                self.forget_before(i + (s.next - i) / 2);
                if self.window.len() > self.cap {
                    self.forget_before(n);
                }
                return;
            }
            let j = s.next;
            if j - i >= self.rule.min_shots && s.roll >= self.rule.min_roll_rad {
                self.runs.push(i..j);
                self.start = j;
            } else {
                // A stretch that does not roll may still hold a run that starts later in it.
                self.start = i + ((j - i) / 2).max(1);
            }
            self.scan = None;
            if self.start < self.base {
                self.rewind = true;
                return;
            }
            self.forget_before(self.start);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;
    use proptest::prelude::*;

    /// The runs among `frames` by the finder keeping up to `cap` of them, given again
    /// as often as it asks.
    fn find_runs_within(
        frames: &[Option<Matrix3<f64>>],
        p: &Vector3<f64>,
        rule: &RunRule,
        cap: usize,
    ) -> Vec<Range<usize>> {
        let mut finder = RunFinder::new(*p, *rule, cap);
        loop {
            for (k, f) in frames.iter().enumerate() {
                if finder.wants(k) {
                    finder.push(*f);
                }
            }
            if !finder.end_pass() {
                return finder.runs();
            }
        }
    }

    /// The runs among `frames` by the finder, every frame kept.
    fn find_runs(
        frames: &[Option<Matrix3<f64>>],
        p: &Vector3<f64>,
        rule: &RunRule,
    ) -> Vec<Range<usize>> {
        find_runs_within(frames, p, rule, usize::MAX)
    }

    /// The runs among `frames` by the definition, every frame at hand: what the finder must
    /// give, shot by shot.
    fn runs_by_definition(
        frames: &[Option<Matrix3<f64>>],
        p: &Vector3<f64>,
        rule: &RunRule,
    ) -> Vec<Range<usize>> {
        let n = frames.len();
        let mut runs = Vec::new();
        let mut i = 0;
        while i < n {
            let Some(first) = frames[i] else {
                i += 1;
                continue;
            };
            let w0 = first * p;
            let mut j = i + 1;
            let mut roll: f64 = 0.0;
            while j < n {
                let Some(f) = frames[j] else { break };
                if (f * p).angle(&w0) > rule.tolerance_rad {
                    break;
                }
                roll = roll.max(rotation_angle(&f, &first));
                j += 1;
            }
            if j - i >= rule.min_shots && roll >= rule.min_roll_rad {
                runs.push(i..j);
                i = j;
            } else {
                i += ((j - i) / 2).max(1);
            }
        }
        runs
    }

    proptest! {
        /// Frames that wander, hold still, roll about the pointing axis and drop out: the
        /// finder, shot by shot, finds the runs of the definition.
        #[test]
        fn the_finder_finds_the_runs_of_the_definition(
            steps in prop::collection::vec((0u8..6, 0.0f64..1.0, 1usize..40), 0..40),
            min_shots in 3usize..6, cap in 1usize..12,
        ) {
            let mut frames = Vec::new();
            let (mut yaw, mut pitch, mut roll) = (0.0f64, 0.0f64, 0.0f64);
            for (kind, x, len) in steps {
                for _ in 0..len {
                    match kind {
                        0 => roll += 0.3 * x,
                        1 => yaw += 0.05 * x,
                        2 => pitch = (pitch + 0.4 * (x - 0.5)).clamp(-1.2, 1.2),
                        3 => {}
                        4 => { roll += 0.5; yaw += 0.2 * x; }
                        _ => { frames.push(None); continue; }
                    }
                    frames.push(frame(yaw, pitch, roll));
                }
            }
            let rule = RunRule { min_shots, ..RULE };
            let want = runs_by_definition(&frames, &Vector3::x(), &rule);
            prop_assert_eq!(find_runs(&frames, &Vector3::x(), &rule), want.clone());
            // And keeping only a few frames, passing over the shots again when asked.
            prop_assert_eq!(find_runs_within(&frames, &Vector3::x(), &rule, cap), want);
        }
    }

    fn frame(yaw: f64, pitch: f64, roll: f64) -> Option<Matrix3<f64>> {
        // Body → level: its rows are the level axes in body coordinates.
        Some(Rotation3::from_euler_angles(roll, pitch, yaw).into_inner())
    }

    const RULE: RunRule = RunRule {
        tolerance_rad: 0.17,
        min_roll_rad: 1.57,
        min_shots: 3,
    };

    #[test]
    fn rolled_shots_form_runs_and_assorted_ones_do_not() {
        let mut frames = Vec::new();
        for k in 0..8 {
            frames.push(frame(
                0.3 * k as f64 + 1.0,
                0.5 * (k as f64).sin(),
                0.7 * k as f64,
            ));
        }
        for k in 0..8 {
            frames.push(frame(2.0, 0.4, 0.785 * k as f64));
        }
        // Held still: no roll, no run.
        for _ in 0..5 {
            frames.push(frame(-1.0, 0.1, 0.2));
        }
        for k in 0..8 {
            frames.push(frame(-0.5, -0.3, 0.785 * k as f64));
        }
        let runs = find_runs(&frames, &Vector3::x(), &RULE);
        assert_eq!(runs, vec![8..16, 21..29]);
        assert!(find_runs(&[None, None], &Vector3::x(), &RULE).is_empty());
    }
}
