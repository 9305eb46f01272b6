//! The commands: each turns its parsed flags (src/cli.rs) into settings and calls the library.
//! [`run`] dispatches; every command returns its exit code, or an error whose exit code says what
//! kind it is (src/error.rs).

mod bssrdf;
mod compare;
mod devices;
mod export;
mod profile;
mod render;

use std::path::{Path, PathBuf};

use crate::bad_input;
use crate::cli::{BenchArgs, Cli, Command};
use crate::error::Result;
use crate::settings::BUNNY;

/// Runs a parsed command; `Ok(code)` is the exit code when it finished without an error.
pub fn run(cli: Cli) -> Result<i32> {
    match cli.command {
        Command::Render(args) => render::render(&args),
        Command::Devices => devices::devices(),
        Command::Materials => {
            crate::error::write_stdout(&crate::materials::materials_table())?;
            Ok(0)
        }
        Command::Bssrdf(args) => bssrdf::bssrdf(&args),
        Command::Profile(args) => profile::profile(&args),
        Command::View(args) => crate::view::run(&args),
        Command::Bench(args) => bench(&args),
        Command::Compare(args) => compare::compare(&args),
        Command::Export(args) => match args.format {
            crate::cli::ExportFormat::Mitsuba(m) => export::mitsuba(&m),
        },
    }
}

fn bench(args: &BenchArgs) -> Result<i32> {
    let meshes = args.meshes.clone().unwrap_or_else(|| {
        let mut m = vec!["sphere".to_string()];
        if Path::new(BUNNY).exists() {
            m.insert(0, BUNNY.to_string());
        }
        m
    });
    let options = crate::bench::BenchOptions {
        meshes,
        samples: args.samples.clone(),
        width: args.width,
        height: args.height,
        frames: args.frames,
        accuracy_size: args.accuracy_size,
        accuracy_samples: args.accuracy_samples.clone(),
        epsilons: args.epsilons.clone(),
        peer_size: args.peer_size,
        scene_size: args.scene_size,
        context: args.device.options(),
    };
    crate::error::write_stdout(&crate::bench::run(&options)?)?;
    Ok(0)
}

fn check_output_path(path: &Path, flag: &str, allowed: &[&str]) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
    if !allowed.contains(&ext.as_str()) {
        return Err(bad_input!("{flag} {}: the extension must be one of .{}", path.display(), allowed.join(", .")));
    }
    // Found out before a long render, not after it.
    if path.is_dir() {
        return Err(bad_input!("{flag} {}: is a folder; give a file name", path.display()));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            return Err(bad_input!("{flag} {}: the folder {} does not exist", path.display(), dir.display()));
        }
    }
    // Can it be written (permissions, a read-only file system)? Opened without truncating; a
    // file created only for this test is removed again.
    let first = frame_path(path, 0);
    let existed = first.exists();
    std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(&first)
        .map_err(|e| bad_input!("{flag} {}: cannot be written: {e}", first.display()))?;
    if !existed {
        std::fs::remove_file(&first).ok();
    }
    Ok(())
}

/// `--out` for frame `index`: `{frame}` replaced by the zero-padded number.
fn frame_path(out: &Path, index: u32) -> PathBuf {
    PathBuf::from(out.to_string_lossy().replace("{frame}", &format!("{index:04}")))
}
