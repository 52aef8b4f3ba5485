"""Incremental loading with Newton's method, automatic cutbacks and an optional line search.

One step goes from load factor lam_a to lam_b. The first iteration is a predictor with the tangent at the
converged state and the prescribed displacement increment on the right-hand side (-R - K_fd du_d); the
remaining iterations are plain Newton with homogeneous Dirichlet conditions. Convergence criteria
(``SolverOptions.criterion``):

- ``"residual"`` (default): ||R_k|| <= max(rtol * max(||R_0||, ||R_1||), atol * F), with R_0 the
  predictor's right-hand side (for a load step: the load increment), R_1 the out-of-balance after the
  predictor and F a force scale of the step (loads, reactions);
- ``"energy"``: |du_k . R_(k-1)| <= etol * |du_1 . R_0| (the energy norm of FEAP-like codes; it measures
  the residual of the previous iteration, so it needs one iteration more than the residual test);
- ``"both"``: both.

Whatever the criterion, a step also converges on the round-off floor: the energy criterion holds and the
residual stopped falling (thin shells: about eps_mach E A per node, whatever the load increment). A step that diverges, runs out of
iterations, inverts an element or meets a singular matrix is cut back (its increment halved) up to
``max_cutbacks`` times in a row.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..assembly.system import InvertedElementError
from .linear import LinearSolverError, SingularMatrixError, make_solver


class StepFailed(RuntimeError):
    """A load increment failed; the caller cuts back."""


@dataclass
class IterationRecord:
    iteration: int
    residual: float
    energy: float
    active: int


@dataclass
class StepOutcome:
    converged: bool
    iterations: int = 0
    records: list[IterationRecord] = field(default_factory=list)
    residual_norms: list[float] = field(default_factory=list)
    reason: str = ""
    augmentation: int = 0


class Newton:
    """Newton solver over a ``Model`` (``covcontact.solvers.model``)."""

    def __init__(self, model, options, linear: str | None = None):
        self.model = model
        self.opt = options
        self.linear = make_solver(linear or options.linear, symmetric=model.symmetric)
        self.timing = {"assembly": 0.0, "contact": 0.0, "bc": 0.0, "factor": 0.0, "solve": 0.0}

    # ------------------------------------------------------------------------------------------
    def _evaluate(self, u: np.ndarray, lam: float, want_K: bool = True):
        R, K = self.model.evaluate(u, lam, want_K=want_K, timing=self.timing)
        return R, K

    def _solve(self, K, rhs):
        t0 = time.perf_counter()
        du = self.linear.solve(K, rhs)
        dt = time.perf_counter() - t0
        tf = getattr(self.linear, "t_factor", None)
        if tf is not None:
            self.timing["factor"] += tf
            self.timing["solve"] += max(dt - tf, 0.0)
        else:
            self.timing["solve"] += dt
        if not np.all(np.isfinite(du)):
            raise SingularMatrixError("linear solve returned non-finite values")
        return du

    def _line_search(self, u, du, lam, R0):
        s0 = float(du @ R0)
        R1, _ = self._evaluate(u + du, lam, want_K=False)
        s1 = float(du @ R1)
        if s0 == 0.0 or abs(s1) <= 0.8 * abs(s0):
            return 1.0
        a0, a1, f0, f1 = 0.0, 1.0, s0, s1
        eta = 1.0
        for _ in range(6):
            if f1 == f0:
                break
            eta = a1 - f1 * (a1 - a0) / (f1 - f0)
            eta = float(np.clip(eta, 0.1, 1.0))
            Rt, _ = self._evaluate(u + eta * du, lam, want_K=False)
            ft = float(du @ Rt)
            if abs(ft) <= 0.8 * abs(s0):
                break
            a0, f0, a1, f1 = a1, f1, eta, ft
        return eta

    # ------------------------------------------------------------------------------------------
    def step(self, u: np.ndarray, lam_a: float, lam_b: float) -> StepOutcome:
        """Advance ``u`` in place from lam_a to lam_b; on failure ``u`` is left undefined."""
        m, opt = self.model, self.opt
        out = StepOutcome(converged=False)
        free = m.free
        m.begin_step(u, lam_b)
        du_d = m.prescribed(lam_b) - m.prescribed(lam_a)
        R, K = self._evaluate(u, lam_b)
        t0 = time.perf_counter()
        rhs = -R - K @ du_d
        rhs[~free] = 0.0
        K = m.eliminate(K)
        self.timing["bc"] += time.perf_counter() - t0
        r0 = float(np.linalg.norm(rhs))
        scale = max(float(np.linalg.norm(lam_b * m.f_ext)), float(np.linalg.norm(R)), r0, 1e-300)
        out.residual_norms.append(r0)
        out.records.append(IterationRecord(0, r0, 0.0, m.active_count()))
        if r0 <= opt.atol * scale and not np.any(du_d):
            out.converged = True
            return out
        e0 = None
        for it in range(1, opt.max_iterations + 1):
            du = self._solve(K, rhs)
            du[~free] = du_d[~free] if it == 1 else 0.0
            eta = 1.0
            if opt.line_search and it > 1:
                eta = self._line_search(u, du, lam_b, -rhs)
            energy = abs(float(du[free] @ rhs[free])) * eta
            if e0 is None:
                e0 = max(energy, 1e-300)
            u += eta * du
            out.iterations = it
            R, K = self._evaluate(u, lam_b)
            t0 = time.perf_counter()
            reactions = float(np.linalg.norm(R[~free]))
            rhs = -R
            rhs[~free] = 0.0
            K = m.eliminate(K)
            self.timing["bc"] += time.perf_counter() - t0
            rn = float(np.linalg.norm(rhs))
            out.residual_norms.append(rn)
            out.records.append(IterationRecord(it, rn, energy, m.active_count()))
            if not np.isfinite(rn) or (it >= 3 and rn > opt.divergence_factor * max(r0, opt.atol * scale)):
                out.reason = f"diverged (residual {rn:.3e} against {r0:.3e})"
                return out
            if it == 1:
                r_ref = max(r0, rn)
            scale_k = max(scale, reactions)
            conv_energy = energy <= opt.etol * e0
            conv_res = rn <= max(opt.rtol * r_ref, opt.atol * scale_k)
            # round-off floor: the energy criterion holds and the residual stopped falling
            floor = conv_energy and it >= 2 and rn >= 0.5 * out.residual_norms[-2]
            conv = {"residual": conv_res, "energy": conv_energy, "both": conv_res and conv_energy}[opt.criterion]
            if conv or floor:
                if m.active_set_settled():
                    out.converged = True
                    return out
        out.reason = f"no convergence in {opt.max_iterations} iterations"
        return out

    def advance(self, u: np.ndarray, lam_a: float, lam_b: float):
        """Reach lam_b from lam_a, cutting back on failure. Returns (ok, list of StepOutcome, cutbacks, why)."""
        outcomes: list[StepOutcome] = []
        cutbacks = 0
        depth = 0
        lam = lam_a
        inc = lam_b - lam_a
        why = ""
        while lam < lam_b - 1e-14 * max(1.0, abs(lam_b)):
            target = min(lam + inc, lam_b)
            saved = u.copy()
            self.model.save_state()
            try:
                res = self.step(u, lam, target)
            except (InvertedElementError, LinearSolverError) as exc:
                res = StepOutcome(converged=False, reason=str(exc))
            outcomes.append(res)
            if res.converged:
                # augmented Lagrangian: Uzawa updates at the converged state, each followed by Newton
                augment = 0
                while res.converged and self.model.augment():
                    augment += 1
                    try:
                        res = self.step(u, target, target)
                    except (InvertedElementError, LinearSolverError) as exc:
                        res = StepOutcome(converged=False, reason=str(exc))
                    res.augmentation = augment
                    outcomes.append(res)
            if res.converged:
                self.model.commit()
                lam = target
                depth = max(depth - 1, 0)
                continue
            u[:] = saved
            self.model.restore_state()
            why = res.reason
            depth += 1
            cutbacks += 1
            if depth > self.opt.max_cutbacks:
                return False, outcomes, cutbacks, why
            inc = (target - lam) / 2.0
        return True, outcomes, cutbacks, why
