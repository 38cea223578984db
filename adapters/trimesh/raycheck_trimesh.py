"""trimesh's pure-numpy ray/triangle intersector as a tracer for raycheck.

    python raycheck_trimesh.py MESH.ply RAYS HITS

The mesh is a `trimesh.Trimesh` built with `process=False` (so no vertex is
merged and no face dropped or reordered: face i is primID i), asked through
`trimesh.ray.ray_triangle.ray_triangle_id`, the function behind
`RayMeshIntersector.intersects_id` and `intersects_location`, with the
mesh's own triangles, normals and r-tree and `multiple_hits=True`: every hit
of each ray along its whole forward line, as a point. (`intersects_id` with
`return_locations=True` then merges hits at the same point to 1e-8 and may
keep the wrong triangle of two; see the README.) trimesh has no tnear or
tfar; the adapter computes each hit's t from its point, keeps the hits with
tnear <= t <= tfar and answers the smallest t, the first in trimesh's order
on a tie, as trimesh's `multiple_hits=False` does (closest hit), or whether
any is left (any hit). u and v are trimesh's own barycentric coordinates of the hit
point (`trimesh.triangles.points_to_barycentric`), weights of the second and
third corners. The conventions are in the README beside this file. Exit
codes: 0 written, 2 a bad file or rays the tracer cannot be asked.
"""

import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "python"))

import numpy as np  # noqa: E402
import raycheck_exchange as rx  # noqa: E402

# Rays asked per call. trimesh holds every (ray, candidate triangle) pair of a
# call in several float64 arrays: on dragon-871k's primary rays, about 1,700
# candidates a ray and 0.8 MB, so 512 rays take some 400 MB.
BATCH = 512


def closest_in_intervals(mesh, rays, index):
    """(t, u, v, prim) of the closest hit in [tnear, tfar] of each ray at `index`; prim MISS for none."""
    import trimesh

    n = len(index)
    t = np.zeros(n, np.float64)
    uv = np.zeros((n, 2), np.float64)
    prim = np.full(n, rx.MISS, np.uint32)
    origins = rays.origins[index].astype(np.float64)
    directions = rays.directions[index].astype(np.float64)
    tri, ray, points = trimesh.ray.ray_triangle.ray_triangle_id(
        triangles=mesh.triangles,
        ray_origins=origins,
        ray_directions=directions,
        triangles_normal=mesh.face_normals,
        tree=mesh.triangles_tree,
        multiple_hits=True,
    )
    if not len(tri):
        return t, uv[:, 0], uv[:, 1], prim
    d = directions[ray]
    along = np.einsum("ij,ij->i", points - origins[ray], d) / np.einsum("ij,ij->i", d, d)
    inside = (rays.tnear[index][ray] <= along) & (along <= rays.tfar[index][ray])
    tri, ray, points, along = tri[inside], ray[inside], points[inside], along[inside]
    # The first of each ray's hits in order of t (a stable sort keeps trimesh's order on ties).
    order = np.lexsort((along, ray))
    first = order[np.r_[True, ray[order][1:] != ray[order][:-1]]] if len(order) else order
    weights = trimesh.triangles.points_to_barycentric(mesh.triangles[tri[first]], points[first])
    t[ray[first]] = along[first]
    uv[ray[first]] = weights[:, 1:3]
    prim[ray[first]] = tri[first]
    return t, uv[:, 0], uv[:, 1], prim


def trace(mesh_path, rays_path, hits_path):
    vertices, faces = rx.read_mesh(mesh_path)
    rays = rx.Rays(rays_path)
    rays.refuse_negative_tnear(rays_path, "trimesh")
    import trimesh

    mesh = trimesh.Trimesh(vertices=vertices.astype(np.float64), faces=faces, process=False, validate=False)
    t = np.zeros(len(rays), np.float64)
    u = np.zeros(len(rays), np.float64)
    v = np.zeros(len(rays), np.float64)
    prim = np.full(len(rays), rx.MISS, np.uint32)
    asked = np.flatnonzero(~rays.empty_intervals() & askable(rays))
    for start in range(0, len(asked), BATCH):
        index = asked[start:start + BATCH]
        t[index], u[index], v[index], prim[index] = closest_in_intervals(mesh, rays, index)
    if rays.any_hit:
        rx.write_occluded(hits_path, rays, prim != rx.MISS)
    else:
        rx.write_closest(hits_path, rays, t, u, v, prim, gives_uv=True)


def askable(rays):
    """Rays trimesh can be asked: a NaN or infinite origin, or a NaN direction, makes its r-tree query raise
    (RTreeError: minimums more than maximums), so the adapter answers those rays as misses without asking."""
    return np.isfinite(rays.origins).all(axis=1) & ~np.isnan(rays.directions).any(axis=1)


def main(argv):
    if len(argv) != 3:
        print("usage: raycheck_trimesh.py MESH.ply RAYS HITS", file=sys.stderr)
        sys.exit(2)
    trace(*argv)


if __name__ == "__main__":
    rx.run("raycheck_trimesh", main, sys.argv[1:])
