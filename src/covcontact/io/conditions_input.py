"""The ``[[dirichlet]]``, ``[[force]]``, ``[[pressure]]`` and ``[[traction]]`` sections, and the references
``"body.set"`` that they and the contact pairs make to the bodies' node and face sets (docs/input.md)."""

from __future__ import annotations

from ..description import COMPONENTS
from ..loads import Dirichlet, NodalForce, Pressure, Traction
from .fields import dirichlet_values, read_motion, split_ref
from .validate import Section, suggest


class SetRefs:
    """Resolves ``"body.set"`` references against the bodies and the meshed rigid bodies."""

    def __init__(self, bodies: list, rigid: list):
        self.bodies, self.rigid = bodies, rigid

    def mesh(self, bname: str):
        """The mesh of body ``bname`` (deformable or rigid meshed), or None."""
        owner = next((b.mesh for b in self.bodies if b.name == bname), None)
        if owner is None:
            owner = next((r.mesh for r in self.rigid if r.name == bname and r.mesh is not None), None)
        return owner

    def body_set(self, sec: Section, key: str, kind: str) -> tuple[str, str]:
        ref = sec.get(key, "str")
        bname, sname = split_ref(sec, key, ref)
        owner = self.mesh(bname)
        if owner is None:
            names = [b.name for b in self.bodies] + [r.name for r in self.rigid if r.mesh is not None]
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

    def deformable(self, sec: Section, key: str, bname: str) -> None:
        if not any(b.name == bname for b in self.bodies):
            sec.fail(f"{bname!r} is not a deformable body", key)


def read_dirichlet(top: Section, sets: SetRefs) -> list[Dirichlet]:
    """Every ``[[dirichlet]]`` entry."""
    dirichlet = []
    for d in top.get("dirichlet", "array", []):
        bname, sname = sets.body_set(d, "set", "node")
        sets.deformable(d, "set", bname)
        comps = d.get("components", "str", "xyz")
        if not comps or any(c not in COMPONENTS for c in comps) or len(set(comps)) != len(comps):
            d.fail(f"must be a non-empty combination of x, y, z, got {comps!r}", "components")
        dname = d.get("name", "str", "")
        motion = None
        if d.has("motion"):
            if d.has("value"):
                d.fail("give either 'value' or 'motion', not both", "motion")
            motion = read_motion(d.get("motion", "table"))
            values = (0.0,) * len(comps)
        else:
            values = dirichlet_values(d, "value", len(comps))
        d.done()
        dirichlet.append(Dirichlet(bname, sname, tuple(COMPONENTS[c] for c in comps), tuple(values), dname,
                                   motion))
    return dirichlet


def read_loads(top: Section, sets: SetRefs) -> tuple[list, list, list]:
    """(forces, pressures, tractions): every ``[[force]]``, ``[[pressure]]`` and ``[[traction]]`` entry."""
    forces = []
    for f in top.get("force", "array", []):
        bname, sname = sets.body_set(f, "set", "node")
        sets.deformable(f, "set", bname)
        value = f.get("value", "vector")
        dist = f.get("distribution", "str", "per_node", choices=("per_node", "total"))
        fname = f.get("name", "str", "")
        f.done()
        forces.append(NodalForce(bname, sname, value, dist, fname))

    pressures = []
    for p in top.get("pressure", "array", []):
        bname, sname = sets.body_set(p, "set", "face")
        sets.deformable(p, "set", bname)
        value = p.get("value", "float")
        pname = p.get("name", "str", "")
        p.done()
        pressures.append(Pressure(bname, sname, value, pname))

    tractions = []
    for t in top.get("traction", "array", []):
        bname, sname = sets.body_set(t, "set", "face")
        sets.deformable(t, "set", bname)
        value = t.get("value", "vector")
        tname = t.get("name", "str", "")
        t.done()
        tractions.append(Traction(bname, sname, value, tname))
    return forces, pressures, tractions
