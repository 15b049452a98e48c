"""Triangle meshes of a URDF's visual geometry: STL (binary and ASCII) and Collada (.dae) files read with numpy
and xml.etree, and decimated by vertex clustering to a number of triangles.

A mesh is its vertices (n, 3) in metres, in the frame of the file, and its triangles (k, 3), indices into the
vertices; identical vertices are merged. What each format gives:

- STL: the facets' vertices as written, taken as metres (STL has no unit; ROS's meshes are in m). A file of
  84 + 50 k bytes whose count at byte 80 is k is binary (whatever its header says), another one beginning with
  ``solid`` ASCII.
- Collada: the ``<triangles>``, ``<polylist>`` and ``<polygons>`` (fanned into triangles) of every
  ``<geometry>`` the ``<visual_scene>`` instantiates, each placed by its nodes' ``<matrix>``, ``<translate>``,
  ``<rotate>`` and ``<scale>``, the positions times ``<unit meter>``; the first ``<diffuse><color>`` of
  the effects is the mesh's colour. Materials beyond that colour, textures and ``<up_axis>`` are not applied.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

#: The file name endings read (lower case) and the format each is.
FORMATS = {".stl": "STL", ".dae": "Collada"}
#: The most triangles a mesh keeps when read (a finer one is decimated): the viewer never draws more.
MAX_TRIANGLES = 200_000


class UnreadableMesh(Exception):
    """A mesh file this module cannot read (its format, or its contents): ``Model.from_urdf`` turns it into a note in
    ``model.urdf.notes`` and draws the body's inertia box instead; it never reaches the user as an error."""


@dataclass(frozen=True, eq=False)
class Mesh:
    """A triangle mesh: ``vertices`` (n, 3) float32 in m, ``triangles`` (k, 3) uint32 indices into them, and
    ``colour`` (r, g, b, a) in [0, 1] from the file (Collada's first diffuse colour) or None."""

    vertices: np.ndarray
    triangles: np.ndarray
    colour: tuple | None = None

    @property
    def size(self) -> int:
        """The number of triangles."""
        return len(self.triangles)


def read(path) -> Mesh:
    """The mesh of the STL or Collada file ``path`` (by its ending, ``FORMATS``), decimated to at most
    ``MAX_TRIANGLES``. A file that cannot be read as its format is an UnreadableMesh saying why."""
    name = str(path).lower()
    if name.endswith(".stl"):
        with open(path, "rb") as f:
            mesh = _stl(f.read())
    elif name.endswith(".dae"):
        mesh = _collada(path)
    else:
        raise UnreadableMesh(f"not a format read here ({', '.join(FORMATS)})")
    if mesh.size == 0:
        raise UnreadableMesh("no triangles in it")
    return decimated(mesh, MAX_TRIANGLES)


def _merged(vertices: np.ndarray, triangles: np.ndarray, colour=None) -> Mesh:
    """The mesh with identical vertices merged and triangles with a repeated vertex dropped."""
    vertices = np.asarray(vertices, dtype=np.float32).reshape(-1, 3)
    if not np.all(np.isfinite(vertices)):
        raise UnreadableMesh("vertices that are not finite numbers")
    unique, inverse = np.unique(vertices, axis=0, return_inverse=True)
    t = inverse.reshape(-1)[np.asarray(triangles, dtype=np.int64)]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
    return Mesh(unique, t.astype(np.uint32), colour)


# --- STL -------------------------------------------------------------------------------------------------------

#: A binary STL facet: its normal, three vertices (float32) and a uint16 attribute, 50 bytes.
_FACET = np.dtype([("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
_VERTEX = re.compile(r"vertex\s+(\S+)\s+(\S+)\s+(\S+)")


def _stl(raw: bytes) -> Mesh:
    """A binary STL (80-byte header, uint32 count k, k facets of 50 bytes) or an ASCII one (``vertex x y z``)."""
    if len(raw) >= 84:
        k = int(np.frombuffer(raw, "<u4", 1, 80)[0])
        if len(raw) == 84 + 50 * k:
            v = np.frombuffer(raw, _FACET, k, 84)["vertices"].reshape(-1, 3)
            return _merged(v, np.arange(3 * k).reshape(-1, 3))
    if not raw.lstrip()[:5].lower() == b"solid":
        raise UnreadableMesh(f"not an STL file (neither 84 + 50 k bytes nor text beginning with 'solid', {len(raw)} bytes)")
    try:
        v = np.array(_VERTEX.findall(raw.decode("latin-1")), dtype=float)
    except ValueError:
        raise UnreadableMesh("an ASCII STL file with a vertex that is not three numbers") from None
    if len(v) % 3:
        raise UnreadableMesh(f"an ASCII STL file of {len(v)} vertices, not three per facet")
    return _merged(v, np.arange(len(v)).reshape(-1, 3))


# --- Collada ---------------------------------------------------------------------------------------------------


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _numbers(text: str | None, kind=float) -> np.ndarray:
    return np.array((text or "").split(), dtype=kind)


def _collada(path) -> Mesh:
    """The triangles of a Collada file's visual scene in metres (see the module's docstring)."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as error:
        raise UnreadableMesh(f"not an XML file ({error})") from None
    for e in root.iter():  # namespaces dropped: <mesh> whatever the schema's version
        e.tag = _local(e.tag)
    if root.tag != "COLLADA":
        raise UnreadableMesh(f"not a Collada file (its root is <{root.tag}>)")
    unit = root.find("asset/unit")
    metre = float(unit.get("meter", "1")) if unit is not None else 1.0
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    colour = None
    for diffuse in root.iter("diffuse"):  # the first diffuse colour of the effects
        rgba = _numbers(diffuse.findtext("color"))
        if 3 <= rgba.size <= 4:
            colour = tuple(float(x) for x in np.r_[rgba, [1.0] * (4 - rgba.size)])
            break
    placed = []  # (geometry element, 4x4 transform)
    scene = root.find("library_visual_scenes/visual_scene")
    instance = root.find("scene/instance_visual_scene")
    if instance is not None and instance.get("url", "").lstrip("#") in ids:
        scene = ids[instance.get("url").lstrip("#")]
    if scene is not None:
        for node in scene.findall("node"):
            _walk(node, np.eye(4), ids, placed, 0)
    else:  # no scene: every geometry as it is
        placed = [(g, np.eye(4)) for g in root.iter("geometry")]
    vertices, triangles, n = [], [], 0
    for geometry, T in placed:
        for v, t in _geometry(geometry, ids):
            vertices.append(v @ T[:3, :3].T + T[:3, 3])
            triangles.append(t + n)
            n += len(v)
    if not triangles:
        return Mesh(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32), colour)
    return _merged(metre * np.concatenate(vertices), np.concatenate(triangles), colour)


def _node_transform(node) -> np.ndarray:
    """T of a Collada node: its <matrix>, <translate>, <rotate> (axis, degrees) and <scale> in their order."""
    T = np.eye(4)
    for e in node:
        x = _numbers(e.text) if e.tag in ("matrix", "translate", "rotate", "scale") else None
        A = np.eye(4)
        if e.tag == "matrix" and x.size == 16:
            A = x.reshape(4, 4)
        elif e.tag == "translate" and x.size == 3:
            A[:3, 3] = x
        elif e.tag == "scale" and x.size == 3:
            A[:3, :3] = np.diag(x)
        elif e.tag == "rotate" and x.size == 4 and np.linalg.norm(x[:3]) > 0:
            u, a = x[:3] / np.linalg.norm(x[:3]), math.radians(x[3])
            K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
            A[:3, :3] = np.eye(3) + math.sin(a) * K + (1.0 - math.cos(a)) * K @ K
        T = T @ A
    return T


def _walk(node, T_parent: np.ndarray, ids: dict, placed: list, depth: int) -> None:
    """The geometries under a node, each with its transform in the scene (T = T_parent T_node)."""
    if depth > 64:
        raise UnreadableMesh("nodes nested more than 64 deep (a cycle of <instance_node>?)")
    T = T_parent @ _node_transform(node)
    for e in node:
        target = ids.get(e.get("url", "").lstrip("#"))
        if e.tag == "instance_geometry" and target is not None:
            placed.append((target, T))
        elif e.tag == "instance_node" and target is not None:
            _walk(target, T, ids, placed, depth + 1)
        elif e.tag == "node":
            _walk(e, T, ids, placed, depth + 1)


def _positions(mesh, ids: dict) -> np.ndarray:
    """(n, 3) positions of a <mesh>: its <vertices>' POSITION source (a <float_array>, stride 3 or more)."""
    vertices = mesh.find("vertices")
    inp = next((i for i in vertices.findall("input") if i.get("semantic") == "POSITION"), None) \
        if vertices is not None else None
    source = ids.get(inp.get("source", "").lstrip("#")) if inp is not None else None
    array = source.find("float_array") if source is not None else None
    if array is None:
        raise UnreadableMesh("a <mesh> without a POSITION <float_array>")
    values = _numbers(array.text)
    accessor = source.find("technique_common/accessor")
    stride = int(accessor.get("stride", "3")) if accessor is not None else 3
    if stride < 3 or values.size % stride:
        raise UnreadableMesh(f"a <float_array> of {values.size} numbers, not a multiple of its stride {stride}")
    return values.reshape(-1, stride)[:, :3]


def _geometry(geometry, ids: dict):
    """(vertices (n, 3), triangles (k, 3)) of each primitive of a <geometry>'s <mesh>, in the file's units."""
    mesh = geometry.find("mesh")
    if mesh is None:
        return
    positions = None
    for prim in mesh:
        if prim.tag not in ("triangles", "polylist", "polygons"):
            continue
        if positions is None:
            positions = _positions(mesh, ids)
        inputs = prim.findall("input")
        offset = next((int(i.get("offset", "0")) for i in inputs if i.get("semantic") == "VERTEX"), None)
        if offset is None:
            continue
        stride = 1 + max(int(i.get("offset", "0")) for i in inputs)
        if prim.tag == "polygons":
            polygons = [_numbers(p.text, np.int64)[offset::stride] for p in prim.findall("p")]
            counts = np.array([len(p) for p in polygons], dtype=np.int64)
            index = np.concatenate(polygons) if polygons else np.zeros(0, np.int64)
        else:
            index = _numbers(prim.findtext("p"), np.int64)[offset::stride]
            counts = (np.full(len(index) // 3, 3, np.int64) if prim.tag == "triangles"
                      else _numbers(prim.findtext("vcount"), np.int64))
        if counts.sum() != len(index) or np.any(counts < 3) or np.any(index < 0) or np.any(index >= len(positions)):
            raise UnreadableMesh(f"a <{prim.tag}> whose indices do not match its counts or its {len(positions)} positions")
        # fans: polygon (a0, a1, ..., a(c-1)) -> (a0, aj, aj+1), j = 1..c-2
        starts = np.r_[0, np.cumsum(counts)[:-1]]
        first = np.repeat(starts, counts - 2)
        j = np.arange(len(first)) - np.repeat(np.cumsum(counts - 2) - (counts - 2), counts - 2) + 1
        yield positions, np.c_[index[first], index[first + j], index[first + j + 1]]


# --- decimation ------------------------------------------------------------------------------------------------


def _clustered(mesh: Mesh, n: int) -> Mesh:
    """Vertex clustering on a grid of n cells along the mesh's longest side: the vertices of a cell merged into
    their mean, triangles that lost a corner or repeat another dropped."""
    v = mesh.vertices.astype(float)
    lo = v.min(axis=0)
    cell = max(float(np.ptp(v, axis=0).max()), 1e-30) / n
    keys = np.floor((v - lo) / cell).astype(np.int64)
    _, cluster, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    cluster = cluster.reshape(-1)
    centres = np.zeros((len(counts), 3))
    np.add.at(centres, cluster, v)
    centres /= counts[:, None]
    t = cluster[mesh.triangles.astype(np.int64)]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
    _, first = np.unique(np.sort(t, axis=1), axis=0, return_index=True)
    return Mesh(centres.astype(np.float32), t[np.sort(first)].astype(np.uint32), mesh.colour)


def decimated(mesh: Mesh, triangles: int) -> Mesh:
    """The mesh with at most ``triangles`` triangles (itself if it has no more): vertex clustering on the finest
    grid (bisected on its number of cells) that leaves at most that many."""
    if mesh.size <= triangles:
        return mesh
    lo, hi, best = 1, max(2, int(4 * math.sqrt(mesh.size))), None
    while lo <= hi:
        n = (lo + hi) // 2
        candidate = _clustered(mesh, n)
        if candidate.size <= triangles:
            best, lo = candidate, n + 1
        else:
            hi = n - 1
    return best if best is not None else Mesh(mesh.vertices, mesh.triangles[:0], mesh.colour)
