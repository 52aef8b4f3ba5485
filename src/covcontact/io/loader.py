"""Read a TOML problem file into a ``covcontact.problem.Problem``, validating everything first.

The schema is documented in docs/input.md. Every error is an ``InputError`` whose message names the file,
the key path (or line) and what is wrong.
"""

from __future__ import annotations

import inspect
import math
import tomllib
from pathlib import Path

import numpy as np

from ..problem import (
    COMPONENTS,
    TANGENT_CASES,
    Body,
    ContactPair,
    Dirichlet,
    NodalForce,
    OutputOptions,
    Pressure,
    Problem,
    RigidBody,
    RigidMotion,
    SolverOptions,
    Steps,
    Traction,
)
from .validate import _REQUIRED, InputError, Section, suggest

CELLS = ("hex8", "hex18", "hex27")
RIGID_SHAPES = ("plane", "cylinder", "sphere", "mesh")


def _generators() -> dict:
    from ..mesh import generators, generators_solid

    return {name: fn for mod in (generators, generators_solid) for name, fn in vars(mod).items()
            if inspect.isfunction(fn) and not name.startswith("_") and fn.__module__ == mod.__name__
            and "cell" in inspect.signature(fn).parameters}


def build_mesh(sec: Section, base: Path, element: str | None):
    """Mesh from ``generator = ...`` plus its arguments, or ``file = ...`` (read through meshio)."""
    from ..mesh.io import MeshError, read_mesh

    if sec.has("file") == sec.has("generator"):
        sec.fail("give exactly one of 'file' or 'generator'")
    if sec.has("file"):
        fname = sec.get("file", "str")
        sec.done()
        path = (base / fname) if not Path(fname).is_absolute() else Path(fname)
        if not path.exists():
            sec.fail(f"mesh file {fname!r} does not exist (looked for {path}; a relative path is taken from the "
                     f"problem file's folder)", "file")
        try:
            mesh = read_mesh(path)
        except (MeshError, ValueError, KeyError, OSError) as exc:
            sec.fail(f"cannot read mesh file {path}: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}",
                     "file")
        if element is not None and mesh.cell_type != element:
            sec.fail(f"element {element!r} does not match the mesh file's cells ({mesh.cell_type})", "file")
        return mesh
    gens = _generators()
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
    try:
        return fn(cell=element or "hex8", **kwargs)
    except (ValueError, TypeError) as exc:
        sec.fail(f"generator {name!r}: {exc}")


_HARDENING = {"linear": ("modulus",), "swift": ("K", "eps0", "n"), "voce": ("sigma_inf", "delta", "modulus")}


def _hardening(sec: Section) -> dict:
    law = sec.get("law", "str", choices=tuple(_HARDENING))
    out: dict = {"law": law}
    for key in _HARDENING[law]:
        optional = law == "voce" and key == "modulus"
        value = sec.get(key, "float", 0.0 if optional else _REQUIRED)
        out[key] = value
    sec.done()
    return out


def _material(sec: Section):
    from ..materials import material_from_name

    model = sec.get("model", "str", choices=("svk", "saint-venant-kirchhoff", "neo-hooke", "neohooke", "j2"))
    E = sec.get("E", "float", positive=True)
    nu = sec.get("nu", "float")
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
                                kinematic_modulus=kinematic, hill48=hill)
        except ValueError as exc:
            sec.fail(str(exc))
    sec.done()
    try:
        return material_from_name(model, E=E, nu=nu)
    except ValueError as exc:
        sec.fail(str(exc))


def _motion(sec: Section | None) -> RigidMotion:
    if sec is None:
        return RigidMotion()
    translation = sec.get("translation", "vector", (0.0, 0.0, 0.0))
    rotation = sec.get("rotation", "vector", (0.0, 0.0, 0.0))
    center = sec.get("center", "vector", (0.0, 0.0, 0.0))
    path = None
    if sec.has("path"):
        raw = sec.get("path", "any")
        ok = isinstance(raw, list) and all(
            isinstance(r, list) and len(r) == 4 and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in r)
            for r in raw)
        if not ok:
            sec.fail("must be an array of rows [lam, tx, ty, tz]", "path")
        path = raw
    sec.done()
    try:
        return RigidMotion(translation=translation, rotation=rotation, center=center, path=path)
    except ValueError as exc:
        sec.fail(str(exc), "path" if path is not None else None)


def _user_sets(sec: Section | None, mesh) -> None:
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


def _reuse_option(sec: Section, default):
    """[solver] reuse_factorization: true, false or "auto"."""
    value = sec.get("reuse_factorization", "any", default)
    if not (isinstance(value, bool) or value == "auto"):
        sec.fail(f'must be true, false or "auto", got {value!r}', "reuse_factorization")
    return value


def _split_ref(sec: Section, key: str, value: str) -> tuple[str, str]:
    if "." in value:
        body, name = value.split(".", 1)
        return body, name
    return value, ""


def _dirichlet_values(sec: Section, key: str, n: int) -> tuple:
    """A Dirichlet value: one number for every component, or an array of one per component."""
    if sec.has(key) and isinstance(sec.data[key], list):
        return tuple(sec.get(key, "floats", length=n))
    return (sec.get(key, "float", 0.0),) * n


_COMPONENT_NAMES = ("x", "y", "z", "rx", "ry", "rz")


def _free_components(sec: Section) -> tuple[int, ...]:
    """``free = ["z", "rx", ...]``: the rigid body's components left to equilibrium."""
    names = _strs(sec, "free")
    for n in names:
        if n not in _COMPONENT_NAMES:
            sec.fail(f"{n!r} is not a component (x, y, z, rx, ry, rz)", "free")
    if len(set(names)) != len(names):
        sec.fail("names a component twice", "free")
    return tuple(sorted(_COMPONENT_NAMES.index(n) for n in names))


def _strs(sec: Section, key: str) -> tuple[str, ...]:
    raw = sec.get(key, "any", [])
    if not isinstance(raw, list) or not all(isinstance(v, str) for v in raw):
        sec.fail("must be an array of names (strings)", key)
    return tuple(raw)


def _steps(sec: Section | None) -> Steps:
    if sec is None:
        return Steps.equal(1)
    if sec.has("factors"):
        factors = sec.get("factors", "floats")
        sec.done()
        if not factors or any(b <= a for a, b in zip((0.0,) + factors, factors)):
            sec.fail("must be a non-empty, strictly increasing list of positive load factors", "factors")
        return Steps(factors)
    n = sec.get("count", "int", 1, positive=True)
    final = sec.get("final", "float", 1.0, positive=True)
    sec.done()
    return Steps.equal(n, final)


def load_problem(path: str | Path) -> Problem:
    """Parse and validate a problem file; raise InputError with a one-line message on any problem."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: file does not exist")
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: TOML syntax error: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read: {exc}") from None
    return problem_from_dict(raw, path)


_TOP_LEVEL = ("problem", "bodies", "rigid", "dirichlet", "force", "pressure", "traction", "contact", "steps",
              "stages", "solver", "output")


def problem_from_dict(raw: dict, path: Path) -> Problem:
    base = path.parent
    top = Section(raw, "", path)
    stray = sorted(set(top.data) - set(_TOP_LEVEL))
    if stray:  # before anything else: a misspelt section would otherwise surface as a missing name elsewhere
        top.fail("unknown section" + suggest(stray[0], _TOP_LEVEL, f" (known: {', '.join(_TOP_LEVEL)})"), stray[0])
    meta = top.get("problem", "table")
    name = meta.get("name", "str")
    description = meta.get("description", "str", "")
    meta_stage = meta.get("stage", "str", "stage1")
    units = meta.get("units", "str", "")
    meta.done()

    bodies: list[Body] = []
    for b in top.get("bodies", "array", []):
        bname = b.get("name", "str")
        if any(x.name == bname for x in bodies):
            b.fail(f"duplicate body name {bname!r}", "name")
        element = b.get("element", "str", None, choices=CELLS)
        formulation = b.get("formulation", "str", "solid", choices=("solid", "solid-shell", "fbar"))
        options = b.get("options", "table", None)
        options = options.rest() if options is not None else {}
        material = _material(b.get("material", "table"))
        mesh = build_mesh(b.get("mesh", "table"), base, element)
        _user_sets(b.get("sets", "table", None), mesh)
        b.done()
        if formulation == "solid-shell":
            from ..elements.solidshell import check_options

            try:
                options = check_options(mesh, options)
            except ValueError as exc:
                b.fail(str(exc), "options")
        elif formulation == "fbar":
            if mesh.cell_type not in ("hex8", "hex27"):
                b.fail(f"formulation = \"fbar\" needs hex8 or hex27 elements, got {mesh.cell_type}", "formulation")
            unknown = sorted(set(options) - {"form"})
            if unknown:
                b.fail(f"unknown option {unknown[0]!r} for formulation = \"fbar\" (known: form)", "options")
            if options.get("form", "spatial") not in ("spatial", "variational"):
                b.fail(f"form must be \"spatial\" or \"variational\", got {options['form']!r}", "options")
            if mesh.cell_type == "hex27" and options.get("form", "spatial") != "spatial":
                b.fail("F-bar hex27 has the spatial form only; leave out 'form'", "options")
        elif options:
            b.fail("options are only known for formulation = \"solid-shell\" and \"fbar\"", "options")
        bodies.append(Body(bname, mesh, material, formulation, options))
    if not bodies:
        top.fail("at least one [[bodies]] entry is needed")

    rigid: list[RigidBody] = []
    for r in top.get("rigid", "array", []):
        rname = r.get("name", "str")
        if any(x.name == rname for x in rigid) or any(x.name == rname for x in bodies):
            r.fail(f"duplicate body name {rname!r}", "name")
        shape = r.get("shape", "str", choices=RIGID_SHAPES)
        params: dict = {}
        mesh = None
        if shape == "plane":
            params = {"point": r.get("point", "vector"), "normal": r.get("normal", "vector")}
            if np.linalg.norm(params["normal"]) == 0:
                r.fail("must not be zero", "normal")
        elif shape == "cylinder":
            params = {"center": r.get("center", "vector"), "axis": r.get("axis", "vector"),
                      "radius": r.get("radius", "float", positive=True),
                      "outside": r.get("outside", "bool", True)}
            if np.linalg.norm(params["axis"]) == 0:
                r.fail("must not be zero", "axis")
        elif shape == "sphere":
            params = {"center": r.get("center", "vector"), "radius": r.get("radius", "float", positive=True),
                      "outside": r.get("outside", "bool", True)}
        else:
            element = r.get("element", "str", None, choices=CELLS)
            mesh = build_mesh(r.get("mesh", "table"), base, element)
            _user_sets(r.get("sets", "table", None), mesh)
        motion = _motion(r.get("motion", "table", None))
        free = _free_components(r)
        force = r.get("force", "vector", (0.0, 0.0, 0.0))
        moment = r.get("moment", "vector", (0.0, 0.0, 0.0))
        reference = r.get("reference", "vector", None)
        for key, vec, base in (("force", force, 0), ("moment", moment, 3)):
            bad = [i for i in range(3) if vec[i] != 0.0 and base + i not in free]
            if bad:
                r.fail(f"{'xyz'[bad[0]]} component given, but that component follows the motion; add "
                       f"{_COMPONENT_NAMES[base + bad[0]]!r} to 'free' (a component is either moved or loaded)",
                       key)
        r.done()
        rigid.append(RigidBody(rname, motion=motion, mesh=mesh, shape=shape, params=params, free=free,
                               force=force, moment=moment, reference=reference))

    def body_set(sec: Section, key: str, kind: str) -> tuple[str, str]:
        ref = sec.get(key, "str")
        bname, sname = _split_ref(sec, key, ref)
        owner = next((b.mesh for b in bodies if b.name == bname), None)
        if owner is None:
            owner = next((r.mesh for r in rigid if r.name == bname and r.mesh is not None), None)
        if owner is None:
            names = [b.name for b in bodies] + [r.name for r in rigid if r.mesh is not None]
            sec.fail(f"{ref!r}: no body named {bname!r}{suggest(bname, names)} (bodies: {', '.join(names) or 'none'})",
                     key)
        sets = owner.node_sets if kind == "node" else owner.face_sets
        if sname not in sets:
            known = ", ".join(sorted(sets)) or "none"
            sec.fail(f"{ref!r}: body {bname!r} has no {kind} set {sname!r}{suggest(sname, sets)} (known: {known})",
                     key)
        if len(sets[sname]) == 0:
            sec.fail(f"{ref!r}: {kind} set is empty", key)
        return bname, sname

    def deformable(sec: Section, key: str, bname: str) -> None:
        if not any(b.name == bname for b in bodies):
            sec.fail(f"{bname!r} is not a deformable body", key)

    dirichlet = []
    for d in top.get("dirichlet", "array", []):
        bname, sname = body_set(d, "set", "node")
        deformable(d, "set", bname)
        comps = d.get("components", "str", "xyz")
        if not comps or any(c not in COMPONENTS for c in comps) or len(set(comps)) != len(comps):
            d.fail(f"must be a non-empty combination of x, y, z, got {comps!r}", "components")
        dname = d.get("name", "str", "")
        motion = None
        if d.has("motion"):
            if d.has("value"):
                d.fail("give either 'value' or 'motion', not both", "motion")
            motion = _motion(d.get("motion", "table"))
            values = (0.0,) * len(comps)
        else:
            values = _dirichlet_values(d, "value", len(comps))
        d.done()
        dirichlet.append(Dirichlet(bname, sname, tuple(COMPONENTS[c] for c in comps), tuple(values), dname,
                                   motion))

    forces = []
    for f in top.get("force", "array", []):
        bname, sname = body_set(f, "set", "node")
        deformable(f, "set", bname)
        value = f.get("value", "vector")
        dist = f.get("distribution", "str", "per_node", choices=("per_node", "total"))
        fname = f.get("name", "str", "")
        f.done()
        forces.append(NodalForce(bname, sname, value, dist, fname))

    pressures = []
    for p in top.get("pressure", "array", []):
        bname, sname = body_set(p, "set", "face")
        deformable(p, "set", bname)
        value = p.get("value", "float")
        pname = p.get("name", "str", "")
        p.done()
        pressures.append(Pressure(bname, sname, value, pname))

    tractions = []
    for t in top.get("traction", "array", []):
        bname, sname = body_set(t, "set", "face")
        deformable(t, "set", bname)
        value = t.get("value", "vector")
        tname = t.get("name", "str", "")
        t.done()
        tractions.append(Traction(bname, sname, value, tname))

    contacts = []
    for i, c in enumerate(top.get("contact", "array", [])):
        cname = c.get("name", "str", f"contact{i + 1}")
        slave = body_set(c, "slave", "node")
        mref = c.get("master", "str")
        mbody, mset = _split_ref(c, "master", mref)
        analytic = next((r for r in rigid if r.name == mbody and r.mesh is None), None)
        if analytic is not None:
            if mset:
                c.fail(f"{mref!r}: the analytic surface {mbody!r} has no sets; name it alone", "master")
            master = (mbody, "")
        else:
            c.data["master"] = mref
            master = body_set(c, "master", "face")
        if slave[0] == master[0] and slave[0] in {r.name for r in rigid}:
            c.fail("slave and master are the same rigid body")
        if isinstance(c.data.get("penalty"), str):
            penalty = c.get("penalty", "str", choices=("auto",))
        else:
            penalty = c.get("penalty", "float", positive=True)
        auto_factor = c.get("auto_factor", "float", 10.0, positive=True)
        method = c.get("method", "str", "penalty", choices=("penalty", "augmented"))
        gap_tol = c.get("gap_tolerance", "float", None, positive=True)
        gap_rel = c.get("gap_tolerance_relative", "float", None, positive=True)
        max_aug = c.get("max_augmentations", "int", 20, positive=True)
        if method == "augmented" and gap_tol is None and gap_rel is None:
            gap_rel = 1e-3
        if method == "penalty" and (gap_tol is not None or gap_rel is not None):
            c.fail("gap tolerances need method = \"augmented\"")
        weighting = c.get("weighting", "str", "nodal", choices=("nodal", "area"))
        tangent = c.get("tangent", "str", "a", choices=TANGENT_CASES)
        two_pass = c.get("two_pass", "bool", False)
        mu = c.get("friction", "float", 0.0, nonnegative=True)
        eps_t = c.get("tangential_penalty", "float", None, positive=True)
        enabled = c.get("enabled", "bool", True)
        c.done()
        if any(x.name == cname for x in contacts):
            c.fail(f"duplicate contact name {cname!r}", "name")
        contacts.append(ContactPair(cname, slave, master, penalty, weighting, tangent, two_pass,
                                    friction=mu, tangential_penalty=eps_t, method=method, gap_tolerance=gap_tol,
                                    gap_tolerance_relative=gap_rel, max_augmentations=max_aug,
                                    auto_factor=auto_factor, enabled=enabled))

    for i, r in enumerate(rigid):
        if r.free and not any(r.name in (c.slave[0], c.master[0]) for c in contacts):
            top.fail(f"rigid body {r.name!r} has free components but no contact pair: nothing would restrain "
                     f"it; add a [[contact]] with it or drop 'free'", f"rigid[{i}].free")
    steps = _steps(top.get("steps", "table", None))
    from .stage_input import named_conditions, stage  # here: stage_input uses this module's field readers

    named = named_conditions(top, dirichlet, forces, pressures, tractions)
    for r in rigid:  # rigid bodies with free components: their force is a load later stages may change
        if r.free and r.name not in named:
            named[r.name] = ("rigid", r)
    stage_name = meta_stage
    stages = []
    for st in top.get("stages", "array", []):
        stages.append(stage(st, named, dirichlet, rigid, contacts, stages, stage_name))

    s = top.get("solver", "table", None)
    solver = SolverOptions()
    if s is not None:
        solver = SolverOptions(
            linear=s.get("linear", "str", solver.linear),
            max_iterations=s.get("max_iterations", "int", solver.max_iterations, positive=True),
            rtol=s.get("rtol", "float", solver.rtol, positive=True),
            atol=s.get("atol", "float", solver.atol, nonnegative=True),
            etol=s.get("etol", "float", solver.etol, nonnegative=True),
            criterion=s.get("criterion", "str", solver.criterion, choices=("residual", "energy", "both")),
            max_cutbacks=s.get("max_cutbacks", "int", solver.max_cutbacks, nonnegative=True),
            line_search=s.get("line_search", "bool", solver.line_search),
            divergence_factor=s.get("divergence_factor", "float", solver.divergence_factor, positive=True),
            reuse_factorization=_reuse_option(s, solver.reuse_factorization),
            krylov_max=s.get("krylov_max", "int", solver.krylov_max, positive=True),
            predictor=s.get("predictor", "str", solver.predictor, choices=("tangent", "extrapolate")),
            factorization_precision=s.get("factorization_precision", "str", solver.factorization_precision,
                                          choices=("auto", "double", "single")),
            reproducible=s.get("reproducible", "bool", solver.reproducible),
        )
        if solver.factorization_precision == "single" and solver.linear.lower().strip() not in ("auto", "pardiso"):
            s.fail(f'"single" is PARDISO\'s; linear = {solver.linear!r} factorises in double precision '
                   f'(use linear = "pardiso", or leave factorization_precision out)', "factorization_precision")
        s.done()
    o = top.get("output", "table", None)
    output = OutputOptions()
    if o is not None:
        output = OutputOptions(vtu=o.get("vtu", "bool", True), every=o.get("every", "int", 1, positive=True),
                               pictures=o.get("pictures", "bool", False),
                               checkpoint_every=o.get("checkpoint_every", "int", 1, positive=True))
        o.done()
    top.done()
    return Problem(name=name, description=description, bodies=bodies, dirichlet=dirichlet, forces=forces,
                   pressures=pressures, tractions=tractions, rigid=rigid, contacts=contacts, steps=steps, solver=solver,
                   output=output, source=path, stages=stages, stage_name=stage_name,
                   units=units)
