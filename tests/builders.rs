//! Both builders' trees pass `validate()` on every built-in scene.

use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::scene;

/// Scenes above this many triangles are left to the wide BVH's own test
/// below: two binary builds of them take minutes.
const BINARY_BUILDS_UP_TO: usize = 2_000_000;

#[test]
fn both_builders_validate_on_every_scene() {
    let names = scene::builtin_names().unwrap();
    assert!(names.len() >= 6, "{names:?}");
    for name in names {
        let scene = scene::load(&name).unwrap();
        if scene.mesh.triangle_count() > BINARY_BUILDS_UP_TO {
            continue;
        }
        for options in [BuildOptions::median(), BuildOptions::sah()] {
            let bvh = Bvh::build(&scene.mesh, &options);
            if let Err(e) = bvh.validate(&scene.mesh) {
                panic!("{name} with {options:?}: {e}");
            }
        }
    }
}

/// The largest built-in scene (generated and cached on first use): the
/// wide BVH builds within its limits and validates. About half a minute
/// and 2 GB, so run on demand:
/// `cargo test --release --test main largest -- --ignored`.
#[test]
#[ignore = "builds a 14M-triangle tree: half a minute, 2 GB"]
fn the_wide_bvh_validates_on_the_largest_scene() {
    let scene = scene::load("dragon-14m").unwrap();
    assert_eq!(scene.mesh.triangle_count(), 13_942_624);
    let bvh = raycheck::bvh::wide::WideBvh::try_build(&scene.mesh).unwrap();
    bvh.validate(&scene.mesh).unwrap();
}
