"""The ``[[contact]]`` section: contact pairs, their slave set and master surface, law, penalty, tangent case
and friction (docs/input.md)."""

from __future__ import annotations

from ..description import TANGENT_CASES, ContactPair
from .conditions_input import SetRefs
from .fields import split_ref
from .validate import Section


def read_contacts(top: Section, sets: SetRefs, rigid: list) -> list[ContactPair]:
    """Every ``[[contact]]`` entry."""
    contacts = []
    for i, c in enumerate(top.get("contact", "array", [])):
        cname = c.get("name", "str", f"contact{i + 1}")
        slave = sets.body_set(c, "slave", "node")
        mref = c.get("master", "str")
        mbody, mset = split_ref(c, "master", mref)
        analytic = next((r for r in rigid if r.name == mbody and r.mesh is None), None)
        if analytic is not None:
            if mset:
                c.fail(f"{mref!r}: the analytic surface {mbody!r} has no sets; name it alone", "master")
            master = (mbody, "")
        else:
            c.data["master"] = mref
            master = sets.body_set(c, "master", "face")
        if slave[0] == master[0] and slave[0] in {r.name for r in rigid}:
            c.fail("slave and master are the same rigid body")
        if slave == master:
            c.fail(f"slave and master are the same surface '{slave[0]}.{slave[1]}': a surface in contact with "
                   f"itself needs self-contact, which covcontact does not have yet; for two parts of one body's "
                   f"surface name two different face sets", "master")
        law = c.get("law", "str", "penalty", choices=("penalty", "exponential"))
        clearance = pressure = None
        if law == "exponential":
            for key in ("penalty", "smoothing", "method"):
                if c.has(key):
                    c.fail(f"not used by law = \"exponential\" (its pressure-overclosure curve is given by "
                           f"clearance and pressure)", key)
            clearance = c.get("clearance", "float", positive=True)
            pressure = c.get("pressure", "float", positive=True)
            penalty = pressure
        elif isinstance(c.data.get("penalty"), str):
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
        if weighting == "area" or penalty == "auto":
            owner = next((b.mesh for b in sets.bodies if b.name == slave[0]), None) or next(
                (r.mesh for r in rigid if r.name == slave[0] and r.mesh is not None), None)
            if owner is not None and slave[1] not in owner.face_sets:
                faces = ", ".join(sorted(owner.face_sets)) or "none"
                what = 'weighting = "area"' if weighting == "area" else 'penalty = "auto"'
                c.fail(f"{what} needs the slave's faces, but {slave[0]}.{slave[1]} is a node set only: give a "
                       f'face set of {slave[0]!r} ({faces}) or weighting = "nodal"', "slave")
        tangent = c.get("tangent", "str", "a", choices=TANGENT_CASES)
        two_pass = c.get("two_pass", "bool", False)
        mu = c.get("friction", "float", 0.0, nonnegative=True)
        eps_t = c.get("tangential_penalty", "float", None, positive=True)
        enabled = c.get("enabled", "bool", True)
        smoothing = c.get("smoothing", "float", 0.0, nonnegative=True)
        c.done()
        if any(x.name == cname for x in contacts):
            c.fail(f"duplicate contact name {cname!r}", "name")
        contacts.append(ContactPair(cname, slave, master, penalty, weighting, tangent, two_pass,
                                    friction=mu, tangential_penalty=eps_t, method=method, gap_tolerance=gap_tol,
                                    gap_tolerance_relative=gap_rel, max_augmentations=max_aug,
                                    auto_factor=auto_factor, enabled=enabled, smoothing=smoothing, law=law,
                                    clearance=clearance, pressure=pressure))
    return contacts
