//! Evaluates the BSSRDF for a list of queries in a compute shader through `bssrdf.glsl`, the same
//! code the shading pass uses. Reads: queries. Writes: one Sd per query.

use glam::Vec4;

use crate::error::Result;
use crate::gpu::{BssrdfQueryGpu, EvalConstants, GpuChannel};
use crate::physics::{Diffusion, Model, Query};
use crate::vk::{Bind, Buffer, BufferUsageFlags, Context, MemoryLocation, Pipeline};

const GROUP: usize = 64;

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
        for part in queries.chunks(chunk) {
            let rows: Vec<BssrdfQueryGpu> = part.iter().map(|q| pack(q, diffusion)).collect();
            let mut input = Buffer::new(
                ctx,
                "bssrdf queries",
                (rows.len() * row_bytes) as u64,
                BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::CpuToGpu,
            )?;
            input.write(0, &rows)?;
            let results = Buffer::new(
                ctx,
                "bssrdf results",
                (rows.len() * 4) as u64,
                BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::GpuToCpu,
            )?;
            let constants = EvalConstants { count: rows.len() as u32, model: model.gpu_code() };
            let groups = rows.len().div_ceil(GROUP) as u32;
            ctx.submit(None, |rec| {
                rec.dispatch(
                    &self.pipeline,
                    &[Bind::Read(&input), Bind::Write(&results)],
                    bytemuck::bytes_of(&constants),
                    [groups, 1, 1],
                )?;
                rec.host_read(&results)
            })?;
            out.extend(results.read::<f32>(rows.len())?);
        }
        Ok(out)
    }
}

/// The model depends on xo − xi only: translate to xi = 0 in f64, so that two nearby points far
/// from the origin keep their separation in f32.
fn pack(q: &Query, diffusion: Diffusion) -> BssrdfQueryGpu {
    let v = |d: glam::DVec3| d.as_vec3().extend(0.0);
    BssrdfQueryGpu {
        channel: GpuChannel::from(&q.medium.constants(diffusion)),
        xi: Vec4::ZERO,
        ni: v(q.ni),
        wi: v(q.wi),
        xo: v(q.xo - q.xi),
        no: v(q.no),
    }
}
