"""Run a Problem: one procedure per stage, observers for everything that records the run.

``Run.execute`` reads like the algorithm: start (or resume from a checkpoint), then for each stage enter it
and let its procedure advance one increment at a time until the stage is done or a step fails; every event
goes to the observers (docs/architecture.md), which write the files, print the progress and keep their part
of a checkpoint. How the model is built and how a failure is handled on several MPI ranks is the run's
*strategy*: ``SerialRun`` here, the distributed one supplied by ``covcontact.parallel`` through the linear
solver that distributes (``LinearSolver.run_strategy``).
"""

from __future__ import annotations

import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

import numba
import numpy as np
from threadpoolctl import ThreadpoolController

from ..io import checkpoint
from ..io.checkpoint import CheckpointError
from ..io.observers import Checkpoints, Convergence, Pictures, Progress, Results, Summary
from ..io.output import ResultWriter, atomic_write_text
from .choice import auto_line, distributes, run_solver
from .model import Model
from .newton import Newton
from .procedure import QuasiStatic, increment_control
from .signals import Interrupted, StopSignals
from .state import State


@dataclass
class Result:
    """What a run produced: the summary dict, the final displacement and the exit code (0, 1, 130, 143)."""

    summary: dict
    u: np.ndarray
    out: Path
    exit_code: int
    model: Model = field(repr=False, default=None)
    state: State = field(repr=False, default=None)  # the committed state of the last converged step


class SerialRun:
    """The strategy of a run in one process: the serial model; a failure is the process's own."""

    def make_model(self, problem, tangent: str | None) -> Model:
        return Model(problem, tangent=tangent)

    def execute(self, model, run):
        return run()

    def check_resumed(self, model, state: State, out: Path) -> None:
        pass

    def signal_comm(self, model):
        return None


def strategy_for(linear: str):
    """The run strategy of the linear solver ``linear``: its own where it distributes (``petsc*``), else serial."""
    if distributes(linear):
        from .linear import backend_class

        return backend_class(linear).run_strategy()
    return SerialRun()


def stage_steps(problem) -> list:
    """The ``Steps`` of every stage of ``problem``, the first stage first."""
    return [problem.steps] + [st.steps for st in problem.stages]


def _tangent_name(problem, tangent: str | None) -> str:
    """The tangent case of the run: the override, else the pairs' common case (or "per-pair")."""
    if tangent:
        return tangent
    cases = {c.tangent for c in problem.contacts}
    return cases.pop() if len(cases) == 1 else ("a" if not cases else "per-pair")


def solve_problem(problem, out=None, tangent=None, quiet=True, linear=None, resume=False,
                  observers=(), strict: bool = False) -> Result:
    """Solve ``problem`` and write its results; see ``Problem.run``.

    With a distributing backend (``petsc``, ``petsc-gamg``) every MPI rank runs this function; only
    rank 0 writes files and prints. ``observers``: more observers of the run's events
    (``covcontact.observer.Observer``), called after the run's own.
    """
    # numpy's and scipy's OpenBLAS on one thread for the run: no vector operation of a run gains from threads,
    # but a threaded call leaves OpenBLAS's workers spinning for a while afterwards, and they take the cores
    # from numba's element assembly and PARDISO (measured: assembly 1.5-2x slower on 2 cores); MKL untouched
    with ThreadpoolController().select(internal_api="openblas").limit(limits=1):
        t_start = time.perf_counter()
        out = Path(out) if out is not None else Path("results") / problem.name
        requested, linear = run_solver(problem, linear)
        strategy = strategy_for(linear)
        model = strategy.make_model(problem, tangent)
        if linear != requested and not quiet and model.is_root:
            print(auto_line(linear, model.size, numba.get_num_threads() > 1), file=sys.stderr, flush=True)
        run = Run(problem, model, out, tangent, quiet, linear, t_start, strategy, list(observers))
        run.strict = strict
        return strategy.execute(model, lambda: run.execute(resume))


class Run:
    """One run of a problem: its model, Newton solver, displacement ``u``, committed ``state``, the
    procedure of the current stage and the observers of its events."""

    def __init__(self, problem, model, out: Path, tangent: str | None, quiet: bool, linear: str,
                 t_start: float, strategy, extra_observers: list):
        self.problem, self.model, self.out, self.strategy = problem, model, out, strategy
        self.t_start = t_start
        self.newton = Newton(model, problem.solver, linear=linear)
        self.case = _tangent_name(problem, tangent)
        self.problem_hash = checkpoint.fingerprint(problem) + ":" + self.case
        self.u = model.prescribed(0.0)
        self.state = model.initial_state()
        plan = model.stages
        self.n_stages = len(plan)
        counts = [st.count for st in stage_steps(problem)]
        self.n_steps = None if None in counts else sum(counts)  # None: automatic increments somewhere
        self.procedure = None
        self.warnings: list[str] = []
        self.interruption: Interrupted | None = None
        self.summary_timing: dict = {}
        self.total_time = 0.0
        self.stop_status: str | None = None  # set by an observer to end the run after the current step
        self.strict = False  # the first step whose energy grows ends the run as failed (``--strict``)
        self.control_state: dict = {}  # the increment control's state of a resumed stage (from the checkpoint)
        #: why a failed run failed (summary.json: ``reason``, ``failed_step`` or ``error``; ``last_converged``)
        self.failure: dict | None = None
        self.partition = model.partition_report()  # collective under mpiexec
        root = model.is_root
        writer = ResultWriter(out) if root else None
        self.progress = Progress(quiet, enabled=root)
        self.summary = Summary(writer)
        self.summary.header(self)
        # computed on every rank (collective), written by the first
        self.results = Results(writer, problem.output.every) if problem.output.vtu else None
        # what a checkpoint holds besides u and the committed state, each part its own
        convergence = Convergence(writer) if writer else None
        self.parts = [self.summary, *(p for p in (self.results, convergence) if p is not None), self.newton,
                      self.model, self.newton.linear, self]
        out_obs = [convergence] if convergence else []
        if self.results is not None:
            out_obs.append(self.results)
        out_obs += [self.summary, Checkpoints(out, problem.output.checkpoint_every, self.problem_hash, self.parts,
                                              model.rank, model.size)]
        if root and problem.output.pictures and problem.output.vtu:
            out_obs.append(Pictures(out, self.progress.say))
        self.observers = [*out_obs, self.progress, *extra_observers]

    def checkpoint(self) -> tuple[dict, dict]:
        """The run's own part of a checkpoint: its increment control's state in the current stage."""
        if self.procedure is None:
            return {}, {}
        return {}, {"increment_control": {"stage": self.procedure.spec.index, **self.procedure.control.state()}}

    def restore(self, arrays: dict, meta: dict) -> None:
        self.control_state = dict(meta.get("increment_control") or {})

    def emit(self, event: str, *args) -> None:
        for obs in self.observers:
            getattr(obs, event)(self, *args)

    def request_stop(self, status: str) -> None:
        """End the run after the step in hand with ``status`` (an observer's request, e.g. check-tangent's)."""
        self.stop_status = status

    # ------------------------------------------------------------------------------------------
    def execute(self, resume: bool) -> Result:
        """Run (or resume) to the end. Every way out leaves summary.json with the run's status: ``completed``,
        ``failed`` (a step that did not converge after its cutbacks, or an exception: the exception is raised again
        once the summary says so) or ``interrupted``; a checkpoint that cannot be resumed leaves the folder as it
        was."""
        try:
            return self._execute(resume)
        except CheckpointError:
            raise
        except Exception as exc:
            self._crashed(exc)
            raise

    def _execute(self, resume: bool) -> Result:
        status, code = "completed", 0
        if resume:
            self._resume()
        else:
            self._start()
        with StopSignals(comm=self.strategy.signal_comm(self.model)) as stops:
            self.newton.poll = stops.poll  # distributed: every rank stops at the same Newton iteration
            try:
                status = self._stages(stops)
                code = 1 if status == "failed" else 0
            except (Interrupted, SystemError) as exc:
                stop = _interruption(exc)
                if stop is None:
                    raise
                status, code, self.interruption = "interrupted", stop.exit_code, stop
            with stops.critical():
                self._end(status)
        return Result(summary=self.summary.data, u=self.u, out=self.out, exit_code=code, model=self.model,
                      state=self.state)

    def _start(self) -> None:
        model, newton = self.model, self.newton
        self.warnings = model.start_warnings(self.u, self.state)
        if self.problem.solver.factorization_precision == "single" and newton.linear.precision_report() is None:
            self.warnings.append(f'factorization_precision = "single" is for PARDISO; the linear solver '
                                 f'{newton.linear.name} factorises in double precision')
        self._forget_crash()
        self.emit("started")

    def _resume(self) -> None:
        model = self.model
        u, arrays, meta = checkpoint.load(self.out, self.problem_hash, model.rank, model.size)
        for part in self.parts:
            part.restore(arrays, meta)
        try:
            state = State.from_arrays(arrays, like=self.state)
        except (KeyError, ValueError) as exc:
            raise checkpoint.CheckpointError(f"{checkpoint.path_for(self.out, model.rank, model.size)}: does not "
                                             f"match the problem ({exc})") from None
        self.strategy.check_resumed(model, state, self.out)
        self.u, self.state = u, state
        model.set_stage(state)
        self._forget_crash()
        self.emit("resumed")

    def _stages(self, stops) -> str:
        """Every stage from the committed state's on; the run's status."""
        model, plan = self.model, self.model.stages
        for si in range(self.state.stage, len(plan)):
            spec = plan[si]
            entering = si > self.state.stage
            if entering:
                self.state = model.enter_stage(self.u, self.state)
                self.newton.linear.set_near_null_space(model.near_null_space())
            t_stage = sum(q.lam_end for q in plan.stages[:si])     # the earlier stages' total pseudo-time
            control = increment_control(spec, stage_steps(self.problem)[si], self.problem.stage_dynamics(si))
            if self.control_state.get("stage") == si:  # resumed inside this stage
                control.restore(self.control_state)
            dyn = self.problem.stage_dynamics(si)
            if dyn is None:
                self.procedure = QuasiStatic(model, self.newton, spec, t_stage, len(plan) > 1, control)
            else:
                from .dynamics import Dynamic

                t_start = sum(d.t_end if (d := self.problem.stage_dynamics(k)) is not None else plan.stages[k].lam_end
                              for k in range(si))
                self.procedure = Dynamic(model, self.newton, spec, t_stage, len(plan) > 1, control, dyn,
                                         self.problem, t_start)
            self.state = self.procedure.start(self.state, self.u)
            self.emit("stage_entered", self.procedure, entering)
            while (nxt := self.procedure.next_step(self.state)) is not None:
                self.emit("increment_started", *nxt)
                inc = self.procedure.advance(self.u, self.state, *nxt)
                with stops.critical():
                    if not inc.success:
                        failed = {"step": inc.step, "stage": spec.name, "load_factor": inc.lam}
                        failed.update({k: inc.entry[k] for k in ("time", "increment") if k in inc.entry})
                        self.failure = {"reason": f"step {inc.step} (load factor {inc.lam:.4g}) failed after "
                                                  f"{inc.cutbacks} cutbacks: {inc.why}", "failed_step": failed}
                        self.emit("increment_failed", inc)
                        return "failed"
                    self.state = inc.state
                    self.emit("increment_converged", inc)
                    growth = inc.entry.get("energy_warning")
                    if self.strict and growth is not None:  # (the step is kept: it converged)
                        self.failure = {"reason": f"--strict: step {inc.step}: {growth}"}
                        return "failed"
                stops.poll()
                if self.stop_status is not None:
                    return self.stop_status
        return "completed"

    def _forget_crash(self) -> None:
        """The traceback.txt of an earlier run in the folder goes (it would belong to none of this run's files)."""
        if self.model.is_root:
            (self.out / "traceback.txt").unlink(missing_ok=True)

    def last_converged(self) -> dict:
        """The committed state's step (0: none converged yet), its stage, load factor and (dynamic stages) time."""
        st = self.state
        out = {"step": int(st.step), "stage": self.model.stages[st.stage].name, "load_factor": float(st.lam)}
        if st.dynamics and "time" in st.dynamics:
            out["time"] = float(st.dynamics["time"])
        return out

    def _crashed(self, exc: BaseException) -> None:
        """An exception ends the run: summary.json says ``failed`` with the exception and the last converged step,
        and the traceback goes to ``traceback.txt`` beside it (named on ``exc`` as ``covcontact_traceback``)."""
        root = exc
        while isinstance(root, SystemError) and (root.__cause__ or root.__context__) is not None:
            root = root.__cause__ or root.__context__  # numba wraps an exception of compiled code so
        frames = traceback.extract_tb(exc.__traceback__)
        where = ""
        if frames:
            f = frames[-1]
            path = Path(f.filename)
            parts = path.parts
            name = "/".join(parts[parts.index("covcontact") + 1:]) if "covcontact" in parts else path.name
            where = f"{name}:{f.lineno} in {f.name}"
        message = " ".join(str(root).split())
        error = {"type": type(root).__name__, "message": message, "where": where}
        if self.model.is_root:
            path = self.out / "traceback.txt"
            try:
                self.out.mkdir(parents=True, exist_ok=True)
                atomic_write_text(path, "".join(traceback.format_exception(exc)))
                error["traceback"] = path.name
                exc.covcontact_traceback = str(path)
            except OSError:  # (a folder that cannot take it: the summary is what matters)
                pass
        self.failure = {"reason": f"{error['type']}: {message}" + (f" ({where})" if where else ""), "error": error}
        try:
            self._end("failed")
        except Exception:  # noqa: BLE001  (an observer that cannot finish after the error: the summary alone)
            self.summary.ended_status(self, "failed")

    def _end(self, status: str) -> None:
        timing = dict(self.newton.timing)
        split = self.model.contact.timing
        timing["contact_search"] = split["search"]
        timing["contact_projection"] = split["projection"]
        timing["contact_assembly"] = max(timing["contact"] - split["search"] - split["projection"], 0.0)
        timing["output"] = self.results.seconds if self.results is not None else 0.0
        self.total_time = timing["total"] = time.perf_counter() - self.t_start
        self.summary_timing = {k: round(v, 4) for k, v in timing.items()}
        self.emit("ended", status)


def _interruption(exc: BaseException) -> Interrupted | None:
    """The Interrupted behind ``exc``: itself, or the cause of a SystemError (a signal that arrived while
    compiled code called back into Python, e.g. numba loading a cached function, comes out wrapped so)."""
    while exc is not None:
        if isinstance(exc, Interrupted):
            return exc
        exc = exc.__cause__ or exc.__context__
    return None
