//! Measured material presets.
