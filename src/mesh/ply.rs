//! PLY meshes (Stanford's polygon format): ASCII, binary little and big endian. The header and the
//! elements are read by ply-rs-bw, one element at a time, so that every error can name its line
//! (ASCII) or the element's index and byte offset (binary); the sizes the header declares are
//! checked against the bytes that follow before anything is read.
//!
//! Read: `vertex` x y z (any scalar type), optional nx ny nz (all three) and texture coordinates
//! (u v, s t, texture_u texture_v or texture_s texture_t); `face` with a `vertex_indices` or
//! `vertex_index` list (polygons fan-triangulated). Other elements and properties are skipped,
//! `comment` and `obj_info` lines ignored.

use std::io::Cursor;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{ElementDef, Encoding, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType};

use super::{RawMesh, MAX_ELEMENTS};

/// The texture coordinate names accepted, in pairs.
const UV_NAMES: [(&str, &str); 4] = [("u", "v"), ("s", "t"), ("texture_u", "texture_v"), ("texture_s", "texture_t")];
/// The names of the face's index list.
const INDEX_NAMES: [&str; 2] = ["vertex_indices", "vertex_index"];

/// One vertex as read: every scalar property the reader knows (by slot), others ignored.
#[derive(Default)]
struct Vertex {
    /// x y z nx ny nz, then the pairs of [`UV_NAMES`].
    values: [f64; 6 + 2 * UV_NAMES.len()],
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex::default()
    }
    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let slot = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            "nx" => 3,
            "ny" => 4,
            "nz" => 5,
            _ => match UV_NAMES
                .iter()
                .enumerate()
                .find_map(|(i, (u, v))| (name == *u).then_some(6 + 2 * i).or((name == *v).then_some(7 + 2 * i)))
            {
                Some(slot) => slot,
                None => return PropertyAccessResult::Ignored,
            },
        };
        match scalar(&property) {
            Some(v) => {
                self.values[slot] = v;
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::Ignored,
        }
    }
}

/// One face as read: its index list, whatever its integer type.
#[derive(Default)]
struct Face {
    indices: Option<Vec<i64>>,
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Face::default()
    }
    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if !INDEX_NAMES.contains(&name) {
            return PropertyAccessResult::Ignored;
        }
        let list: Vec<i64> = match property {
            Property::ListChar(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUChar(v) => v.into_iter().map(i64::from).collect(),
            Property::ListShort(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUShort(v) => v.into_iter().map(i64::from).collect(),
            Property::ListInt(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUInt(v) => v.into_iter().map(i64::from).collect(),
            _ => return PropertyAccessResult::UnsupportedType,
        };
        self.indices = Some(list);
        PropertyAccessResult::Set
    }
}

/// An element the mesh does not use: read past, values dropped.
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}

fn scalar_size(t: &ScalarType) -> u64 {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// The fewest bytes one element takes in a binary file (lists counted empty).
fn min_binary_size(element: &ElementDef) -> u64 {
    element
        .properties
        .values()
        .map(|p| match &p.data_type {
            PropertyType::Scalar(t) => scalar_size(t),
            PropertyType::List(count, _) => scalar_size(count),
        })
        .sum()
}

/// Where an element is, for messages: its line (ASCII) or its index and byte offset (binary).
enum At {
    Line(usize),
    Binary { index: usize, offset: u64 },
}

impl std::fmt::Display for At {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            At::Line(n) => write!(f, "line {n}"),
            At::Binary { index, offset } => write!(f, "element {index} at byte {offset}"),
        }
    }
}

/// Reads a PLY file's bytes. Messages name the line or element, not the file: the caller adds it.
pub fn read(bytes: &[u8]) -> std::result::Result<RawMesh, String> {
    if !(bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")) {
        return Err("line 1: not a PLY file (it must begin with the line 'ply')".into());
    }
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = Parser::<Skip>::new()
        .read_header(&mut reader)
        .map_err(|e| format!("line {}: malformed PLY header: {}", e.line().unwrap_or(1), one_line(&e.to_string())))?;
    let payload_start = reader.get_ref().position() as usize;
    let header_text = String::from_utf8_lossy(&bytes[..payload_start]);
    let header_lines = header_text.lines().count();
    // The line of each `element` statement, for messages about the header.
    let element_line = |name: &str| {
        header_text
            .lines()
            .position(|l| {
                let mut w = l.split_whitespace();
                w.next() == Some("element") && w.next() == Some(name)
            })
            .map(|i| i + 1)
            .unwrap_or(1)
    };

    let vertex_def = header.elements.get("vertex").ok_or("the header has no 'element vertex'")?;
    let face_def =
        header.elements.get("face").ok_or("the header has no 'element face': no triangles (a point cloud?)")?;
    let scalar_prop = |def: &ElementDef, name: &str| {
        def.properties.get(name).is_some_and(|p| matches!(p.data_type, PropertyType::Scalar(_)))
    };
    for axis in ["x", "y", "z"] {
        if !scalar_prop(vertex_def, axis) {
            return Err(format!(
                "line {}: element vertex has no scalar property '{axis}' (x, y and z are required)",
                element_line("vertex")
            ));
        }
    }
    let has_normals = ["nx", "ny", "nz"].iter().all(|n| scalar_prop(vertex_def, n));
    // The slot of the first pair of texture coordinates the file has.
    let uv =
        UV_NAMES.iter().position(|(u, v)| scalar_prop(vertex_def, u) && scalar_prop(vertex_def, v)).map(|i| 6 + 2 * i);
    let index_prop = INDEX_NAMES.iter().find_map(|n| face_def.properties.get(*n));
    match index_prop.map(|p| &p.data_type) {
        Some(PropertyType::List(_, t)) if !matches!(t, ScalarType::Float | ScalarType::Double) => {}
        Some(_) => {
            return Err(format!("line {}: element face's index list must be a list of integers", element_line("face")))
        }
        None => {
            return Err(format!(
                "line {}: element face has no list property 'vertex_indices' or 'vertex_index'",
                element_line("face")
            ))
        }
    }
    for def in [vertex_def, face_def] {
        if def.count > MAX_ELEMENTS {
            return Err(format!(
                "line {}: the header declares {} '{}' elements: at most {MAX_ELEMENTS} are read",
                element_line(&def.name),
                def.count,
                def.name
            ));
        }
    }

    // Sizes before reading: every declared element must have room in what follows the header.
    let payload = &bytes[payload_start..];
    let ascii = header.encoding == Encoding::Ascii;
    let lines: Vec<&str> = if ascii {
        let text = std::str::from_utf8(payload).map_err(|e| {
            let line = header_lines + 1 + payload[..e.valid_up_to()].iter().filter(|&&b| b == b'\n').count();
            format!(
                "line {line}: an ASCII PLY file must be text (byte {} is not UTF-8)",
                payload_start + e.valid_up_to() + 1
            )
        })?;
        text.lines().collect()
    } else {
        Vec::new()
    };
    let mut room = if ascii { lines.len() as u64 } else { payload.len() as u64 };
    for def in header.elements.values() {
        let need = if ascii { def.count as u64 } else { def.count as u64 * min_binary_size(def) };
        // An element with no properties takes no bytes but would still be counted through.
        if need > room || (!ascii && min_binary_size(def) == 0 && def.count > 0) {
            return Err(format!(
                "line {}: the header declares {} '{}' elements, but {} {} follow the header for them (truncated file or wrong count)",
                element_line(&def.name),
                def.count,
                def.name,
                room,
                if ascii { "lines" } else { "bytes" }
            ));
        }
        room -= need;
    }

    let mut raw = RawMesh {
        positions: Vec::with_capacity(vertex_def.count),
        normals: has_normals.then(|| Vec::with_capacity(vertex_def.count)),
        uvs: uv.map(|_| Vec::with_capacity(vertex_def.count)),
        indices: Vec::new(),
    };
    let mut cursor = Cursor::new(payload);
    let mut line_index = 0usize; // into `lines`
    let vertex_parser = Parser::<Vertex>::new();
    let face_parser = Parser::<Face>::new();
    let skip_parser = Parser::<Skip>::new();
    let mut vertices_read = false;
    // The next element of `def`: (where it is, the line's text or the binary cursor).
    macro_rules! next {
        ($parser:expr, $def:expr, $index:expr) => {{
            if ascii {
                // Blank lines between elements are skipped.
                while lines.get(line_index).is_some_and(|l| l.trim().is_empty()) {
                    line_index += 1;
                }
                let at = At::Line(header_lines + line_index + 1);
                let Some(line) = lines.get(line_index) else {
                    return Err(format!("{at}: the file ends before '{}' element {} (truncated?)", $def.name, $index));
                };
                line_index += 1;
                let element = $parser.read_ascii_element(line, $def).map_err(|e| {
                    let e = e.to_string();
                    let why = if e.contains("Couldn't parse element line") {
                        format!("'{}' are not numbers", one_line(line))
                    } else {
                        one_line(&e)
                    };
                    format!("{at}: '{}' element {}: {why}", $def.name, $index)
                })?;
                (at, element)
            } else {
                let at = At::Binary { index: $index, offset: payload_start as u64 + cursor.position() };
                let element = if header.encoding == Encoding::BinaryBigEndian {
                    $parser.read_big_endian_element(&mut cursor, $def)
                } else {
                    $parser.read_little_endian_element(&mut cursor, $def)
                }
                .map_err(|e| {
                    if e.kind() == std::io::ErrorKind::UnexpectedEof {
                        format!("binary '{}' {at}: the file ends inside it (truncated?)", $def.name)
                    } else {
                        format!("binary '{}' {at}: {}", $def.name, one_line(&e.to_string()))
                    }
                })?;
                (at, element)
            }
        }};
    }
    for def in header.elements.values() {
        match def.name.as_str() {
            "vertex" => {
                for i in 0..def.count {
                    let (at, v) = next!(vertex_parser, def, i);
                    let p = [v.values[0], v.values[1], v.values[2]];
                    if let Some(c) = p.iter().find(|c| !c.is_finite() || c.abs() > f32::MAX as f64) {
                        return Err(format!("{at}: vertex {i} has a coordinate that is not finite in f32: {c}"));
                    }
                    raw.positions.push(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32));
                    if let Some(n) = &mut raw.normals {
                        let v = [v.values[3], v.values[4], v.values[5]].map(|c| c as f32);
                        n.push(Vec3::from(v));
                    }
                    if let (Some(t), Some(slot)) = (&mut raw.uvs, uv) {
                        t.push(Vec2::new(v.values[slot] as f32, v.values[slot + 1] as f32));
                    }
                }
                vertices_read = true;
            }
            "face" => {
                for i in 0..def.count {
                    let (at, f) = next!(face_parser, def, i);
                    let indices = f.indices.unwrap_or_default();
                    if indices.len() < 3 {
                        return Err(format!("{at}: face {i} has {} vertices: a face needs at least 3", indices.len()));
                    }
                    let count = vertex_def.count as i64;
                    if let Some(bad) = indices.iter().find(|&&k| k < 0 || k >= count) {
                        let later = if vertices_read { "" } else { " (faces before the vertices)" };
                        return Err(format!(
                            "{at}: face {i}: vertex index {bad} is out of range ({count} vertices, numbered from 0){later}"
                        ));
                    }
                    if raw.indices.len() / 3 + indices.len() - 2 > MAX_ELEMENTS {
                        return Err(format!("{at}: more than {MAX_ELEMENTS} triangles"));
                    }
                    for k in 1..indices.len() - 1 {
                        raw.indices.extend([indices[0], indices[k], indices[k + 1]].map(|v| v as u32));
                    }
                }
            }
            _ => {
                for i in 0..def.count {
                    next!(skip_parser, def, i);
                }
            }
        }
    }
    if ascii {
        if let Some(extra) = lines[line_index..].iter().position(|l| !l.trim().is_empty()) {
            return Err(format!(
                "line {}: data after the last element the header declares (a wrong count?)",
                header_lines + line_index + extra + 1
            ));
        }
    }
    if face_def.count == 0 {
        return Err("no faces: the file holds no triangles (empty mesh or point cloud)".into());
    }
    Ok(raw)
}

/// ply-rs-bw's messages span lines (`…\n\tString: …`): one line, for `error:`.
fn one_line(s: &str) -> String {
    let s: Vec<&str> = s.split('\n').map(str::trim).filter(|l| !l.is_empty()).collect();
    let joined = s.join("; ");
    if joined.chars().count() > 120 {
        format!("{}…", joined.chars().take(120).collect::<String>())
    } else {
        joined
    }
}
