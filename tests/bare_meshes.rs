//! Meshes given on the command line without a manifest render with what
//! their materials hold, `explain` says which passes that turned on and
//! why (and, for a manifest, why each feature it lists runs or not), and an
//! exporter's dangling texcoord or normal index loads with a warning naming
//! the file and the line.

use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::render::pipeline::explain;
use raycheck::render::{RenderSettings, render};
use raycheck::scene::{self, Feature, Scene};
use std::process::Command;

fn data(name: &str) -> String {
    format!("{}/tests/data/bare/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Pixels whose linear colour is clearly red, and clearly blue: the two
/// colours of the checker texture, which the untextured grey is neither.
fn red_and_blue_pixels(scene: &Scene) -> (usize, usize) {
    let bvh = Bvh::build(&scene.mesh, &BuildOptions::sah());
    let image = render(scene, &bvh, &RenderSettings::square(48));
    let red = image
        .pixels
        .iter()
        .filter(|p| p.x > 0.02 && p.x > 3.0 * p.z)
        .count();
    let blue = image
        .pixels
        .iter()
        .filter(|p| p.z > 0.02 && p.z > 3.0 * p.x)
        .count();
    (red, blue)
}

#[test]
fn a_bare_obj_with_map_kd_renders_textured() {
    let scene = scene::load(&data("textured_box.obj")).unwrap();
    assert_eq!(
        scene.features,
        [Feature::Shading, Feature::HardShadows, Feature::Textures]
    );
    let (red, blue) = red_and_blue_pixels(&scene);
    // The front face shows 8 red and 8 blue texels, each about 8 pixels
    // wide; bilinear filtering leaves the middle of each clearly one colour.
    assert!(red > 32 && blue > 32, "red {red}, blue {blue}");
    let untextured = Scene {
        features: vec![Feature::Shading, Feature::HardShadows],
        ..scene
    };
    assert_eq!(red_and_blue_pixels(&untextured), (0, 0));
}

#[test]
fn explain_names_the_material_that_turned_textures_on() {
    let path = data("textured_box.obj");
    let scene = scene::load(&path).unwrap();
    let light = scene.lights[0].representative_point();
    let expected = format!(
        "textured_box: primary rays (1 per pixel), phong shading, hard shadows (1 occlusion ray per point light), texture mapping
features of the bare mesh {path}: shading and hard_shadows always, the others where its content has what they act on
  shading: on: 1 light
  hard_shadows: on: a point light at {light}
  reflection: off: no material in use is a mirror
  normal_interpolation: off: no mesh has vertex normals
  textures: on: material \"checker\" has diffuse texture {}
  glossy: off: no mirror in use has a roughness above 0
  transparency: off: every material in use is opaque
",
        data("checker4x4.png")
    );
    assert_eq!(explain(&scene, None), expected);
}

#[test]
fn mirror_and_translucent_materials_turn_on_reflection_and_transparency() {
    let scene = scene::load(&data("mirror_and_glass.obj")).unwrap();
    assert_eq!(
        scene.features,
        [
            Feature::Shading,
            Feature::HardShadows,
            Feature::Reflection,
            Feature::Transparency
        ]
    );
    let text = explain(&scene, Some(4));
    for line in [
        "  reflection: on: material \"mirror\" is a mirror (reflectance [0.9, 0.9, 0.9])\n",
        "  transparency: on: material \"glass\" has opacity 0.4\n",
        "  textures: off: no material in use has a diffuse texture\n",
        "  multisample: on: 4 samples per pixel asked for\n",
    ] {
        assert!(text.contains(line), "{line:?} missing from:\n{text}");
    }
    assert!(
        text.starts_with(
            "mirror_and_glass: primary rays (4 per pixel), jittered pixel samples, phong shading"
        ),
        "{text}"
    );
}

#[test]
fn a_material_no_face_uses_turns_nothing_on() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl matte\nKd 0.5 0.5 0.5\nnewmtl chrome\nKs 0.9 0.9 0.9\nillum 3\nnewmtl smoke\nd 0.2\n",
    )
    .unwrap();
    let obj = dir.path().join("m.obj");
    std::fs::write(
        &obj,
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl matte\nf 1 2 3\n",
    )
    .unwrap();
    let scene = scene::load(obj.to_str().unwrap()).unwrap();
    assert_eq!(scene.features, [Feature::Shading, Feature::HardShadows]);
}

#[test]
fn dangling_texcoord_and_normal_indices_warn_and_turn_textures_off() {
    let path = data("missing_attributes.obj");
    let scene = scene::load(&path).unwrap();
    assert_eq!(scene.mesh.triangle_count(), 2);
    assert!(scene.mesh.texcoords.is_none() && scene.mesh.normals.is_none());
    assert_eq!(scene.features, [Feature::Shading, Feature::HardShadows]);
    let text = explain(&scene, None);
    let textures_off = format!(
        "  textures: off: material \"checker\" has diffuse texture {}, but no mesh has texture coordinates\n",
        data("checker4x4.png")
    );
    assert!(text.contains(&textures_off), "{text}");

    let out = Command::new(env!("CARGO_BIN_EXE_raycheck"))
        .args(["render", &path, "--explain"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        stderr,
        format!(
            "{path}:13: warning: texcoord index 9 out of range (mesh has 2 texcoords); the mesh is loaded without texture coordinates
{path}:14: warning: normal index 3 out of range (mesh has 1 normals); the mesh is loaded without vertex normals
"
        )
    );
}

#[test]
fn explain_of_a_manifest_gives_each_feature_it_lists_its_reason() {
    let scene = scene::load("cornell-area").unwrap();
    let light = scene.lights[0].representative_point();
    let expected = format!(
        "cornell-area: primary rays (4 per pixel), jittered pixel samples, phong shading, area lights (16 stratified shadow rays each), mirror reflection (depth 4)
features listed in {}:
  shading: on: 1 light
  hard_shadows: off: no point light
  reflection: on: material \"mirror\" is a mirror (reflectance [0.9, 0.9, 0.9])
  area_lights: on: an area light centred at {light}
  multisample: on: jittered camera samples in every pixel
",
        scene.source.display()
    );
    assert_eq!(explain(&scene, None), expected);
}
