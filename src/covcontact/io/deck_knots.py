"""Knots and hinges of a deck's shells (docs/input.md, "Knots"; docs/theory.md section 25): the nodes that
``covcontact.io.deck_shells`` expands once per subset of their elements and joins by a rigid body, and the shell
nodes that solid elements share (CalculiX's hinge: equations)."""

from __future__ import annotations

import numpy as np

from .deck import DeckError


def forced_knots(m, shell_nodes: np.ndarray) -> dict[int, str]:
    """Shell node label -> the card that gives it a non-zero rotation (*BOUNDARY, dofs 4-6) or a moment (*CLOAD,
    dofs 4-6) in some step: a knot (CalculiX's dynamic steps make one; its static ones a mean rotation, which
    leaves the thickness there free)."""
    out: dict[int, str] = {}
    for b in list(m.model_boundary) + [b for st in m.steps for b in st.boundary]:
        if b.value not in (None, 0.0) and any(d >= 4 for d in b.dofs):
            for lab in np.intersect1d(b.nodes, shell_nodes).tolist():
                out.setdefault(int(lab), b.where)
    for st in m.steps:
        for ld in st.loads:
            if ld.kind == "cload" and ld.dof >= 4 and ld.value != 0.0:
                for lab in np.intersect1d(ld.nodes, shell_nodes).tolist():
                    out.setdefault(int(lab), ld.where)
    return out


def split_part(shells, nodes, cells, points, tc, oc, cell, rank, forced):
    """The part's surface split at its knots (mesh.shell.split_at_knots: subsets by normal within 20 degrees, by
    thickness ``tc`` and by offset ``oc`` (each element's at each of its nodes), and the nodes of ``forced``): (its
    node labels, the expansions after the deck's with labels of their own (``shells._next`` on); cells; points;
    thicknesses; offsets; [(knot label, its expansions' places)])."""
    from ..mesh.shell import ShellMeshError, split_at_knots

    pairs = np.stack([tc.ravel(), oc.ravel()], axis=1)
    key = np.unique(pairs, axis=0, return_inverse=True)[1].reshape(tc.shape).astype(float)  # (one per pair)
    try:
        points, cells_new, source, found = split_at_knots(points, cells, cell, rank=rank, key=key,
                                                          forced=np.isin(nodes, list(forced)))
    except ShellMeshError:  # (extrude_surface says so)
        cells_new, labels, found = cells, nodes, []
    else:
        copies = source.size - (nodes.size - len(found))
        labels = np.concatenate([nodes[source[: source.size - copies]], shells._next + np.arange(copies)])
        shells._next += copies
    t, o = np.zeros(labels.size), np.zeros(labels.size)
    t[cells_new.ravel()], o[cells_new.ravel()] = tc.ravel(), oc.ravel()
    return labels, cells_new, points, t, o, [(int(nodes[i]), places) for i, places in found]


def register_knot(shells, lab: int, copies: np.ndarray, d: np.ndarray, where: str) -> None:
    """Shell node ``lab`` as a knot: a rigid body (appended to the deck's *RIGID BODYs) of its expansions
    ``copies`` (labels; ``d`` their directors) with the node as REF NODE. Expansions on one line leave the
    rotation about it to nothing: held where the line is a global axis, else listed."""
    if lab in shells.shared:
        raise DeckError(f"{where}: shell node {lab} is a knot of the shell expansion and a node of a solid element: "
                        f"not supported (tie the shell to the solid with *TIE there)")
    drill = None
    if np.all(np.linalg.norm(np.cross(d, d[0]), axis=1) < 1e-6):
        k = int(np.argmax(np.abs(d[0])))
        if abs(d[0][k]) < 1.0 - 1e-9:
            shells.unsupported.append(f"{where}: a moment or a non-zero rotation on shell node {lab}, whose normal "
                                    f"{_vec(d[0])} is no global axis: its knot (a rigid body of the node's "
                                    f"expansion along the normal) cannot hold the rotation about the normal; "
                                    f"not supported")
        drill = k
    shells.knots[len(shells.m.rigid_bodies)] = (lab, drill)
    shells.m.rigid_bodies.append((np.asarray(copies, dtype=np.int64), lab, None, where))


def hinge_equations(shells, ref, solid_ref) -> list[dict]:
    """The [[equation]] entries of the nodes shared with solid elements (CalculiX: a hinge): per component the
    mean of the shell node's two layers equals the solid node's displacement, u_b + u_t - 2 u_s = 0
    (``solid_ref(label)``: the solid node's single-node set reference)."""
    out = []
    for lab in sorted(shells.shared):
        body = int(shells.label_body[lab])
        if body < 0:
            continue
        b, t, s = ref(body, f"_SN{lab}_b"), ref(body, f"_SN{lab}_t"), solid_ref(lab)
        out += [{"name": f"hinge{lab}_{c}", "terms": [[b, c, 1.0], [t, c, 1.0], [s, c, -2.0]]} for c in "xyz"]
    return out


def knot_note(where: str, first: int, found: list) -> str:
    """The note that says a shell part's knots (``found``: [(label, its expansions' places)])."""
    spread = sum(1 for _, c in found if c.size > 1)
    why = [f"{spread} where its elements' normals differ by more than 20 degrees or their thicknesses or offsets differ"] \
        if spread else []
    why += [f"{len(found) - spread} for a moment or a non-zero rotation"] if spread < len(found) else []
    return (f"{where}: {len(found)} knot{'s' if len(found) > 1 else ''} in the shell part of element {first} "
            f"({', '.join(why)}): as in CalculiX each such node is expanded once per normal and the expansions are "
            f"joined by a rigid body whose reference is the node (its dofs 1-6 the body's translation and rotation); "
            f"CalculiX's knot may also expand uniformly, covcontact's holds the thickness there")


def _vec(v) -> str:
    return "(" + ", ".join(f"{x:.3g}" for x in v) + ")"
