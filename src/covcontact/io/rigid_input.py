"""The ``[[rigid]]`` section: rigid bodies, analytic (plane, cylinder, sphere, profile) or meshed, with their motion,
free components and applied force and moment (docs/input.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..contact.tool_profile import Profile
from ..description import RigidBody
from .bodies_input import CELLS, build_mesh, user_faces, user_sets
from .fields import COMPONENT_NAMES, free_components, names, read_motion, split_ref
from .validate import Section, suggest

RIGID_SHAPES = ("plane", "cylinder", "sphere", "profile", "mesh")


def read_rigid(top: Section, base: Path, bodies: list) -> list[RigidBody]:
    """Every ``[[rigid]]`` entry; ``bodies``: the deformable ones (names must differ)."""
    rigid: list[RigidBody] = []
    for r in top.get("rigid", "array", []):
        rname = r.get("name", "str")
        if any(x.name == rname for x in rigid) or any(x.name == rname for x in bodies):
            r.fail(f"duplicate body name {rname!r}", "name")
        attach = _attach(r, bodies)
        attach_components = _attach_components(r, attach)
        shape = r.get("shape", "str", "", choices=RIGID_SHAPES) if attach else r.get("shape", "str", choices=RIGID_SHAPES)
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
        elif shape == "profile":
            params = _read_profile(r)
        elif shape == "mesh":
            element = r.get("element", "str", None, choices=CELLS)
            mesh = build_mesh(r.get("mesh", "table"), base, element)
            user_sets(r.get("sets", "table", None), mesh)
            user_faces(r.get("faces", "table", None), mesh)
        motion = read_motion(r.get("motion", "table", None))
        free = free_components(r)
        force = r.get("force", "vector", (0.0, 0.0, 0.0))
        moment = r.get("moment", "vector", (0.0, 0.0, 0.0))
        reference = r.get("reference", "vector", None)
        if not shape and reference is None:
            r.fail("missing: a rigid body of attached nodes alone needs its reference point (the centre of its "
                   "rotation, e.g. reference = [0.0, 0.0, 0.0])", "reference")
        mass = r.get("mass", "float", None, positive=True)
        inertia = r.get("inertia", "vector", None)
        if inertia is not None and not all(v > 0.0 for v in inertia):
            r.fail(f"the principal moments of inertia must be > 0, got {list(inertia)}", "inertia")
        if attach and (mass is not None or inertia is not None):
            r.fail("a rigid body with attached nodes takes its mass and inertia from their elements; remove mass and "
                   "inertia", "mass" if mass is not None else "inertia")
        for key, val in (("mass", mass), ("inertia", inertia)):
            if val is not None and not free:
                r.fail(f"{key} is for a body with free components (its motion follows equilibrium); this one's "
                       f"motion is prescribed", key)
        for key, vec, first in (("force", force, 0), ("moment", moment, 3)):
            bad = [i for i in range(3) if vec[i] != 0.0 and first + i not in free]
            if bad:
                r.fail(f"{'xyz'[bad[0]]} component given, but that component follows the motion; add "
                       f"{COMPONENT_NAMES[first + bad[0]]!r} to 'free' (a component is either moved or loaded)",
                       key)
        r.done()
        rigid.append(RigidBody(rname, motion=motion, mesh=mesh, shape=shape, params=params, free=free,
                               force=force, moment=moment, reference=reference, mass=mass, inertia=inertia,
                               attach=attach, attach_components=attach_components))
    return rigid


def _attach_components(r: Section, attach: tuple) -> tuple:
    """``attach_components = ["x", "z"]``: the components of the attached nodes that follow the body (default all
    three; the others stay free: a deck's *KINEMATIC coupling of some dofs)."""
    if not r.has("attach_components"):
        return (0, 1, 2)
    given = names(r, "attach_components")
    if not attach:
        r.fail("is for a body with attach (the attached nodes' components that follow it)", "attach_components")
    if not given or any(n not in ("x", "y", "z") for n in given) or len(set(given)) != len(given):
        r.fail(f"must name some of x, y, z, each once (the attached nodes' components that follow the body), got "
               f"{list(given)}", "attach_components")
    return tuple(sorted("xyz".index(n) for n in given))


def _attach(r: Section, bodies: list) -> tuple:
    """``attach = ["body.set", ...]``: node sets of deformable bodies that move with the rigid body."""
    out = []
    for ref in names(r, "attach"):
        bname, sname = split_ref(r, "attach", ref)
        body = next((b for b in bodies if b.name == bname), None)
        if body is None:
            known = [b.name for b in bodies]
            r.fail(f"{ref!r}: no deformable body named {bname!r}{suggest(bname, known)} (bodies: "
                   f"{', '.join(known) or 'none'})", "attach")
        if sname not in body.mesh.node_sets or len(body.mesh.node_sets[sname]) == 0:
            sets = body.mesh.node_sets
            r.fail(f"{ref!r}: body {bname!r} has no node set {sname!r}{suggest(sname, sets)} (known: "
                   f"{', '.join(sorted(sets)) or 'none'})", "attach")
        if (bname, sname) in out:
            r.fail(f"{ref!r} named twice", "attach")
        out.append((bname, sname))
    return tuple(out)


def _read_profile(r: Section) -> dict:
    """points, fillets and extrude or revolve of a profile tool, checked by building it (one line naming
    the key on error)."""
    raw = r.get("points", "any")
    if not (isinstance(raw, list) and all(isinstance(p, list) and len(p) == 2 and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in p) for p in raw)):
        r.fail("must be an array of [p, q] pairs (the profile in its own plane), e.g. [[35.0, 60.0], "
               "[35.0, 0.0], [0.0, 0.0]]", "points")
    points = [tuple(float(v) for v in p) for p in raw]
    fillets = r.get("fillets", "floats", None)
    if fillets is None and len(points) > 2:
        r.fail(f"missing: one radius per interior corner ({len(points) - 2} here; 0 for a sharp corner)",
               "fillets")
    params = {"points": points, "fillets": fillets, "extrude": None, "revolve": None}
    if r.has("extrude") == r.has("revolve"):
        r.fail("give either extrude = { axis, origin } or revolve = { axis, center }")
    if r.has("extrude"):
        ex = r.get("extrude", "table")
        params["extrude"] = {"axis": ex.get("axis", "vector"), "origin": ex.get("origin", "vector", (0.0, 0.0, 0.0)),
                             "u": ex.get("u", "vector", None), "v": ex.get("v", "vector", None)}
        ex.done()
    else:
        rv = r.get("revolve", "table")
        params["revolve"] = {"axis": rv.get("axis", "vector"), "center": rv.get("center", "vector", (0.0, 0.0, 0.0))}
        rv.done()
    try:
        Profile(**params)
    except ValueError as err:
        msg = str(err)
        key, _, text = msg.partition(": ")
        if key in ("points", "fillets") or key.startswith(("extrude.", "revolve.")):
            r.fail(text, key)
        r.fail(msg)
    return params


def knot_bodies(bodies: list, rigid: list) -> list[RigidBody]:
    """The rigid bodies of shell bodies' knots (``shell = { creases = "knots" }``, mesh.shell ``extrude_surface``):
    one per knot, ``BODY_knotK``, its expansions attached, its reference the knot's point, its six components
    free."""
    out = []
    taken = {r.name for r in rigid} | {b.name for b in bodies}
    for b in bodies:
        for k, (point, _) in enumerate(getattr(b.mesh, "shell_knots", None) or []):
            name = f"{b.name}_knot{k + 1}"
            while name in taken:
                name += "_"
            taken.add(name)
            out.append(RigidBody(name, free=(0, 1, 2, 3, 4, 5), reference=tuple(float(v) for v in point),
                                 attach=((b.name, f"_knot{k + 1}"),)))
    return out


def check_attached(top: Section, rigid: list, bodies: list, dirichlet: list, equations: list) -> None:
    """Attached nodes follow their rigid body alone (in the components it holds, ``attach_components``): not
    prescribed there by a Dirichlet condition, not the dependent dof of an equation there, not attached to two bodies
    (one line naming both)."""
    meshes = {b.name: b.mesh for b in bodies}
    owner: dict = {}
    held: dict = {}
    for i, r in enumerate(rigid):
        held[r.name] = set(r.attach_components)
        for bname, sname in r.attach:
            for node in meshes[bname].node_sets[sname]:
                prev = owner.setdefault((bname, int(node)), r.name)
                if prev != r.name:
                    top.fail(f"node {int(node)} of body {bname!r} is attached to rigid bodies {prev!r} and "
                             f"{r.name!r}; attach it to one", f"rigid[{i}].attach")
    if not owner:
        return
    for i, bc in enumerate(dirichlet):
        hit = [int(n) for n in meshes[bc.body].node_sets[bc.set] if (bc.body, int(n)) in owner
               and held[owner[(bc.body, int(n))]] & set(bc.components)]
        if hit:
            knot = owner[(bc.body, hit[0])].startswith(f"{bc.body}_knot")
            top.fail(f"set {bc.body}.{bc.set} holds node {hit[0]} attached to rigid body "
                     f"{owner[(bc.body, hit[0])]!r}: an attached node follows its body; " + (
                         "that body is a knot of the shell (creases = \"knots\"), which a support in a problem file "
                         "cannot hold yet: support the shell away from the junction, or leave creases at \"mean\""
                         if knot else "prescribe the rigid body's motion instead"), f"dirichlet[{i}].set")
    for i, eq in enumerate(equations):
        bname, sname, comp = eq.terms[0][0], eq.terms[0][1], eq.terms[0][2]
        if bname not in meshes:
            continue
        node = int(meshes[bname].node_sets[sname][0])
        if (bname, node) in owner and comp in held[owner[(bname, node)]]:
            top.fail(f"its first (dependent) term is node {node} of body {bname!r}, attached to rigid body "
                     f"{owner[(bname, node)]!r}; put another term first", f"equation[{i}]")
