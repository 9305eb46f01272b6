//! Everything the GPU reads or writes with a layout of its own: the structs that mirror GLSL
//! blocks (`#[repr(C)]`, std430 = C layout; tests/layouts.rs compares them with the SPIR-V's
//! member offsets) and the constants both sides use. Sections follow `shaders/include/`:
//!
//! - `points`: points.glsl (surface points, their light records, tree nodes);
//! - `lights`: lights.glsl;
//! - `subsurface`: shading_params.glsl (per object, per frame) and bssrdf.glsl's per-channel
//!   constants;
//! - `sd_table`: the tabulated Sd(r) of the classical dipole and of photon beam diffusion as
//!   bssrdf.glsl reads it (f16 pairs);
//! - `shade`: shade_constants.glsl and shade.frag's work counters;
//! - `passes`: the other passes' push constants and blocks (bssrdf_eval.comp, tonemap.comp, the
//!   hierarchy's compute shaders, the debug views);
//! - `constants`: shared constants, from which build.rs writes the GLSL header
//!   `gpu_constants.glsl`.

pub mod constants;
pub mod lights;
pub mod passes;
pub mod points;
pub mod sd_table;
pub mod shade;
pub mod subsurface;

pub use constants::*;
pub use lights::*;
pub use passes::*;
pub use points::*;
pub use sd_table::SdTable;
pub use shade::*;
pub use subsurface::*;
