use raycheck_reference::{Device, DeviceConfig, DeviceProperty};

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
        verbose: 0,
    });
    assert!(device.is_ok());
}
