"""The ``[[contact]]`` section: contact pairs, their slave set and master surface, law, penalty, tangent case
and friction (docs/input.md)."""

from __future__ import annotations

from ..description import TANGENT_CASES, ContactPair
from .conditions_input import SetRefs
from .fields import split_ref
from .validate import Section, suggest

#: the largest number of Gauss points per direction of a segment-to-surface slave facet
MAX_ORDER = 8


def _slave_faces(c, sets) -> None:
    """An sts pair's slave must be a face set: one line naming it when it is a node set only."""
    ref = c.data.get("slave")
    if not isinstance(ref, str):
        return  # body_set reports it
    bname, sname = split_ref(c, "slave", ref)
    owner = sets.mesh(bname)
    if owner is not None and sname in owner.node_sets and sname not in owner.face_sets:
        faces = ", ".join(sorted(owner.face_sets)) or "none"
        c.fail(f"type = \"sts\" integrates over the slave's faces, but {ref!r} is a node set only: give a face set "
               f"of {bname!r} ({faces})", "slave")


def _self_surfaces(c, sets) -> tuple:
    """The face sets of a self-contact: one "BODY.FACESET" or a list of them (merged into one surface)."""
    val = c.get("self", "any")
    refs = [val] if isinstance(val, str) else val
    if not isinstance(refs, list) or not refs or not all(isinstance(r, str) for r in refs):
        c.fail("give a face set \"BODY.FACESET\" or a list of them", "self")
    out = []
    for ref in refs:
        c.data["self"] = ref
        bname, sname = split_ref(c, "self", ref)
        owner = sets.mesh(bname)
        if owner is not None and sname in owner.node_sets and sname not in owner.face_sets:
            c.fail(f"{ref!r} is a node set; self-contact needs the faces of the surface: give a face set of "
                   f"{bname!r} ({', '.join(sorted(owner.face_sets)) or 'none'})", "self")
        out.append(sets.body_set(c, "self", "face"))
    if len(set(out)) != len(out):
        c.fail("a face set is listed twice", "self")
    return tuple(out)


def _pressure_table(c) -> tuple:
    """``table``: at least two [overclosure, pressure] pairs, the overclosures increasing, no pressure negative."""
    val = c.get("table", "any")
    ok = isinstance(val, list) and len(val) >= 2 and all(
        isinstance(r, list) and len(r) == 2 and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                    for v in r) for r in val)
    if not ok:
        c.fail("give at least two pairs [overclosure, pressure], e.g. [[0.0, 0.0], [0.01, 100.0]]", "table")
    rows = tuple((float(a), float(b)) for a, b in val)
    if any(b[0] <= a[0] for a, b in zip(rows, rows[1:])):
        c.fail("the overclosures must increase from pair to pair", "table")
    if any(r[1] < 0.0 for r in rows):
        c.fail("pressures must not be negative (the contact pushes; tension is not transmitted)", "table")
    return rows


def read_contacts(top: Section, sets: SetRefs, rigid: list) -> list[ContactPair]:
    """Every ``[[contact]]`` entry."""
    contacts = []
    for i, c in enumerate(top.get("contact", "array", [])):
        cname = c.get("name", "str", f"contact{i + 1}")
        ctype = c.get("type", "str", "nts", choices=("nts", "sts"))
        surfaces = None
        if c.has("self"):
            for key in ("slave", "master", "two_pass"):
                if c.has(key):
                    c.fail(f"not used with self (one surface is slave and master of itself, both sides act): "
                           f"remove {key!r}", key)
            surfaces = _self_surfaces(c, sets)
            slave = master = surfaces[0]
        else:
            if ctype == "sts":
                _slave_faces(c, sets)
            slave = sets.body_set(c, "slave", "face" if ctype == "sts" else "node")
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
                       f"itself is self-contact: write self = \"{slave[0]}.{slave[1]}\" instead of slave and "
                       f"master", "master")
        order = None
        if c.has("order"):
            if ctype != "sts":
                c.fail("the Gauss rule of the slave facets is for type = \"sts\"", "order")
            order = c.get("order", "int")
            if not 1 <= order <= MAX_ORDER:
                c.fail(f"{order} Gauss points per direction: the slave facets have rules of 1 to {MAX_ORDER} points "
                       f"per direction (2 suits quad4 facets, 3 quad9)", "order")
        law = c.get("law", "str", "penalty", choices=("penalty", "exponential", "tied", "arctan", "table"))
        clearance = pressure = tie_tol = None
        form, tension, reach, table = "abaqus", 0.0, None, ()
        if law == "tied":
            for key in ("friction", "method", "smoothing", "two_pass"):
                if c.has(key):
                    c.fail("not used by law = \"tied\" (the surfaces are bonded: no opening, no sliding)", key)
            if surfaces is not None:
                c.fail("a surface cannot be tied to itself", "law")
            if master[1] == "":
                c.fail(f"law = \"tied\" bonds to a meshed surface; {master[0]!r} is an analytic one", "master")
            tie_tol = c.get("tie_tolerance", "float", None, positive=True)
        elif c.has("tie_tolerance"):
            c.fail("tie_tolerance is for law = \"tied\"", "tie_tolerance")
        if law == "exponential":
            for key in ("penalty", "smoothing", "method"):
                if c.has(key):
                    c.fail("not used by law = \"exponential\" (its pressure-overclosure curve is given by "
                           "clearance and pressure)", key)
            clearance = c.get("clearance", "float", positive=True)
            pressure = c.get("pressure", "float", positive=True)
            form = c.get("form", "str", "abaqus", choices=("abaqus", "calculix"))
            if form == "calculix" and master[1] == "":
                c.fail(f"form = \"calculix\" acts on meshed masters; {master[0]!r} is an analytic surface", "form")
            penalty = pressure
        elif c.has("form"):
            c.fail("form is for law = \"exponential\" (\"abaqus\" or \"calculix\")", "form")
        if law in ("arctan", "table"):
            for key in ("smoothing", "method"):
                if c.has(key):
                    c.fail(f"not used by law = \"{law}\" (its curve is the pressure-overclosure law itself; "
                           f"penalty only)", key)
            if master[1] == "":
                c.fail(f"law = \"{law}\" acts on meshed masters; {master[0]!r} is an analytic surface (use law = "
                       f"\"penalty\" or \"exponential\")", "law")
            reach = c.get("reach", "float", None, positive=True)
        elif c.has("reach"):
            c.fail("reach is for law = \"arctan\" or \"table\"", "reach")
        if law == "arctan":
            tension = c.get("tension", "float", positive=True)
        elif c.has("tension"):
            c.fail("tension is for law = \"arctan\"", "tension")
        if law == "table":
            if c.has("penalty"):
                c.fail("not used by law = \"table\" (the table's slopes are its stiffness)", "penalty")
            table = _pressure_table(c)
            penalty = max(abs(b[1] - a[1]) / (b[0] - a[0]) for a, b in zip(table, table[1:])) or 1.0
        elif c.has("table"):
            c.fail("table is for law = \"table\" (pairs [overclosure, pressure])", "table")
        if law in ("exponential", "table"):
            pass
        elif isinstance(c.data.get("penalty"), str):
            penalty = c.get("penalty", "str", choices=("auto",))
        else:
            penalty = c.get("penalty", "float", positive=True)
        if law == "arctan" and penalty == "auto":
            c.fail("law = \"arctan\" takes its slope K as a number (its tension sigma_inf is relative to it)",
                   "penalty")
        auto_factor = c.get("auto_factor", "float", None, positive=True)
        method = c.get("method", "str", "penalty", choices=("penalty", "augmented"))
        gap_tol = c.get("gap_tolerance", "float", None, positive=True)
        gap_rel = c.get("gap_tolerance_relative", "float", None, positive=True)
        max_aug = c.get("max_augmentations", "int", 20, positive=True)
        if method == "augmented" and gap_tol is None and gap_rel is None:
            gap_rel = 1e-3
        if method == "penalty" and (gap_tol is not None or gap_rel is not None):
            c.fail("gap tolerances need method = \"augmented\"")
        given = c.has("weighting")
        weighting = c.get("weighting", "str", "nodal", choices=("nodal", "area", "boundary"))
        if weighting == "boundary" and (ctype == "sts" or surfaces is not None):
            c.fail("weighting = \"boundary\" gives node-to-surface slaves their area over all the boundary faces of "
                   "their body around them (CalculiX's node surfaces): not for sts or self-contact", "weighting")
        if ctype == "sts":
            if given and weighting != "area":
                c.fail("type = \"sts\" integrates the gap over the slave surface: its penalty is per unit area "
                       "(weighting = \"area\" or leave weighting out)", "weighting")
            weighting = "area"
        if surfaces is None and (weighting == "area" or penalty == "auto"):
            owner = sets.mesh(slave[0])
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
        adjust = _adjust(c, sets, slave, master, law, surfaces, rigid)
        gap = _gap(c, ctype, law, method, mu, rigid, master)
        c.done()
        if any(x.name == cname for x in contacts):
            c.fail(f"duplicate contact name {cname!r}", "name")
        contacts.append(ContactPair(cname, slave, master, penalty, weighting, tangent, two_pass,
                                    friction=mu, tangential_penalty=eps_t, method=method, gap_tolerance=gap_tol,
                                    gap_tolerance_relative=gap_rel, max_augmentations=max_aug,
                                    auto_factor=auto_factor, enabled=enabled, smoothing=smoothing, law=law,
                                    clearance=clearance, pressure=pressure, form=form, tension=tension,
                                    reach=reach, table=table, type=ctype, order=order,
                                    self_surfaces=surfaces, tie_tolerance=tie_tol, adjust=adjust, gap=gap))
    return contacts


def _gap(c: Section, ctype: str, law: str, method: str, mu: float, rigid: list, master) -> str:
    """``gap``: segment-to-surface's law on each Gauss point's gap ("points") or on each slave node's weighted gap
    ("nodal"; frictionless penalty pairs, smoothed or not, not against an analytic tool with a reference node)."""
    gap = c.get("gap", "str", "points", choices=("points", "nodal"))
    if gap == "nodal":
        tool = next((r for r in rigid if r.name == master[0] and r.mesh is None and (r.free or r.attach)), None)
        why = ("it is for type = \"sts\"" if ctype != "sts" else
               f"not with law = \"{law}\" (penalty only)" if law != "penalty" else
               "not with method = \"augmented\"" if method != "penalty" else
               "not with friction (frictionless pairs)" if mu > 0.0 else
               f"not against {tool.name!r}, an analytic surface with free components or attached nodes (a reference "
               f"node): mesh the tool, or use gap = \"points\"" if tool is not None else None)
        if why:
            c.fail(f"gap = \"nodal\": {why}", "gap")
    return gap


def _adjust(c: Section, sets: SetRefs, slave, master, law: str, surfaces, rigid) -> float | str | None:
    """``adjust``: a distance (>= 0) or a node set of the slave body."""
    if not c.has("adjust"):
        return None
    if surfaces is not None or law == "tied":
        c.fail("moves slave nodes onto a master: not for self-contact or law = \"tied\" (which bonds within "
               "tie_tolerance)", "adjust")
    if master[1] == "":
        c.fail(f"moves slave nodes onto a meshed master; {master[0]!r} is an analytic surface", "adjust")
    if any(r.name == slave[0] for r in rigid):
        c.fail(f"moves slave nodes of a deformable body; {slave[0]!r} is rigid", "adjust")
    if isinstance(c.data["adjust"], str):
        name = c.get("adjust", "str")
        sets_of = sets.mesh(slave[0]).node_sets
        if name not in sets_of:
            c.fail(f"body {slave[0]!r} has no node set {name!r}{suggest(name, sets_of)} (a distance, or a node set "
                   f"of the slave body)", "adjust")
        return name
    return c.get("adjust", "float", nonnegative=True)
