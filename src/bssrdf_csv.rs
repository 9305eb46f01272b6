//! The `translucent bssrdf` contract: CSV rows of one channel each, on stdin, with exactly the
//! header below (mm⁻¹ and mm, normals outward, wi toward the light); out go the same columns plus
//! `sd`. Extra trailing columns are accepted and ignored (so the reference file, which carries
//! `sd,sd_dipole`, can be piped in as it is).

use std::io::{BufRead, Write};

use glam::DVec3;

use crate::bad_input;
use crate::error::Result;
use crate::physics::{Medium, Query};
use crate::runtime;

pub const COLUMNS: [&str; 19] = [
    "sigma_a", "sigma_s", "g", "eta", "xi_x", "xi_y", "xi_z", "ni_x", "ni_y", "ni_z", "wi_x", "wi_y", "wi_z", "xo_x",
    "xo_y", "xo_z", "no_x", "no_y", "no_z",
];

/// Parses the rows; a bad row is an error naming its line number, the column and the reason.
pub fn parse(input: impl BufRead) -> Result<Vec<Query>> {
    let mut lines = input.lines().enumerate();
    let header = match lines.next() {
        Some((_, line)) => line.map_err(|e| runtime!("stdin: {e}"))?,
        None => return Err(bad_input!("bssrdf: empty input; expected the header {}", COLUMNS.join(","))),
    };
    let names: Vec<&str> = header.trim_end_matches('\r').split(',').map(str::trim).collect();
    if names.len() < COLUMNS.len() || names[..COLUMNS.len()] != COLUMNS {
        return Err(bad_input!("bssrdf: line 1: the header must start with exactly {}", COLUMNS.join(",")));
    }
    let mut queries = Vec::new();
    let mut values = [0f64; 19];
    for (index, line) in lines {
        let line_number = index + 1;
        let line = line.map_err(|e| runtime!("stdin line {line_number}: {e}"))?;
        let line = line.trim_end_matches('\r');
        if line.trim().is_empty() {
            continue;
        }
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
        let q = to_query(&values).map_err(|why| bad_input!("bssrdf: line {line_number}, {why}"))?;
        queries.push(q);
    }
    Ok(queries)
}

fn to_query(v: &[f64; 19]) -> std::result::Result<Query, String> {
    for (i, name) in [(0, "sigma_a"), (1, "sigma_s")] {
        if v[i] < 0.0 {
            return Err(format!("column {name}: {} is negative", v[i]));
        }
    }
    if v[2] <= -1.0 || v[2] >= 1.0 {
        return Err(format!("column g: {} is outside (−1, 1)", v[2]));
    }
    if v[3] <= 0.0 {
        return Err(format!("column eta: {} must be positive", v[3]));
    }
    let vec = |i: usize| DVec3::new(v[i], v[i + 1], v[i + 2]);
    let unit = |i: usize, name: &str| {
        vec(i).try_normalize().ok_or_else(|| format!("column {name}_x: the vector ({}) has zero length", vec(i)))
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
    let io = |e: std::io::Error| runtime!("stdout: {e}");
    writeln!(out, "{},sd", COLUMNS.join(",")).map_err(io)?;
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
    out.flush().map_err(io)
}
