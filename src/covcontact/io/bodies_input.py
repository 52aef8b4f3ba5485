"""The ``[[bodies]]`` section: deformable bodies, their meshes (generated or read), node sets given in the
input and materials (docs/input.md)."""

from __future__ import annotations

import copy
import inspect
import math
from pathlib import Path

import numpy as np

from ..description import Body
from .validate import _REQUIRED, InputError, Section, suggest

CELLS = ("hex8", "hex18", "hex27", "tet4", "tet10", "wedge6", "hex20")
#: the cells of plane strain, plane stress and axisymmetric bodies (x-y plane)
PLANAR_CELLS = ("quad4", "quad8", "quad9", "tri3", "tri6")
PLANAR_FORMULATIONS = ("plane_strain", "plane_stress", "axisymmetric")


def mesh_generators() -> dict:
    """The mesh generators a ``mesh = { generator = NAME }`` may name: name -> function."""
    from ..mesh import generators, generators_planar, generators_solid

    return {name: fn for mod in (generators, generators_solid, generators_planar) for name, fn in vars(mod).items()
            if inspect.isfunction(fn) and not name.startswith("_") and fn.__module__ == mod.__name__
            and "cell" in inspect.signature(fn).parameters}


_MESH_FILES: dict = {}


#: meshes already read, by resolved path and modification time (``preload``): the files an import just wrote
_PRELOADED: dict = {}


def preload(meshes: dict) -> None:
    """Hand the loader meshes it would read from these files (path -> Mesh; the files as they are now)."""
    _PRELOADED.clear()
    for path, mesh in meshes.items():
        p = Path(path)
        _PRELOADED[(str(p.resolve()), p.stat().st_mtime_ns)] = mesh


def _read_once(path: Path, element: str | None = None):
    """A mesh file read once per problem file for all the bodies that take parts of it (keyed by path and
    modification time); callers copy or select from it, never change it. A file of cell types that do not mix
    gives the cells of ``element`` when that is given."""
    from ..mesh.io import MixedTypesError, read_mesh

    key = (str(path.resolve()), path.stat().st_mtime_ns)
    if key in _PRELOADED:
        return _PRELOADED[key]
    if key not in _MESH_FILES:
        _MESH_FILES.clear()  # one file at a time: a problem's bodies come one after the other
        try:
            _MESH_FILES[key] = read_mesh(path)
        except MixedTypesError:
            if element is None:
                raise
            return read_mesh(path, element)
    return _MESH_FILES[key]


def build_shell(shell: Section, sec: Section, base: Path):
    """The solid-shell mesh of a body with ``shell = { thickness, offset }`` and ``mesh = { file = "SURFACE" }``, a
    mid-surface mesh (mesh/shell.py ``extrude_surface``)."""
    from ..mesh.shell import EDGE_SIDES, OFFSETS, ShellMeshError, extrude_surface, read_surface

    thickness = shell.get("thickness", "any")
    per_node = isinstance(thickness, list)
    values = thickness if per_node else [thickness]
    if not values or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0
                             for v in values):
        shell.fail(f"must be a positive number or an array of them (one per node of the surface mesh), got "
                   f"{thickness if not per_node else next((v for v in values if not (isinstance(v, (int, float)) and v > 0)), values)!r}",
                   "thickness")
    offset = shell.get("offset", "any", "middle")

    def number(v) -> bool:
        return isinstance(v, (int, float)) and not isinstance(v, bool) and -0.5 <= v <= 0.5

    if isinstance(offset, str):
        if offset not in OFFSETS:
            shell.fail(f"must be \"middle\", \"top\", \"bottom\" or a number in [-0.5, 0.5], got {offset!r}"
                       f"{suggest(offset, list(OFFSETS))}", "offset")
    elif isinstance(offset, list):  # (one per node of the surface file: a deck's sections of different OFFSET)
        if not offset or not all(number(v) for v in offset):
            shell.fail(f"an array of offsets must hold numbers in [-0.5, 0.5], got "
                       f"{next((v for v in offset if not number(v)), offset)!r}", "offset")
    elif not number(offset):
        shell.fail(f"must be \"middle\", \"top\", \"bottom\" or a number in [-0.5, 0.5], got {offset!r}", "offset")
    creases = shell.get("creases", "str", "mean", choices=("mean", "knots"))
    knot_angle = shell.get("knot_angle", "float", 20.0, positive=True)
    if shell.has("knot_angle") and creases != "knots":
        shell.fail("is the angle between normals beyond which a node becomes a knot: it needs creases = \"knots\"",
                   "knot_angle")
    faces = shell.get("faces", "table", None)
    face_rows = {}
    if faces is not None:  # NAME = [["ELSET", "top" | "bottom"], ...]: the faces of those cells on that side
        for name in list(faces.data):
            rows = faces.get(name, "any")
            if not (isinstance(rows, list) and rows and all(isinstance(r, list) and len(r) == 2 and isinstance(r[0], str)
                                                            and r[1] in ("top", "bottom", *EDGE_SIDES) for r in rows)):
                faces.fail("must be an array of [\"ELEMENT SET\", \"top\", \"bottom\" or \"edge1\"..\"edge4\"] "
                           "pairs", name)
            face_rows[name] = rows
        faces.done()
    shell.done()
    if not sec.has("file"):
        sec.fail("a shell body's mesh is a surface mesh file: give mesh = { file = \"SURFACE.msh\" }")
    fname = sec.get("file", "str")
    sec.done()
    path = (base / fname) if not Path(fname).is_absolute() else Path(fname)
    if not path.exists():
        sec.fail(f"mesh file {fname!r} does not exist (looked for {path}; a relative path is taken from the "
                 f"problem file's folder)", "file")
    key = (str(path.resolve()), path.stat().st_mtime_ns)
    if key in _PRELOADED:  # (the solid-shells a deck's import built from this file)
        return _PRELOADED[key]
    try:
        points, cell_type, cells, node_sets, element_sets = read_surface(path)
        if per_node and len(values) != points.shape[0]:
            shell.fail(f"has {len(values)} values for the {points.shape[0]} nodes of {fname}", "thickness")
        if isinstance(offset, list) and len(offset) != points.shape[0]:
            shell.fail(f"has {len(offset)} values for the {points.shape[0]} nodes of {fname}", "offset")
        missing = [e for rows in face_rows.values() for e, _ in rows if e not in element_sets]
        if missing:
            shell.fail(f"faces: no element set {missing[0]!r} in {fname}", "faces")
        face_sets = {name: [(element_sets[e], side) for e, side in rows] for name, rows in face_rows.items()}
        return extrude_surface(points, cell_type, cells, np.asarray(values, dtype=float) if per_node else thickness,
                               np.asarray(offset, dtype=float) if isinstance(offset, list) else offset, node_sets,
                               element_sets, face_sets,
                               knot_angle if creases == "knots" else None)
    except ShellMeshError as exc:
        sec.fail(str(exc), "file")


def build_mesh(sec: Section, base: Path, element: str | None):
    """Mesh from ``generator = ...`` plus its arguments, or ``file = ...`` (read through meshio)."""
    from ..mesh.io import MeshError

    if sec.has("file") == sec.has("generator"):
        sec.fail("give exactly one of 'file' or 'generator'")
    if sec.has("file"):
        fname = sec.get("file", "str")
        volume = sec.get("volume", "str", None)
        sec.done()
        path = (base / fname) if not Path(fname).is_absolute() else Path(fname)
        if not path.exists():
            sec.fail(f"mesh file {fname!r} does not exist (looked for {path}; a relative path is taken from the "
                     f"problem file's folder)", "file")
        try:
            mesh = _read_once(path, element)
        except (MeshError, ValueError, KeyError, OSError) as exc:
            sec.fail(f"cannot read mesh file {path}: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}",
                     "file")
        if element is not None and mesh.cell_type != element:
            sec.fail(f"element {element!r} does not match the mesh file's cells ({' and '.join(mesh.cell_types)})",
                     "file")
        if volume is not None:  # one body of several in the file: its element set (Gmsh physical volume, ELSET)
            if volume not in mesh.element_sets:
                known = ", ".join(sorted(mesh.element_sets)) or "none"
                sec.fail(f"{fname} has no volume (element set) {volume!r}{suggest(volume, mesh.element_sets)} "
                         f"(known: {known})", "volume")
            from ..mesh.parts import select

            return select(mesh, mesh.element_sets[volume])
        return copy.deepcopy(mesh)
    gens = mesh_generators()
    name = sec.get("generator", "str", choices=tuple(sorted(gens)))
    fn = gens[name]
    params = inspect.signature(fn).parameters
    kwargs = {}
    for key, value in sec.rest().items():
        if key not in params or key == "cell":
            allowed = ", ".join(k for k in params if k != "cell")
            sec.fail(f"unknown key for generator {name!r}{suggest(key, [k for k in params if k != 'cell'])} "
                     f"(allowed: {allowed})", key)
        if isinstance(value, bool) or not isinstance(value, (int, float, str, list)):
            sec.fail("must be a number, string or array", key)
        if isinstance(value, list):
            value = tuple(value)
        kwargs[key] = value
    missing = [k for k, p in params.items() if p.default is inspect.Parameter.empty and k not in kwargs
               and k != "cell"]
    if missing:
        sec.fail(f"generator {name!r} needs {', '.join(missing)}")
    from ..mesh.convert import SOURCE, convert

    try:
        if element in SOURCE:  # bricks split (tet4, tet10, wedge6) or trimmed (hex20); no face sets
            return convert(fn(cell=SOURCE[element], **kwargs), element)
        return fn(cell=element or ("quad4" if getattr(fn, "planar", False) else "hex8"), **kwargs)
    except (ValueError, TypeError) as exc:
        sec.fail(f"generator {name!r}: {exc}")


HARDENING = {"linear": ("modulus",), "swift": ("K", "eps0", "n"), "voce": ("sigma_inf", "delta", "modulus"),
             "table": ("stress", "strain")}


def _hardening(sec: Section) -> dict:
    law = sec.get("law", "str", choices=tuple(HARDENING))
    out: dict = {"law": law}
    for key in HARDENING[law]:
        if law == "table":  # arrays of numbers: (yield stress, equivalent plastic strain) points
            out[key] = sec.get(key, "floats")
            continue
        optional = law == "voce" and key == "modulus"
        value = sec.get(key, "float", 0.0 if optional else _REQUIRED)
        out[key] = value
    sec.done()
    if law == "table":  # the table's own checks, reported at the hardening table
        from ..materials.plasticity import hardening_from_dict

        try:
            hardening_from_dict(out)
        except ValueError as exc:
            sec.fail(str(exc))
    return out


def read_material(sec: Section):
    from ..materials import material_from_name

    from ..materials.rubber import MODELS, RubberError, rubber_from_keys

    model = sec.get("model", "str", choices=("svk", "saint-venant-kirchhoff", "neo-hooke", "neohooke", "j2",
                                             *MODELS[1:]))
    if model in MODELS[1:] or (model in ("neo-hooke", "neohooke") and not sec.has("E") and not sec.has("nu")):
        # the rubber models of the manuals (Neo-Hooke with c10 and d1; with E and nu the compressible Neo-Hooke)
        density = sec.get("density", "float", None, positive=True)
        if sec.has("test_data"):  # (the constants fitted to test data: materials/fit.py)
            from ..materials.fit import FitError, fitted_material

            try:
                return fitted_material(model, sec.rest(), Path(sec.file).parent, density)
            except (FitError, RubberError) as exc:
                sec.fail(str(exc), exc.key)
        try:
            return rubber_from_keys(model, sec.rest(), density)
        except RubberError as exc:
            sec.fail(str(exc), exc.key)
    E = sec.get("E", "float", positive=True)
    nu = sec.get("nu", "float")
    density = sec.get("density", "float", None, positive=True)
    if not -1.0 < nu < 0.5:
        sec.fail(f"must lie in (-1, 0.5), got {nu}", "nu")
    if model == "j2":
        from ..materials.plasticity import J2Plasticity

        yield_stress = sec.get("yield_stress", "float", None)
        hardening = _hardening(sec.get("hardening", "table"))
        kinematic = sec.get("kinematic_modulus", "float", 0.0, nonnegative=True)
        hill = None
        if sec.has("hill48"):
            h = sec.get("hill48", "table")
            hill = {k: h.get(k, "float") for k in ("r0", "r45", "r90")}
            h.done()
        sec.done()
        try:
            return J2Plasticity(E=E, nu=nu, yield_stress=yield_stress, hardening=hardening,
                                kinematic_modulus=kinematic, hill48=hill, density=density)
        except ValueError as exc:
            sec.fail(str(exc))
    sec.done()
    try:
        return material_from_name(model, E=E, nu=nu, density=density)
    except ValueError as exc:
        sec.fail(str(exc))


def user_cells(sec: Section | None, mesh) -> None:
    """Element sets defined in the input: ``cells = { NAME = { box = [[x0, y0, z0], [x1, y1, z1]] } }`` (the cells
    whose centroid lies inside the box, bounds included) or ``{ elements = [i, j, ...] }`` (cell numbers, from 0)."""
    if sec is None:
        return
    for name in list(sec.data):
        if name in mesh.element_sets:
            sec.fail(f"an element set {name!r} exists already (from the mesh)", name)
        d = sec.get(name, "table")
        given = [k for k in ("box", "elements") if d.has(k)]
        if len(given) != 1:
            d.fail("give exactly one of 'box' or 'elements'")
        if given[0] == "elements":
            raw = d.get("elements", "any")
            if not isinstance(raw, list) or not raw or not all(isinstance(v, int) and not isinstance(v, bool)
                                                               for v in raw):
                d.fail("must be a non-empty array of cell numbers", "elements")
            ids = np.unique(np.asarray(raw, dtype=np.int64))
            if ids.min() < 0 or ids.max() >= mesh.n_cells:
                d.fail(f"cell numbers must lie in [0, {mesh.n_cells - 1}]", "elements")
        else:
            box = d.get("box", "any")
            if not (isinstance(box, list) and len(box) == 2 and all(
                    isinstance(q, list) and len(q) == 3 and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                                for v in q) for q in box)):
                d.fail("must be [[x0, y0, z0], [x1, y1, z1]]", "box")
            lo, hi = np.asarray(box, dtype=float)
            c = mesh.centroids()
            ids = np.flatnonzero(np.all((c >= lo) & (c <= hi), axis=1))
            if ids.size == 0:
                d.fail("no cell centroid lies inside this box", "box")
        d.done()
        mesh.element_sets[name] = ids


def user_sets(sec: Section | None, mesh) -> None:
    """Node sets defined in the input: ``sets = { NAME = { box = [[x0, y0, z0], [x1, y1, z1]] } }`` (the nodes
    inside an axis-aligned box, bounds included), ``{ closest = [x, y, z] }`` or ``{ closest = [[...], ...] }``
    (the node nearest to each point) or ``{ nodes = [i, j, ...] }`` (node numbers of the mesh, from 0)."""
    if sec is None:
        return
    X = mesh.points
    for name in list(sec.data):
        if name in mesh.node_sets:
            sec.fail(f"a node set {name!r} exists already (from the mesh)", name)
        d = sec.get(name, "table")
        given = [k for k in ("box", "closest", "nodes") if d.has(k)]
        if len(given) != 1:
            d.fail("give exactly one of 'box', 'closest' or 'nodes'")
        kind = given[0]
        raw = d.get(kind, "any")
        d.done()
        key = d.key_path(kind)
        where = f"{d.file}: {key}"
        if kind == "nodes":
            if not isinstance(raw, list) or not raw or not all(isinstance(v, int) and not isinstance(v, bool)
                                                               for v in raw):
                raise InputError(f"{where}: must be a non-empty array of node numbers")
            ids = np.asarray(raw, dtype=np.int64)
            if ids.min() < 0 or ids.max() >= len(X):
                raise InputError(f"{where}: node numbers must lie in [0, {len(X) - 1}]")
        else:
            pts = raw if isinstance(raw, list) and raw and isinstance(raw[0], list) else [raw]
            ok = all(isinstance(q, list) and len(q) == 3 and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in q)
                for q in pts)
            if not ok or (kind == "box" and len(pts) != 2):
                shape = "two points [[x0, y0, z0], [x1, y1, z1]]" if kind == "box" else \
                    "a point [x, y, z] or an array of points"
                raise InputError(f"{where}: must be {shape}")
            P = np.asarray(pts, dtype=float)
            if kind == "box":
                lo, hi = P.min(axis=0), P.max(axis=0)
                ids = np.flatnonzero(np.all((X >= lo) & (X <= hi), axis=1))
                if ids.size == 0:
                    raise InputError(f"{where}: no node lies in the box")
            else:
                ids = np.unique(np.argmin(((X[None, :, :] - P[:, None, :]) ** 2).sum(axis=2), axis=1))
        mesh.node_sets[name] = np.unique(ids).astype(np.int64)


FACE_FILTERS = ("box", "normal", "cells")


def user_faces(sec: Section | None, mesh) -> None:
    """Face sets defined in the input (docs/input.md, "Face sets of your own"): ``faces = { NAME = { ... } }``,
    the boundary faces that pass every filter given: ``box = [[x0, y0, z0], [x1, y1, z1]]`` (all their nodes
    inside, bounds included), ``normal = [nx, ny, nz]`` with ``angle`` (degrees, default 10: the outward
    normal at the face's centre within that angle of the direction), ``cells = "SET"`` (faces of the elements
    of that element set); or ``union = ["a", "b", ...]`` of face sets. Each also becomes a node set of the
    same name (its nodes), as the generators' sets are."""
    if sec is None:
        return
    from ..mesh.faces import all_boundary_faces, edge_normals, face_normals

    every = all_boundary_faces(mesh)
    X = mesh.points
    for name in list(sec.data):
        if name in mesh.face_sets or name in mesh.node_sets:
            sec.fail(f"a {'face' if name in mesh.face_sets else 'node'} set {name!r} exists already", name)
        d = sec.get(name, "table")
        if d.has("union"):
            parts = d.get("union", "any")
            d.done()
            if not (isinstance(parts, list) and parts and all(isinstance(p, str) for p in parts)):
                d.fail("must be a non-empty array of face set names", "union")
            missing = [p for p in parts if p not in mesh.face_sets]
            if missing:
                d.fail(f"no face set {missing[0]!r}{suggest(missing[0], mesh.face_sets)} (known: "
                       f"{', '.join(sorted(mesh.face_sets)) or 'none'}; sets defined here count from above)", "union")
            chosen = np.unique(np.vstack([mesh.face_sets[p] for p in parts]), axis=0)
        else:
            if d.has("angle") and not d.has("normal"):
                d.fail("needs 'normal', the direction the angle is measured from", "angle")
            if not any(d.has(k) for k in FACE_FILTERS):
                d.fail("give 'box', 'normal' (with 'angle'), 'cells', any of them together, or 'union'")
            box = direction = cname = None
            if d.has("box"):
                box = d.get("box", "any")
                ok = isinstance(box, list) and len(box) == 2 and all(isinstance(q, list) and len(q) == 3 and all(
                    isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in q)
                    for q in box)
                if not ok:
                    d.fail("must be two points [[x0, y0, z0], [x1, y1, z1]]", "box")
                P = np.asarray(box, dtype=float)
                inside = np.all((X >= P.min(axis=0)) & (X <= P.max(axis=0)), axis=1)
            if d.has("normal"):
                direction = np.asarray(d.get("normal", "vector"))
                if not np.linalg.norm(direction) > 0.0:
                    d.fail("must not be zero", "normal")
                angle = d.get("angle", "float", 10.0, positive=True)
                if angle > 180.0:
                    d.fail(f"must lie in (0, 180] degrees, got {angle:g}", "angle")
            if d.has("cells"):
                cname = d.get("cells", "str")
                if cname not in mesh.element_sets:
                    d.fail(f"no element set {cname!r}{suggest(cname, mesh.element_sets)} (known: "
                           f"{', '.join(sorted(mesh.element_sets)) or 'none'})", "cells")
            d.done()
            picked = []
            for faces, elem, _ in every:  # one face type, or a wedge mesh's triangles and quadrilaterals
                keep = np.ones(len(faces), dtype=bool)
                if box is not None:
                    keep &= np.all(inside[faces], axis=1)
                if direction is not None:
                    n = edge_normals(X, faces) if mesh.is_planar else face_normals(X, faces)
                    cosine = n @ direction / np.maximum(np.linalg.norm(n, axis=1) * np.linalg.norm(direction),
                                                        1e-300)
                    keep &= cosine >= np.cos(np.radians(angle)) - 1e-12
                if cname is not None:
                    keep &= np.isin(elem, mesh.element_sets[cname])
                if keep.any():
                    picked.append(faces[keep])
            if len(picked) > 1:
                sec.fail(f"these filters pick {len(picked[0])} triangles and {len(picked[1])} quadrilaterals; "
                         f"a face set holds faces of one type: narrow the filters (normal, box)", name)
            chosen = picked[0] if picked else np.zeros((0, 3), dtype=np.int64)
        if len(chosen) == 0:
            sec.fail("no boundary face passes these filters", name)
        mesh.add_face_set(name, chosen)
        mesh.add_node_set(name, chosen.ravel())


def _check_cells(sec: Section, mesh, formulation: str) -> None:
    """Inverted or degenerate cells (det J <= 0 at an integration point) are one line naming them (solid-shells
    check their own points later); so are the cells of a mixed mesh whose faces do not match (a triangle on a
    quadrilateral)."""
    from ..mesh import Mesh
    from ..mesh.faces import jacobian_determinants

    if formulation == "solid-shell" or mesh.n_cells == 0:
        return
    chunk = 20000  # (cells, points, 3, 3) Jacobians a chunk at a time
    bad = np.concatenate([np.flatnonzero(~np.all(jacobian_determinants(
        Mesh(mesh.points, b.cell_type, b.cells[k: k + chunk])) > 0.0, axis=1)) + b.first + k
        for b in mesh.blocks for k in range(0, len(b.cells), chunk)])
    if bad.size:
        cells = ", ".join(map(str, bad[:5])) + (f" and {bad.size - 5} more" if bad.size > 5 else "")
        sec.fail(f"{bad.size} of {mesh.n_cells} {'/'.join(mesh.cell_types)} cells are inverted or degenerate (det J "
                 f"<= 0 at an integration point): cells {cells} (numbered from 0); check the file's node order (VTK's) "
                 f"or the geometry", "mesh")
    from ..mesh.faces import nonconforming_cells

    pairs = nonconforming_cells(mesh) if mesh.is_mixed else ()
    if len(pairs):
        a, q = pairs[0]
        sec.fail(f"the mesh is not conforming: {len(pairs)} triangular faces lie on quadrilateral faces of other cells "
                 f"(first: cell {a} against cell {q}, numbered from 0); a tetrahedron or wedge meets a brick only "
                 f"through a wedge's quadrilateral face", "mesh")


def _check_planar(sec: Section, name: str, mesh, formulation: str, thickness: float | None) -> None:
    """A planar formulation needs planar cells in the x-y plane (axisymmetric: at radius x >= 0) and the others
    volume cells; ``thickness`` is for the two plane formulations. One line naming the body."""
    planar = formulation in PLANAR_FORMULATIONS
    if planar and not mesh.is_planar:
        sec.fail(f"body {name!r}: formulation = \"{formulation}\" needs planar cells ({', '.join(PLANAR_CELLS)}) in "
                 f"the x-y plane, got {' and '.join(mesh.cell_types)}", "formulation")
    if not planar and mesh.is_planar:
        sec.fail(f"body {name!r}: {' and '.join(mesh.cell_types)} cells are planar: give formulation = "
                 f"\"plane_strain\", \"plane_stress\" or \"axisymmetric\" (formulation \"{formulation}\" needs "
                 f"volume cells)", "formulation")
    if thickness is not None and formulation not in ("plane_strain", "plane_stress"):
        sec.fail(f"body {name!r}: thickness is for formulation = \"plane_strain\" or \"plane_stress\" (an "
                 f"axisymmetric body spans the full circumference)", "thickness")
    if not planar:
        return
    z = mesh.points[:, 2]
    if np.any(z != 0.0):
        k = int(np.argmax(np.abs(z)))
        sec.fail(f"body {name!r}: a planar body lies in the x-y plane, but node {k} (numbered from 0) has z = "
                 f"{z[k]:g}", "mesh")
    if formulation == "axisymmetric":
        x = mesh.points[:, 0]
        tol = 1e-12 * max(1.0, float(np.abs(mesh.points).max()))
        if np.any(x < -tol):
            k = int(np.argmin(x))
            sec.fail(f"body {name!r}: an axisymmetric body lies at radius x >= 0, but node {k} (numbered from 0) "
                     f"has x = {x[k]:g}", "mesh")


def _materials_by_set(sec: Section, mesh, default) -> dict:
    """``materials = { SET = {...}, ... }``: a material per element set of the body (the cells in no set take
    ``material``). One line for an unknown set, a cell in two sets, or cells left without a material."""
    out = {}
    owner = np.full(mesh.n_cells, -1)
    for k, name in enumerate(list(sec.data)):
        if name not in mesh.element_sets:
            sec.fail(f"no element set {name!r}{suggest(name, mesh.element_sets)} in the body's mesh (known: "
                     f"{', '.join(sorted(mesh.element_sets)) or 'none'})", name)
        cells = np.asarray(mesh.element_sets[name], dtype=np.int64)
        twice = cells[owner[cells] >= 0]
        if twice.size:
            other = list(out)[int(owner[twice[0]])]
            sec.fail(f"element set {name!r} shares {twice.size} cells with {other!r}: give every cell one "
                     f"material", name)
        owner[cells] = k
        out[name] = read_material(sec.get(name, "table"))
    if default is None and np.any(owner < 0):
        sec.fail(f"{int(np.count_nonzero(owner < 0))} of {mesh.n_cells} cells lie in none of these element sets: "
                 f"give a 'material' for them or add their set")
    return out


def read_bodies(top: Section, base: Path) -> list[Body]:
    """Every ``[[bodies]]`` entry (at least one); ``base``: the folder mesh files are relative to."""
    bodies: list[Body] = []
    for b in top.get("bodies", "array", []):
        bname = b.get("name", "str")
        if any(x.name == bname for x in bodies):
            b.fail(f"duplicate body name {bname!r}", "name")
        element = b.get("element", "str", None, choices=CELLS + PLANAR_CELLS)
        formulation_given = b.has("formulation")
        formulation = b.get("formulation", "str", "solid", choices=("solid", "3d", "solid-shell", "fbar",
                                                                    *PLANAR_FORMULATIONS))
        formulation = "solid" if formulation == "3d" else formulation
        thickness = b.get("thickness", "float", None, positive=True)
        options = b.get("options", "table", None)
        options = options.rest() if options is not None else {}
        material = read_material(b.get("material", "table")) if b.has("material") or not b.has("materials") else None
        by_set = b.get("materials", "table", None)
        if b.has("shell"):  # a mid-surface mesh made into solid-shells (mesh/shell.py)
            if formulation_given and formulation != "solid-shell":
                b.fail(f"a shell body is made of solid-shells: leave out formulation (got {formulation!r})",
                       "formulation")
            formulation = "solid-shell"
            mesh = build_shell(b.get("shell", "table"), b.get("mesh", "table"), base)
        else:
            mesh = build_mesh(b.get("mesh", "table"), base, element)
        _check_planar(b, bname, mesh, formulation, thickness)
        _check_cells(b, mesh, formulation)
        user_cells(b.get("cells", "table", None), mesh)
        user_sets(b.get("sets", "table", None), mesh)
        user_faces(b.get("faces", "table", None), mesh)
        materials = _materials_by_set(by_set, mesh, material) if by_set is not None else {}
        b.done()
        if formulation == "solid-shell":
            from ..elements.solidshell import check_options

            try:
                options = check_options(mesh, options)
            except ValueError as exc:
                b.fail(str(exc), "options")
        elif formulation == "fbar":
            from ..elements.fbar import FBAR_CELLS

            if mesh.cell_type not in FBAR_CELLS:
                b.fail(f"formulation = \"fbar\" needs {', '.join(FBAR_CELLS)} elements, got "
                       f"{' and '.join(mesh.cell_types)}", "formulation")
            unknown = sorted(set(options) - {"form"})
            if unknown:
                b.fail(f"unknown option {unknown[0]!r} for formulation = \"fbar\" (known: form)", "options")
            if options.get("form", "spatial") not in ("spatial", "variational"):
                b.fail(f"form must be \"spatial\" or \"variational\", got {options['form']!r}", "options")
            if mesh.cell_type != "hex8" and options.get("form", "spatial") != "spatial":
                b.fail(f"F-bar {mesh.cell_type} has the spatial form only; leave out 'form'", "options")
        elif formulation in PLANAR_FORMULATIONS:
            from ..fem.planar_cells import REDUCED_CELLS

            unknown = sorted(set(options) - {"integration", "fbar"})
            if unknown:
                b.fail(f"unknown option {unknown[0]!r} for formulation = \"{formulation}\" (known: integration, "
                       f"fbar)", "options")
            fbar = options.get("fbar", False)
            if not isinstance(fbar, bool):
                b.fail(f"fbar must be true or false, got {fbar!r}", "options")
            if fbar:
                from ..elements.planar_fbar import PLANAR_FBAR_CELLS

                if formulation == "plane_stress":
                    b.fail(f"body {bname!r}: fbar = true is for plane_strain and axisymmetric bodies (plane stress "
                           f"has no volume constraint to relieve: leave it out)", "options")
                bad = [t for t in mesh.cell_types if t not in PLANAR_FBAR_CELLS]
                if bad:
                    b.fail(f"body {bname!r}: fbar = true needs {', '.join(PLANAR_FBAR_CELLS)} cells, got "
                           f"{' and '.join(bad)} (tri3 has one point: nothing to relieve)", "options")
                if options.get("integration", "full") != "full":
                    b.fail(f"body {bname!r}: fbar = true takes full integration; leave out integration", "options")
            if options.get("integration", "full") not in ("full", "reduced"):
                b.fail(f"integration must be \"full\" or \"reduced\", got {options['integration']!r}", "options")
            if options.get("integration") == "reduced" and any(t not in REDUCED_CELLS for t in mesh.cell_types):
                b.fail(f"integration = \"reduced\" is for quad8 elements (as CPE8R, CPS8R, CAX8R), not "
                       f"{' and '.join(mesh.cell_types)}: the others would have zero-energy modes", "options")
            options = {**options, "thickness": 1.0 if thickness is None else thickness}
        elif options:
            unknown = sorted(set(options) - {"integration", "incompatible_modes"})
            if unknown:
                b.fail(f"unknown option {unknown[0]!r} for formulation = \"solid\" (known: integration, "
                       f"incompatible_modes)", "options")
            if options.get("integration", "full") not in ("full", "reduced"):
                b.fail(f"integration must be \"full\" or \"reduced\", got {options['integration']!r}", "options")
            if options.get("integration") == "reduced" and mesh.cell_type != "hex20":
                b.fail(f"integration = \"reduced\" is for hex20 elements (as C3D20R), not {mesh.cell_type}: the "
                       f"others would have zero-energy modes", "options")
            modes = options.get("incompatible_modes", False)
            if not isinstance(modes, bool):
                b.fail(f"incompatible_modes must be true or false, got {modes!r}", "options")
            if modes and "hex8" not in mesh.cell_types:
                b.fail(f"incompatible_modes = true is for hex8 elements (as C3D8I), not "
                       f"{' and '.join(mesh.cell_types)}", "options")
        if materials and material is None:  # every cell in a set: the first set's material stands for the body
            material = next(iter(materials.values()))
        bodies.append(Body(bname, mesh, material, formulation, options, materials))
    if not bodies:
        top.fail("at least one [[bodies]] entry is needed")
    return bodies
