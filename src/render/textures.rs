//! Texture mapping (Catmull 1974; Heckbert 1986, "Survey of Texture
//! Mapping"): texture coordinates interpolated with the hit's barycentrics,
//! wrapped (repeat) into [0, 1), and the diffuse colour looked up with
//! nearest or bilinear filtering. `v` grows upward, as in OBJ files.

use crate::geometry::TriangleMesh;
use crate::scene::{TextureFilter, TextureImage};
use glam::Vec2;
use glam::Vec3;

/// The texture coordinates at barycentrics (`u`, `v`) of triangle `prim`.
pub fn texcoord(mesh: &TriangleMesh, prim: u32, u: f32, v: f32) -> Option<Vec2> {
    let texcoords = mesh.texcoords.as_ref()?;
    let [a, b, c] = mesh.indices[prim as usize].map(|i| texcoords[i as usize]);
    Some((1.0 - u - v) * a + u * b + v * c)
}

/// The texture's colour at `uv`.
pub fn lookup(texture: &TextureImage, filter: TextureFilter, uv: Vec2) -> Vec3 {
    let size = Vec2::new(texture.width as f32, texture.height as f32);
    // Continuous texel coordinates: texel (i, j) covers [i, i+1) x [j, j+1),
    // row 0 at the top.
    let wrapped = uv - uv.floor();
    let p = Vec2::new(wrapped.x, 1.0 - wrapped.y) * size;
    match filter {
        TextureFilter::Nearest => {
            let x = wrap(p.x.floor() as i64, texture.width);
            let y = wrap(p.y.floor() as i64, texture.height);
            texture.texel(x, y)
        }
        TextureFilter::Bilinear => {
            let q = p - 0.5;
            let base = q.floor();
            let f = q - base;
            let at = |dx: i64, dy: i64| {
                texture.texel(
                    wrap(base.x as i64 + dx, texture.width),
                    wrap(base.y as i64 + dy, texture.height),
                )
            };
            let top = at(0, 0).lerp(at(1, 0), f.x);
            let bottom = at(0, 1).lerp(at(1, 1), f.x);
            top.lerp(bottom, f.y)
        }
    }
}

fn wrap(i: i64, n: u32) -> u32 {
    i.rem_euclid(n as i64) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> TextureImage {
        // Row 0 (top): black, white; row 1: red, green.
        TextureImage {
            width: 2,
            height: 2,
            texels: vec![Vec3::ZERO, Vec3::ONE, Vec3::X, Vec3::Y],
        }
    }

    #[test]
    fn nearest_picks_the_texel_and_v_grows_upward() {
        let t = checker();
        assert_eq!(
            lookup(&t, TextureFilter::Nearest, Vec2::new(0.25, 0.75)),
            Vec3::ZERO
        );
        assert_eq!(
            lookup(&t, TextureFilter::Nearest, Vec2::new(0.75, 0.75)),
            Vec3::ONE
        );
        assert_eq!(
            lookup(&t, TextureFilter::Nearest, Vec2::new(0.25, 0.25)),
            Vec3::X
        );
        assert_eq!(
            lookup(&t, TextureFilter::Nearest, Vec2::new(1.75, -0.75)),
            Vec3::Y
        );
    }

    #[test]
    fn bilinear_is_exact_at_centres_and_averages_between() {
        let t = checker();
        assert_eq!(
            lookup(&t, TextureFilter::Bilinear, Vec2::new(0.25, 0.75)),
            Vec3::ZERO
        );
        let middle = lookup(&t, TextureFilter::Bilinear, Vec2::new(0.5, 0.5));
        assert!(
            (middle - Vec3::new(0.5, 0.5, 0.25)).length() < 1e-6,
            "{middle}"
        );
    }
}
