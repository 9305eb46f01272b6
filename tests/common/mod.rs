//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::Arc;

use translucent::vk::{Context, ContextOptions, ValidationCounts};

/// A context with validation and synchronization validation on. The counts are returned separately
/// so they can be read after the context (and its device) is destroyed.
pub fn validated_context() -> (Context, Arc<ValidationCounts>) {
    let ctx = Context::new(&ContextOptions { validation: true, device: None }).expect("Vulkan context with validation");
    let counts = ctx.validation_counts();
    (ctx, counts)
}

/// Asserts that the validation layer reported nothing (call after dropping the context).
pub fn assert_clean(counts: &ValidationCounts) {
    use std::sync::atomic::Ordering;
    let (w, e) = (counts.warnings.load(Ordering::SeqCst), counts.errors.load(Ordering::SeqCst));
    assert_eq!((w, e), (0, 0), "validation reported {e} error(s) and {w} warning(s); see the log above");
}

/// Runs the `translucent` binary with `args`.
pub fn translucent(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_translucent")).args(args).output().expect("run translucent")
}

/// Where tests write images (actual and difference images on failure).
pub fn output_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("translucent-tests");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn repo_path(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel)
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}
