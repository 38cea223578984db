//! The rendering features a scene asks for, and what in a scene each one
//! acts on; the renderer builds its passes from both.

use super::{Light, Material, Scene};
use serde::Deserialize;

/// A rendering feature, named in manifests in snake_case (`hard_shadows`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Feature {
    Shading,
    HardShadows,
    Reflection,
    AreaLights,
    NormalInterpolation,
    Textures,
    MotionBlur,
    Bloom,
    Multisample,
    Glossy,
    Transparency,
}

impl Feature {
    pub const ALL: [Feature; 11] = [
        Feature::Shading,
        Feature::HardShadows,
        Feature::Reflection,
        Feature::AreaLights,
        Feature::NormalInterpolation,
        Feature::Textures,
        Feature::MotionBlur,
        Feature::Bloom,
        Feature::Multisample,
        Feature::Glossy,
        Feature::Transparency,
    ];

    /// The manifest spelling.
    pub fn name(self) -> &'static str {
        match self {
            Feature::Shading => "shading",
            Feature::HardShadows => "hard_shadows",
            Feature::Reflection => "reflection",
            Feature::AreaLights => "area_lights",
            Feature::NormalInterpolation => "normal_interpolation",
            Feature::Textures => "textures",
            Feature::MotionBlur => "motion_blur",
            Feature::Bloom => "bloom",
            Feature::Multisample => "multisample",
            Feature::Glossy => "glossy",
            Feature::Transparency => "transparency",
        }
    }
}

impl Feature {
    /// What in `scene` this feature acts on, described (`Ok`), or why it
    /// has nothing to act on (`Err`). Only materials some triangle uses
    /// count; `bloom` and `multisample` act on every image.
    pub fn support(self, scene: &Scene) -> Result<String, String> {
        let material = |test: fn(&Material) -> bool| used_materials(scene).find(|m| test(m));
        let meshes = scene.meshes();
        match self {
            Feature::Shading => Ok(match scene.lights.len() {
                1 => "1 light".to_string(),
                n => format!("{n} lights"),
            }),
            Feature::HardShadows => scene
                .lights
                .iter()
                .find(|l| matches!(l, Light::Point { .. }))
                .map(|l| format!("a point light at {}", l.representative_point()))
                .ok_or_else(|| "no point light".into()),
            Feature::AreaLights => scene
                .lights
                .iter()
                .find(|l| !matches!(l, Light::Point { .. }))
                .map(|l| format!("an area light centred at {}", l.representative_point()))
                .ok_or_else(|| "no segment or parallelogram light".into()),
            Feature::Reflection => material(|m| m.mirror.max_element() > 0.0)
                .map(|m| {
                    format!(
                        "material {:?} is a mirror (reflectance {})",
                        m.name, m.mirror
                    )
                })
                .ok_or_else(|| "no material in use is a mirror".into()),
            Feature::Glossy => material(|m| m.mirror.max_element() > 0.0 && m.roughness > 0.0)
                .map(|m| {
                    format!(
                        "material {:?} is a glossy mirror (roughness {})",
                        m.name, m.roughness
                    )
                })
                .ok_or_else(|| "no mirror in use has a roughness above 0".into()),
            Feature::Transparency => material(|m| m.opacity < 1.0)
                .map(|m| format!("material {:?} has opacity {}", m.name, m.opacity))
                .ok_or_else(|| "every material in use is opaque".into()),
            Feature::NormalInterpolation => meshes
                .iter()
                .any(|m| m.normals.is_some())
                .then(|| "the mesh has vertex normals".to_string())
                .ok_or_else(|| "no mesh has vertex normals".into()),
            Feature::Textures => {
                let has = used_materials(scene)
                    .find_map(|m| {
                        let texture = m.diffuse_texture.as_ref()?;
                        Some(format!(
                            "material {:?} has diffuse texture {}",
                            m.name,
                            texture.display()
                        ))
                    })
                    .ok_or("no material in use has a diffuse texture")?;
                if meshes.iter().any(|m| m.texcoords.is_some()) {
                    Ok(has)
                } else {
                    Err(format!("{has}, but no mesh has texture coordinates"))
                }
            }
            Feature::MotionBlur => match scene.moving.len() {
                0 => Err("nothing moves".into()),
                1 => Ok("1 moving mesh".into()),
                n => Ok(format!("{n} moving meshes")),
            },
            Feature::Bloom => Ok("a post-process of the whole image".into()),
            Feature::Multisample => Ok("jittered camera samples in every pixel".into()),
        }
    }
}

/// The materials some triangle of `scene` uses, in material order.
fn used_materials(scene: &Scene) -> impl Iterator<Item = &Material> {
    let mut used = vec![false; scene.materials.len()];
    for mesh in scene.meshes() {
        for &id in &mesh.materials {
            if let Some(flag) = used.get_mut(id as usize) {
                *flag = true;
            }
        }
    }
    scene
        .materials
        .iter()
        .zip(used)
        .filter_map(|(material, used)| used.then_some(material))
}

impl std::fmt::Display for Feature {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Deserialize)]
    struct Wrapper {
        feature: Feature,
    }

    #[test]
    fn every_name_deserializes_to_its_feature() {
        for feature in Feature::ALL {
            let parsed: Wrapper = toml::from_str(&format!("feature = \"{feature}\"")).unwrap();
            assert_eq!(parsed.feature, feature);
        }
    }
}
