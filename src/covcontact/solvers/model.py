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
from .state import State


class Model:
    """Bodies, loads, Dirichlet conditions and contact of a problem, evaluated at a displacement u.

    ``tangent`` overrides the tangent case of every contact pair (None: each pair's own). Satisfies
    ``covcontact.protocols.ModelLike``; a serial model is rank 0 of 1.
    """

    is_root = True
    rank = 0
    size = 1

    def __init__(self, problem, tangent: str | None = None):
        self.problem = problem
        self.system = System(problem)
        self.tangent = tangent
        self.contact = ContactManager(problem, self.system, tangent)
        self.symmetric = self.contact.symmetric and all(b.solid.symmetric_tangent for b in self.system.blocks)
        blocks = [body.mesh.cells + blk.offset for blk, body in zip(self.system.blocks, problem.bodies)]
        self.coupling = CouplingPattern(self.system.n_nodes, blocks, pattern=self.system.pattern)

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
        return self.system.prescribed(lam)

    def eliminate(self, K):
        return self.system.eliminate(K)

    def positions(self, u: np.ndarray) -> np.ndarray:
        return self.system.X + u.reshape(-1, 3)

    def near_null_space(self) -> np.ndarray:
        """Rigid-body modes of the free dofs (zero rows on constrained dofs), for AMG preconditioners."""
        from .linear import rigid_body_modes

        return rigid_body_modes(self.system.X, self.system.constrained)

    # state ------------------------------------------------------------------------------------
    def initial_state(self) -> State:
        return State(self.system.new_state(), self.contact.initial_state())

    def begin_step(self) -> None:
        """A new Newton solve: contact searches start afresh (a cache, not state)."""
        self.contact.begin_step()

    def start_step(self, committed: State) -> State:
        """The trial a new load step starts from."""
        self.begin_step()
        return State(committed.elements, self.contact.start_step(committed.contact), committed.stage,
                     committed.step, committed.lam)

    def augment(self, trial: State) -> State | None:
        """One Uzawa update of the augmented-Lagrangian pairs: the new trial, or None when none is needed."""
        c = self.contact.augment(trial.contact)
        return None if c is None else State(trial.elements, c, trial.stage, trial.step, trial.lam)

    # evaluation -------------------------------------------------------------------------------
    def evaluate(self, u: np.ndarray, lam: float, committed: State, guess: State | None = None,
                 want_K: bool = True, timing: dict | None = None):
        """Residual R = f_int + f_contact - lam f_ext, its tangent (CSR or None) and the trial state.

        ``committed`` gives the history, ``guess`` (default ``committed``) the starting point of the local
        iterations (EAS parameters, contact points, Uzawa multipliers). Neither is changed.
        """
        guess = committed if guess is None else guess
        t0 = time.perf_counter()
        ev, ctrial = self.contact.evaluate(self.positions(u), lam, committed.contact, guess.contact, want_K)
        pattern, triples = self.coupling.covering(ev.blocks) if want_K else (None, [])
        t1 = time.perf_counter()
        r, K, etrial = self.system.internal(u, committed.elements, guess.elements, want_K, pattern)
        t2 = time.perf_counter()
        r += ev.blocks.residual()
        if want_K:
            CouplingPattern.scatter(K.data, pattern, triples)
        t3 = time.perf_counter()
        if timing is not None:
            timing["assembly"] += t2 - t1
            timing["contact"] += (t1 - t0) + (t3 - t2)
        return r - lam * self.f_ext, K, State(etrial, ctrial, committed.stage, committed.step, lam)

    # queries on a state -----------------------------------------------------------------------
    def active_count(self, state: State) -> int:
        return self.contact.active_count(state.contact)

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
