//! glTF accessors read from the bytes of their buffer view: every size checked before anything is
//! allocated or read, so that no count, stride or offset a file gives can read out of range,
//! overflow or allocate past [`crate::mesh::MAX_ELEMENTS`] elements. Pure functions on byte
//! slices: `tests/gltf.rs` checks them against a reference decoder with property tests.

use crate::mesh::MAX_ELEMENTS;

/// An accessor's component type (glTF's `componentType`; 5125 `UNSIGNED_INT` is for indices).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Component {
    I8,
    U8,
    I16,
    U16,
    U32,
    F32,
}

impl Component {
    pub const ALL: [Component; 6] =
        [Component::I8, Component::U8, Component::I16, Component::U16, Component::U32, Component::F32];

    /// Bytes per component.
    pub fn size(self) -> usize {
        match self {
            Component::I8 | Component::U8 => 1,
            Component::I16 | Component::U16 => 2,
            Component::U32 | Component::F32 => 4,
        }
    }

    /// glTF's name for it.
    pub fn name(self) -> &'static str {
        match self {
            Component::I8 => "BYTE",
            Component::U8 => "UNSIGNED_BYTE",
            Component::I16 => "SHORT",
            Component::U16 => "UNSIGNED_SHORT",
            Component::U32 => "UNSIGNED_INT",
            Component::F32 => "FLOAT",
        }
    }

    /// Component `k` of the element at byte `at` of `bytes`, as glTF defines its value: floats
    /// and unnormalised integers as they are, normalised integers mapped to [0, 1] (unsigned) or
    /// [−1, 1] (signed: c / (2^(n−1) − 1), the most negative value clamped to −1). The caller has
    /// checked `at + size() ≤ bytes.len()`.
    fn value(self, bytes: &[u8], at: usize, normalized: bool) -> f32 {
        let b = |n: usize| &bytes[at..at + n];
        match self {
            Component::I8 => {
                let c = b(1)[0] as i8 as f32;
                if normalized {
                    (c / 127.0).max(-1.0)
                } else {
                    c
                }
            }
            Component::U8 => {
                let c = b(1)[0] as f32;
                if normalized {
                    c / 255.0
                } else {
                    c
                }
            }
            Component::I16 => {
                let c = i16::from_le_bytes([b(2)[0], b(2)[1]]) as f32;
                if normalized {
                    (c / 32767.0).max(-1.0)
                } else {
                    c
                }
            }
            Component::U16 => {
                let c = u16::from_le_bytes([b(2)[0], b(2)[1]]) as f32;
                if normalized {
                    c / 65535.0
                } else {
                    c
                }
            }
            Component::U32 => u32::from_le_bytes([b(4)[0], b(4)[1], b(4)[2], b(4)[3]]) as f32,
            Component::F32 => f32::from_le_bytes([b(4)[0], b(4)[1], b(4)[2], b(4)[3]]),
        }
    }

    /// An index component as an integer.
    fn index(self, bytes: &[u8], at: usize) -> u32 {
        match self {
            Component::U8 => bytes[at] as u32,
            Component::U16 => u16::from_le_bytes([bytes[at], bytes[at + 1]]) as u32,
            _ => u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]),
        }
    }
}

/// Where an accessor's elements lie in its buffer view.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    pub component: Component,
    /// Components per element: 1 (`SCALAR`) to 4 (`VEC4`).
    pub width: usize,
    pub normalized: bool,
    /// Elements (glTF's `count`).
    pub count: u64,
    /// The accessor's `byteOffset` within the view.
    pub offset: u64,
    /// The view's `byteStride` (`None`: elements packed tightly).
    pub stride: Option<u64>,
}

/// The largest `byteStride` glTF allows.
pub const MAX_STRIDE: u64 = 252;

impl Layout {
    /// Bytes one element takes.
    pub fn element_size(&self) -> u64 {
        (self.component.size() * self.width) as u64
    }

    /// Every check against a view of `view_len` bytes: the count within 1..=2^25, the width, a
    /// normalised flag only on 8- and 16-bit integers, the offset and the stride multiples of the
    /// component size, the stride at least an element and at most 252, and the last element
    /// within the view. Returns the step between elements.
    pub fn check(&self, view_len: u64) -> Result<u64, String> {
        if self.count == 0 || self.count > MAX_ELEMENTS as u64 {
            return Err(format!("count {} must be between 1 and {MAX_ELEMENTS}", self.count));
        }
        if !(1..=4).contains(&self.width) {
            return Err(format!("{} components per element: only SCALAR, VEC2, VEC3 and VEC4 are read", self.width));
        }
        if self.normalized && matches!(self.component, Component::U32 | Component::F32) {
            return Err(format!("normalized {}: only 8- and 16-bit integers may be normalized", self.component.name()));
        }
        let size = self.component.size() as u64;
        if !self.offset.is_multiple_of(size) {
            return Err(format!(
                "byteOffset {} is not a multiple of the component size ({size} bytes, {})",
                self.offset,
                self.component.name()
            ));
        }
        let element = self.element_size();
        let step = match self.stride {
            None => element,
            Some(s) => {
                if s < element || s > MAX_STRIDE || !s.is_multiple_of(size) {
                    return Err(format!(
                        "byteStride {s}: must be at least the element's {element} bytes, at most {MAX_STRIDE}, and a multiple of {size}"
                    ));
                }
                s
            }
        };
        // count ≤ 2^25 and step ≤ 252: no overflow in u64; the offset is checked too.
        let end = (self.count - 1)
            .checked_mul(step)
            .and_then(|v| v.checked_add(element))
            .and_then(|v| v.checked_add(self.offset));
        match end {
            Some(end) if end <= view_len => Ok(step),
            _ => Err(format!(
                "{} elements of {element} bytes every {step} bytes from byte {} need {} bytes; the buffer view has {view_len}",
                self.count,
                self.offset,
                end.map(|e| e.to_string()).unwrap_or_else(|| "more than 2^64".into())
            )),
        }
    }
}

/// Every component of every element (`count × width` values, element after element), decoded as
/// [`Component`]'s values are; `view` is the buffer view's bytes.
pub fn read_floats(view: &[u8], layout: &Layout) -> Result<Vec<f32>, String> {
    let step = layout.check(view.len() as u64)? as usize;
    let (size, offset) = (layout.component.size(), layout.offset as usize);
    let mut out = Vec::with_capacity(layout.count as usize * layout.width);
    for e in 0..layout.count as usize {
        let at = offset + e * step;
        for k in 0..layout.width {
            out.push(layout.component.value(view, at + k * size, layout.normalized));
        }
    }
    Ok(out)
}

/// An index accessor: `SCALAR` of `UNSIGNED_BYTE`, `UNSIGNED_SHORT` or `UNSIGNED_INT`, not
/// normalised.
pub fn read_indices(view: &[u8], layout: &Layout) -> Result<Vec<u32>, String> {
    if !matches!(layout.component, Component::U8 | Component::U16 | Component::U32) || layout.width != 1 {
        return Err(format!(
            "indices must be SCALAR UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT ({} components of {} given)",
            layout.width,
            layout.component.name()
        ));
    }
    if layout.normalized {
        return Err("indices must not be normalized".into());
    }
    let step = layout.check(view.len() as u64)? as usize;
    let offset = layout.offset as usize;
    Ok((0..layout.count as usize).map(|e| layout.component.index(view, offset + e * step)).collect())
}
