//! The Monte Carlo tables kept on disk (src/physics/table_cache.rs): read back the same bits as
//! measured, measured again where the file is damaged, and measured anyway where nothing can be
//! written.

use std::cell::Cell;
use std::path::PathBuf;
use translucent::materials::Material;
use translucent::physics::table_cache::{cached_in, Flat};
use translucent::physics::{curvature_profile, mc_profile::McProfile, slab_profile, Medium};

fn ketchup() -> [Medium; 3] {
    let m = Material::find("ketchup").expect("preset");
    [0, 1, 2].map(|c| m.channel(c))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("translucent-table-cache-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Measures once into `dir`, then reads: the second call must not measure and must give the same.
fn round_trip<T: Flat + PartialEq + std::fmt::Debug + Clone>(dir: &std::path::Path, kind: &str, table: T) {
    let measured = Cell::new(0);
    let measure = || {
        measured.set(measured.get() + 1);
        table.clone()
    };
    let first = cached_in(Some(dir), kind, &[1, 2, 3], measure);
    let second = cached_in(Some(dir), kind, &[1, 2, 3], measure);
    assert_eq!(measured.get(), 1, "{kind}: read back, not measured again");
    assert_eq!(first, table);
    assert_eq!(second, table, "{kind}: the same bits");
    // Another key is another table.
    let _ = cached_in(Some(dir), kind, &[1, 2, 4], measure);
    assert_eq!(measured.get(), 2, "{kind}: another key measures");
}

/// A file of the same table measured by older code (another source hash) is replaced, not kept.
#[test]
fn older_files_of_a_table_are_replaced() {
    let dir = scratch("replaced");
    let table = (*McProfile::of(&ketchup()[0])).clone();
    let _ = cached_in(Some(&dir), "half-space", &[9], || table.clone());
    let names = || {
        let mut v: Vec<String> = std::fs::read_dir(&dir)
            .expect("cache dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    let current = names();
    assert_eq!(current.len(), 1, "{current:?}");
    // The same stem with another source hash, as an older build left it.
    let stem = current[0].rsplit_once('-').expect("kind-key-source").0;
    let older = dir.join(format!("{stem}-0123456789abcdef.f64"));
    std::fs::write(&older, b"from an older build").expect("write");
    std::fs::remove_file(dir.join(&current[0])).expect("remove");
    let _ = cached_in(Some(&dir), "half-space", &[9], || table.clone());
    assert_eq!(names(), current, "the older file is gone, the new one written");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_table_reads_back_the_same_bits() {
    let media = ketchup();
    let dir = scratch("round-trip");
    round_trip(&dir, "half-space", (*McProfile::of(&media[0])).clone());
    let unit = curvature_profile::unit_of(&media);
    round_trip(&dir, "slab", (*slab_profile::SlabChannel::of(&media[1], unit)).clone());
    round_trip(&dir, "curvature", (*curvature_profile::of_channels(&media)[2]).clone());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_damaged_file_is_measured_again_and_an_unwritable_cache_is_skipped() {
    let dir = scratch("damaged");
    let table = (*McProfile::of(&ketchup()[0])).clone();
    let measured = Cell::new(0);
    let measure = || {
        measured.set(measured.get() + 1);
        table.clone()
    };
    let _ = cached_in(Some(&dir), "half-space", &[7], measure);
    let file = std::fs::read_dir(&dir).expect("cache dir").next().expect("one file").expect("entry").path();
    let bytes = std::fs::read(&file).expect("read");
    for damage in [bytes[..bytes.len() / 2].to_vec(), [&bytes[..], &[0u8; 8]].concat(), {
        let mut b = bytes.clone();
        b[40] ^= 1;
        b
    }] {
        std::fs::write(&file, damage).expect("write");
        let before = measured.get();
        assert_eq!(cached_in(Some(&dir), "half-space", &[7], measure), table);
        assert_eq!(measured.get(), before + 1, "a damaged file is not read");
    }
    // A file far longer than any table is refused and the table measured again (that it is
    // refused before being read, the metadata check in `read`, no test here can see).
    std::fs::write(&file, vec![0u8; 9 << 20]).expect("write");
    let before = measured.get();
    assert_eq!(cached_in(Some(&dir), "half-space", &[7], measure), table);
    assert_eq!(measured.get(), before + 1, "an oversized file is not read");
    // The cache's directory is a file: nothing can be kept, the table is measured each time.
    let blocked = dir.join("a-file");
    std::fs::write(&blocked, b"x").expect("write");
    let before = measured.get();
    for _ in 0..2 {
        assert_eq!(cached_in(Some(&blocked), "half-space", &[7], measure), table);
    }
    assert_eq!(measured.get(), before + 2);
    let _ = std::fs::remove_dir_all(&dir);
}
