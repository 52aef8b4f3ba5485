"""Mesh files through meshio: read Gmsh, Abaqus .inp, VTU and the rest; write VTU atomically.

Reading keeps one volume cell type ("hexahedron" -> hex8, "hexahedron27" -> hex27; meshio
already turns Gmsh's hex27 node order into the VTK order used here, which the tests check on a
hand-written Gmsh file), drops nodes no volume cell uses and carries named groups over:

- point sets (Abaqus NSET) become node sets;
- cell sets (Abaqus ELSET) and Gmsh physical groups (named by $PhysicalNames, else by their tag
  number) become element sets for their volume cells and face sets for their quadrilaterals that
  match boundary faces (re-ordered outward); the nodes of every group become a node set unless a
  point set of that name exists.

hex18 has no VTK cell type: it is written as a hex27 whose nine mid-thickness nodes are
interpolated linearly between its two quad9 layers (exact, since hex18 is linear through the
thickness), so ParaView shows the true geometry; point data is interpolated the same way. The
extra nodes are appended after the mesh nodes, so node indices of the mesh are unchanged.
"""

from __future__ import annotations

import contextlib
import io
import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..fem.shapes import NODES
from ..io.atomic import replacing
from .faces import match_boundary_faces
from .mesh import MIXABLE, PLANAR_MIXABLE, Mesh

if TYPE_CHECKING:
    import meshio

_VOLUME = {"hexahedron": "hex8", "hexahedron27": "hex27", "tetra": "tet4", "tetra10": "tet10", "wedge": "wedge6",
           "hexahedron20": "hex20"}
#: the planar cells of a two-dimensional file (no volume cells: a plane strain, plane stress or axisymmetric body's
#: mesh in the x-y plane; lines become edge sets)
_PLANAR = {"quad": "quad4", "quad8": "quad8", "quad9": "quad9", "triangle": "tri3", "triangle6": "tri6"}
_TO_MESHIO = {**{v: k for k, v in _VOLUME.items()}, **{v: k for k, v in _PLANAR.items()}}
#: node permutations turning a clockwise planar cell counter-clockwise
_PLANAR_FLIP = {"quad4": [0, 3, 2, 1], "quad8": [0, 3, 2, 1, 7, 6, 5, 4], "quad9": [0, 3, 2, 1, 7, 6, 5, 4, 8],
                "tri3": [0, 2, 1], "tri6": [0, 2, 1, 5, 4, 3]}
_FACE_CELLS = ("quad", "quad8", "quad9", "triangle", "triangle6")
#: the edges S1..Sn of the planar cells (face k from corner k to corner k + 1, as Abaqus numbers them; the mid-node
#: of a quadratic edge matches with its corners)
_PLANAR_EDGES = {"quad4": {1: (0, 1), 2: (1, 2), 3: (2, 3), 4: (3, 0)},
                 "quad8": {1: (0, 1), 2: (1, 2), 3: (2, 3), 4: (3, 0)},
                 "quad9": {1: (0, 1), 2: (1, 2), 3: (2, 3), 4: (3, 0)},
                 "tri3": {1: (0, 1), 2: (1, 2), 3: (2, 0)}, "tri6": {1: (0, 1), 2: (1, 2), 3: (2, 0)}}
_DIM = {"vertex": 0, "line": 1, "line3": 1, "triangle": 2, "triangle6": 2, "quad": 2, "quad8": 2,
        "quad9": 2}


class MeshError(ValueError):
    """A mesh file that cannot be read or holds no supported volume cells."""


class MixedTypesError(MeshError):
    """A mesh file of volume cell types that one mesh does not mix (read one of them with ``cell_type``)."""


def _fail(path: Path, problem: str) -> MeshError:
    return MeshError(f"{path}: {' '.join(str(problem).split())}")


def _hex18_to_hex27() -> tuple[np.ndarray, np.ndarray]:
    """For each hex27 node, the pair of hex18 nodes whose mean it is (equal pair: that node)."""
    h18, h27 = NODES["hex18"], NODES["hex27"]
    pairs = np.empty((27, 2), dtype=np.int64)
    for a, x in enumerate(h27):
        lo = np.array([x[0], x[1], -1.0 if x[2] == 0.0 else x[2]])
        hi = np.array([x[0], x[1], 1.0 if x[2] == 0.0 else x[2]])
        pairs[a, 0] = np.nonzero(np.all(h18 == lo, axis=1))[0][0]
        pairs[a, 1] = np.nonzero(np.all(h18 == hi, axis=1))[0][0]
    return pairs[:, 0], pairs[:, 1]


_H27_LO, _H27_HI = _hex18_to_hex27()


def _expand_hex18(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """hex27 connectivity of a hex18 mesh; returns (cells27, lo, hi) with new node k = mean(lo, hi)."""
    lo, hi = mesh.cells[:, _H27_LO], mesh.cells[:, _H27_HI]
    mid = lo != hi
    key = np.stack([np.minimum(lo[mid], hi[mid]), np.maximum(lo[mid], hi[mid])], axis=1)
    uniq, inv = np.unique(key, axis=0, return_inverse=True)
    cells = lo.copy()
    cells[mid] = mesh.n_nodes + inv.ravel()
    return cells, uniq[:, 0], uniq[:, 1]


def to_meshio(
    mesh: Mesh, point_data: Mapping[str, np.ndarray] | None = None,
    cell_data: Mapping[str, np.ndarray] | None = None,
) -> meshio.Mesh:
    """A meshio.Mesh of ``mesh`` with its node and element sets (hex18 becomes hex27, see above)."""
    import meshio  # here, not at the top: a run that writes no mesh file does not pay for its import

    pdata = {k: np.asarray(v) for k, v in (point_data or {}).items()}
    for k, v in pdata.items():
        if v.shape[0] != mesh.n_nodes:
            raise ValueError(f"point data {k!r} has {v.shape[0]} rows for {mesh.n_nodes} nodes")
    for k, v in (cell_data or {}).items():
        if np.shape(v)[0] != mesh.n_cells:
            raise ValueError(f"cell data {k!r} has {np.shape(v)[0]} rows for {mesh.n_cells} cells")
    points = mesh.points
    if mesh.cell_type == "hex18":
        cells, lo, hi = _expand_hex18(mesh)
        points = np.concatenate([points, 0.5 * (points[lo] + points[hi])])
        pdata = {k: np.concatenate([v, 0.5 * (v[lo] + v[hi])]) for k, v in pdata.items()}
        blocks = [("hex27", cells, 0)]
    else:
        blocks = mesh.blocks
    split = [b.first for b in blocks[1:]] if len(blocks) > 1 else []

    def per_block(v: np.ndarray) -> list[np.ndarray]:
        return np.split(np.asarray(v), split) if split else [np.asarray(v)]

    def set_per_block(v: np.ndarray) -> list[np.ndarray]:
        return [v[(v >= b[2]) & (v < b[2] + len(b[1]))] - b[2] for b in blocks]

    return meshio.Mesh(
        points, [(_TO_MESHIO[b[0]], b[1]) for b in blocks], point_data=pdata,
        cell_data={k: per_block(v) for k, v in (cell_data or {}).items()},
        point_sets={k: v.copy() for k, v in mesh.node_sets.items()},
        cell_sets={k: set_per_block(v) for k, v in mesh.element_sets.items()},
    )


def write_vtu(
    path: str | os.PathLike[str], mesh: Mesh, point_data: Mapping[str, np.ndarray] | None = None,
    cell_data: Mapping[str, np.ndarray] | None = None,
) -> None:
    """Write ``mesh`` with optional data to a VTU file, atomically (temp file, then replace)."""
    m = to_meshio(mesh, point_data, cell_data)
    m.point_sets, m.cell_sets = {}, {}
    target = Path(path)
    import meshio

    with replacing(target) as tmp:
        meshio.write(tmp, m, file_format="vtu")


def _groups(m: meshio.Mesh) -> dict[str, list[tuple[int, np.ndarray]]]:
    """Named groups as name -> [(cell block index, indices within the block)].

    meshio's cell sets (Abaqus ELSET, named Gmsh 4 physical groups) first; failing those, the
    "gmsh:physical" tags of each cell (Gmsh 2), named through $PhysicalNames.
    """
    out: dict[str, list[tuple[int, np.ndarray]]] = {}
    for name, per_block in m.cell_sets.items():
        if name.startswith("gmsh:"):
            continue
        for b, ids in enumerate(per_block):
            if ids is not None and b < len(m.cells) and np.size(ids):
                out.setdefault(name, []).append((b, np.asarray(ids, dtype=np.int64)))
    phys = m.cell_data.get("gmsh:physical")
    if out or phys is None or len(phys) != len(m.cells):
        return out
    names = {(int(v[0]), int(v[1])): k for k, v in m.field_data.items() if np.size(v) == 2}
    for b, (block, tags) in enumerate(zip(m.cells, phys, strict=True)):
        tags = np.asarray(tags)
        for tag in np.unique(tags):
            name = names.get((int(tag), _DIM.get(block.type, 3)), str(int(tag)))
            out.setdefault(name, []).append((b, np.nonzero(tags == tag)[0]))
    return out


def read_mesh(path: str | os.PathLike[str], cell_type: str | None = None) -> Mesh:
    """Read a mesh file through meshio (Gmsh v2/v4, Abaqus .inp, VTU, ...).

    Args:
        path: the file.
        cell_type: "hex8" or "hex27" when the file holds both; by default its only one.

    Raises:
        MeshError: the file does not parse or holds no (or an ambiguous) supported volume cell.
    """
    p = Path(path)
    if not p.is_file():
        raise _fail(p, "no such file")
    return mesh_from_meshio(read_meshio(p), p, cell_type)


def read_meshio(p: Path) -> meshio.Mesh:
    """meshio's mesh of the file ``p``, meshio's own output kept off the terminal; MeshError naming the file and
    meshio's first line where it cannot read it."""
    import meshio

    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            return meshio.read(p)
    except (Exception, SystemExit) as exc:  # meshio raises many kinds, or exits, on bad input
        lines = [ln for ln in said.getvalue().splitlines() if ln.strip()]
        why = lines[0] if lines else f"{type(exc).__name__}: {exc}"
        raise _fail(p, f"cannot read mesh ({why})") from exc


def mesh_from_meshio(m: meshio.Mesh, p: Path, cell_type: str | None = None,
                     surfaces: tuple[dict, dict] | None = None) -> Mesh:
    """The Mesh of a meshio mesh ``m`` read from ``p`` (what ``read_mesh`` does after meshio; an Abaqus file's
    *SURFACE definitions ``surfaces`` (element, node: as ``abaqus.read_surfaces`` gives them) are read from ``p``
    unless given)."""
    found = sorted({_VOLUME[b.type] for b in m.cells if b.type in _VOLUME})
    kinds, face_cells, note = _VOLUME, _FACE_CELLS, ""
    flat = [b for b in m.cells if b.type in _PLANAR]
    if not found and flat and m.points.shape[1] > 2 and np.any(m.points[np.unique(np.concatenate(
            [b.data.ravel() for b in flat]))][:, 2] != 0.0):
        note = " (two-dimensional cells make a planar body's mesh only in the x-y plane, z = 0)"
    elif not found and flat:  # a two-dimensional mesh: planar cells, edge groups
        kinds, face_cells = _PLANAR, ("line", "line3")
        found = sorted({_PLANAR[b.type] for b in m.cells if b.type in _PLANAR})
        planar_mixed = any(set(found) <= set(pair) for pair in PLANAR_MIXABLE)
        if cell_type is None and len(found) > 1 and not planar_mixed:
            raise MixedTypesError(_fail(p, f"holds {' and '.join(found)} cells, which one mesh does not mix (only "
                                           f"quad4 with tri3, quad8 with tri6): take the cells of one type (a body's "
                                           f"element = \"TYPE\")"))
    from meshio._mesh import topological_dimension

    other = sorted({b.type for b in m.cells if topological_dimension.get(b.type) == 3 and b.type not in _VOLUME})
    if other:
        raise _fail(p, f"holds {', '.join(other)} cells, which covcontact does not have; its volume cells are "
                       f"{', '.join(_VOLUME)}: mesh without them (Gmsh: no pyramids or wedges of other orders)")
    if cell_type is not None and cell_type not in _TO_MESHIO:
        raise _fail(p, f"cell_type must be one of {', '.join(_TO_MESHIO)}, got {cell_type!r}")
    if not found:
        kinds = ", ".join(sorted({b.type for b in m.cells})) or "none"
        raise _fail(p, f"no supported volume cells ({', '.join(_VOLUME)}); found: {kinds}{note}")
    if cell_type is None:
        if kinds is _PLANAR:
            chosen = found
        elif len(found) > 1 and not set(found) <= set(MIXABLE):
            raise MixedTypesError(_fail(p, f"holds {' and '.join(found)} cells, which one mesh does not mix (only "
                                           f"{', '.join(MIXABLE)} cells mix): take the cells of one type (a body's "
                                           f"element = \"TYPE\", read_mesh's cell_type)"))
        chosen = found
    elif cell_type not in found:
        raise _fail(p, f"no {cell_type} cells; found: {', '.join(found)}")
    else:
        chosen = [cell_type]
    vol = [b for b, blk in enumerate(m.cells) if kinds.get(blk.type) in chosen]
    first = np.cumsum([0] + [len(m.cells[b].data) for b in vol])
    pts = np.zeros((len(m.points), 3))
    pts[:, : min(3, m.points.shape[1])] = m.points[:, :3]
    used = np.unique(np.concatenate([m.cells[b].data.ravel() for b in vol]).astype(np.int64))
    new = np.full(len(pts), -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    blocks = [(kinds[m.cells[b].type], new[m.cells[b].data.astype(np.int64)]) for b in vol]
    if kinds is _PLANAR:
        blocks = [(t, _counter_clockwise(t, pts[used], c)) for t, c in blocks]
    mesh = Mesh.of_blocks(pts[used], blocks)

    def keep(nodes: np.ndarray) -> np.ndarray:
        k = new[np.asarray(nodes, dtype=np.int64)]
        return k[k >= 0]

    for name, ids in m.point_sets.items():
        mesh.add_node_set(name, keep(ids))
    for name, parts in _groups(m).items():
        elems, faces, nodes = [], [], []
        for b, ids in parts:
            data = m.cells[b].data[ids]
            nodes.append(data.ravel())
            if b in vol:
                elems.append(first[vol.index(b)] + ids)
            elif m.cells[b].type in face_cells and len(data):
                faces.append(new[data[:, :4]])
        if elems:
            mesh.element_sets[name] = np.unique(np.concatenate(elems)).astype(np.int64)
        if faces and len({f.shape[1] for f in faces}) == 1:  # (a group of wedge triangles and quadrilaterals: no
            f = np.concatenate(faces)                          # face set, a face set holds one type)
            mesh.face_groups[name] = f[np.all(f >= 0, axis=1)]
            matched, _ = match_boundary_faces(mesh, f[np.all(f >= 0, axis=1)])
            if matched.shape[0]:
                mesh.add_face_set(name, matched)
        kept = keep(np.concatenate(nodes))
        if name not in mesh.node_sets and kept.size:
            mesh.add_node_set(name, kept)
    if p.suffix.lower() == ".inp" or surfaces is not None:
        _abaqus_surfaces(p, m, mesh, vol, first, keep, surfaces)
    return mesh


def _counter_clockwise(cell_type: str, points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Planar ``cells`` with the clockwise ones (in the x-y plane) renumbered counter-clockwise."""
    from ..fem.planar_cells import CENTRE, reference_jacobians

    det = reference_jacobians(cell_type, points, cells, np.array([CENTRE[cell_type]]))[:, 0]
    cells = cells.copy()
    flip = det < 0.0
    cells[flip] = cells[flip][:, _PLANAR_FLIP[cell_type]]
    return cells


def _abaqus_surfaces(p: Path, m, mesh: Mesh, vol: list, first: np.ndarray, keep, surfaces=None) -> None:
    """The deck's *SURFACE definitions as face sets (element surfaces: their faces, matched outward) and node
    sets (node surfaces), each element surface also a node set of its nodes."""
    from .abaqus import HEX_FACES, TET_FACES, WEDGE_FACES, read_surfaces

    try:
        elem, node = read_surfaces(p) if surfaces is None else surfaces
    except (ValueError, OSError) as exc:
        raise _fail(p, str(exc)) from exc
    for name, refs in elem.items():
        faces = []
        for elset, face in refs:
            parts = m.cell_sets.get(elset)
            if parts is None:
                raise _fail(p, f"*SURFACE {name}: no element set {elset!r}")
            for k, b in enumerate(vol):
                ids = np.asarray(parts[b], dtype=np.int64) if b < len(parts) and parts[b] is not None else []
                if len(ids):
                    ctype, cells = mesh.cells_of(first[k] + ids)
                    table = (TET_FACES if ctype in ("tet4", "tet10") else WEDGE_FACES if ctype == "wedge6"
                             else _PLANAR_EDGES[ctype] if ctype in _PLANAR_EDGES else HEX_FACES)
                    if face not in table:
                        raise _fail(p, f"*SURFACE {name}: {ctype} elements have the faces S1..S{len(table)}, "
                                       f"not S{face}")
                    faces.append(cells[:, list(table[face])])
        if not faces:
            raise _fail(p, f"*SURFACE {name}: its element sets hold no volume cells")
        if len({f.shape[1] for f in faces}) > 1:
            raise _fail(p, f"*SURFACE {name}: mixes triangular and quadrilateral faces (wedges: S1, S2 and S3..S5); "
                           f"a surface holds faces of one type: split it in two")
        f = np.concatenate(faces)
        matched, found = match_boundary_faces(mesh, f)
        if not found.all():
            raise _fail(p, f"*SURFACE {name}: {int((~found).sum())} of its faces are not on the boundary "
                           f"(a face identifier of another element type?)")
        mesh.face_groups[name] = f
        mesh.add_face_set(name, matched)
        if name not in mesh.node_sets:
            mesh.add_node_set(name, matched.ravel())
    for name, refs in node.items():
        ids = []
        for r in refs:
            if r.isdigit():
                raise _fail(p, f"*SURFACE {name}, TYPE=NODE: node numbers are not supported; name an *NSET")
            if r not in m.point_sets:
                raise _fail(p, f"*SURFACE {name}: no node set {r!r}")
            ids.append(keep(m.point_sets[r]))
        mesh.add_node_set(name, np.concatenate(ids))
