//! The `translucent bssrdf` contract: CSV rows of one channel each, on stdin, with exactly the
//! header below (mm⁻¹ and mm, normals outward, wi toward the light); out go the same columns plus
//! `sd`. Extra trailing columns are accepted and ignored (so the reference file, which carries
//! `sd,sd_dipole`, can be piped in as it is).

use std::io::{BufRead, Read, Write};

use glam::DVec3;

use crate::bad_input;
use crate::error::Result;
use crate::physics::{Medium, Query};
use crate::runtime;

pub const COLUMNS: [&str; 19] = [
    "sigma_a", "sigma_s", "g", "eta", "xi_x", "xi_y", "xi_z", "ni_x", "ni_y", "ni_z", "wi_x", "wi_y", "wi_z", "xo_x",
    "xo_y", "xo_z", "no_x", "no_y", "no_z",
];

/// The longest line read (bytes): a row of 19 numbers needs a few hundred; this bounds memory on
/// input with no line ends.
pub const MAX_LINE_BYTES: usize = 1 << 16;

/// Rows per batch when streaming: memory stays bounded whatever the input's length, and output
/// starts after the first batch.
pub const BATCH_ROWS: usize = 1 << 16;

/// Reads the CSV in batches: the header first, then rows on demand. Errors name the line.
pub struct Reader<R: BufRead> {
    input: R,
    line_number: usize,
    buffer: Vec<u8>,
    header_done: bool,
}

impl<R: BufRead> Reader<R> {
    pub fn new(input: R) -> Reader<R> {
        Reader { input, line_number: 0, buffer: Vec::new(), header_done: false }
    }

    /// The next line without its line end, or `None` at the end of the input.
    fn next_line(&mut self) -> Result<Option<&str>> {
        self.buffer.clear();
        self.line_number += 1;
        let at = self.line_number;
        let limit = (MAX_LINE_BYTES + 1) as u64;
        let read = (&mut self.input)
            .take(limit)
            .read_until(b'\n', &mut self.buffer)
            .map_err(|e| runtime!("stdin line {at}: {e}"))?;
        if read == 0 {
            return Ok(None);
        }
        if self.buffer.len() > MAX_LINE_BYTES && self.buffer.last() != Some(&b'\n') {
            if self.buffer.contains(&b'\r') {
                return Err(bad_input!(
                    "bssrdf: line {at}: no LF line end but carriage returns: CR-only (classic Mac) line endings \
                     are not supported; use LF or CRLF"
                ));
            }
            return Err(bad_input!("bssrdf: line {at}: longer than {MAX_LINE_BYTES} bytes (not this CSV?)"));
        }
        let mut bytes = self.buffer.as_slice();
        if at == 1 {
            bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes); // a UTF-8 byte-order mark
        }
        let bytes = bytes.strip_suffix(b"\n").unwrap_or(bytes);
        let bytes = bytes.strip_suffix(b"\r").unwrap_or(bytes);
        let text = std::str::from_utf8(bytes).map_err(|e| {
            bad_input!("bssrdf: line {at}: not UTF-8 text (byte {} of the line is invalid)", e.valid_up_to() + 1)
        })?;
        if text.contains('\r') {
            return Err(bad_input!(
                "bssrdf: line {at}: a carriage return inside the line: CR-only (classic Mac) line endings are not \
                 supported; use LF or CRLF"
            ));
        }
        Ok(Some(text))
    }

    fn header(&mut self) -> Result<()> {
        if self.header_done {
            return Ok(());
        }
        let Some(header) = self.next_line()? else {
            return Err(bad_input!("bssrdf: empty input; expected the header {}", COLUMNS.join(",")));
        };
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        if names.len() < COLUMNS.len() || names[..COLUMNS.len()] != COLUMNS {
            return Err(bad_input!("bssrdf: line 1: the header must start with exactly {}", COLUMNS.join(",")));
        }
        self.header_done = true;
        Ok(())
    }

    /// Up to `max` rows, with their line numbers; empty at the end of the input. The header is
    /// checked on the first call.
    pub fn next_batch(&mut self, max: usize) -> Result<Vec<(usize, Query)>> {
        self.header()?;
        let mut queries = Vec::new();
        while queries.len() < max {
            let at = self.line_number + 1;
            let Some(line) = self.next_line()? else { break };
            if line.trim().is_empty() {
                continue;
            }
            queries.push((at, parse_row(line, at)?));
        }
        Ok(queries)
    }
}

/// Parses all the rows at once; a bad row is an error naming its line number, the column and the
/// reason. (The command itself streams through [`Reader`].)
pub fn parse(input: impl BufRead) -> Result<Vec<Query>> {
    let mut reader = Reader::new(input);
    let mut queries = Vec::new();
    loop {
        let batch = reader.next_batch(BATCH_ROWS)?;
        if batch.is_empty() {
            return Ok(queries);
        }
        queries.extend(batch.into_iter().map(|(_, q)| q));
    }
}

fn parse_row(line: &str, line_number: usize) -> Result<Query> {
    let mut values = [0f64; 19];
    let mut fields = line.split(',');
    for (column, slot) in COLUMNS.iter().zip(values.iter_mut()) {
        let field = fields.next().ok_or_else(|| {
            bad_input!("bssrdf: line {line_number}: missing column {column} (a row needs {} values)", COLUMNS.len())
        })?;
        let v: f64 = field
            .trim()
            .parse()
            .map_err(|_| bad_input!("bssrdf: line {line_number}, column {column}: '{field}' is not a number"))?;
        if !v.is_finite() {
            return Err(bad_input!("bssrdf: line {line_number}, column {column}: {v} is not finite"));
        }
        *slot = v;
    }
    to_query(&values).map_err(|why| bad_input!("bssrdf: line {line_number}, {why}"))
}

/// The largest position coordinate (mm): distances squared stay finite in f64.
pub const MAX_COORDINATE_MM: f64 = 1e100;

/// The largest σt = σa + σs (1/mm) that `--gpu` accepts: Sd grows about as σt², and past this
/// it (or its intermediate terms) would leave f32's range.
pub const GPU_MAX_SIGMA_T: f64 = 1e6;

/// Whether a row can be evaluated in f32 on the GPU; the reason when it cannot.
pub fn gpu_range_check(q: &Query) -> std::result::Result<(), String> {
    let f32_ok = |v: f64| v == 0.0 || (v.abs() <= f32::MAX as f64 && v.abs() >= f32::MIN_POSITIVE as f64);
    let m = q.medium;
    if m.sigma_a + m.sigma_s > GPU_MAX_SIGMA_T {
        return Err(format!("sigma_a + sigma_s = {:e} is above {GPU_MAX_SIGMA_T:e} /mm", m.sigma_a + m.sigma_s));
    }
    let d = q.xo - q.xi;
    for (name, v) in
        [("sigma_a", m.sigma_a), ("sigma_s", m.sigma_s), ("xo - xi", d.x), ("xo - xi", d.y), ("xo - xi", d.z)]
    {
        if !f32_ok(v) {
            return Err(format!("{name} = {v:e} is outside f32's normal range"));
        }
    }
    Ok(())
}

fn to_query(v: &[f64; 19]) -> std::result::Result<Query, String> {
    for (i, name) in [(0, "sigma_a"), (1, "sigma_s")] {
        if v[i] < 0.0 {
            return Err(format!("column {name}: {} is negative", v[i]));
        }
        let (lo, hi) = (crate::materials::MIN_SIGMA, crate::materials::MAX_SIGMA);
        if v[i] > hi || (v[i] > 0.0 && v[i] < lo) {
            return Err(format!("column {name}: {:e} must be 0 or within [{lo:e}, {hi:e}] /mm", v[i]));
        }
    }
    if v[2] <= -1.0 || v[2] >= 1.0 {
        return Err(format!("column g: {} is outside (−1, 1)", v[2]));
    }
    if !(crate::materials::ETA_RANGE.0..=crate::materials::ETA_RANGE.1).contains(&v[3]) {
        let (lo, hi) = crate::materials::ETA_RANGE;
        return Err(format!("column eta: {} must be within [{lo}, {hi}]", v[3]));
    }
    // Squared distances must stay finite in f64.
    for (i, name) in [(4, "xi"), (13, "xo")] {
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            if v[i + k].abs() > MAX_COORDINATE_MM {
                return Err(format!("column {name}_{axis}: {:e} is beyond ±{MAX_COORDINATE_MM:e} mm", v[i + k]));
            }
        }
    }
    let vec = |i: usize| DVec3::new(v[i], v[i + 1], v[i + 2]);
    // Scaled by the largest component first: (1e308, 1e308, 0) is a fine direction even though
    // its squared length overflows.
    let unit = |i: usize, name: &str| {
        let v = vec(i);
        let m = v.abs().max_element();
        (if m > 0.0 { (v / m).try_normalize() } else { None })
            .ok_or_else(|| format!("column {name}_x: the vector ({v}) has zero length"))
    };
    Ok(Query {
        medium: Medium { sigma_a: v[0], sigma_s: v[1], g: v[2], eta: v[3] },
        xi: vec(4),
        ni: unit(7, "ni")?,
        wi: unit(10, "wi")?,
        xo: vec(13),
        no: unit(16, "no")?,
    })
}

/// Writes the header and one row per query with its Sd.
pub fn write(out: impl Write, queries: &[Query], sd: &[f64]) -> Result<()> {
    let mut out = std::io::BufWriter::with_capacity(1 << 16, out);
    write_header(&mut out)?;
    write_rows(&mut out, queries, sd)?;
    out.flush().map_err(|e| runtime!("stdout: {e}"))
}

/// The output's header line.
pub fn write_header(mut out: impl Write) -> Result<()> {
    writeln!(out, "{},sd", COLUMNS.join(",")).map_err(|e| runtime!("stdout: {e}"))
}

/// One line per query with its Sd (no header, no flush).
pub fn write_rows(mut out: impl Write, queries: &[Query], sd: &[f64]) -> Result<()> {
    let io = |e: std::io::Error| runtime!("stdout: {e}");
    for (q, s) in queries.iter().zip(sd) {
        let m = q.medium;
        let [xi, ni, wi, xo, no] = [q.xi, q.ni, q.wi, q.xo, q.no];
        writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            m.sigma_a,
            m.sigma_s,
            m.g,
            m.eta,
            xi.x,
            xi.y,
            xi.z,
            ni.x,
            ni.y,
            ni.z,
            wi.x,
            wi.y,
            wi.z,
            xo.x,
            xo.y,
            xo.z,
            no.x,
            no.y,
            no.z,
            s
        )
        .map_err(io)?;
    }
    Ok(())
}
