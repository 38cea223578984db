//! The debug views: one snapshot per view (the mechanism of the feature
//! renders), the same bits for one and two threads, the rays a pixel
//! records, and the views that need our BVH refusing Embree.

use crate::features::assert_png_snapshot;
use raycheck::backends::BackendName;
use raycheck::backends::ours::{OURS, OURS_SAH};
use raycheck::bvh::BvhView;
use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::check::layered::{LayeredBackend, bvh_views};
use raycheck::render::debug::ray_paths::RayKind;
use raycheck::render::debug::{DebugImage, DebugView, render_debug};
use raycheck::render::{RenderSettings, Renderer};
use raycheck::report::measure::REFERENCE;
use raycheck::scene::{self, Scene};

/// Each view on the scene that shows it best, at 64×64.
const VIEWS: [(&str, &str); 7] = [
    ("cornell", "bvh-level=2"),
    ("monkey", "heat"),
    ("monkey-smooth", "normals"),
    ("textured-cube", "barycentrics"),
    ("textured-quad", "texcoords"),
    ("cornell-bloom", "bloom-mask"),
    ("cornell-glossy", "rays=24,35"),
];

fn settings() -> RenderSettings {
    RenderSettings {
        seed: 1,
        ..RenderSettings::square(64)
    }
}

/// Our trees of backend `ours` over every layer of `scene`.
fn trees(ours: &BackendName, scene: &Scene) -> Vec<Box<dyn BvhView>> {
    bvh_views(ours, scene)
        .expect("the harness reads our trees")
        .unwrap()
}

/// Draws `view` on our trees of backend `ours`, on `threads` threads.
fn on_ours(
    ours: &BackendName,
    scene: &Scene,
    view: DebugView,
    threads: usize,
) -> anyhow::Result<DebugImage> {
    let workers = crate::support::workers(Some(threads));
    let trees = workers.install(|| trees(ours, scene));
    let layers: Vec<&dyn BvhView> = trees.iter().map(|t| t.as_ref()).collect();
    workers.install(|| render_debug(scene, &layers, Some(&layers), view, &settings()))
}

/// `view` of scene `name` on our trees of backend `ours`: the same bits and
/// legend on one and two threads, not one flat colour, and equal to its
/// snapshot `{prefix}-{name}-{view}`.
fn assert_view_is_pinned(ours: &BackendName, prefix: &str, name: &str, view: &str) {
    let scene = scene::load(name).unwrap();
    let view: DebugView = view.parse().unwrap();
    let [one, two] = [1, 2].map(|threads| on_ours(ours, &scene, view, threads).unwrap());
    assert_eq!(one.image, two.image, "{name} {view}");
    assert_eq!(one.legend, two.legend, "{name} {view}");
    let distinct: std::collections::HashSet<[u8; 3]> = one
        .image
        .to_srgb8()
        .chunks(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    assert!(distinct.len() >= 2, "{name} {view} is one flat colour");
    let file = format!(
        "{prefix}-{name}-{}",
        view.to_string().replace(['=', ','], "-")
    );
    assert_png_snapshot(&file, &one.image);
}

/// The views on our binary SAH BVH.
fn ours(scene: &Scene, view: DebugView, threads: usize) -> anyhow::Result<DebugImage> {
    on_ours(&OURS_SAH, scene, view, threads)
}

#[test]
fn every_debug_view_matches_its_snapshot_on_any_thread_count() {
    for (name, view) in VIEWS {
        assert_view_is_pinned(&OURS_SAH, "debug", name, view);
    }
}

#[test]
fn a_pixel_records_its_rays_without_changing_its_value() {
    let settings = settings();
    for (name, (x, y), kinds) in [
        ("cornell-glossy", (24, 35), vec![RayKind::Reflected]),
        ("cornell-transparent", (19, 49), vec![RayKind::Transmitted]),
        ("cornell", (19, 49), vec![RayKind::Shadow { blocked: true }]),
        (
            "cornell",
            (13, 59),
            vec![RayKind::Shadow { blocked: false }],
        ),
    ] {
        let scene = scene::load(name).unwrap();
        let trees = trees(&OURS, &scene);
        let layers: Vec<&dyn BvhView> = trees.iter().map(|t| t.as_ref()).collect();
        let renderer = Renderer::new(&scene, &layers, &settings);
        let rays = renderer.pixel_rays(x, y);
        let spp = renderer.passes.samples_per_pixel as usize;
        let primary = rays.iter().filter(|r| r.kind == RayKind::Primary).count();
        assert_eq!(primary, spp, "{name}: {rays:?}");
        assert_eq!(rays[0].kind, RayKind::Primary, "{name}");
        for kind in kinds {
            assert!(rays.iter().any(|r| r.kind == kind), "{name}: no {kind:?}");
        }
        // Recording is read-only: the pixel renders as before.
        let image = raycheck::render::render_layers(&scene, &layers, &settings);
        assert_eq!(renderer.pixel(x, y), image.get(x, y), "{name}");
    }
}

#[test]
fn views_without_bvh_internals_run_on_embree_and_the_others_refuse() {
    let scene = scene::load("cornell-bloom").unwrap();
    let workers = crate::support::workers(Some(1));
    let embree = LayeredBackend::build(&REFERENCE, &scene, workers.build_context()).unwrap();
    let layers = embree.intersectors();
    let settings = settings();
    for view in ["normals", "bloom-mask", "rays=30,30"] {
        let view: DebugView = view.parse().unwrap();
        let on_embree = render_debug(&scene, &layers, None, view, &settings).unwrap();
        let on_ours = ours(&scene, view, 1).unwrap();
        let same = on_embree
            .image
            .pixels
            .iter()
            .zip(&on_ours.image.pixels)
            .filter(|(a, b)| (**a - **b).abs().max_element() < 1e-3)
            .count();
        assert!(same >= 64 * 64 * 99 / 100, "{view}: {same} pixels agree");
    }
    for view in [DebugView::Heat, DebugView::BvhLevel(0)] {
        let error = render_debug(&scene, &layers, None, view, &settings).unwrap_err();
        assert!(error.to_string().contains("--backend ours"), "{error}");
    }
}

#[test]
fn bad_levels_and_pixels_are_errors() {
    let scene = scene::load("cornell").unwrap();
    let levels = Bvh::build(&scene.mesh, &BuildOptions::sah()).stats().levels;
    let error = ours(&scene, DebugView::BvhLevel(levels), 1).unwrap_err();
    assert!(error.to_string().contains("beyond the tree"), "{error}");
    assert!(ours(&scene, DebugView::BvhLevel(levels - 1), 1).is_ok());
    let error = ours(&scene, DebugView::Rays { x: 64, y: 0 }, 1).unwrap_err();
    assert!(
        error.to_string().contains("outside the 64×64 image"),
        "{error}"
    );
}

/// The views that read BVH nodes, on the 8-wide BVH: the same bits on one
/// and two threads, a snapshot each, and levels beyond its tree refused.
#[test]
fn bvh_views_read_the_wide_bvh() {
    use raycheck::bvh::wide::WideBvh;

    for (name, view) in [
        ("cornell", "bvh-level=1"),
        ("monkey", "heat"),
        ("monkey", "bvh-level=2"),
    ] {
        assert_view_is_pinned(&OURS, "debug-wide", name, view);
    }
    let scene = scene::load("monkey").unwrap();
    let levels = WideBvh::build(&scene.mesh).levels();
    let error = on_ours(&OURS, &scene, DebugView::BvhLevel(levels), 1).unwrap_err();
    assert!(error.to_string().contains("beyond the tree"), "{error}");
}
