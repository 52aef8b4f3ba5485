"""The Model: what Newton iterates on: the bodies' system plus the contact pairs."""

from __future__ import annotations

import time

import numpy as np

from ..assembly.system import System


class NoContact:
    """Stand-in for a problem without contact pairs."""

    symmetric = True

    def begin_step(self, x, lam):
        pass

    def evaluate(self, x, lam, want_K):
        return None, None

    def save_state(self):
        pass

    def restore_state(self):
        pass

    def commit(self):
        pass

    def active_count(self) -> int:
        return 0

    def step_report(self, x, lam) -> dict:
        return {}

    def point_data(self, n_nodes: int) -> dict:
        return {}


class Model:
    """Bodies, loads, Dirichlet conditions and contact of a problem, evaluated at a displacement u."""

    def __init__(self, problem, tangent: str = "a"):
        self.problem = problem
        self.system = System(problem)
        self.tangent = tangent
        if problem.contacts:
            from ..contact.manager import ContactManager

            self.contact = ContactManager(problem, self.system, tangent)
        else:
            self.contact = NoContact()
        self.symmetric = self.contact.symmetric

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

    # evaluation -------------------------------------------------------------------------------
    def evaluate(self, u: np.ndarray, lam: float, want_K: bool = True, timing: dict | None = None):
        """Residual R = f_int + f_contact - lam f_ext and its tangent (CSR or None)."""
        t0 = time.perf_counter()
        r, K = self.system.internal(u, want_K=want_K)
        t1 = time.perf_counter()
        rc, Kc = self.contact.evaluate(self.positions(u), lam, want_K)
        t2 = time.perf_counter()
        if timing is not None:
            timing["assembly"] += t1 - t0
            timing["contact"] += t2 - t1
        if rc is not None:
            r += rc
        if Kc is not None and K is not None:
            K = (K + Kc).tocsr()
        return r - lam * self.f_ext, K

    def begin_step(self, u: np.ndarray, lam: float) -> None:
        self.contact.begin_step(self.positions(u), lam)

    def save_state(self) -> None:
        self.system.save_state()
        self.contact.save_state()

    def restore_state(self) -> None:
        self.system.restore_state()
        self.contact.restore_state()

    def commit(self) -> None:
        self.system.commit()
        self.contact.commit()

    def active_count(self) -> int:
        return self.contact.active_count()

    def active_set_settled(self) -> bool:
        return True

    def augment(self) -> bool:
        """One Uzawa update of the augmented-Lagrangian pairs; True when another Newton solve is needed."""
        return bool(getattr(self.contact, "augment", lambda: False)())
