//! The GPU's copy of the [`World`]: per object its mesh buffers, its hierarchy (points, tree,
//! shadow maps) and its shading parameters. [`GpuWorld::sync`] is the one place that decides what
//! to make again when the world or the frame's lights change; the renderer calls it when a frame
//! begins, never while one is in flight.

use glam::{Vec2, Vec3, Vec4};

use crate::bad_input;
use crate::budget::{self, FrameSizes};
use crate::error::Result;
use crate::frame_desc::FrameDesc;
use crate::gpu::sd_table::{AngularFactors, CurvatureRatios, SlabTransmission};
use crate::gpu::{GpuChannel, ObjectParams, SdTable, SurfaceConstants};
use crate::hierarchy::{self, Hierarchy, HierarchyOptions};
use crate::materials::{Material, ScatterWeight};
use std::cell::OnceCell;

use crate::mesh::occupancy::{self, Occupancy};
use crate::mesh::Mesh;
use crate::passes::reentry::{self, ReentryBuffers, ReentryProfile};
use crate::physics::beam_diffusion::BeamMedium;
use crate::physics::mc_profile::McProfile;
use crate::physics::{curvature_profile, slab_profile};
use crate::physics::{Diffusion, Model};
use crate::scene::Light;
use crate::shadows::Shadows;
use crate::vk::{
    self, Buffer, BufferUsageFlags, Context, Extent2D, Format, Image, ImageUsageFlags, MemoryLocation, Sampler,
};
use crate::world::{Object, Opaque, Reflectance, Texture, World};

/// One object on the GPU.
pub struct GpuObject {
    pub hierarchy: Hierarchy,
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
    /// The world mesh's box (the camera's near and far planes are fitted to it).
    pub bounds: (Vec3, Vec3),
    /// The material's constants and the tree's size (`ObjectParams`, a uniform buffer).
    pub params: Buffer,
    /// The Sd table (texels) of the material for the frame's model: photon beam diffusion's for
    /// `pbd`, else the classical dipole's (the directional dipole reads none).
    pub sd_table: Buffer,
    /// Its texture's scatter weight (1 everywhere without one).
    pub texture: SurfaceTexture,
    /// Per vertex, its mean curvature smoothed over the material's longest diffusion length
    /// (1/scene unit, `mesh::curvature`), for the Monte Carlo table's curvature ratios (zeros
    /// for the other models, which do not read it).
    pub curvature: Buffer,
    /// The mean distance between its sample points, √(area / points), in scene units.
    pub point_spacing: f32,
    /// The grid of its mesh's inside (`mesh::occupancy`), made when the Monte Carlo table first
    /// needs it and kept until the mesh changes: a change of material, model or scale rewrites
    /// the Sd table but does not pay for it again (0.9 s for a million triangles).
    inside: OnceCell<Option<Occupancy>>,
    /// For light that leaves and enters it again (passes::reentry, the Monte Carlo table on a
    /// closed mesh only): the flat profile's near integral and reach, and ∫ Ft cos dω.
    pub reentry_profile: Option<ReentryProfile>,
    pub reentry: ReentryBuffers,
    /// What the buffers above were made from.
    made_from: MadeFrom,
}

/// What an object's GPU state was made from, to tell what changed.
struct MadeFrom {
    mesh: Mesh,
    material: Material,
    diffusion: Diffusion,
    /// Which profile the Sd table holds.
    table: TableProfile,
    mm_per_unit: f32,
    /// The sample count asked for (`None`: the default), and the count it resolved to.
    samples: Option<u32>,
    /// The texture and its uvs (the scatter weight is made from them, the material and the
    /// model with its diffusion).
    texture: Option<Reflectance>,
    uvs: Option<Vec<Vec2>>,
    weight_model: (Model, Diffusion),
}

/// The radial profile an object's Sd table holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum TableProfile {
    Dipole,
    BeamDiffusion,
    MonteCarlo,
}

impl TableProfile {
    fn of(model: Model) -> TableProfile {
        match model {
            Model::Pbd => TableProfile::BeamDiffusion,
            Model::Mc => TableProfile::MonteCarlo,
            Model::Directional | Model::Dipole => TableProfile::Dipole,
        }
    }
}

/// An object's texture on the GPU (shaders/include/surface_texture.glsl): one uv per vertex, an
/// image (one white texel unless the texture is an image) with its repeating sampler, and how to
/// read them. Opaque objects hold their Lambertian reflectance in it, translucent ones their
/// scatter weight ([`ScatterWeight`]).
pub struct SurfaceTexture {
    pub uvs: Buffer,
    pub image: Image,
    pub sampler: Sampler,
    /// surface_texture.glsl's kind, and its two values (with a checkerboard's scales in w).
    pub kind: u32,
    pub tex1: Vec4,
    pub tex2: Vec4,
}

impl SurfaceTexture {
    /// `texture` over `uvs` (zeros where there are none: then it must be constant).
    pub fn new(
        ctx: &Context,
        texture: &Reflectance,
        uvs: Option<&[Vec2]>,
        vertex_count: usize,
    ) -> Result<SurfaceTexture> {
        let uvs: Vec<[f32; 2]> = match uvs {
            Some(uvs) => uvs.iter().map(|uv| uv.to_array()).collect(),
            None => vec![[0.0; 2]; vertex_count.max(1)],
        };
        let uvs = vk::upload_buffer(ctx, "uvs", &uvs, BufferUsageFlags::STORAGE_BUFFER)?;
        let white = [[1.0f32; 4]];
        let (width, height, texels) = match texture {
            Reflectance::Image(t) => (t.width, t.height, t.texels.as_slice()),
            _ => (1, 1, &white[..]),
        };
        let max = ctx.limits().max_image_dimension2_d;
        if width > max || height > max {
            return Err(bad_input!("texture {width}x{height}: this device allows at most {max} texels a side"));
        }
        let usage = ImageUsageFlags::SAMPLED | ImageUsageFlags::TRANSFER_DST;
        let image =
            Image::new_2d(ctx, "surface texture", Format::R32G32B32A32_SFLOAT, Extent2D { width, height }, 1, usage)?;
        let mut staging = Buffer::new(
            ctx,
            "surface texture (staging)",
            std::mem::size_of_val(texels) as u64,
            BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        staging.write(0, texels)?;
        ctx.submit(None, |rec| rec.copy_buffer_to_image(&staging, &image))?;
        let sampler = Sampler::repeating(ctx)?;
        let (tex1, tex2, kind) = match *texture {
            Reflectance::Constant(c) => (c.extend(1.0), c.extend(1.0), 0),
            Reflectance::Checkerboard { uscale, vscale, tex1, tex2 } => (tex1.extend(uscale), tex2.extend(vscale), 1),
            Reflectance::Image(_) => (Vec4::ONE, Vec4::ONE, 2),
        };
        Ok(SurfaceTexture { uvs, image, sampler, kind, tex1, tex2 })
    }

    /// A translucent object's scatter weight under `model`: its texture's reflectance turned
    /// into the weight on its material ([`ScatterWeight`]), or 1 everywhere without a texture.
    pub fn scatter_weight(
        ctx: &Context,
        object: &Object,
        (model, diffusion): (Model, Diffusion),
        vertex_count: usize,
    ) -> Result<SurfaceTexture> {
        let curve = object.texture.as_ref().map(|_| ScatterWeight::new(&object.material, model, diffusion));
        let weight = |c: Vec3| {
            let w = curve.as_ref().map_or([1.0; 3], |curve| curve.of([c.x as f64, c.y as f64, c.z as f64]));
            Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32)
        };
        let texture = match &object.texture {
            None => Reflectance::Constant(Vec3::ONE),
            Some(Reflectance::Constant(c)) => Reflectance::Constant(weight(*c)),
            Some(Reflectance::Checkerboard { uscale, vscale, tex1, tex2 }) => {
                Reflectance::Checkerboard { uscale: *uscale, vscale: *vscale, tex1: weight(*tex1), tex2: weight(*tex2) }
            }
            Some(Reflectance::Image(t)) => {
                let texels = t.texels.iter().map(|p| weight(Vec3::new(p[0], p[1], p[2])).extend(1.0).to_array());
                Reflectance::Image(Texture {
                    name: t.name.clone(),
                    width: t.width,
                    height: t.height,
                    texels: std::sync::Arc::new(texels.collect()),
                })
            }
        };
        SurfaceTexture::new(ctx, &texture, object.uvs.as_deref(), vertex_count)
    }

    /// The draw into the G-buffer as object `id`, seen through `view_projection`.
    pub fn surface_constants(&self, view_projection: glam::Mat4, id: u32) -> SurfaceConstants {
        let (tex1, tex2, texture_kind) = (self.tex1, self.tex2, self.kind);
        SurfaceConstants { view_projection, tex1, tex2, object: id, texture_kind, pad: [0; 2] }
    }
}

/// One opaque object on the GPU.
pub struct GpuOpaque {
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
    /// Zeros per vertex: the surface pass's curvature, which only translucent objects use.
    pub curvature: Buffer,
    /// Its reflectance.
    pub texture: SurfaceTexture,
    pub bounds: (Vec3, Vec3),
    /// What it was made from.
    pub made_from: Opaque,
}

impl GpuOpaque {
    fn new(ctx: &Context, opaque: &Opaque) -> Result<GpuOpaque> {
        let mesh = opaque.world_mesh();
        let (vertices, indices, index_count) = upload_mesh(ctx, &mesh)?;
        let texture = SurfaceTexture::new(ctx, &opaque.reflectance, opaque.uvs.as_deref(), mesh.positions.len())?;
        let bounds = mesh.bounds();
        let zeros = vec![0.0f32; mesh.positions.len().max(1)];
        let curvature = vk::upload_buffer(ctx, "no curvature", &zeros, BufferUsageFlags::STORAGE_BUFFER)?;
        Ok(GpuOpaque { vertices, indices, index_count, curvature, texture, bounds, made_from: opaque.clone() })
    }
}

/// The world's objects on the GPU, and the light layout their hierarchies were made for.
#[derive(Default)]
pub struct GpuWorld {
    pub objects: Vec<GpuObject>,
    pub opaque: Vec<GpuOpaque>,
    /// The lights and the shadow maps fitted to the opaque objects (when there are any).
    pub opaque_shadows: Option<Shadows>,
    lights: Vec<Light>,
    shadow_resolution: u32,
    /// Whether the hierarchies keep each light's own records (brute force).
    per_light_records: bool,
    /// How many grids of an object's inside were made (a change of material must not make one).
    pub inside_grids_made: u64,
}

impl GpuWorld {
    /// Makes the GPU's copy follow `world` and the lights of `desc`: a new hierarchy where the
    /// sample count, the number of lights (or of shadow layers) or the shadow resolution changed;
    /// new mesh buffers (and the hierarchy's triangle count and bounds) where the mesh changed;
    /// new light records where only the lights moved; new parameters where the material, the
    /// diffusion or the scale changed. Both are validated by the caller.
    pub fn sync(&mut self, ctx: &Context, world: &World, desc: &FrameDesc) -> Result<()> {
        // Objects gone from the world take their GPU state with them.
        if self.objects.len() > world.objects.len() {
            ctx.wait_idle()?;
            self.objects.truncate(world.objects.len());
        }
        let layout = |lights: &[Light]| (lights.len(), FrameSizes::shadow_layers(lights));
        let per_light_records = desc.integration.brute_force;
        let relayout = layout(&self.lights) != layout(&desc.lights)
            || self.shadow_resolution != desc.shadow_resolution
            || self.per_light_records != per_light_records;
        let per_light_count = if per_light_records { desc.lights.len() as u32 } else { 0 };
        let shadow_resolution = FrameSizes::fitted_shadow_resolution(desc.shadow_resolution, &desc.lights);
        // The sample counts first (each known before anything is made), and the frame's sizes
        // against the device.
        let mut point_counts = Vec::with_capacity(world.objects.len());
        for (i, object) in world.objects.iter().enumerate() {
            let kept = self.objects.get(i).filter(|g| g.made_from.samples == object.samples && !relayout);
            point_counts.push(match (kept, object.samples) {
                (Some(g), _) => g.hierarchy.point_count,
                (None, Some(n)) => {
                    hierarchy::check_point_count(ctx, n, per_light_count)?;
                    n
                }
                (None, None) => {
                    let mesh = object.world_mesh();
                    let m = &object.material;
                    let share = world.objects.len() as u32;
                    hierarchy::default_point_count(ctx, &mesh, world.mm_per_unit, m, per_light_count, share)
                }
            });
        }
        budget::check_frame(
            ctx,
            &FrameSizes {
                width: desc.width,
                height: desc.height,
                shadow_resolution,
                shadow_layers: FrameSizes::shadow_layers(&desc.lights),
                point_count: point_counts.iter().sum(),
                per_light_count,
            },
        )?;
        let diffusion = desc.integration.diffusion;
        let table = TableProfile::of(desc.integration.model);
        let weight_model = (desc.integration.model, diffusion);
        let bounds: Vec<(Vec3, Vec3)> = world.objects.iter().map(|o| o.world_mesh().bounds()).collect();
        let opaque_bounds = world.opaque.iter().map(|o| o.world_mesh().bounds()).reduce(union);
        for (i, (object, &point_count)) in world.objects.iter().zip(&point_counts).enumerate() {
            let mesh = object.world_mesh();
            // The other objects, whose shadows this one's maps must see.
            let others = bounds.iter().enumerate().filter(|&(j, _)| j != i).map(|(_, b)| *b).chain(opaque_bounds);
            let others = others.reduce(union);
            let options =
                HierarchyOptions { point_count, shadow_resolution, eta: object.material.eta as f32, per_light_records };
            let Some(g) = self.objects.get_mut(i) else {
                let made_from = MadeFrom {
                    mesh: mesh.into_owned(),
                    material: object.material.clone(),
                    diffusion,
                    table,
                    mm_per_unit: world.mm_per_unit,
                    samples: object.samples,
                    texture: object.texture.clone(),
                    uvs: object.uvs.clone(),
                    weight_model,
                };
                let vertex_count = made_from.mesh.positions.len();
                let texture = SurfaceTexture::scatter_weight(ctx, object, weight_model, vertex_count)?;
                self.objects.push(GpuObject::new(
                    ctx,
                    &desc.lights,
                    &options,
                    made_from,
                    texture,
                    others,
                    &mut self.inside_grids_made,
                )?);
                continue;
            };
            let mesh_changed = *mesh != g.made_from.mesh;
            let remade = point_count != g.hierarchy.point_count || relayout;
            // A window's copy of the last image may still be in flight; nothing else uses what
            // is made again here (every frame's submissions have completed).
            if mesh_changed || remade {
                ctx.wait_idle()?;
            }
            if mesh_changed {
                (g.vertices, g.indices, g.index_count) = upload_mesh(ctx, &mesh)?;
                g.bounds = mesh.bounds();
            }
            let eta_changed = object.material.eta != g.made_from.material.eta;
            let casters_moved = others != g.hierarchy.casters();
            g.hierarchy.set_casters(others);
            if remade {
                g.hierarchy = Hierarchy::new(ctx, &mesh, &desc.lights, &options)?;
                if others.is_some() {
                    g.hierarchy.set_casters(others);
                    g.hierarchy.set_lights(&mesh, &desc.lights)?;
                }
            } else {
                if eta_changed {
                    g.hierarchy.set_eta(options.eta)?;
                }
                if mesh_changed {
                    g.hierarchy.set_mesh(ctx, &mesh, &desc.lights)?;
                } else if desc.lights != self.lights || casters_moved {
                    g.hierarchy.set_lights(&mesh, &desc.lights)?;
                }
            }
            // The mesh's area sets the points' spacing, and with it the near field's radii.
            let params_changed = remade
                || mesh_changed
                || object.material != g.made_from.material
                || diffusion != g.made_from.diffusion
                || table != g.made_from.table
                || world.mm_per_unit != g.made_from.mm_per_unit;
            if mesh_changed {
                g.made_from.mesh = mesh.into_owned();
                g.inside = OnceCell::new();
            }
            g.made_from.samples = object.samples;
            // The scatter weight is the texture's reflectance over the material's.
            if object.material != g.made_from.material
                || object.texture != g.made_from.texture
                || object.uvs != g.made_from.uvs
                || (object.texture.is_some() && weight_model != g.made_from.weight_model)
            {
                ctx.wait_idle()?;
                let vertex_count = g.made_from.mesh.positions.len();
                g.texture = SurfaceTexture::scatter_weight(ctx, object, weight_model, vertex_count)?;
                (g.made_from.texture, g.made_from.uvs) = (object.texture.clone(), object.uvs.clone());
                g.made_from.weight_model = weight_model;
            }
            if params_changed {
                g.made_from.material = object.material.clone();
                (g.made_from.diffusion, g.made_from.mm_per_unit) = (diffusion, world.mm_per_unit);
                g.made_from.table = table;
                let grid = inside_grid(&g.inside, &g.made_from, &mut self.inside_grids_made);
                (g.point_spacing, g.reentry_profile) =
                    write_params(&mut g.params, &mut g.sd_table, &g.made_from, grid, point_count)?;
                // Its smoothing length is the material's, in scene units.
                ctx.wait_idle()?;
                g.curvature = curvature_buffer(ctx, &g.made_from)?;
            }
        }
        self.sync_opaque(ctx, world, desc, (relayout, shadow_resolution), bounds.into_iter().reduce(union))?;
        self.lights = desc.lights.clone();
        self.shadow_resolution = desc.shadow_resolution;
        self.per_light_records = per_light_records;
        Ok(())
    }

    /// The opaque objects' buffers (made again when an object changes) and their shadow maps,
    /// fitted to them with the translucent objects (`translucent`, their box) as casters.
    fn sync_opaque(
        &mut self,
        ctx: &Context,
        world: &World,
        desc: &FrameDesc,
        (relayout, shadow_resolution): (bool, u32),
        translucent: Option<(Vec3, Vec3)>,
    ) -> Result<()> {
        if self.opaque.len() > world.opaque.len() {
            ctx.wait_idle()?;
            self.opaque.truncate(world.opaque.len());
        }
        for (j, o) in world.opaque.iter().enumerate() {
            match self.opaque.get_mut(j) {
                None => self.opaque.push(GpuOpaque::new(ctx, o)?),
                Some(g) if g.made_from != *o => {
                    ctx.wait_idle()?;
                    *g = GpuOpaque::new(ctx, o)?;
                }
                Some(_) => {}
            }
        }
        let Some((lo, hi)) = self.opaque.iter().map(|o| o.bounds).reduce(union) else {
            self.opaque_shadows = None;
            return Ok(());
        };
        if relayout || self.opaque_shadows.is_none() {
            ctx.wait_idle()?;
            self.opaque_shadows = Some(Shadows::new(ctx, &desc.lights, shadow_resolution, 1.0)?);
        }
        if let Some(shadows) = self.opaque_shadows.as_mut() {
            shadows.set_casters(translucent);
            shadows.set_lights((lo + hi) * 0.5, (hi - lo).length() * 0.5, &desc.lights)?;
        }
        Ok(())
    }

    /// The box around every object.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let opaque = self.opaque.iter().map(|o| o.bounds);
        self.objects.iter().map(|o| o.bounds).chain(opaque).reduce(union).unwrap_or((Vec3::ZERO, Vec3::ZERO))
    }
}

/// The box around two boxes.
fn union(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> (Vec3, Vec3) {
    (a.0.min(b.0), a.1.max(b.1))
}

impl GpuObject {
    /// What sources.glsl reads of it.
    pub fn sources(&self) -> crate::passes::Sources<'_> {
        let h = &self.hierarchy;
        crate::passes::Sources {
            object_params: &self.params,
            nodes: &h.nodes,
            points: &h.sorted_points,
            node_flux: &h.node_flux,
            point_flux: &h.sorted_point_flux,
            point_spread: &h.sorted_point_spread,
            sd_table: &self.sd_table,
        }
    }

    fn new(
        ctx: &Context,
        lights: &[Light],
        options: &HierarchyOptions,
        made_from: MadeFrom,
        texture: SurfaceTexture,
        casters: Option<(Vec3, Vec3)>,
        grids_made: &mut u64,
    ) -> Result<GpuObject> {
        let mesh = &made_from.mesh;
        let (vertices, indices, index_count) = upload_mesh(ctx, mesh)?;
        let mut hierarchy = Hierarchy::new(ctx, mesh, lights, options)?;
        if casters.is_some() {
            hierarchy.set_casters(casters);
            hierarchy.set_lights(mesh, lights)?;
        }
        let mut params = Buffer::new(
            ctx,
            "object parameters",
            std::mem::size_of::<ObjectParams>() as u64,
            BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let mut sd_table = Buffer::new(
            ctx,
            "Sd table",
            // A header texel, TABLE_SIZE - 1 pairs, the angular factors, the slab's transmission, the
            // curvature rows and the object's inside (its mesh's, not its material's: one buffer per object).
            ((crate::gpu::sd_table::TABLE_SIZE
                + AngularFactors::TEXELS
                + SlabTransmission::TEXELS
                + CurvatureRatios::TEXELS
                + occupancy::TEXELS)
                * 16) as u64,
            BufferUsageFlags::UNIFORM_TEXEL_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let inside = OnceCell::new();
        let grid = inside_grid(&inside, &made_from, grids_made);
        let (point_spacing, reentry_profile) =
            write_params(&mut params, &mut sd_table, &made_from, grid, options.point_count)?;
        let curvature = curvature_buffer(ctx, &made_from)?;
        Ok(GpuObject {
            hierarchy,
            vertices,
            indices,
            index_count,
            bounds: made_from.mesh.bounds(),
            params,
            sd_table,
            texture,
            curvature,
            point_spacing,
            inside,
            reentry_profile,
            reentry: ReentryBuffers::new(ctx)?,
            made_from,
        })
    }
}

/// Per vertex of an object's mesh, its mean curvature for the Monte Carlo table (smoothed over
/// the material's longest diffusion length, in scene units), zeros for the other models.
fn curvature_buffer(ctx: &Context, from: &MadeFrom) -> Result<Buffer> {
    let n = from.mesh.positions.len().max(1);
    let values = if from.table == TableProfile::MonteCarlo {
        let media = [0, 1, 2].map(|c| from.material.channel(c));
        let radius = curvature_profile::unit_of(&media) as f32 / from.mm_per_unit;
        crate::mesh::curvature::smoothed_mean_curvature(&from.mesh, radius)
    } else {
        vec![0.0; n]
    };
    vk::upload_buffer(ctx, "mean curvature", &values, BufferUsageFlags::STORAGE_BUFFER)
}

/// The vertex and index buffers of `mesh`, and its index count.
fn upload_mesh(ctx: &Context, mesh: &Mesh) -> Result<(Buffer, Buffer, u32)> {
    let index_count = u32::try_from(mesh.indices.len()).map_err(|_| bad_input!("mesh: too many indices"))?;
    let usage = BufferUsageFlags::STORAGE_BUFFER;
    let vertices = vk::upload_buffer(ctx, "vertices", &mesh.vertex_data(), usage | BufferUsageFlags::VERTEX_BUFFER)?;
    let indices = vk::upload_buffer(ctx, "indices", &mesh.indices, usage | BufferUsageFlags::INDEX_BUFFER)?;
    Ok((vertices, indices, index_count))
}

/// The grid of an object's inside where its table is the Monte Carlo one (which reads it), made
/// now if `cell` holds none yet (counted in `made`).
fn inside_grid<'a>(cell: &'a OnceCell<Option<Occupancy>>, from: &MadeFrom, made: &mut u64) -> Option<&'a Occupancy> {
    if from.table != TableProfile::MonteCarlo {
        return None;
    }
    cell.get_or_init(|| {
        *made += 1;
        Occupancy::of(&from.mesh)
    })
    .as_ref()
}

/// Writes an object's parameters and its Sd table from what it is made from and the grid of its
/// inside (`inside_grid`); returns the points' mean spacing in scene units, and where the Monte
/// Carlo table has a grid, what the re-entry needs of its profile (`GpuObject::reentry_profile`).
fn write_params(
    params: &mut Buffer,
    table: &mut Buffer,
    from: &MadeFrom,
    inside: Option<&Occupancy>,
    point_count: u32,
) -> Result<(f32, Option<ReentryProfile>)> {
    let constants = |c: usize| from.material.channel(c).constants(from.diffusion);
    let channels = [0, 1, 2].map(|c| GpuChannel::from(&constants(c)));
    let area_mm2 = from.mesh.surface_area() * from.mm_per_unit * from.mm_per_unit;
    let spacing_mm = (area_mm2 / point_count.max(1) as f32).sqrt();
    let (near_start_mm, near_end_mm, near_scale_mm) = ObjectParams::near_field(spacing_mm, &channels);
    params.write(
        0,
        &[ObjectParams {
            channels,
            mm_per_unit: from.mm_per_unit,
            point_count,
            node_count: point_count - 1,
            spacing_mm,
            near_start_mm,
            near_end_mm,
            near_scale_mm,
            pad: 0.0,
        }],
    )?;
    let mut reentry_profile = None;
    let (sd_table, factors, across, curvature) = match from.table {
        TableProfile::Dipole => (
            SdTable::dipole(&[0, 1, 2].map(constants)),
            AngularFactors::none(),
            SlabTransmission::none(),
            CurvatureRatios::none(),
        ),
        TableProfile::BeamDiffusion => (
            SdTable::beam_diffusion(&[0, 1, 2].map(|c| BeamMedium::new(&from.material.channel(c)))),
            AngularFactors::none(),
            SlabTransmission::none(),
            CurvatureRatios::none(),
        ),
        TableProfile::MonteCarlo => {
            let media = [0, 1, 2].map(|c| from.material.channel(c));
            let (profiles, slabs, curved) = std::thread::scope(|s| {
                let slabs = s.spawn(|| slab_profile::of_channels(&media));
                let curved = s.spawn(|| curvature_profile::of_channels(&media));
                let profiles = McProfile::of_channels(&media);
                let slabs = slabs.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
                (profiles, slabs, curved.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            });
            let sd_table = SdTable::monte_carlo(&profiles, &[0, 1, 2].map(constants));
            if inside.is_some() {
                let reach_mm = (reentry::REACH_SPACINGS * spacing_mm) as f64;
                let mut near = reentry::near_integral(|c, r| profiles[c].sd(r), reach_mm);
                // Single scattering leaves too (the shade pass draws it along the view ray): all
                // of it where it entered, the fraction at normal incidence (0.05-0.07 of what
                // enters Skin1, near all its multiple scattering's in blue).
                for c in 0..3 {
                    near[c] += (profiles[c].single_escape / profiles[c].exit_norm) as f32;
                }
                reentry_profile = Some(ReentryProfile {
                    near,
                    exit_integral: profiles[0].exit_norm as f32,
                    eta: from.material.eta as f32,
                });
            }
            let factors = AngularFactors::monte_carlo(&profiles);
            (sd_table, factors, SlabTransmission::monte_carlo(&slabs), CurvatureRatios::monte_carlo(&curved, &profiles))
        }
    };
    table.write(0, &sd_table.texels())?;
    let factors_at = crate::gpu::sd_table::TABLE_SIZE * 16;
    table.write(factors_at as u64, &factors.texels())?;
    let across_at = factors_at + AngularFactors::TEXELS * 16;
    table.write(across_at as u64, &across.texels())?;
    let curvature_at = across_at + SlabTransmission::TEXELS * 16;
    table.write(curvature_at as u64, &curvature.texels())?;
    // The object's inside, for the Monte Carlo table's pairs (its chord through the medium).
    table.write((curvature_at + CurvatureRatios::TEXELS * 16) as u64, &Occupancy::texels(inside))?;
    Ok((spacing_mm / from.mm_per_unit, reentry_profile))
}
