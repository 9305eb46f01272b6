//! Morton codes and a stable GPU radix sort of (key, point index), then the points gathered in
//! Morton order with their light records. Reads: points, point light records. Writes: keys,
//! order, sorted points and light records.

use glam::Vec3;

use crate::error::Result;
use crate::gpu::{MortonConstants, RadixConstants, RADIX_TILE as TILE};
use crate::vk::{Bind, Buffer, Context, Pipeline, Recorder};

pub struct SortBuffers<'a> {
    pub points: &'a Buffer,
    pub keys: [&'a Buffer; 2],
    pub values: [&'a Buffer; 2],
    pub counts: &'a Buffer,
    pub sorted_points: &'a Buffer,
    /// Each light's own record of each point, for brute force only (`per_light_count` 0 else).
    pub point_lights: &'a Buffer,
    pub sorted_point_lights: &'a Buffer,
    pub per_light_count: u32,
    /// Every light's merged record of each point.
    pub point_flux: &'a Buffer,
    pub sorted_point_flux: &'a Buffer,
    /// How the lights' directions spread at each point.
    pub point_spread: &'a Buffer,
    pub sorted_point_spread: &'a Buffer,
}

pub struct SortPass {
    morton: Pipeline,
    histogram: Pipeline,
    scan: Pipeline,
    scatter: Pipeline,
    gather: Pipeline,
}

impl SortPass {
    pub fn new(ctx: &Context) -> Result<SortPass> {
        Ok(SortPass {
            morton: Pipeline::compute(ctx, "hierarchy/morton.comp")?,
            histogram: Pipeline::compute(ctx, "hierarchy/radix_histogram.comp")?,
            scan: Pipeline::compute(ctx, "hierarchy/radix_scan.comp")?,
            scatter: Pipeline::compute(ctx, "hierarchy/radix_scatter.comp")?,
            gather: Pipeline::compute(ctx, "hierarchy/gather_points.comp")?,
        })
    }

    /// Morton codes in `bounds`: recorded in its own timestamp scope.
    pub fn record_morton(&self, rec: &mut Recorder, b: &SortBuffers, n: u32, bounds: (Vec3, Vec3)) -> Result<()> {
        let constants = MortonConstants {
            bounds_min: bounds.0.extend(0.0),
            bounds_extent: (bounds.1 - bounds.0).extend(0.0),
            point_count: n,
            pad: [0; 3],
        };
        rec.dispatch(
            &self.morton,
            &[Bind::Read(b.points), Bind::Write(b.keys[0]), Bind::Write(b.values[0])],
            bytemuck::bytes_of(&constants),
            [n.div_ceil(64), 1, 1],
        )
    }

    /// Eight 8-bit LSD passes over the 64-bit keys (ping-pong, ending in `keys[0]`/`values[0]`),
    /// then the gather of the points into Morton order.
    pub fn record_sort(&self, rec: &mut Recorder, b: &SortBuffers, n: u32) -> Result<()> {
        let tile_count = n.div_ceil(TILE);
        for pass in 0..8u32 {
            let (src, dst) = ((pass % 2) as usize, ((pass + 1) % 2) as usize);
            let constants = RadixConstants { count: n, tile_count, shift: pass * 8 };
            let push = bytemuck::bytes_of(&constants);
            let groups = [tile_count.div_ceil(64), 1, 1];
            rec.dispatch(&self.histogram, &[Bind::Read(b.keys[src]), Bind::Write(b.counts)], push, groups)?;
            rec.dispatch(&self.scan, &[Bind::Write(b.counts)], push, [1, 1, 1])?;
            rec.dispatch(
                &self.scatter,
                &[
                    Bind::Read(b.keys[src]),
                    Bind::Read(b.values[src]),
                    Bind::Write(b.keys[dst]),
                    Bind::Write(b.values[dst]),
                    Bind::Write(b.counts),
                ],
                push,
                groups,
            )?;
        }
        rec.dispatch(
            &self.gather,
            &[
                Bind::Read(b.points),
                Bind::Read(b.values[0]),
                Bind::Write(b.sorted_points),
                Bind::Read(b.point_lights),
                Bind::Write(b.sorted_point_lights),
                Bind::Read(b.point_flux),
                Bind::Write(b.sorted_point_flux),
                Bind::Read(b.point_spread),
                Bind::Write(b.sorted_point_spread),
            ],
            bytemuck::bytes_of(&[n, b.per_light_count]),
            [n.div_ceil(64), 1, 1],
        )
    }
}
