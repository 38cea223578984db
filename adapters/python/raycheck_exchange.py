"""Reading raycheck's mesh and rays files and writing its hits files with numpy.

The layouts are those of docs/exchange.md: a binary little-endian PLY mesh
(`float x, y, z` vertices, `list uchar uint vertex_indices` triangles, face i
being primID i) and the rays and hits files (a 32-byte header, then one record
per ray). Every adapter in this folder's siblings imports this module; a bad
file raises `BadFile`, naming the file and what is wrong, and `run` turns
that into one line on stderr and exit code 2.
"""

import sys

import numpy as np

RAYS_MAGIC = b"RCRAYS\0\0"
HITS_MAGIC = b"RCHITS\0\0"
VERSION = 1
HEADER_BYTES = 32
RAY_BYTES = 32
MISS = 0xFFFFFFFF
FLAG_UV = 1
# Set codes: which query each set asks.
SETS = {1: "primary", 2: "shadow", 3: "reflection", 4: "diffuse", 5: "stability case",
        6: "stability case any-hit"}
ANY_HIT_SETS = {2, 6}
HEADER = np.dtype(
    [("magic", "S8"), ("version", "<u4"), ("set", "<u4"), ("count", "<u8"),
     ("flags", "<u4"), ("reserved", "<u4")]
)
CLOSEST_HIT = np.dtype([("t", "<f4"), ("u", "<f4"), ("v", "<f4"), ("prim", "<u4")])
FACE = np.dtype([("corners", "u1"), ("indices", "<u4", (3,))])
PLY_PROPERTIES = [
    "element vertex",
    "property float x",
    "property float y",
    "property float z",
    "element face",
    "property list uchar uint vertex_indices",
]


class BadFile(Exception):
    """A file that is not what it should be: its path and what is wrong."""

    def __init__(self, path, what):
        super().__init__(f"{path}: {what}")


def _read(path):
    try:
        with open(path, "rb") as f:
            return f.read()
    except OSError as e:
        raise BadFile(path, f"cannot be read ({e.strerror})") from None


def read_mesh(path):
    """The mesh of a PLY file as (vertices (n, 3) float32, faces (m, 3) uint32)."""
    data = _read(path)
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        raise BadFile(path, "not a PLY file (no `ply` line or no `end_header`)")
    lines = []
    for number, line in enumerate(data[:end].decode("ascii", "replace").splitlines(), 1):
        if line.startswith(("comment", "obj_info")) or number == 1:
            continue
        lines.append((number, line.strip()))
    if not lines or lines[0][1] != "format binary_little_endian 1.0":
        raise BadFile(path, "only `format binary_little_endian 1.0` is read")
    counts = {}
    layout = []
    for number, line in lines[1:]:
        words = line.split()
        if words[:1] == ["element"]:
            if len(words) != 3 or not words[2].isdigit():
                raise BadFile(path, f"line {number}: expected `element NAME COUNT`, found `{line}`")
            counts[words[1]] = int(words[2])
            layout.append(f"element {words[1]}")
        else:
            layout.append(" ".join(words))
    if layout != PLY_PROPERTIES:
        raise BadFile(
            path,
            "expected exactly the layout `raycheck rays --mesh-out` writes "
            f"({'; '.join(PLY_PROPERTIES)}), found {'; '.join(layout)}",
        )
    vertices, faces = counts["vertex"], counts["face"]
    body = data[end + len(b"end_header\n"):]
    expected = 12 * vertices + FACE.itemsize * faces
    if len(body) != expected:
        raise BadFile(
            path,
            f"{vertices} vertices and {faces} triangles need {expected} bytes after the header, "
            f"found {len(body)}",
        )
    positions = np.frombuffer(body, "<f4", 3 * vertices).reshape(vertices, 3)
    records = np.frombuffer(body, FACE, faces, offset=12 * vertices)
    not_triangles = np.flatnonzero(records["corners"] != 3)
    if len(not_triangles):
        i = not_triangles[0]
        raise BadFile(path, f"face {i} has {records['corners'][i]} corners; every face must be a triangle")
    indices = records["indices"]
    out_of_range = np.flatnonzero((indices >= vertices).any(axis=1))
    if len(out_of_range):
        i = out_of_range[0]
        raise BadFile(path, f"face {i} refers to vertex {indices[i].max()}, but there are {vertices}")
    if not np.isfinite(positions).all():
        i = np.flatnonzero(~np.isfinite(positions).all(axis=1))[0]
        raise BadFile(path, f"vertex {i} has a NaN or infinite coordinate")
    return positions.astype(np.float32), indices.astype(np.uint32)


def _header(path, data, magic, kind):
    if len(data) < HEADER_BYTES:
        raise BadFile(path, f"truncated: {len(data)} bytes, shorter than the {HEADER_BYTES}-byte header")
    header = np.frombuffer(data, HEADER, 1)[0]
    if data[:8] != magic:
        raise BadFile(path, f"not a raycheck {kind} file: it starts with {data[:8]!r}, expected {magic!r}")
    if header["version"] != VERSION:
        raise BadFile(path, f"version {header['version']} is not supported (this adapter reads version {VERSION})")
    return header


class Rays:
    """A rays file: its set code and the rays as float32 columns."""

    def __init__(self, path):
        data = _read(path)
        header = _header(path, data, RAYS_MAGIC, "rays")
        self.set = int(header["set"])
        if self.set not in SETS:
            raise BadFile(path, f"unknown ray set code {self.set} (this adapter knows {sorted(SETS)})")
        count = int(header["count"])
        body = len(data) - HEADER_BYTES
        if count * RAY_BYTES != body:
            raise BadFile(
                path,
                f"the header says {count} rays of {RAY_BYTES} bytes ({count * RAY_BYTES} bytes), "
                f"the body has {body} bytes",
            )
        records = np.frombuffer(data, "<f4", 8 * count, HEADER_BYTES).reshape(count, 8)
        self.origins = records[:, 0:3]
        self.tnear = records[:, 3]
        self.directions = records[:, 4:7]
        self.tfar = records[:, 7]

    def __len__(self):
        return len(self.tnear)

    @property
    def any_hit(self):
        """Whether the set asks any-hit (occluded or not) rather than closest hit."""
        return self.set in ANY_HIT_SETS

    def empty_intervals(self):
        """Rays whose interval holds no t (tnear > tfar, or either NaN): a miss by definition."""
        return ~(self.tnear <= self.tfar)

    def refuse_negative_tnear(self, path, tracer):
        """Raises Unanswerable when a ray asks for hits behind its origin, which `tracer` cannot."""
        behind = np.flatnonzero((self.tnear < 0) & ~self.empty_intervals())
        if len(behind):
            raise Unanswerable(
                f"{path}: {len(behind)} rays have tnear < 0 (the first is ray {behind[0]}, "
                f"tnear = {float(self.tnear[behind[0]])}); {tracer} finds no hits behind a ray's origin, "
                "so these rays cannot be asked"
            )


def write_closest(path, rays, t, u, v, prim, gives_uv):
    """Writes closest hits: `prim` is MISS for a miss (its t, u, v are then written as 0)."""
    hits = np.zeros(len(rays), CLOSEST_HIT)
    prim = np.asarray(prim, np.uint32)
    hit = prim != MISS
    hits["prim"] = prim
    hits["t"][hit] = np.asarray(t, np.float32)[hit]
    if gives_uv:
        hits["u"][hit] = np.asarray(u, np.float32)[hit]
        hits["v"][hit] = np.asarray(v, np.float32)[hit]
    _write(path, rays, FLAG_UV if gives_uv else 0, hits.tobytes())


def write_occluded(path, rays, occluded):
    """Writes any-hit answers: one byte per ray, 1 occluded, 0 not."""
    _write(path, rays, 0, np.asarray(occluded, bool).astype(np.uint8).tobytes())


def _write(path, rays, flags, body):
    header = np.array([(HITS_MAGIC, VERSION, rays.set, len(rays), flags, 0)], HEADER)
    try:
        with open(path, "wb") as f:
            f.write(header.tobytes() + body)
    except OSError as e:
        raise BadFile(path, f"cannot be written ({e.strerror})") from None


class Unanswerable(Exception):
    """Rays whose query the tracer cannot express, with why."""


def run(name, main, argv):
    """Runs `main(argv)`, turning bad files and unanswerable rays into one line on stderr and exit code 2."""
    try:
        main(argv)
    except (BadFile, Unanswerable) as e:
        print(f"{name}: {e}", file=sys.stderr)
        sys.exit(2)
