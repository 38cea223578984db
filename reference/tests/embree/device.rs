use raycheck_reference::{Device, DeviceConfig, DeviceProperty, Isa};

#[test]
fn the_linked_library_is_embree_4_4_0() {
    let device = crate::device();
    assert_eq!(device.version(), 40400);
    assert_eq!(device.property(DeviceProperty::VersionMajor), 4);
    assert_eq!(device.property(DeviceProperty::VersionMinor), 4);
    assert_eq!(device.property(DeviceProperty::VersionPatch), 0);
}

#[test]
fn ray_masks_are_on_and_no_ray_or_face_is_culled() {
    let device = crate::device();
    assert_eq!(device.property(DeviceProperty::RayMaskSupported), 1);
    assert_eq!(device.property(DeviceProperty::BackfaceCullingEnabled), 0);
    assert_eq!(
        device.property(DeviceProperty::TriangleGeometrySupported),
        1
    );
}

#[test]
fn a_device_can_be_limited_to_one_thread() {
    let device = Device::new(&DeviceConfig {
        threads: Some(1),
        ..DeviceConfig::default()
    });
    assert!(device.is_ok());
}

/// The instruction set Embree selects is read from its own report: asked
/// for AVX2 it runs AVX2 intersectors; asked for AVX-512 on a CPU that has
/// it, AVX-512 ones; left to itself, the widest of the two the CPU has.
#[test]
fn the_selected_isa_is_what_embree_reports() {
    let selected = |isa: Isa| {
        let device = Device::new(&DeviceConfig {
            threads: Some(1),
            isa,
            ..DeviceConfig::default()
        })
        .unwrap();
        assert_eq!(device.isa(), isa);
        let selected = device.selected_isa().unwrap();
        assert!(
            selected
                .intersector
                .starts_with(&format!("{}::", selected.isa)),
            "{selected:?}"
        );
        assert!(!selected.frequency_level.is_empty(), "{selected:?}");
        selected.isa
    };
    if !std::arch::is_x86_feature_detected!("avx2") {
        eprintln!("skipped: this CPU has no AVX2");
        return;
    }
    assert_eq!(selected(Isa::Avx2), "avx2");
    let avx512 = std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512dq")
        && std::arch::is_x86_feature_detected!("avx512bw");
    let widest = if avx512 { "avx512" } else { "avx2" };
    assert_eq!(selected(Isa::Auto), widest);
    if avx512 {
        assert_eq!(selected(Isa::Avx512), "avx512");
    } else {
        eprintln!("isa=avx512 not checked: this CPU has no AVX-512");
    }
}
