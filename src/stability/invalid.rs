//! Case 10: NaN and infinities in ray origins, directions, `tnear` and
//! `tfar`, and in vertex data. No panic, no hit on an invalid ray, no NaN
//! out; triangles with invalid corners are dropped as Embree drops them.

use super::harness::Backends;
use super::{CaseDetails, CaseResult, Context};
use crate::geometry::{Ray, TriangleMesh};
use glam::Vec3;

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let (nan, inf) = (f32::NAN, f32::INFINITY);
    let quad = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
    ];
    let mut triangles = vec![quad];
    for bad in [nan, inf, -inf, 1e19, -2e18] {
        for corner in 0..3 {
            let mut t = quad;
            t[corner].x = bad;
            triangles.push(t);
        }
    }
    let mesh = TriangleMesh::soup(&triangles);
    let backends = Backends::new(context, &mesh)?;
    let valid = Ray::new(Vec3::new(0.5, -0.5, 1.0), Vec3::new(0.0, 0.0, -1.0));
    let specials = [nan, inf, -inf, 0.0, -0.0];
    let mut rays = vec![valid];
    for input in 0..8 {
        for &value in &specials {
            let mut v = [
                valid.origin.x,
                valid.origin.y,
                valid.origin.z,
                valid.dir.x,
                valid.dir.y,
                valid.dir.z,
                valid.tnear,
                valid.tfar,
            ];
            v[input] = value;
            rays.push(Ray::segment(
                Vec3::new(v[0], v[1], v[2]),
                Vec3::new(v[3], v[4], v[5]),
                v[6],
                v[7],
            ));
        }
    }
    let mut result = CaseResult::judged("nan_and_inf", backends.trace(&rays));
    result.details = CaseDetails::Dropped {
        dropped_triangles: triangles.len() - 1,
    };
    Ok(result)
}
