//! translucent: subsurface scattering with the directional dipole BSSRDF, integrated over a
//! Jensen–Buhler hierarchy that the GPU rebuilds every frame.

pub mod batching;
pub mod bench;
pub mod bssrdf_csv;
pub mod budget;
pub mod cli;
pub mod commands;
pub mod compare;
pub mod deform;
pub mod environment;
pub mod error;
pub mod export;
pub mod frame;
pub mod frame_desc;
pub mod gltf;
pub mod gpu;
pub mod gpu_world;
pub mod hierarchy;
pub mod image_quality;
pub mod materials;
pub mod mesh;
pub mod models;
pub mod output;
pub mod passes;
pub mod pbrt;
pub mod physics;
pub mod plot;
pub mod profiling;
pub mod scene;
pub mod settings;
pub mod shaders;
pub mod shadows;
pub mod view;
pub mod vk;
pub mod world;

pub use error::{Error, Result};
