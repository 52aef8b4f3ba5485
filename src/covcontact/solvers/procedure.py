"""Procedures: how a stage is stepped. A run drives one procedure per stage; a procedure advances the run one
increment at a time and reports each increment (docs/architecture.md).

``QuasiStatic`` is the load stepping of every stage today: each step goes from the last converged load factor
to the next one its increment control gives, with Newton and cutbacks (``Newton.advance``). The increment
control is a small object of its own (``FixedIncrements``: the stage's ``count`` or ``factors``), so that a
control that chooses its increments from the last ones can take its place.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .state import State


class FixedIncrements:
    """The load factors of a stage as its input gives them (``count`` or ``factors``)."""

    def __init__(self, factors, marks=()):
        self.factors = tuple(float(f) for f in factors)
        self.marks = tuple(float(m) for m in marks)

    def is_mark(self, lam: float) -> bool:
        """Whether results are requested at load factor ``lam`` (``output_at``)."""
        return any(abs(lam - m) <= 1e-9 * max(1.0, abs(m)) for m in self.marks)

    def target(self, lam: float) -> float | None:
        """The load factor of the step after the converged load factor ``lam``; None when the stage is done."""
        tol = 1e-12 * max(1.0, abs(lam))
        return next((f for f in self.factors if f > lam + tol), None)

    def record(self, inc, converged: list) -> None:
        pass

    def state(self) -> dict:
        return {}

    def restore(self, state: dict) -> None:
        pass


class AutomaticIncrements:
    """Increments of the load factor chosen as the steps go (``[steps] initial, min, max``), in the manner of
    Abaqus/Standard: start with ``initial``; after ``EASY_STEPS`` steps in a row that converged without a
    cutback in at most ``EASY_ITERATIONS`` iterations, grow by ``GROW``; after a step that needed more than
    ``HARD_ITERATIONS`` (counting every attempt at the increment: a failed extrapolated start retried from the
    tangent made the step hard, however quickly the retry converged), or more than ``EASY_ITERATIONS`` while
    more than ``SET_CHANGE`` of the active slave nodes (and more than ``SET_CHANGE_MIN``) opened or closed, or
    more than ``ZONE_CHANGE`` of the yielding Gauss points started or stopped yielding, shrink by ``SHRINK``;
    after a step that needed cutbacks, go on with the increment that finally converged; never below ``min``
    (Newton's cutbacks stop there) nor above ``max``; the last step ends exactly at the stage's end (a
    remainder below ``min`` is taken with the step before it)."""

    EASY_ITERATIONS = 5
    EASY_STEPS = 2
    HARD_ITERATIONS = 12
    GROW = 1.5
    SHRINK = 0.75
    SET_CHANGE = 0.25  # shrink when more than this fraction of the active slaves opened or closed in a step
    SET_CHANGE_MIN = 8  # (and more than this many)
    ZONE_CHANGE = 0.5  # ... or when more than this fraction of the yielding Gauss points started or stopped

    def __init__(self, initial: float, lo: float, hi: float, end: float, marks=()):
        self.increment, self.lo, self.hi, self.end = float(initial), float(lo), float(hi), float(end)
        self.marks = tuple(float(m) for m in marks)
        self.easy = 0  # easy steps in a row

    is_mark = FixedIncrements.is_mark

    def target(self, lam: float) -> float | None:
        if lam >= self.end - 1e-12 * max(1.0, abs(self.end)):
            return None
        t = lam + self.increment
        # the next output_at (or the stage's end) is hit exactly; a remainder below min goes with this step
        stop = next((m for m in self.marks + (self.end,) if m > lam + 1e-9 * max(1.0, abs(m))), self.end)
        return stop if t >= stop - self.lo else t

    def _settled(self, inc, converged: list) -> bool:
        """True when step ``inc`` leaves nothing to adapt: it failed, or it needed cutbacks (then the increment that
        finally converged, the last of ``converged``, is the next one's size)."""
        if not inc.success:
            return True
        if inc.cutbacks:
            a, b = converged[-1]
            self.increment, self.easy = min(max(b - a, self.lo), self.hi), 0
            return True
        return False

    def record(self, inc, converged: list) -> None:
        """Adapt the increment to how step ``inc`` went (``converged``: its increments that converged, after
        cutbacks the last one is the size that worked)."""
        if self._settled(inc, converged):
            return
        its = inc.iterations  # (every attempt: a failed extrapolated start retried from the tangent counts)
        moved = (inc.opened_closed > max(self.SET_CHANGE_MIN, self.SET_CHANGE * inc.active)
                 or inc.plastic_changed > max(self.SET_CHANGE_MIN, self.ZONE_CHANGE * inc.yielding))
        if its > self.EASY_ITERATIONS and moved:
            # a step that was not easy and in which the active set or the plastic zone changed a lot: the next
            # one is likely to change them as much
            self.increment, self.easy = max(self.increment * self.SHRINK, self.lo), 0
            return
        if its <= self.EASY_ITERATIONS:
            self.easy += 1
            if self.easy >= self.EASY_STEPS:
                self.increment, self.easy = min(self.increment * self.GROW, self.hi), 0
        else:
            self.easy = 0
            if its > self.HARD_ITERATIONS:
                self.increment = max(self.increment * self.SHRINK, self.lo)

    def state(self) -> dict:
        """What a checkpoint keeps of the control (a resumed run goes on with the same increments)."""
        return {"increment": self.increment, "easy": self.easy}

    def restore(self, state: dict) -> None:
        self.increment, self.easy = float(state["increment"]), int(state["easy"])


class TimeSteps(AutomaticIncrements):
    """Automatic time steps of a dynamic stage: on the local error estimate of Zienkiewicz and Xie (1991, Earthquake
    Eng. Struct. Dyn. 20, 871-887), eta = dt^2 |beta - 1/6| ||a_(n+1) - a_n|| / ||u_(n+1) - u_start|| in the mass
    norm (the step's ``error``, set by the procedure), against ``tol``: a step above it makes the next dt * max(0.5, 0.9
    (tol / eta)^(1/3)); below tol / 4, after ``EASY_STEPS`` such steps in a row without a change of the active set,
    the next grows by min(``GROW``, 0.9 (tol / eta)^(1/3)). Newton's verdicts as in ``AutomaticIncrements``: cutbacks
    set the size that converged, a hard step (more than ``HARD_ITERATIONS``) or a contact that opened or closed
    shrinks by ``SHRINK`` (contact events are resolved with short steps)."""

    def __init__(self, initial: float, lo: float, hi: float, end: float, tol: float, marks=()):
        super().__init__(initial, lo, hi, end, marks)
        self.tol = float(tol)

    def record(self, inc, converged: list) -> None:
        if self._settled(inc, converged):
            return
        eta = float(getattr(inc, "error", 0.0))
        factor = 0.9 * (self.tol / eta) ** (1.0 / 3.0) if eta > 0.0 else self.GROW
        if eta > self.tol:
            self.increment, self.easy = max(self.increment * max(0.5, factor), self.lo), 0
        elif inc.outcomes[-1].iterations > self.HARD_ITERATIONS or inc.opened_closed > 0:
            self.increment, self.easy = max(self.increment * self.SHRINK, self.lo), 0
        elif eta < 0.25 * self.tol:
            self.easy += 1
            if self.easy >= self.EASY_STEPS:
                self.increment, self.easy = min(self.increment * min(self.GROW, factor), self.hi), 0
        else:
            self.easy = 0


def increment_control(spec, steps, dynamics=None):
    """The increment control of stage ``spec`` from its ``Steps``: automatic (time steps of a dynamic stage
    ``dynamics`` on their error estimate) or the given load factors."""
    marks = () if steps is None else steps.output_at
    if steps is not None and steps.is_automatic:
        if dynamics is not None:
            return TimeSteps(steps.initial, steps.min, steps.max, spec.lam_end, dynamics.tolerance, marks)
        return AutomaticIncrements(steps.initial, steps.min, steps.max, spec.lam_end, marks)
    return FixedIncrements(spec.factors, marks)


@dataclass
class Increment:
    """One step of a stage as the procedure made it: the step number over the whole run, its load factors,
    whether it converged (with cutbacks), Newton's outcomes, the committed state after it (the one before it
    when it failed) and ``entry``, its summary record (docs/input.md, summary.json)."""

    step: int
    lam_a: float
    lam: float
    success: bool
    outcomes: list
    cutbacks: int
    why: str
    state: State
    entry: dict = field(default_factory=dict)
    ends_stage: bool = False  # the step reached the stage's end
    output: bool = False  # the step ended at a load factor of ``output_at``
    opened_closed: int = 0  # slave nodes whose contact opened or closed in the step (automatic increments)
    active: int = 0  # slave nodes in contact at its end (automatic increments)
    plastic_changed: int = 0  # Gauss points that started or stopped yielding in the step (automatic increments)
    yielding: int = 0  # Gauss points yielding in the step (automatic increments)
    error: float = 0.0  # a dynamic step's local error estimate (automatic time steps)

    @property
    def iterations(self) -> int:
        return sum(o.iterations for o in self.outcomes)

    @property
    def records(self) -> list:
        """Newton's iteration records of every attempt of the step, in order."""
        return [r for o in self.outcomes for r in o.records]

    @property
    def residual(self) -> float:
        """The last residual norm of the converged attempt (nan when none converged)."""
        conv = [o for o in self.outcomes if o.converged]
        return conv[-1].residual_norms[-1] if conv else float("nan")


class QuasiStatic:
    """Quasi-static load stepping of one stage (``spec``, a ``StageSpec``) of ``model`` with ``newton``.

    ``t_stage``: the total pseudo-time of the earlier stages, ``staged``: the problem has several stages (its
    records then name the stage and carry the time); ``control``: the increment control (default: the stage's
    load factors).
    """

    name = "static"

    def __init__(self, model, newton, spec, t_stage: float, staged: bool, control=None):
        self.model = model
        self.newton = newton
        self.spec = spec
        self.t_stage = t_stage
        self.staged = staged
        self.control = control if control is not None else FixedIncrements(spec.factors)
        self.automatic = isinstance(self.control, AutomaticIncrements)
        self.augmented = any(c.method == "augmented" for c in model.problem.contacts)
        self.work = None

    def start(self, state: State, u: np.ndarray | None = None) -> State:
        """Start, or resume, the stage at the committed ``state`` (its plastic work is the reference of the
        next step's dissipation); returns the state the stage starts from (a quasi-static stage starts at rest:
        without the kinematics of a dynamic stage before it)."""
        self.work = self.model.plastic_work(state)
        return state.but(dynamics={}) if state.dynamics else state

    def next_step(self, state: State) -> tuple[int, float] | None:
        """(step number, load factor) of the next increment after ``state``; None when the stage is done."""
        lam = self.control.target(state.lam)
        return None if lam is None else (state.step + 1, lam)

    def advance(self, u: np.ndarray, state: State, step: int, lam: float) -> Increment:
        """Make step ``step`` to load factor ``lam`` from the committed ``state`` (``u`` updated in place to the
        new committed displacement) and report it."""
        newton = self.newton
        stats0, time0 = dict(newton.stats), dict(newton.timing)
        if self.automatic:  # one converged increment per step: after cutbacks, the step ends where it got to
            success, outcomes, cutbacks, why, new = newton.advance(u, state.lam, lam, state, self.control.lo,
                                                                   single=True)
            lam = newton.converged_increments[-1][1] if success else lam
        else:
            success, outcomes, cutbacks, why, new = newton.advance(u, state.lam, lam, state)
        inc = Increment(step, state.lam, lam, success, outcomes, cutbacks, why, new if success else state,
                        ends_stage=success and self.control.target(lam) is None,
                        output=success and self.control.is_mark(lam))
        if success and self.automatic:  # how much the active set moved in the step (the increment control)
            inc.opened_closed, inc.active = self.model.active_set_change(state, new)
            inc.plastic_changed, inc.yielding = self.model.plastic_change(state, new)
        inc.entry = self._report(inc, u, stats0, time0)
        self.control.record(inc, newton.converged_increments)
        return inc

    def _reactions(self, u: np.ndarray, lam: float, state: State) -> dict:
        """The supports' resultant forces at the committed ``state`` (``reactions``)."""
        return reactions(self.model, u, lam, state)

    def _report(self, inc: Increment, u: np.ndarray, stats0: dict, time0: dict) -> dict:
        """The summary record of ``inc`` (its model reports computed at the new committed state)."""
        newton, model = self.newton, self.model
        conv = [o for o in inc.outcomes if o.converged]
        entry = {
            "step": inc.step,
            "load_factor": inc.lam,
            "converged": inc.success,
            "iterations": inc.iterations,
            "residual_norms": [r / max(o.residual_norms[0], 1e-300) for o in conv[-1:] for r in o.residual_norms]
            if conv else [],
            "cutbacks": inc.cutbacks,
            "factorizations": newton.stats["factorizations"] - stats0["factorizations"],
            "krylov_iterations": newton.stats["krylov_iterations"] - stats0["krylov_iterations"],
            "factor_s": round(newton.timing["factor"] - time0["factor"], 6),
            "krylov_s": round(newton.timing["krylov"] - time0["krylov"], 6),
        }
        if self.staged:
            entry["stage"] = self.spec.name
            entry["time"] = self.t_stage + inc.lam
        if self.automatic:
            entry["increment"] = inc.lam - inc.lam_a
        if self.augmented:
            entry["uzawa_iterations"] = sum(1 for o in inc.outcomes if o.augmentation > 0)
        backtracks = newton.stats.get("backtracks", 0) - stats0.get("backtracks", 0)
        if backtracks:  # Newton corrections shortened because their full length inverted an element
            entry["backtracks"] = backtracks
        searches = newton.stats.get("line_searches", 0) - stats0.get("line_searches", 0)
        if searches:  # Newton corrections the line search shortened
            entry["line_searches"] = searches
        if newton.stats.get("stabilised", 0) > stats0.get("stabilised", 0):  # a body held by contact alone
            entry["stabilised"] = True
        if inc.cutbacks:
            entry["cutback_reasons"] = [o.reason for o in inc.outcomes if not o.converged]
        if not inc.success:
            entry["failure"] = inc.why
            return entry
        state, lam = inc.state, inc.lam
        work = model.plastic_work(state)
        if work is not None:
            entry["plastic_dissipation"] = work - self.work
            entry["plastic_work"] = self.work = work
        state.step = inc.step
        entry.update(model.step_report(u, lam, state))
        entry["reactions"] = self._reactions(u, lam, state)
        rigid = model.rigid_report(u, lam, state)
        if rigid:
            entry["rigid_bodies"] = rigid
        return entry


def reactions(model, u: np.ndarray, lam: float, state: State, R: np.ndarray | None = None) -> dict:
    """The resultant reaction of every Dirichlet condition in force (released ones are left out): the residual ``R``
    (default the quasi-static one at ``u``) summed over its nodes, on its components; conditions on different
    components of one node set share its entry."""
    if R is None:
        R, _, _ = model.evaluate(u, lam, state, want_K=False)
    out = {}
    held = {c.name for c in model.loading.spec.conditions}
    for i, bc in enumerate(model.problem.dirichlet):
        if (bc.name or f"#{i}") not in held:
            continue
        nodes = model.system.global_nodes(bc.body, bc.set)
        total = R.reshape(-1, 3)[nodes].sum(axis=0)
        comp = np.zeros(3, dtype=bool)
        comp[list(bc.components)] = True
        key = f"{bc.body}.{bc.set}"  # (conditions on one set, each on its components: one entry of them all)
        out[key] = np.where(comp, total, out.get(key, 0.0)).tolist()
    return out
