"""``covcontact check-tangent``: the assembled tangent against finite differences of the residual.

The state checked is the one ``covcontact run`` reaches at a step (any stage, cutbacks included): the run
itself is driven up to the step and its last converged increment is captured, so the tangent is compared at
the displacement, load factor, committed history and stage that Newton saw when it converged (docs/input.md,
"Checking the tangent").

Every chosen column c of the tangent is compared with differences of the residual R(u +- h e_c) at several
step sizes h. A perturbation that changes a status of the state (a Gauss point yielding or unloading, a slave
node opening or closing, stick/slip, a contact point moving onto another facet, an edge or a vertex) crosses
a kink of R, where no difference quotient approximates the one-sided derivative the tangent is: such a
column is judged only at step sizes at which neither side changes a status (at the one that agrees best:
a wrong tangent disagrees at every step size), and listed as a kink when there is none. The verdict is the relative error over the judged columns.
"""

from __future__ import annotations

import copy
import tempfile
from dataclasses import dataclass, field, replace

import numpy as np

from .observer import Observer
from .solvers.model import Model
from .solvers.state import State

#: the step sizes of the differences, as fractions of the first (``h``)
H_RATIOS = (1.0, 1e-1, 1e-2)
#: relative distance of xi to the edge of its facet below which a contact point lies on the edge
ON_EDGE = 1e-12
#: how many kink columns and worst columns the text report lists
LISTED = 12


@dataclass
class Reached:
    """The state a run reaches at a step: the converged displacement ``u`` at load factor ``lam`` of stage
    ``stage``, the committed state the step's last increment started from and its converged trial (the
    starting point of local iterations), or why the run did not get there."""

    model: Model
    step: int
    stage: str
    lam: float
    u: np.ndarray | None = None
    committed: State | None = None
    guess: State | None = None
    converged: bool = True
    reason: str = ""
    exit_code: int = 0
    cutbacks: int = 0  # the cutbacks the run made up to and in the step


class _Probe(Observer):
    """An observer that stops a run after a step and keeps that step's last converged increment: step ``step``
    counted over all stages, or with ``stage`` (an index) the ``step``-th step of that stage."""

    def __init__(self, step: int, stage: int | None = None):
        self.step, self.stage = step, stage
        self.in_stage = 0  # steps started in the current stage
        self.current = -1  # the current stage's index
        self.last = None
        self.found: tuple[int, str] | None = None  # (step over all stages, stage name) of the step checked

    def stage_entered(self, run, procedure, entering: bool) -> None:
        self.current, self.in_stage = procedure.spec.index, 0

    def _wanted(self, step: int) -> bool:
        return step == self.step if self.stage is None else (self.current == self.stage and self.in_stage == self.step)

    def increment_started(self, run, step: int, lam: float) -> None:
        self.in_stage += 1
        wanted = self._wanted(step)
        if wanted:
            self.found = (step, run.procedure.spec.name)
        run.newton.on_converged = self.increment if wanted else None

    def increment(self, u, lam_a, lam_b, committed, trial) -> None:
        self.last = (u.copy(), lam_b, committed, trial)

    def increment_converged(self, run, inc) -> None:
        if self._wanted(inc.step):
            run.request_stop("stopped")


def stage_steps(problem) -> list[tuple[str, int | None]]:
    """(name, number of steps; None where the stage chooses its increments) of every stage, the first first."""
    from .solvers.run import stage_steps as steps_of

    names = [problem.stage_name] + [st.name for st in problem.stages]
    return [(name, steps.count) for name, steps in zip(names, steps_of(problem))]


def serial_solver(problem, solver: str | None) -> str | None:
    """The linear solver of the check's run: the run's own, unless it would distribute the model over MPI
    ranks (the check differences the serial model): then the first direct solver."""
    from .solvers.choice import distributes, resolve_linear

    name = resolve_linear(problem, solver, ranks=1)
    return "auto" if distributes(name) else solver


def reach(problem, step: int, tangent: str | None = None, solver: str | None = None,
          stage: int | None = None) -> Reached:
    """Run ``problem`` as ``covcontact run`` does up to ``step`` (counted over all stages; 0: the undeformed
    start; with ``stage``, an index, the ``step``-th step of that stage) and return the state of its last
    converged increment. ``tangent``: the run's ``--tangent`` (None: each pair's own case, as ``covcontact
    run`` without the option)."""
    if step == 0:
        model = Model(problem, tangent=tangent)
        committed = model.initial_state()
        return Reached(model, 0, problem.stage_name, 0.0, model.prescribed(0.0), committed,
                       model.start_step(committed))
    from .solvers.run import solve_problem

    prob = copy.copy(problem)
    prob.output = replace(problem.output, vtu=False, pictures=False, checkpoint_every=10**9)
    probe = _Probe(step, stage)
    with tempfile.TemporaryDirectory() as tmp:
        res = solve_problem(prob, out=tmp, tangent=tangent, quiet=True, linear=serial_solver(problem, solver),
                            observers=[probe])
    steps = res.summary["steps"]
    number, name = probe.found if probe.found is not None else (step, problem.stage_name)
    if probe.last is None or res.exit_code != 0 or not steps or steps[-1]["step"] != number:
        last = steps[-1] if steps else {}
        if last and not last.get("converged", True):
            why = f"step {last.get('step')} did not converge: {last.get('failure', '')}"
        elif res.summary["status"] == "completed":
            where = f"stage {stage_steps(problem)[stage][0]!r}" if stage is not None else "the run"
            why = f"{where} ends before step {step}"
        else:
            why = f"the run ended with status {res.summary['status']!r}"
        return Reached(res.model, number, name, float("nan"), converged=False, reason=why,
                       exit_code=res.exit_code or 1)
    u, lam, committed, trial = probe.last
    return Reached(res.model, number, name, lam, u, committed, trial,
                   cutbacks=sum(int(e.get("cutbacks", 0)) for e in steps))


# statuses ------------------------------------------------------------------------------------------------
def statuses(model, state: State) -> dict[str, np.ndarray]:
    """Every status of ``state`` whose change marks a kink of the residual, as integer arrays: per Gauss
    point of a J2 body whether it yields in the step; per slave node of a contact pass whether it is active,
    its friction status, its facet, its place on the facet (0 inside, 1 edge, 2 vertex) and its edge lock."""
    from .materials.plasticity import H_FLAG, J2

    out: dict[str, np.ndarray] = {}
    for blk, est in zip(model.system.blocks, state.elements):
        hist = est.get("hist")
        if hist is not None and hist.shape[-1] > H_FLAG and blk.solid.material.kind == J2:
            out[f"{blk.name}|plastic"] = (hist[..., H_FLAG] > 0).astype(np.int64)
    for k, (p, s) in enumerate(zip(model.contact.passes, state.contact.passes)):
        out[f"{p.name}|active"] = model.contact.active_mask(k, state.contact).astype(np.int64)
        if p.mu > 0.0:
            out[f"{p.name}|friction"] = s.status.astype(np.int64)
        if p.surface is not None:
            on = (np.abs(np.abs(s.xi) - 1.0) <= ON_EDGE).sum(axis=1)
            out[f"{p.name}|facet"] = s.facet.astype(np.int64)
            out[f"{p.name}|place"] = np.where(s.facet >= 0, on, 0).astype(np.int64)
            out[f"{p.name}|edge_lock"] = s.edge_lock.astype(np.int64)
    return out


_WORDS = {"plastic": ("elastic", "yielding"), "active": ("open", "closed"),
          "friction": ("open", "stick", "slip", "new"), "place": ("inside its facet", "on an edge", "on a vertex")}


def describe_changes(model, ref: dict[str, np.ndarray], new: dict[str, np.ndarray]) -> list[str]:
    """What changed between two status dicts, one short phrase per kind of status."""
    out = []
    blocks = {blk.name: blk for blk in model.system.blocks}
    passes = {p.name: p for p in model.contact.passes}
    for key, a in ref.items():
        b = new[key]
        where = np.flatnonzero((a != b).ravel())
        if not where.size:
            continue
        owner, kind = key.split("|")
        i = int(where[0])
        words = _WORDS.get(kind)

        def say(v, words=words, kind=kind):
            return words[int(v)] if words is not None and 0 <= int(v) < len(words) else f"{kind} {int(v)}"
        if owner in blocks:  # Gauss points: (nelem, ngp)
            ngp = a.shape[1] if a.ndim > 1 else 1
            e, g = divmod(i, ngp)
            what = f"{owner}: {where.size} Gauss point(s) {say(a.ravel()[i])} -> {say(b.ravel()[i])} " \
                   f"(element {e}, point {g})"
        else:
            node = int(passes[owner].slaves[i]) if owner in passes else i
            if kind in ("facet", "edge_lock"):
                change = f"{kind} {int(a[i])} -> {int(b[i])}"
            else:
                change = f"{say(a[i])} -> {say(b[i])}"
            what = f"contact {owner}: {where.size} slave node(s) {change} (node {node})"
        out.append(what)
    return out


# columns ------------------------------------------------------------------------------------------------
def dof_label(model, dof: int) -> str:
    """A dof in words: the body, its local node and the component (or a rigid body's reference node)."""
    node, comp = divmod(int(dof), 3)
    sysm = model.system
    for blk in sysm.blocks:
        if blk.offset <= node < blk.offset + blk.n_nodes:
            return f"{blk.name} node {node - blk.offset} {'xyz'[comp]}"
    for ref in getattr(sysm, "reference", []):
        if node == ref.A:
            return f"rigid {ref.name} translation {'xyz'[comp]}"
        if node == ref.B:
            return f"rigid {ref.name} rotation {'xyz'[comp]}"
    return f"node {node} {'xyz'[comp]}"


def zones(model, state: State) -> dict[str, np.ndarray]:
    """The free dofs of the contact zone (nodes of active contact elements and slave nodes about to touch)
    and of the plastic zone (nodes of elements with a Gauss point that yields in the step, else with plastic
    strain)."""
    from .materials.plasticity import H_ALPHA, H_FLAG, J2

    free = model.free
    span = float(np.ptp(model.system.X, axis=0).max()) if model.system.X.size else 1.0
    nodes = [model.contact.coupled_dofs(state.contact) // 3]
    for k, (p, s) in enumerate(zip(model.contact.passes, state.contact.passes)):
        near = np.isfinite(s.gap) & (s.gap < 1e-3 * span)
        nodes.append(p.slaves[near])
    contact = np.unique(np.concatenate(nodes)).astype(np.int64) if nodes else np.zeros(0, np.int64)
    contact = contact[contact < model.system.n_deformable]
    plastic = []
    for blk, est in zip(model.system.blocks, state.elements):
        hist = est.get("hist")
        if hist is None or hist.shape[-1] <= H_FLAG or blk.solid.material.kind != J2:
            continue
        yielding = np.flatnonzero(hist[..., H_FLAG].max(axis=1) > 0)
        if not yielding.size:
            yielding = np.flatnonzero(hist[..., H_ALPHA].max(axis=1) > 0)
        plastic.append(blk.solid.element_nodes(yielding) + blk.offset)
    plastic_nodes = np.unique(np.concatenate(plastic)) if plastic else np.zeros(0, np.int64)

    def dofs(n):
        d = (3 * np.asarray(n, dtype=np.int64)[:, None] + np.arange(3)).ravel()
        return d[free[d]]
    return {"contact": dofs(contact), "plastic": dofs(plastic_nodes)}


def choose_columns(model, state: State, columns: int | None, seed: int = 0) -> tuple[np.ndarray, dict]:
    """The dofs to difference: every free dof (``columns`` None or at least their number), else a share of
    the budget for the contact zone, one for the plastic zone (random samples within each where it is
    larger) and the rest drawn from the other free dofs. Returns (sorted dofs, count per zone)."""
    free = np.flatnonzero(model.free)
    z = zones(model, state)
    counts = {"contact": int(np.intersect1d(z["contact"], free).size),
              "plastic": int(np.intersect1d(z["plastic"], free).size)}
    if columns is None or len(free) <= columns:
        return free, {**counts, "other": int(len(free) - len(np.union1d(z["contact"], z["plastic"])))}
    rng = np.random.default_rng(seed)
    chosen = np.zeros(0, np.int64)
    groups = [g for g in ("contact", "plastic") if z[g].size]
    share = columns // (len(groups) + 1)
    picked = {}
    for g in groups:
        pool = np.setdiff1d(z[g], chosen)
        take = pool if len(pool) <= share else rng.choice(pool, share, replace=False)
        picked[g] = len(take)
        chosen = np.union1d(chosen, take)
    pool = np.setdiff1d(free, chosen)
    rest = columns - len(chosen)
    take = pool if len(pool) <= rest else rng.choice(pool, rest, replace=False)
    picked["other"] = len(take)
    return np.union1d(chosen, take), picked


# the check ----------------------------------------------------------------------------------------------
@dataclass
class ColumnCheck:
    """The differences of one column: squared errors per step size (central, forward, backward), whether each
    side changed a status, and what changed (at the first step size at which it did)."""

    dof: int
    k2: float
    central: list[float] = field(default_factory=list)
    forward: list[float] = field(default_factory=list)
    backward: list[float] = field(default_factory=list)
    plus_smooth: list[bool] = field(default_factory=list)
    minus_smooth: list[bool] = field(default_factory=list)
    changes: list[str] = field(default_factory=list)

    def judged_at(self) -> int | None:
        """The index of the step size at which the column is judged: among those at which neither side
        changes a status, the one whose central difference agrees best with the tangent (a wrong tangent
        disagrees at every step size; a right one agrees better until round-off takes over). None: there is
        no such step size."""
        smooth = [i for i, (p, m) in enumerate(zip(self.plus_smooth, self.minus_smooth)) if p and m]
        return min(smooth, key=lambda i: self.central[i]) if smooth else None


def difference_columns(model, u, lam, committed, guess, cols, hs, R0, K, ref) -> list[ColumnCheck]:
    """Differences of R for every dof in ``cols`` at every step size of ``hs``, compared with K's columns."""
    free = model.free
    K = K.tocsc()
    out = []
    for c in cols:
        kc = K[:, [c]].toarray().ravel()[free]
        col = ColumnCheck(int(c), float(kc @ kc))
        for h in hs:
            sides = []
            for sign in (1.0, -1.0):
                up = u.copy()
                up[c] += sign * h
                R, _, trial = model.evaluate(up, lam, committed, guess, want_K=False)
                new = statuses(model, trial)
                changed = describe_changes(model, ref, new)
                side = "forward" if sign > 0 else "backward"
                if changed and not any(w.startswith(side) for w in col.changes):
                    col.changes += [f"{side}: {w}" for w in changed]
                sides.append((R[free], not changed))
            (rp, ok_p), (rm, ok_m) = sides
            r0 = R0[free]
            for store, fd in ((col.central, (rp - rm) / (2 * h)), (col.forward, (rp - r0) / h),
                              (col.backward, (r0 - rm) / h)):
                d = kc - fd
                store.append(float(d @ d))
            col.plus_smooth.append(ok_p)
            col.minus_smooth.append(ok_m)
        out.append(col)
    return out


def _rel(err2: float, ref2: float) -> float:
    return float(np.sqrt(err2) / max(np.sqrt(ref2), 1e-300))


def check_tangent(problem, step: int = 1, tangent: str = "exact", columns: int | None = 60, seed: int = 0,
                  h: float | None = None, solver: str | None = None, run_tangent: str | None = None,
                  stage: int | None = None) -> dict:
    """Reach ``step`` as a run does (:func:`reach`, with the tangent case ``run_tangent``, default each
    pair's own) and compare the tangent of case ``tangent`` with differences of the residual there.

    ``columns``: how many tangent columns to difference (None: every free dof), chosen by
    :func:`choose_columns`; ``h``: the first step size (default 1e-7 times the largest coordinate, at least
    1e-7), the others ``H_RATIOS`` of it. Returns a dict: ``relative_error`` (over the judged columns, each at
    :meth:`ColumnCheck.judged_at`, Frobenius norm over the free rows),
    ``converged`` (the run reached the step; else ``reason``), ``step``, ``stage``, ``load_factor``,
    ``columns``, ``judged``, ``kinks`` (one entry per column whose perturbation at the first step size
    changes a status: dof, label, what changed, the step size it was judged at or None), ``by_step_size``
    (relative errors of the central, forward and backward differences over the columns smooth at every step
    size), ``worst`` (the columns with the largest errors) and ``residual_norm`` of the checked state.
    """
    reached = reach(problem, step, run_tangent, solver, stage)
    base = {"step": reached.step, "stage": reached.stage, "load_factor": reached.lam, "converged": reached.converged,
            "cutbacks": reached.cutbacks}
    if not reached.converged:
        return {**base, "relative_error": float("nan"), "columns": 0, "reason": reached.reason,
                "exit_code": reached.exit_code}
    u, lam, committed, guess = reached.u, reached.lam, reached.committed, reached.guess
    # the state is checked with the tangent case asked for, whatever case the run solved with
    model = Model(problem, tangent=tangent)
    model.set_stage(committed)
    model.begin_step()
    R0, K, trial = model.evaluate(u, lam, committed, guess, want_K=True)
    ref = statuses(model, trial)
    cols, picked = choose_columns(model, trial, columns, seed)
    if h is None:
        h = 1e-7 * max(float(np.abs(model.system.X).max()), 1.0)
    hs = [h * r for r in H_RATIOS]
    checks = difference_columns(model, u, lam, committed, guess, cols, hs, R0, K, ref)

    judged = [(c, c.judged_at()) for c in checks if c.judged_at() is not None]
    err2 = sum(c.central[i] for c, i in judged)
    ref2 = sum(c.k2 for c, _ in judged)
    smooth = [c for c in checks if all(c.plus_smooth) and all(c.minus_smooth)]
    by_h = []
    for i, hh in enumerate(hs):
        k2 = sum(c.k2 for c in smooth)
        by_h.append({"h": hh, "central": _rel(sum(c.central[i] for c in smooth), k2),
                     "forward": _rel(sum(c.forward[i] for c in smooth), k2),
                     "backward": _rel(sum(c.backward[i] for c in smooth), k2)})
    kinks = []
    for c in checks:
        if c.plus_smooth[0] and c.minus_smooth[0]:
            continue
        i = c.judged_at()
        entry = {"dof": c.dof, "label": dof_label(model, c.dof), "changes": c.changes,
                 "judged_at": None if i is None else hs[i],
                 "error": None if i is None else _rel(c.central[i], c.k2)}
        if i is None:  # the best one-sided estimate: the smallest step size with a smooth side
            for j in reversed(range(len(hs))):
                if c.plus_smooth[j] or c.minus_smooth[j]:
                    side = "forward" if c.plus_smooth[j] else "backward"
                    entry["one_sided"] = {"side": side, "h": hs[j],
                                          "error": _rel(getattr(c, side)[j], c.k2)}
                    break
        kinks.append(entry)
    worst = sorted(judged, key=lambda ci: -ci[0].central[ci[1]])[:5]
    scale = max(float(np.linalg.norm(model.external(lam))), float(np.linalg.norm(R0)), 1e-300)
    return {**base, "relative_error": _rel(err2, ref2) if judged else float("nan"),
            "columns": len(cols), "judged": len(judged), "zones": picked, "h": hs,
            "by_step_size": by_h, "smooth_columns": len(smooth), "kinks": kinks,
            "worst": [{"dof": c.dof, "label": dof_label(model, c.dof), "h": hs[i],
                       "error": _rel(c.central[i], c.k2)} for c, i in worst],
            "residual_norm": float(np.linalg.norm(R0[model.free])), "force_scale": scale,
            "tangent": tangent}


def report_lines(rep: dict, tol: float) -> list[str]:
    """The text report of :func:`check_tangent`: the error and the verdict first, then the details."""
    where = f"step {rep['step']} (stage {rep['stage']!r}, load factor {rep['load_factor']:.6g})"
    if not rep["converged"]:
        return [f"{where}: not reached: {rep['reason']}", "NOT CHECKED: the run does not reach this step"]
    err = rep["relative_error"]
    lines = [(f"{where}  tangent {rep['tangent']}  columns {rep['columns']} (judged {rep['judged']})  "
              f"relative error {err:.3e}")]
    if not rep["judged"]:
        lines.append("NO VERDICT: every column's perturbation changes a status at every step size")
    else:
        ok = err <= tol
        lines.append(f"{'PASS' if ok else 'FAIL'}: relative error {err:.3e} {'<=' if ok else '>'} tol {tol:.1e}"
                     + ("" if ok or rep["tangent"] == "exact" else
                        f" (case {rep['tangent']} leaves out parts of the exact Hessian; compare with "
                        f"--tangent exact)"))
    z = rep["zones"]
    lines.append("columns: " + ", ".join(f"{v} {k}" for k, v in z.items()) + f"; residual of the state "
                 f"{rep['residual_norm']:.2e} (force scale {rep['force_scale']:.2e}); reached after "
                 f"{rep['cutbacks']} cutback(s)")
    lines.append(f"differences over the {rep['smooth_columns']} columns that change no status at any step size "
                 "(relative error):")
    lines.append(f"  {'h':>10}  {'central':>10}  {'forward':>10}  {'backward':>10}")
    for row in rep["by_step_size"]:
        lines.append(f"  {row['h']:10.2e}  {row['central']:10.2e}  {row['forward']:10.2e}  {row['backward']:10.2e}")
    kinks = rep["kinks"]
    if kinks:
        lines.append(f"kinks: {len(kinks)} column(s) whose perturbation by h = {rep['h'][0]:.2e} changes a status "
                     "(judged at a step size that changes none, else left out of the verdict):")
        for k in kinks[:LISTED]:
            how = (f"judged at h = {k['judged_at']:.1e}: {k['error']:.2e}" if k["judged_at"] is not None else
                   "at the kink" + (f"; {k['one_sided']['side']} difference at h = {k['one_sided']['h']:.1e}: "
                                    f"{k['one_sided']['error']:.2e}" if "one_sided" in k else "")
                   + " (not judged)")
            lines.append(f"  {k['label']}: {'; '.join(k['changes'])}; {how}")
        if len(kinks) > LISTED:
            lines.append(f"  ... and {len(kinks) - LISTED} more (--json FILE lists them all)")
    else:
        lines.append("kinks: none (no perturbation changes a status)")
    if rep["worst"]:
        lines.append("largest column errors: " + "; ".join(f"{w['label']} {w['error']:.2e}" for w in rep["worst"]))
    return lines
