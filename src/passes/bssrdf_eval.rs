//! Evaluates the BSSRDF for a list of queries in a compute shader through `bssrdf.glsl`, the same
//! code the shading pass uses. Reads: queries, and for photon beam diffusion one Sd table per
//! distinct medium (made on the CPU as the renderer makes an object's). Writes: one Sd per query.

use std::collections::HashMap;

use glam::{Vec3, Vec4};

use crate::error::Result;
use crate::gpu::sd_table::TABLE_SIZE;
use crate::gpu::{BssrdfQueryGpu, EvalConstants, GpuChannel, SdTable, EVAL_JOINED_INSIDE};
use crate::mesh::occupancy::Occupancy;
use crate::physics::beam_diffusion::BeamMedium;
use crate::physics::{Diffusion, Medium, Model, Query};
use crate::vk::{Bind, Buffer, BufferUsageFlags, Context, MemoryLocation, Pipeline};

const GROUP: usize = 64;

/// Photon beam diffusion's tables in one dispatch at most (64 KiB each): 64 MiB. Each costs tens
/// of milliseconds on the CPU, so rows of many distinct media are slow, not large.
const MAX_TABLES: usize = 1024;

pub struct BssrdfEvalPass {
    pipeline: Pipeline,
}

impl BssrdfEvalPass {
    pub fn new(ctx: &Context) -> Result<BssrdfEvalPass> {
        let pipeline = Pipeline::compute(ctx, "bssrdf_eval.comp")?;
        Ok(BssrdfEvalPass { pipeline })
    }

    /// Sd for every query (f32), in order. Large inputs go in chunks that fit the device's
    /// storage-buffer range and dispatch limits.
    pub fn evaluate(&self, ctx: &Context, queries: &[Query], model: Model, diffusion: Diffusion) -> Result<Vec<f32>> {
        let row_bytes = std::mem::size_of::<BssrdfQueryGpu>();
        let by_range = ctx.limits().max_storage_buffer_range as usize / row_bytes;
        let by_groups = ctx.limits().max_compute_work_group_count[0] as usize * GROUP;
        let chunk = by_range.min(by_groups).clamp(GROUP, 1 << 20);
        let mut out = Vec::with_capacity(queries.len());
        let max_tables = MAX_TABLES.min(ctx.limits().max_texel_buffer_elements as usize / TABLE_SIZE).max(1);
        for part in queries.chunks(chunk) {
            if !matches!(model, Model::Pbd | Model::Mc) {
                let placeholder = texel_buffer(ctx, &[[0u32; 4]])?;
                out.extend(self.dispatch(ctx, part, &vec![0; part.len()], &placeholder, model, diffusion)?);
                continue;
            }
            // Rows in runs of at most `max_tables` distinct media, each run with its tables.
            let mut start = 0;
            while start < part.len() {
                let mut index: HashMap<[u64; 4], u32> = HashMap::new();
                let mut media: Vec<Medium> = Vec::new();
                let mut rows_table = Vec::new();
                for q in &part[start..] {
                    let m = q.medium;
                    let key = [m.sigma_a, m.sigma_s, m.g, m.eta].map(f64::to_bits);
                    let table = match index.get(&key) {
                        Some(&t) => t,
                        None if media.len() == max_tables => break,
                        None => {
                            media.push(m);
                            index.insert(key, media.len() as u32 - 1);
                            media.len() as u32 - 1
                        }
                    };
                    rows_table.push(table);
                }
                let table_of = |m: &Medium| match model {
                    Model::Mc => SdTable::monte_carlo_one(m),
                    _ => SdTable::beam_diffusion_one(&BeamMedium::new(m)),
                };
                let texels: Vec<[u32; 4]> = media.iter().flat_map(|m| table_of(m).texels()).collect();
                let tables = texel_buffer(ctx, &texels)?;
                let end = start + rows_table.len();
                out.extend(self.dispatch(ctx, &part[start..end], &rows_table, &tables, model, diffusion)?);
                start = end;
            }
        }
        Ok(out)
    }

    /// One dispatch: Sd for `rows`, row i reading table `tables_of[i]` of `tables`.
    /// Whether each pair (xi, ni, xo, no) is joined inside the object of `grid`, as the shade pass
    /// decides it (bssrdf.glsl `joined_inside`; the GPU's mirror of
    /// [`crate::mesh::occupancy::joined_inside`]).
    pub fn joined_inside(&self, ctx: &Context, grid: &Occupancy, pairs: &[[Vec3; 4]]) -> Result<Vec<bool>> {
        let tables = texel_buffer(ctx, &Occupancy::texels(Some(grid)))?;
        let mut out = Vec::with_capacity(pairs.len());
        for part in pairs.chunks(1 << 16) {
            let packed: Vec<BssrdfQueryGpu> = part
                .iter()
                .map(|&[xi, ni, xo, no]| BssrdfQueryGpu {
                    channel: bytemuck::Zeroable::zeroed(),
                    xi: xi.extend(0.0),
                    ni: ni.extend(0.0),
                    wi: Vec4::ZERO,
                    xo: xo.extend(0.0),
                    no: no.extend(0.0),
                    table: [0; 4],
                })
                .collect();
            out.extend(self.dispatch_packed(ctx, &packed, &tables, EVAL_JOINED_INSIDE)?.iter().map(|&v| v != 0.0));
        }
        Ok(out)
    }

    fn dispatch(
        &self,
        ctx: &Context,
        rows: &[Query],
        tables_of: &[u32],
        tables: &Buffer,
        model: Model,
        diffusion: Diffusion,
    ) -> Result<Vec<f32>> {
        let packed: Vec<BssrdfQueryGpu> = rows.iter().zip(tables_of).map(|(q, &t)| pack(q, diffusion, t)).collect();
        self.dispatch_packed(ctx, &packed, tables, model.gpu_code())
    }

    fn dispatch_packed(
        &self,
        ctx: &Context,
        packed: &[BssrdfQueryGpu],
        tables: &Buffer,
        model: u32,
    ) -> Result<Vec<f32>> {
        let mut input = Buffer::new(
            ctx,
            "bssrdf queries",
            std::mem::size_of_val(packed) as u64,
            BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        input.write(0, packed)?;
        let results = Buffer::new(
            ctx,
            "bssrdf results",
            (packed.len() * 4) as u64,
            BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        let constants = EvalConstants { count: packed.len() as u32, model };
        let groups = packed.len().div_ceil(GROUP) as u32;
        ctx.submit(None, |rec| {
            rec.dispatch(
                &self.pipeline,
                &[Bind::Read(&input), Bind::Write(&results), Bind::Texels(tables)],
                bytemuck::bytes_of(&constants),
                [groups, 1, 1],
            )?;
            rec.host_read(&results)
        })?;
        results.read::<f32>(packed.len())
    }
}

/// A texel buffer (RGBA32UI) holding `texels`.
fn texel_buffer(ctx: &Context, texels: &[[u32; 4]]) -> Result<Buffer> {
    let mut buffer = Buffer::new(
        ctx,
        "Sd tables",
        std::mem::size_of_val(texels) as u64,
        BufferUsageFlags::UNIFORM_TEXEL_BUFFER,
        MemoryLocation::CpuToGpu,
    )?;
    buffer.write(0, texels)?;
    Ok(buffer)
}

/// The model depends on xo − xi only: translate to xi = 0 in f64, so that two nearby points far
/// from the origin keep their separation in f32.
fn pack(q: &Query, diffusion: Diffusion, table: u32) -> BssrdfQueryGpu {
    let v = |d: glam::DVec3| d.as_vec3().extend(0.0);
    BssrdfQueryGpu {
        channel: GpuChannel::from(&q.medium.constants(diffusion)),
        xi: Vec4::ZERO,
        ni: v(q.ni),
        wi: v(q.wi),
        xo: v(q.xo - q.xi),
        no: v(q.no),
        table: [table, 0, 0, 0],
    }
}
