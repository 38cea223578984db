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
        "analytic-area",
        "cornell",
        "cornell-area",
        "cornell-bloom",
        "cornell-glossy",
        "cornell-sampled",
        "cornell-segment",
        "cornell-transparent",
        "dragon-11k",
        "dragon-14m",
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
        (
            "nan_coordinate.obj",
            "nan_coordinate.obj:3: vertex coordinate \"nan\" is not a finite number",
        ),
        (
            "truncated.obj",
            "truncated.obj:3: expected 3 numbers, found 2",
        ),
        ("empty.obj", "empty.obj: no faces: the mesh is empty"),
        (
            "wrong_count.obj",
            "wrong_count.obj:4: a face needs at least 3 vertices, this one has 2",
        ),
        (
            "truncated.mtl",
            "truncated.mtl:3: expected 3 numbers, found 2",
        ),
        (
            "nan_value.mtl",
            "nan_value.mtl:3: d \"nan\" is not a finite number",
        ),
        (
            "inf_value.mtl",
            "inf_value.mtl:3: Ns \"1e40\" is not a finite number",
        ),
        (
            "bad_number.mtl",
            "bad_number.mtl:2: Kd \"0.4x\" is not a number",
        ),
        (
            "negative_illum.mtl",
            "negative_illum.mtl:2: illum \"-1\" is not an illumination model number",
        ),
        (
            "illum_out_of_range.mtl",
            "illum_out_of_range.mtl:2: illum \"300\" is not an illumination model number",
        ),
        ("non_utf8.mtl", "non_utf8.mtl:3: invalid UTF-8"),
        (
            "missing_texture.mtl",
            "missing_texture.mtl:3: texture \"nowhere.png\" not found",
        ),
        (
            "inf_coordinate.ply",
            "inf_coordinate.ply:11: vertex 1 of 4: y = inf is not a finite number",
        ),
        ("empty.ply", "empty.ply: no faces: the mesh is empty"),
        ("non_utf8.ply", "non_utf8.ply:3: invalid UTF-8"),
        ("truncated.ply.gz", "truncated.ply.gz: corrupt gzip data"),
        (
            "binary_truncated.ply",
            "binary_truncated.ply: face 0 of 1: file truncated",
        ),
        (
            "binary_wrong_count.ply",
            "binary_wrong_count.ply: face 0 of 1: file truncated",
        ),
        (
            "binary_absurd_count.ply",
            "binary_absurd_count.ply:7: element face declares 4000000000 rows",
        ),
        (
            "chunk_length_lies.glb",
            "chunk_length_lies.glb: chunk at byte 500 runs past the end of the file",
        ),
        (
            "accessor_count_lies.glb",
            "accessor_count_lies.glb: mesh 0 primitive 0: POSITION: accessor 0 has 4000000000 elements",
        ),
        (
            "zero_stride.glb",
            "zero_stride.glb: mesh 0 primitive 0: POSITION: bufferView 0 has byteStride 0",
        ),
        (
            "index_out_of_range.glb",
            "index_out_of_range.glb: triangle 0 has index [0, 1, 9] but the mesh has 3 vertices",
        ),
        (
            "nan_coordinate.glb",
            "nan_coordinate.glb: vertex 1 is at [1, NaN, 0], not a finite point",
        ),
        (
            "inf_coordinate.glb",
            "inf_coordinate.glb: vertex 1 is at [1, inf, 0], not a finite point",
        ),
        (
            "wrong_count.glb",
            "wrong_count.glb: mesh 0 primitive 0: 4 indices is not a whole number of triangles",
        ),
        ("node_cycle.glb", "node_cycle.glb: node 0 is reached twice"),
        (
            "empty.glb",
            "empty.glb: no triangle meshes in the default scene",
        ),
        (
            "material_out_of_range.glb",
            "material_out_of_range.glb: mesh 0 primitive 0: no material 4294967296",
        ),
        ("non_utf8.glb", "non_utf8.glb: invalid glTF JSON"),
        ("nan_camera.toml", "nan_camera.toml:6: eye must be finite"),
        (
            "inf_light.toml",
            "inf_light.toml:6: position must be finite",
        ),
        ("truncated.toml", "truncated.toml:8: unclosed array"),
        ("empty.toml", "empty.toml: no [[mesh]] entries"),
        ("non_utf8.toml", "non_utf8.toml:1: invalid UTF-8"),
        (
            "absurd_count.toml",
            "absurd_count.toml:7: invalid value: integer `99999999999`, expected u32",
        ),
        (
            "negative_count.toml",
            "negative_count.toml:7: invalid value: integer `-4`, expected u32",
        ),
        (
            "missing_texture.toml",
            "missing_texture.toml:6: texture \"nowhere.png\" not found",
        ),
        (
            "wrong_count.toml",
            "wrong_count.toml:6: a Segment light takes 2 colors, not 3",
        ),
    ];
    // Every corpus file is a case, except the valid library the OBJ cases use.
    let corpus = std::fs::read_dir(bad(""))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().file_name() != "wood.mtl")
        .count();
    assert_eq!(corpus, cases.len(), "a corpus file has no case");
    for (file, expected) in cases {
        let err = load_bad(&bad(file)).expect_err(file).to_string();
        assert!(
            err.contains(&format!("/tests/data/bad/{expected}")),
            "{file}: expected {expected:?}, got {err:?}"
        );
    }
}

/// Loads a corpus file: an MTL library on its own, anything else as a scene.
fn load_bad(path: &str) -> Result<(), SceneError> {
    if path.ends_with(".mtl") {
        let bytes = error::read_file(Path::new(path))?;
        return obj::parse_mtl_bytes(Path::new(path), &bytes).map(drop);
    }
    load(path).map(drop)
}
