"""Mitsuba 3 as a tracer for raycheck: reads a mesh and a rays file, writes the hits file.

    python raycheck_mitsuba.py [--variant scalar_rgb|llvm_ad_rgb] MESH.ply RAYS HITS

`scalar_rgb` asks one ray per Python call, `llvm_ad_rgb` all rays at once as
arrays. The mesh is one `mi.Mesh` whose `vertex_positions` and `faces` are
set through `mi.traverse`, so face i is primID i; closest hits come from
`Scene.ray_intersect_preliminary` (t, prim_index, prim_uv), any hit from
`Scene.ray_test`. Mitsuba's `Ray3f` has `maxt` (set to tfar) and no tnear: its
rays start at t = 0. How the adapter answers rays with tnear != 0 is in the
README beside this file. Exit codes: 0 written, 2 a bad file or rays the
tracer cannot be asked (one line on stderr says which and why).
"""

import argparse
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "python"))

import numpy as np  # noqa: E402
import raycheck_exchange as rx  # noqa: E402

VARIANTS = ("scalar_rgb", "llvm_ad_rgb")
# Triangles a ray may meet before its tnear, each costing one scene build,
# before the adapter gives up on the ray (see the README).
MAX_EXCLUDED = 64


def build_scene(mi, vertices, faces):
    """A Mitsuba scene of one mesh with exactly these f32 vertices and triangles."""
    mesh = mi.Mesh("raycheck", len(vertices), len(faces))
    params = mi.traverse(mesh)
    params["vertex_positions"] = type(params["vertex_positions"])(vertices.ravel())
    params["faces"] = type(params["faces"])(faces.ravel())
    params.update()
    return mi.load_dict({"type": "scene", "mesh": mesh})


class Tracer:
    """One variant's queries: closest hits and occlusion for the rays at `index`."""

    def __init__(self, mi, variant):
        self.mi = mi
        self.scalar = variant == "scalar_rgb"

    def closest(self, scene, rays, index):
        """(t, u, v, prim) arrays for the rays at `index` from t = 0 to tfar; prim is MISS for a miss."""
        mi = self.mi
        n = len(index)
        t = np.zeros(n, np.float32)
        u = np.zeros(n, np.float32)
        v = np.zeros(n, np.float32)
        prim = np.full(n, rx.MISS, np.uint32)
        if self.scalar:
            for k, i in enumerate(index):
                pi = scene.ray_intersect_preliminary(self._scalar_ray(rays, i))
                if pi.is_valid():
                    t[k], u[k], v[k], prim[k] = pi.t, pi.prim_uv[0], pi.prim_uv[1], pi.prim_index
        elif n:
            pi = scene.ray_intersect_preliminary(self._llvm_rays(rays, index))
            valid = pi.is_valid().numpy()
            t[valid] = pi.t.numpy()[valid]
            u[valid] = pi.prim_uv.x.numpy()[valid]
            v[valid] = pi.prim_uv.y.numpy()[valid]
            prim[valid] = pi.prim_index.numpy()[valid]
        return t, u, v, prim

    def occluded(self, scene, rays, index):
        """Whether each ray at `index` meets the mesh between t = 0 and tfar."""
        if self.scalar:
            return np.array([bool(scene.ray_test(self._scalar_ray(rays, i))) for i in index], bool)
        if not len(index):
            return np.zeros(0, bool)
        return scene.ray_test(self._llvm_rays(rays, index)).numpy().astype(bool)

    def _scalar_ray(self, rays, i):
        mi = self.mi
        ray = mi.Ray3f(mi.Point3f(*map(float, rays.origins[i])), mi.Vector3f(*map(float, rays.directions[i])))
        ray.maxt = float(rays.tfar[i])
        return ray

    def _llvm_rays(self, rays, index):
        mi = self.mi

        def column(values):
            return mi.Float(np.ascontiguousarray(values, np.float32))

        o, d = rays.origins[index], rays.directions[index]
        ray = mi.Ray3f(
            mi.Point3f(column(o[:, 0]), column(o[:, 1]), column(o[:, 2])),
            mi.Vector3f(column(d[:, 0]), column(d[:, 1]), column(d[:, 2])),
        )
        ray.maxt = column(rays.tfar[index])
        return ray


def closest_from_tnear(tracer, vertices, faces, rays, i, prim):
    """The closest hit of ray i at t >= tnear, when Mitsuba's first hit from t = 0 (on `prim`) lies before tnear.

    Embree, which Mitsuba traces with, tests each triangle on its own, so the
    hits of a ray are those of every triangle; the triangles met before tnear
    are taken out of the mesh one by one and the ray asked again.
    """
    keep = np.ones(len(faces), bool)
    for _ in range(MAX_EXCLUDED):
        keep[prim] = False
        kept = np.flatnonzero(keep)
        scene = build_scene(tracer.mi, vertices, faces[kept])
        t, u, v, p = (a[0] for a in tracer.closest(scene, rays, np.array([i])))
        if p == rx.MISS:
            return None
        prim = kept[p]
        if t >= rays.tnear[i]:
            return t, u, v, prim
    raise rx.Unanswerable(
        f"ray {i} meets more than {MAX_EXCLUDED} triangles before its tnear = {float(rays.tnear[i])}; "
        "Mitsuba's rays have no tnear, so the adapter stops there"
    )


def trace(variant, mesh_path, rays_path, hits_path):
    vertices, faces = rx.read_mesh(mesh_path)
    rays = rx.Rays(rays_path)
    rays.refuse_negative_tnear(rays_path, "Mitsuba")
    import mitsuba as mi

    mi.set_variant(variant)
    mi.set_log_level(mi.LogLevel.Warn)
    tracer = Tracer(mi, variant)
    scene = build_scene(mi, vertices, faces)
    asked = np.flatnonzero(~rays.empty_intervals())
    # The closest hit from t = 0 is the closest from tnear when it lies at or
    # beyond tnear; a miss from t = 0 is a miss from tnear.
    if rays.any_hit:
        occluded = np.zeros(len(rays), bool)
        occluded[asked] = tracer.occluded(scene, rays, asked)
        ahead = asked[occluded[asked] & (rays.tnear[asked] > 0)]
        t, _, _, prim = tracer.closest(scene, rays, ahead)
        for k, i in enumerate(ahead):
            if prim[k] != rx.MISS and t[k] < rays.tnear[i]:
                occluded[i] = closest_from_tnear(tracer, vertices, faces, rays, i, prim[k]) is not None
        rx.write_occluded(hits_path, rays, occluded)
        return
    t = np.zeros(len(rays), np.float32)
    u = np.zeros(len(rays), np.float32)
    v = np.zeros(len(rays), np.float32)
    prim = np.full(len(rays), rx.MISS, np.uint32)
    t[asked], u[asked], v[asked], prim[asked] = tracer.closest(scene, rays, asked)
    for i in asked[(prim[asked] != rx.MISS) & (t[asked] < rays.tnear[asked])]:
        found = closest_from_tnear(tracer, vertices, faces, rays, i, prim[i])
        t[i], u[i], v[i], prim[i] = found if found is not None else (0.0, 0.0, 0.0, rx.MISS)
    rx.write_closest(hits_path, rays, t, u, v, prim, gives_uv=True)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variant", choices=VARIANTS, default="llvm_ad_rgb")
    parser.add_argument("mesh")
    parser.add_argument("rays")
    parser.add_argument("hits")
    args = parser.parse_args(argv)
    trace(args.variant, args.mesh, args.rays, args.hits)


if __name__ == "__main__":
    rx.run("raycheck_mitsuba", main, sys.argv[1:])
