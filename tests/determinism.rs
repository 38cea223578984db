//! The same render gives the same bits whatever the thread count.

use raycheck::backends::BackendName;
use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::parallel::thread_pool;
use raycheck::render::{RenderSettings, render};
use raycheck::results::compare_scene;
use raycheck::scene;

#[test]
fn cornell_render_is_identical_on_one_and_two_threads() {
    let scene = scene::load("cornell").unwrap();
    let bvh = Bvh::build(&scene.mesh, &BuildOptions::sah());
    let settings = RenderSettings::square(96);
    let one = thread_pool(Some(1))
        .unwrap()
        .install(|| render(&scene, &bvh, &settings));
    let two = thread_pool(Some(2))
        .unwrap()
        .install(|| render(&scene, &bvh, &settings));
    let bits = |img: &raycheck::render::image::Image| -> Vec<u32> {
        img.pixels
            .iter()
            .flat_map(|p| p.to_array().map(f32::to_bits))
            .collect()
    };
    assert_eq!(bits(&one), bits(&two));
    // The image is not trivially empty: the box and its walls are lit.
    let lit = one.pixels.iter().filter(|p| p.max_element() > 0.05).count();
    assert!(lit > one.pixels.len() / 2, "only {lit} lit pixels");
}

/// The compare summary, samples included, is the same on one and two
/// threads (Embree's device and ours alike): differences are logged from
/// several threads but reported in the order of their ray bits.
#[test]
fn compare_summary_is_identical_on_one_and_two_threads() {
    let scene = scene::load("dragon-11k").unwrap();
    let names = BackendName::parse_list("ours,ours-sah,embree-robust").unwrap();
    let summary_on = |threads: usize| {
        let workers = crate::support::workers(Some(threads));
        let summary = compare_scene(&scene, &names, &workers, 160).unwrap();
        assert!(!summary.samples.is_empty(), "no samples to order");
        serde_json::to_string(&summary).unwrap()
    };
    // Ties on the dragon's shared edges give samples to order.
    assert_eq!(summary_on(1), summary_on(2));
}
