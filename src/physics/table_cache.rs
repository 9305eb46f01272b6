//! The Monte Carlo table's measurements kept on disk between runs: the half-space profile, the
//! slab's transmission and the curvature ratios take 2-20 s a material on two cores, every time
//! `--model mc` starts, though they depend only on the material and on this code.
//!
//! Each table is written as its numbers (f64, little-endian) under a name of its kind, a hash of
//! its key (the medium's coefficients) and a hash of the source of every file that shapes the
//! walk, so that a change to the physics misses the old file instead of reading it, and replaces
//! it: the cache holds one file per table and material. A file that is missing,
//! short, too long or fails its checksum is measured again and rewritten; a cache that cannot be
//! written (read-only home, full disk) is skipped: the table is still measured, only not kept.
//! Measurements are deterministic (fixed seeds), so a table read back is the same bits as the one
//! measured.
//!
//! Where: `$TRANSLUCENT_TABLE_CACHE` (a directory, or `off` to neither read nor write), else
//! `$XDG_CACHE_HOME/translucent`, else `$HOME/.cache/translucent`.

use std::path::{Path, PathBuf};

/// FNV-1a over `bytes`, continuing from `hash`.
const fn fnv(mut hash: u64, bytes: &[u8]) -> u64 {
    let mut i = 0;
    while i < bytes.len() {
        hash ^= bytes[i] as u64;
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        i += 1;
    }
    hash
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// The source of everything that decides a table's numbers.
const SOURCE_HASH: u64 = {
    let mut h = FNV_OFFSET;
    h = fnv(h, include_bytes!("halfspace.rs"));
    h = fnv(h, include_bytes!("sphere.rs"));
    h = fnv(h, include_bytes!("fresnel.rs"));
    h = fnv(h, include_bytes!("beam_diffusion.rs"));
    h = fnv(h, include_bytes!("mc_profile.rs"));
    h = fnv(h, include_bytes!("slab_profile.rs"));
    h = fnv(h, include_bytes!("curvature_profile.rs"));
    h = fnv(h, include_bytes!("table_cache.rs"));
    h
};

const MAGIC: &[u8; 8] = b"TLTABLE1";
/// No table here is near this many numbers; a longer file is not read.
const MAX_VALUES: usize = 1 << 20;

/// A table as a flat list of numbers and back (`None`: not a table of this kind).
pub trait Flat: Sized {
    fn to_flat(&self) -> Vec<f64>;
    fn from_flat(values: &[f64]) -> Option<Self>;
}

/// Reads fixed-size pieces off the front of a flat list.
pub struct Take<'a>(pub &'a [f64]);

impl Take<'_> {
    pub fn scalar(&mut self) -> Option<f64> {
        let (&first, rest) = self.0.split_first()?;
        self.0 = rest;
        Some(first)
    }
    pub fn array<const N: usize>(&mut self) -> Option<[f64; N]> {
        if self.0.len() < N {
            return None;
        }
        let (head, rest) = self.0.split_at(N);
        self.0 = rest;
        head.try_into().ok()
    }
    /// A length, then that many values.
    pub fn vec(&mut self) -> Option<Vec<f64>> {
        let n = self.count()?;
        (self.0.len() >= n).then(|| {
            let (head, rest) = self.0.split_at(n);
            self.0 = rest;
            head.to_vec()
        })
    }
    /// A length, then that many arrays of N.
    pub fn vec_of<const N: usize>(&mut self) -> Option<Vec<[f64; N]>> {
        let n = self.count()?;
        (0..n).map(|_| self.array::<N>()).collect()
    }
    fn count(&mut self) -> Option<usize> {
        let n = self.scalar()?;
        (n >= 0.0 && n.fract() == 0.0 && n <= MAX_VALUES as f64).then_some(n as usize)
    }
    /// Nothing may be left over.
    pub fn end(&self) -> Option<()> {
        self.0.is_empty().then_some(())
    }
}

/// Appends a length and the values (the counterpart of [`Take::vec`] and [`Take::vec_of`]).
pub fn push_vec(out: &mut Vec<f64>, values: impl ExactSizeIterator<Item = f64>) {
    out.push(values.len() as f64);
    out.extend(values);
}

/// The directory in use, or None where caching is off or there is no home.
pub fn directory() -> Option<PathBuf> {
    match std::env::var_os("TRANSLUCENT_TABLE_CACHE") {
        Some(v) if v == "off" => None,
        Some(v) if !v.is_empty() => Some(PathBuf::from(v)),
        _ => std::env::var_os("XDG_CACHE_HOME")
            .filter(|v| !v.is_empty())
            .map(|v| PathBuf::from(v).join("translucent"))
            .or_else(|| {
                std::env::var_os("HOME").filter(|v| !v.is_empty()).map(|h| PathBuf::from(h).join(".cache/translucent"))
            }),
    }
}

/// The table of `kind` and `key`: read from the cache directory, else measured by `measure` and
/// written there.
pub fn cached<T: Flat>(kind: &str, key: &[u64], measure: impl FnOnce() -> T) -> T {
    cached_in(directory().as_deref(), kind, key, measure)
}

/// [`cached`] in `dir` (None: measure, keep nothing).
pub fn cached_in<T: Flat>(dir: Option<&Path>, kind: &str, key: &[u64], measure: impl FnOnce() -> T) -> T {
    let Some(dir) = dir else { return measure() };
    let key_hash = key.iter().fold(fnv(FNV_OFFSET, kind.as_bytes()), |h, k| fnv(h, &k.to_le_bytes()));
    // One file per kind and key: measured by other code, it is replaced, not kept beside.
    let stem = format!("{kind}-{key_hash:016x}-");
    let path = dir.join(format!("{stem}{SOURCE_HASH:016x}.f64"));
    if let Some(table) = read(&path).and_then(|v| T::from_flat(&v)) {
        return table;
    }
    let table = measure();
    match write(dir, &path, &table.to_flat()) {
        Ok(()) => remove_others(dir, &stem, &path),
        Err(e) => log::debug!("table cache: not kept ({}): {e}", path.display()),
    }
    table
}

/// Removes the files of `stem` other than `keep` (the same table measured by older code).
fn remove_others(dir: &Path, stem: &str, keep: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if path != keep && name.starts_with(stem) && name.ends_with(".f64") {
            let _ = std::fs::remove_file(&path);
        }
    }
}

fn checksum(values: &[f64]) -> u64 {
    values.iter().fold(FNV_OFFSET, |h, v| fnv(h, &v.to_le_bytes()))
}

fn read(path: &Path) -> Option<Vec<f64>> {
    // Not read at all when longer than any table: a stray large file costs no memory.
    if std::fs::metadata(path).ok()?.len() > (8 * (MAX_VALUES + 3)) as u64 {
        return None;
    }
    let bytes = std::fs::read(path).ok()?;
    let body = bytes.strip_prefix(MAGIC)?;
    if body.len() < 16 || !body.len().is_multiple_of(8) || body.len() / 8 - 2 > MAX_VALUES {
        return None;
    }
    let words: Vec<[u8; 8]> = body.chunks_exact(8).map(|c| c.try_into().unwrap_or([0; 8])).collect();
    let n = u64::from_le_bytes(words[0]) as usize;
    if n != words.len() - 2 {
        return None;
    }
    let values: Vec<f64> = words[1..=n].iter().map(|w| f64::from_le_bytes(*w)).collect();
    (u64::from_le_bytes(words[n + 1]) == checksum(&values)).then_some(values)
}

/// Writes beside the final name and renames, so that a reader (another process measuring the
/// same material) never sees half a file.
fn write(dir: &Path, path: &Path, values: &[f64]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut bytes = Vec::with_capacity(8 * (values.len() + 3));
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&(values.len() as u64).to_le_bytes());
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.extend_from_slice(&checksum(values).to_le_bytes());
    let temporary = path.with_extension(format!("{}.partial", std::process::id()));
    std::fs::write(&temporary, &bytes)?;
    std::fs::rename(&temporary, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&temporary);
    })
}
