//! Scenes: manifests, mesh loaders, packaged assets, cameras, lights and materials.
//!
//! [`load`] takes a built-in scene name (`cornell`, `monkey`, `dragon-11k`,
//! ...: a manifest `scenes/<name>.toml`) or a path to a manifest (`.toml`)
//! or a bare mesh (`.obj`, `.ply`, `.ply.gz`, `.glb`). A bare mesh gets a
//! camera that frames it, one point light near the camera, the features
//! `shading` and `hard_shadows`, and those its content calls for (see
//! [`frame::bare_mesh_features`]: a diffuse texture turns on `textures`, a
//! mirror `reflection`, an opacity below 1 `transparency`). The manifest
//! format is documented in [`formats::manifest`]. Every error is a [`SceneError`]
//! naming the file, and the line where the format has lines; every
//! [`LoadWarning`] (input loaded without its faulty part) is printed on
//! stderr as the mesh loads.

pub mod assets;
pub mod camera;
pub mod error;
pub mod feature;
pub mod formats;
pub mod frame;
pub mod light;
pub mod material;
pub mod moving;
pub mod render_params;
pub mod subdivide;
pub mod suite;
pub mod texture;
mod transform;
pub mod warning;

pub use camera::Camera;
pub use error::SceneError;
pub use feature::Feature;
pub use light::Light;
pub use material::Material;
pub use moving::MovingMesh;
pub use render_params::{BloomFilter, BloomParams, RenderParams};
pub use suite::{BENCHMARK_SCENES, QUICK_SCENES, SCALE_SCENES, benchmark_scenes};
pub use texture::{TextureFilter, TextureImage};
pub use warning::LoadWarning;

use crate::geometry::TriangleMesh;
use formats::{data_uri_module, glb, manifest, obj, ply};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Everything a render needs: all meshes flattened into one (triangle ids
/// are global), the materials `mesh.materials` indexes, a camera and lights.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    /// One line for reports; empty for a bare mesh.
    pub description: String,
    pub mesh: TriangleMesh,
    pub materials: Vec<Material>,
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub features: Vec<Feature>,
    /// The manifest or mesh file the scene came from.
    pub source: PathBuf,
    /// Meshes moving during the shutter (`motion_blur`), apart from `mesh`.
    pub moving: Vec<MovingMesh>,
    /// The decoded diffuse texture of each material, by material id; empty
    /// unless the scene lists `textures`.
    pub textures: Vec<Option<Arc<TextureImage>>>,
    pub params: RenderParams,
}

impl Scene {
    /// Every mesh layer: `mesh`, then each moving mesh. Renders and checks
    /// take one intersector per layer, in this order.
    pub fn meshes(&self) -> Vec<&TriangleMesh> {
        std::iter::once(&self.mesh)
            .chain(self.moving.iter().map(|m| &m.mesh))
            .collect()
    }

    /// Whether the scene is a bare mesh file rather than a manifest.
    pub fn is_bare_mesh(&self) -> bool {
        MeshFormat::of(&self.source).is_some()
    }

    /// Layer `layer` of [`Scene::meshes`].
    pub fn layer_mesh(&self, layer: usize) -> &TriangleMesh {
        match layer {
            0 => &self.mesh,
            i => &self.moving[i - 1].mesh,
        }
    }
}

/// A mesh as one loader produced it, with the materials its triangles index.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    pub mesh: TriangleMesh,
    pub materials: Vec<Material>,
    /// What was left out of the file, and why.
    pub warnings: Vec<LoadWarning>,
}

/// Loads a built-in scene by name, or a manifest or mesh file by path.
pub fn load(spec: &str) -> Result<Scene, SceneError> {
    let path = Path::new(spec);
    if MeshFormat::of(path).is_some()
        || path.extension().is_some_and(|e| e == "toml")
        || path.is_file()
    {
        return load_path(path);
    }
    let manifest = scenes_dir().join(format!("{spec}.toml"));
    if manifest.is_file() {
        return manifest::load(&manifest);
    }
    Err(SceneError::UnknownScene {
        name: spec.to_string(),
        known: builtin_names()?,
    })
}

/// The built-in scene names (manifests in the scenes folder), sorted.
pub fn builtin_names() -> Result<Vec<String>, SceneError> {
    let dir = scenes_dir();
    let entries = std::fs::read_dir(&dir).map_err(|e| SceneError::io(&dir, e))?;
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    names.sort();
    Ok(names)
}

/// The folder of built-in scenes: `$RAYCHECK_SCENES`, else the crate's `scenes/`.
pub fn scenes_dir() -> PathBuf {
    std::env::var_os("RAYCHECK_SCENES")
        .filter(|v| !v.is_empty())
        .map_or_else(
            || PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes")),
            PathBuf::from,
        )
}

fn load_path(path: &Path) -> Result<Scene, SceneError> {
    if path.extension().is_some_and(|e| e == "toml") {
        return manifest::load(path);
    }
    let LoadedMesh {
        mesh, materials, ..
    } = load_mesh_file(path)?;
    let bounds = mesh.bounds();
    let camera = frame::framing_camera(&bounds);
    let mut scene = Scene {
        name: manifest::file_stem(path),
        description: String::new(),
        lights: vec![frame::default_light(&bounds, &camera)],
        camera,
        mesh,
        materials,
        features: Vec::new(),
        source: path.to_path_buf(),
        moving: Vec::new(),
        textures: Vec::new(),
        params: RenderParams::default(),
    };
    scene.features = frame::bare_mesh_features(&scene);
    if scene.features.contains(&Feature::Textures) {
        scene.textures = manifest::decode_textures(&scene.materials)?;
    }
    Ok(scene)
}

/// The mesh formats, told apart by file name.
#[derive(Clone, Copy, Debug, PartialEq)]
enum MeshFormat {
    Obj,
    Ply,
    Glb,
    DataUriModule,
}

impl MeshFormat {
    fn of(path: &Path) -> Option<Self> {
        let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
        [
            (".obj", MeshFormat::Obj),
            (".ply", MeshFormat::Ply),
            (".ply.gz", MeshFormat::Ply),
            (".glb", MeshFormat::Glb),
            (".js", MeshFormat::DataUriModule),
        ]
        .into_iter()
        .find(|(suffix, _)| name.ends_with(suffix))
        .map(|(_, format)| format)
    }
}

/// Loads one mesh file, choosing the loader by its name, and prints its
/// warnings on stderr.
pub fn load_mesh_file(path: &Path) -> Result<LoadedMesh, SceneError> {
    let loaded = parse_mesh_file(path)?;
    for warning in &loaded.warnings {
        eprintln!("{warning}");
    }
    Ok(loaded)
}

fn parse_mesh_file(path: &Path) -> Result<LoadedMesh, SceneError> {
    match MeshFormat::of(path) {
        Some(MeshFormat::Obj) => obj::load(path),
        Some(MeshFormat::Ply) => ply::load(path),
        Some(MeshFormat::Glb) => glb::load(path),
        Some(MeshFormat::DataUriModule) => data_uri_module::load(path),
        None => Err(SceneError::in_file(
            path,
            "unsupported mesh format (expected .obj, .ply, .ply.gz, .glb or .js)",
        )),
    }
}

#[cfg(test)]
mod tests;
