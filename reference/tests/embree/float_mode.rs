use raycheck_reference::{
    enable_flush_to_zero_and_denormals_are_zero, flush_to_zero_and_denormals_are_zero_enabled,
};
use std::hint::black_box;

#[cfg(target_arch = "x86_64")]
#[test]
fn the_mode_is_per_thread_and_flushes_denormals() {
    std::thread::spawn(|| {
        let smallest_normal = black_box(f32::MIN_POSITIVE);
        assert!(!flush_to_zero_and_denormals_are_zero_enabled());
        assert!(smallest_normal * black_box(0.5) > 0.0, "denormal before");
        enable_flush_to_zero_and_denormals_are_zero();
        assert!(flush_to_zero_and_denormals_are_zero_enabled());
        assert_eq!(smallest_normal * black_box(0.5), 0.0, "flushed after");
    })
    .join()
    .unwrap();
    std::thread::spawn(|| assert!(!flush_to_zero_and_denormals_are_zero_enabled()))
        .join()
        .unwrap();
}
