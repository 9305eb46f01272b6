//! The renderer and its frame: the one place where a frame's passes are listed, in order.

use glam::Vec3;

use crate::bad_input;
use crate::batching::{FrameShading, ShadeBatching};
use crate::error::Result;
use crate::gpu::{DebugConstants, GpuChannel, ShadeConstants, SubsurfaceParams, WorkCounters};
use crate::hierarchy::{Hierarchy, HierarchyOptions};
use crate::materials::Material;
use crate::output::{self, Exposure, HdrImage};
use crate::passes::debug_view::{self, DebugViewPass};
use crate::passes::irradiance::IrradiancePass;
use crate::passes::sampling::SamplingPass;
use crate::passes::shade::{self, ShadeInputs, ShadePass};
use crate::passes::shadow::ShadowPass;
use crate::passes::sort::SortPass;
use crate::passes::tile_cut::{TileCutPass, TileLists};
use crate::passes::tonemap::{self, TonemapPass};
use crate::passes::tree::TreePass;
use crate::physics::dipole::{self, SdTable};
use crate::physics::{Diffusion, Model};
use crate::scene::Scene;
use crate::vk::{
    self, Buffer, BufferUsageFlags, Context, Extent2D, GpuProfiler, Image, ImageUsageFlags, MemoryLocation, Recorder,
    TimedScope,
};

pub use crate::batching::DEFAULT_TILE;

/// The classical dipole's Sd table for the material of `o`.
fn dipole_table(o: &SubsurfaceOptions) -> SdTable {
    SdTable::new(&[0, 1, 2].map(|c| o.material.channel(c).constants(o.diffusion)))
}

fn subsurface_params(o: &SubsurfaceOptions, mm_per_unit: f32, point_count: u32) -> SubsurfaceParams {
    let channel = |c: usize| GpuChannel::from(&o.material.channel(c).constants(o.diffusion));
    SubsurfaceParams {
        channels: [channel(0), channel(1), channel(2)],
        mm_per_unit,
        epsilon: o.epsilon,
        model: o.model.gpu_code(),
        brute_force: o.brute_force as u32,
        point_count,
        node_count: point_count - 1,
        count_work: 0,
        specular: o.specular as u32,
        roughness: o.roughness,
        pad: [0; 3],
    }
}

/// A node is used whole when its area / squared distance is below this (`--epsilon`): with its two
/// sigma points per light, 0.2 gives 0.95% relative RMSE against brute force on the back-lit bunny
/// and 0.2–0.4% front-lit, unbiased, at about the cost 0.1 had with one source per node (0.65%,
/// biased low by 0.6–1.6%). See the sweep in BENCHMARKS.md.
pub const DEFAULT_EPSILON: f32 = 0.2;

/// The shading inputs, borrowed field by field (a method would borrow all of `self`, and the
/// profiler is borrowed mutably beside them).
macro_rules! shade_inputs {
    ($r:expr) => {
        ShadeInputs {
            color: &$r.color,
            depth: &$r.depth,
            position: &$r.position,
            normal: &$r.normal,
            vertices: &$r.vertices,
            indices: &$r.indices,
            index_count: $r.index_count,
            params: &$r.subsurface_params,
            nodes: &$r.hierarchy.nodes,
            points: &$r.hierarchy.sorted_points,
            work: &$r.work_counters,
            lights: &$r.hierarchy.lights,
            shadow_map: &$r.hierarchy.shadow_map,
            shadow_sampler: &$r.hierarchy.shadow_sampler,
            point_lights: &$r.hierarchy.sorted_point_lights,
            node_lights: &$r.hierarchy.node_lights,
            tile_headers: &$r.tile_lists.headers,
            tile_entries: &$r.tile_lists.entries,
            dipole_table: &$r.dipole_table,
        }
    };
}

/// Records the tile-cut pass (a macro for the same reason as `shade_inputs`).
macro_rules! record_tile_cut {
    ($r:expr, $rec:expr) => {{
        let h = &$r.hierarchy;
        let (params, lists) = (&$r.subsurface_params, &$r.tile_lists);
        $r.passes.tile_cut.record($rec, params, &h.nodes, &h.sorted_points, &$r.position, lists, h.light_count)
    }};
}

/// A frame between [`Renderer::begin_frame`] and [`Renderer::finish_frame`].
pub struct FrameInProgress {
    view_projection: glam::Mat4,
    constants: ShadeConstants,
    units: Vec<shade::ShadeUnit>,
    done: usize,
    shading: FrameShading,
    extent: Extent2D,
}

impl FrameInProgress {
    /// The fraction of the shading done, 0 to 1.
    pub fn progress(&self) -> f32 {
        self.done as f32 / self.units.len().max(1) as f32
    }

    /// The longest time one shading unit (tile) took so far, as measured per submission.
    pub fn longest_unit_seconds(&self) -> f64 {
        self.shading.longest_unit_seconds()
    }
}

/// The most timestamp scopes one frame may open (each shading submission opens one).
const MAX_SCOPES: u32 = 4096;

/// What to draw: the shaded mesh, or a debug view instead of it (the subsurface pass is skipped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Show {
    Shading,
    /// The sample points coloured by irradiance.
    Samples,
    /// The boxes of the tree nodes this many levels below the root.
    Tree(u32),
}

/// How the subsurface term is integrated.
pub struct SubsurfaceOptions {
    pub material: Material,
    pub model: Model,
    pub diffusion: Diffusion,
    /// A node is used whole when its area / squared distance is below this.
    pub epsilon: f32,
    /// Sum over every point instead of walking the tree (the reference).
    pub brute_force: bool,
    /// Add the surface's microfacet reflection (`--no-specular` turns it off).
    pub specular: bool,
    /// Roughness of the microfacet lobe (α = roughness²), in (0, 1].
    pub roughness: f32,
}

pub struct FrameOptions {
    pub subsurface: SubsurfaceOptions,
    pub width: u32,
    pub height: u32,
    /// Time every pass with GPU timestamps.
    pub profile: bool,
    /// Count nodes visited and points evaluated per pixel on the GPU (costs atomics).
    pub count_work: bool,
    pub hierarchy: HierarchyOptions,
    pub show: Show,
    /// Of the tone-mapped 8-bit image (PNG); the HDR image is untouched.
    pub exposure: Exposure,
}

pub struct Renderer {
    // Field order is drop order: every resource before the context.
    profiler: Option<GpuProfiler>,
    pub hierarchy: Hierarchy,
    subsurface_params: Buffer,
    /// The classical dipole's Sd table (texels), for the material of `subsurface_params`.
    dipole_table: Buffer,
    /// Nodes and points per pixel, counted on the GPU when profiling.
    work_counters: Buffer,
    brute_force: bool,
    /// The model's GPU code (`SubsurfaceParams::model`): which shading pipeline draws.
    model: u32,
    passes: Passes,
    /// The per-tile source lists, sized for the frame and grown when a frame needs more.
    tile_lists: TileLists,
    /// The most entries the lists may hold, when set lower than the device allows (tests).
    tile_list_limit: Option<u64>,
    /// The lights the hierarchy was last given (re-sent only when they change).
    lights: Vec<crate::scene::Light>,
    /// Tile size and units per shading submission, learnt from the frames before.
    batching: ShadeBatching,
    /// Frames rendered, for the progress bar.
    frames_done: u64,
    /// Advanced by one per shading unit done, when set (the CLI sets one on a terminal).
    pub progress: Option<indicatif::ProgressBar>,
    show: Show,
    vertices: Buffer,
    indices: Buffer,
    index_count: u32,
    bounds: (Vec3, Vec3),
    color: Image,
    depth: Image,
    /// The G-buffer of the surface pass: world position and normal per pixel.
    position: Image,
    normal: Image,
    exposure: Exposure,
    histogram: Buffer,
    /// The tone-mapped image, one packed RGBA8 pixel per u32, read by the host.
    ldr: Buffer,
    readback: Buffer,
    extent: Extent2D,
    pub ctx: Context,
}

impl Renderer {
    /// Uploads the scene's mesh and creates the targets for `width` x `height` images.
    pub fn new(ctx: Context, scene: &Scene, options: FrameOptions) -> Result<Renderer> {
        let FrameOptions { subsurface, width, height, profile, count_work, hierarchy, show, exposure } = options;
        if !(subsurface.epsilon.is_finite() && subsurface.epsilon >= 0.0) {
            return Err(bad_input!("--epsilon {}: must be a finite number ≥ 0", subsurface.epsilon));
        }
        crate::settings::check_roughness(subsurface.roughness, "--roughness")?;
        let max = ctx.limits().max_image_dimension2_d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(bad_input!(
                "image size {width}x{height}: width and height must be between 1 and {max} on {}",
                ctx.info.name
            ));
        }
        let extent = Extent2D { width, height };
        let profiler = if profile {
            let p = GpuProfiler::new(&ctx, MAX_SCOPES)?;
            if p.is_none() {
                log::warn!("--profile: {} has no timestamp support on its queue; no GPU timings", ctx.info.name);
            }
            p
        } else {
            None
        };
        let vertex_data = scene.mesh.vertex_data();
        let index_count = u32::try_from(scene.mesh.indices.len()).map_err(|_| bad_input!("mesh: too many indices"))?;
        let vertices = vk::upload_buffer(
            &ctx,
            "vertices",
            &vertex_data,
            BufferUsageFlags::VERTEX_BUFFER | BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let indices = vk::upload_buffer(
            &ctx,
            "indices",
            &scene.mesh.indices,
            BufferUsageFlags::INDEX_BUFFER | BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let Targets { color, depth, position, normal, readback, ldr } = Targets::new(&ctx, extent)?;
        let histogram = Buffer::new(
            &ctx,
            "luminance histogram",
            tonemap::histogram_bytes(),
            BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let passes = Passes::new(&ctx)?;
        let tile_lists = TileLists::new(&ctx, width, height, None, None)?;
        let hierarchy = Hierarchy::new(&ctx, &scene.mesh, &scene.lights, &hierarchy)?;
        let mut params = subsurface_params(&subsurface, scene.mm_per_unit, hierarchy.point_count);
        params.count_work = count_work as u32;
        let work_counters = Buffer::new(
            &ctx,
            "work counters",
            std::mem::size_of::<WorkCounters>() as u64,
            BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let mut subsurface_params = Buffer::new(
            &ctx,
            "subsurface parameters",
            std::mem::size_of::<SubsurfaceParams>() as u64,
            BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        subsurface_params.write(0, &[params])?;
        let mut dipole_table = Buffer::new(
            &ctx,
            "dipole Sd table",
            (dipole::TABLE_SIZE * 16) as u64, // a header texel and TABLE_SIZE - 1 pairs
            BufferUsageFlags::UNIFORM_TEXEL_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        dipole_table.write(0, &self::dipole_table(&subsurface).texels())?;
        Ok(Renderer {
            profiler,
            hierarchy,
            subsurface_params,
            dipole_table,
            work_counters,
            brute_force: subsurface.brute_force,
            model: params.model,
            passes,
            tile_lists,
            tile_list_limit: None,
            lights: scene.lights.clone(),
            batching: ShadeBatching::default(),
            frames_done: 0,
            progress: None,
            show,
            vertices,
            indices,
            index_count,
            bounds: scene.mesh.bounds(),
            color,
            depth,
            position,
            normal,
            exposure,
            histogram,
            ldr,
            readback,
            extent,
            ctx,
        })
    }

    /// Renders `width` x `height` images from the next frame on (the window's size, or a preview
    /// of it); only the size-dependent targets are made again.
    pub fn set_size(&mut self, width: u32, height: u32) -> Result<()> {
        let max = self.ctx.limits().max_image_dimension2_d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(bad_input!("image size {width}x{height}: width and height must be between 1 and {max}"));
        }
        let extent = Extent2D { width, height };
        if extent == self.extent {
            return Ok(());
        }
        // A window's copy of the last image may still be reading these targets.
        self.ctx.wait_idle()?;
        let Targets { color, depth, position, normal, readback, ldr } = Targets::new(&self.ctx, extent)?;
        (self.color, self.depth, self.position, self.normal) = (color, depth, position, normal);
        (self.readback, self.ldr, self.extent) = (readback, ldr, extent);
        self.tile_lists = TileLists::new(&self.ctx, width, height, None, self.tile_list_limit)?;
        // Learn again whether a frame of this size fits one submission.
        self.batching.relearn();
        Ok(())
    }

    /// How long one shading submission should take from now on (a window wants short ones to stay
    /// responsive; the default suits GPU watchdogs and the progress bar).
    pub fn set_submission_target(&mut self, seconds: f64) {
        self.batching.set_target(seconds);
    }

    /// Tile lists of `capacity` entries from the next frame on, growing when a frame needs more
    /// up to `limit` entries (beyond it, a tile whose list does not fit is shaded by walking the
    /// tree from the root per pixel). For tests of those paths; the defaults suit rendering.
    pub fn set_tile_lists(&mut self, capacity: u64, limit: Option<u64>) -> Result<()> {
        self.ctx.wait_idle()?;
        let (w, h) = (self.extent.width, self.extent.height);
        self.tile_lists = TileLists::new(&self.ctx, w, h, Some(capacity), limit)?;
        self.tile_list_limit = limit;
        Ok(())
    }

    /// Entries the last frame's tile lists asked for, and the entries they hold.
    pub fn tile_list_entries(&self) -> Result<(u64, u64)> {
        Ok((self.tile_lists.entries_needed()?, self.tile_lists.capacity))
    }

    /// The size of the images rendered.
    pub fn extent(&self) -> Extent2D {
        self.extent
    }

    /// Material, model, ε, brute force and specular for the next frame (the work counting set at
    /// creation is kept). The hierarchy keeps the η it was built with.
    pub fn set_subsurface(&mut self, subsurface: &SubsurfaceOptions, mm_per_unit: f32) -> Result<()> {
        if !(subsurface.epsilon.is_finite() && subsurface.epsilon >= 0.0) {
            return Err(bad_input!("epsilon {}: must be a finite number ≥ 0", subsurface.epsilon));
        }
        crate::settings::check_roughness(subsurface.roughness, "roughness")?;
        let count_work = self.subsurface_params.read::<SubsurfaceParams>(1)?[0].count_work;
        let mut params = subsurface_params(subsurface, mm_per_unit, self.hierarchy.point_count);
        params.count_work = count_work;
        self.subsurface_params.write(0, &[params])?;
        self.dipole_table.write(0, &dipole_table(subsurface).texels())?;
        self.brute_force = subsurface.brute_force;
        self.model = params.model;
        self.hierarchy.set_eta(subsurface.material.eta as f32)
    }

    /// Samples `point_count` points from the next frame on: a new hierarchy for `mesh` (the
    /// scene's current mesh) with the same shadow resolution and η.
    pub fn set_point_count(&mut self, point_count: u32, mesh: &crate::mesh::Mesh) -> Result<()> {
        if point_count == self.hierarchy.point_count {
            return Ok(());
        }
        self.ctx.wait_idle()?;
        let options = HierarchyOptions {
            point_count,
            shadow_resolution: self.hierarchy.shadow_map.extent.width,
            eta: self.hierarchy.eta(),
        };
        self.hierarchy = Hierarchy::new(&self.ctx, mesh, &self.lights, &options)?;
        let mut params = self.subsurface_params.read::<SubsurfaceParams>(1)?[0];
        (params.point_count, params.node_count) = (point_count, point_count - 1);
        self.subsurface_params.write(0, &[params])
    }

    pub fn show(&self) -> Show {
        self.show
    }

    /// What to draw over the shading from the next frame on.
    pub fn set_show(&mut self, show: Show) {
        self.show = show;
    }

    /// Exposure of the tone-mapped image from the next frame on.
    pub fn set_exposure(&mut self, exposure: Exposure) {
        self.exposure = exposure;
    }

    /// The last frame tone-mapped on the GPU: one packed RGBA8 pixel per u32 (R in the low byte),
    /// rows of `extent().width`; a transfer source, e.g. for copying into a window's image.
    pub fn tone_mapped_buffer(&self) -> &Buffer {
        &self.ldr
    }

    fn units(&self) -> Vec<shade::ShadeUnit> {
        // Brute force sums (point, light) records, in ranges.
        let brute_force_points = self.brute_force.then_some(self.hierarchy.point_count * self.hierarchy.light_count);
        self.batching.units(self.extent.width, self.extent.height, brute_force_points)
    }

    /// Shades in tiles of `tile` pixels square from the next frame on, always (tests compare
    /// tilings).
    pub fn set_tile_size(&mut self, tile: u32) {
        self.batching.set_tile_size(tile);
    }

    /// Draws `mesh` from the next frame on (a deformed mesh, the next of a sequence): new vertex
    /// and index buffers, the hierarchy's triangle count, bounds and shadow matrices. The point
    /// count stays; the points are sampled on the new surface, as every frame.
    pub fn set_mesh(&mut self, mesh: &crate::mesh::Mesh) -> Result<()> {
        mesh.validate()?;
        let index_count = u32::try_from(mesh.indices.len()).map_err(|_| bad_input!("mesh: too many indices"))?;
        // A window's copy of the last image may still be in flight; nothing else uses the buffers.
        self.ctx.wait_idle()?;
        self.vertices = vk::upload_buffer(
            &self.ctx,
            "vertices",
            &mesh.vertex_data(),
            BufferUsageFlags::VERTEX_BUFFER | BufferUsageFlags::STORAGE_BUFFER,
        )?;
        self.indices = vk::upload_buffer(
            &self.ctx,
            "indices",
            &mesh.indices,
            BufferUsageFlags::INDEX_BUFFER | BufferUsageFlags::STORAGE_BUFFER,
        )?;
        self.index_count = index_count;
        self.bounds = mesh.bounds();
        self.hierarchy.set_mesh(&self.ctx, mesh, &self.lights)
    }

    /// The side of the shading tiles in pixels (when not shading whole frames).
    pub fn tile_size(&self) -> u32 {
        self.batching.tile_size()
    }

    /// The progress bar's length for `frames` frames (it counts thousandths of a frame).
    pub fn progress_length(frames: u32) -> u64 {
        frames as u64 * 1000
    }

    /// Work of the last frame's shading per pixel (zeros unless `count_work` was set).
    pub fn work(&self) -> Result<WorkCounters> {
        Ok(self.work_counters.read::<WorkCounters>(1)?[0])
    }

    /// The last frame tone-mapped on the GPU (exposure, filmic curve, sRGB; alpha = coverage).
    pub fn tone_mapped_image(&self) -> Result<image::RgbaImage> {
        let (w, h) = (self.extent.width, self.extent.height);
        output::rgba8_from_packed(w, h, &self.ldr.read::<u32>((w * h) as usize)?)
    }

    /// Writes the last frame: `.png` as tone-mapped on the GPU, `.exr` as linear radiance.
    pub fn write_image(&self, path: &std::path::Path) -> Result<()> {
        let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
        if ext == "png" {
            let image = self.tone_mapped_image()?;
            return output::write_file(path, &output::encode(image, image::ImageFormat::Png)?);
        }
        output::write_image(path, &self.image()?, self.exposure)
    }

    /// The guard on every frame: a non-finite pixel in the radiance makes the frame an error.
    /// With TRANSLUCENT_CHECK_PASSES=1 the error names the first pass whose output holds a
    /// non-finite value (sampling, irradiance, tree summaries, else shade).
    fn check_finite(&self) -> Result<()> {
        let Err(e) = output::check_finite(&self.image()?) else { return Ok(()) };
        if std::env::var("TRANSLUCENT_CHECK_PASSES").is_ok_and(|v| !v.is_empty() && v != "0") {
            let snapshot = self.hierarchy.download(&self.ctx)?;
            let bad_point = |p: &crate::gpu::SurfacePoint| !(p.position.is_finite() && p.area.is_finite());
            let pass = if snapshot.points.iter().any(bad_point) || snapshot.points.iter().any(|p| !p.normal.is_finite())
            {
                "sampling"
            } else if snapshot.points.iter().any(|p| !(p.irradiance.is_finite() && p.light_dir.is_finite())) {
                "irradiance"
            } else if snapshot
                .nodes
                .iter()
                .any(|n| !(n.power.is_finite() && n.center.is_finite() && n.area.is_finite()))
            {
                "tree summaries"
            } else {
                "shade"
            };
            return Err(crate::runtime!("{e}; the first pass with a non-finite output: {pass}"));
        }
        Err(e)
    }

    /// The last frame's linear radiance, read back from the GPU.
    pub fn image(&self) -> Result<HdrImage> {
        let count = (self.extent.width * self.extent.height) as usize;
        let pixels = self.readback.read::<[f32; 4]>(count)?;
        Ok(HdrImage { width: self.extent.width, height: self.extent.height, pixels })
    }
}

// The frame, in order: the hierarchy's seven passes (`HierarchyPasses::record`), the surface pass
// and the tile cut (`Renderer::begin_frame`), shading in tiles (`Renderer::shade_some`), then
// debug views, tone mapping and read-back (`Renderer::finish_frame`). One line per pass, each in
// its own timestamp scope (the names are what `--profile` and `bench` report).

/// Every pass's pipelines, made once; what they read and write belongs to the renderer and the
/// hierarchy.
struct Passes {
    hierarchy: HierarchyPasses,
    tile_cut: TileCutPass,
    shade: ShadePass,
    debug_view: DebugViewPass,
    tonemap: TonemapPass,
}

impl Passes {
    fn new(ctx: &Context) -> Result<Passes> {
        Ok(Passes {
            hierarchy: HierarchyPasses::new(ctx)?,
            tile_cut: TileCutPass::new(ctx)?,
            shade: ShadePass::new(ctx)?,
            debug_view: DebugViewPass::new(ctx)?,
            tonemap: TonemapPass::new(ctx)?,
        })
    }
}

/// The pipelines of the passes that rebuild a [`Hierarchy`] (which owns only its buffers).
pub struct HierarchyPasses {
    sampling: SamplingPass,
    shadow: ShadowPass,
    irradiance: IrradiancePass,
    sort: SortPass,
    tree: TreePass,
}

impl HierarchyPasses {
    pub fn new(ctx: &Context) -> Result<HierarchyPasses> {
        Ok(HierarchyPasses {
            sampling: SamplingPass::new(ctx)?,
            shadow: ShadowPass::new(ctx)?,
            irradiance: IrradiancePass::new(ctx)?,
            sort: SortPass::new(ctx)?,
            tree: TreePass::new(ctx)?,
        })
    }

    /// The frame's first seven passes: `h` rebuilt from the mesh in `vertices` and `indices`.
    /// Tests and tools record them alone to build a hierarchy.
    pub fn record(&self, rec: &mut Recorder, h: &Hierarchy, vertices: &Buffer, indices: &Buffer) -> Result<()> {
        let n = h.point_count;
        let (sort, tree) = (h.sort_buffers(), h.tree_buffers());
        // N points uniform by area over the mesh.
        rec.scope("sampling", |rec| {
            self.sampling.record(rec, vertices, indices, h.triangle_count, &h.prefix, &h.points, n, h.seed)
        })?;
        // Depth from each light, into the layers of one shadow map.
        rec.scope("shadow maps", |rec| {
            self.shadow.record(rec, vertices, indices, h.index_count, &h.shadow_map, &h.layer_matrices)
        })?;
        // Per point and light: the light entering the surface, and its direction.
        rec.scope("irradiance", |rec| {
            let (points, records, lights) = (&h.points, &h.point_lights, &h.lights);
            self.irradiance.record(rec, points, records, n, lights, &h.shadow_map, &h.shadow_sampler)
        })?;
        // A key per point along a Morton curve through the mesh's box.
        rec.scope("morton codes", |rec| self.sort.record_morton(rec, &sort, n, h.bounds()))?;
        // The points and their light records in key order.
        rec.scope("radix sort", |rec| self.sort.record_sort(rec, &sort, n))?;
        // A binary radix tree over the sorted keys.
        rec.scope("tree build", |rec| self.tree.record_build(rec, &tree, n))?;
        // Each node's summary of its points, bottom-up.
        rec.scope("tree summaries", |rec| self.tree.record_aggregate(rec, &tree, n))
    }
}

impl Renderer {
    /// Renders one frame and returns its GPU timestamp scopes (empty without a profiler). The
    /// lights are taken from `scene` every frame, so they may move between frames.
    pub fn render_frame(&mut self, scene: &Scene) -> Result<Vec<TimedScope>> {
        let mut frame = self.begin_frame(scene)?;
        while !self.shade_some(&mut frame, None)? {}
        self.finish_frame(frame)
    }

    /// The first part of [`render_frame`](Self::render_frame): the hierarchy and the depth
    /// pre-pass. Shading follows in [`shade_some`](Self::shade_some) steps (a window spreads them
    /// over turns of its event loop), then [`finish_frame`](Self::finish_frame). A frame may be
    /// dropped unfinished; every submission has completed when these return.
    pub fn begin_frame(&mut self, scene: &Scene) -> Result<FrameInProgress> {
        let aspect = self.extent.width as f32 / self.extent.height as f32;
        let view_projection = scene.camera.view_projection(aspect, self.bounds);
        let constants =
            ShadeConstants { view_projection, eye: scene.camera.eye.extend(1.0), point_range: glam::UVec4::ZERO };
        if scene.lights != self.lights {
            let layers = |lights: &[crate::scene::Light]| crate::budget::FrameSizes::shadow_layers(lights);
            if scene.lights.len() != self.lights.len() || layers(&scene.lights) != layers(&self.lights) {
                // Another number of lights (or of point lights): per-light records and shadow
                // layers are sized at creation, so the hierarchy is made anew.
                self.ctx.wait_idle()?;
                let options = HierarchyOptions {
                    point_count: self.hierarchy.point_count,
                    shadow_resolution: self.hierarchy.shadow_map.extent.width,
                    eta: self.hierarchy.eta(),
                };
                self.hierarchy = Hierarchy::new(&self.ctx, &scene.mesh, &scene.lights, &options)?;
            } else {
                self.hierarchy.set_lights(&scene.mesh, &scene.lights)?;
            }
            self.lights = scene.lights.clone();
        }
        if self.show == Show::Shading {
            self.passes.shade.prepare(&self.ctx, self.model, self.brute_force)?;
        }
        let inputs = shade_inputs!(self);

        let cut = self.show == Show::Shading && !self.brute_force;
        if let Some(p) = self.profiler.as_mut() {
            p.begin_frame();
        }
        self.ctx.submit(self.profiler.as_mut(), |rec| {
            // The hierarchy, rebuilt from the mesh: seven passes (listed in `HierarchyPasses::record`).
            self.passes.hierarchy.record(rec, &self.hierarchy, &self.vertices, &self.indices)?;
            // The depth pre-pass and the G-buffer (world position and normal per pixel).
            rec.scope("surface", |rec| self.passes.shade.record_surface(rec, &inputs, &constants))?;
            if cut {
                // Per tile, the sources far enough for every pixel in it.
                rec.scope("tile cut", |rec| record_tile_cut!(self, rec))
            } else {
                // Brute force reads no lists; still, nothing the shader may load is left undefined.
                rec.fill_buffer(&self.tile_lists.headers, 0)
            }
        })?;
        if cut {
            if let Some(lists) = self.tile_lists.grown(&self.ctx)? {
                // Some tiles' lists did not fit (they would walk from the root): cut again into
                // lists as big as this frame needs.
                self.tile_lists = lists;
                self.ctx
                    .submit(self.profiler.as_mut(), |rec| rec.scope("tile cut", |rec| record_tile_cut!(self, rec)))?;
            }
        }
        Ok(FrameInProgress {
            view_projection,
            constants,
            // A debug view costs what it draws: no subsurface shading under it (the pre-pass's
            // depth still hides what is behind the surface).
            units: if self.show == Show::Shading { self.units() } else { Vec::new() },
            done: 0,
            shading: FrameShading::default(),
            extent: self.extent,
        })
    }

    /// Shading submissions until the frame is shaded, or with a `budget`, until the next one
    /// would likely overrun it (at least one is made). Returns whether the shading is complete.
    pub fn shade_some(&mut self, frame: &mut FrameInProgress, budget: Option<std::time::Duration>) -> Result<bool> {
        if frame.extent != self.extent {
            return Err(crate::runtime!("a frame begun at one size was continued at another"));
        }
        let inputs = shade_inputs!(self);
        let constants = frame.constants;
        let started = std::time::Instant::now();
        // Shading in several submissions, so that none runs long (see src/batching.rs).
        let units = &frame.units;
        while frame.done < units.len() {
            let spent = started.elapsed().as_secs_f64();
            let Some(size) = self.batching.next_batch(&frame.shading, spent, budget) else { break };
            let batch = &units[frame.done..(frame.done + size).min(units.len())];
            let submitted = std::time::Instant::now();
            // The subsurface term and the specular lobe per pixel, a batch of tiles at a time.
            self.ctx.submit(self.profiler.as_mut(), |rec| {
                rec.scope("shade", |rec| {
                    batch
                        .iter()
                        .try_for_each(|unit| self.passes.shade.record_unit(rec, &inputs, &constants, unit, self.model))
                })
            })?;
            let seconds = submitted.elapsed().as_secs_f64();
            frame.done += batch.len();
            self.batching.after_submission(&mut frame.shading, batch.len(), seconds);
            if let Some(bar) = &self.progress {
                bar.set_position(self.frames_done * 1000 + (1000 * frame.done / units.len()) as u64);
            }
        }
        Ok(frame.done == units.len())
    }

    /// The last part of a frame: debug views, tone mapping and read-back. Returns the frame's GPU
    /// timestamp scopes (empty without a profiler).
    pub fn finish_frame(&mut self, frame: FrameInProgress) -> Result<Vec<TimedScope>> {
        if frame.done < frame.units.len() || frame.extent != self.extent {
            return Err(crate::runtime!("finish_frame: the frame's shading is not complete"));
        }
        let view_projection = frame.view_projection;
        self.frames_done += 1;
        self.batching.after_frame(&frame.shading);

        if self.show == Show::Samples {
            // Debug view: the sample points coloured by irradiance.
            let debug = DebugConstants { view_projection, color_scale: Vec3::ONE.extend(2.0) };
            let (points, n) = (&self.hierarchy.sorted_points, self.hierarchy.point_count);
            self.ctx.submit(self.profiler.as_mut(), |rec| {
                rec.scope("show samples", |rec| {
                    self.passes.debug_view.record_points(rec, &self.color, &self.depth, points, n, &debug)
                })
            })?;
        }
        if let Show::Tree(level) = self.show {
            // Debug only: the boxes come from a download of the nodes, drawn in a second submission.
            let nodes = self.hierarchy.download(&self.ctx)?.nodes;
            let lines = debug_view::tree_level_lines(&nodes, level);
            if lines.is_empty() {
                return Err(crate::bad_input!("--level {level}: the tree has no internal nodes that deep"));
            }
            let buffer = vk::upload_buffer(&self.ctx, "tree lines", &lines, BufferUsageFlags::VERTEX_BUFFER)?;
            let debug = DebugConstants { view_projection, color_scale: Vec3::ONE.extend(1.0) };
            self.ctx.submit(None, |rec| {
                self.passes.debug_view.record_lines(rec, &self.color, &self.depth, &buffer, lines.len() as u32, &debug)
            })?;
        }
        self.ctx.submit(self.profiler.as_mut(), |rec| {
            // Exposure from a luminance histogram, the filmic curve and sRGB, packed to 8 bits.
            rec.scope("tone mapping", |rec| {
                self.passes.tonemap.record(rec, &self.color, &self.histogram, &self.ldr, self.exposure)
            })?;
            // The 8-bit image, the linear radiance and the work counters, for the host.
            rec.scope("readback", |rec| {
                rec.host_read(&self.work_counters)?;
                rec.host_read(&self.ldr)?;
                rec.copy_image_to_buffer(&self.color, &self.readback)
            })
        })?;
        self.check_finite()?;
        Ok(self.profiler.as_mut().map(|p| p.take_scopes()).unwrap_or_default())
    }
}

/// The images and buffers whose size is the frame's.
struct Targets {
    color: Image,
    depth: Image,
    position: Image,
    normal: Image,
    readback: Buffer,
    ldr: Buffer,
}

impl Targets {
    fn new(ctx: &Context, extent: Extent2D) -> Result<Targets> {
        let color = Image::new_2d(
            ctx,
            "hdr colour",
            shade::COLOR_FORMAT,
            extent,
            1,
            ImageUsageFlags::COLOR_ATTACHMENT | ImageUsageFlags::TRANSFER_SRC | ImageUsageFlags::STORAGE,
        )?;
        let depth =
            Image::new_2d(ctx, "depth", shade::DEPTH_FORMAT, extent, 1, ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT)?;
        let surface = |name| {
            let usage = ImageUsageFlags::COLOR_ATTACHMENT | ImageUsageFlags::STORAGE;
            Image::new_2d(ctx, name, shade::SURFACE_FORMAT, extent, 1, usage)
        };
        let (position, normal) = (surface("surface position")?, surface("surface normal")?);
        let readback_bytes = extent.width as u64 * extent.height as u64 * 16;
        let readback =
            Buffer::new(ctx, "readback", readback_bytes, BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?;
        let ldr = Buffer::new(
            ctx,
            "tone-mapped image",
            tonemap::ldr_bytes(extent.width, extent.height),
            // TRANSFER_SRC: `view` copies it into the window's image.
            BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuToCpu,
        )?;
        Ok(Targets { color, depth, position, normal, readback, ldr })
    }
}
