"""The state of a whole model: element history, contact history and the position in the load history.

One ``State`` is *committed* (the end of the last converged load step, what a checkpoint holds) and the
others are *trials* (what an evaluation produced). See docs/theory.md section 10.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..contact.state import ContactState


@dataclass
class State:
    """elements: per body, named arrays (solid-shells: ``alpha``, the EAS parameters per element);
    contact: the contact state of every pass; stage (0-based), step, lam: the stage, the step (1-based over
    the whole analysis, 0 before the first) that the state closes and its load factor within the stage;
    forces: the stage's released reactions ``release`` and the forces ``held`` from earlier stages, (n_dofs,)
    each, absent before a stage released anything (``covcontact.solvers.stages``)."""

    elements: list[dict[str, np.ndarray]]
    contact: ContactState
    stage: int = 0
    step: int = 0
    lam: float = 0.0
    forces: dict[str, np.ndarray] = field(default_factory=dict)
    #: a dynamic stage's kinematic state at the end of the step: ``u``, ``v``, ``a`` (n_dofs,) each and ``r``, the
    #: static residual there (the generalized-alpha mid-point uses it); ``time`` (the stage's time) and the energy
    #: account (``covcontact.solvers.dynamics``); empty in a quasi-static stage
    dynamics: dict[str, np.ndarray] = field(default_factory=dict)

    def copy(self) -> State:
        return State([{k: v.copy() for k, v in e.items()} for e in self.elements], self.contact.copy(),
                     self.stage, self.step, self.lam, {k: v.copy() for k, v in self.forces.items()},
                     {k: v.copy() for k, v in self.dynamics.items()})

    def but(self, **changes) -> State:
        """This state with some fields replaced (the arrays of the others shared, not copied)."""
        return replace(self, **changes)

    def arrays(self) -> dict[str, np.ndarray]:
        """Every array of the state under a flat name (for checkpoints)."""
        out = {f"elements.{b}.{k}": v for b, e in enumerate(self.elements) for k, v in e.items()}
        out.update(self.contact.arrays())
        out["step.stage"] = np.array(self.stage)
        out["step.step"] = np.array(self.step)
        out["step.lam"] = np.array(self.lam)
        out.update({f"forces.{k}": v for k, v in self.forces.items()})
        out.update({f"dynamics.{k}": v for k, v in self.dynamics.items()})
        return out

    @classmethod
    def from_arrays(cls, data, like: State) -> State:
        """The state stored by :meth:`arrays`, shaped like ``like`` (a model's initial state)."""
        elements = []
        for b, e in enumerate(like.elements):
            elements.append({k: np.array(data[f"elements.{b}.{k}"]) for k in e})
        for b, e in enumerate(like.elements):
            for k, v in e.items():
                if elements[b][k].shape != v.shape:
                    raise ValueError(f"elements.{b}.{k} has shape {elements[b][k].shape}, expected {v.shape}")
        contact = ContactState.from_arrays(data, len(like.contact.passes))
        for p, q in zip(contact.passes, like.contact.passes):
            if p.gap.shape != q.gap.shape:
                raise ValueError("the contact state does not match the problem's slave sets")
        forces = {k[len("forces."):]: np.array(data[k]) for k in data if k.startswith("forces.")}
        dynamics = {k[len("dynamics."):]: np.array(data[k]) for k in data if k.startswith("dynamics.")}
        return cls(elements, contact, int(data["step.stage"]), int(data["step.step"]), float(data["step.lam"]),
                   forces, dynamics)
