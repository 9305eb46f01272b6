//! The renderer and its frame: the one place where a frame's passes are listed, in order. A frame
//! is made from a [`World`] (what is drawn) and a [`FrameDesc`] (how this frame draws it):
//! [`Renderer::begin_frame`] copies the description, brings the GPU's copy of the world up to date
//! ([`GpuWorld::sync`]) and records the passes; the rest of the frame uses only that copy.

use glam::Vec3;

use crate::bad_input;
use crate::batching::{FrameShading, ShadeBatching};
use crate::error::Result;
use crate::frame_desc::{FrameDesc, Show};
use crate::gpu::sd_table::AngularFactors;
use crate::gpu::{DebugConstants, FrameParams, ShadeConstants, WorkCounters};
use crate::gpu_world::{GpuObject, GpuWorld, SurfaceTexture};
use crate::hierarchy::Hierarchy;
use crate::output::{self, Exposure, HdrImage};
use crate::passes::background::BackgroundPass;
use crate::passes::debug_view::{self, DebugViewPass};
use crate::passes::diffuse::DiffusePass;
use crate::passes::far_field::{FarFieldInputs, FarFieldPass};
use crate::passes::irradiance::IrradiancePass;
use crate::passes::reentry::{self, ReentryInputs, ReentryPass};
use crate::passes::sampling::SamplingPass;
use crate::passes::shade::{self, ShadeInputs, ShadePass, SurfaceDraw};
use crate::passes::shadow::{Caster, ShadowPass};
use crate::passes::sort::SortPass;
use crate::passes::tile_cut::{initial_entries_per_tile, list_tile, TileCutPass, TileLists, FAR_FIELD_TILE};
use crate::passes::tonemap::{self, TonemapPass};
use crate::passes::tree::TreePass;
use crate::shadows::Shadows;
use crate::vk::{
    self, Buffer, BufferUsageFlags, Context, Extent2D, GpuProfiler, Image, ImageUsageFlags, MemoryLocation, Recorder,
    TimedScope,
};
use crate::world::World;

pub use crate::batching::DEFAULT_TILE;

/// The shading inputs of object `o`, borrowed field by field (a method would borrow all of the
/// renderer, and the profiler is borrowed mutably beside them).
macro_rules! shade_inputs {
    ($r:expr, $k:expr) => {{
        let (o, t, lists): (&GpuObject, &Targets, &TileLists) =
            (&$r.world.objects[$k], &$r.targets, &$r.tile_lists[$k]);
        ShadeInputs {
            color: &t.color,
            depth: &t.depth,
            position: &t.position,
            normal: &t.normal,
            albedo: &t.albedo,
            vertices: &o.vertices,
            indices: &o.indices,
            index_count: o.index_count,
            object_params: &o.params,
            frame_params: &$r.frame_params,
            nodes: &o.hierarchy.nodes,
            points: &o.hierarchy.sorted_points,
            work: &$r.work_counters,
            lights: &o.hierarchy.shadows.lights,
            shadow_map: &o.hierarchy.shadows.shadow_map,
            shadow_normals: &o.hierarchy.shadows.shadow_normals,
            shadow_sampler: &o.hierarchy.shadows.shadow_sampler,
            depth_sampler: &o.hierarchy.shadows.depth_sampler,
            point_lights: &o.hierarchy.sorted_point_lights,
            point_flux: &o.hierarchy.sorted_point_flux,
            node_flux: &o.hierarchy.node_flux,
            point_spread: &o.hierarchy.sorted_point_spread,
            tile_headers: &lists.headers,
            tile_entries: &lists.entries,
            far_field: &lists.far_field,
            list_tile: lists.list_tile,
            sd_table: &o.sd_table,
        }
    }};
}

/// Records the tile-cut pass of object `k` (a macro for the same reason as `shade_inputs`).
macro_rules! record_tile_cut {
    ($r:expr, $k:expr, $rec:expr, $model:expr) => {{
        let (o, lists): (&GpuObject, &TileLists) = (&$r.world.objects[$k], &$r.tile_lists[$k]);
        let h = &o.hierarchy;
        let surface = (&$r.targets.position, &$r.targets.normal);
        let lights = (&h.shadows.lights, &h.shadows.shadow_map, &h.shadows.shadow_sampler);
        let params = (&o.params, &$r.frame_params);
        let object = $k as u32;
        $r.passes.tile_cut.record($rec, params, &h.nodes, &h.sorted_points, surface, lights, lists, (object, $model))
    }};
}

/// A frame between [`Renderer::begin_frame`] and [`Renderer::finish_frame`]: its own copy of the
/// description it was begun with.
pub struct FrameInProgress {
    desc: FrameDesc,
    /// The renderer's count of frames begun when this one was: only the latest may go on.
    generation: u64,
    view_projection: glam::Mat4,
    constants: ShadeConstants,
    units: Vec<shade::ShadeUnit>,
    done: usize,
    shading: FrameShading,
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

    /// The description the frame was begun with.
    pub fn desc(&self) -> &FrameDesc {
        &self.desc
    }
}

/// The most timestamp scopes one frame may open (each shading submission opens one).
const MAX_SCOPES: u32 = 4096;

pub struct Renderer {
    // Field order is drop order: every resource before the context.
    profiler: Option<GpuProfiler>,
    world: GpuWorld,
    /// How the frame integrates (`FrameParams`), written when a frame begins.
    frame_params: Buffer,
    /// Nodes and points per pixel, counted on the GPU when profiling.
    work_counters: Buffer,
    passes: Passes,
    /// Per object, the per-tile source lists, sized for the frame and grown when a frame needs
    /// more.
    tile_lists: Vec<TileLists>,
    /// The most entries the lists may hold, when set lower than the device allows (tests).
    tile_list_limit: Option<u64>,
    /// The list tiles' size when set (tests), else chosen per object and frame.
    forced_list_tile: Option<u32>,
    /// Tile size and units per shading submission, learnt from the frames before.
    batching: ShadeBatching,
    /// Frames begun (a frame in progress may go on only while it is the latest).
    generation: u64,
    /// Frames finished, for the progress bar.
    frames_done: u64,
    /// Advanced by one per shading unit done, when set (the CLI sets one on a terminal).
    pub progress: Option<indicatif::ProgressBar>,
    /// The exposure of the last finished frame, for writing it.
    exposure: Exposure,
    histogram: Buffer,
    /// The frame's size-dependent images and buffers.
    targets: Targets,
    pub ctx: Context,
}

impl Renderer {
    /// A renderer on `ctx`; with `profile`, every pass is timed with GPU timestamps. What it
    /// draws comes with each frame ([`Renderer::begin_frame`]).
    pub fn new(ctx: Context, profile: bool) -> Result<Renderer> {
        let profiler = if profile {
            let p = GpuProfiler::new(&ctx, MAX_SCOPES)?;
            if p.is_none() {
                log::warn!("--profile: {} has no timestamp support on its queue; no GPU timings", ctx.info.name);
            }
            p
        } else {
            None
        };
        let histogram = Buffer::new(
            &ctx,
            "luminance histogram",
            tonemap::histogram_bytes(),
            BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let work_counters = work_counters(&ctx, std::mem::size_of::<WorkCounters>() as u64)?;
        let frame_params = Buffer::new(
            &ctx,
            "frame parameters",
            std::mem::size_of::<FrameParams>() as u64,
            BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        // The first frame makes the targets of its size.
        let unsized_extent = Extent2D { width: 1, height: 1 };
        Ok(Renderer {
            profiler,
            world: GpuWorld::default(),
            frame_params,
            work_counters,
            passes: Passes::new(&ctx)?,
            tile_lists: Vec::new(),
            tile_list_limit: None,
            forced_list_tile: None,
            batching: ShadeBatching::default(),
            generation: 0,
            frames_done: 0,
            progress: None,
            exposure: Exposure::Auto,
            histogram,
            targets: Targets::new(&ctx, unsized_extent)?,
            ctx,
        })
    }

    /// How long one shading submission should take from now on (a window wants short ones to stay
    /// responsive; the default suits GPU watchdogs and the progress bar).
    pub fn set_submission_target(&mut self, seconds: f64) {
        self.batching.set_target(seconds);
    }

    /// List tiles of `size` pixels a side (one of `LIST_TILE_SIZES`) from the next frame on, or
    /// (`None`) as `passes::tile_cut::list_tile` chooses per object and frame.
    pub fn force_list_tile(&mut self, size: Option<u32>) -> Result<()> {
        if let Some(s) = size.filter(|s| !crate::gpu::LIST_TILE_SIZES.contains(s)) {
            return Err(crate::bad_input!(
                "list tiles: {s} pixels a side is not one of {:?}",
                crate::gpu::LIST_TILE_SIZES
            ));
        }
        self.forced_list_tile = size;
        Ok(())
    }

    /// Tile lists of `capacity` entries from the next frame on, growing when a frame needs more
    /// up to `limit` entries (beyond it, a tile whose list does not fit is shaded by walking the
    /// tree from the root per pixel). For tests of those paths; the defaults suit rendering.
    pub fn set_tile_lists(&mut self, capacity: u64, limit: Option<u64>) -> Result<()> {
        self.ctx.wait_idle()?;
        let Extent2D { width, height } = self.targets.extent;
        for lists in &mut self.tile_lists {
            *lists = TileLists::new(&self.ctx, (width, height), lists.list_tile, Some(capacity), limit)?;
        }
        self.tile_list_limit = limit;
        Ok(())
    }

    /// Entries the last frame's tile lists of the first object asked for, and the entries they
    /// hold.
    pub fn tile_list_entries(&self) -> Result<(u64, u64)> {
        let lists = self.tile_lists.first().ok_or_else(|| crate::runtime!("no frame has been rendered"))?;
        Ok((lists.entries_needed()?, lists.capacity))
    }

    /// The size of the images rendered.
    pub fn extent(&self) -> Extent2D {
        self.targets.extent
    }

    /// The first object's hierarchy, once a frame has made it (tests and tools download it).
    pub fn hierarchy(&self) -> Option<&Hierarchy> {
        self.world.objects.first().map(|o| &o.hierarchy)
    }

    /// The last frame's re-entry patches of object `k` (passes::reentry), or None where it has
    /// none (not the Monte Carlo table, or not a closed mesh).
    pub fn reentry_patches(&self, k: usize) -> Result<Option<reentry::Patches>> {
        let Some(o) = self.world.objects.get(k) else { return Ok(None) };
        let Some(profile) = &o.reentry_profile else { return Ok(None) };
        let h = &o.hierarchy;
        let constants = reentry::constants(h.point_count, reentry::total_area(o.point_spacing, h.point_count), profile);
        Ok(Some(o.reentry.download(&self.ctx, constants)?))
    }

    /// How many grids of an object's inside the frames so far made (one per mesh the Monte Carlo
    /// table read; a change of material or model makes none).
    pub fn inside_grids_made(&self) -> u64 {
        self.world.inside_grids_made
    }

    /// Every translucent object's sample count (from the last frame).
    pub fn point_counts(&self) -> Vec<u32> {
        self.world.objects.iter().map(|o| o.hierarchy.point_count).collect()
    }

    /// The first object's sample count, once a frame has made its hierarchy.
    pub fn point_count(&self) -> Option<u32> {
        self.hierarchy().map(|h| h.point_count)
    }

    /// The last frame tone-mapped on the GPU: one packed RGBA8 pixel per u32 (R in the low byte),
    /// rows of `extent().width`; a transfer source, e.g. for copying into a window's image.
    pub fn tone_mapped_buffer(&self) -> &Buffer {
        &self.targets.ldr
    }

    /// Each object's shading units, object after object.
    fn units(&self, desc: &FrameDesc) -> Vec<shade::ShadeUnit> {
        let mut units = Vec::new();
        for (k, o) in self.world.objects.iter().enumerate() {
            // Brute force sums (point, light) records, in ranges.
            let records = o.hierarchy.point_count * o.hierarchy.per_light_count;
            let brute_force_points = desc.integration.brute_force.then_some(records);
            let first = units.len();
            units.extend(self.batching.units(desc.width, desc.height, brute_force_points));
            units[first..].iter_mut().for_each(|u| u.object = k as u32);
        }
        units
    }

    /// Shades in tiles of `tile` pixels square from the next frame on, always. How the shading is
    /// split into submissions, not what it computes: tests compare tilings bit for bit, and the
    /// viewer makes tiles smaller to keep its turns short.
    pub fn set_tile_size(&mut self, tile: u32) {
        self.batching.set_tile_size(tile);
    }

    /// The side of the shading tiles in pixels (when not shading whole frames).
    pub fn tile_size(&self) -> u32 {
        self.batching.tile_size()
    }

    /// The progress bar's length for `frames` frames (it counts thousandths of a frame).
    pub fn progress_length(frames: u32) -> u64 {
        frames as u64 * 1000
    }

    /// Work of the last frame's shading per pixel, every object's together (zeros unless it
    /// counted work).
    pub fn work(&self) -> Result<WorkCounters> {
        Ok(WorkCounters::combined(&self.work_per_object()?))
    }

    /// The same per translucent object, in the world's order.
    pub fn work_per_object(&self) -> Result<Vec<WorkCounters>> {
        self.work_counters.read::<WorkCounters>(self.world.objects.len().max(1))
    }

    /// The last frame tone-mapped on the GPU (exposure, filmic curve, sRGB; alpha = coverage).
    pub fn tone_mapped_image(&self) -> Result<image::RgbaImage> {
        let Extent2D { width, height } = self.targets.extent;
        output::rgba8_from_packed(width, height, &self.targets.ldr.read::<u32>((width * height) as usize)?)
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
        let Some(hierarchy) = self.hierarchy() else { return Err(e) };
        if std::env::var("TRANSLUCENT_CHECK_PASSES").is_ok_and(|v| !v.is_empty() && v != "0") {
            let snapshot = hierarchy.download(&self.ctx)?;
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
        let Extent2D { width, height } = self.targets.extent;
        let pixels = self.targets.readback.read::<[f32; 4]>((width * height) as usize)?;
        Ok(HdrImage { width, height, pixels })
    }

    /// Targets and tile lists for `width` x `height` images, made again only when the size
    /// changes.
    fn fit_targets(&mut self, width: u32, height: u32) -> Result<()> {
        let max = self.ctx.limits().max_image_dimension2_d;
        if width > max || height > max {
            return Err(bad_input!(
                "image size {width}x{height}: width and height must be between 1 and {max} on {}",
                self.ctx.info.name
            ));
        }
        let extent = Extent2D { width, height };
        if extent == self.targets.extent {
            return Ok(());
        }
        // A window's copy of the last image may still be reading these targets.
        self.ctx.wait_idle()?;
        self.targets = Targets::new(&self.ctx, extent)?;
        self.tile_lists.clear();
        // Learn again whether a frame of this size fits one submission.
        self.batching.relearn();
        Ok(())
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
    far_field: FarFieldPass,
    reentry: ReentryPass,
    shade: ShadePass,
    debug_view: DebugViewPass,
    diffuse: DiffusePass,
    background: BackgroundPass,
    tonemap: TonemapPass,
}

impl Passes {
    fn new(ctx: &Context) -> Result<Passes> {
        Ok(Passes {
            hierarchy: HierarchyPasses::new(ctx)?,
            tile_cut: TileCutPass::new(ctx)?,
            far_field: FarFieldPass::default(),
            reentry: ReentryPass::new(ctx)?,
            shade: ShadePass::new(ctx)?,
            debug_view: DebugViewPass::new(ctx)?,
            diffuse: DiffusePass::new(ctx)?,
            background: BackgroundPass::new(ctx)?,
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
    /// An Sd table buffer with no angular factors (all 1): what [`HierarchyPasses::record`]'s
    /// irradiance reads for a hierarchy without an object.
    no_factors: Buffer,
    /// No texture (a scatter weight of 1 everywhere), for the same.
    no_texture: SurfaceTexture,
    /// No curvature (one 0, which the shadow pass reads for every vertex), for the same.
    no_curvature: Buffer,
}

impl HierarchyPasses {
    pub fn new(ctx: &Context) -> Result<HierarchyPasses> {
        let table_texels = crate::gpu::sd_table::TABLE_SIZE;
        let mut no_factors = Buffer::new(
            ctx,
            "no angular factors",
            ((table_texels + AngularFactors::TEXELS) * 16) as u64,
            BufferUsageFlags::UNIFORM_TEXEL_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        no_factors.write((table_texels * 16) as u64, &AngularFactors::none().texels())?;
        Ok(HierarchyPasses {
            no_factors,
            no_curvature: vk::upload_buffer(ctx, "no curvature", &[0.0f32], BufferUsageFlags::STORAGE_BUFFER)?,
            no_texture: SurfaceTexture::new(ctx, &crate::world::Reflectance::Constant(glam::Vec3::ONE), None, 1)?,
            sampling: SamplingPass::new(ctx)?,
            shadow: ShadowPass::new(ctx)?,
            irradiance: IrradiancePass::new(ctx)?,
            sort: SortPass::new(ctx)?,
            tree: TreePass::new(ctx)?,
        })
    }

    /// The frame's first seven passes: `h` rebuilt from the mesh in `vertices` and `indices`,
    /// alone in the world. Tests and tools record them so to build a hierarchy.
    pub fn record(&self, rec: &mut Recorder, h: &Hierarchy, vertices: &Buffer, indices: &Buffer) -> Result<()> {
        let casters = [(vertices, indices, h.index_count, &self.no_curvature)];
        self.record_among(rec, h, (vertices, indices), &self.no_texture, &self.no_factors, &casters)
    }

    /// Every mesh of `casters` into the maps of `shadows`.
    pub fn record_shadows(&self, rec: &mut Recorder, casters: &[Caster], shadows: &Shadows) -> Result<()> {
        self.shadow.record(rec, casters, (&shadows.shadow_map, &shadows.shadow_normals), &shadows.layer_matrices)
    }

    /// The same among other objects: `casters` (every object's mesh, this one's included) cast
    /// the shadows its irradiance sees; `texture` is its scatter weight and `sd_table` its Sd
    /// table (their angular factors).
    pub fn record_among(
        &self,
        rec: &mut Recorder,
        h: &Hierarchy,
        (vertices, indices): (&Buffer, &Buffer),
        texture: &SurfaceTexture,
        sd_table: &Buffer,
        casters: &[Caster],
    ) -> Result<()> {
        let n = h.point_count;
        let (sort, tree) = (h.sort_buffers(), h.tree_buffers());
        // N points uniform by area over the mesh.
        rec.scope("sampling", |rec| {
            self.sampling.record(rec, vertices, indices, texture, h.triangle_count, &h.prefix, &h.points, n, h.seed)
        })?;
        // Depth of every object from each light, into the layers of one shadow map.
        let shadows = &h.shadows;
        rec.scope("shadow maps", |rec| self.record_shadows(rec, casters, shadows))?;
        // Per point: the light entering the surface from every light, merged (and per light for
        // brute force).
        rec.scope("irradiance", |rec| {
            let (points, flux, lights) = (&h.points, (&h.point_flux, &h.point_spread), &shadows.lights);
            let records = (&h.point_lights, h.per_light_count > 0);
            let shadow = (&shadows.shadow_map, &shadows.shadow_sampler);
            self.irradiance.record(rec, points, records, flux, n, lights, shadow.0, shadow.1, sd_table)
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

    /// The tree's summaries made again from its points' irradiance and records (after the
    /// re-entry added to them): the tree again (which clears the summaries' arrival counters),
    /// then the summaries.
    pub fn record_summaries_again(&self, rec: &mut Recorder, h: &Hierarchy) -> Result<()> {
        let (tree, n) = (h.tree_buffers(), h.point_count);
        self.tree.record_build(rec, &tree, n)?;
        self.tree.record_aggregate(rec, &tree, n)
    }
}

impl Renderer {
    /// Renders one frame of `world` as `desc` describes it, and returns its GPU timestamp scopes
    /// (empty without a profiler).
    pub fn render_frame(&mut self, world: &World, desc: &FrameDesc) -> Result<Vec<TimedScope>> {
        let mut frame = self.begin_frame(world, desc)?;
        while !self.shade_some(&mut frame, None)? {}
        self.finish_frame(frame)
    }

    /// The first part of [`render_frame`](Self::render_frame): checks and copies `desc`, brings
    /// the GPU's copy of `world` up to date, and records the hierarchy, the surface pass and the
    /// tile cut. Shading follows in [`shade_some`](Self::shade_some) steps (a window spreads them
    /// over turns of its event loop), then [`finish_frame`](Self::finish_frame). A frame may be
    /// dropped unfinished; every submission has completed when these return, and a frame begun
    /// later makes an earlier one impossible to go on with.
    pub fn begin_frame(&mut self, world: &World, desc: &FrameDesc) -> Result<FrameInProgress> {
        desc.validate()?;
        world.validate()?;
        self.world.sync(&self.ctx, world, desc)?;
        self.passes.background.sync(&self.ctx, desc.environment.as_ref())?;
        self.fit_targets(desc.width, desc.height)?;
        // A work record per object.
        let work_bytes = (self.world.objects.len() * std::mem::size_of::<WorkCounters>()) as u64;
        if self.work_counters.size < work_bytes {
            self.ctx.wait_idle()?;
            self.work_counters = work_counters(&self.ctx, work_bytes)?;
        }
        // Tile lists for each object (made again with the targets, or for a new object).
        self.tile_lists.truncate(self.world.objects.len());
        // Each object's list tiles from its pixels' width at its centre against its points' spacing.
        let camera = &desc.camera;
        let pixel_angle = 2.0 * (camera.fov_y_deg.to_radians() * 0.5).tan() / desc.height.max(1) as f32;
        let tile_of = |o: &GpuObject| {
            let footprint = pixel_angle * (0.5 * (o.bounds.0 + o.bounds.1) - camera.eye).length();
            self.forced_list_tile.unwrap_or_else(|| list_tile(footprint, o.point_spacing, self.ctx.subgroup_size))
        };
        for (o, lists) in self.world.objects.iter().zip(&mut self.tile_lists) {
            lists.set_list_tile(tile_of(o));
        }
        while self.tile_lists.len() < self.world.objects.len() {
            let o = &self.world.objects[self.tile_lists.len()];
            let (limit, size) = (self.tile_list_limit, tile_of(o));
            let tiles = desc.width.div_ceil(size) as u64 * desc.height.div_ceil(size) as u64;
            let capacity = tiles * initial_entries_per_tile(desc.integration.epsilon, o.hierarchy.point_count);
            self.tile_lists.push(TileLists::new(&self.ctx, (desc.width, desc.height), size, Some(capacity), limit)?);
        }
        let desc = desc.clone();
        let integration = desc.integration;
        self.frame_params.write(
            0,
            &[FrameParams {
                epsilon: integration.epsilon,
                brute_force: integration.brute_force as u32,
                count_work: desc.count_work as u32,
                specular: desc.specular as u32,
                roughness: desc.roughness,
                near_field: integration.splits_near_field() as u32,
                far_field: integration.uses_far_field() as u32,
                scattering: desc.scattering.code(),
            }],
        )?;
        self.generation += 1;
        let view_projection = desc.view_projection(self.world.bounds());
        let constants =
            ShadeConstants { view_projection, eye: desc.camera.eye.extend(1.0), point_range: glam::UVec4::ZERO };
        let shading = desc.show == Show::Shading;
        if shading {
            self.passes.shade.prepare(&self.ctx, shade_variant(&desc), integration.brute_force)?;
        }
        let cut = shading && !integration.brute_force;
        // Brute force sums each light's own records, which hold no re-entered light.
        let reentry_drawn = shading && integration.reentry && !integration.brute_force;
        let far_field = integration.uses_far_field();
        let objects = self.world.objects.len();
        let w = &self.world;
        let opaque_meshes = w.opaque.iter().map(|o| (&o.vertices, &o.indices, o.index_count, &o.curvature));
        let casters: Vec<_> = w
            .objects
            .iter()
            .map(|o| (&o.vertices, &o.indices, o.index_count, &o.curvature))
            .chain(opaque_meshes)
            .collect();
        let inputs: Vec<ShadeInputs> = (0..objects).map(|k| shade_inputs!(self, k)).collect();
        // Every object's draw into the G-buffer: the translucent ones (ids from 0), then the
        // opaque ones.
        let translucent_meshes =
            w.objects.iter().map(|o| (&o.vertices, &o.indices, o.index_count, &o.texture, &o.curvature));
        let opaque_surfaces =
            w.opaque.iter().map(|o| (&o.vertices, &o.indices, o.index_count, &o.texture, &o.curvature));
        let surfaces: Vec<SurfaceDraw> = (translucent_meshes.chain(opaque_surfaces).enumerate())
            .map(|(id, (vertices, indices, index_count, texture, curvature))| SurfaceDraw {
                vertices,
                indices,
                index_count,
                uvs: &texture.uvs,
                curvature,
                texture: (&texture.image, &texture.sampler),
                constants: texture.surface_constants(view_projection, id as u32),
            })
            .collect();
        if let Some(p) = self.profiler.as_mut() {
            p.begin_frame();
        }
        self.ctx.submit(self.profiler.as_mut(), |rec| {
            for o in &self.world.objects {
                // Each object's hierarchy, rebuilt from its mesh: seven passes (listed in
                // `HierarchyPasses::record`), its shadow maps seeing every object.
                self.passes.hierarchy.record_among(
                    rec,
                    &o.hierarchy,
                    (&o.vertices, &o.indices),
                    &o.texture,
                    &o.sd_table,
                    &casters,
                )?;
                // Light that leaves the object and enters it again, added to the points' own.
                if let (true, Some(profile)) = (reentry_drawn, &o.reentry_profile) {
                    let h = &o.hierarchy;
                    let total_area = reentry::total_area(o.point_spacing, h.point_count);
                    let constants = reentry::constants(h.point_count, total_area, profile);
                    let inputs = ReentryInputs { sources: o.sources(), buffers: &o.reentry };
                    // Three stages, each its own timestamp scope, and the tree again.
                    self.passes.reentry.record(rec, &inputs, &constants)?;
                    rec.scope("re-entry tree", |rec| self.passes.hierarchy.record_summaries_again(rec, h))?;
                }
            }
            if let Some(shadows) = &w.opaque_shadows {
                // The opaque objects' shadow maps, of every object.
                rec.scope("shadow maps", |rec| self.passes.hierarchy.record_shadows(rec, &casters, shadows))?;
            }
            // The depth pre-pass and the G-buffer (world position with the object, normal, and
            // the reflectance of opaque objects).
            let t = &self.targets;
            let targets = shade::SurfaceTargets {
                color: &t.color,
                depth: &t.depth,
                position: &t.position,
                normal: &t.normal,
                albedo: &t.albedo,
                work: &self.work_counters,
            };
            rec.scope("surface", |rec| self.passes.shade.record_surface(rec, &targets, &surfaces))?;
            // What no surface covers: the environment, or black.
            let aspect = desc.width as f32 / desc.height as f32;
            let t = &self.targets;
            rec.scope("background", |rec| {
                self.passes.background.record(rec, &t.color, &t.position, &desc.camera, aspect)
            })?;
            if let Some(shadows) = w.opaque_shadows.as_ref().filter(|_| shading) {
                // The opaque objects' reflection of the lights.
                let t = &self.targets;
                let gbuffer = (&t.position, &t.normal, &t.albedo);
                rec.scope("diffuse", |rec| {
                    self.passes.diffuse.record(rec, &t.color, gbuffer, shadows, objects as u32)
                })?;
            }
            for k in 0..objects {
                if cut {
                    // Per tile, the sources of this object far enough for every pixel of it.
                    rec.scope("tile cut", |rec| record_tile_cut!(self, k, rec, integration.model))?;
                } else {
                    // Brute force reads no lists; still, nothing the shader may load is left
                    // undefined.
                    rec.fill_buffer(&self.tile_lists[k].headers, 0)?;
                }
            }
            Ok(())
        })?;
        drop((inputs, surfaces));
        for k in 0..objects {
            if !cut {
                break;
            }
            if let Some(lists) = self.tile_lists[k].grown(&self.ctx)? {
                // Some tiles' lists did not fit (they would walk from the root): cut again into
                // lists as big as this frame needs.
                self.tile_lists[k] = lists;
                self.ctx.submit(self.profiler.as_mut(), |rec| {
                    rec.scope("tile cut", |rec| record_tile_cut!(self, k, rec, integration.model))
                })?;
            }
        }
        // The far field of the objects whose lists are of 8x8 tiles: after the last cut.
        let far: Vec<usize> =
            (0..objects).filter(|&k| cut && far_field && self.tile_lists[k].list_tile == FAR_FIELD_TILE).collect();
        if !far.is_empty() {
            let variant = (integration.model, desc.lights.len() == 1);
            self.passes.far_field.prepare(&self.ctx, variant.0, variant.1)?;
            self.ctx.submit(self.profiler.as_mut(), |rec| {
                rec.scope("far field", |rec| {
                    far.iter().try_for_each(|&k| {
                        let (o, t) = (&self.world.objects[k], &self.targets);
                        let inputs = FarFieldInputs { sources: o.sources(), position: &t.position, normal: &t.normal };
                        let eye = desc.camera.eye.extend(1.0).to_array();
                        self.passes.far_field.record(rec, variant, &inputs, &self.tile_lists[k], (k as u32, eye))
                    })
                })
            })?;
        }
        Ok(FrameInProgress {
            // A debug view costs what it draws: no subsurface shading under it (the pre-pass's
            // depth still hides what is behind the surface).
            units: if shading { self.units(&desc) } else { Vec::new() },
            desc,
            generation: self.generation,
            view_projection,
            constants,
            done: 0,
            shading: FrameShading::default(),
        })
    }

    /// Refuses to go on with a frame that a later one replaced (its inputs are gone).
    fn check_current(&self, frame: &FrameInProgress) -> Result<()> {
        if frame.generation != self.generation {
            return Err(crate::runtime!("a frame was begun after this one; it cannot be continued"));
        }
        Ok(())
    }

    /// Shading submissions until the frame is shaded, or with a `budget`, until the next one
    /// would likely overrun it (at least one is made). Returns whether the shading is complete.
    pub fn shade_some(&mut self, frame: &mut FrameInProgress, budget: Option<std::time::Duration>) -> Result<bool> {
        self.check_current(frame)?;
        let inputs: Vec<ShadeInputs> = (0..self.world.objects.len()).map(|k| shade_inputs!(self, k)).collect();
        let (constants, variant) = (frame.constants, shade_variant(&frame.desc));
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
                    batch.iter().try_for_each(|unit| {
                        self.passes.shade.record_unit(rec, &inputs[unit.object as usize], &constants, unit, variant)
                    })
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
        self.check_current(&frame)?;
        if frame.done < frame.units.len() {
            return Err(crate::runtime!("finish_frame: the frame's shading is not complete"));
        }
        let (view_projection, desc) = (frame.view_projection, &frame.desc);
        self.frames_done += 1;
        self.batching.after_frame(&frame.shading);
        let t = &self.targets;

        if desc.show == Show::Samples {
            // Debug view: every object's sample points coloured by irradiance.
            let debug = DebugConstants { view_projection, color_scale: Vec3::ONE.extend(2.0) };
            let objects = &self.world.objects;
            self.ctx.submit(self.profiler.as_mut(), |rec| {
                rec.scope("show samples", |rec| {
                    objects.iter().try_for_each(|o| {
                        let (points, n) = (&o.hierarchy.sorted_points, o.hierarchy.point_count);
                        self.passes.debug_view.record_points(rec, &t.color, &t.depth, points, n, &debug)
                    })
                })
            })?;
        }
        if let Show::Tree(level) = desc.show {
            // Debug only: the boxes come from a download of every object's nodes, drawn in a
            // second submission.
            let mut lines = Vec::new();
            for o in &self.world.objects {
                lines.extend(debug_view::tree_level_lines(&o.hierarchy.download(&self.ctx)?.nodes, level));
            }
            if self.world.objects.is_empty() {
                return Err(crate::bad_input!("--show tree: the scene has no translucent object (no tree)"));
            }
            if lines.is_empty() {
                return Err(crate::bad_input!("--level {level}: the tree has no internal nodes that deep"));
            }
            let buffer = vk::upload_buffer(&self.ctx, "tree lines", &lines, BufferUsageFlags::VERTEX_BUFFER)?;
            let debug = DebugConstants { view_projection, color_scale: Vec3::ONE.extend(1.0) };
            self.ctx.submit(None, |rec| {
                self.passes.debug_view.record_lines(rec, &t.color, &t.depth, &buffer, lines.len() as u32, &debug)
            })?;
        }
        let exposure = desc.exposure;
        self.ctx.submit(self.profiler.as_mut(), |rec| {
            // Exposure from a luminance histogram, the filmic curve and sRGB, packed to 8 bits.
            rec.scope("tone mapping", |rec| {
                self.passes.tonemap.record(rec, &t.color, &self.histogram, &t.ldr, exposure)
            })?;
            // The 8-bit image, the linear radiance and the work counters, for the host.
            rec.scope("readback", |rec| {
                rec.host_read(&self.work_counters)?;
                rec.host_read(&t.ldr)?;
                rec.copy_image_to_buffer(&t.color, &t.readback)
            })
        })?;
        self.exposure = exposure;
        self.check_finite()?;
        Ok(self.profiler.as_mut().map(|p| p.take_scopes()).unwrap_or_default())
    }
}

/// The work counters' buffer (`bytes`: a record per object), read by the host.
fn work_counters(ctx: &Context, bytes: u64) -> Result<Buffer> {
    let usage = BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_DST;
    Buffer::new(ctx, "work counters", bytes, usage, MemoryLocation::GpuToCpu)
}

/// The images and buffers whose size is the frame's.
struct Targets {
    extent: Extent2D,
    color: Image,
    depth: Image,
    position: Image,
    normal: Image,
    /// The reflectance of opaque objects (the surface pass writes it, the diffuse pass reads it).
    albedo: Image,
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
        let albedo = surface("surface albedo")?;
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
        Ok(Targets { extent, color, depth, position, normal, albedo, readback, ldr })
    }
}

/// The shade pass's pipeline for a frame described by `desc`.
fn shade_variant(desc: &FrameDesc) -> crate::passes::shade::ShadeVariant {
    let integration = &desc.integration;
    crate::passes::shade::ShadeVariant {
        model: integration.model,
        near_field: integration.splits_near_field(),
        one_light: desc.lights.len() == 1,
    }
}
