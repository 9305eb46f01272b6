//! GPU timestamp scopes: `vkCmdWriteTimestamp2` around each pass, converted to nanoseconds with
//! `timestampPeriod` and masked by the queue's `timestampValidBits`.

use std::sync::Arc;

use ash::vk;

use super::context::{Context, Shared};
use crate::error::Result;
use crate::runtime;

/// One resolved scope, in nanoseconds on the GPU's clock.
#[derive(Clone, Debug)]
pub struct TimedScope {
    pub name: String,
    pub begin_ns: f64,
    pub end_ns: f64,
}

pub struct GpuProfiler {
    shared: Arc<Shared>,
    pool: vk::QueryPool,
    capacity: u32,
    period_ns: f64,
    valid_mask: u64,
    /// Scopes opened in the current submission: name, begin query, end query (set on close).
    scopes: Vec<(String, u32, Option<u32>)>,
    next_query: u32,
    /// Scopes of the last resolved submission.
    resolved: Vec<TimedScope>,
}

impl GpuProfiler {
    /// `None` when the device cannot write timestamps on its queue.
    pub fn new(ctx: &Context, max_scopes: u32) -> Result<Option<GpuProfiler>> {
        if ctx.timestamp_valid_bits == 0 || ctx.limits().timestamp_period <= 0.0 {
            return Ok(None);
        }
        let capacity = max_scopes * 2;
        let info = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(capacity);
        // SAFETY: valid device.
        let pool =
            unsafe { ctx.device().create_query_pool(&info, None) }.map_err(|e| runtime!("vkCreateQueryPool: {e}"))?;
        let bits = ctx.timestamp_valid_bits;
        Ok(Some(GpuProfiler {
            shared: ctx.shared.clone(),
            pool,
            capacity,
            period_ns: ctx.limits().timestamp_period as f64,
            valid_mask: if bits >= 64 { u64::MAX } else { (1u64 << bits) - 1 },
            scopes: Vec::new(),
            next_query: 0,
            resolved: Vec::new(),
        }))
    }

    /// Starts a frame, which may span several submissions: resets the queries on the host
    /// (Vulkan 1.2 hostQueryReset) and forgets the last frame's scopes.
    pub fn begin_frame(&mut self) {
        // SAFETY: no submission using the pool is pending (every submit waits on its fence).
        unsafe { self.shared.device.reset_query_pool(self.pool, 0, self.capacity) };
        self.scopes.clear();
        self.next_query = 0;
        self.resolved.clear();
    }

    /// Reserves the begin query of a new scope; `None` (the scope is skipped) when full.
    pub(crate) fn open(&mut self, name: &str) -> Option<(vk::QueryPool, u32, usize)> {
        if self.next_query + 2 > self.capacity {
            log::warn!("profiler: more than {} scopes in one submission; '{name}' is not timed", self.capacity / 2);
            return None;
        }
        let q = self.next_query;
        self.next_query += 1;
        self.scopes.push((name.to_string(), q, None));
        Some((self.pool, q, self.scopes.len() - 1))
    }

    pub(crate) fn close(&mut self, index: usize) -> (vk::QueryPool, u32) {
        let q = self.next_query;
        self.next_query += 1;
        self.scopes[index].2 = Some(q);
        (self.pool, q)
    }

    /// Reads the timestamps written so far in this frame (after a submission has finished).
    pub(crate) fn resolve(&mut self) -> Result<()> {
        self.resolved.clear();
        if self.next_query == 0 {
            return Ok(());
        }
        let mut ticks = vec![0u64; self.next_query as usize];
        // SAFETY: the submission that wrote these queries has completed (fence waited).
        unsafe {
            self.shared.device.get_query_pool_results(
                self.pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .map_err(|e| runtime!("vkGetQueryPoolResults: {e}"))?;
        let origin = ticks[0];
        for (name, begin, end) in &self.scopes {
            let Some(end) = end else { continue };
            // Differences under the valid-bit mask survive a counter wrap between the two writes.
            let b = ticks[*begin as usize].wrapping_sub(origin) & self.valid_mask;
            let e = ticks[*end as usize].wrapping_sub(origin) & self.valid_mask;
            self.resolved.push(TimedScope {
                name: name.clone(),
                begin_ns: b as f64 * self.period_ns,
                end_ns: e.max(b) as f64 * self.period_ns,
            });
        }
        Ok(())
    }

    /// The frame's scopes, in the order they were opened, relative to its first timestamp.
    pub fn take_scopes(&mut self) -> Vec<TimedScope> {
        std::mem::take(&mut self.resolved)
    }
}

impl Drop for GpuProfiler {
    fn drop(&mut self) {
        unsafe { self.shared.device.destroy_query_pool(self.pool, None) };
    }
}
