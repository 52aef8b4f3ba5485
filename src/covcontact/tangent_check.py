"""``covcontact check-tangent``: the assembled tangent against central finite differences of the residual."""

from __future__ import annotations

import copy
import tempfile

import numpy as np

from .problem import OutputOptions, Steps
from .solvers.model import Model
from .solvers.newton import Newton


def fd_columns(model, u: np.ndarray, lam: float, cols: np.ndarray, h: float, committed, guess) -> np.ndarray:
    """Central differences of the assembled residual R(u) for the given dof columns: (n_dofs, len(cols))."""
    out = np.zeros((model.n_dofs, len(cols)))
    for j, c in enumerate(cols):
        up = u.copy()
        up[c] += h
        rp, _, _ = model.evaluate(up, lam, committed, guess, want_K=False)
        um = u.copy()
        um[c] -= h
        rm, _, _ = model.evaluate(um, lam, committed, guess, want_K=False)
        out[:, j] = (rp - rm) / (2 * h)
    return out


def check_tangent(problem, step: int = 1, tangent: str = "exact", columns: int = 60, seed: int = 0) -> dict:
    """Solve up to ``step`` and compare the tangent with finite differences at the converged state.

    Columns are all free dofs when there are at most ``columns`` of them, else the free dofs of contact
    nodes first, then a random sample. Returns relative_error (Frobenius norm over free rows and the chosen
    columns), the number of columns and the step.
    """
    prob = copy.copy(problem)
    factors = problem.steps.factors
    prob.output = OutputOptions(vtu=False)
    if step >= 2:
        prob.steps = Steps(factors[: step - 1])
        with tempfile.TemporaryDirectory() as tmp:
            res = prob.run(out=tmp, tangent=tangent, quiet=True)
        model, u, committed = res.model, res.u, res.state
        converged = bool(res.summary["converged"])
        lam_a = factors[step - 2]
    else:
        model = Model(prob, tangent=tangent)
        u = model.prescribed(0.0)
        committed = model.initial_state()
        converged, lam_a = True, 0.0
    lam = factors[step - 1] if step > 0 else 0.0
    guess = model.start_step(committed)
    if step > 0:
        # the last step is solved without committing it, so path-dependent laws (friction) are checked
        # against the history of the previous step, as Newton sees them
        newton = Newton(model, prob.solver)
        out, trial = newton.step(u, lam_a, lam, committed)
        converged = converged and out.converged
        guess = trial if trial is not None else guess
    model.begin_step()
    R, K, trial = model.evaluate(u, lam, committed, guess, want_K=True)
    free = np.flatnonzero(model.free)
    rng = np.random.default_rng(seed)
    if len(free) <= columns:
        cols = free
    else:
        cdofs = np.intersect1d(model.contact.coupled_dofs(trial.contact), free)
        if len(cdofs) > columns:
            cols = rng.choice(cdofs, columns, replace=False)
        else:
            rest = np.setdiff1d(free, cdofs)
            cols = np.concatenate([cdofs, rng.choice(rest, columns - len(cdofs), replace=False)])
    scale = max(float(np.abs(model.system.X).max()), 1.0)
    h = 1e-7 * scale
    fd = fd_columns(model, u, lam, np.sort(cols), h, committed, guess)
    Kc = K[:, np.sort(cols)].toarray()
    diff = np.linalg.norm((Kc - fd)[free])
    ref = max(np.linalg.norm(Kc[free]), 1e-300)
    return {"relative_error": float(diff / ref), "columns": int(len(cols)), "step": step,
            "converged": converged}
