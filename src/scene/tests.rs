//! Whole-scene tests: the built-in scenes load with the expected triangle
//! counts, and every file of the malformed-input corpus (`tests/data/bad/`)
//! gives an error naming the file and the line.

use super::*;
use glam::Vec3;
use std::time::Instant;

fn bad(name: &str) -> String {
    format!("{}/tests/data/bad/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn builtin_names_are_the_manifests_sorted() {
    let names = builtin_names().unwrap();
    let expected = [
        "cornell",
        "cornell-area",
        "cornell-bloom",
        "cornell-glossy",
        "cornell-segment",
        "cornell-transparent",
        "dragon-11k",
        "dragon-203k",
        "dragon-48k",
        "dragon-871k",
        "monkey",
        "monkey-smooth",
        "motion-blur",
        "textured-cube",
        "textured-quad",
    ];
    assert_eq!(names, expected);
}

#[test]
fn unknown_scene_names_list_the_builtin_ones() {
    let err = load("no-such-scene").unwrap_err().to_string();
    assert!(
        err.contains("no-such-scene") && err.contains("cornell, cornell-area"),
        "{err}"
    );
}

#[test]
fn cornell_box_has_32_triangles_5_materials_and_a_mirror_tall_block() {
    let scene = load("cornell").unwrap();
    assert_eq!(scene.name, "cornell");
    assert_eq!(scene.mesh.triangle_count(), 32);
    scene.mesh.check().unwrap();
    let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["white", "red", "green", "light", "mirror"]);
    // The tall block is the last 5 quads in the file.
    let mirror = &scene.materials[scene.mesh.materials[31] as usize];
    assert_eq!(mirror.mirror, Vec3::splat(0.9));
    assert!(
        scene.mesh.materials[..22]
            .iter()
            .all(|&m| scene.materials[m as usize].mirror == Vec3::ZERO)
    );
    let bounds = scene.mesh.bounds();
    assert_eq!(bounds.min, Vec3::ZERO);
    assert_eq!(bounds.max, Vec3::new(556.0, 548.8, 559.2));
    assert_eq!(scene.camera.eye, Vec3::new(278.0, 273.0, -800.0));
    assert_eq!(
        scene.features,
        [Feature::Shading, Feature::HardShadows, Feature::Reflection]
    );
    assert_eq!(scene.lights.len(), 1);
    let light = scene.lights[0].representative_point();
    assert!(light.y < 548.3 && light.y > 500.0, "{light}");
}

#[test]
fn a_bare_mesh_is_framed_and_lit() {
    let path = format!("{}/scenes/cornell.obj", env!("CARGO_MANIFEST_DIR"));
    let scene = load(&path).unwrap();
    assert_eq!(scene.name, "cornell");
    assert_eq!(scene.mesh.triangle_count(), 32);
    assert_eq!(scene.lights.len(), 1);
    let bounds = scene.mesh.bounds();
    assert!(!bounds.contains(&crate::geometry::Aabb::from_points(&[scene.camera.eye])));
    assert_eq!(scene.camera.look_at, bounds.center());
}

#[test]
fn monkey_has_3936_triangles_with_normals_and_texcoords() {
    let scene = load("monkey").unwrap();
    let mesh = &scene.mesh;
    assert_eq!(mesh.triangle_count(), 3936);
    assert_eq!(mesh.positions.len(), 7872);
    mesh.check().unwrap();
    let normals = mesh.normals.as_ref().expect("normals");
    assert!(normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-2));
    let texcoords = mesh.texcoords.as_ref().expect("texcoords");
    assert!(
        texcoords
            .iter()
            .all(|t| t.cmpge(glam::Vec2::ZERO).all() && t.cmple(glam::Vec2::ONE).all())
    );
    // The accessor's recorded bounds, within the quantization error.
    let bounds = mesh.bounds();
    assert!(
        (bounds.max - Vec3::new(1.3259, 0.9392, 0.8223))
            .abs()
            .max_element()
            < 1e-3
    );
    assert!(
        (bounds.min - Vec3::new(-1.3259, -0.9705, -0.7783))
            .abs()
            .max_element()
            < 1e-3
    );
    assert_eq!(scene.lights.len(), 2);
    assert_ne!(scene.lights[0].mean_color(), scene.lights[1].mean_color());
}

fn check_dragon(name: &str, triangles: usize) {
    let start = Instant::now();
    let scene = load(name).unwrap();
    eprintln!(
        "{name}: {} triangles in {:?}",
        scene.mesh.triangle_count(),
        start.elapsed()
    );
    assert_eq!(scene.mesh.triangle_count(), triangles);
    scene.mesh.check().unwrap();
    let bounds = scene.mesh.bounds();
    assert!(
        (bounds.max - Vec3::new(0.0952, 0.1963, 0.0408))
            .abs()
            .max_element()
            < 2e-3
    );
    let camera = scene.camera;
    let centre_ray = camera.ray(0.5, 0.5, 1, 1);
    let to_centre = bounds.center() - camera.eye;
    assert!(centre_ray.dir.normalize().dot(to_centre.normalize()) > 0.999);
}

#[test]
fn dragon_11k() {
    check_dragon("dragon-11k", 11_102);
}

#[test]
fn dragon_48k() {
    check_dragon("dragon-48k", 47_794);
}

#[test]
fn dragon_203k() {
    check_dragon("dragon-203k", 202_520);
}

#[test]
fn dragon_871k() {
    check_dragon("dragon-871k", 871_414);
}

#[test]
fn every_malformed_file_gives_an_error_naming_file_and_line() {
    let cases = [
        (
            "truncated.ply",
            "truncated.ply:15: face 1 of 2: too few values",
        ),
        (
            "wrong_count.ply",
            "wrong_count.ply:15: data after the last element",
        ),
        (
            "index_out_of_range.ply",
            "index_out_of_range.ply:15: face 1 of 2: face index 40 out of range (mesh has 4 vertices)",
        ),
        (
            "negative_index.ply",
            "negative_index.ply:15: face 1 of 2: negative face index -2",
        ),
        (
            "nan_coordinate.ply",
            "nan_coordinate.ply:11: vertex 1 of 4: y = NaN is not a finite number",
        ),
        (
            "bad_number.ply",
            "bad_number.ply:11: vertex 1 of 4: \"0.2x5\" is not a number",
        ),
        (
            "absurd_count.ply",
            "absurd_count.ply:3: element vertex declares 999999999999 rows",
        ),
        (
            "inf_coordinate.obj",
            "inf_coordinate.obj:3: vertex coordinate \"inf\" is not a finite number",
        ),
        (
            "obj_index_out_of_range.obj",
            "obj_index_out_of_range.obj:5: face index 9 out of range (mesh has 3 vertices)",
        ),
        (
            "obj_zero_index.obj",
            "obj_zero_index.obj:4: face index 0 (OBJ indices start at 1)",
        ),
        (
            "obj_negative_index.obj",
            "obj_negative_index.obj:5: relative face index -4 reaches before the first",
        ),
        ("non_utf8.obj", "non_utf8.obj:3: invalid UTF-8"),
        (
            "missing_mtl.obj",
            "missing_mtl.obj:2: material library \"nowhere.mtl\" not found",
        ),
        (
            "missing_texture.obj",
            "missing_texture.mtl:3: texture \"nowhere.png\" not found",
        ),
        (
            "unknown_material.obj",
            "unknown_material.obj:5: usemtl \"stone\": no such material",
        ),
        ("bad_key.toml", "bad_key.toml:5: unknown field `scael`"),
        (
            "unknown_feature.toml",
            "unknown_feature.toml:4: unknown variant `ray_marching`, expected one of `shading`, `hard_shadows`",
        ),
        (
            "bad_light.toml",
            "bad_light.toml:6: a Point light does not take `endpoints`",
        ),
        ("missing_mesh.toml", "missing_mesh.toml:3: mesh file"),
        ("truncated.glb", "truncated.glb: GLB header says 64 bytes"),
    ];
    // Every corpus file is a case, except the MTL libraries the OBJ files use.
    let corpus = std::fs::read_dir(bad(""))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().path().extension().unwrap() != "mtl")
        .count();
    assert_eq!(corpus, cases.len(), "a corpus file has no case");
    for (file, expected) in cases {
        let err = load(&bad(file)).expect_err(file).to_string();
        assert!(
            err.contains(&format!("/tests/data/bad/{expected}")),
            "{file}: expected {expected:?}, got {err:?}"
        );
    }
}
