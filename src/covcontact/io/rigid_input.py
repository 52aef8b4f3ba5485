"""The ``[[rigid]]`` section: rigid bodies, analytic (plane, cylinder, sphere) or meshed, with their motion,
free components and applied force and moment (docs/input.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..description import RigidBody
from .bodies_input import CELLS, build_mesh, user_sets
from .fields import COMPONENT_NAMES, free_components, read_motion
from .validate import Section

RIGID_SHAPES = ("plane", "cylinder", "sphere", "mesh")


def read_rigid(top: Section, base: Path, bodies: list) -> list[RigidBody]:
    """Every ``[[rigid]]`` entry; ``bodies``: the deformable ones (names must differ)."""
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
            user_sets(r.get("sets", "table", None), mesh)
        motion = read_motion(r.get("motion", "table", None))
        free = free_components(r)
        force = r.get("force", "vector", (0.0, 0.0, 0.0))
        moment = r.get("moment", "vector", (0.0, 0.0, 0.0))
        reference = r.get("reference", "vector", None)
        for key, vec, first in (("force", force, 0), ("moment", moment, 3)):
            bad = [i for i in range(3) if vec[i] != 0.0 and first + i not in free]
            if bad:
                r.fail(f"{'xyz'[bad[0]]} component given, but that component follows the motion; add "
                       f"{COMPONENT_NAMES[first + bad[0]]!r} to 'free' (a component is either moved or loaded)",
                       key)
        r.done()
        rigid.append(RigidBody(rname, motion=motion, mesh=mesh, shape=shape, params=params, free=free,
                               force=force, moment=moment, reference=reference))
    return rigid
