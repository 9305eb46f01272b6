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
    let options = bench_options(args, meshes);
    crate::error::write_stdout(&crate::bench::run(&options)?)?;
    Ok(0)
}

/// The bench's options from its flags: a size typed for the frame (--width, --height) sizes
/// every table that has no size of its own typed, so a bench asked to be small is small.
pub fn bench_options(args: &BenchArgs, meshes: Vec<String>) -> crate::bench::BenchOptions {
    let (width, height) = (args.width.unwrap_or(512), args.height.unwrap_or(512));
    let typed = (args.width.is_some() || args.height.is_some()).then_some(width.max(height));
    crate::bench::BenchOptions {
        meshes,
        samples: args.samples.clone(),
        width,
        height,
        frames: args.frames,
        accuracy_size: args.accuracy_size,
        accuracy_samples: args.accuracy_samples.clone(),
        epsilons: args.epsilons.clone(),
        lights: if args.no_lights { Vec::new() } else { args.lights.clone() },
        peer_size: args.peer_size.or(typed).unwrap_or(1024),
        scene_size: args.scene_size.or(typed).unwrap_or(512),
        context: args.device.options(),
    }
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

#[cfg(test)]
mod tests {
    use clap::Parser;

    fn options(argv: &[&str]) -> crate::bench::BenchOptions {
        let cli = crate::cli::Cli::try_parse_from([&["translucent", "bench"], argv].concat()).unwrap();
        let crate::cli::Command::Bench(args) = cli.command else { unreachable!() };
        super::bench_options(&args, vec!["sphere".into()])
    }

    #[test]
    fn a_small_bench_is_small_and_the_default_unchanged() {
        let d = options(&[]);
        assert_eq!((d.width, d.height, d.peer_size, d.scene_size), (512, 512, 1024, 512));
        assert_eq!(d.lights, [1, 8, 64, 256]);
        let s = options(&["--width", "32", "--height", "24", "--lights", "1,8"]);
        assert_eq!((s.width, s.height, s.peer_size, s.scene_size), (32, 24, 32, 32));
        assert_eq!(s.lights, [1, 8]);
        assert!(options(&["--no-lights"]).lights.is_empty());
        let own = options(&["--width", "32", "--peer-size", "0", "--scene-size", "64"]);
        assert_eq!((own.peer_size, own.scene_size), (0, 64));
    }
}
