"""Plane strain (CPE), plane stress (CPS) and axisymmetric (CAX) elements of an Abaqus or CalculiX deck as planar
bodies (docs/input.md, "Abaqus and CalculiX decks"; covcontact.elements.planar).

The element types map to the planar cells: 3 -> tri3, 4 and 4R -> quad4 (there is no hourglass-controlled quad4:
the R types take full integration, said in a note), 6 -> tri6, 8 -> quad8, 8R -> quad8 with reduced (2 x 2)
integration. The deck's node order is covcontact's (VTK's): corners counter-clockwise in the x-y plane, then the
mid-nodes of the edges 1-2, 2-3, 3-4 (4-1); face k (S k of *SURFACE, P k of *DLOAD) runs from node k to node k + 1
(the last to the first), as in both manuals. A body of CPE elements is ``formulation = "plane_strain"``, of CPS
elements ``"plane_stress"``, each with the thickness of its *SOLID SECTION's data line (default 1); a body of CAX
elements ``"axisymmetric"`` (x the radius, y the axis; the section's value has no effect, as in CalculiX). Forces mean
what they mean in CalculiX: a *CLOAD on a plane body acts on its thickness, on an axisymmetric body on the full
circumference (CalculiX's manual: "the point forces on the axisymmetric elements are to be given for the complete
circumference"); pressures are per area; the reactions of the .dat are of the same totals.
"""

from __future__ import annotations

import re

import numpy as np

from .deck import DeckError

#: the deck's type prefix -> the body's formulation
PLANAR_FORMULATION = {"CPE": "plane_strain", "CPS": "plane_stress", "CAX": "axisymmetric"}
#: the planar element types -> (cell type, options)
PLANAR_ELEMENTS = {f"{p}{n}": cell for p in PLANAR_FORMULATION for n, cell in (
    ("3", ("tri3", {})), ("4", ("quad4", {})), ("4R", ("quad4", {})), ("6", ("tri6", {})), ("8", ("quad8", {})),
    ("8R", ("quad8", {"integration": "reduced"})))}
#: Abaqus's hybrid plane strain and axisymmetric elements (there are no plane stress ones): the planar F-bar
#: (``options.fbar``; deck_import, a note), the triangle the plain one (one point: nothing to relieve)
PLANAR_ELEMENTS.update({f"{p}{n}H": (cell, {"hybrid": True}) for p in ("CPE", "CAX") for n, cell in (
    ("3", "tri3"), ("4", "quad4"), ("4R", "quad4"), ("6", "tri6"), ("8", "quad8"), ("8R", "quad8"))})
#: nodes and faces (edges) of the planar cells
PLANAR_NNODE = {"quad4": 4, "quad8": 8, "tri3": 3, "tri6": 6}
PLANAR_NFACES = {"quad4": 4, "quad8": 4, "tri3": 3, "tri6": 3}
#: the type written into an imported body's mesh file for each planar cell (types meshio reads as these cells)
MESH_TYPE = {"quad4": "CPS4", "quad8": "S8R", "tri3": "CPS3", "tri6": "CPE6"}


def is_planar_type(etype: str) -> bool:
    return etype in PLANAR_ELEMENTS


def formulation_of(etype: str) -> str | None:
    """The formulation of a planar element type (None: not planar)."""
    return PLANAR_FORMULATION[etype[:3]] if etype in PLANAR_ELEMENTS else None


def planar_body(w, k: int, name: str, types: set, secs: list, labels: np.ndarray) -> dict:
    """The planar keys of body ``k`` of the import ``w`` (deck_import._Writer) of deck element ``types``:
    ``formulation`` and ``thickness``; {} for a body of volume elements. One line (DeckError) for a body that mixes
    planar and volume elements or two formulations, a node off the x-y plane, an axisymmetric node at negative radius,
    a clockwise element, cells one mesh does not mix, several thicknesses; notes for the R types of quad4 and a
    thickness on CAX elements."""
    m = w.m
    planar = sorted(t for t in types if t in PLANAR_ELEMENTS)
    if not planar:
        return {}
    where = {t: next(wh for (bt, _, _, _), wh in zip(m.blocks, m.block_where) if bt == t) for t in types}
    if len(planar) < len(types):
        solid = sorted(set(types) - set(planar))
        raise DeckError(f"{where[solid[0]]}: body {name} joins {solid[0]} elements with planar {planar[0]} elements "
                        f"({where[planar[0]]}) through shared nodes: a body is planar or three-dimensional")
    forms = sorted({formulation_of(t) for t in planar})
    if len(forms) > 1:
        a, b = (next(t for t in planar if formulation_of(t) == f) for f in forms[:2])
        raise DeckError(f"{where[b]}: body {name} joins {a} ({forms[0]}) and {b} ({forms[1]}) elements through shared "
                        f"nodes: a body has one of plane strain (CPE), plane stress (CPS), axisymmetric (CAX)")
    form = forms[0]
    cells = sorted({PLANAR_ELEMENTS[t][0] for t in planar})
    if len(cells) > 1 and set(cells) not in ({"quad4", "tri3"}, {"quad8", "tri6"}):
        a, b = (next(t for t in planar if PLANAR_ELEMENTS[t][0] == c) for c in cells[:2])
        raise DeckError(f"{where[b]}: body {name} joins {a} and {b} elements: a planar body mixes only linear "
                        f"quadrilaterals with linear triangles and quadratic ones with quadratic ones")
    mine = w.b.of_node == k
    X, node_labels = m.X[mine], m.node_labels[mine]
    off = np.abs(X[:, 2]) > 0.0
    if off.any():
        j = int(np.flatnonzero(off)[0])
        raise DeckError(f"{where[planar[0]]}: node {int(node_labels[j])} of the {planar[0]} elements has z = "
                        f"{X[j, 2]:g}: plane strain, plane stress and axisymmetric elements lie in the x-y plane "
                        f"(z = 0)")
    if form == "axisymmetric" and np.any(X[:, 0] < 0.0):
        j = int(np.flatnonzero(X[:, 0] < 0.0)[0])
        raise DeckError(f"{where[planar[0]]}: node {int(node_labels[j])} of the {planar[0]} elements has x = "
                        f"{X[j, 0]:g}: x is the radius of an axisymmetric model (x >= 0)")
    index = m.node_index()
    for (etype, cell, elabels, conn), wh in zip(m.blocks, m.block_where):
        if etype not in planar:
            continue
        xy = m.X[index[conn[:, :3 if cell.startswith("tri") else 4]]][:, :, :2]
        area = 0.5 * np.sum(xy[:, :, 0] * np.roll(xy[:, :, 1], -1, axis=1)
                            - np.roll(xy[:, :, 0], -1, axis=1) * xy[:, :, 1], axis=1)
        bad = np.flatnonzero((area <= 0.0) & np.isin(elabels, labels))
        if bad.size:
            raise DeckError(f"{wh}: element {int(elabels[bad[0]])} ({etype}) is clockwise or of no area in the x-y "
                            f"plane: the corners of planar elements go counter-clockwise (CalculiX stops at its "
                            f"negative Jacobian)")
    quad_r = [t for t in planar if t.endswith("4R")]
    if quad_r:
        w.notes.append(f"{where[quad_r[0]]}: {', '.join(quad_r)}: covcontact's quad4 has no hourglass control; read as "
                       f"{', '.join(t[:-1] for t in quad_r)} (full integration, 2 x 2 points)")
    values = {}
    for s, _, swhere in secs:
        text, dwhere = m.section_thickness.get(swhere, ("", swhere))
        if text:
            try:
                t = float(text.replace("d", "e").replace("D", "E"))
            except ValueError:
                raise DeckError(f"{dwhere}: *SOLID SECTION: the thickness must be a number, got {text!r}") from None
            if not t > 0.0 and form != "axisymmetric":
                raise DeckError(f"{dwhere}: *SOLID SECTION: the thickness must exceed zero, got {text}")
            values[swhere] = t
    out = {"formulation": form}
    if form == "axisymmetric":
        if values:
            w.notes.append(f"{next(iter(values))}: *SOLID SECTION of {planar[0]} elements: the thickness has no effect "
                           f"(an axisymmetric model spans the full circumference; CalculiX ignores it too)")
        return out
    thick = {values.get(swhere, 1.0) for _, _, swhere in secs}
    if len(thick) > 1:
        raise DeckError(f"{secs[1][2]}: body {name} has *SOLID SECTIONs of thicknesses "
                        f"{', '.join(f'{t:g}' for t in sorted(thick))}: a planar body has one thickness")
    out["thickness"] = thick.pop()
    return out


def _planar_bodies(w) -> dict[int, str]:
    """The bodies of the import ``w`` made of planar elements: body -> the first deck type."""
    if "_planar_bodies" not in w.__dict__:
        out: dict[int, str] = {}
        for j, (etype, _, _, _) in enumerate(w.m.blocks):
            if etype in PLANAR_ELEMENTS:
                for body in np.unique(w.b.of_element[w.b.block_range(j)]):
                    out.setdefault(int(body), etype)
        w._planar_bodies = out
    return w._planar_bodies


def planar_dof3(w, body: int, where: str, value: float | None, load: bool = False) -> bool:
    """Whether dof 3 (z) of nodes of ``body`` is left out: a planar body's z is held at zero everywhere (CalculiX holds
    the out-of-plane motion of its expanded 2D elements too), so a *BOUNDARY of z = 0 is what it is anyway; a nonzero
    one is listed as unsupported, a *CLOAD along z (a reaction of the held dof) said in a note."""
    etype = _planar_bodies(w).get(int(body))
    if etype is None:
        return False
    if load:
        w.notes.append(f"{where}: *CLOAD along dof 3 on nodes of {etype} elements: the out-of-plane direction is held; "
                       f"the force is left out")
    elif value:
        w.unsupported.append(f"{where}: *BOUNDARY of {value:g} on dof 3 of nodes of {etype} elements: the out-of-plane "
                             f"displacement of plane strain, plane stress and axisymmetric nodes is zero; with "
                             f"--ignore-unsupported it is left out")
    return True


def planar_contact(w, sb: int, mb: int, kind: str, sk: str, it, where: str) -> dict | bool | None:
    """A deck's contact pair (or *TIE, ``kind`` "TIE") between the bodies ``sb`` (slave; ``sk`` "ELEMENT" or "NODE"
    its surface's kind) and ``mb`` as node-to-segment contact in the plane (docs/input.md, "Contact pairs on planar
    bodies"): None when neither body is planar (the 3D mapping goes on), False when the pair is left out (listed as
    unsupported), else the keys of the [[contact]] entry besides its name, slave and master.

    The laws keep CalculiX's meaning. CalculiX expands a planar element into one layer of 3D elements (the section's
    thickness; an axisymmetric one into a 2 degree segment), so a penalty K per area of an expanded face is K per unit
    length of the edge times the thickness (2 pi R over the full circumference, of which the .dat prints 1/180): the
    planar pair's ``weighting = "area"`` (eps = K int N_a t ds, t the thickness or 2 pi R) is that same law, the
    forces totals as the body's. Mapped: PRESSURE-OVERCLOSURE=HARD on NODE TO SURFACE pairs of element surfaces
    (augmented Lagrange with the automatic penalty 10 E / h per area, as the 3D import); LINEAR (face-to-face pairs
    the penalty K per area, node-to-face ones CalculiX's arctan curve with its tension), EXPONENTIAL and TABULAR as
    in 3D, per area. Face-to-face pairs (TYPE=SURFACE TO SURFACE on element surfaces) are segment-to-segment
    contact in the plane (``type = "sts"``: the Gauss points of the slave edges). Listed as unsupported (CalculiX has
    them, contact in the plane does not): a node surface (TYPE=NODE) as the slave, a pair
    between planar and 3D elements or between two planar formulations (left out with the flag) and ADJUST (left out
    with the flag). *FRICTION is Coulomb friction along the master edges (mu, and the stick slope as the tangential
    penalty per area, as in 3D). *TIE and PRESSURE-OVERCLOSURE=TIED become tied pairs in the plane
    (``law = "tied"``): *TIE with the automatic tie penalty (CalculiX writes equations), TIED with its slope K per
    area."""
    kinds = {b: _planar_bodies(w).get(int(b)) for b in (sb, mb)}
    if kinds[sb] is None and kinds[mb] is None:
        return None
    name = {b: w.body_names[int(b)] for b in (sb, mb)}
    types = [kinds[b] for b in (sb, mb)]
    what = "*TIE" if kind == "TIE" else "*CONTACT PAIR"
    flag = "with --ignore-unsupported the pair is left out"
    if None in types:
        solid = sb if kinds[sb] is None else mb
        planar = mb if solid == sb else sb
        w.unsupported.append(f"{where}: {what} between planar {kinds[planar]} elements (body {name[planar]}) and 3D "
                             f"elements (body {name[solid]}): contact in the plane joins planar bodies only; {flag}")
        return False
    forms = [formulation_of(t) for t in types]
    if forms[0] != forms[1]:
        w.unsupported.append(f"{where}: {what} between {types[0]} ({forms[0]}, body {name[sb]}) and {types[1]} "
                             f"({forms[1]}, body {name[mb]}) elements: contact in the plane joins bodies of one "
                             f"formulation; {flag}")
        return False
    etype = types[0]
    sts = kind == "SURFACE TO SURFACE" and sk == "ELEMENT"
    if (kind == "TIE" or it.behavior == "tied") and sk == "NODE":
        w.unsupported.append(f"{where}: {what if kind == 'TIE' else 'PRESSURE-OVERCLOSURE=TIED'} with a node surface "
                             f"(TYPE=NODE) as the slave on {etype} elements: a tie in the plane weights its slave "
                             f"nodes by their edges; {flag}")
        return False
    if kind == "TIE":  # CalculiX's equations; here a stiff penalty tie (100 E / h per area), as in 3D
        entry = {"law": "tied", "penalty": "auto", "weighting": "area"}
        tol = next((t for _, _, _, t, at in w.m.ties if at == where), None)
        if tol:
            entry["tie_tolerance"] = tol
        return entry
    if it.behavior == "tied":  # face-to-face: the slope K per area (the stick slope checked as in 3D)
        entry = {"weighting": "area"}
        return entry if w._tied_pair(entry, it, True, where) else False
    if sk == "NODE":
        w.unsupported.append(f"{where}: a node surface (TYPE=NODE) as the slave of a pair on {etype} elements: "
                             f"CalculiX weights such nodes by their share of the body's boundary faces, which contact "
                             f"in the plane does not have (its slaves are edge surfaces); {flag}")
        return False
    entry: dict = {"type": "sts"} if sts else {"weighting": "area"}   # (face-to-face: segment-to-segment)
    if it.behavior == "linear":  # (face-to-face: the linear penalty K; node-to-face: the arctan curve, as in 3D)
        w._linear(entry, it, sts, where)
    elif it.behavior in ("exponential", "tabular"):
        entry.update(it.curve(w.dialect))
    else:
        entry.update({"penalty": "auto", "method": "augmented"})
    if it.friction is not None and it.friction[0] > 0:  # covariant Coulomb friction along the master edges
        entry["friction"] = it.friction[0]
        if it.friction[1] is not None and it.friction[1] > 0:  # the stick slope, per area as K
            entry["tangential_penalty"] = it.friction[1]
    if w.m.pair_adjust.get(where) is not None:
        w.unsupported.append(f"{where}: ADJUST on {etype} elements: not available in the plane; with "
                             f"--ignore-unsupported the slave nodes are not moved")
    return entry


#: deck types CalculiX expands into 3D elements (shells, membranes, beams, planar elements): their nodes get new labels
_EXPANDED = re.compile(r"^(S\d|M3D|B3\d|CPE|CPS|CAX)")


def contact_print_labels(w, pairs: dict[str, tuple[int, bool]]) -> tuple[dict, list[str]]:
    """The planar pairs whose slaves the .dat tabulates as CalculiX does, and those it cannot: ``pairs`` maps a
    planar pair's name to (slave body, face-to-face). CalculiX expands each node of its 2D elements (in the order of
    the labels) into three, numbered after the deck's largest label: max + 3 j + 1, + 2, + 3 (j the node's place
    among them), and its node-to-face contact elements on linear edges (CPE3/4, CPS3/4, CAX3/4) are the two face nodes
    + 1 and + 3, each with half the 2D node's force (an axisymmetric one: of the 2 degree segment). Returns ({"pairs":
    {name: formulation}, "labels": {deck label: max + 3 j + 1}}, the names left out: face-to-face pairs, quadratic
    edges, and every pair of a deck with shells, membranes or beams, whose expansion numbers nodes otherwise)."""
    kinds = _planar_bodies(w)
    expanded = [j for j, (etype, _, _, _) in enumerate(w.m.blocks) if _EXPANDED.match(etype)]
    others = any(not is_planar_type(w.m.blocks[j][0]) for j in expanded) or bool(w.m.shell_blocks) or \
        any(_EXPANDED.match(etype) for etype, _, _ in w.m.skipped_blocks)
    printed, left = {}, []
    for name, (sb, sts) in sorted(pairs.items()):
        etype = kinds.get(int(sb), "")
        if sts or others or PLANAR_ELEMENTS.get(etype, ("",))[0] not in ("quad4", "tri3"):
            left.append(name)
        else:
            printed[name] = formulation_of(etype)
    if not printed:
        return {}, left
    nodes = np.unique(np.concatenate([w.m.blocks[j][3].ravel() for j in expanded]))
    top = int(w.m.node_labels.max())
    return {"pairs": printed, "labels": {int(n): top + 3 * j + 1 for j, n in enumerate(nodes)}}, left


def element_names(types) -> str:
    """The element types a deck may have, as a message lists them: the planar ones grouped per formulation
    ('C3D8, C3D8R, ..., CPE3/4/4R/6/8/8R, CPS3/..., CAX3/...')."""
    plain = [t for t in types if t not in PLANAR_ELEMENTS]
    groups = [p + "/".join(t[3:] for t in types if t in PLANAR_ELEMENTS and t.startswith(p)) for p in PLANAR_FORMULATION
              if any(t.startswith(p) for t in types if t in PLANAR_ELEMENTS)]
    return ", ".join(plain + groups)
