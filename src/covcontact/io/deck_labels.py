"""The labels file of an imported deck (NAME.nodes.json): what ``covcontact.io.deck_dat`` and ``covcontact.io.frd``
need to print the run in the deck's terms, written by the import's writer (``covcontact.io.deck_import``), whose
mixin this is."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .deck import DeckError
from .deck_planar import contact_print_labels


class DeckLabels:
    """The labels part of the import's writer (it reads the writer's m, b, shells, rigid, deck, out, body_names,
    element_labels, stage_steps, print_end, print_every and _plane_pairs, and adds to its notes)."""

    def _write_labels(self) -> Path:
        """NAME.nodes.json beside the problem: what the .dat table and the .frd file need of the deck (its node and
        element labels per body, the shells' layers, the print requests per stage and the sets and surfaces they
        name); its path."""
        labels = self.out.with_suffix(".nodes.json")
        per_body = {}
        for k, name in enumerate(self.body_names[: self.b.n]):
            per_body[name] = self.m.node_labels[self.b.of_node == k].tolist()
        shells = {}  # shell body -> (its surface nodes' deck labels, n): label i is mesh nodes i and i + n
        start = int(self.m.node_labels.max()) + 1 if self.m.node_labels.size else 1
        for j, (info, labs) in enumerate(zip(self.shells.bodies, self.shells.frd_labels(start))):
            per_body[self.body_names[self.b.n + j]] = labs.tolist()  # (the .frd's expanded nodes, numbered anew)
            shells[self.body_names[self.b.n + j]] = [info["nodes"].tolist(), info["n"]]
        # every stage of a deck step prints its requests: at the increments FREQUENCY picks and where a step or a
        # time point ends (print_every, print_end)
        # each request with its place among the step's print cards (CalculiX prints them in the order of its cards,
        # the ones carried over from earlier steps first), its totals, and the step's *SECTION PRINT surfaces
        order = self._print_order()
        prints = [[[nset, list(v), totals, order[w]] for nset, v, w, totals in self.m.steps[s].node_print]
                  for s, _ in self.stage_steps]
        el_prints = [[[elset, list(v), totals, order[w]] for elset, v, w, totals in self.m.steps[s].el_print]
                     for s, _ in self.stage_steps]
        for st in self.m.steps:  # (the solid-shells' strains are assumed ones, not Gauss-point gradients)
            for elset, v, w, _ in st.el_print:
                tri = self.shells.n and any(t in ("S3", "S6") and np.intersect1d(labs, self.m.elsets.get(elset, [])).size
                                            for t, _, labs, _ in self.m.shell_blocks)
                gone = list(v) if tri else [x for x in v if x in ("E", "ENER", "ELSE")]
                if gone and self.shells.n and np.any(self.shells.elements_body(self.m.elsets.get(elset, [])) >= 0):
                    note = (f"{w}: *EL PRINT {', '.join(gone)} on shell elements ({elset}): not printed for them (" + (
                        "S3 and S6 are each three solid-shells)" if tri else "the solid-shells' strains are assumed, "
                        "enhanced ones; S, PEEQ and EVOL are printed at their Gauss points)"))
                    if note not in self.notes:
                        self.notes.append(note)
        contact_prints = [list(self.m.steps[s].contact_print) for s, _ in self.stage_steps]
        printing = [self.m.steps[s].contact_card[0] for s, _ in self.stage_steps if self.m.steps[s].contact_print]
        contact = {name: (sb, sts) for name, (sb, sts, tied) in getattr(self, "_plane_pairs", {}).items()
                   if not tied}   # (tied pairs and *TIE: no contact elements, as in 3D)
        planar, left = contact_print_labels(self, contact) if printing else ({}, [])
        if left:  # (said, not left to an empty table)
            self.notes.append(f"{printing[0]}: *CONTACT PRINT: the pairs on planar elements ({', '.join(left)}: "
                              f"face-to-face, quadratic edges, or a deck with shells or beams) are not tabulated in "
                              f"the .dat; their gap and contact pressure are in the VTU output")
        contact_cards = [[self.m.steps[s].contact_card[1], order.get(self.m.steps[s].contact_card[0], 0)]
                         for s, _ in self.stage_steps]
        section_prints = [[[surf, name, list(v), order[w]] for surf, name, v, w in self.m.steps[s].section_print
                           if self._section_surface(surf, w)] for s, _ in self.stage_steps]
        wanted = {p[0] for per_step in prints for p in per_step}
        missing = sorted(wanted - set(self.m.nsets))
        if missing:
            raise DeckError(f"{self.deck}: *NODE PRINT names the node set {missing[0]!r}, which no *NSET defines")
        el_wanted = {p[0] for per_step in el_prints for p in per_step}
        missing = sorted(el_wanted - set(self.m.elsets))
        if missing:
            raise DeckError(f"{self.deck}: *EL PRINT names the element set {missing[0]!r}, which no *ELSET defines")
        labels.write_text(json.dumps({"bodies": per_body, "shells": shells, "node_print": prints,
                                      "rigid": self.rigid.labels(),
                                      "elements": self.element_labels, "el_print": el_prints,
                                      "contact_print": contact_prints, "contact_card": contact_cards,
                                      "contact_pairs": self._contact_pairs(), "planar_contact": planar,
                                      "section_print": section_prints,
                                      "surfaces": self._surface_faces(section_prints),
                                      "elsets": {k: self.m.elsets[k].tolist() for k in sorted(el_wanted)},
                                      "nsets": {k: self.m.nsets[k].tolist() for k in sorted(wanted)},
                                      "periods": [d for _, d in self.stage_steps],
                                      "deck_step": [k for k, _ in self.stage_steps],
                                      "print_end": self.print_end, "print_every": self.print_every}))
        return labels

    def _print_order(self) -> dict[str, int]:
        """The rank of every print card (by its "file:line") in the order of the deck."""
        wheres = {w for st in self.m.steps for w in [p[2] for p in st.node_print] + [p[2] for p in st.el_print]
                  + [p[3] for p in st.section_print] + ([st.contact_card[0]] if st.contact_card[0] else [])}

        def key(w: str):
            file, _, line = w.rpartition(":")
            return (file, int(line) if line.isdigit() else 0)

        return {w: k + 1 for k, w in enumerate(sorted(wheres, key=key))}

    def _section_surface(self, name: str, where: str) -> bool:
        """Whether *SECTION PRINT's surface is an element face surface (else a note: nothing printed, as CalculiX
        warns and prints nothing)."""
        kind = self.m.surfaces.get(name, (None,))[0]
        if kind is None:  # (CalculiX warns and prints nothing)
            self.notes.append(f"{where}: *SECTION PRINT names the surface {name!r}, which no *SURFACE defines: nothing "
                              f"printed (CalculiX warns likewise)")
            return False
        if kind != "ELEMENT":
            self.notes.append(f"{where}: *SECTION PRINT, SURFACE={name}: a node surface; section forces need element "
                              f"faces (nothing printed, as in CalculiX)")
            return False
        els = np.concatenate([e for e, _, _ in self.m.surfaces[name][1]] or [np.zeros(0, np.int64)])
        planar = sorted({t for t, _, labels, _ in self.m.blocks if t[:3] in ("CPE", "CPS", "CAX")
                         and np.isin(labels, els).any()})
        if planar:  # (CalculiX prints its expanded elements' section; covcontact tabulates 3D faces only)
            self.notes.append(f"{where}: *SECTION PRINT, SURFACE={name}: edges of planar elements ({', '.join(planar)}): "
                              f"not printed in the .dat (the reactions and contact forces are in covcontact's own "
                              f"results)")
            return False
        if name in self.m.shell_surfaces:  # (its faces are the solid-shells' faces of no deck element)
            self.notes.append(f"{where}: *SECTION PRINT, SURFACE={name}: faces of shell elements: not printed in the "
                              f".dat (the reactions and contact forces are in covcontact's own results)")
            return False
        return True

    def _contact_pairs(self) -> dict[str, str]:
        """The contact pairs the .dat's *CONTACT PRINT tabulates (those of *CONTACT PAIR: a *TIE is CalculiX's
        equations, no contact elements) by covcontact's pair name: "node" (slave nodes) or the deck's name of the
        element surface whose faces' integration points are the slaves (surface-to-surface)."""
        out = {}
        for k, (_, kind, slave, _, _) in enumerate(self.m.pairs):
            sts = kind == "SURFACE TO SURFACE" and self.m.surfaces[slave][0] == "ELEMENT"
            out[f"pair{k + 1}"] = slave if sts and f"pair{k + 1}" not in getattr(self, "_plane_pairs", ()) else "node"
        return out

    def _surface_faces(self, section_prints: list) -> dict[str, list[list[int]]]:
        """(element label, face number) of every face of the element surfaces the .dat needs: those of *SECTION PRINT
        and the slave surfaces of surface-to-surface pairs."""
        names = {p[0] for per_stage in section_prints for p in per_stage}
        names |= {v for v in self._contact_pairs().values() if v != "node"}
        return {name: [[int(e), int(face)] for els, face, _ in self.m.surfaces[name][1] for e in els]
                for name in sorted(names)}
