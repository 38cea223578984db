//! The build script's Embree cache heals: a damaged library or link in a
//! cache folder is fetched again, and the line saying so names the file
//! and the hash expected and found.

#[path = "../build_script/embree_cache.rs"]
mod embree_cache;

use embree_cache::{LIBRARIES, LINK_NAME, checked_embree_folder, sha256_hex};
use std::fs;

#[test]
fn a_damaged_library_or_link_is_fetched_again_and_named() {
    let cache = tempfile::tempdir().unwrap();
    let fresh = checked_embree_folder(cache.path()).unwrap();
    assert!(fresh.repaired.is_none());
    let [(embree, _), (tbb, tbb_sha256)] = LIBRARIES;
    assert_eq!(
        fresh.files,
        [LINK_NAME, embree, tbb].map(|name| fresh.dir.join(name))
    );

    // One bit changed, as a disk fault or an editor might leave it.
    let damaged = fresh.dir.join(tbb);
    let mut bytes = fs::read(&damaged).unwrap();
    bytes[4096] ^= 1;
    fs::write(&damaged, &bytes).unwrap();
    let healed = checked_embree_folder(cache.path()).unwrap();
    assert_eq!(
        healed.repaired.unwrap(),
        format!(
            "{} has SHA-256 {}, expected {tbb_sha256}: fetched embreex==4.4.0.post1 again",
            damaged.display(),
            sha256_hex(&bytes)
        )
    );
    assert_eq!(sha256_hex(&fs::read(&damaged).unwrap()), tbb_sha256);

    // The link replaced by a copy of the library it pointed at.
    let link = fresh.dir.join(LINK_NAME);
    fs::remove_file(&link).unwrap();
    fs::copy(fresh.dir.join(embree), &link).unwrap();
    let healed = checked_embree_folder(cache.path()).unwrap();
    assert_eq!(
        healed.repaired.unwrap(),
        format!(
            "{} is not a link to {embree}: fetched embreex==4.4.0.post1 again",
            link.display()
        )
    );
    assert_eq!(fs::read_link(&link).unwrap(), std::path::Path::new(embree));

    assert!(
        checked_embree_folder(cache.path())
            .unwrap()
            .repaired
            .is_none()
    );
    let left: Vec<_> = fs::read_dir(cache.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["embree-4.4.0"], "scratch folders were left behind");
}
