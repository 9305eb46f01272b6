//! Adaptive batching of the shading: how many tiles (units) each submission takes, learnt from the
//! submissions before, and whether a frame is shaded as one whole-image tile.

use std::time::Duration;

use crate::passes::shade::{self, ShadeUnit};

/// Shading is cut into tiles of this many pixels square (and, for brute force, ranges of points).
pub const DEFAULT_TILE: u32 = 128;

/// Each shading submission takes as many tiles as fit in about this much time, learnt from the
/// submissions before: short enough for GPU watchdogs (about 2 s on desktop drivers) and for a
/// moving progress bar, while a fast GPU still shades a frame in one or two submissions.
const SUBMISSION_TARGET_S: f64 = 0.2;

/// At most this many shading units per submission: each draw takes a descriptor set from the
/// submission's pool (`SETS_PER_SUBMIT` = 512 in src/vk/commands.rs).
const MAX_UNITS_PER_SUBMISSION: usize = 256;

/// Shading units for the next submission after `batch` units took `seconds`: as many as fit in
/// `target` seconds (SUBMISSION_TARGET_S unless set) at that pace, growing at most ×2 per step,
/// within [1, MAX_UNITS_PER_SUBMISSION].
fn next_batch_size(batch: usize, seconds: f64, target: f64) -> usize {
    let per_unit = seconds / batch.max(1) as f64;
    let fit = (target / per_unit.max(1e-9)).floor() as usize;
    fit.clamp(1, (2 * batch).clamp(1, MAX_UNITS_PER_SUBMISSION))
}

/// Whether the next frame shades the whole image as one tile: once a frame's shading took one
/// submission of under a quarter of the `target` time, and for as long as it stays under the target.
fn shade_whole_frame(whole_frame: bool, submissions: usize, seconds: f64, target: f64) -> bool {
    if whole_frame {
        seconds < target
    } else {
        submissions == 1 && seconds < target / 4.0
    }
}

/// What the renderer has learnt about shading submissions, across frames.
pub struct ShadeBatching {
    /// Side of the shading tiles in pixels.
    tile: u32,
    /// Shade the whole image as one tile: set once a frame's shading fits one short submission,
    /// since every tile draws the whole mesh again (unless a tile size was set explicitly).
    whole_frame: bool,
    tile_fixed: bool,
    /// Shading units per submission, adapted to `target_s`.
    units_per_submission: usize,
    /// How long one shading submission should take (SUBMISSION_TARGET_S unless set).
    target_s: f64,
}

/// One frame's shading submissions so far.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameShading {
    submissions: usize,
    seconds: f64,
    /// The longest time a submission took per unit in it.
    longest_unit_seconds: f64,
}

impl FrameShading {
    /// The longest time one shading unit (tile) took so far, as measured per submission.
    pub fn longest_unit_seconds(&self) -> f64 {
        self.longest_unit_seconds
    }
}

impl Default for ShadeBatching {
    fn default() -> ShadeBatching {
        ShadeBatching {
            tile: DEFAULT_TILE,
            whole_frame: false,
            tile_fixed: false,
            units_per_submission: 1,
            target_s: SUBMISSION_TARGET_S,
        }
    }
}

impl ShadeBatching {
    /// The shading units of a `width` x `height` frame: tiles, or the whole image as one.
    /// `brute_force_points` is the number of (point, light) records brute force sums, in ranges.
    pub fn units(&self, width: u32, height: u32, brute_force_points: Option<u32>) -> Vec<ShadeUnit> {
        let tile = if self.whole_frame { width.max(height) } else { self.tile };
        shade::shade_units(width, height, tile, brute_force_points)
    }

    /// Units for the next submission, `spent` seconds into this call's shading; `None` when,
    /// with a `budget`, the next submission would likely overrun it.
    pub fn next_batch(&self, frame: &FrameShading, spent: f64, budget: Option<Duration>) -> Option<usize> {
        if budget.is_some_and(|b| spent > 0.0 && spent + self.target_s > b.as_secs_f64()) {
            return None;
        }
        let mut size = self.units_per_submission;
        if let Some(b) = budget {
            // Tiles differ in cost (background ones are cheap): with a budget, no more than
            // the rest of it fits at the slowest pace seen in this frame.
            let worst = frame.longest_unit_seconds.max(1e-9);
            size = size.min((((b.as_secs_f64() - spent) / worst).floor() as usize).max(1));
        }
        Some(size)
    }

    /// Learns from a submission of `units` units that took `seconds`.
    pub fn after_submission(&mut self, frame: &mut FrameShading, units: usize, seconds: f64) {
        frame.longest_unit_seconds = frame.longest_unit_seconds.max(seconds / units as f64);
        (frame.submissions, frame.seconds) = (frame.submissions + 1, frame.seconds + seconds);
        self.units_per_submission = next_batch_size(units, seconds, self.target_s);
    }

    /// Learns from a frame's whole shading whether the next frame is shaded as one tile.
    pub fn after_frame(&mut self, frame: &FrameShading) {
        if !self.tile_fixed {
            self.whole_frame = shade_whole_frame(self.whole_frame, frame.submissions, frame.seconds, self.target_s);
        }
    }

    /// Learns again whether a frame fits one submission (after a change of the frame's size).
    pub fn relearn(&mut self) {
        if !self.tile_fixed {
            self.whole_frame = false;
            self.units_per_submission = 1;
        }
    }

    /// Shades in tiles of `tile` pixels square from now on, always.
    pub fn set_tile_size(&mut self, tile: u32) {
        self.tile = tile.max(1);
        self.tile_fixed = true;
        self.whole_frame = false;
    }

    /// The side of the shading tiles in pixels (when not shading whole frames).
    pub fn tile_size(&self) -> u32 {
        self.tile
    }

    /// How long one shading submission should take from now on.
    pub fn set_target(&mut self, seconds: f64) {
        self.target_s = seconds.max(1e-3);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn submissions_grow_and_shrink_toward_the_target_time() {
        assert_eq!(next_batch_size(1, 1e-6, SUBMISSION_TARGET_S), 2, "fast: at most doubles");
        assert_eq!(
            next_batch_size(200, 1e-6, SUBMISSION_TARGET_S),
            MAX_UNITS_PER_SUBMISSION,
            "never past the descriptor pool"
        );
        assert_eq!(next_batch_size(8, 0.1, SUBMISSION_TARGET_S), 16);
        assert_eq!(next_batch_size(8, 0.8, SUBMISSION_TARGET_S), 2, "slow: shrinks to what fits");
        assert_eq!(next_batch_size(1, 30.0, SUBMISSION_TARGET_S), 1, "never below one unit");
        assert_eq!(next_batch_size(4, 0.0, SUBMISSION_TARGET_S), 8);
    }

    #[test]
    fn fast_frames_are_shaded_whole() {
        assert!(shade_whole_frame(false, 1, 0.01, SUBMISSION_TARGET_S), "one quick submission: one tile next time");
        assert!(!shade_whole_frame(false, 2, 0.01, SUBMISSION_TARGET_S), "several submissions: keep the tiles");
        assert!(!shade_whole_frame(false, 1, 0.1, SUBMISSION_TARGET_S), "not quick enough to risk a whole frame");
        assert!(shade_whole_frame(true, 1, 0.15, SUBMISSION_TARGET_S), "stays whole while under the target");
        assert!(!shade_whole_frame(true, 1, 0.5, SUBMISSION_TARGET_S), "back to tiles when a frame gets slow");
    }
}
