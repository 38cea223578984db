//! The fast path against the readable one: same hits bit for bit, with
//! every kernel, and a valid tree from every build.

use super::{Kernel, KernelChoice, WideBvh};
use crate::bvh::test_meshes::{
    LOWEST_TIED_PRIM, Rng, grid, random_rays, random_soup, sphere, tie_mesh, untraceable_variants,
};
use crate::bvh::traverse::Uncounted;
use crate::bvh::{BuildOptions, Bvh};
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::trace::Intersector;
use glam::Vec3;

/// Every bit of a hit, so -0.0 and 0.0 (or two NaNs) are told apart.
fn bits(hit: Option<Hit>) -> Option<[u32; 7]> {
    hit.map(|h| {
        [
            h.t,
            h.u,
            h.v,
            f32::from_bits(h.prim),
            h.ng.x,
            h.ng.y,
            h.ng.z,
        ]
        .map(f32::to_bits)
    })
}

/// The tree with each kernel this CPU runs, the scalar one first (it
/// always runs); each kernel left out is named with the reason.
fn kernels(bvh: &WideBvh) -> Vec<WideBvh> {
    let mut all = vec![bvh.clone().with_kernel(Kernel::Scalar).unwrap()];
    for kernel in Kernel::ALL.into_iter().filter(|&k| k != Kernel::Scalar) {
        match Kernel::resolve(KernelChoice::Only(kernel)) {
            Ok(kernel) => all.extend(bvh.clone().with_kernel(kernel)),
            Err(why) => eprintln!("skipping the {kernel} kernel: {why}"),
        }
    }
    all
}

/// The kernel `bvh` traverses with.
fn traversal(bvh: &WideBvh) -> String {
    format!("{:?}", bvh.kernel())
}

/// The closest hit with every leaf put through the any-hit filter first,
/// as incoherent rays take it in a tree of sparse leaves, whatever this
/// tree's leaves.
fn closest_filtered(bvh: &WideBvh, ray: &Ray) -> Option<Hit> {
    bvh.closest::<true>(ray, &mut Uncounted)
}

/// Asserts that `bvh` answers `ray` as the loop over all of `reference`'s
/// triangles does, the closest hit bit for bit (with its leaves filtered
/// first or not) and occlusion alike; returns that answer.
fn assert_equals_brute_force(bvh: &WideBvh, reference: &Bvh, ray: &Ray, name: &str) -> Option<Hit> {
    let expected = reference.intersect_brute_force(ray);
    let kernel = traversal(bvh);
    assert_eq!(
        bits(bvh.intersect(ray)),
        bits(expected),
        "{name}, {kernel}, {ray:?}"
    );
    assert_eq!(
        bits(closest_filtered(bvh, ray)),
        bits(expected),
        "{name}, {kernel}, leaves filtered, {ray:?}"
    );
    assert_eq!(
        bvh.occluded(ray),
        expected.is_some(),
        "{name}, {kernel}, {ray:?}"
    );
    expected
}

fn meshes(rng: &mut Rng) -> Vec<(&'static str, TriangleMesh)> {
    let mut duplicated = random_soup(300, 0.3, rng);
    let copy = duplicated.clone();
    duplicated.append(&copy, 0);
    let mut centred_grid = grid(30);
    centred_grid
        .positions
        .iter_mut()
        .for_each(|p| *p = 2.0 * *p - Vec3::ONE);
    vec![
        ("soup", random_soup(3000, 0.1, rng)),
        ("big triangles", random_soup(300, 1.0, rng)),
        ("grid", centred_grid),
        ("sphere", sphere(Vec3::ZERO, 0.9, 24, 37)),
        ("duplicated", duplicated),
        (
            "one triangle",
            TriangleMesh::soup(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]),
        ),
        ("empty", TriangleMesh::default()),
    ]
}

#[test]
fn every_kernel_equals_brute_force_bit_for_bit() {
    let mut rng = Rng::new(50);
    let rays = random_rays(3000, &mut rng);
    for (name, mesh) in meshes(&mut rng) {
        let reference = Bvh::build(&mesh, &BuildOptions::sah());
        let wide = WideBvh::build(&mesh);
        wide.validate(&mesh)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(wide.triangles(), reference.triangles().len(), "{name}");
        let mut hits = 0;
        for bvh in kernels(&wide) {
            for ray in &rays {
                let expected = assert_equals_brute_force(&bvh, &reference, ray, name);
                hits += usize::from(expected.is_some());
            }
        }
        if mesh.indices.len() > 100 {
            assert!(hits > rays.len() / 4, "{name}: only {hits} hits");
        }
    }
}

/// Intervals that start behind the origin, from origins among the
/// triangles: the boxes behind the origin are met by the reversed ray,
/// whose box distances round the other way.
#[test]
fn intervals_behind_the_origin_are_traversed_too() {
    let mut rng = Rng::new(56);
    let rays: Vec<Ray> = random_rays(3000, &mut rng)
        .into_iter()
        .enumerate()
        .map(|(i, ray)| {
            let (tnear, tfar) = match i % 3 {
                0 => (rng.range_f32(-3.0, 0.0), rng.range_f32(0.0, 3.0)),
                1 => (rng.range_f32(-3.0, -1.0), rng.range_f32(-1.0, 0.0)),
                _ => (f32::NEG_INFINITY, f32::INFINITY),
            };
            Ray::segment(rng.point(-0.7, 0.7), ray.dir, tnear, tfar)
        })
        .collect();
    for (name, mesh) in meshes(&mut rng) {
        let reference = Bvh::build(&mesh, &BuildOptions::sah());
        for bvh in kernels(&WideBvh::build(&mesh)) {
            let mut behind = 0;
            for ray in &rays {
                let expected = assert_equals_brute_force(&bvh, &reference, ray, name);
                behind += usize::from(expected.is_some_and(|h| h.t < 0.0));
            }
            if mesh.indices.len() > 100 {
                assert!(behind > 100, "{name}: only {behind} hits behind the origin");
            }
        }
    }
}

#[test]
fn the_scalar_fallback_is_always_available() {
    let bvh = WideBvh::build(&random_soup(10, 0.5, &mut Rng::new(51)));
    assert_eq!(
        bvh.with_kernel(Kernel::Scalar).unwrap().kernel(),
        Kernel::Scalar
    );
    assert!(Kernel::detect().is_supported());
}

#[test]
fn ties_go_to_the_lowest_prim_id() {
    let (mesh, ray) = tie_mesh(&mut Rng::new(52));
    let wide = WideBvh::build(&mesh);
    for bvh in kernels(&wide) {
        for hit in [bvh.intersect(&ray), closest_filtered(&bvh, &ray)] {
            let hit = hit.unwrap();
            assert_eq!(
                (hit.t, hit.prim),
                (1.0, LOWEST_TIED_PRIM),
                "{:?}",
                bvh.kernel()
            );
        }
    }
}

/// As Embree's verify WatertightTest: no ray from the centre of a closed
/// sphere far from the origin escapes it.
#[test]
fn no_ray_escapes_a_closed_sphere() {
    let centre = Vec3::new(148_376.0, 1234.0, -223_423.0);
    let mesh = sphere(centre, 2.0, 200, 200);
    let wide = WideBvh::build(&mesh);
    wide.validate(&mesh).unwrap();
    let mut rng = Rng::new(53);
    for bvh in kernels(&wide) {
        for _ in 0..20_000 {
            let ray = Ray::new(centre, rng.point(-1.0, 1.0));
            assert!(bvh.intersect(&ray).is_some(), "{ray:?} escapes");
            assert!(closest_filtered(&bvh, &ray).is_some(), "{ray:?} escapes");
            assert!(bvh.occluded(&ray), "{ray:?} escapes");
        }
    }
}

#[test]
fn untraceable_rays_hit_nothing() {
    let mesh = random_soup(100, 0.5, &mut Rng::new(25));
    let wide = WideBvh::build(&mesh);
    let ok = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
    for bvh in kernels(&wide) {
        assert!(bvh.intersect(&ok).is_some(), "the valid ray should hit");
        for ray in untraceable_variants(ok) {
            assert_eq!(bvh.intersect(&ray), None, "{ray:?}");
            assert!(!bvh.occluded(&ray), "{ray:?}");
        }
    }
}

/// Unusable triangles, a flat one among them, are left out exactly as the
/// binary builders do.
#[test]
fn unusable_triangles_are_skipped() {
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let mut far = tri;
    far[2].y = 1e19;
    let mut nan = tri;
    nan[0].x = f32::NAN;
    let flat = [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X];
    let mesh = TriangleMesh::soup(&[tri, far, nan, flat, tri.map(|p| p + Vec3::Z)]);
    let wide = WideBvh::build(&mesh);
    wide.validate(&mesh).unwrap();
    assert_eq!((wide.triangles(), wide.skipped_triangles()), (2, 3));
}

/// The any-hit filter's bounds are only as safe as the stored edge norms,
/// so validation checks each against its block, down to one ulp, and
/// that there is one a block.
#[test]
fn edge_norms_smaller_than_their_blocks_fail_validation() {
    use super::WideValidationError;
    let mesh = sphere(Vec3::ZERO, 1.0, 12, 24);
    let wide = WideBvh::build(&mesh);
    wide.validate(&mesh).unwrap();
    assert_eq!(wide.edge_norms.len(), wide.blocks().len());
    let mut one_short = wide.clone();
    one_short.edge_norms.pop();
    assert!(matches!(
        one_short.validate(&mesh),
        Err(WideValidationError::WrongNorms { .. })
    ));
    let mut lowered = wide.clone();
    let norm = &mut lowered.edge_norms.last_mut().unwrap().product[0];
    *norm = norm.next_down();
    let last = wide.blocks().len() - 1;
    assert!(matches!(
        lowered.validate(&mesh),
        Err(WideValidationError::WrongNorms { block }) if block == last
    ));
}

/// Thousands of identical triangles: every split falls back to the median,
/// and the tree is still valid and answers with the lowest prim id.
#[test]
fn coincident_triangles_build_a_valid_tree() {
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let mesh = TriangleMesh::soup(&vec![tri; 10_000]);
    let wide = WideBvh::build(&mesh);
    wide.validate(&mesh).unwrap();
    for bvh in kernels(&wide) {
        let hit = bvh
            .intersect(&Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z))
            .unwrap();
        assert_eq!(hit.prim, 0);
    }
}

/// The same tree, node for node and block for block, on one thread and on
/// several.
#[test]
fn the_build_does_not_depend_on_the_thread_count() {
    // Large enough for subtrees, binning and partitions on several threads.
    let mesh = random_soup(200_000, 0.01, &mut Rng::new(55));
    let build_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| WideBvh::build(&mesh))
    };
    let (one, four) = (build_on(1), build_on(4));
    one.validate(&mesh).unwrap();
    assert!(one.nodes() == four.nodes(), "nodes differ");
    assert!(
        block_bits(one.blocks()) == block_bits(four.blocks()),
        "blocks differ"
    );
}

/// Every corner's bits and every prim id of `blocks`, to compare them
/// (padding lanes hold NaN, which `==` on floats never matches).
fn block_bits(blocks: &[super::node::TriangleBlock]) -> Vec<u32> {
    blocks
        .iter()
        .flat_map(|b| {
            b.corners
                .as_flattened()
                .as_flattened()
                .iter()
                .map(|c| c.to_bits())
                .chain(b.prims)
        })
        .collect()
}

/// A mesh of one block's worth of triangles in two clusters far apart
/// fills the root's free slots with a leaf per cluster, not one leaf whose
/// box spans both; a surface of thousands of triangles keeps its blocks
/// about as full as before (splitting a leaf a small part of the whole
/// saves too little).
#[test]
fn free_slots_take_tighter_leaves_only_where_that_pays() {
    let cluster = |x: f32| {
        (0..4).map(move |i| {
            [Vec3::ZERO, Vec3::X, Vec3::Y].map(|p| 0.1 * p + Vec3::new(x, i as f32 * 0.1, 0.0))
        })
    };
    let two = TriangleMesh::soup(&cluster(0.0).chain(cluster(100.0)).collect::<Vec<_>>());
    let stats = WideBvh::build(&two).stats();
    assert_eq!((stats.nodes, stats.leaves), (1, 2), "{stats:?}");
    let mesh = grid(60);
    let wide = WideBvh::build(&mesh);
    wide.validate(&mesh).unwrap();
    let stats = wide.stats();
    assert!(
        4 * stats.leaves * super::LEAF_SIZE < 5 * mesh.indices.len(),
        "{stats:?}"
    );
}

/// Levels, leaves and the largest leaf of trees whose shape is known, and
/// a wide tree never deeper than the binary one it was formed from.
#[test]
fn stats_describe_the_tree() {
    let one = WideBvh::build(&TriangleMesh::soup(&[[Vec3::ZERO, Vec3::X, Vec3::Y]])).stats();
    assert_eq!(
        (one.levels, one.nodes, one.leaves, one.max_leaf_triangles),
        (2, 1, 1, 1)
    );
    assert_eq!(
        WideBvh::build(&TriangleMesh::default()).stats(),
        super::WideStats::default()
    );
    let mesh = sphere(Vec3::ZERO, 0.9, 24, 37);
    let wide = WideBvh::build(&mesh).stats();
    let binary = Bvh::build(&mesh, &BuildOptions::sah());
    assert!(
        wide.levels >= 2 && wide.levels < binary.stats().levels,
        "{wide:?}"
    );
    assert!(
        wide.max_leaf_triangles as usize <= super::LEAF_SIZE,
        "{wide:?}"
    );
    assert!(
        wide.leaves >= mesh.indices.len() / super::LEAF_SIZE,
        "{wide:?}"
    );
}

/// Whether the AVX2 kernel runs on this CPU; says why not where it does
/// not, for the tests of its triangle kernel to skip.
#[cfg(target_arch = "x86_64")]
fn avx2_runs() -> bool {
    Kernel::resolve(KernelChoice::Only(Kernel::Avx2))
        .inspect_err(|why| eprintln!("skipped: {why}"))
        .is_ok()
}

/// A block's worth of triangles with corners within `size` of `centre`
/// on each axis.
#[cfg(target_arch = "x86_64")]
fn random_block(rng: &mut Rng, centre: Vec3, size: f32) -> Vec<[Vec3; 3]> {
    (0..super::node::BLOCK_WIDTH)
        .map(|_| [(); 3].map(|_| centre + rng.point(-size, size)))
        .collect()
}

/// A point on an edge or a corner of `triangle`, then moved off it by
/// 1e-9 to 1e-2 of `size`: where edge functions are within their rounding
/// of 0, or just beyond it.
#[cfg(target_arch = "x86_64")]
fn beside_an_edge(rng: &mut Rng, triangle: [Vec3; 3], size: f32) -> Vec3 {
    let corner = rng.below(3);
    let on_edge = triangle[corner].lerp(
        triangle[(corner + 1) % 3],
        rng.unit_f32().round() * rng.unit_f32(),
    );
    on_edge + rng.point(-1.0, 1.0) * size * 10f32.powf(rng.range_f32(-9.0, -2.0))
}

/// A uniformly random point of `triangle`.
#[cfg(target_arch = "x86_64")]
fn point_inside(rng: &mut Rng, [p0, p1, p2]: [Vec3; 3]) -> Vec3 {
    let (u, v) = (rng.unit_f32(), rng.unit_f32());
    let (u, v) = if u + v > 1.0 {
        (1.0 - u, 1.0 - v)
    } else {
        (u, v)
    };
    p0 + u * (p1 - p0) + v * (p2 - p0)
}

/// The AVX2 triangle kernel's sorting of `triangles` (one block) for `ray`
/// over `segment`, with the block's own box as the reach: the tightest a
/// traversal could give.
#[cfg(target_arch = "x86_64")]
fn avx2_lanes(
    triangles: &[[Vec3; 3]],
    ray: &crate::geometry::triangle::WatertightRay,
    segment: &crate::geometry::triangle::Segment,
) -> super::lanes::TriangleLanes {
    use super::lanes::{Lanes, reach};
    use super::simd::Avx2;
    let block = super::node::TriangleBlock::new((0..).zip(triangles.iter().copied()));
    let corners: Vec<Vec3> = triangles.iter().flatten().copied().collect();
    let reach = reach(&crate::geometry::Aabb::from_points(&corners), ray.origin());
    Avx2::triangle_lanes(&block, &Avx2::triangle_ray(ray, reach), segment)
}

/// The AVX2 triangle kernel's own decisions against the exact edge signs:
/// a lane it finishes from its f32 edges has those edges' signs exactly,
/// and a lane it drops has exact signs of both kinds. Rays are aimed at
/// corners and edges, and just beside them, at scales from 1e-4 to 1e4,
/// where the f32 values are within their rounding of 0 or just beyond.
#[cfg(target_arch = "x86_64")]
#[test]
fn the_simd_triangle_kernel_decides_only_what_the_exact_signs_confirm() {
    use super::node::BLOCK_WIDTH;
    use crate::exact::edge_sign;
    use crate::geometry::triangle::WatertightRay;
    use std::cmp::Ordering;

    if !avx2_runs() {
        return;
    }
    let mut rng = Rng::new(57);
    let (mut decided, mut aimed_decided, mut aimed_undecided) = (0, 0, 0);
    for _ in 0..5000 {
        let size = 10f32.powf(rng.range_f32(-4.0, 4.0));
        let centre = rng.point(-1.0, 1.0) * size * 10.0;
        let triangles = random_block(&mut rng, centre, size);
        let aimed = rng.below(BLOCK_WIDTH);
        let target = beside_an_edge(&mut rng, triangles[aimed], size);
        let origin = centre + rng.point(-100.0 * size, 100.0 * size);
        let ray = Ray::new(origin, target - origin);
        let wray = WatertightRay::new(&ray);
        // The whole line: no lane is dropped for lying outside the window.
        let line = wray.segment(f32::NEG_INFINITY, f32::INFINITY);
        let sorted = avx2_lanes(&triangles, &wray, &line);
        for (lane, [p0, p1, p2]) in triangles.iter().enumerate() {
            let [o, d] = [ray.origin, ray.dir].map(|v| v.to_array());
            let exact = [(p2, p1), (p0, p2), (p1, p0)]
                .map(|(p, q)| edge_sign(&o, &d, &p.to_array(), &q.to_array()));
            let bit = 1 << lane;
            if lane == aimed {
                aimed_undecided += usize::from(sorted.undecided & bit != 0);
                aimed_decided += usize::from(sorted.undecided & bit == 0);
            }
            if sorted.inside & bit != 0 {
                let found = sorted.edges(lane).map(|e| e.partial_cmp(&0.0).unwrap());
                assert_eq!(found, exact, "lane {lane} of {triangles:?}, {ray:?}");
                decided += 1;
            } else if sorted.undecided & bit == 0 {
                assert!(
                    exact.contains(&Ordering::Less) && exact.contains(&Ordering::Greater),
                    "lane {lane} of {triangles:?}, {ray:?}: dropped with exact signs {exact:?}"
                );
                decided += 1;
            }
        }
    }
    assert!(decided > 30_000, "only {decided} lanes decided");
    // Aimed at an edge or just beside it, lanes fall on both sides of
    // the bound: both regimes are exercised.
    assert!(
        aimed_decided > 500 && aimed_undecided > 500,
        "aimed lanes: {aimed_decided} decided, {aimed_undecided} not"
    );
}

/// The triangle kernel's drop of candidates behind the origin
/// (`behind.rs`) against the scalar test: every lane it drops from a
/// segment starting at `t >= 0` is one the scalar test misses, and the
/// triangle a secondary ray leaves, spawned off it as the renderer does,
/// is dropped in most cases (so the drop is not dead). Origins are spawned
/// to either side, left on the triangle's plane or moved a few ulps off
/// it along the ray, at sizes 1e-6 to 1e6, up to 1e4 sizes from the
/// world's origin, with directions down to grazing.
#[cfg(target_arch = "x86_64")]
#[test]
fn candidates_are_dropped_behind_the_origin_only_where_the_scalar_test_misses_them() {
    use super::node::BLOCK_WIDTH;
    use crate::geometry::offset::offset_ray_origin;
    use crate::geometry::triangle::{WatertightRay, geometric_normal};

    if !avx2_runs() {
        return;
    }
    let mut rng = Rng::new(61);
    let (mut dropped, mut spawned, mut left_dropped) = (0, 0, 0);
    for case in 0..40_000 {
        let size = 10f32.powf(rng.range_f32(-6.0, 6.0));
        let centre = rng.point(-1.0, 1.0) * size * 10f32.powf(rng.range_f32(0.0, 4.0));
        let triangles = random_block(&mut rng, centre, size);
        let left = rng.below(BLOCK_WIDTH);
        let [p0, p1, p2] = triangles[left];
        let normal = geometric_normal(p0, p1, p2).normalize_or_zero();
        let on_plane = point_inside(&mut rng, [p0, p1, p2]);
        // Towards the side the ray leaves into, down to grazing.
        let tangent = (p1 - p0).normalize_or_zero();
        let lift = 10f32.powf(rng.range_f32(-6.0, 0.0));
        let side = if rng.below(2) == 0 { 1.0 } else { -1.0 };
        let across = rng.point(-0.3, 0.3);
        let dir = tangent * rng.range_f32(-1.0, 1.0)
            + (across - normal * across.dot(normal))
            + normal * side * lift;
        let towards = normal * side;
        let origin = match case % 4 {
            0 | 1 => offset_ray_origin(on_plane, towards),
            2 => on_plane,
            // A few ulps along the ray, either way.
            _ => on_plane + dir * (rng.range_f32(-8.0, 8.0) * f32::EPSILON * size),
        };
        let ray = Ray::new(origin, dir);
        if !ray.is_traceable() {
            continue;
        }
        let wray = WatertightRay::new(&ray);
        let tnear = if case % 3 == 0 {
            0.0
        } else {
            rng.unit_f32() * 1e-3 * size
        };
        let segment = wray.segment(tnear, f32::INFINITY);
        let sorted = avx2_lanes(&triangles, &wray, &segment);
        for (lane, &[q0, q1, q2]) in triangles.iter().enumerate() {
            if (sorted.inside | sorted.undecided) & 1 << lane != 0 {
                continue;
            }
            dropped += 1;
            let scalar = wray.intersect_in(q0, q1, q2, &segment);
            assert_eq!(
                scalar, None,
                "lane {lane} of {triangles:?}, {ray:?}, {segment:?}"
            );
        }
        if case % 4 < 2 {
            spawned += 1;
            left_dropped += usize::from((sorted.inside | sorted.undecided) & 1 << left == 0);
        }
    }
    assert!(dropped > 100_000, "only {dropped} lanes dropped");
    // Most spawned rays' own triangles never reach the scalar test.
    assert!(
        left_dropped > spawned * 3 / 4,
        "{left_dropped} of {spawned} left triangles dropped"
    );
}

/// The any-hit filter (`candidates.rs`) against the scalar test: every
/// lane the scalar test hits within the ray's interval is left to it, and
/// every lane it proves hit is one the scalar test hits. Rays are aimed at
/// corners and edges or just beside them, or spawned off a triangle as the
/// renderer does (down to grazing), at sizes 1e-6 to 1e6; intervals are
/// the whole line, from 0 on, behind the origin, or end exactly at a hit's
/// own distance or an ulp short of it or past it, where the filter's
/// margins are tightest. The filter must also drop most lanes, and the
/// triangle a spawned ray leaves in most cases, and prove most hits, or it
/// would be no filter at all.
#[cfg(target_arch = "x86_64")]
#[test]
fn the_any_hit_filter_leaves_every_lane_the_scalar_test_hits() {
    use super::lanes::Lanes;
    use super::node::{BLOCK_WIDTH, EdgeNorms, TriangleBlock};
    use super::simd::Avx2;
    use crate::geometry::offset::offset_ray_origin;
    use crate::geometry::triangle::{WatertightRay, geometric_normal};

    if !avx2_runs() {
        return;
    }
    let mut rng = Rng::new(67);
    let (mut hits, mut at_an_end, mut spawned) = (0, 0, 0);
    let (mut proved, mut dropped, mut left_dropped) = (0, 0, 0);
    for case in 0..60_000 {
        let size = 10f32.powf(rng.range_f32(-6.0, 6.0));
        let centre = rng.point(-1.0, 1.0) * size * 10f32.powf(rng.range_f32(0.0, 4.0));
        let triangles = random_block(&mut rng, centre, size);
        let aimed = rng.below(BLOCK_WIDTH);
        let [p0, p1, p2] = triangles[aimed];
        let spawn = case % 2 == 0;
        let (origin, dir) = if spawn {
            let normal = geometric_normal(p0, p1, p2).normalize_or_zero();
            let on_plane = point_inside(&mut rng, [p0, p1, p2]);
            let side = if rng.below(2) == 0 { 1.0 } else { -1.0 };
            let across = rng.point(-1.0, 1.0);
            let lift = 10f32.powf(rng.range_f32(-6.0, 0.0));
            let dir = (across - normal * across.dot(normal)) + normal * side * lift;
            (offset_ray_origin(on_plane, normal * side), dir)
        } else {
            let target = beside_an_edge(&mut rng, triangles[aimed], size);
            let origin = centre + rng.point(-100.0 * size, 100.0 * size);
            (origin, target - origin)
        };
        let line = Ray::segment(origin, dir, f32::NEG_INFINITY, f32::INFINITY);
        if !line.is_traceable() {
            continue;
        }
        let wray = WatertightRay::new(&line);
        let distance = wray
            .intersect(p0, p1, p2, f32::NEG_INFINITY, f32::INFINITY)
            .map(|hit| hit.t);
        let (tnear, tfar) = match (case / 2 % 6, distance) {
            (0, _) | (_, None) => (f32::NEG_INFINITY, f32::INFINITY),
            (1, _) => (0.0, f32::INFINITY),
            (2, _) => (f32::NEG_INFINITY, 0.0),
            (3, Some(t)) => (t, t),
            (4, Some(t)) => (f32::NEG_INFINITY, t.next_down()),
            (_, Some(t)) => (t.next_up(), f32::INFINITY),
        };
        let ray = Ray::segment(origin, dir, tnear, tfar);
        let block = TriangleBlock::new((0..).zip(triangles.iter().copied()));
        let norms = EdgeNorms::of(&block);
        let filtered = Avx2::filter::<true>(&block, &norms, &ray);
        for (lane, &[q0, q1, q2]) in triangles.iter().enumerate() {
            let hit = wray.intersect(q0, q1, q2, tnear, tfar);
            if let Some(hit) = hit {
                hits += 1;
                at_an_end += usize::from(hit.t == tnear || hit.t == tfar);
                assert!(
                    filtered.may_hit & 1 << lane != 0,
                    "lane {lane} of {triangles:?}, {ray:?}: dropped, but the scalar test hits it at {}",
                    hit.t
                );
            }
            dropped += usize::from(filtered.may_hit & 1 << lane == 0);
            if filtered.hit & 1 << lane != 0 {
                proved += 1;
                assert!(
                    hit.is_some(),
                    "lane {lane} of {triangles:?}, {ray:?}: proved hit, but the scalar test misses it"
                );
            }
        }
        if spawn && tnear == 0.0 {
            spawned += 1;
            left_dropped += usize::from(filtered.may_hit & 1 << aimed == 0);
        }
    }
    assert!(
        hits > 30_000 && at_an_end > 2_000,
        "{hits} hits, {at_an_end} at an end"
    );
    assert!(dropped > 300_000, "only {dropped} lanes dropped");
    assert!(proved > hits / 2, "{proved} of {hits} hits proved");
    assert!(
        left_dropped > spawned * 3 / 4,
        "{left_dropped} of {spawned} left triangles dropped"
    );
}

/// The filter's proof of a hit where the watertight test's own checks
/// are tightest: slivers (a corner 1e-9 to 1e-1 of the size off the line
/// of the other two, where the sheared determinant and the geometric
/// normal near 0) and origins up to 1e7 sizes away, the rays aimed inside
/// the triangle, the intervals ending at, before or after the hit. A lane
/// proved hit must be hit by the scalar test, and some must be proved.
#[cfg(target_arch = "x86_64")]
#[test]
fn a_lane_the_any_hit_filter_proves_hit_is_hit_on_slivers_and_from_afar() {
    use super::lanes::Lanes;
    use super::node::{EdgeNorms, TriangleBlock};
    use super::simd::Avx2;
    use crate::geometry::triangle::WatertightRay;

    if !avx2_runs() {
        return;
    }
    let mut rng = Rng::new(71);
    let (mut hits, mut proved) = (0, 0);
    for case in 0..20_000 {
        let size = 10f32.powf(rng.range_f32(-4.0, 4.0));
        let centre = rng.point(-1.0, 1.0) * size * 10f32.powf(rng.range_f32(0.0, 3.0));
        let triangles: Vec<[Vec3; 3]> = random_block(&mut rng, centre, size)
            .into_iter()
            .map(|[p0, p1, _]| {
                let off = rng.point(-1.0, 1.0) * size * 10f32.powf(rng.range_f32(-9.0, -1.0));
                [p0, p1, p0.lerp(p1, rng.range_f32(-0.5, 1.5)) + off]
            })
            .collect();
        let aimed = rng.below(triangles.len());
        let target = point_inside(&mut rng, triangles[aimed]);
        let away =
            rng.point(-1.0, 1.0).normalize_or_zero() * size * 10f32.powf(rng.range_f32(-1.0, 7.0));
        let (origin, dir) = (target + away, -away * 10f32.powf(rng.range_f32(-3.0, 3.0)));
        let line = Ray::segment(origin, dir, 0.0, f32::INFINITY);
        if !line.is_traceable() {
            continue;
        }
        let wray = WatertightRay::new(&line);
        let (tnear, tfar) = match (
            case % 3,
            wray.intersect(
                triangles[aimed][0],
                triangles[aimed][1],
                triangles[aimed][2],
                0.0,
                f32::INFINITY,
            ),
        ) {
            (1, Some(hit)) => (0.0, hit.t),
            (2, Some(hit)) => (0.0, hit.t.next_down()),
            _ => (0.0, f32::INFINITY),
        };
        let ray = Ray::segment(origin, dir, tnear, tfar);
        let block = TriangleBlock::new((0..).zip(triangles.iter().copied()));
        let norms = EdgeNorms::of(&block);
        let filtered = Avx2::filter::<true>(&block, &norms, &ray);
        for (lane, &[q0, q1, q2]) in triangles.iter().enumerate() {
            let hit = wray.intersect(q0, q1, q2, tnear, tfar);
            hits += usize::from(hit.is_some());
            if filtered.hit & 1 << lane != 0 {
                proved += 1;
                assert!(
                    hit.is_some(),
                    "lane {lane} of {triangles:?}, {ray:?}: proved hit, but the scalar test misses it"
                );
            }
        }
    }
    assert!(proved > hits / 20, "{proved} of {hits} hits proved");
}

/// The index limits, with synthetic counts (no mesh here comes near
/// them): one triangle more than the child references can address is
/// refused before the build; the largest allowed tree's indices encode and
/// decode, its prim ids stay below the padding id; and on a machine with
/// less than the 256 GiB the largest allowed build needs, the memory check
/// refuses it.
#[test]
fn meshes_beyond_the_index_limits_or_the_memory_are_refused() {
    use super::node::Child;
    use super::{MAX_INDEX, NEEDS};
    use crate::bvh::{CapacityError, available_memory};

    let error = NEEDS.check(MAX_INDEX + 1).unwrap_err();
    assert!(
        matches!(
            error,
            CapacityError::TooManyTriangles {
                limit: MAX_INDEX,
                ..
            }
        ),
        "{error}"
    );
    for child in [Child::Inner(MAX_INDEX - 1), Child::Leaf(MAX_INDEX - 1)] {
        assert_eq!(Child::decode(child.encode()), child);
    }
    assert!((MAX_INDEX as u64) < u64::from(super::TriangleBlock::PADDING));
    if available_memory().is_some_and(|bytes| bytes < 256 << 30) {
        let error = NEEDS.check(MAX_INDEX).unwrap_err();
        assert!(
            matches!(error, CapacityError::OutOfMemory { .. }),
            "{error}"
        );
    }
    assert!(WideBvh::try_build(&random_soup(100, 0.1, &mut Rng::new(58))).is_ok());
}

/// Every kernel visits the same nodes in the same order, so the heat
/// map's counts do not depend on the CPU.
#[test]
fn every_kernel_counts_the_same_visits() {
    let mut rng = Rng::new(59);
    let rays = random_rays(2000, &mut rng);
    let mesh = random_soup(5000, 0.05, &mut rng);
    let counts = |bvh: &WideBvh| -> Vec<u32> {
        rays.iter()
            .map(|ray| {
                let mut visits = 0u32;
                bvh.intersect_counted(ray, &mut visits);
                visits
            })
            .collect()
    };
    let all = kernels(&WideBvh::build(&mesh));
    let scalar = counts(&all[0]);
    assert!(scalar.iter().sum::<u32>() > 2000, "{scalar:?}");
    for bvh in &all[1..] {
        assert_eq!(counts(bvh), scalar, "{}", traversal(bvh));
    }
}
