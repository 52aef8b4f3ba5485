"""The conditions of a deck's shell nodes (docs/input.md, "*BOUNDARY on shell nodes"): how ``DeckShells`` maps
each shell node's *BOUNDARY onto the two layers of its solid-shells (CalculiX's gen3dboun), as the components both
layers take and the equations of their mean and of their line's direction."""

from __future__ import annotations

import numpy as np

from .deck import DeckError
from .deck_knots import _vec


class ShellConditions:
    """The boundary-condition part of ``covcontact.io.deck_shells.DeckShells`` (it reads and writes its m, bodies,
    plan, label_body, label_index, first, equation_nodes, sum_values, notes and _drilled, and calls is_shell)."""

    # -- boundary conditions --------------------------------------------------------------------------------------
    def plan_boundaries(self) -> None:
        """The mapping of every shell node's *BOUNDARY dofs (those of the model data and the first step, which hold
        over the run) onto its two layers, after CalculiX's gen3dboun (static steps, no knot):

        - a translation c of the shell node prescribes the mean of its expanded nodes (u_1 + u_3 = 2 u(n)): the mean
          of the bottom and top node, an equation u_b,c + u_t,c = 2 v whose right-hand side follows the deck's values
          over the steps (``sum_values``: its first stage's, the later ones as stage targets);
        - a rotation about a tangent axis a fixes the mean rotation of the line of expanded nodes about a; with both
          tangent rotations fixed (a clamp) the line keeps its direction: the tangential components of u_t - u_b
          vanish (exact at any rotation), its thickness change stays free as in CalculiX; the drilling rotation
          (an axis within 0.999 of the normal) is dropped, as CalculiX drops it;
        - a single tangent rotation is kept where it makes a symmetry plane: the shell's normal and the rotation axis
          along global axes and the translation normal to the plane fixed: then both layers hold that translation.

        Where the pair's component is held alike (a clamped or symmetric tangential component) both layers get the
        *BOUNDARY (any value, amplitudes, later steps); the rest are [[equation]]s holding from the first step on:
        the means with the deck's values, the rotations' differences at zero. Everything else is one line
        (DeckError)."""
        m = self.m
        first = list(m.model_boundary) + (list(m.steps[0].boundary) if m.steps else [])
        dofs: dict[int, set] = {}
        wh: dict[int, str] = {}
        nonzero: dict[tuple, str] = {}
        for b in first:
            shell = b.nodes[self.is_shell(b.nodes)]
            if shell.size and b.fixed:
                raise DeckError(f"{b.where}: *BOUNDARY, FIXED on shell node {int(shell[0])}: not supported on shells")
            for lab in shell.tolist():
                dofs.setdefault(lab, set()).update(b.dofs)
                wh.setdefault(lab, b.where)
                if b.value not in (None, 0.0):
                    for d in b.dofs:
                        nonzero.setdefault((lab, d), b.where)
        for lab, D in dofs.items():
            self.plan[lab] = self._classify(lab, D, wh[lab], nonzero)
        for st in m.steps[1:]:
            for b in st.boundary:
                for lab in b.nodes[self.is_shell(b.nodes)].tolist():
                    both, sums = self.plan.get(lab, (set(), []))[:2]
                    extra = [d for d in b.dofs if d > 3 or d - 1 not in both]
                    valued = [d for d in extra if d > 3 or d - 1 not in sums]  # (a mean takes any value)
                    if extra and (set(b.dofs) - dofs.get(lab, set()) or b.fixed
                                  or (valued and b.value not in (None, 0.0))):
                        raise DeckError(f"{b.where}: *BOUNDARY on dof {extra[0]} of shell node {lab} in a later step: "
                                        f"a shell node's rotations and the translations its two layers share through "
                                        f"an equation are held from the first step on (model data or the first step), "
                                        f"at zero")
            if st.boundary_new and any(self.plan[lab][1] or self.plan[lab][2] for lab in self.plan):
                raise DeckError(f"{st.where}: *BOUNDARY, OP=NEW in a step of a deck with shell nodes held through "
                                f"equations (their conditions hold over the whole run here)")

    def _classify(self, lab: int, D: set, where: str, nonzero: dict):
        body = self.bodies[self.label_body[lab] - self.first]
        d = body["d"][self.label_index[lab]]
        T = sorted(c - 1 for c in D if c <= 3)
        R = sorted(c - 4 for c in D if c >= 4)
        rot = [c for c in D if c >= 4 and (lab, c) in nonzero]
        if rot:
            raise DeckError(f"{nonzero[(lab, rot[0])]}: *BOUNDARY: a rotation (dof {rot[0]}) prescribed non-zero on "
                            f"shell node {lab}: not supported (a rotation of the line of its two layers)")
        drill = [r for r in R if abs(d[r]) > 0.999]
        if drill and where not in self._drilled:
            self._drilled.add(where)
            self.notes.append(f"{where}: *BOUNDARY: dof {drill[0] + 4} of shell node {lab} (and of the others there "
                              f"whose normal it is) is a drilling rotation (about the normal): dropped, as CalculiX "
                              f"drops it")
        R = [r for r in R if r not in drill]
        P = np.array([np.eye(3)[r] - d[r] * d for r in R]).reshape(-1, 3)
        rank = int(np.linalg.matrix_rank(P, tol=1e-6)) if R else 0
        k = int(np.argmax(np.abs(d))) if np.max(np.abs(d)) > 1.0 - 1e-9 else None
        both: set = set()
        sums: list = []
        diffs: list = []
        if rank == 2:
            if k is not None:
                for c in range(3):
                    if c == k:
                        continue
                    if c in T:
                        both.add(c)
                    else:
                        diffs.append(np.eye(3)[c])
                sums = [k] if k in T else []
            else:
                sums = list(T)
                e1 = P[0] / np.linalg.norm(P[0])
                e2 = np.cross(d, e1)
                diffs = [e1, e2]
        elif rank == 1:
            if k is None or len(R) != 1:
                raise DeckError(f"{where}: *BOUNDARY: rotation dof {R[0] + 4} of shell node {lab} alone (its other "
                                f"tangent rotation free) on a shell whose normal {_vec(d)} is no global axis: only "
                                f"symmetry planes (e.g. XSYMM: 1, 5, 6 on a flat shell) map exactly; not supported")
            i = 3 - k - R[0]
            if i not in T:
                raise DeckError(f"{where}: *BOUNDARY: rotation dof {R[0] + 4} of shell node {lab} without the "
                                f"translation {i + 1} normal to its symmetry plane: only symmetry planes (e.g. XSYMM: "
                                f"1, 5, 6 on a flat shell) map exactly; not supported")
            both.add(i)
            sums = [c for c in T if c != i]
        else:
            sums = list(T)
        for row in diffs:
            if np.count_nonzero(np.abs(row) > 1e-14) > 1 and any((lab, c + 1) in nonzero for c in T):
                raise DeckError(f"{where}: *BOUNDARY: non-zero values on shell node {lab} of a curved shell: not "
                                f"supported")
        if sums or diffs:
            self.equation_nodes.setdefault(int(self.label_body[lab]), set()).add(lab)
        return both, sums, diffs

    def boundary_split(self, labels: np.ndarray, dofs) -> tuple[np.ndarray, dict[int, np.ndarray]]:
        """(the labels that are no shell nodes, {component: the shell labels whose two layers both take it})."""
        shell = self.is_shell(labels)
        out = {}
        for d in dofs:
            if d <= 3:
                labs = [lab for lab in labels[shell].tolist() if d - 1 in self.plan.get(lab, (set(),))[0]]
                if labs:
                    out[d - 1] = np.asarray(labs, dtype=np.int64)
        return labels[~shell], out

    def equations(self, ref) -> list[dict]:
        """The [[equation]] entries of the plan (``ref(body, set)``: the set's reference in the problem file)."""
        out = []
        comps = "xyz"
        for lab, (_, sums, diffs) in sorted(self.plan.items()):
            body = int(self.label_body[lab])
            b, t = ref(body, f"_SN{lab}_b"), ref(body, f"_SN{lab}_t")
            for c in sums:
                value = self.sum_values.get((lab, c), 0.0)
                out.append({"name": f"shell{lab}_{comps[c]}", "terms": [[t, comps[c], 1.0], [b, comps[c], 1.0]]}
                           | ({"value": value} if value else {}))
            rows = [np.asarray(r, dtype=float) for r in diffs]
            if len(rows) == 2:  # (two rows, their dependents distinct: eliminated with pivoting)
                c1 = int(np.argmax(np.abs(rows[0])))
                rows[1] = rows[1] - rows[1][c1] / rows[0][c1] * rows[0]
            for j, r in enumerate(rows):
                c1 = int(np.argmax(np.abs(r)))
                terms = [[b, comps[c1], -float(r[c1])], [t, comps[c1], float(r[c1])]]
                terms += [[x, comps[c], s * float(r[c])] for c in range(3) if c != c1 and abs(r[c]) > 1e-14
                          for x, s in ((t, 1.0), (b, -1.0))]
                out.append({"name": f"shell{lab}_r{j + 1}", "terms": terms})
        return out

    def layer_sets(self, body: int) -> dict:
        """The single-node sets of the equations' nodes of shell body ``body`` (its ``sets`` table)."""
        info = self.bodies[body - self.first]
        out = {}
        for lab in sorted(self.equation_nodes.get(body, ())):
            i = int(self.label_index[lab])
            out[f"_SN{lab}_b"] = {"nodes": [i]}
            out[f"_SN{lab}_t"] = {"nodes": [i + info["n"]]}
        return out
