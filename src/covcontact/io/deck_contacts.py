"""A deck's contact pairs and ties as covcontact's ``[[contact]]`` entries (docs/input.md, "Abaqus and CalculiX
decks"): the part of :class:`covcontact.io.deck_import._Writer` that maps *CONTACT PAIR, *TIE, *SURFACE INTERACTION,
*SURFACE BEHAVIOR and *FRICTION, as a mixin of the writer (it reads the writer's model ``m``, parts ``b``, shells
and notes; pairs on planar elements go through :func:`covcontact.io.deck_planar.planar_contact`)."""

from __future__ import annotations

import numpy as np

from .deck import DeckError
from .deck_mesh import safe_name as _name
from .deck_model import Interaction
from .deck_planar import planar_contact
from .deck_toml import _table



def quadratic_edges(m, name: str) -> str | None:
    """Whether the shell surface ``name`` holds edges (S3..S6) of S8 or S8R elements: the side faces of their 18-node
    solid-shells have six nodes, each taken as its two 4-node halves (mesh.shell), which serve slave surfaces (nodes
    and their tributary areas). As a master they are exact where the edge is straight (its mid-side node on the chord
    of its corners: "straight", the halves then are the side face's two halves, their displacement linear along the
    edge where the element's is quadratic) and chords of a curved edge ("curved"); None: no such edges."""
    rows = m.shell_surfaces.get(name, [])
    eight = [(labs, c) for t, _, labs, c in m.shell_blocks if t in ("S8", "S8R")]
    out = None
    index = m.node_index()
    for els, side, _ in rows:
        if not side.startswith("EDGE"):
            continue
        k = int(side[4:]) - 1
        for labs, conn in eight:
            rows_here = conn[np.isin(labs, els)]
            if not rows_here.size:
                continue
            out = "straight"
            x = m.X[index[rows_here[:, [k, (k + 1) % 4, 4 + k]]]]   # (corner a, corner b, the mid-side node)
            chord = x[:, 1] - x[:, 0]
            off = np.cross(x[:, 2] - x[:, 0], chord)
            if np.any(np.linalg.norm(off, axis=1) > 1e-6 * np.einsum("ij,ij->i", chord, chord)):
                return "curved"
    return out


class ContactMapping:
    """The contact methods of the deck writer (``_contacts`` writes the entries; the others serve it and
    deck_planar)."""

    def _contacts(self) -> str:
        text = ""
        self._plane_pairs: dict[str, tuple] = {}  # (pairs on planar elements: slave body, face-to-face, tied)
        pairs = list(self.m.pairs) + [("*TIE", "TIE", slave, master, where) for _, slave, master, _, where in self.m.ties]
        ties = {where: tol for _, _, _, tol, where in self.m.ties}
        for k, (inter, kind, slave, master, where) in enumerate(pairs):
            it = Interaction("*TIE", behavior="tied") if kind == "TIE" else self.m.interactions.get(inter)
            if it is None:
                raise DeckError(f"{where}: *CONTACT PAIR names the interaction {inter!r}, which no *SURFACE "
                                f"INTERACTION defines")
            for s in (slave, master):
                if s not in self.m.surfaces:
                    raise DeckError(f"{where}: *CONTACT PAIR names the surface {s!r}, which no *SURFACE defines")
            mk, mrefs = self.m.surfaces[master]
            if mk != "ELEMENT":
                raise DeckError(f"{where}: the master surface {master} must be an element surface (faces)")
            if self._on_skipped([master, slave], where):
                continue
            edges = quadratic_edges(self.m, master)
            if edges == "curved":
                self.unsupported.append(f"{where}: the master surface {master} holds curved edges of S8/S8R elements: "
                                        f"the side faces of their solid-shells have six nodes, a facet type covcontact "
                                        f"has for slave surfaces only (swap slave and master, or use S4 elements "
                                        f"there); with --ignore-unsupported the pair is left out")
                continue
            if edges == "straight":
                self.notes.append(f"{where}: the master surface {master} holds straight edges of S8/S8R elements: "
                                  f"each side face of their solid-shells is its two 4-node halves, exact in the "
                                  f"reference configuration, the displacement along each half linear (the element's "
                                  f"is quadratic along the edge)")
            mb = self._surface_body(master, mrefs, where)
            sk, sref = self.m.surfaces[slave]
            sts = kind in ("SURFACE TO SURFACE", "TIE") and sk == "ELEMENT"
            if sk == "NODE":
                targets = self._node_targets(slave, sref, where)
                if not targets:  # (nodes of elements not read, e.g. shells: the pair cannot be built)
                    what = "elements covcontact does not read" if set(sref.tolist()) & self.m.skipped_nodes else \
                        "no element"
                    self.unsupported.append(f"{where}: the slave surface {slave}'s nodes belong to {what}; with "
                                            f"--ignore-unsupported the pair is left out")
                    continue
                if len(targets) > 1:
                    raise DeckError(f"{where}: the slave surface {slave} lies on several parts of the mesh")
                sb = targets[0][0]
                sname = targets[0][1]
            else:
                sb = self._surface_body(slave, sref, where)
                sname = _name(slave)
            entry: dict = {"name": f"pair{k + 1}", "slave": self._ref(sb, sname), "master": self._ref(mb, _name(master))}
            plane = planar_contact(self, sb, mb, kind, sk, it, where)  # (contact in the plane: deck_planar)
            if plane is False:
                continue
            if plane is not None:  # (node-to-segment: the .dat tabulates its slave nodes)
                text += _table("[[contact]]", entry | plane)
                self._plane_pairs[entry["name"]] = (sb, plane.get("type") == "sts", plane.get("law") == "tied")
                continue
            if sts:
                entry["type"] = "sts"
            else:  # faces: per tributary area; a node surface: per the node's area over its body's boundary faces
                entry["weighting"] = "boundary" if sk == "NODE" else "area"  # (CalculiX's spring area of such nodes)
            if kind == "TIE":  # *TIE: CalculiX writes equations; a stiff penalty tie here
                entry.update({"law": "tied", "penalty": "auto" if sk != "NODE" else self._hard_penalty(mb)})
                if sk == "NODE":
                    entry["weighting"] = "nodal"
                if ties.get(where):
                    entry["tie_tolerance"] = ties[where]
            elif it.behavior == "tied":
                if not self._tied_pair(entry, it, sts, where):
                    continue
            elif it.behavior == "linear":
                self._linear(entry, it, sts, where)
            elif it.behavior in ("exponential", "tabular"):
                entry.update(it.curve(self.dialect))
            elif sk == "NODE":  # hard contact, node slaves: augmented Lagrange with 10 E h per node
                entry.update({"penalty": self._hard_penalty(mb), "method": "augmented", "weighting": "nodal"})
            else:
                entry.update({"penalty": "auto", "method": "augmented"})
            adjust = self.m.pair_adjust.get(where)
            if adjust is not None and entry.get("law") != "tied":  # (a node set: its name in the slave body's mesh)
                entry["adjust"] = _name(adjust) if isinstance(adjust, str) else adjust
            if it.friction is not None and it.friction[0] > 0 and entry.get("law") != "tied":
                entry["friction"] = it.friction[0]
                if it.friction[1] is not None and it.friction[1] > 0:
                    entry["tangential_penalty"] = it.friction[1]
            text += _table("[[contact]]", entry)
        return text

    def _on_skipped(self, names: list[str], where: str) -> bool:
        """Whether one of the element surfaces ``names`` is empty or lies on elements not read (beams): then
        the pair is listed as unsupported (left out with --ignore-unsupported)."""
        for name in names:
            kind, refs = self.m.surfaces[name]
            if kind != "ELEMENT" or name in self.m.shell_surfaces:
                continue
            els = np.concatenate([e for e, _, _ in refs]) if refs else np.zeros(0, np.int64)
            gone = [int(e) for e in els if int(e) in self.m.skipped_elements]
            if gone or not els.size:
                what = f"element {gone[0]}, a {self.m.skipped_elements[gone[0]]} (not read), from " \
                    f"{self.m.skipped_card(gone[0])}" if gone else \
                    "no faces covcontact reads"
                self.unsupported.append(f"{where}: the surface {name} has {what}; with --ignore-unsupported the pair "
                                        f"is left out")
                return True
        return False

    def _first_modulus(self) -> float:
        """The first elastic constant of the first material in the deck (CalculiX's reference for its defaults)."""
        return next((mat.get("E", mat.get("E0")) for mat in self.m.materials.values() if "E" in mat or "E0" in mat),
                    0.0)

    def _linear(self, entry: dict, it: Interaction, sts: bool, where: str) -> None:
        """PRESSURE-OVERCLOSURE=LINEAR as CalculiX reads it: face-to-face pairs the linear penalty law with slope K
        (per area); node-to-face pairs K d (1/2 + atan(d / e) / pi) with e = pi sigma_inf / K, felt up to the
        clearance c0 sqrt(area) (law "arctan", its tension at clearances included). Missing or non-positive K, sigma_inf, c0 take CalculiX's defaults
        (50 E, E / 70000, 1e-3; E the deck's first elastic constant), each said in the notes."""
        K, sig, c0 = it.values
        E = self._first_modulus()
        if K <= 0.0:
            K = 50.0 * E
            self.notes.append(f"{it.where}: *SURFACE BEHAVIOR, LINEAR without a slope K: CalculiX's default 50 E = "
                              f"{K:g} is used")
        if sts:
            entry["penalty"] = K
            return
        if sig <= 0.0:
            sig = E / 70000.0
            self.notes.append(f"{it.where}: *SURFACE BEHAVIOR, LINEAR without sigma_inf: CalculiX's default E / "
                              f"70000 = {sig:g} is used")
        entry.update({"law": "arctan", "penalty": K, "tension": sig})
        if c0 > 0.0:
            entry["reach"] = c0

    def _tied_pair(self, entry: dict, it: Interaction, sts: bool, where: str) -> bool:
        """PRESSURE-OVERCLOSURE=TIED (face-to-face only in CalculiX): the slave faces bonded with the slope K per
        area in the normal direction and the stick slope of the *FRICTION card tangentially; covcontact's tie has
        one stiffness in all directions, so a stick slope other than K is refused (listed). Returns False when the
        pair is left out."""
        K = it.values[0] if it.values and it.values[0] > 0.0 else 50.0 * self._first_modulus()
        if not it.values or it.values[0] <= 0.0:
            self.notes.append(f"{it.where}: *SURFACE BEHAVIOR, TIED without a slope K: CalculiX's default 50 E = "
                              f"{K:g} is used")
        if not sts:
            self.unsupported.append(f"{where}: PRESSURE-OVERCLOSURE=TIED on a NODE TO SURFACE pair (CalculiX ties "
                                    f"face-to-face pairs only: TYPE=SURFACE TO SURFACE); with --ignore-unsupported "
                                    f"the pair is left out")
            return False
        lam = it.friction[1] if it.friction is not None else None
        if lam is None:
            self.unsupported.append(f"{it.where}: PRESSURE-OVERCLOSURE=TIED needs the stick slope of a *FRICTION card "
                                    f"(CalculiX stops without it); with --ignore-unsupported K is used tangentially")
        elif abs(lam - K) > 1e-9 * K:
            self.unsupported.append(f"{it.where}: PRESSURE-OVERCLOSURE=TIED with a stick slope ({lam:g}) other than "
                                    f"its slope K ({K:g}): covcontact's tie has one stiffness in all directions; with "
                                    f"--ignore-unsupported K is used tangentially too")
        entry.update({"law": "tied", "penalty": K})
        return True

    def _hard_penalty(self, body: int) -> float:
        """10 E h of the master body (its smallest Young's modulus, h its mean element size), a force per length."""
        labels = self.b.el_labels[self.b.of_element == body]
        mods = [self.m.materials[mat].get("E", self.m.materials[mat].get("E0", 0.0)) for s, mat, _ in self.m.sections
                if np.intersect1d(self.m.elsets.get(s, np.zeros(0, np.int64)), labels).size]
        X = self.m.X[self.b.of_node == body]
        h = float(np.prod(np.maximum(X.max(axis=0) - X.min(axis=0), 1e-300)) / max(labels.size, 1)) ** (1.0 / 3.0)
        return 10.0 * min(mods) * h

    def _surface_body(self, name: str, refs, where: str) -> int:
        parts = [self.b.elements_body(els) for els, _, _ in refs]
        parts += [self.shells.elements_body(els) for els, _, _ in self.m.shell_surfaces.get(name, [])]
        bodies = np.unique(np.concatenate(parts)) if parts else np.zeros(0, np.int64)
        if bodies.size != 1 or bodies[0] < 0:
            raise DeckError(f"{where}: the surface {name} must lie on one part of the mesh (found {bodies.size})")
        return int(bodies[0])
