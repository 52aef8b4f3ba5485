"""The Model: what Newton iterates on: the bodies' system plus the contact pairs.

``Model.evaluate(u, lam, committed, guess)`` returns the residual, the tangent and a trial state and
changes nothing it is given (docs/theory.md section 10).
"""

from __future__ import annotations

import time

import numpy as np

from ..assembly.system import System
from ..contact.assembly import CouplingPattern
from ..contact.manager import ContactManager
from ..contact.setup import ContactSetupError
from ..io.validate import InputError
from ..elements.follower import follower_set
from ..elements.springs import add_blocks, spring_set
from .stages import Loading, StagePlan
from .state import State


def adjust_once(problem) -> None:
    """Move the slave nodes of the pairs with ``adjust`` onto their masters, once per problem (every model of it, and
    every rank of a distributed run, then sees the same meshes); ``problem.adjusted`` keeps what was done."""
    if getattr(problem, "adjusted", None) is None:
        from ..contact.adjust import adjust_slaves

        problem.adjusted = adjust_slaves(problem)


class Model:
    """Bodies, loads, Dirichlet conditions and contact of a problem, evaluated at a displacement u.

    ``tangent`` overrides the tangent case of every contact pair (None: each pair's own). Satisfies
    ``covcontact.protocols.ModelLike``; a serial model is rank 0 of 1.
    """

    is_root = True
    rank = 0
    size = 1

    #: multi-point constraints (``covcontact.solvers.constraints``: linear equations, rigid links), None without
    constraints = None
    #: follower pressures (``covcontact.elements.follower.FollowerSet``), None without
    followers = None

    def __init__(self, problem, tangent: str | None = None):
        self.problem = problem
        adjust_once(problem)
        self.system = System(problem.bodies, problem.rigid, problem.loads, problem.dirichlet)
        self._constraint_sets: dict = {}
        self._rigid_links = None
        self._mpcs = None
        self.tangent = tangent
        try:
            self.contact = ContactManager(problem, self.system, tangent)
        except ContactSetupError as exc:  # (a tie whose surfaces do not meet: the input's)
            raise InputError(f"{problem.source or 'the problem'}: {exc}") from None
        self.symmetric = self.contact.symmetric and all(b.solid.symmetric_tangent for b in self.system.blocks)
        blocks = [b.cells + blk.offset for blk, body in zip(self.system.blocks, problem.bodies) for b in body.mesh.blocks]
        #: springs and dashpots (``covcontact.elements.springs``), None without: element blocks beside the bodies'
        self.springs = spring_set(problem, self.system)
        if self.springs is not None:  # (their node pairs join the bodies' pattern)
            from ..assembly.pattern import Pattern

            pairs = [np.array([[ref.A, ref.B] for ref in self.system.reference])] if self.system.reference else []
            blocks = blocks + pairs + self.springs.couplings()
            self.system.pattern = Pattern(self.system.n_nodes, blocks)
            self.symmetric = self.symmetric and self.springs.symmetric
        self.coupling = CouplingPattern(self.system.n_nodes, blocks, pattern=self.system.pattern)
        self.stages = StagePlan(problem, self.system)
        #: follower pressures (``covcontact.elements.follower``), None without: blocks on the bodies' faces
        self.followers = follower_set(self.stages, self.system)
        if self.followers is not None:
            self.symmetric = False  # (the load stiffness of a pressure on an open surface is not symmetric)
        self.constraints = self._constraints(problem)
        if self.constraints is not None and not self.constraints.symmetric:
            self.symmetric = False  # (attached nodes: the rotation's second-order part is not symmetric)
        self.set_stage(State([], None))

    def _constraints(self, problem, stage: int = 0):
        """The multi-point constraints of a stage: nodes attached to rigid bodies, nonlinear MPCs and linear
        equations (those no stage up to it removed), chained in that order where there are several, or None; built
        once per set of equations."""
        from .constraints import ChainedConstraints, LinearConstraints, RigidLinks
        from .mpc import NonlinearMPCs

        if self._rigid_links is None and any(r.attached.size for r in self.system.reference):
            self._rigid_links = RigidLinks(self.system)
        if self._mpcs is None and getattr(problem, "mpcs", None):
            self._mpcs = NonlinearMPCs(problem.mpcs, self.system)
        removed = frozenset(n for st in list(getattr(problem, "stages", []))[:stage] for n in st.remove)
        if removed not in self._constraint_sets:
            kept = [(i, e) for i, e in enumerate(getattr(problem, "equations", None) or [])
                    if not (e.name and e.name in removed)]
            linear = LinearConstraints([e for _, e in kept], self.system, [i for i, _ in kept]) if kept else None
            layers = [c for c in (self._rigid_links, self._mpcs, linear) if c is not None]
            self._constraint_sets[removed] = (ChainedConstraints(*layers) if len(layers) > 1
                                              else layers[0] if layers else None)
        return self._constraint_sets[removed]

    # stages -----------------------------------------------------------------------------------
    def set_stage(self, state: State) -> None:
        """Prescribe what ``state``'s stage prescribes (after a stage change or a resume)."""
        spec = self.stages[state.stage]
        self.loading = Loading(spec, self.system.X, state.forces.get("release"), state.forces.get("held"),
                               state.forces.get("parked"), state.forces.get("applied"))
        if getattr(self.problem, "equations", None):  # (equations a stage removes hold no more from its start)
            self.constraints = self._constraints(self.problem, state.stage)
        held = spec.constrained if self.constraints is None else spec.constrained | self.constraints.mask
        self.system.set_constraints(held)
        self.contact.set_stage(spec.motions, spec.contacts, spec.friction)

    def enter_stage(self, u: np.ndarray, committed: State) -> State:
        """The committed state at the start of the next stage, which is then prescribed: the reactions of
        the conditions it releases become forces, pairs switched off lose their history."""
        spec = self.stages[committed.stage + 1]
        forces = {}
        held = self.loading.left_over()
        if spec.released.size or np.any(held) or spec.released_pairs:
            release = np.zeros(self.n_dofs)
            if spec.released.size:
                R, _, _ = self.evaluate(u, committed.lam, committed, want_K=False)
                release[spec.released] = R[spec.released]
            if spec.released_pairs:  # the pairs' forces on the bodies become loads ramped to zero
                r_pairs = self._pair_residual(u, committed, spec.released_pairs)
                r_pairs[spec.constrained] = 0.0
                release -= r_pairs
            forces = {"release": release, "held": held}
        if spec.parked.size:  # free rigid bodies without an active pair stay where they are
            parked = np.zeros(self.n_dofs)
            parked[spec.parked] = u[spec.parked]
            forces["parked"] = parked
        applied = committed.forces.get("applied")
        if spec.applied_names or (applied is not None and any(c.from_state for c in spec.conditions)):
            applied = np.zeros(self.n_dofs) if applied is None else applied.copy()
            for c in spec.conditions:  # conditions that start now: from the displacement their dofs have
                if c.name in spec.applied_names:
                    applied[c.dofs] = u[c.dofs]
            forces["applied"] = applied
        new = committed.but(stage=committed.stage + 1, lam=0.0, forces=forces)
        self.set_stage(new)
        return new.but(contact=self.contact.switch(new.contact))

    def _pair_residual(self, u: np.ndarray, committed: State, names: tuple[str, ...]) -> np.ndarray:
        """The contact residual of the named pairs alone at ``u`` (the current stage's motions), on the
        system's dofs."""
        ev, _ = self.contact.evaluate(self.positions(u), committed.lam, committed.contact, None, False,
                                      pairs=names)
        return ev.blocks.residual()

    # delegation -------------------------------------------------------------------------------
    @property
    def free(self) -> np.ndarray:
        return self.system.free

    @property
    def f_ext(self) -> np.ndarray:
        return self.system.f_ext

    @property
    def n_dofs(self) -> int:
        return self.system.n_dofs

    def prescribed(self, lam: float) -> np.ndarray:
        """Displacements on the constrained dofs at load factor lam of the current stage (0 elsewhere)."""
        return self.loading.prescribed(lam)

    def external(self, lam: float) -> np.ndarray:
        """External forces at load factor lam of the current stage (and the weight, in full at every lam)."""
        f = self.loading.external(lam)
        return f + self.weight if self.weight is not None else f

    def applied(self, u: np.ndarray, lam: float) -> np.ndarray:
        """All external forces at displacement u and load factor lam: ``external(lam)`` and the follower pressures'
        forces on the current faces."""
        f = self.external(lam)
        if self.followers is not None:
            f = f + self.followers.force(self.positions(u), self.loading.follower_values(lam))
        return f

    @property
    def weight(self) -> np.ndarray | None:
        """The bodies' weight under ``problem.gravity``: int rho N_a g dV0 = M (g at every node), None without
        gravity."""
        g = getattr(self.problem, "gravity", None)
        if g is None:
            return None
        if getattr(self, "_weight", None) is None:
            self._weight = self.system.mass() @ np.tile(np.asarray(g, dtype=float), self.system.n_nodes)
        return self._weight

    def eliminate(self, K):
        return self.system.eliminate(K)

    def positions(self, u: np.ndarray) -> np.ndarray:
        return self.system.X + u.reshape(-1, 3)

    def near_null_space(self) -> np.ndarray:
        """Rigid-body modes of the free dofs (zero rows on constrained dofs), for AMG preconditioners."""
        from .linear import rigid_body_modes

        return rigid_body_modes(self.system.X, self.system.constrained)

    # checkpoints ------------------------------------------------------------------------------
    def checkpoint(self) -> tuple[dict, dict]:
        """The model's part of a checkpoint: the contact couplings met so far (the tangent's sparsity pattern,
        which a resumed run rebuilds alike)."""
        coupling = getattr(self, "coupling", None)
        return (coupling.arrays() if coupling is not None else {}), {}

    def restore(self, arrays: dict, meta: dict) -> None:
        coupling = getattr(self, "coupling", None)
        if coupling is not None:
            coupling.restore({k: v for k, v in arrays.items() if k.startswith("coupling.")})

    # state ------------------------------------------------------------------------------------
    def initial_state(self) -> State:
        return State(self.system.new_state(), self.contact.initial_state())

    def begin_step(self) -> None:
        """A new Newton solve: contact searches start afresh (a cache, not state)."""
        self.contact.begin_step()

    def start_step(self, committed: State) -> State:
        """The trial a new load step starts from."""
        self.begin_step()
        return committed.but(contact=self.contact.start_step(committed.contact))

    def augment(self, trial: State) -> State | None:
        """One Uzawa update of the augmented-Lagrangian pairs: the new trial, or None when none is needed."""
        c = self.contact.augment(trial.contact)
        return None if c is None else trial.but(contact=c)

    # evaluation -------------------------------------------------------------------------------
    def evaluate(self, u: np.ndarray, lam: float, committed: State, guess: State | None = None,
                 want_K: bool = True, timing: dict | None = None, raw: bool = False, check: bool = True):
        """Residual R = f_int + f_contact - f_ext(lam), its tangent (CSR or None) and the trial state.

        ``committed`` gives the history, ``guess`` (default ``committed``) the starting point of the local
        iterations (EAS parameters, contact points, Uzawa multipliers). Neither is changed. With multi-point
        constraints the residual and tangent are those of the independent dofs (``constraints.transform``), unless
        ``raw``: then R at every dof (the nodal forces before the constraints hand them over). ``check``: the
        tangent must restrain every free dof of a rigid body (SingularMatrixError naming the body otherwise).
        """
        guess = committed if guess is None else guess
        t0 = time.perf_counter()
        if self.constraints is not None:  # (the dependent dofs follow the others: u is set in place)
            if self.stages.equation_values:  # (equations with right-hand sides: theirs at lam)
                self.constraints.set_rhs(self.loading.equation_rhs(lam))
            self.constraints.complete(u)
        x = self.positions(u)
        ev, ctrial = self.contact.evaluate(x, lam, committed.contact, guess.contact, want_K)
        if self.system.reference:
            self._rigid_loads(ev.blocks, x, lam, want_K)
        pattern, triples = self.coupling.covering(ev.blocks) if want_K else (None, [])
        t1 = time.perf_counter()
        r, K, etrial = self.system.internal(u, committed.elements, guess.elements, want_K, pattern)
        t2 = time.perf_counter()
        rc = ev.blocks.residual()
        r += rc
        #: the contact forces' share of the last residual (the dynamic energy account reads it)
        self.last_contact_residual = rc
        if want_K:
            CouplingPattern.scatter(K.data, pattern, triples)
        if self.springs is not None:
            add_blocks(self.springs.spring_blocks(x, u.reshape(-1, 3), want_K), r, K, pattern)
        if self.followers is not None:
            add_blocks(self.followers.blocks(x, self.loading.follower_values(lam), want_K), r, K, pattern)
        t3 = time.perf_counter()
        if timing is not None:
            timing["assembly"] += t2 - t1
            timing["contact"] += (t1 - t0) + (t3 - t2)
        r = r - self.external(lam)
        if self.constraints is not None and not raw:
            r, K = self.constraints.transform(r, K)
        if check and want_K and self.system.reference and (self.constraints is None or not raw):
            self._check_restrained(K)
        return r, K, committed.but(elements=etrial, contact=ctrial, lam=lam)

    # rigid bodies with a reference node ------------------------------------------------------------
    def _rigid_loads(self, blocks, x: np.ndarray, lam: float, want_K: bool) -> None:
        from ..contact.reference import load_block

        for ref in self.system.reference:
            force, moment = self.loading.rigid_load(ref.name, lam)
            if np.any(force) or np.any(moment):
                blocks.add(*load_block(ref, ref.pose(x), force, moment, want_K))

    def _check_restrained(self, K) -> None:
        """A free component of a reference body with no stiffness at all: a clear message (and a cutback)
        instead of a singular matrix."""
        from .linear import SingularMatrixError

        diag = K.diagonal()
        names = ("x", "y", "z", "rx", "ry", "rz")
        for ref in self.system.reference:
            for c in ref.free:
                dof = 3 * (ref.A if c < 3 else ref.B) + c % 3
                if diag[dof] == 0.0 and self.system.free[dof]:
                    raise SingularMatrixError(
                        f"rigid body {ref.name!r} is free in {names[c]} but nothing restrains it there (no "
                        f"active contact); start it touching its partner or prescribe that component until "
                        f"it touches")

    def rigid_report(self, u: np.ndarray, lam: float, state: State) -> dict:
        """Per reference body: displacement, rotation vector, applied force and moment, and the contact
        resultant (force and moment about the reference point) acting on it; with attached nodes also their
        resultant on it (``attached_force``, ``attached_moment``)."""
        if not self.system.reference:
            return {}
        from ..contact.reference import tangent_map

        x = self.positions(u)
        ev, _ = self.contact.evaluate(x, lam, state.contact, want_K=False)
        r = ev.blocks.residual().reshape(-1, 3)
        out = {}
        for ref in self.system.reference:
            force, moment = self.loading.rigid_load(ref.name, lam)
            theta = x[ref.B]
            # the contact residual on (A, B) is -(force, T^T moment) on the body
            contact_moment = -np.linalg.solve(tangent_map(theta).T, r[ref.B])
            out[ref.name] = {"displacement": (x[ref.A] - ref.origin).tolist(),
                             "rotation": theta.tolist(),
                             "applied_force": force.tolist(), "applied_moment": moment.tolist(),
                             "contact_force": (-r[ref.A]).tolist(), "contact_moment": contact_moment.tolist()}
        if any(ref.attached.size for ref in self.system.reference):
            # the attached nodes' pull: each node's residual R_i is the force the body applies to it
            R = self.evaluate(u.copy(), lam, state, want_K=False, raw=True)[0].reshape(-1, 3)
            for ref in self.system.reference:
                if ref.attached.size:
                    f = np.zeros((ref.attached.size, 3))
                    comps = list(ref.attached_components)  # (the components the body holds)
                    f[:, comps] = R[ref.attached][:, comps]
                    ry = x[ref.attached] - x[ref.A]
                    out[ref.name]["attached_force"] = (-f.sum(axis=0)).tolist()
                    out[ref.name]["attached_moment"] = (-np.cross(ry, f).sum(axis=0)).tolist()
        return out

    def start_warnings(self, u: np.ndarray, state: State) -> list[str]:
        """Warnings about the start of a run that is legal but almost certainly wrong: materials whose Young's
        modulus and yield stress look like mixed units; slave nodes inside their master (contact/report.py)."""
        out = self._material_warnings() + list(getattr(self.problem, "adjusted", None) or [])
        for body in self.problem.bodies:  # (shell bodies whose mid-surface folds sharply: mesh/shell.py)
            creases = getattr(body.mesh, "shell_creases", None)
            if creases:
                a, b, node, angle = max(creases, key=lambda c: c[3])
                out.append(f"body {body.name!r}: its mid-surface's cells meet at {len(creases)} node(s) at more than "
                           f"45 degrees (up to {angle:.0f}: node {node} (0-based) between cells {a} and {b}), a junction "
                           f"or a crease, where the solid-shells take the mean director of the cells around the node "
                           f"and so bend it: split the surface there (bodies tied along the edge) or mesh the junction "
                           f"with solid elements")
        if not self.contact.passes or self.size > 1:
            return out
        from ..contact.report import start_warnings

        names = {}
        for pair in self.problem.contacts:
            rb = next((r for r in self.problem.rigid if r.name == pair.master[0] and r.mesh is None), None)
            if rb is not None:
                extra = f" (outside = {str(rb.params['outside']).lower()})" if "outside" in rb.params else ""
                names[pair.name] = f"the analytic {rb.shape} {rb.name!r}{extra}"
            else:
                names[pair.name] = f"the faces {pair.master[0]}.{pair.master[1]}"
        return out + start_warnings(self.contact, self.positions(u), state.contact, names)

    def _material_warnings(self) -> list[str]:
        """E / sigma_y0 of every plastic body against the range of engineering metals and polymers (about 20
        to 1e4): outside 10..1e5 the two were most likely given in different units (GPa and MPa, Pa and MPa)."""
        from ..materials.plasticity import J2

        out = []
        for body, blk in zip(self.problem.bodies, self.system.blocks):
            mat = blk.solid.material
            if mat.kind != J2:
                continue
            E, sy = float(mat.params[0]), float(mat.params[6])  # Young's modulus, initial yield stress
            ratio = E / sy if sy > 0.0 else np.inf
            if not 10.0 <= ratio <= 1e5:
                out.append(f"body {body.name!r}: Young's modulus E = {E:g} is {ratio:.3g} times the initial yield "
                           f"stress {sy:g}; metals and polymers lie between about 20 and 1e4: are E and the yield "
                           f"stress in the same units (MPa and GPa, Pa and MPa)?")
        return out

    # queries on a state -----------------------------------------------------------------------
    def active_count(self, state: State) -> int:
        return self.contact.active_count(state.contact)

    def floating_dofs(self) -> np.ndarray | None:
        """The dofs of the deformable bodies whose Dirichlet conditions (in the current stage) leave a rigid-body
        mode free, so that only contact holds them; None when there is none (or in a distributed run)."""
        if self.size > 1:
            return None
        from .nullspace import rigid_body_modes

        free = self.system.free
        mask = np.zeros(self.system.n_dofs, dtype=bool)
        for blk in self.system.blocks:
            dofs = np.arange(3 * blk.offset, 3 * (blk.offset + blk.n_nodes))
            fixed = ~free[dofs]
            modes = rigid_body_modes(self.system.X[blk.offset: blk.offset + blk.n_nodes])
            if np.linalg.matrix_rank(modes[fixed], tol=1e-8) < 6:
                mask[dofs] = True
        return mask if mask.any() else None

    def explain_inversion(self, body: str, element: int) -> str:
        """Where element ``element`` of ``body`` lies, and the contact pairs whose slave nodes it carries (an
        element that inverts next to a contact is most often crushed by it: a penalty too soft or too stiff,
        an increment too large, a tool that cuts in at a sharp corner)."""
        blk = next((b for b in self.system.blocks if b.name == body), None)
        if self.size > 1 or blk is None or not hasattr(blk.solid, "element_nodes"):  # (a rank holds part of it)
            return ""
        nodes = blk.solid.element_nodes([element]) + blk.offset
        X = self.system.X[nodes].mean(axis=0)
        pairs = sorted({p.pair for p in self.contact.passes if np.intersect1d(p.slaves, nodes).size})
        where = f" (centre at {X[0]:.4g}, {X[1]:.4g}, {X[2]:.4g})"
        names = ", ".join(repr(p) for p in pairs)
        return where + (f", on the slave side of contact pair{'s' if len(pairs) > 1 else ''} {names}" if pairs else "")

    def drive(self, lam: float) -> list[np.ndarray]:
        """What drives the current stage at load factor ``lam``, per kind: the prescribed displacements, the
        external forces and the rigid bodies' motions (each applied to four points); the extrapolating
        predictor compares their increments to notice a turn of the loading."""
        pts = np.vstack([np.zeros(3), np.eye(3)])
        motions = [np.ravel(m.apply(pts, lam)) for m in self.contact.num.motions.values()]
        return [self.prescribed(lam), self.external(lam), np.concatenate(motions) if motions else np.zeros(0)]

    def plastic_change(self, a: State, b: State) -> tuple[int, int]:
        """(Gauss points whose yielding in the step differs between ``a`` and ``b``, Gauss points yielding in
        the step of ``b``): how much the plastic zone moved; (0, 0) without a plastic body."""
        from ..materials.plasticity import H_FLAG, J2

        changed = yielding = 0
        for blk, ea, eb in zip(self.system.blocks, a.elements, b.elements):
            ha, hb = ea.get("hist"), eb.get("hist")
            if hb is None or hb.shape[-1] <= H_FLAG or blk.solid.material.kind != J2:
                continue
            fa, fb = ha[..., H_FLAG] > 0, hb[..., H_FLAG] > 0
            changed += int(np.count_nonzero(fa != fb))
            yielding += int(np.count_nonzero(fb))
        return changed, yielding

    def active_set_change(self, a: State, b: State) -> tuple[int, int]:
        """(slave nodes whose contact opened or closed from ``a`` to ``b``, slave nodes in contact in ``b``),
        over all ranks of a distributed run."""
        return self.contact.opened_closed(a.contact, b.contact), self.contact.active_count(b.contact)

    def contact_codes(self, state: State) -> np.ndarray:
        """The contact status of every slave node of every pass in ``state``: 0 open, 1 closed (stick), 2
        slip; the changes from one Newton iteration to the next measure how much the active set moves."""
        out = [np.where(self.contact.active_mask(k, state.contact), np.where(p.status == 2, 2, 1), 0)
               for k, p in enumerate(state.contact.passes)]
        return np.concatenate(out) if out else np.zeros(0, np.int64)

    def plastic_work(self, state: State) -> float | None:
        """Plastic work of all bodies in ``state``; None when no body has a plastic material."""
        from ..materials.plasticity import J2

        if not any(b.solid.material.kind == J2 for b in self.system.blocks):
            return None
        return sum(b.solid.plastic_work(e) for b, e in zip(self.system.blocks, state.elements))

    def partition_report(self) -> dict | None:
        """Elements and dofs per rank of a distributed model; None for a serial one."""
        return None

    def step_report(self, u: np.ndarray, lam: float, state: State) -> dict:
        return self.contact.step_report(self.positions(u), lam, state.contact) if self.contact.passes else {}
