// Constants the GPU code and the Rust code share, defined here only. build.rs includes this file
// and writes every entry of `GLSL_CONSTANTS` into the generated header `gpu_constants.glsl`
// (`const uint NAME = VALUEu;`), which the shaders include; so this file must stand alone (no
// `crate::` paths, no `use`).

/// `SubsurfaceParams.model` and the BSSRDF evaluation's push constant: the directional dipole.
pub const MODEL_DIRECTIONAL: u32 = 0;
/// The same for the classical dipole.
pub const MODEL_DIPOLE: u32 = 1;

/// Set in a tree node's child index when the child is a point (index into the sorted points).
pub const LEAF_BIT: u32 = 0x8000_0000;

/// Lights in a `LightSet` (lights.glsl).
pub const MAX_LIGHTS: usize = 8;

/// Keys per tile of the radix sort (radix.glsl).
pub const RADIX_TILE: u32 = 256;

/// Every constant of the GLSL header, by its GLSL name.
pub const GLSL_CONSTANTS: &[(&str, u32)] = &[
    ("MODEL_DIRECTIONAL", MODEL_DIRECTIONAL),
    ("MODEL_DIPOLE", MODEL_DIPOLE),
    ("LEAF_BIT", LEAF_BIT),
    ("MAX_LIGHTS", MAX_LIGHTS as u32),
    ("RADIX_TILE", RADIX_TILE),
];
