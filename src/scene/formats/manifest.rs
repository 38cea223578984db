//! Scene manifests: TOML files that place meshes, name the features a scene
//! exercises, and give its camera, lights and material overrides.
//!
//! ```toml
//! name = "cornell"                      # optional; defaults to the file stem
//! description = "..."                   # optional
//! features = ["shading", "hard_shadows"]  # see `Feature` for the names
//!
//! [[mesh]]                              # one or more
//! path = "cornell.obj"                  # relative to the manifest, or:
//! # asset = "npm:PACKAGE@VERSION/path/in/package"
//! material = "white"                    # optional: every triangle gets this material
//! subdivide = 2                         # optional: split every triangle into 4, this many
//!                                       # times (see `subdivide`; cached)
//! [mesh.transform]                      # optional; applied scale, rotate, translate
//! scale = 2.0                           # or [x, y, z]
//! rotate_axis = [0, 1, 0]               # default +y
//! rotate_deg = 90
//! translate = [0, 0, 1]
//!
//! [camera]                              # optional; by default the meshes are framed
//! eye = [278, 273, -800]
//! look_at = [278, 273, 0]
//! up = [0, 1, 0]                        # optional, default +y
//! fov_y_deg = 39.3
//!
//! [[light]]                             # zero or more; none gives a default point light
//! kind = "point"                        # point | segment | parallelogram
//! position = [278, 540, 279.5]          # point
//! # endpoints = [[x, y, z], [x, y, z]]  # segment
//! # corner = [x, y, z]                  # parallelogram: corner + s·edges[0] + t·edges[1],
//! # edges = [[x, y, z], [x, y, z]]      #   emitting towards edges[0] × edges[1]
//! # two_sided = false                   # parallelogram: emit on both sides
//! color = [1, 1, 1]                     # or colors = [...]: 2 (segment ends) or 4 (corners);
//!                                       # intensity (point, segment) or radiance
//!                                       # (parallelogram): see `Light`
//!
//! [[material]]                          # overrides by name; an unknown name adds a material
//! name = "mirror"
//! kd = [0.1, 0.1, 0.1]                  # every field optional
//! ks = [0.9, 0.9, 0.9]
//! shininess = 100
//! mirror = [0.9, 0.9, 0.9]
//! opacity = 1.0
//! texture = "wood.png"                  # relative to the manifest
//! filter = "bilinear"                   # texture filter: nearest | bilinear
//! roughness = 0.1                       # glossy reflection spread, 0 = mirror
//!
//! [render]                              # optional sample counts
//! samples_per_pixel = 1                 # jittered camera rays per pixel
//! light_samples = 16                    # stratified shadow rays per area light
//! glossy_samples = 8                    # reflection rays per glossy primary hit
//! max_depth = 4                         # reflection/transmission depth
//!
//! [bloom]                               # optional
//! threshold = 1.0                       # luminance above which pixels bloom
//! radius = 8                            # filter radius in pixels
//! filter = "gaussian"                   # gaussian | box
//! strength = 0.5                        # weight of the blur added back
//! ```
//!
//! A `[[mesh]]` with `velocity = [x, y, z]` moves by that much over the
//! shutter interval (motion blur) and is kept apart from the static meshes.
//!
//! Unknown keys are errors; every error names the manifest and the line.

use super::text::line_at;
use crate::geometry::TriangleMesh;
use crate::scene::error::{SceneError, read_file};
use crate::scene::feature::Feature;
use crate::scene::light::Light;
use crate::scene::material::Material;
use crate::scene::moving::MovingMesh;
use crate::scene::render_params::{BloomFilter, RenderParams};
use crate::scene::texture::{TextureFilter, TextureImage};
use crate::scene::transform::transform_mesh;
use crate::scene::{Camera, LoadedMesh, Scene, assets, frame, load_mesh_file, subdivide};
use glam::{Mat4, Quat, Vec3};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    name: Option<String>,
    #[serde(default)]
    description: String,
    #[serde(default)]
    features: Vec<Feature>,
    #[serde(default, rename = "mesh")]
    meshes: Vec<Spanned<MeshEntry>>,
    camera: Option<Spanned<CameraEntry>>,
    #[serde(default, rename = "light")]
    lights: Vec<Spanned<LightEntry>>,
    #[serde(default, rename = "material")]
    materials: Vec<Spanned<MaterialEntry>>,
    render: Option<Spanned<RenderEntry>>,
    bloom: Option<Spanned<BloomEntry>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderEntry {
    samples_per_pixel: Option<u32>,
    light_samples: Option<u32>,
    glossy_samples: Option<u32>,
    max_depth: Option<u32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BloomEntry {
    threshold: Option<f32>,
    radius: Option<u32>,
    filter: Option<BloomFilter>,
    strength: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshEntry {
    path: Option<String>,
    asset: Option<String>,
    transform: Option<TransformEntry>,
    material: Option<String>,
    velocity: Option<[f32; 3]>,
    subdivide: Option<u32>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct TransformEntry {
    scale: Option<Scale>,
    rotate_axis: Option<[f32; 3]>,
    rotate_deg: Option<f32>,
    translate: Option<[f32; 3]>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum Scale {
    Uniform(f32),
    PerAxis([f32; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraEntry {
    eye: [f32; 3],
    look_at: [f32; 3],
    up: Option<[f32; 3]>,
    fov_y_deg: f32,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Debug)]
#[serde(rename_all = "snake_case")]
enum LightKind {
    Point,
    Segment,
    Parallelogram,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightEntry {
    kind: LightKind,
    position: Option<[f32; 3]>,
    endpoints: Option<[[f32; 3]; 2]>,
    corner: Option<[f32; 3]>,
    edges: Option<[[f32; 3]; 2]>,
    color: Option<[f32; 3]>,
    colors: Option<Vec<[f32; 3]>>,
    two_sided: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialEntry {
    name: String,
    kd: Option<[f32; 3]>,
    ks: Option<[f32; 3]>,
    shininess: Option<f32>,
    mirror: Option<[f32; 3]>,
    opacity: Option<f32>,
    texture: Option<String>,
    filter: Option<TextureFilter>,
    roughness: Option<f32>,
}

/// A manifest read and checked on its own, before the files it names are
/// loaded: the camera, lights and render parameters are already converted.
pub struct ParsedManifest {
    manifest: Manifest,
    camera: Option<Camera>,
    lights: Vec<Light>,
    params: RenderParams,
}

/// Loads the manifest at `path` and everything it refers to.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let bytes = read_file(path)?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|e| SceneError::at(path, line_at(&bytes, e.valid_up_to()), "invalid UTF-8"))?;
    let parsed = parse_str(path, text)?;
    resolve(path, text, parsed)
}

/// Parses and checks manifest text without touching any other file; `path`
/// names the manifest in errors.
pub fn parse_str(path: &Path, text: &str) -> Result<ParsedManifest, SceneError> {
    let manifest: Manifest = toml::from_str(text).map_err(|e| {
        let line = e.span().map_or(1, |s| line_at(text.as_bytes(), s.start));
        SceneError::at(path, line, e.message().trim().to_string())
    })?;
    let at = |span: std::ops::Range<usize>, msg: String| {
        SceneError::at(path, line_at(text.as_bytes(), span.start), msg)
    };
    if manifest.meshes.is_empty() {
        return Err(SceneError::in_file(path, "no [[mesh]] entries"));
    }
    let params = RenderParams::default();
    let params = match &manifest.render {
        Some(entry) => apply_render(params, entry.get_ref()).map_err(|m| at(entry.span(), m))?,
        None => params,
    };
    let params = match &manifest.bloom {
        Some(entry) => apply_bloom(params, entry.get_ref()).map_err(|m| at(entry.span(), m))?,
        None => params,
    };
    let camera = manifest
        .camera
        .as_ref()
        .map(|entry| to_camera(entry.get_ref()).map_err(|m| at(entry.span(), m)))
        .transpose()?;
    let lights = manifest
        .lights
        .iter()
        .map(|entry| to_light(entry.get_ref()).map_err(|m| at(entry.span(), m)))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(ParsedManifest {
        manifest,
        camera,
        lights,
        params,
    })
}

/// Loads the meshes, materials and textures a parsed manifest names.
fn resolve(path: &Path, text: &str, parsed: ParsedManifest) -> Result<Scene, SceneError> {
    let ParsedManifest {
        manifest,
        camera,
        mut lights,
        params,
    } = parsed;
    let at = |span: std::ops::Range<usize>, msg: String| {
        SceneError::at(path, line_at(text.as_bytes(), span.start), msg)
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut mesh = TriangleMesh::default();
    let mut materials: Vec<Material> = Vec::new();
    let mut overrides = Vec::new();
    let mut moving: Vec<MovingMesh> = Vec::new();
    for entry in &manifest.meshes {
        let span = entry.span();
        let entry = entry.get_ref();
        let file = match (&entry.path, &entry.asset) {
            (Some(p), None) => dir.join(p),
            (None, Some(asset)) => assets::resolve(asset)?,
            _ => {
                return Err(at(
                    span,
                    "a [[mesh]] needs exactly one of `path` and `asset`".into(),
                ));
            }
        };
        if !file.is_file() {
            return Err(at(span, format!("mesh file {} not found", file.display())));
        }
        let LoadedMesh {
            mesh: mut part,
            materials: part_materials,
            ..
        } = load_mesh_file(&file)?;
        if let Some(levels) = entry.subdivide {
            part = subdivide::subdivided(&part, levels, &file)
                .map_err(|e| at(span.clone(), e.to_string()))?;
        }
        let transform = entry.transform.as_ref().map(to_matrix).transpose();
        transform_mesh(
            &mut part,
            transform
                .map_err(|m| at(span.clone(), m))?
                .unwrap_or_default(),
        );
        if let Some(velocity) = entry.velocity {
            let velocity = finite3(velocity, "velocity").map_err(|m| at(span.clone(), m))?;
            let mut alone = TriangleMesh::default();
            alone.append(&part, materials.len() as u32);
            materials.extend(part_materials);
            let layer = Layer::Moving(moving.len());
            moving.push(MovingMesh {
                mesh: alone,
                velocity,
            });
            if let Some(name) = &entry.material {
                let triangles = 0..moving[moving.len() - 1].mesh.indices.len();
                overrides.push((layer, triangles, name, span));
            }
            continue;
        }
        let first_triangle = mesh.indices.len();
        mesh.append(&part, materials.len() as u32);
        materials.extend(part_materials);
        if let Some(name) = &entry.material {
            overrides.push((Layer::Fixed, first_triangle..mesh.indices.len(), name, span));
        }
    }

    for entry in &manifest.materials {
        let span = entry.span();
        let entry = entry.get_ref();
        if !materials.iter().any(|m| m.name == entry.name) {
            materials.push(Material::named(&entry.name));
        }
        for material in materials.iter_mut().filter(|m| m.name == entry.name) {
            apply_override(material, entry, dir).map_err(|m| at(span.clone(), m))?;
        }
    }
    for (layer, triangles, name, span) in overrides {
        let id = materials
            .iter()
            .position(|m| &m.name == name)
            .ok_or_else(|| {
                at(
                    span,
                    format!(
                        "material {name:?} is defined neither by the mesh nor by a [[material]]"
                    ),
                )
            })?;
        let target = match layer {
            Layer::Fixed => &mut mesh,
            Layer::Moving(i) => &mut moving[i].mesh,
        };
        target.materials[triangles].fill(id as u32);
    }
    let textures = if manifest.features.contains(&Feature::Textures) {
        decode_textures(&materials)?
    } else {
        Vec::new()
    };
    let camera = camera.unwrap_or_else(|| frame::framing_camera(&mesh.bounds()));
    if lights.is_empty() {
        lights.push(frame::default_light(&mesh.bounds(), &camera));
    }
    Ok(Scene {
        name: manifest.name.unwrap_or_else(|| file_stem(path)),
        description: manifest.description,
        mesh,
        materials,
        camera,
        lights,
        features: manifest.features,
        source: path.to_path_buf(),
        moving,
        textures,
        params,
    })
}

/// Which mesh a `[[mesh]]` entry's triangles went into.
#[derive(Clone, Copy)]
enum Layer {
    Fixed,
    Moving(usize),
}

/// Decodes each distinct texture once; materials sharing a file share it.
pub(in crate::scene) fn decode_textures(
    materials: &[Material],
) -> Result<Vec<Option<Arc<TextureImage>>>, SceneError> {
    let mut decoded: Vec<(&Path, Arc<TextureImage>)> = Vec::new();
    let mut textures = Vec::with_capacity(materials.len());
    for material in materials {
        let Some(path) = material.diffuse_texture.as_deref() else {
            textures.push(None);
            continue;
        };
        let image = match decoded.iter().find(|(p, _)| *p == path) {
            Some((_, image)) => image.clone(),
            None => {
                let image = Arc::new(TextureImage::load(path)?);
                decoded.push((path, image.clone()));
                image
            }
        };
        textures.push(Some(image));
    }
    Ok(textures)
}

fn positive(value: Option<u32>, what: &str, default: u32) -> Result<u32, String> {
    match value {
        Some(0) => Err(format!("{what} must be at least 1")),
        Some(n) => Ok(n),
        None => Ok(default),
    }
}

fn apply_render(params: RenderParams, r: &RenderEntry) -> Result<RenderParams, String> {
    Ok(RenderParams {
        samples_per_pixel: positive(
            r.samples_per_pixel,
            "samples_per_pixel",
            params.samples_per_pixel,
        )?,
        light_samples: positive(r.light_samples, "light_samples", params.light_samples)?,
        glossy_samples: positive(r.glossy_samples, "glossy_samples", params.glossy_samples)?,
        max_depth: r.max_depth.unwrap_or(params.max_depth),
        ..params
    })
}

fn apply_bloom(params: RenderParams, b: &BloomEntry) -> Result<RenderParams, String> {
    let mut bloom = params.bloom;
    if let Some(threshold) = b.threshold {
        bloom.threshold = finite1(threshold, "threshold")?;
    }
    if let Some(strength) = b.strength {
        if !(strength.is_finite() && strength >= 0.0) {
            return Err(format!(
                "strength {strength} must be finite and not negative"
            ));
        }
        bloom.strength = strength;
    }
    bloom.radius = b.radius.unwrap_or(bloom.radius);
    bloom.filter = b.filter.unwrap_or(bloom.filter);
    Ok(RenderParams { bloom, ..params })
}

pub(in crate::scene) fn file_stem(path: &Path) -> String {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    name.split('.').next().unwrap_or_default().to_string()
}

fn finite3(values: [f32; 3], what: &str) -> Result<Vec3, String> {
    let v = Vec3::from(values);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{what} must be finite, got {values:?}"))
    }
}

fn finite1(value: f32, what: &str) -> Result<f32, String> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("{what} must be finite, got {value}"))
    }
}

fn to_matrix(t: &TransformEntry) -> Result<Mat4, String> {
    let scale = match t.scale {
        None => Vec3::ONE,
        Some(Scale::Uniform(s)) => finite3([s; 3], "scale")?,
        Some(Scale::PerAxis(s)) => finite3(s, "scale")?,
    };
    if scale.cmpeq(Vec3::ZERO).any() {
        return Err(format!("scale {scale} has a zero component"));
    }
    let axis = finite3(t.rotate_axis.unwrap_or([0.0, 1.0, 0.0]), "rotate_axis")?;
    let angle = finite1(t.rotate_deg.unwrap_or(0.0), "rotate_deg")?;
    if axis.length_squared() == 0.0 {
        return Err("rotate_axis must not be zero".into());
    }
    let rotation = Quat::from_axis_angle(axis.normalize(), angle.to_radians());
    let translation = finite3(t.translate.unwrap_or_default(), "translate")?;
    Ok(Mat4::from_scale_rotation_translation(
        scale,
        rotation,
        translation,
    ))
}

fn to_camera(c: &CameraEntry) -> Result<Camera, String> {
    let camera = Camera {
        eye: finite3(c.eye, "eye")?,
        look_at: finite3(c.look_at, "look_at")?,
        up: finite3(c.up.unwrap_or([0.0, 1.0, 0.0]), "up")?,
        fov_y_deg: c.fov_y_deg,
    };
    if !(camera.fov_y_deg > 0.0 && camera.fov_y_deg < 180.0) {
        return Err(format!(
            "fov_y_deg {} is not between 0 and 180",
            c.fov_y_deg
        ));
    }
    let forward = camera.look_at - camera.eye;
    if forward.length_squared() == 0.0 || forward.cross(camera.up).length_squared() == 0.0 {
        return Err("the camera's eye, look_at and up do not define a view".into());
    }
    Ok(camera)
}

fn to_light(l: &LightEntry) -> Result<Light, String> {
    let kind = l.kind;
    let expected = match kind {
        LightKind::Point => 1,
        LightKind::Segment => 2,
        LightKind::Parallelogram => 4,
    };
    let colors: Vec<Vec3> = match (&l.color, &l.colors) {
        (Some(_), Some(_)) => return Err("give `color` or `colors`, not both".into()),
        (None, None) => vec![Vec3::ONE; expected],
        (Some(c), None) => vec![finite3(*c, "color")?; expected],
        (None, Some(cs)) if cs.len() == expected && kind != LightKind::Point => cs
            .iter()
            .map(|c| finite3(*c, "colors"))
            .collect::<Result<_, _>>()?,
        (None, Some(cs)) => {
            return Err(format!(
                "a {kind:?} light takes {expected} colors, not {}",
                cs.len()
            ));
        }
    };
    let fields = [
        ("position", l.position.is_some(), LightKind::Point),
        ("endpoints", l.endpoints.is_some(), LightKind::Segment),
        ("corner", l.corner.is_some(), LightKind::Parallelogram),
        ("edges", l.edges.is_some(), LightKind::Parallelogram),
    ];
    if let Some((name, ..)) = fields
        .iter()
        .find(|(_, present, owner)| *present && *owner != kind)
    {
        return Err(format!("a {kind:?} light does not take `{name}`"));
    }
    if let Some((name, ..)) = fields
        .iter()
        .find(|(_, present, owner)| !*present && *owner == kind)
    {
        return Err(format!("a {kind:?} light needs `{name}`"));
    }
    if l.two_sided.is_some() && kind != LightKind::Parallelogram {
        return Err(format!(
            "a {kind:?} light has no side to emit on: `two_sided` is for parallelograms"
        ));
    }
    Ok(match kind {
        LightKind::Point => Light::Point {
            position: finite3(l.position.unwrap_or_default(), "position")?,
            color: colors[0],
        },
        LightKind::Segment => {
            let [a, b] = l.endpoints.unwrap_or_default();
            Light::Segment {
                a: finite3(a, "endpoints")?,
                b: finite3(b, "endpoints")?,
                colors: [colors[0], colors[1]],
            }
        }
        LightKind::Parallelogram => {
            let [u, v] = l.edges.unwrap_or_default();
            let light = Light::Parallelogram {
                corner: finite3(l.corner.unwrap_or_default(), "corner")?,
                edge_u: finite3(u, "edges")?,
                edge_v: finite3(v, "edges")?,
                colors: [colors[0], colors[1], colors[2], colors[3]],
                two_sided: l.two_sided.unwrap_or(false),
            };
            if !(light.area() > 0.0 && light.area().is_finite()) {
                return Err(format!(
                    "the edges {u:?} and {v:?} span no area: a parallelogram light needs two \
                     edges that are not parallel"
                ));
            }
            light
        }
    })
}

fn apply_override(
    material: &mut Material,
    entry: &MaterialEntry,
    dir: &Path,
) -> Result<(), String> {
    if let Some(kd) = entry.kd {
        material.kd = finite3(kd, "kd")?;
    }
    if let Some(ks) = entry.ks {
        material.ks = finite3(ks, "ks")?;
    }
    if let Some(mirror) = entry.mirror {
        material.mirror = finite3(mirror, "mirror")?;
    }
    if let Some(roughness) = entry.roughness {
        if !(0.0..=1.0).contains(&roughness) {
            return Err(format!("roughness {roughness} is not between 0 and 1"));
        }
        material.roughness = roughness;
    }
    if let Some(filter) = entry.filter {
        material.texture_filter = filter;
    }
    if let Some(shininess) = entry.shininess {
        material.shininess = finite1(shininess, "shininess")?;
    }
    if let Some(opacity) = entry.opacity {
        if !(0.0..=1.0).contains(&opacity) {
            return Err(format!("opacity {opacity} is not between 0 and 1"));
        }
        material.opacity = opacity;
    }
    if let Some(texture) = &entry.texture {
        let file: PathBuf = dir.join(texture);
        if !file.is_file() {
            return Err(format!(
                "texture {texture:?} not found (looked for {})",
                file.display()
            ));
        }
        material.diffuse_texture = Some(file);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_material_overrides_and_lights_are_applied() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("tri.obj"),
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        image::save_buffer(
            dir.path().join("grain.png"),
            &[200, 150, 100],
            1,
            1,
            image::ExtendedColorType::Rgb8,
        )
        .unwrap();
        let manifest = dir.path().join("s.toml");
        std::fs::write(
            &manifest,
            r#"features = ["area_lights", "textures"]
[[mesh]]
path = "tri.obj"
[[mesh]]
path = "tri.obj"
material = "wood"
transform = { scale = 2, rotate_deg = 90, rotate_axis = [0, 0, 1], translate = [5, 0, 0] }
[[material]]
name = "wood"
kd = [0.5, 0.3, 0.1]
texture = "grain.png"
[[light]]
kind = "parallelogram"
corner = [0, 2, 0]
edges = [[1, 0, 0], [0, 0, 1]]
colors = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]]
[[light]]
kind = "segment"
endpoints = [[0, 0, 0], [0, 0, 2]]
"#,
        )
        .unwrap();
        let scene = load(&manifest).unwrap();
        assert_eq!(scene.name, "s");
        assert_eq!(scene.features, [Feature::AreaLights, Feature::Textures]);
        assert_eq!(scene.mesh.triangle_count(), 2);
        // (1, 0, 0) scaled by 2, turned 90° about z, moved by +5 in x.
        let moved = scene.mesh.triangle(1)[1];
        assert!(
            (moved - Vec3::new(5.0, 2.0, 0.0)).length() < 1e-5,
            "{moved}"
        );
        let wood = &scene.materials[scene.mesh.materials[1] as usize];
        assert_eq!(wood.name, "wood");
        assert_eq!(wood.kd, Vec3::new(0.5, 0.3, 0.1));
        assert_eq!(wood.diffuse_texture, Some(dir.path().join("grain.png")));
        assert_eq!(
            scene.materials[scene.mesh.materials[0] as usize].name,
            "default"
        );
        assert_eq!(
            scene.lights[0].representative_point(),
            Vec3::new(0.5, 2.0, 0.5)
        );
        assert_eq!(scene.lights[1].mean_color(), Vec3::ONE);
        // One-sided unless asked, facing edges[0] × edges[1] = x × z = -y.
        assert!(matches!(
            scene.lights[0],
            Light::Parallelogram {
                two_sided: false,
                ..
            }
        ));
        assert_eq!(scene.lights[0].normal(), Some(Vec3::NEG_Y));
        let err = |text: &str| {
            std::fs::write(&manifest, text).unwrap();
            load(&manifest).unwrap_err().to_string()
        };
        let wrong_colors = err(
            "[[mesh]]\npath = \"tri.obj\"\n[[light]]\nkind = \"segment\"\nendpoints = [[0, 0, 0], [1, 1, 1]]\ncolors = [[1, 1, 1]]\n",
        );
        assert!(
            wrong_colors.ends_with("s.toml:3: a Segment light takes 2 colors, not 1"),
            "{wrong_colors}"
        );
        let sided_segment = err(
            "[[mesh]]\npath = \"tri.obj\"\n[[light]]\nkind = \"segment\"\nendpoints = [[0, 0, 0], [1, 1, 1]]\ntwo_sided = true\n",
        );
        assert!(
            sided_segment.ends_with(
                "s.toml:3: a Segment light has no side to emit on: `two_sided` is for parallelograms"
            ),
            "{sided_segment}"
        );
        let flat = err(
            "[[mesh]]\npath = \"tri.obj\"\n[[light]]\nkind = \"parallelogram\"\ncorner = [0, 0, 0]\nedges = [[1, 0, 0], [2, 0, 0]]\n",
        );
        assert!(flat.contains("s.toml:3: the edges"), "{flat}");
        assert!(flat.ends_with("edges that are not parallel"), "{flat}");
        std::fs::write(
            &manifest,
            "[[mesh]]\npath = \"tri.obj\"\n[[light]]\nkind = \"parallelogram\"\ncorner = [0, 0, 0]\nedges = [[1, 0, 0], [0, 1, 0]]\ntwo_sided = true\n",
        )
        .unwrap();
        assert!(matches!(
            load(&manifest).unwrap().lights[0],
            Light::Parallelogram {
                two_sided: true,
                ..
            }
        ));
        let no_material = err(
            "[[mesh]]\npath = \"tri.obj\"\n\n[[mesh]]\npath = \"tri.obj\"\nmaterial = \"nope\"\n",
        );
        assert!(
            no_material.ends_with(
                "s.toml:4: material \"nope\" is defined neither by the mesh nor by a [[material]]"
            ),
            "{no_material}"
        );
    }
}
