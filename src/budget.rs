//! Checks a frame's sizes against what the device allows before anything is created, so that a
//! size inside the documented flag ranges that this device cannot hold is refused as bad input
//! (exit 2, naming the flag) instead of failing in `vkCreateImage` or the validation layer.

use crate::error::Result;
use crate::passes::{shade, shadow};
use crate::scene::Light;
use crate::vk::{Context, Format, ImageUsageFlags};
use crate::{bad_input, runtime};

/// What a frame allocates that grows with the user's flags.
pub struct FrameSizes {
    pub width: u32,
    pub height: u32,
    pub shadow_resolution: u32,
    /// Shadow-map layers: one per directional light and spot light, six per point light and spot
    /// wider than [`crate::scene::SPOT_CUBE_ABOVE_DEG`] (at least 2).
    pub shadow_layers: u32,
    pub point_count: u32,
    /// Lights with their own record per point (brute force's exact sum; 0 else).
    pub per_light_count: u32,
}

/// Bytes of one shadow-map array (of one receiver) beyond which many lights get maps of a lower
/// resolution: 768 MiB, e.g. 64 layers of 1024² or 256 of 512² (a 32-bit depth, a 32-bit normal
/// and a 32-bit curvature per texel).
pub const SHADOW_MAP_BUDGET: u64 = 768 << 20;
/// Bytes per shadow-map texel: its depth, and the normal and curvature there
/// (`shadow::SHADOW_NORMAL_FORMAT`).
pub const SHADOW_TEXEL_BYTES: u64 = 12;
/// Light counts up to which `--shadow-resolution` is taken as given (and refused if too large).
pub const FITTED_ABOVE_LIGHTS: usize = 8;

impl FrameSizes {
    pub fn shadow_layers(lights: &[Light]) -> u32 {
        lights.iter().map(Light::shadow_layers).sum::<u32>().max(2)
    }

    /// The shadow-map resolution for `lights` when `requested` is asked for: the requested one
    /// for up to [`FITTED_ABOVE_LIGHTS`] lights; for more (an environment's samples), halved
    /// while so many layers would pass [`SHADOW_MAP_BUDGET`] (never below 128 texels: many lights
    /// each cast a coarser shadow, and memory stays bounded by the work).
    pub fn fitted_shadow_resolution(requested: u32, lights: &[Light]) -> u32 {
        let layers = Self::shadow_layers(lights) as u64;
        let mut res = requested;
        if lights.len() <= FITTED_ABOVE_LIGHTS {
            return res;
        }
        while res > 128 && res as u64 * res as u64 * SHADOW_TEXEL_BYTES * layers > SHADOW_MAP_BUDGET {
            res = (res / 2).max(128);
        }
        res
    }
}

fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1u64 << 20) as f64
}

/// One image against `vkGetPhysicalDeviceImageFormatProperties`.
fn check_image(
    ctx: &Context,
    flag: &str,
    what: &str,
    format: Format,
    usage: ImageUsageFlags,
    (width, height, layers): (u32, u32, u32),
    bytes_per_texel: u64,
) -> Result<()> {
    let props = ctx
        .image_format_properties(format, usage)
        .ok_or_else(|| runtime!("this device cannot create the {what} image ({format:?})"))?;
    let max = props.max_extent;
    if width > max.width || height > max.height {
        return Err(bad_input!(
            "{flag}: the {what} image would be {width}x{height}; this device allows at most {}x{} for {format:?}",
            max.width,
            max.height
        ));
    }
    if layers > props.max_array_layers {
        return Err(bad_input!(
            "{flag}: the {what} image needs {layers} layers; this device allows {}",
            props.max_array_layers
        ));
    }
    let bytes = width as u64 * height as u64 * layers as u64 * bytes_per_texel;
    if bytes > props.max_resource_size {
        return Err(bad_input!(
            "{flag}: the {what} image ({width}x{height}{}) would take {:.0} MiB; this device allows {:.0} MiB for one \
             {format:?} image",
            if layers > 1 { format!(" x {layers} layers") } else { String::new() },
            mib(bytes),
            mib(props.max_resource_size)
        ));
    }
    Ok(())
}

/// Refuses a frame that this device cannot hold: each image's extent, layers and size against
/// the driver's limits for its format, and device memory against the largest device-local heap.
pub fn check_frame(ctx: &Context, s: &FrameSizes) -> Result<()> {
    let size = "--width/--height";
    let (w, h) = (s.width, s.height);
    let color_usage = ImageUsageFlags::COLOR_ATTACHMENT | ImageUsageFlags::TRANSFER_SRC | ImageUsageFlags::STORAGE;
    check_image(ctx, size, "colour", shade::COLOR_FORMAT, color_usage, (w, h, 1), 16)?;
    check_image(ctx, size, "depth", shade::DEPTH_FORMAT, ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT, (w, h, 1), 4)?;
    let surface_usage = ImageUsageFlags::COLOR_ATTACHMENT | ImageUsageFlags::STORAGE;
    check_image(ctx, size, "surface", shade::SURFACE_FORMAT, surface_usage, (w, h, 1), 16)?;
    let res = s.shadow_resolution;
    let shadow_usage = ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | ImageUsageFlags::SAMPLED;
    let shadow_size = (res, res, s.shadow_layers);
    if let Some(props) = ctx.image_format_properties(shadow::SHADOW_FORMAT, shadow_usage) {
        if s.shadow_layers > props.max_array_layers {
            return Err(bad_input!(
                "--light: the lights need {} shadow-map layers (1 per directional or spot light, 6 per point light); \
                 this device allows {}",
                s.shadow_layers,
                props.max_array_layers
            ));
        }
    }
    check_image(ctx, "--shadow-resolution", "shadow-map", shadow::SHADOW_FORMAT, shadow_usage, shadow_size, 4)?;
    let normal_usage = ImageUsageFlags::COLOR_ATTACHMENT | ImageUsageFlags::SAMPLED | ImageUsageFlags::TRANSFER_SRC;
    let format = shadow::SHADOW_NORMAL_FORMAT;
    check_image(ctx, "--shadow-resolution", "shadow-map normal", format, normal_usage, shadow_size, 8)?;

    // Device memory: the frame's targets, the shadow maps and the hierarchy (host-visible
    // read-back buffers live in another heap on a discrete GPU and are left out).
    let parts = [
        // Colour 16, depth 4, G-buffer 3 × 16, tile lists about 17 (a 16-byte header and 256
        // entries of 4 bytes per 8×8 tile) bytes per pixel.
        (size, w as u64 * h as u64 * (16 + 4 + 3 * 16 + 17)),
        ("--shadow-resolution", res as u64 * res as u64 * s.shadow_layers as u64 * SHADOW_TEXEL_BYTES),
        ("--samples", crate::hierarchy::bytes_used(s.point_count, s.per_light_count)),
    ];
    let total: u64 = parts.iter().map(|p| p.1).sum();
    let heap = ctx.largest_device_heap();
    if heap > 0 && total > heap {
        let (flag, _) = parts.iter().max_by_key(|p| p.1).copied().unwrap_or(parts[0]);
        return Err(bad_input!(
            "{flag}: this frame needs {:.0} MiB of device memory (image {:.0}, shadow maps {:.0}, points and tree \
             {:.0}); the device's largest memory heap holds {:.0} MiB",
            mib(total),
            mib(parts[0].1),
            mib(parts[1].1),
            mib(parts[2].1),
            mib(heap)
        ));
    }
    Ok(())
}
