"""The interfaces between the layers, as typing Protocols (what Newton and the run loop rely on).

The serial and the distributed implementations satisfy them: :class:`covcontact.solvers.model.Model` and
``covcontact.parallel.model.DistributedModel`` are ``ModelLike``; ``ContactManager`` and its distributed
subclass are ``ContactLayer``; every element body is a ``BodyKernel``. States follow docs/theory.md
section 10.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from .contact.manager import ContactEvaluation
from .contact.state import ContactState
from .solvers.state import State


class BodyKernel(Protocol):
    """One deformable body's elements."""

    def new_state(self) -> dict[str, np.ndarray]: ...

    def assemble(self, u: np.ndarray, data: np.ndarray, rhs: np.ndarray, pattern: Any, node_offset: int = 0,
                 want_K: bool = True, state: dict | None = None) -> int: ...

    def energy(self, u: np.ndarray, state: dict | None = None) -> float: ...

    def stress(self, u: np.ndarray, state: dict | None = None) -> Any: ...


class ContactLayer(Protocol):
    """The contact pairs of a problem (no pairs: a manager with no passes)."""

    symmetric: bool
    timing: dict[str, float]

    def initial_state(self) -> ContactState: ...

    def begin_step(self) -> None: ...

    def start_step(self, committed: ContactState) -> ContactState: ...

    def evaluate(self, x: np.ndarray, lam: float, committed: ContactState, guess: ContactState | None = None,
                 want_K: bool = True, case: int | None = None,
                 want_parts: bool = False) -> tuple[ContactEvaluation, ContactState]: ...

    def augment(self, trial: ContactState) -> ContactState | None: ...

    def active_count(self, state: ContactState) -> int: ...

    def step_report(self, x: np.ndarray, lam: float, state: ContactState) -> dict: ...

    def point_data(self, n_nodes: int, state: ContactState) -> dict: ...

    def node_fields(self, state: ContactState) -> tuple: ...


class ModelLike(Protocol):
    """What Newton iterates on."""

    symmetric: bool
    is_root: bool
    rank: int
    size: int

    @property
    def free(self) -> np.ndarray: ...

    @property
    def f_ext(self) -> np.ndarray: ...

    @property
    def n_dofs(self) -> int: ...

    def prescribed(self, lam: float) -> np.ndarray: ...

    def external(self, lam: float) -> np.ndarray: ...

    def applied(self, u: np.ndarray, lam: float) -> np.ndarray: ...

    def set_stage(self, state: State) -> None: ...

    def enter_stage(self, u: np.ndarray, committed: State) -> State: ...

    def eliminate(self, K: Any) -> Any: ...

    def near_null_space(self) -> np.ndarray: ...

    def initial_state(self) -> State: ...

    def begin_step(self) -> None: ...

    def start_step(self, committed: State) -> State: ...

    def augment(self, trial: State) -> State | None: ...

    def evaluate(self, u: np.ndarray, lam: float, committed: State, guess: State | None = None,
                 want_K: bool = True, timing: dict | None = None) -> tuple[np.ndarray, Any, State]: ...

    def active_count(self, state: State) -> int: ...

    def step_report(self, u: np.ndarray, lam: float, state: State) -> dict: ...

    def partition_report(self) -> dict | None: ...
