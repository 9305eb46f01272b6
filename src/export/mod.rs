//! Scenes for other renderers: what `render` would draw, written for a path tracer that solves the
//! radiative transfer equation exactly, as the ground truth to compare with (`translucent compare`).

pub mod mitsuba;
