//! Both builders' trees pass `validate()` on every built-in scene.

use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::scene;

#[test]
fn both_builders_validate_on_every_scene() {
    let names = scene::builtin_names().unwrap();
    assert!(names.len() >= 6, "{names:?}");
    for name in names {
        let scene = scene::load(&name).unwrap();
        for options in [BuildOptions::median(), BuildOptions::sah()] {
            let bvh = Bvh::build(&scene.mesh, &options);
            if let Err(e) = bvh.validate(&scene.mesh) {
                panic!("{name} with {options:?}: {e}");
            }
        }
    }
}
