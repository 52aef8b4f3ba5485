"""A deck's *RIGID BODY as covcontact rigid bodies with attached nodes (docs/input.md, "Abaqus and CalculiX decks").

A *RIGID BODY's nodes (NSET=, or the nodes of ELSET=) are attached to a ``[[rigid]]`` body whose reference point is
its REF NODE; the REF NODE's dofs 1-3 are the body's translation and the ROT NODE's three its rotation vector
(CalculiX's convention), as are the REF NODE's dofs 4-6 (Abaqus'; ``covcontact.io.deck_coupling``, which also adds
the *KINEMATIC couplings as such bodies). A *BOUNDARY on either node prescribes that component (the body's
``motion``, a stage's ``motions``), a *CLOAD on it applies the body's force or moment; the components never
prescribed are ``free``. A prescribed value is the node's total displacement, the rotation vector the body's total
rotation R(theta) about the REF NODE, each going linearly over a step from the value the step starts with (as
CalculiX's rotational node means it): a later stage's motion is a ``total`` one.
"""

from __future__ import annotations

import numpy as np

from .deck import DeckError
from .deck_coupling import coupled_components, coupling_names, planar_couplings

_NAMES = ("x", "y", "z", "rx", "ry", "rz")


class DeckRigid:
    """The rigid bodies of a deck, their prescribed components and loads per covcontact stage."""

    def __init__(self, m, parts, shells=None):
        self.m, self.b, self.shells = m, parts, shells
        #: the knots of shell expansions among the bodies (deck_shells): body -> (shell node label, drilling component)
        self.knots = dict(shells.knots) if shells is not None else {}
        self.by_label: dict[int, tuple[int, int]] = {}   # REF / ROT node label -> (body, 0 or 3)
        index = m.node_index()
        for r, (nodes, ref, rot, where) in enumerate(m.rigid_bodies):
            for lab, off, key in ((ref, 0, "REF NODE"), (rot, 3, "ROT NODE")):
                if lab is None:
                    continue
                if lab >= index.size or index[lab] < 0:
                    raise DeckError(f"{where}: {key}={lab}: no *NODE defines node {lab}")
                if lab in self.by_label:
                    raise DeckError(f"{where}: {key}={lab}: node {lab} is already the reference or rotation node of a "
                                    f"rigid body; give each body its own")
                self.by_label[lab] = (r, off)
        # (a *COUPLING with *KINEMATIC: named after its CONSTRAINT NAME; its nodes may follow some components only)
        self.names = coupling_names(m, [f"KNOT{self.knots[r][0]}" if r in self.knots else f"RIGID{r + 1}"
                                        for r in range(len(m.rigid_bodies))])
        self.components = coupled_components(m)
        # (a *KINEMATIC coupling of some dofs: the translations its nodes do not follow move nothing, they are held
        # where nothing prescribes them, as CalculiX leaves such a dof out)
        self.idle = {r: [c for c in range(3) if c not in comps] for r, comps in self.components.items()}
        for r in planar_couplings(m):  # (on planar elements: in the plane; tz is idle already, no node follows it)
            self.idle[r] = sorted(set(self.idle.get(r, [])) | {3, 4})
        for r, (_, drill) in self.knots.items():  # (a knot on one line: its rotation about the line moves nothing)
            if drill is not None:
                self.idle[r] = [3 + drill]
        # each body's reference point: its REF NODE, or (without one: its translation can be neither prescribed nor
        # loaded) the centroid of its nodes
        self.origins = [m.X[index[ref]] if ref is not None else m.X[index[nodes]].mean(axis=0)
                        for nodes, ref, _, _ in m.rigid_bodies]
        self.stage_values: list[dict] = []   # per covcontact stage: {(r, comp): prescribed value at its end}
        self.stage_loads: list[dict] = []    # per covcontact stage: {(r, comp): force or moment at its end}
        self.unsupported: list[str] = []
        self.notes: list[str] = []

    def split(self, labels: np.ndarray) -> tuple[np.ndarray, list[tuple[int, int]]]:
        """(the labels that are no rigid body's REF or ROT node, [(body, 0 or 3)] of those that are)."""
        if not self.by_label:
            return labels, []
        hit = np.isin(labels, list(self.by_label))
        return labels[~hit], [self.by_label[int(lab)] for lab in labels[hit]]

    def stage(self, values: dict, loads: dict) -> tuple[dict, dict]:
        """Record a stage's prescribed values and loads; for a stage after the first its ``motions`` (``total``
        ones: the prescribed displacement and rotation vector at its end) and rigid ``targets`` (new force and
        moment)."""
        self.stage_values.append(values)
        self.stage_loads.append(loads)
        if len(self.stage_values) == 1:
            return {}, {}
        prev_v, prev_l = self.stage_values[-2], self.stage_loads[-2]
        motions, targets = {}, {}
        for r, name in enumerate(self.names):
            comps = {c for (q, c) in values if q == r}
            if comps:
                v = [values.get((r, c), 0.0) for c in range(6)]
                if v != [prev_v.get((r, c), 0.0) for c in range(6)]:
                    # (the total rotation vector, not its change composed onto the rotation reached: the two differ
                    # once the axis turns)
                    motions[name] = {"translation": v[:3], "rotation": v[3:], "center": self.origins[r].tolist(),
                                     "total": True}
            new = [0.0 if c in self.idle.get(r, ()) else loads.get((r, c), 0.0) for c in range(6)]
            if new != [prev_l.get((r, c), 0.0) for c in range(6)]:
                targets[name] = {"force": new[:3], "moment": new[3:]}
        return motions, targets

    def entries(self, node_sets: dict, ref) -> list[dict]:
        """The ``[[rigid]]`` tables: ``node_sets`` receives each body's attached node sets, ``ref(body, set)`` names
        them."""
        out = []
        first_v = self.stage_values[0] if self.stage_values else {}
        first_l = self.stage_loads[0] if self.stage_loads else {}
        prescribed = {(r, c) for v in self.stage_values for (r, c) in v}
        for r, (nodes, _, _, where) in enumerate(self.m.rigid_bodies):
            for k, v in enumerate(self.stage_values):
                if {c for (q, c) in v if q == r} != {c for (q, c) in prescribed if q == r}:
                    self.unsupported.append(f"{where}: a rigid body whose prescribed components change between steps "
                                            f"(a *BOUNDARY on its REF or ROT node added or removed after the first)")
                    break
            attach = []
            bodies = self.b.nodes_body(nodes)
            if self.shells is not None and self.shells.n:  # (a shell node: both its layers)
                bodies = np.where(bodies >= 0, bodies, self.shells.nodes_body(nodes))
            mine = (bodies >= 0) & ~np.isin(nodes, list(self.by_label))
            own = nodes[mine]
            for k in np.unique(bodies[mine]):
                set_name = f"_RB{r + 1}"
                node_sets[set_name] = own
                attach.append(ref(int(k), set_name))
            if not attach:
                raise DeckError(f"{where}: the rigid body holds no node of an element")
            origin = self.origins[r]
            idle = self.idle.get(r, [])
            free = [_NAMES[c] for c in range(6) if (r, c) not in prescribed and c not in idle]
            entry = {"name": self.names[r], "attach": attach, "reference": origin.tolist()}
            if r in self.components:
                entry["attach_components"] = [_NAMES[c] for c in self.components[r]]
            vals = [first_v.get((r, c), 0.0) for c in range(6)]
            if any(vals):
                entry["motion"] = {"translation": vals[:3], "rotation": vals[3:], "center": origin.tolist()}
            if free:
                entry["free"] = free
            loads = [first_l.get((r, c), 0.0) for c in range(6)]
            if r in self.knots and any((r, c) in v and v[(r, c)] for v in self.stage_loads for c in idle):
                self.notes.append(f"{where}: a drilling moment (about the normal) on shell node {self.knots[r][0]}: "
                                  f"dropped, as CalculiX drops it")
                loads = [0.0 if c in idle else v for c, v in enumerate(loads)]
            elif any((r, c) in v for v in self.stage_loads for c in idle):
                self.unsupported.append(f"{where}: a *CLOAD on a translation of the REF NODE that the *KINEMATIC "
                                        f"coupling's nodes do not follow (it moves nothing)")
                loads = [0.0 if c in idle else v for c, v in enumerate(loads)]
            bad = [c for v in self.stage_loads for (q, c) in v if q == r and (r, c) in prescribed]
            if bad:
                self.unsupported.append(f"{where}: a *CLOAD on the prescribed component {_NAMES[bad[0]]} of the rigid "
                                        f"body (on its REF or ROT node)")
            if any(loads[:3]):
                entry["force"] = loads[:3]
            if any(loads[3:]):
                entry["moment"] = loads[3:]
            out.append(entry)
        return out

    def labels(self) -> dict:
        """{body name: [REF label or None, ROT label or None]} for the .dat table."""
        return {name: [ref, rot] for name, (_, ref, rot, _) in zip(self.names, self.m.rigid_bodies)}
