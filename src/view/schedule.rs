//! When the viewer renders what: previews while the user interacts, a full frame once the view is
//! still, and which frame in progress to drop. Pure code with the clock passed in, so that its
//! decisions are unit-tested; the window (src/view/mod.rs) carries them out.

use std::time::{Duration, Instant};

/// Input this recent counts as an ongoing interaction: frames are previews until it is older.
pub const INTERACTION_HOLD: Duration = Duration::from_millis(300);

/// Previews aim at this wall time (their size adapts).
pub const PREVIEW_TARGET: Duration = Duration::from_millis(250);

/// Full frames faster than this need no previews.
pub const FAST_FRAME_S: f64 = 0.05;

/// Tiles are halved while one takes longer than STEP_BUDGET, down to this side.
pub const MIN_TILE: u32 = 16;

/// Shading work per turn of the event loop while a frame is refined, so that input is handled
/// about every 100 ms even when a full frame takes seconds (lavapipe).
pub const STEP_BUDGET: Duration = Duration::from_millis(80);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameKind {
    /// At a fraction of the window's size, while the user interacts.
    Preview,
    Full,
}

impl FrameKind {
    pub fn name(self) -> &'static str {
        match self {
            FrameKind::Preview => "preview",
            FrameKind::Full => "refined",
        }
    }
}

/// What to do with frames this turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    /// Drop the frame in progress (a full frame of a view that has changed since).
    pub drop: bool,
    /// Begin a frame of this kind (of the current view).
    pub begin: Option<FrameKind>,
}

/// The schedule's state.
#[derive(Debug)]
pub struct Schedule {
    /// The view changed since the last frame was begun.
    dirty: bool,
    /// The kind of the frame being shaded, if one is.
    in_progress: Option<FrameKind>,
    /// Previews are the window's size divided by this (adapted to PREVIEW_TARGET).
    preview_divisor: u32,
    /// Wall time of the last full frame.
    last_full_frame_s: Option<f64>,
    /// The last frame shown was a preview: refine once the interaction stops.
    shown_preview: bool,
    last_interaction: Option<Instant>,
}

impl Default for Schedule {
    fn default() -> Self {
        Schedule {
            dirty: true,
            in_progress: None,
            preview_divisor: 4,
            last_full_frame_s: None,
            shown_preview: false,
            last_interaction: None,
        }
    }
}

impl Schedule {
    /// The view (world or frame description) changed: the next frame must show it.
    pub fn changed(&mut self) {
        self.dirty = true;
    }

    pub fn is_dirty(&self) -> bool {
        self.dirty
    }

    /// Input from the hands at `now` (frames are previews while it keeps coming).
    pub fn interacted(&mut self, now: Instant) {
        self.last_interaction = Some(now);
    }

    pub fn interacting(&self, now: Instant) -> bool {
        self.last_interaction.is_some_and(|t| now.saturating_duration_since(t) < INTERACTION_HOLD)
    }

    /// The frame in progress, if any.
    pub fn in_progress(&self) -> Option<FrameKind> {
        self.in_progress
    }

    /// A preview was shown and no full frame has replaced it yet.
    pub fn shown_preview(&self) -> bool {
        self.shown_preview
    }

    /// A full frame took so little that previews would not help (a GPU).
    fn full_frames_are_fast(&self) -> bool {
        self.last_full_frame_s.is_some_and(|s| s < FAST_FRAME_S)
    }

    /// This turn's plan at `now`; `wanted` says whether anything besides the view's changes asks
    /// for a new frame (a script's frame count, a trace, an animation, `--frames`). A full frame
    /// of a view that has changed is dropped; a preview is short and is finished (its image is of
    /// the settings it was begun with, and a full frame of the new ones follows).
    pub fn plan(&self, now: Instant, wanted: bool) -> Plan {
        let drop = self.dirty && self.in_progress == Some(FrameKind::Full);
        let idle = self.in_progress.is_none() || drop;
        let begin = if !idle {
            None
        } else if self.dirty && self.interacting(now) && !self.full_frames_are_fast() {
            Some(FrameKind::Preview)
        } else if self.dirty || wanted || self.shown_preview {
            Some(FrameKind::Full)
        } else {
            None
        };
        Plan { drop, begin }
    }

    /// A frame of `kind` was begun of the current view.
    pub fn begun(&mut self, kind: FrameKind) {
        self.in_progress = Some(kind);
        self.dirty = false;
    }

    /// The frame in progress was dropped unfinished.
    pub fn dropped(&mut self) {
        self.in_progress = None;
    }

    /// The frame in progress finished after `seconds` of wall time: previews adapt their size to
    /// [`PREVIEW_TARGET`] (coarser when slower, finer when faster).
    pub fn finished(&mut self, seconds: f64) {
        match self.in_progress.take() {
            Some(FrameKind::Full) => {
                self.last_full_frame_s = Some(seconds);
                self.shown_preview = false;
            }
            Some(FrameKind::Preview) => {
                if seconds > 2.0 * PREVIEW_TARGET.as_secs_f64() && self.preview_divisor < 16 {
                    self.preview_divisor *= 2;
                } else if seconds < 0.5 * PREVIEW_TARGET.as_secs_f64() && self.preview_divisor > 2 {
                    self.preview_divisor /= 2;
                }
                self.shown_preview = true;
            }
            None => {}
        }
    }

    /// The size of a frame of `kind` in a window of `window` pixels.
    pub fn frame_size(&self, kind: FrameKind, (w, h): (u32, u32)) -> (u32, u32) {
        match kind {
            FrameKind::Full => (w, h),
            FrameKind::Preview => ((w / self.preview_divisor).max(1), (h / self.preview_divisor).max(1)),
        }
    }

    /// When to come round again when nothing is pending: at the end of the interaction (to refine
    /// the preview shown), at once when it has ended, else on the next input.
    pub fn idle_turn(&self, now: Instant) -> Turn {
        match (self.shown_preview, self.last_interaction) {
            (true, Some(t)) if self.interacting(now) => Turn::At(t + INTERACTION_HOLD),
            (true, _) => Turn::Now,
            _ => Turn::OnInput,
        }
    }
}

/// When the event loop should come round to the viewer again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Turn {
    Now,
    At(Instant),
    OnInput,
}

/// The tile side for the next frames when one tile of `tile` pixels took `longest_unit_s`: halved
/// while a tile is longer than a turn's budget, down to [`MIN_TILE`].
pub fn next_tile(tile: u32, longest_unit_s: f64) -> Option<u32> {
    (longest_unit_s > STEP_BUDGET.as_secs_f64() && tile > MIN_TILE).then(|| (tile / 2).max(MIN_TILE))
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: Duration = Duration::from_millis(1);

    /// A slow device (a full frame took a second), after its first full frame.
    fn slow() -> (Schedule, Instant) {
        let mut s = Schedule::default();
        let t0 = Instant::now();
        assert_eq!(s.plan(t0, false), Plan { drop: false, begin: Some(FrameKind::Full) });
        s.begun(FrameKind::Full);
        s.finished(1.0);
        assert_eq!(s.plan(t0, false), Plan { drop: false, begin: None }, "nothing to do when still");
        (s, t0)
    }

    /// An edit while a preview shades (the `d` key, the brute-force toggle, the sample slider, as
    /// the hands make them): the preview is finished with the settings it began with, and the
    /// next frame begun is a frame of the edited view; once still, a full one.
    #[test]
    fn an_edit_during_a_preview_is_shown_by_the_next_frame() {
        let (mut s, t0) = slow();
        s.interacted(t0);
        s.changed();
        let plan = s.plan(t0 + MS, false);
        assert_eq!(plan.begin, Some(FrameKind::Preview));
        s.begun(FrameKind::Preview);
        // Three edits while the preview is shading.
        for k in 1..=3 {
            s.interacted(t0 + MS * (10 * k));
            s.changed();
            assert_eq!(s.plan(t0 + MS * (10 * k), false), Plan { drop: false, begin: None }, "the preview goes on");
        }
        s.finished(0.2);
        // Still interacting: a preview of the edited view.
        assert_eq!(s.plan(t0 + MS * 40, false).begin, Some(FrameKind::Preview));
        s.begun(FrameKind::Preview);
        s.finished(0.2);
        // The hands stop: the view is refined in a full frame, at once after the hold.
        let still = t0 + MS * 40 + INTERACTION_HOLD;
        assert_eq!(s.idle_turn(t0 + MS * 50), Turn::At(t0 + MS * 30 + INTERACTION_HOLD));
        assert_eq!(s.idle_turn(still), Turn::Now);
        assert_eq!(s.plan(still, false), Plan { drop: false, begin: Some(FrameKind::Full) });
        s.begun(FrameKind::Full);
        s.finished(1.0);
        assert!(!s.shown_preview() && !s.is_dirty());
        assert_eq!(s.plan(still, false).begin, None);
    }

    /// An edit during a full frame drops it and begins one of the edited view.
    #[test]
    fn an_edit_during_a_full_frame_drops_it() {
        let (mut s, t0) = slow();
        s.changed();
        assert_eq!(s.plan(t0, false).begin, Some(FrameKind::Full));
        s.begun(FrameKind::Full);
        assert_eq!(s.plan(t0, false), Plan { drop: false, begin: None }, "shading goes on");
        s.changed();
        assert_eq!(s.plan(t0, false), Plan { drop: true, begin: Some(FrameKind::Full) });
        // By the keys: an interaction makes it a preview instead.
        s.interacted(t0);
        assert_eq!(s.plan(t0, false), Plan { drop: true, begin: Some(FrameKind::Preview) });
    }

    #[test]
    fn previews_adapt_their_size_and_fast_devices_skip_them() {
        let (mut s, t0) = slow();
        assert_eq!(s.frame_size(FrameKind::Preview, (640, 480)), (160, 120));
        s.changed();
        s.interacted(t0);
        s.begun(FrameKind::Preview);
        s.finished(0.9);
        assert_eq!(s.frame_size(FrameKind::Preview, (640, 480)), (80, 60), "slower than twice the target");
        s.begun(FrameKind::Preview);
        s.finished(0.01);
        assert_eq!(s.frame_size(FrameKind::Preview, (640, 480)), (160, 120));
        assert_eq!(s.frame_size(FrameKind::Full, (640, 480)), (640, 480));
        let mut fast = Schedule::default();
        fast.begun(FrameKind::Full);
        fast.finished(0.01);
        fast.changed();
        fast.interacted(t0);
        assert_eq!(fast.plan(t0, false).begin, Some(FrameKind::Full), "a GPU renders full frames at once");
    }

    #[test]
    fn tiles_halve_while_one_overruns_the_turn() {
        assert_eq!(next_tile(64, 0.2), Some(32));
        assert_eq!(next_tile(32, 0.01), None);
        assert_eq!(next_tile(MIN_TILE, 1.0), None);
        assert_eq!(next_tile(20, 1.0), Some(MIN_TILE));
    }
}
