//! Proves the hand-written `RTCRayHit`/`RTCRay` match the linked library:
//! guard words placed right after each struct must survive real
//! `rtcIntersect1`/`rtcOccluded1` calls, and the answers must be right.

use std::ptr;

use crate::ffi::{self, RtcHit, RtcRay, RtcRayHit};
use crate::{Device, DeviceConfig, SceneOptions, TriangleMeshRef};

const GUARD: u32 = 0xA5A5_A5A5;

/// A struct followed directly by guard words, as on a caller's stack.
#[repr(C)]
struct Guarded<T> {
    value: T,
    guard: [u32; 16],
}

fn down_the_z_axis_at(x: f32, y: f32) -> RtcRay {
    RtcRay {
        org_x: x,
        org_y: y,
        org_z: 1.0,
        dir_z: -1.0,
        tfar: f32::INFINITY,
        mask: u32::MAX,
        ..RtcRay::default()
    }
}

#[test]
fn embree_writes_nothing_past_the_ray_and_hit_structs() {
    crate::enable_flush_to_zero_and_denormals_are_zero();
    let device = Device::new(&DeviceConfig::default()).unwrap();
    let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let indices = [[0, 1, 2]];
    let mesh = TriangleMeshRef {
        positions: &positions,
        indices: &indices,
    };
    let scene = device
        .build_scene(&[mesh], SceneOptions::default())
        .unwrap();

    for (x, y, hits) in [(0.25, 0.5, true), (2.0, 2.0, false)] {
        let mut ray_hit = Guarded {
            value: RtcRayHit {
                ray: down_the_z_axis_at(x, y),
                hit: RtcHit {
                    geom_id: ffi::RTC_INVALID_GEOMETRY_ID,
                    inst_id: [ffi::RTC_INVALID_GEOMETRY_ID],
                    inst_prim_id: [ffi::RTC_INVALID_GEOMETRY_ID],
                    ..RtcHit::default()
                },
            },
            guard: [GUARD; 16],
        };
        // SAFETY: a committed scene and a valid ray/hit; default arguments.
        unsafe { ffi::rtcIntersect1(scene.raw(), &mut ray_hit.value, ptr::null_mut()) };
        assert_eq!(
            ray_hit.guard, [GUARD; 16],
            "rtcIntersect1 wrote past RTCRayHit"
        );
        let hit = ray_hit.value.hit;
        if hits {
            // Embree divides by an approximate reciprocal: a few ulps off.
            let t = ray_hit.value.ray.tfar;
            assert!((t - 1.0).abs() < 1e-6, "t = {t}");
            assert!((hit.u - 0.25).abs() < 1e-6 && (hit.v - 0.5).abs() < 1e-6);
            assert_eq!((hit.geom_id, hit.prim_id), (0, 0));
            assert_eq!([hit.ng_x, hit.ng_y, hit.ng_z], [0.0, 0.0, 1.0]);
            assert_eq!(hit.inst_id, [ffi::RTC_INVALID_GEOMETRY_ID]);
        } else {
            assert_eq!(hit.geom_id, ffi::RTC_INVALID_GEOMETRY_ID);
            assert_eq!(ray_hit.value.ray.tfar, f32::INFINITY);
        }

        let mut ray = Guarded {
            value: down_the_z_axis_at(x, y),
            guard: [GUARD; 16],
        };
        // SAFETY: as above.
        unsafe { ffi::rtcOccluded1(scene.raw(), &mut ray.value, ptr::null_mut()) };
        assert_eq!(ray.guard, [GUARD; 16], "rtcOccluded1 wrote past RTCRay");
        assert_eq!(ray.value.tfar == f32::NEG_INFINITY, hits);
    }
}
