//! Access tracking and synchronization2 barriers.
//!
//! Each buffer and image remembers its last write and the reads made since ([`TrackedState`]).
//! A pass declares how the next command uses a resource ([`BufferAccess`] for buffers, [`Access`]
//! with a layout for images); the recorder turns that into a [`Barrier`] when one is needed and
//! gathers the barriers of one command into a single `vkCmdPipelineBarrier2`.

use ash::vk;

use super::commands::Recorder;
use super::resources::{aspect_of, Buffer, Image};
use crate::error::Result;
use crate::runtime;

/// How a command uses a buffer: pipeline stage and memory access (buffers have no layout).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BufferAccess {
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
}

/// How a command uses an image: pipeline stage, memory access and layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Access {
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
    pub layout: vk::ImageLayout,
}

const WRITE_ACCESS: vk::AccessFlags2 = vk::AccessFlags2::from_raw(
    vk::AccessFlags2::SHADER_WRITE.as_raw()
        | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw()
        | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE.as_raw()
        | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
        | vk::AccessFlags2::TRANSFER_WRITE.as_raw()
        | vk::AccessFlags2::HOST_WRITE.as_raw()
        | vk::AccessFlags2::MEMORY_WRITE.as_raw(),
);

const STORAGE_READ_WRITE: vk::AccessFlags2 = vk::AccessFlags2::from_raw(
    vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw() | vk::AccessFlags2::SHADER_STORAGE_READ.as_raw(),
);

impl BufferAccess {
    const fn new(stage: vk::PipelineStageFlags2, access: vk::AccessFlags2) -> BufferAccess {
        BufferAccess { stage, access }
    }
    pub const NONE: BufferAccess = BufferAccess::new(vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE);
    pub const COMPUTE_READ: BufferAccess = Access::COMPUTE_READ.memory();
    pub const COMPUTE_WRITE: BufferAccess = Access::COMPUTE_WRITE.memory();
    pub const FRAGMENT_READ: BufferAccess = Access::FRAGMENT_READ.memory();
    pub const FRAGMENT_WRITE: BufferAccess = Access::FRAGMENT_WRITE.memory();
    pub const VERTEX_READ: BufferAccess = Access::VERTEX_READ.memory();
    pub const VERTEX_INPUT: BufferAccess =
        BufferAccess::new(vk::PipelineStageFlags2::VERTEX_ATTRIBUTE_INPUT, vk::AccessFlags2::VERTEX_ATTRIBUTE_READ);
    pub const INDEX_INPUT: BufferAccess =
        BufferAccess::new(vk::PipelineStageFlags2::INDEX_INPUT, vk::AccessFlags2::INDEX_READ);
    pub const INDIRECT: BufferAccess =
        BufferAccess::new(vk::PipelineStageFlags2::DRAW_INDIRECT, vk::AccessFlags2::INDIRECT_COMMAND_READ);
    /// A uniform texel buffer's reads (the stage is set per use).
    pub const TEXEL_READ: BufferAccess =
        BufferAccess::new(vk::PipelineStageFlags2::FRAGMENT_SHADER, vk::AccessFlags2::SHADER_SAMPLED_READ);
    pub const UNIFORM_READ: BufferAccess = BufferAccess::new(
        vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::VERTEX_SHADER.as_raw()
                | vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw()
                | vk::PipelineStageFlags2::COMPUTE_SHADER.as_raw(),
        ),
        vk::AccessFlags2::UNIFORM_READ,
    );
    pub const TRANSFER_READ: BufferAccess = Access::TRANSFER_READ.memory();
    pub const TRANSFER_WRITE: BufferAccess = Access::TRANSFER_WRITE.memory();
    pub const HOST_READ: BufferAccess = BufferAccess::new(vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ);

    pub fn writes(&self) -> bool {
        self.access.intersects(WRITE_ACCESS)
    }
}

impl Access {
    const fn new(stage: vk::PipelineStageFlags2, access: vk::AccessFlags2, layout: vk::ImageLayout) -> Access {
        Access { stage, access, layout }
    }
    pub const NONE: Access =
        Access::new(vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE, vk::ImageLayout::UNDEFINED);
    pub const COMPUTE_READ: Access = Access::new(
        vk::PipelineStageFlags2::COMPUTE_SHADER,
        vk::AccessFlags2::SHADER_STORAGE_READ,
        vk::ImageLayout::GENERAL,
    );
    pub const COMPUTE_WRITE: Access =
        Access::new(vk::PipelineStageFlags2::COMPUTE_SHADER, STORAGE_READ_WRITE, vk::ImageLayout::GENERAL);
    // SHADER_READ rather than sync2's narrower SHADER_SAMPLED_READ: the best-practices layer
    // (1.3.239) expects SHADER_READ with SHADER_READ_ONLY_OPTIMAL and warns otherwise.
    pub const COMPUTE_SAMPLED: Access = Access::new(
        vk::PipelineStageFlags2::COMPUTE_SHADER,
        vk::AccessFlags2::SHADER_READ,
        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    );
    pub const FRAGMENT_READ: Access = Access::new(
        vk::PipelineStageFlags2::FRAGMENT_SHADER,
        vk::AccessFlags2::SHADER_STORAGE_READ,
        vk::ImageLayout::GENERAL,
    );
    pub const FRAGMENT_WRITE: Access =
        Access::new(vk::PipelineStageFlags2::FRAGMENT_SHADER, STORAGE_READ_WRITE, vk::ImageLayout::GENERAL);
    pub const FRAGMENT_SAMPLED: Access = Access::new(
        vk::PipelineStageFlags2::FRAGMENT_SHADER,
        vk::AccessFlags2::SHADER_READ,
        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    );
    pub const VERTEX_READ: Access = Access::new(
        vk::PipelineStageFlags2::VERTEX_SHADER,
        vk::AccessFlags2::SHADER_STORAGE_READ,
        vk::ImageLayout::GENERAL,
    );
    pub const COLOR_ATTACHMENT: Access = Access::new(
        vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
        vk::AccessFlags2::from_raw(
            vk::AccessFlags2::COLOR_ATTACHMENT_WRITE.as_raw() | vk::AccessFlags2::COLOR_ATTACHMENT_READ.as_raw(),
        ),
        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    );
    pub const DEPTH_ATTACHMENT: Access = Access::new(
        vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
        ),
        vk::AccessFlags2::from_raw(
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw(),
        ),
        vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
    );
    /// A depth attachment whose format also has stencil (both aspects in one layout).
    pub const DEPTH_STENCIL_ATTACHMENT: Access = Access::new(
        vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
        ),
        vk::AccessFlags2::from_raw(
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw(),
        ),
        vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
    );
    pub const TRANSFER_READ: Access = Access::new(
        vk::PipelineStageFlags2::TRANSFER,
        vk::AccessFlags2::TRANSFER_READ,
        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
    );
    pub const TRANSFER_WRITE: Access = Access::new(
        vk::PipelineStageFlags2::TRANSFER,
        vk::AccessFlags2::TRANSFER_WRITE,
        vk::ImageLayout::TRANSFER_DST_OPTIMAL,
    );

    // Buffer-only uses, spelled as before (`rec.use_buffer(b, Access::VERTEX_INPUT)`): they are
    // `BufferAccess`es, with no layout.
    pub const VERTEX_INPUT: BufferAccess = BufferAccess::VERTEX_INPUT;
    pub const INDEX_INPUT: BufferAccess = BufferAccess::INDEX_INPUT;
    pub const INDIRECT: BufferAccess = BufferAccess::INDIRECT;
    pub const UNIFORM_READ: BufferAccess = BufferAccess::UNIFORM_READ;
    pub const HOST_READ: BufferAccess = BufferAccess::HOST_READ;

    /// The stage and access, without the layout: the same use of a buffer.
    pub const fn memory(self) -> BufferAccess {
        BufferAccess { stage: self.stage, access: self.access }
    }

    pub fn writes(&self) -> bool {
        self.memory().writes()
    }
}

impl From<Access> for BufferAccess {
    fn from(access: Access) -> BufferAccess {
        access.memory()
    }
}

/// A barrier that orders earlier uses of a resource before the next one (and, for images,
/// changes the layout; buffers leave both layouts `UNDEFINED`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Barrier {
    pub src_stage: vk::PipelineStageFlags2,
    pub src_access: vk::AccessFlags2,
    pub dst_stage: vk::PipelineStageFlags2,
    pub dst_access: vk::AccessFlags2,
    pub old_layout: vk::ImageLayout,
    pub new_layout: vk::ImageLayout,
}

/// What the recorder remembers about a resource between uses: the last write, and the reads that
/// have already been made to see it (so repeated reads need no barrier); for images, the layout.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TrackedState {
    pub last_write: BufferAccess,
    pub reads_since_write: BufferAccess,
    /// Always `UNDEFINED` for buffers.
    pub layout: vk::ImageLayout,
}

impl TrackedState {
    pub(crate) const fn new() -> TrackedState {
        TrackedState {
            last_write: BufferAccess::NONE,
            reads_since_write: BufferAccess::NONE,
            layout: vk::ImageLayout::UNDEFINED,
        }
    }

    /// The barrier needed before a buffer is used as `next`, or `None`; updates the state as if
    /// it was recorded.
    pub(crate) fn buffer_transition(&mut self, next: BufferAccess) -> Option<Barrier> {
        self.transition(next, None)
    }

    /// The barrier (with a layout change if needed) before an image is used as `next`, or `None`.
    pub(crate) fn image_transition(&mut self, next: Access) -> Option<Barrier> {
        self.transition(next.memory(), Some(next.layout))
    }

    fn transition(&mut self, next: BufferAccess, layout: Option<vk::ImageLayout>) -> Option<Barrier> {
        let old_layout = self.layout;
        let new_layout = layout.unwrap_or(old_layout);
        let layout_change = new_layout != old_layout;
        if next.writes() || layout_change {
            // Write-after-read and write-after-write: wait for every earlier access.
            let src_stage = self.last_write.stage | self.reads_since_write.stage;
            let src_access = self.last_write.access & WRITE_ACCESS;
            let first_use = src_stage == vk::PipelineStageFlags2::NONE && old_layout == vk::ImageLayout::UNDEFINED;
            self.last_write = next;
            self.reads_since_write = if next.writes() { BufferAccess::NONE } else { next };
            self.layout = new_layout;
            if first_use && !layout_change {
                return None;
            }
            return Some(Barrier {
                src_stage,
                src_access,
                dst_stage: next.stage,
                dst_access: next.access,
                old_layout,
                new_layout,
            });
        }
        // Read after write: make the write visible to this stage and access once.
        let covered =
            self.reads_since_write.stage.contains(next.stage) && self.reads_since_write.access.contains(next.access);
        if covered || self.last_write.stage == vk::PipelineStageFlags2::NONE {
            self.reads_since_write.stage |= next.stage;
            self.reads_since_write.access |= next.access;
            return None;
        }
        self.reads_since_write.stage |= next.stage;
        self.reads_since_write.access |= next.access;
        Some(Barrier {
            src_stage: self.last_write.stage,
            src_access: self.last_write.access & WRITE_ACCESS,
            dst_stage: next.stage,
            dst_access: next.access,
            old_layout: self.layout,
            new_layout: self.layout,
        })
    }
}

/// The barriers of one command, recorded together in one `vkCmdPipelineBarrier2`.
#[derive(Default)]
pub(crate) struct PendingBarriers {
    buffers: Vec<vk::BufferMemoryBarrier2<'static>>,
    images: Vec<vk::ImageMemoryBarrier2<'static>>,
}

impl PendingBarriers {
    fn is_empty(&self) -> bool {
        self.buffers.is_empty() && self.images.is_empty()
    }

    fn holds_buffer(&self, buffer: vk::Buffer) -> bool {
        self.buffers.iter().any(|b| b.buffer == buffer)
    }

    fn holds_image(&self, image: vk::Image) -> bool {
        self.images.iter().any(|b| b.image == image)
    }

    fn push_buffer(&mut self, buffer: &Buffer, b: Barrier) {
        self.buffers.push(
            vk::BufferMemoryBarrier2::default()
                .src_stage_mask(b.src_stage)
                .src_access_mask(b.src_access)
                .dst_stage_mask(b.dst_stage)
                .dst_access_mask(b.dst_access)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .buffer(buffer.raw)
                .offset(0)
                .size(vk::WHOLE_SIZE),
        );
    }

    fn push_image(&mut self, image: &Image, b: Barrier) {
        self.images.push(
            vk::ImageMemoryBarrier2::default()
                .src_stage_mask(b.src_stage)
                .src_access_mask(b.src_access)
                .dst_stage_mask(b.dst_stage)
                .dst_access_mask(b.dst_access)
                .old_layout(b.old_layout)
                .new_layout(b.new_layout)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image.raw)
                .subresource_range(vk::ImageSubresourceRange {
                    aspect_mask: aspect_of(image.format),
                    base_mip_level: 0,
                    level_count: 1,
                    base_array_layer: 0,
                    layer_count: image.layers,
                }),
        );
    }
}

impl Recorder<'_> {
    /// Declares that the next commands use `buffer` as `access`, recording a barrier if needed.
    pub fn use_buffer(&mut self, buffer: &Buffer, access: impl Into<BufferAccess>) -> Result<()> {
        self.track_buffer(buffer, access.into())?;
        self.flush_barriers();
        Ok(())
    }

    /// Declares that the next commands use `image` as `access` (in `access.layout`).
    pub fn use_image(&mut self, image: &Image, access: Access) -> Result<()> {
        self.track_image(image, access)?;
        self.flush_barriers();
        Ok(())
    }

    /// Makes the image's contents irrelevant: the next use may start from `UNDEFINED`.
    pub fn discard_image(&mut self, image: &Image) {
        let mut state = image.state.get();
        state.layout = vk::ImageLayout::UNDEFINED;
        image.state.set(state);
    }

    fn barrier_check(&self, what: &str) -> Result<()> {
        if self.inside_rendering {
            return Err(runtime!(
                "{what} needs a barrier inside a rendering scope: declare its use before begin_rendering"
            ));
        }
        Ok(())
    }

    /// Like `use_buffer`, but the barrier waits in the pending batch until `flush_barriers`.
    pub(super) fn track_buffer(&mut self, buffer: &Buffer, access: BufferAccess) -> Result<()> {
        let mut state = buffer.state.get();
        let barrier = state.buffer_transition(access);
        buffer.state.set(state);
        if let Some(barrier) = barrier {
            self.barrier_check(&buffer.name)?;
            // A second use of one resource in a batch goes after the first, as if declared alone.
            if self.pending.holds_buffer(buffer.raw) {
                self.flush_barriers();
            }
            self.pending.push_buffer(buffer, barrier);
        }
        Ok(())
    }

    /// Like `use_image`, but the barrier waits in the pending batch until `flush_barriers`.
    pub(super) fn track_image(&mut self, image: &Image, access: Access) -> Result<()> {
        let mut state = image.state.get();
        let barrier = state.image_transition(access);
        image.state.set(state);
        if let Some(barrier) = barrier {
            self.barrier_check(&image.name)?;
            if self.pending.holds_image(image.raw) {
                self.flush_barriers();
            }
            self.pending.push_image(image, barrier);
        }
        Ok(())
    }

    /// Records the pending barriers, if any, as one dependency.
    pub(super) fn flush_barriers(&mut self) {
        if self.pending.is_empty() {
            return;
        }
        let info = vk::DependencyInfo::default()
            .buffer_memory_barriers(&self.pending.buffers)
            .image_memory_barriers(&self.pending.images);
        // SAFETY: recording into our command buffer, outside a rendering scope (barrier_check).
        unsafe { self.ctx.device().cmd_pipeline_barrier2(self.cmd, &info) };
        self.pending.buffers.clear();
        self.pending.images.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buffer_barriers_follow_writes_and_reads() {
        let mut s = TrackedState::new();
        assert_eq!(s.buffer_transition(BufferAccess::TRANSFER_WRITE), None, "first use waits for nothing");
        let raw = s.buffer_transition(BufferAccess::COMPUTE_READ).expect("read after write");
        assert_eq!(
            (raw.src_stage, raw.src_access),
            (vk::PipelineStageFlags2::TRANSFER, vk::AccessFlags2::TRANSFER_WRITE)
        );
        assert_eq!(
            (raw.dst_stage, raw.dst_access),
            (BufferAccess::COMPUTE_READ.stage, BufferAccess::COMPUTE_READ.access)
        );
        assert_eq!((raw.old_layout, raw.new_layout), (vk::ImageLayout::UNDEFINED, vk::ImageLayout::UNDEFINED));
        assert_eq!(s.buffer_transition(BufferAccess::COMPUTE_READ), None, "the write is already visible");
        let war = s.buffer_transition(BufferAccess::COMPUTE_WRITE).expect("write after read");
        assert_eq!(war.src_stage, vk::PipelineStageFlags2::TRANSFER | vk::PipelineStageFlags2::COMPUTE_SHADER);
        assert_eq!(s.layout, vk::ImageLayout::UNDEFINED, "buffers have no layout");
    }

    #[test]
    fn image_layout_changes_need_a_barrier_even_for_reads() {
        let mut s = TrackedState::new();
        let first = s.image_transition(Access::COMPUTE_SAMPLED).expect("layout change");
        assert_eq!((first.old_layout, first.new_layout), (vk::ImageLayout::UNDEFINED, Access::COMPUTE_SAMPLED.layout));
        assert_eq!(first.src_stage, vk::PipelineStageFlags2::NONE);
        assert_eq!(s.image_transition(Access::COMPUTE_SAMPLED), None);
        let to_write = s.image_transition(Access::TRANSFER_WRITE).expect("layout change");
        assert_eq!(to_write.old_layout, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
        assert_eq!(to_write.src_stage, vk::PipelineStageFlags2::COMPUTE_SHADER);
    }
}
