//! Phong shading (Phong 1975, "Illumination for Computer Generated
//! Pictures"): a diffuse term `kd·max(0, n·l)` and a specular term
//! `ks·max(0, r·v)^shininess` per light (`kd` from the texture where there
//! is one), scaled by the irradiance the light
//! delivers: the intensity a light (or a sample of one, see
//! [`super::area_lights`]) sends towards the point, falling off with the
//! inverse square of the distance.

use super::surface::SurfacePoint;
use crate::scene::Material;
use glam::Vec3;

/// A small constant ambient term, so that fully shadowed surfaces keep their
/// colour instead of turning black.
pub const AMBIENT: f32 = 0.04;

/// The cosine `n·l` between the shading normal at `surface` and the
/// direction `to_light` (unit length) to a light in front of it; `None`
/// when the light is behind, so that it adds nothing and needs no shadow
/// ray (a NaN cosine is passed on, not taken for a light behind).
pub fn facing_cosine(surface: &SurfacePoint, to_light: Vec3) -> Option<f32> {
    let n_dot_l = surface.normal.dot(to_light);
    if n_dot_l <= 0.0 { None } else { Some(n_dot_l) }
}

/// The Phong response at `surface`, of diffuse colour `diffuse`, to a light
/// of `irradiance` arriving from direction `to_light` (unit length) at the
/// cosine `n_dot_l` ([`facing_cosine`]).
pub fn phong(
    material: &Material,
    diffuse: Vec3,
    surface: &SurfacePoint,
    to_light: Vec3,
    n_dot_l: f32,
    irradiance: Vec3,
) -> Vec3 {
    let reflected = 2.0 * n_dot_l * surface.normal - to_light;
    let r_dot_v = reflected.dot(surface.to_viewer).max(0.0);
    let specular = if material.shininess > 0.0 && r_dot_v > 0.0 {
        material.ks * r_dot_v.powf(material.shininess)
    } else {
        Vec3::ZERO
    };
    (diffuse * n_dot_l + specular) * irradiance
}

/// The ambient term of a surface of diffuse colour `diffuse`.
pub fn ambient(diffuse: Vec3) -> Vec3 {
    AMBIENT * diffuse
}

/// The irradiance from intensity `color` at distance² `distance_squared`
/// (on a surface facing it; `phong` applies the surface's cosine).
pub fn inverse_square(color: Vec3, distance_squared: f32) -> Vec3 {
    color / distance_squared.max(f32::MIN_POSITIVE)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn facing_up(normal: Vec3) -> SurfacePoint {
        SurfacePoint {
            position: Vec3::ZERO,
            normal,
            geometric_normal: Vec3::Z,
            to_viewer: Vec3::Z,
            material: 0,
            prim: 0,
            u: 0.0,
            v: 0.0,
        }
    }

    /// A light in front gives its cosine, one behind or grazing none, and
    /// a NaN shading normal still asks its shadow ray, as it did before
    /// the cosine was taken apart from the response.
    #[test]
    fn the_cosine_decides_which_lights_need_a_shadow_ray() {
        let surface = facing_up(Vec3::Z);
        let slanted = Vec3::new(0.6, 0.0, 0.8);
        assert_eq!(facing_cosine(&surface, slanted), Some(slanted.z));
        assert_eq!(facing_cosine(&surface, -Vec3::Z), None);
        assert_eq!(facing_cosine(&surface, Vec3::X), None);
        let cosine = facing_cosine(&facing_up(Vec3::NAN), Vec3::Z);
        assert!(cosine.is_some_and(f32::is_nan), "{cosine:?}");
    }
}
