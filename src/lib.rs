//! translucent: subsurface scattering with the directional dipole BSSRDF, integrated over a
//! Jensen–Buhler hierarchy that the GPU rebuilds every frame.

pub mod error;
pub mod mesh;
pub mod physics;
pub mod materials;

pub use error::{Error, Result};
