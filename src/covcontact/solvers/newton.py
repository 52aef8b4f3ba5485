"""Incremental loading with Newton's method, automatic cutbacks and an optional line search.

One step goes from load factor lam_a to lam_b. The first iteration is a predictor with the tangent at the
converged state and the prescribed displacement increment on the right-hand side (-R - K_fd du_d); the
remaining iterations are plain Newton with homogeneous Dirichlet conditions. Convergence criteria
(``SolverOptions.criterion``):

- ``"residual"`` (default): ||R_k|| <= max(rtol * max(||R_0||, ||R_1||), atol * F), with R_0 the
  predictor's right-hand side (for a load step: the load increment), R_1 the out-of-balance after the
  predictor and F a force scale of the step (loads, reactions) or, when larger, the largest of the
  steps before (a body unloaded by a later stage has no forces of its own to measure round-off against);
- ``"energy"``: |du_k . R_(k-1)| <= etol * |du_1 . R_0| (the energy norm of FEAP-like codes; it measures
  the residual of the previous iteration, so it needs one iteration more than the residual test);
- ``"both"``: both.

Whatever the criterion, a step also converges on the round-off floor: the residual stopped falling and
either the energy criterion holds or the residual is below rtol * F, fell by less than half in each of the
last two iterations and the last correction is below 1e-10 of the solution (thin shells: about eps_mach E A
per node, whatever the load increment; the second form serves steps that start almost converged, whose
relative references are at round-off themselves). A step that diverges, runs out of
iterations, inverts an element or meets a singular matrix is cut back (its increment halved) up to
``max_cutbacks`` times in a row.

Factorisation reuse (``SolverOptions.reuse_factorization``; "auto", the default, where the direct solver
says its factorisation costs enough substitutions to pay, ``LinearSolver.reuse_pays``): the first
correction of a step is made with a new factorisation; the later ones are first sought by GMRES on the new
tangent, right-preconditioned by that factorisation, to the relative residual
eta_k = min(1e-4, 1e-4 ||R_k|| / r_ref, 0.01 tau / ||R_k||) with r_ref = max(||R_0||, ||R_1||) and tau the
step's convergence threshold: a forcing term that falls with the outer residual (quadratic convergence) and
keeps the linear error at 1 % of the threshold, so that a step ends after the iteration exact Newton would end
it. A new factorisation is made when GMRES does not get there in ``krylov_max`` iterations (and then for the
rest of the step) or when the outer residual stalled (||R_k|| > 0.5 ||R_(k-1)||) after an inexact correction.
Counts and times: ``Newton.stats``.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..assembly.system import InvertedElementError
from .linear import LinearSolverError, SingularMatrixError, gmres_right, make_solver

#: from this iteration on, a step whose residuals repeat with a period of up to CYCLE_PERIOD iterations three
#: times over (to CYCLE_RTOL) is given up as cycling instead of iterating on to max_iterations
CYCLE_FROM = 10
#: from this iteration on (CalculiX's I_0), a residual that grew in three iterations in a row to above the step's
#: reference max(||R_0||, ||R_1||) ends the attempt as diverging
DIVERGING_FROM = 4
CYCLE_PERIOD = 4
CYCLE_RTOL = 1e-6


def _diverging(rs: list, ref: float) -> bool:
    """Whether residual norms ``rs`` (R_0, R_1, ...) lead away: from iteration DIVERGING_FROM on, the last one is above
    ``ref`` and grew in three iterations in a row. (CalculiX and Abaqus cut back after two rises in a row; a contact
    step can rise twice, far above its start, and then converge quadratically.)"""
    return len(rs) > DIVERGING_FROM and rs[-1] > ref and rs[-1] > rs[-2] > rs[-3] > rs[-4]


def _cycle(rs: list) -> int:
    """The period p (2..CYCLE_PERIOD) with which the last 3 p residual norms ``rs`` repeat, else 0."""
    for p in range(2, CYCLE_PERIOD + 1):
        if len(rs) >= 3 * p + 1 and all(abs(rs[-i] - rs[-i - p]) <= CYCLE_RTOL * max(rs[-i], rs[-i - p])
                                        for i in range(1, 2 * p + 1)):
            return p
    return 0


#: relative residual of the first correction of a step with an AMG solver and reuse on
AMG_FIRST = 1e-6
#: a later correction of the step keeps its AMG hierarchy if CG converges within this many times the first
#: correction's iterations (+ 10)
AMG_REUSE_FACTOR = 2


class StepFailed(RuntimeError):
    """A load increment failed; the caller cuts back."""


@dataclass
class IterationRecord:
    iteration: int
    residual: float
    energy: float
    active: int
    linear: str = ""      # how the correction was solved: "factor" (new factorisation) or "krylov"
    krylov: int = 0       # GMRES iterations spent on it (including a failed attempt before a factorisation)
    changes: int = 0      # slave nodes whose contact status (open, closed/stick, slip) this iteration changed


@dataclass
class StepOutcome:
    converged: bool
    iterations: int = 0
    records: list[IterationRecord] = field(default_factory=list)
    residual_norms: list[float] = field(default_factory=list)
    reason: str = ""
    augmentation: int = 0


#: the extrapolating predictor continues a drive (prescribed displacements, loads, rigid motions) whose increment
#: turns from the last step's by less than 60 degrees (cosine above TURN); a drive at rest in either step is no turn
TURN = 0.5
#: halvings of a Newton correction whose full length inverts an element, before the increment is cut back
MAX_BACKTRACKS = 5
#: springs of the stabilisation of bodies held by contact alone, relative to their tangent's mean diagonal
STABILISATION = 1e-2


def extrapolates(predictor: str, problem) -> bool:
    """Whether ``predictor`` extrapolates in ``problem``: "extrapolate", or "auto" in a path-dependent problem
    (a plastic material or a frictional contact pair), where the previous step's increment is a far better
    start than the tangent at the converged state (docs/performance.md, "Predictors")."""
    if predictor != "auto":
        return predictor == "extrapolate"
    if problem is None:
        return False
    from ..materials.plasticity import J2

    plastic = any(getattr(b.material, "kind", None) == J2 for b in problem.bodies)
    return plastic or any((c.friction or 0.0) > 0.0 for c in problem.contacts)


class Newton:
    """Newton solver over a ``Model`` (``covcontact.solvers.model``).

    State (docs/theory.md section 10): a step starts from the committed state and
    threads the trial of each evaluation into the next as its starting point; the trial of the converged
    iterate is what :meth:`advance` returns as the new committed state. A cutback drops the trial.
    """

    def __init__(self, model, options, linear: str | None = None):
        self.model = model
        self.opt = options
        self.linear = make_solver(linear or options.linear, symmetric=model.symmetric)
        self.linear.set_precision(options.factorization_precision)
        self.linear.reproducible = options.reproducible
        self.linear.set_near_null_space(model.near_null_space())  # rigid-body modes (AMG only)
        self.scale_seen = 0.0  # the largest force scale of the converged steps so far
        self.timing = {"assembly": 0.0, "contact": 0.0, "bc": 0.0, "factor": 0.0, "solve": 0.0, "krylov": 0.0}
        self.stats = {"factorizations": 0, "krylov_solves": 0, "krylov_iterations": 0}
        self._amg_first = 0  # AMG with reuse: CG iterations of the step's first correction
        self._amg_fresh = False  # a new hierarchy at every further correction of the step
        self._stalled = False  # the last inexact correction did not reduce the residual enough
        self._failed = False  # GMRES missed its tolerance in krylov_max iterations: factorise for the rest of the step
        self._last: tuple[float, float, np.ndarray] | None = None  # (lam_a, lam_b, increment) of the last step
        self._spring: tuple[np.ndarray, np.ndarray] | None = None  # stabilisation: (stiffness per dof, anchor)
        self._attempt: StepOutcome | None = None  # the outcome of the attempt under way (step)
        self.extrapolate = extrapolates(options.predictor, getattr(model, "problem", None))
        self.poll = None  # called before every iteration (a distributed run's stop signals: StopSignals.poll)
        #: called after every converged increment of :meth:`advance` (after its Uzawa updates) as
        #: ``on_converged(u, lam_a, lam_b, committed, trial)``: the converged displacement, the increment's
        #: load factors, the committed state it started from and its converged trial (check-tangent's probe)
        self.on_converged = None
        self.converged_increments: list[tuple[float, float]] = []  # of the last advance
        #: the line search whatever ``line_search`` says (a dynamic stage with friction sets it, see
        #: covcontact.solvers.dynamics.Dynamic.advance)
        self.search_friction = False

    def _contact_codes(self, trial) -> np.ndarray:
        """The model's contact status codes of ``trial`` (an empty array for a model without contact)."""
        codes = getattr(self.model, "contact_codes", None)
        return codes(trial) if codes is not None else np.zeros(0, np.int64)

    def _changes(self, before: np.ndarray, after: np.ndarray) -> int:
        """Slaves whose status code changed from ``before`` to ``after``, over all ranks of a distributed run."""
        n = int(np.count_nonzero(before != after))
        total = getattr(self.model, "sum_over_ranks", None)
        return int(round(total(n))) if total is not None else n

    # checkpoints -------------------------------------------------------------------------------
    def checkpoint(self) -> tuple[dict, dict]:
        """Newton's part of a checkpoint: the largest force scale met, and the last step's increment where the
        extrapolating predictor continues from it."""
        arrays, meta = {}, {"force_scale": self.scale_seen, "last_step_lams": None}
        if self._last is not None and self.extrapolate:
            arrays["newton.last_increment"] = self._last[2]
            meta["last_step_lams"] = [self._last[0], self._last[1]]
        return arrays, meta

    def restore(self, arrays: dict, meta: dict) -> None:
        self.scale_seen = float(meta.get("force_scale", 0.0))
        last = arrays.get("newton.last_increment")
        if last is not None and meta.get("last_step_lams"):
            self._last = (*(float(v) for v in meta["last_step_lams"]), np.array(last))

    # ------------------------------------------------------------------------------------------
    def _evaluate(self, u: np.ndarray, lam: float, committed, guess, want_K: bool = True):
        R, K, trial = self.model.evaluate(u, lam, committed, guess, want_K=want_K, timing=self.timing)
        if self._spring is not None:  # the stabilisation of bodies held by contact alone (_stabilised)
            k, u0 = self._spring
            R = R + k * (u - u0)
            if K is not None:  # on the diagonal, keeping every stored entry (a sum would drop stored zeros,
                K = K.tocsr(copy=True)  # the diagonals of constrained dofs among them)
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", sp.SparseEfficiencyWarning)
                    K.setdiag(K.diagonal() + k)
        return R, K, trial

    def _inexact(self, K, rhs, eta: float, solve):
        """An inexact correction ``solve()`` -> (du or None, Krylov iterations), timed and counted: (du, its), du
        None when the Krylov method gave up or broke down or the true residual misses ``eta`` ||rhs||."""
        t0 = time.perf_counter()
        du, its = solve()
        self.timing["krylov"] += time.perf_counter() - t0
        self.stats["krylov_iterations"] += its
        if du is None or not np.all(np.isfinite(du)):
            return None, its
        if float(np.linalg.norm(rhs - K @ du)) > 1.01 * eta * float(np.linalg.norm(rhs)):
            return None, its  # judged on the true residual
        self.stats["krylov_solves"] += 1
        return du, its

    def _krylov(self, K, rhs, eta: float):
        """GMRES on K du = rhs, right-preconditioned by the last factorisation (so that its residual is the
        true one); None when it needs more than ``krylov_max`` iterations (or breaks down)."""
        flexible = bool(getattr(self.linear, "single", False))  # a single-precision factor: FGMRES
        return self._inexact(K, rhs, eta, lambda: gmres_right(K, rhs, self.linear.precondition, eta,
                                                               self.opt.krylov_max, flexible=flexible))[0]

    def _amg(self, K, rhs, eta: float, maxiter: int | None = None):
        """CG (GMRES) preconditioned by the current AMG hierarchy, to ``eta``: (du or None when it does not
        converge within ``maxiter``, default the solver's, iterations)."""
        return self._inexact(K, rhs, eta, lambda: self.linear.solve_preconditioned(K, rhs, eta, maxiter))

    def _solve(self, K, rhs, eta: float | None = None, loose: float | None = None):
        """The Newton correction: a new factorisation, or (``eta`` given, reuse on) GMRES on the last one to
        ``eta``. With an AMG solver and reuse on, each correction is CG preconditioned by an AMG hierarchy, to
        ``AMG_FIRST`` at the step's first correction, which builds the hierarchy, and to the linear forcing term
        ``loose`` afterwards (a CG iteration on a V-cycle gains far less than a GMRES iteration on an exact
        factorisation; Newton keeps its iteration count). A later correction first tries the step's hierarchy
        (when it fits: a new contact coupling in the sparsity pattern builds a new one for that correction)
        with at most ``AMG_REUSE_FACTOR`` times the first solve's iterations (+ 10); if that is not enough, the
        tangent has moved too far from it and every further correction of the step builds its own. The rule
        counts iterations, not seconds, so it decides alike on every run (a resumed run repeats the
        uninterrupted one)."""
        reuse = self.opt.reuse_factorization
        amg = bool(reuse) and hasattr(self.linear, "solve_preconditioned") and not self._failed
        if amg and eta is not None and not self._amg_fresh and self.linear.preconditioner_fits(K):
            du, _ = self._amg(K, rhs, loose, AMG_REUSE_FACTOR * self._amg_first + 10)
            if du is not None:
                return du
            self._amg_fresh = True
        if amg:
            self.stats["factorizations"] += 1
            t0 = time.perf_counter()
            self.linear.factorize(K)
            self.timing["factor"] += time.perf_counter() - t0
            du, its = self._amg(K, rhs, AMG_FIRST if eta is None else loose)
            if eta is None:
                self._amg_first, self._amg_fresh = its, False
            if du is not None:
                return du
            self._failed = True  # the solver's own solve (to its rtol, with GMRES after CG) below
        ready = (eta is not None and reuse and not self._stalled and not self._failed
                 and getattr(self.linear, "_K", None) is not None and self.linear._K.shape == K.shape)
        if ready and self.linear.direct and (reuse is True or self.linear.reuse_pays()):
            du = self._krylov(K, rhs, eta)
            if du is not None:
                return du
            self._failed = True
        self._stalled = False
        self.stats["factorizations"] += 1
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

    def _backtrack(self, u, du, eta, lam, committed, trial):
        """u += eta du and evaluate there; where an element inverts, halve eta on the free dofs (the prescribed
        part of the correction is always made in full) up to ``MAX_BACKTRACKS`` times before giving up (the
        InvertedElementError then cuts the increment back). Returns (eta, the evaluation)."""
        free = self.model.free
        base = u.copy()
        for k in range(MAX_BACKTRACKS + 1):
            u[:] = base
            u[free] += eta * du[free]
            u[~free] += du[~free]
            try:
                return eta, self._evaluate(u, lam, committed, trial)
            except InvertedElementError:
                if k == MAX_BACKTRACKS:
                    raise
                self.stats["backtracks"] = self.stats.get("backtracks", 0) + 1
                eta *= 0.5
        raise AssertionError("unreachable")

    def _searched(self, u, du, lam, R0, committed, trial):
        """The correction ``du`` with a secant line search on s(eta) = du . R(u + eta du) (``R0`` the residual at
        u, zero on the constrained dofs): the full correction is evaluated first, with its tangent, as without the
        search, and kept where |s(1)| <= 0.8 |s(0)|; otherwise up to 6 secant steps on eta in [0.1, 1] (residuals
        only) until |s| <= 0.8 |s(0)|, and the evaluation with the tangent is made there. A full correction that
        inverts an element is shortened by ``_backtrack`` alone (no search then). Returns (eta, the evaluation at
        u + eta du); ``u`` is moved there. (The full correction's evaluation serves both the test and the next
        iteration, so a search that keeps eta = 1 costs nothing.)"""
        base = u.copy()
        eta, ev = self._backtrack(u, du, 1.0, lam, committed, trial)
        s0, s1 = float(du @ R0), float(du @ ev[0])
        if eta < 1.0 or s0 == 0.0 or abs(s1) <= 0.8 * abs(s0):
            return eta, ev
        a0, a1, f0, f1 = 0.0, 1.0, s0, s1
        try:
            for _ in range(6):
                if f1 == f0:
                    break
                eta = float(np.clip(a1 - f1 * (a1 - a0) / (f1 - f0), 0.1, 1.0))
                Rt, _, _ = self._evaluate(base + eta * du, lam, committed, trial, want_K=False)
                ft = float(du @ Rt)
                if abs(ft) <= 0.8 * abs(s0):
                    break
                a0, f0, a1, f1 = a1, f1, eta, ft
        except InvertedElementError:  # a shorter correction inverts an element: half of it (backtracked below)
            eta = 0.5
        if eta == 1.0:
            return eta, ev
        self.stats["line_searches"] = self.stats.get("line_searches", 0) + 1
        u[:] = base
        return self._backtrack(u, du, eta, lam, committed, trial)

    def _extrapolates_from(self, lam_a: float, lam_b: float) -> bool:
        """Whether the step from lam_a to lam_b starts from the extrapolating predictor (``_predict``): it
        continues the last converged step (a cut-back attempt of a failed step too: it starts where that step
        did), and the loading does not turn (no kind of drive, prescribed displacements, loads or rigid motions,
        whose increment turns by more than 60 degrees from the last step's, ``TURN``)."""
        last = self._last
        if not (self.extrapolate and last is not None and lam_b > lam_a
                and abs(last[1] - lam_a) <= 1e-14 * max(1.0, abs(lam_a)) and last[1] > last[0]):
            return False
        drive = getattr(self.model, "drive", None)
        if drive is None:
            return True
        before = [b - a for a, b in zip(drive(last[0]), drive(last[1]))]
        now = [b - a for a, b in zip(drive(lam_a), drive(lam_b))]
        return all(float(p @ q) >= TURN * float(np.linalg.norm(p)) * float(np.linalg.norm(q))
                   for p, q in zip(before, now))

    def _predict(self, u: np.ndarray, lam_a: float, lam_b: float, du_d: np.ndarray) -> np.ndarray:
        """The extrapolating predictor (``predictor = "extrapolate"``, continuing a converged step): the previous
        increment scaled to this step on the free dofs and the prescribed increment ``du_d`` on the others,
        added to ``u``; returns the prescribed increment the first correction still has to make (zero then)."""
        last, free = self._last, self.model.free
        if self._extrapolates_from(lam_a, lam_b):
            u[free] += (lam_b - lam_a) / (last[1] - last[0]) * last[2][free]
            u[~free] += du_d[~free]
            return np.zeros_like(du_d)
        return du_d

    def _converged(self, rs: list, it: int, r_ref: float, scale_k: float, conv_energy: bool, eta: float,
                   du: np.ndarray, u: np.ndarray) -> bool:
        """The convergence test after iteration ``it`` (residual norms ``rs``, the last one's): the criterion,
        or the round-off floor. The floor: the energy criterion holds and the residual stopped falling; or the
        residual is below rtol of the force scale, stopped falling for two iterations and the correction
        ``eta du`` is at round-off of the solution ``u``, whose norms are taken only then (a step that starts
        almost converged, e.g. after the extrapolating predictor, has r_ref and the energy reference themselves
        at round-off, so neither relative test can hold; a slowly converging step still makes corrections and
        goes on)."""
        opt, rn, free = self.opt, rs[-1], self.model.free
        conv_res = rn <= max(opt.rtol * r_ref, opt.atol * scale_k)
        stalled = it >= 2 and rn >= 0.5 * rs[-2]
        floor = stalled and (conv_energy or (
            it >= 3 and rs[-2] >= 0.5 * rs[-3] and rn <= opt.rtol * scale_k
            and eta * float(np.linalg.norm(du[free])) <= 1e-10 * float(np.linalg.norm(u[free]))))
        conv = {"residual": conv_res, "energy": conv_energy, "both": conv_res and conv_energy}[opt.criterion]
        return conv or floor

    # ------------------------------------------------------------------------------------------
    def step(self, u: np.ndarray, lam_a: float, lam_b: float, committed, trial=None):
        """Advance ``u`` in place from lam_a to lam_b, starting from the state ``trial`` (default: the
        committed one); returns (StepOutcome, the last trial). On failure ``u`` is left undefined."""
        m, opt = self.model, self.opt
        out = self._attempt = StepOutcome(converged=False)  # (an attempt that raises keeps its iterations)
        free = m.free
        self._failed = False
        self.linear.new_step()
        if trial is None:
            trial = m.start_step(committed)
        else:
            m.begin_step()
        du_d = self._predict(u, lam_a, lam_b, m.prescribed(lam_b) - m.prescribed(lam_a))
        R, K, trial = self._evaluate(u, lam_b, committed, trial)
        t0 = time.perf_counter()
        rhs = -R - K @ du_d if np.any(du_d) else -R  # (no product with a zero increment: 0.2 s at 1e6 dofs)
        rhs[~free] = 0.0
        K = m.eliminate(K)
        self.timing["bc"] += time.perf_counter() - t0
        r0 = float(np.linalg.norm(rhs))
        f_b = m.applied(u, lam_b) if hasattr(m, "applied") else m.external(lam_b)  # (with follower pressures)
        scale = max(float(np.linalg.norm(f_b)), float(np.linalg.norm(R)), r0, self.scale_seen,
                    1e-300)
        out.residual_norms.append(r0)
        out.records.append(IterationRecord(0, r0, 0.0, m.active_count(trial)))
        codes = self._contact_codes(trial)
        if r0 <= opt.atol * scale and not np.any(du_d):
            out.converged = True
            return out, trial
        e0 = None
        rn_prev = r0
        r_ref = r0  # max(||R_0||, ||R_1||) once the first correction is made
        inexact = False
        for it in range(1, opt.max_iterations + 1):
            if self.poll is not None:
                self.poll()
            eta = loose = None  # the first correction of a step: a new factorisation (see _solve)
            if it > 1:  # GMRES tolerance relative to ||rhs||: quadratic forcing, and 1 % of the convergence
                # threshold, so that the iterate is that of exact Newton to well within the test
                threshold = max(opt.rtol * r_ref, opt.atol * scale)
                loose = min(1e-4, 1e-2 * threshold / max(rn_prev, 1e-300))
                eta = min(1e-4 * rn_prev / r_ref, loose)
            n_fact, n_kry = self.stats["factorizations"], self.stats["krylov_iterations"]
            # the first correction of a step is always made with a new factorisation: a step's iterations then
            # do not depend on how the run got there (a resumed run has no factorisation to reuse)
            du = self._solve(K, rhs, eta, loose)
            inexact = self.stats["factorizations"] == n_fact
            du[~free] = du_d[~free] if it == 1 else 0.0
            out.iterations = it
            if (opt.line_search or self.search_friction) and it > 1:
                eta, (R, K, trial) = self._searched(u, du, lam_b, -rhs, committed, trial)
            else:
                eta, (R, K, trial) = self._backtrack(u, du, 1.0, lam_b, committed, trial)
            energy = abs(float(du[free] @ rhs[free])) * eta
            if e0 is None:
                e0 = max(energy, 1e-300)
            t0 = time.perf_counter()
            reactions = float(np.linalg.norm(R[~free]))
            rhs = -R
            rhs[~free] = 0.0
            K = m.eliminate(K)
            self.timing["bc"] += time.perf_counter() - t0
            rn = float(np.linalg.norm(rhs))
            if inexact and rn > 0.5 * rn_prev:  # stalled after an inexact correction: refactorise next
                self._stalled = True
            rn_prev = rn
            out.residual_norms.append(rn)
            codes_prev, codes = codes, self._contact_codes(trial)
            out.records.append(IterationRecord(it, rn, energy, m.active_count(trial),
                                               "krylov" if inexact else "factor",
                                               self.stats["krylov_iterations"] - n_kry,
                                               self._changes(codes_prev, codes)))
            if not np.isfinite(rn) or (it >= 3 and rn > opt.divergence_factor * max(r0, opt.atol * scale)):
                out.reason = f"diverged (residual {rn:.3e} against {r0:.3e})"
                return out, trial
            if _diverging(out.residual_norms, max(r_ref, opt.atol * scale)):  # (retried or cut back)
                out.reason = (f"diverging (the residual grew in three iterations in a row, to {rn:.3e}, above the "
                              f"step's {r_ref:.3e})")
                return out, trial
            period = _cycle(out.residual_norms) if it >= CYCLE_FROM else 0
            if period:  # the iteration goes round in a circle (an active set that cycles): cut back now
                out.reason = (f"the active set cycles (the same {period} residuals, {rn:.3e} among them, three times "
                              f"over)")
                return out, trial
            if it == 1:
                r_ref = max(r0, rn)
            scale_k = max(scale, reactions)
            if self._converged(out.residual_norms, it, r_ref, scale_k, energy <= opt.etol * e0, eta, du, u):
                out.converged = True
                self.scale_seen = max(self.scale_seen, scale_k)
                return out, trial
        out.reason = f"no convergence in {opt.max_iterations} iterations"
        return out, trial

    def _try(self, u, lam_a, lam_b, committed, trial):
        u0 = u.copy()
        try:
            return self.step(u, lam_a, lam_b, committed, trial)
        except InvertedElementError as exc:
            explain = getattr(self.model, "explain_inversion", None)
            where = explain(exc.body, exc.element) if explain is not None else ""
            return self._failed_attempt(str(exc) + where), None
        except LinearSolverError as exc:
            floating = getattr(self.model, "floating_dofs", lambda: None)()
            if floating is None:
                return self._failed_attempt(str(exc)), None
            u[:] = u0
            return self._stabilised(u, lam_a, lam_b, committed, trial, floating, str(exc))

    def _failed_attempt(self, reason: str) -> StepOutcome:
        """The outcome of the attempt that raised: its iterations, residuals and records so far, and why."""
        out = self._attempt or StepOutcome(converged=False)
        self._attempt = None
        out.converged, out.reason = False, reason
        return out

    def _stabilised(self, u, lam_a, lam_b, committed, trial, floating, why):
        """The step again with the bodies held by contact alone tied to where they started by soft springs
        (stiffness STABILISATION times the mean diagonal of their tangent), so that a body that is not yet in
        contact, or free to slide, has a regular tangent; once that converged, the springs are taken off and
        Newton goes on from there to the unstabilised equilibrium (the converged answer is the problem's own).
        Returns the combined outcome."""
        try:
            _, K, _ = self._evaluate(u, lam_b, committed, trial)
            d = np.abs(K.diagonal())
            free = self.model.free
            scale = float(np.mean(d[floating & free & (d > 0)])) if np.any(d[floating & free] > 0) else 1.0
            # the floating bodies, and any free dof nothing acts on (a rigid body's reference node out of contact)
            tied = free & (floating | (d == 0.0))
            self._spring = (np.where(tied, STABILISATION * scale, 0.0), u.copy())
            first, t1 = self.step(u, lam_a, lam_b, committed, trial)
            self._spring = None
            if not first.converged:
                first.reason = f"{why}; stabilised: {first.reason}"
                return first, t1
            second, t2 = self.step(u, lam_b, lam_b, committed, t1)
        except (InvertedElementError, LinearSolverError) as exc:
            return StepOutcome(converged=False, reason=f"{why}; stabilised: {exc}"), None
        finally:
            self._spring = None
        second.iterations += first.iterations
        second.records = first.records + second.records
        second.residual_norms = first.residual_norms + second.residual_norms
        self.stats["stabilised"] = self.stats.get("stabilised", 0) + 1
        if not second.converged:
            second.reason = f"{why}; stabilised, then without the stabilisation: {second.reason}"
        return second, t2

    def advance(self, u: np.ndarray, lam_a: float, lam_b: float, committed, min_increment: float | None = None,
                single: bool = False):
        """Reach lam_b from lam_a from the committed state, cutting back on failure (at most ``max_cutbacks``
        times in a row, and not below ``min_increment`` where given). ``single``: stop at the first increment
        that converges (after cutbacks short of lam_b; automatic incrementation goes on from there).

        Returns (ok, list of StepOutcome, cutbacks, why, state): ``state`` is the new committed state (the
        one given if nothing converged). ``u`` holds the displacement of that state. ``converged_increments``
        then lists the (lam_a, lam_b) of every increment that converged on the way.
        """
        self.converged_increments = []
        outcomes: list[StepOutcome] = []
        cutbacks = 0
        depth = 0
        lam = lam_a
        inc = lam_b - lam_a
        why = ""
        while lam < lam_b - 1e-14 * max(1.0, abs(lam_b)):
            target = min(lam + inc, lam_b)
            saved = u.copy()
            extrapolated = self._extrapolates_from(lam, target)
            res, trial = self._try(u, lam, target, committed, None)
            outcomes.append(res)
            last = self._last
            if not res.converged and extrapolated:
                # the extrapolated start led astray: the same increment again from the tangent predictor before
                # a cutback
                u[:] = saved
                self._last = None
                res, trial = self._try(u, lam, target, committed, None)
                outcomes.append(res)
            # the extrapolating predictor continues from the last converged increment, also into the cut back
            # attempts of a failed one (still ending where the cutback starts)
            self._last = (lam, target, u - saved) if res.converged else last
            augment = 0
            # augmented Lagrangian: Uzawa updates at the converged state, each followed by Newton
            while res.converged and (new := self.model.augment(trial)) is not None:
                augment += 1
                res, trial = self._try(u, target, target, committed, new)
                res.augmentation = augment
                outcomes.append(res)
            if res.converged:
                if self.on_converged is not None:
                    self.on_converged(u, lam, target, committed, trial)
                committed = trial
                self.converged_increments.append((lam, target))
                lam = target
                depth = max(depth - 1, 0)
                if single:
                    break
                continue
            u[:] = saved  # the trial is dropped
            why = res.reason
            depth += 1
            cutbacks += 1
            inc = (target - lam) / 2.0
            if depth > self.opt.max_cutbacks or (min_increment is not None and inc < min_increment * (1 - 1e-12)):
                return False, outcomes, cutbacks, why, committed
        return True, outcomes, cutbacks, why, committed
