//! OFF meshes (Geomview's Object File Format, the format of CGAL's sample meshes): a keyword line
//! (`OFF`, or with the prefixes `ST` texture coordinates, `C` colours, `N` normals: `NOFF`,
//! `CNOFF`, `STOFF`, …), the counts `vertices faces edges`, one vertex per line (x y z, then the
//! prefixes' values), one face per line (`n i0 … i(n-1)`, then an optional colour). `#` starts a
//! comment; blank lines are skipped. Polygons are fan-triangulated. Written by hand: the format
//! is a page long, and no maintained crate reads it with line numbers.

use glam::{Vec2, Vec3};

use super::{RawMesh, MAX_ELEMENTS};

/// The lines that hold data, with their numbers (1-based): comments cut, blank lines skipped.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines().enumerate().filter_map(|(i, l)| {
        let l = l.split('#').next().unwrap_or("").trim();
        (!l.is_empty()).then_some((i + 1, l))
    })
}

/// Reads OFF text. Messages name the line, not the file: the caller adds it.
pub fn read(bytes: &[u8]) -> std::result::Result<RawMesh, String> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| format!("not an OFF file (not UTF-8 text: byte {} is invalid)", e.valid_up_to() + 1))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = data_lines(text);
    let (at, first) = lines.next().ok_or("an empty file: an OFF file begins with the line 'OFF'")?;
    let mut words = first.split_whitespace();
    let keyword = words.next().unwrap_or("");
    let Some(prefix) = keyword.strip_suffix("OFF") else {
        return Err(format!("line {at}: not an OFF file (it must begin with 'OFF', not '{}')", truncate(keyword)));
    };
    let (mut texcoords, mut colours, mut normals) = (false, false, false);
    let mut rest = prefix;
    for (flag, name) in [(&mut texcoords, "ST"), (&mut colours, "C"), (&mut normals, "N")] {
        if let Some(r) = rest.strip_prefix(name) {
            *flag = true;
            rest = r;
        }
    }
    if !rest.is_empty() {
        return Err(format!(
            "line {at}: '{keyword}' is not supported: the keyword is OFF with the prefixes ST, C, N (4OFF and nOFF, other dimensions, are not)"
        ));
    }
    // The counts may follow the keyword on its line.
    let after: Vec<&str> = words.collect();
    let (at, counts) = if after.is_empty() {
        let (at, line) =
            lines.next().ok_or(format!("line {at}: the file ends before the counts 'vertices faces edges'"))?;
        (at, line.split_whitespace().collect::<Vec<_>>())
    } else {
        (at, after)
    };
    if counts.len() < 2 {
        return Err(format!(
            "line {at}: expected the counts 'vertices faces edges', found '{}'",
            truncate(&counts.join(" "))
        ));
    }
    let count = |s: &str, what: &str| -> std::result::Result<usize, String> {
        let n: usize =
            s.parse().map_err(|_| format!("line {at}: the {what} count '{}' is not a whole number", truncate(s)))?;
        if n > MAX_ELEMENTS {
            return Err(format!("line {at}: {n} {what}: at most {MAX_ELEMENTS} are read"));
        }
        Ok(n)
    };
    let vertex_count = count(counts[0], "vertex")?;
    let face_count = count(counts[1], "face")?;
    // Every element is a line of its own: a count larger than the lines left is refused before
    // anything is allocated.
    let lines_left = text.lines().count() as u64;
    if (vertex_count + face_count) as u64 > lines_left {
        return Err(format!(
            "line {at}: {vertex_count} vertices and {face_count} faces declared, but the file has {lines_left} lines (truncated file or wrong count)"
        ));
    }

    let counts_at = at;
    let last_line = text.lines().count();
    let ends = |i: usize, what: &str, n: usize| {
        format!("line {last_line}: the file ends after {i} of the {n} {what} declared on line {counts_at} (truncated?)")
    };
    let mut raw = RawMesh {
        positions: Vec::with_capacity(vertex_count),
        normals: normals.then(|| Vec::with_capacity(vertex_count)),
        uvs: texcoords.then(|| Vec::with_capacity(vertex_count)),
        indices: Vec::new(),
    };
    let number = |at: usize, s: &str| -> std::result::Result<f32, String> {
        let v: f32 = s.parse().map_err(|_| format!("line {at}: '{}' is not a number", truncate(s)))?;
        if !v.is_finite() {
            return Err(format!("line {at}: '{}' is not finite", truncate(s)));
        }
        Ok(v)
    };
    for i in 0..vertex_count {
        let (at, line) = lines.next().ok_or_else(|| ends(i, "vertices", vertex_count))?;
        let w: Vec<&str> = line.split_whitespace().collect();
        // x y z [nx ny nz] [r g b [a]] [s t]: the normals follow the position.
        let need = 3 + if normals { 3 } else { 0 };
        if w.len() < need {
            return Err(format!(
                "line {at}: vertex {i} needs {need} numbers ({}), found {}",
                if normals { "x y z nx ny nz" } else { "x y z" },
                w.len()
            ));
        }
        let p = Vec3::new(number(at, w[0])?, number(at, w[1])?, number(at, w[2])?);
        raw.positions.push(p);
        if let Some(n) = &mut raw.normals {
            n.push(Vec3::new(number(at, w[3])?, number(at, w[4])?, number(at, w[5])?));
        }
        if let Some(t) = &mut raw.uvs {
            // The texture coordinates are the last two values, after any colour.
            if w.len() < need + 2 {
                return Err(format!("line {at}: vertex {i} of an STOFF file needs texture coordinates s t at its end"));
            }
            t.push(Vec2::new(number(at, w[w.len() - 2])?, number(at, w[w.len() - 1])?));
        }
        let _ = colours; // colours sit between and are skipped.
    }
    for i in 0..face_count {
        let (at, line) = lines.next().ok_or_else(|| ends(i, "faces", face_count))?;
        let mut w = line.split_whitespace();
        let n: usize = w
            .next()
            .and_then(|s| s.parse().ok())
            .ok_or(format!("line {at}: face {i} must begin with its vertex count"))?;
        if n < 3 {
            return Err(format!("line {at}: face {i} has {n} vertices: a face needs at least 3"));
        }
        let mut face = Vec::with_capacity(n.min(line.len()));
        for k in 0..n {
            let s = w.next().ok_or(format!("line {at}: face {i} declares {n} vertices but lists {k}"))?;
            let v: i64 =
                s.parse().map_err(|_| format!("line {at}: face {i}: '{}' is not a vertex index", truncate(s)))?;
            if v < 0 || v as u64 >= vertex_count as u64 {
                return Err(format!(
                    "line {at}: face {i}: vertex index {v} is out of range ({vertex_count} vertices, numbered from 0)"
                ));
            }
            face.push(v as u32);
        }
        // What follows is an optional colour (ignored).
        if raw.indices.len() / 3 + n - 2 > MAX_ELEMENTS {
            return Err(format!("line {at}: more than {MAX_ELEMENTS} triangles"));
        }
        for k in 1..n - 1 {
            raw.indices.extend([face[0], face[k], face[k + 1]]);
        }
    }
    if face_count == 0 {
        return Err("no faces: the file holds no triangles (empty mesh or point cloud)".into());
    }
    Ok(raw)
}

fn truncate(s: &str) -> String {
    if s.chars().count() > 40 {
        format!("{}…", s.chars().take(40).collect::<String>())
    } else {
        s.to_string()
    }
}
