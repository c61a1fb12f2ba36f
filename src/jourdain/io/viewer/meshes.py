"""Mesh files for the 3-D view: STL (binary, ASCII), Wavefront OBJ and COLLADA (``.dae``).

Each is read into a :class:`Mesh` (vertices, triangles as vertex indices, and groups of
triangles with a colour where the file gives one), which the page embeds. Model files are data:
COLLADA is XML read without DTDs (no entity expansion), every file is bounded in size
(:data:`MAX_MESH_BYTES`), and a malformed file is a :class:`~jourdain.errors.ModelError` that
names it.

COLLADA: the triangles, polylists and polygons of every ``<geometry>``, placed by the nodes of
the ``<visual_scene>`` that instantiate them (``<matrix>``, ``<translate>``, ``<rotate>``,
``<scale>``, nested nodes and ``<instance_node>``), in the file's ``<unit meter=...>``, with the
diffuse colour of their ``<material>``. Lines, textures and the ``<up_axis>`` are ignored
(the coordinates are taken as they are, as URDF tools do).
"""

from __future__ import annotations

import re
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import ModelError
from . import mesh_store

#: files larger than this are not read
MAX_MESH_BYTES = 64 * 2**20
#: nesting of COLLADA nodes (instance_node can refer back: a cycle is an error, not a hang)
MAX_NODE_DEPTH = 64
SUFFIXES = (".stl", ".obj", ".dae")


@dataclass(frozen=True)
class Mesh:
    """``vertices`` (m, 3), ``faces`` (n, 3) vertex indices, ``groups``: (first face, number of
    faces, RGB in [0, 1] or None) covering the faces in order."""

    vertices: np.ndarray
    faces: np.ndarray
    groups: tuple[tuple[int, int, tuple[float, float, float] | None], ...] = field(default=())

    @property
    def triangles(self) -> np.ndarray:
        """(n, 3, 3) corner coordinates."""
        return self.vertices[self.faces]


def _from_triangles(tri: np.ndarray) -> Mesh:
    """Shared corners of a triangle soup (STL) become one vertex each."""
    v, inv = np.unique(tri.reshape(-1, 3), axis=0, return_inverse=True)
    faces = inv.reshape(-1, 3)
    return Mesh(v, faces, ((0, len(faces), None),))


def _stl(data: bytes, where: str) -> Mesh:
    if len(data) >= 84:
        n = int.from_bytes(data[80:84], "little")
        if len(data) == 84 + 50 * n:
            rec = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                                      ("a", "<u2")]), count=n, offset=84)
            return _from_triangles(rec["v"].astype(np.float64))
    text = data.decode("ascii", errors="replace")
    if not text.lstrip().lower().startswith("solid"):
        raise ModelError(f"{where}: neither a binary STL (size 84 + 50·n bytes) nor ASCII STL")
    nums = re.findall(r"vertex\s+(\S+)\s+(\S+)\s+(\S+)", text)
    try:
        v = np.array(nums, dtype=float).reshape(-1, 3)
    except ValueError as exc:
        raise ModelError(f"{where}: a vertex that is not three numbers ({exc})") from None
    if len(v) % 3:
        raise ModelError(f"{where}: {len(v)} vertices, not a whole number of triangles")
    return _from_triangles(v.reshape(-1, 3, 3))


def _fan(polygon: list[int]) -> list[tuple[int, int, int]]:
    return [(polygon[0], polygon[k], polygon[k + 1]) for k in range(1, len(polygon) - 1)]


def _obj(data: bytes, where: str) -> Mesh:
    verts: list[tuple[float, float, float]] = []
    tris: list[tuple[int, int, int]] = []
    for lineno, line in enumerate(data.decode("utf-8", errors="replace").splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        try:
            if parts[0] == "v":
                verts.append((float(parts[1]), float(parts[2]), float(parts[3])))
            elif parts[0] == "f":
                idx = []
                for p in parts[1:]:
                    i = int(p.split("/")[0])
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                tris.extend(_fan(idx))
        except (ValueError, IndexError):
            raise ModelError(f"{where}, line {lineno}: cannot read {line.strip()[:60]!r}"
                             ) from None
    v = np.array(verts, float).reshape(-1, 3)
    t = np.array(tris, int).reshape(-1, 3)
    if t.size and (t.min() < 0 or t.max() >= len(v)):
        raise ModelError(f"{where}: a face refers to a vertex that does not exist")
    return Mesh(v, t, ((0, len(t), None),))


# ------------------------------------------------------------------------------------------
# COLLADA
# ------------------------------------------------------------------------------------------

def _numbers(el: ET.Element | None, where: str, kind: type = float) -> np.ndarray:
    """The whitespace-separated numbers of an element's text (parsed in C: COLLADA arrays hold
    hundreds of thousands)."""
    if el is None or not (el.text or "").strip():
        return np.zeros(0, dtype=kind)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)  # text that is not all numbers
        try:
            a = np.fromstring(el.text or "", dtype=np.float64, sep=" ")
        except (DeprecationWarning, ValueError):
            raise ModelError(f"{where}: <{el.tag}> holds something that is not a number"
                             ) from None
    if kind is int:
        if not np.all(np.isfinite(a)) or np.any(a != np.round(a)) or np.any(np.abs(a) > 2**31):
            raise ModelError(f"{where}: <{el.tag}> holds something that is not an index")
        return a.astype(np.int64)
    return a


def _ref(url: str | None) -> str:
    return (url or "").lstrip("#")


def _dae_geometry(geo: ET.Element, where: str
                  ) -> list[tuple[np.ndarray, np.ndarray, str | None]]:
    """Per primitive of one ``<geometry>``: positions (m, 3), faces (n, 3), material symbol."""
    mesh = geo.find("mesh")
    if mesh is None:
        return []
    sources: dict[str, np.ndarray] = {}
    for src in mesh.findall("source"):
        arr = _numbers(src.find("float_array"), where)
        acc = src.find("technique_common/accessor")
        stride = int(acc.get("stride", "1")) if acc is not None else 3
        if stride >= 3 and arr.size % stride == 0:
            sources[src.get("id", "")] = arr.reshape(-1, stride)[:, :3]
    vertices = {}
    for vx in mesh.findall("vertices"):
        for inp in vx.findall("input"):
            if inp.get("semantic") == "POSITION":
                vertices[vx.get("id", "")] = _ref(inp.get("source"))
    out = []
    for prim in mesh:
        if prim.tag not in ("triangles", "polylist", "polygons"):
            continue  # lines, tristrips, ...
        inputs = prim.findall("input")
        n_in = max((int(i.get("offset", "0")) for i in inputs), default=0) + 1
        vin = [i for i in inputs if i.get("semantic") == "VERTEX"]
        if not vin:
            continue
        off = int(vin[0].get("offset", "0"))
        pos = sources.get(vertices.get(_ref(vin[0].get("source")), ""))
        if pos is None:
            raise ModelError(f"{where}: a primitive's VERTEX input has no positions")
        if prim.tag == "polygons":
            polys = [_numbers(p, where, int).reshape(-1, n_in)[:, off].tolist()
                     for p in prim.findall("p")]
        else:
            idx = _numbers(prim.find("p"), where, int)
            if idx.size % n_in:
                raise ModelError(f"{where}: <p> does not hold whole vertices")
            idx = idx.reshape(-1, n_in)[:, off]
            if prim.tag == "triangles":
                if idx.size % 3:
                    raise ModelError(f"{where}: <triangles> with a corner count not a multiple "
                                     "of 3")
                polys, faces = None, idx.reshape(-1, 3)
            else:
                counts = _numbers(prim.find("vcount"), where, int)
                if counts.sum() != idx.size:
                    raise ModelError(f"{where}: <vcount> does not match <p>")
                ends = np.cumsum(counts)
                polys = [idx[e - c:e].tolist() for c, e in zip(counts, ends, strict=True)]
        if polys is not None:
            faces = np.array([t for p in polys for t in _fan(p)], int).reshape(-1, 3)
        if faces.size and (faces.min() < 0 or faces.max() >= len(pos)):
            raise ModelError(f"{where}: a face refers to a vertex that does not exist")
        out.append((pos, faces, prim.get("material")))
    return out


def _node_matrix(node: ET.Element, where: str) -> np.ndarray:
    """The node's transform: its transformation elements in order (COLLADA 1.4 §5)."""
    T = np.eye(4)
    for el in node:
        if el.tag == "matrix":
            m = _numbers(el, where)
            if m.size != 16:
                raise ModelError(f"{where}: <matrix> of {m.size} numbers")
            T = T @ m.reshape(4, 4)
        elif el.tag == "translate":
            t = _numbers(el, where)
            M = np.eye(4)
            M[:3, 3] = t[:3]
            T = T @ M
        elif el.tag == "rotate":
            a = _numbers(el, where)
            if a.size != 4 or not np.linalg.norm(a[:3]):
                raise ModelError(f"{where}: <rotate> is not an axis and an angle")
            u = a[:3] / np.linalg.norm(a[:3])
            th = np.radians(a[3])
            K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
            M = np.eye(4)
            M[:3, :3] = np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K
            T = T @ M
        elif el.tag == "scale":
            s = _numbers(el, where)
            T = T @ np.diag([*s[:3], 1.0])
    return T


def _dae(data: bytes, where: str) -> Mesh:
    if b"<!DOCTYPE" in data or b"<!ENTITY" in data:
        raise ModelError(f"{where}: COLLADA files with a DTD (<!DOCTYPE>, <!ENTITY>) are not read")
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        raise ModelError(f"{where}: malformed XML ({exc})") from None
    for el in root.iter():  # drop the COLLADA namespace from the tags
        if isinstance(el.tag, str) and "}" in el.tag:
            el.tag = el.tag.split("}", 1)[1]
    unit = root.find("asset/unit")
    try:
        meter = float(unit.get("meter", "1")) if unit is not None else 1.0
    except ValueError:
        raise ModelError(f"{where}: <unit meter=...> is not a number") from None
    # material id -> diffuse colour
    colour_of_effect: dict[str, tuple[float, float, float]] = {}
    for eff in root.iter("effect"):
        c = np.clip(_numbers(eff.find(".//diffuse/color"), where)[:3], 0, 1)
        if c.size == 3:
            colour_of_effect[eff.get("id", "")] = (float(c[0]), float(c[1]), float(c[2]))
    colour: dict[str, tuple[float, float, float] | None] = {}
    for mat in root.iter("material"):
        ie = mat.find("instance_effect")
        if ie is not None:
            colour[mat.get("id", "")] = colour_of_effect.get(_ref(ie.get("url")))
    geometries = {g.get("id", ""): g for g in root.iter("geometry")}
    library_nodes = {n.get("id", ""): n for lib in root.iter("library_nodes")
                     for n in lib.findall("node")}
    parts: list[tuple[np.ndarray, np.ndarray, tuple[float, float, float] | None]] = []
    cache: dict[str, list] = {}

    def geometry(gid: str) -> list:
        if gid not in cache:
            g = geometries.get(gid)
            cache[gid] = [] if g is None else _dae_geometry(g, where)
        return cache[gid]

    def visit(node: ET.Element, T: np.ndarray, depth: int) -> None:
        if depth > MAX_NODE_DEPTH:
            raise ModelError(f"{where}: nodes nested deeper than {MAX_NODE_DEPTH} (a cycle?)")
        T = T @ _node_matrix(node, where)
        for ig in node.findall("instance_geometry"):
            bind = {im.get("symbol"): colour.get(_ref(im.get("target")))
                    for im in ig.iter("instance_material")}
            for pos, faces, symbol in geometry(_ref(ig.get("url"))):
                parts.append((pos @ T[:3, :3].T + T[:3, 3], faces, bind.get(symbol)))
        for inode in node.findall("instance_node"):
            target = library_nodes.get(_ref(inode.get("url")))
            if target is not None:
                visit(target, T, depth + 1)
        for child in node.findall("node"):
            visit(child, T, depth + 1)

    scenes = list(root.iter("visual_scene"))
    if scenes:
        for node in scenes[0].findall("node"):
            visit(node, np.eye(4), 0)
    else:  # no scene: every geometry where it is
        for gid in geometries:
            parts.extend((p, f, None) for p, f, _ in geometry(gid))
    verts: list[np.ndarray] = []
    faces: list[np.ndarray] = []
    groups: list[tuple[int, int, tuple[float, float, float] | None]] = []
    nv = nf = 0
    for pos, f, rgb in parts:
        verts.append(pos * meter)
        faces.append(f + nv)
        groups.append((nf, len(f), rgb))
        nv += len(pos)
        nf += len(f)
    if not nf:
        raise ModelError(f"{where}: no triangles or polygons in the file")
    return Mesh(np.concatenate(verts), np.concatenate(faces), tuple(groups))


def read_mesh(path: str | Path) -> Mesh:
    """The :class:`Mesh` of an STL, OBJ or COLLADA file; ModelError naming the file otherwise.
    Each file is parsed once (:mod:`.mesh_store`): the arrays are shared and read-only."""
    where = f"mesh {str(path)!r}"
    if "://" in str(path):
        raise ModelError(f"{where}: an address, not a file (resolve package:// first)")
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in SUFFIXES:
        raise ModelError(f"{where}: only STL, OBJ and COLLADA (.dae) meshes are read (not "
                         f"{suffix or 'this'})")
    try:
        st = p.stat()
        if st.st_size > MAX_MESH_BYTES:
            raise ModelError(f"{where}: {st.st_size} bytes, more than {MAX_MESH_BYTES}")
        key = mesh_store.file_key(p, st)
        hit = mesh_store.remembered(key)
        if hit is not None:
            return Mesh(*hit)
        data = p.read_bytes()
    except OSError as exc:
        raise ModelError(f"{where}: cannot be read ({exc.strerror or exc})") from None
    content = mesh_store.digest(data, suffix)
    arrays = mesh_store.load(content)
    if arrays is None:
        reader = {".stl": _stl, ".obj": _obj, ".dae": _dae}[suffix]
        m = reader(data, where)
        if not np.all(np.isfinite(m.vertices)):
            raise ModelError(f"{where}: coordinates that are not finite numbers")
        arrays = (m.vertices, m.faces, m.groups)
        mesh_store.store(content, arrays)
    return Mesh(*mesh_store.remember(key, arrays))
