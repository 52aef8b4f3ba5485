"""Run a Problem: load steps, Newton with cutbacks, progress lines and result files."""

from __future__ import annotations

import json
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

import numba
import numpy as np
from threadpoolctl import ThreadpoolController

from ..io import checkpoint
from ..io.output import ResultWriter, _jsonable
from ..io.validate import InputError
from ..parallel.launcher import ranks_from_env
from .model import Model
from .newton import Newton
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


def _reactions(model: Model, u: np.ndarray, lam: float, state) -> dict:
    """The resultant reaction of every Dirichlet condition in force (released ones are left out)."""
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
        out[f"{bc.body}.{bc.set}"] = np.where(comp, total, 0.0).tolist()
    return out


def _write_vtu(writer: ResultWriter, model: Model, u: np.ndarray, lam: float, step: int, state,
               time_value: float | None = None) -> None:
    sysm = model.system
    n = getattr(sysm, "n_deformable", sysm.n_nodes)  # not the reference nodes of rigid bodies
    U = u.reshape(-1, 3)[:n]
    cauchy = np.zeros((n, 6))
    blocks = []
    for blk, body, est in zip(sysm.blocks, model.problem.bodies, state.elements):
        sl = slice(blk.offset, blk.offset + blk.n_nodes)
        st = blk.solid.stress(U[sl], est)
        cauchy[sl] = st.cauchy_nodal
        cd = st.cell_data()
        cd.update(blk.solid.plastic_fields(est))
        cd["body_id"] = np.full(body.mesh.n_cells, len(blocks), dtype=float)
        blocks.append((body.mesh.cell_type, body.mesh.cells + blk.offset, cd))
    points = sysm.X[:n].copy()
    pdata = {"displacement": U.copy(), "cauchy_nodal": cauchy}
    extra_pts, extra_blocks, extra_pdata = model.contact.visual(lam, state.contact)
    pdata.update(model.contact.point_data(n, state.contact) if model.contact.passes else {})
    if extra_pts is not None and len(extra_pts):
        m = len(extra_pts)
        points = np.vstack([points, extra_pts])
        for key, arr in list(pdata.items()):
            pad_shape = (m,) + arr.shape[1:]
            pad = extra_pdata.get(key, np.zeros(pad_shape) if key == "displacement" else np.full(pad_shape, np.nan))
            pdata[key] = np.concatenate([arr, pad])
        for ctype, conn, cd in extra_blocks:
            blocks.append((ctype, conn + n, cd))
    writer.write_vtu(step, lam if time_value is None else time_value, points, blocks, pdata)


class _NoWriter:
    """The writer of the ranks other than 0 in a distributed run: writes nothing."""

    pvd_entries: list = []

    def restore(self, *args, **kwargs) -> None:
        pass

    def write_vtu(self, *args, **kwargs) -> None:
        pass

    def add_iterations(self, *args, **kwargs) -> None:
        pass

    def write_summary(self, *args, **kwargs) -> None:
        pass


#: ``linear = "auto"`` hands a frictionless problem of solid (hex/tet) bodies of compressible materials with at
#: least this many dofs to ``petsc-gamg`` where it is installed (docs/performance.md: 2.5x faster than PARDISO
#: on the Hertz ball at 199,053 dofs, 3.5x on two deformable blocks at 192,480); else to the direct default
AUTO_AMG_DOFS = 100_000
#: the largest Poisson's ratio of such a problem: nearly incompressible bodies slow AMG down
AUTO_AMG_NU = 0.45
#: the largest share of nodes on the bodies' boundaries: a bulky mesh (0.11-0.19 for the raced 2e5-dof meshes)
#: factorises slowly, a plate-like one (1.0 with one element through the thickness) quickly and is hard for AMG
AUTO_AMG_BOUNDARY = 0.3


def auto_amg(problem) -> bool:
    """Whether ``linear = "auto"`` picks the AMG-preconditioned CG of ``petsc-gamg`` for ``problem``: at least
    ``AUTO_AMG_DOFS`` dofs of deformable bodies, all of them ``solid`` (not solid-shell or F-bar) with a
    material of Poisson's ratio at most ``AUTO_AMG_NU``, bulky meshes (at most ``AUTO_AMG_BOUNDARY`` of their
    nodes on a boundary face), no friction (CG needs a symmetric tangent), no rigid body with free components
    (the distributed model has none yet)."""
    from ..mesh.faces import FACES, boundary_faces

    n_nodes = sum(b.mesh.points.shape[0] for b in problem.bodies)
    if 3 * n_nodes < AUTO_AMG_DOFS:
        return False
    if any(b.formulation != "solid" or not 0.0 <= float(getattr(b.material, "nu", 1.0)) <= AUTO_AMG_NU
           or b.mesh.cell_type not in FACES for b in problem.bodies):
        return False
    if any(c.friction for c in problem.contacts) or any(rb.free for rb in problem.rigid):
        return False
    on_boundary = sum(np.unique(boundary_faces(b.mesh)[0]).size for b in problem.bodies)
    return on_boundary <= AUTO_AMG_BOUNDARY * n_nodes


def requested_linear(problem, linear: str | None) -> str:
    """The linear solver asked for: ``linear`` (the command line's), else the problem's, else ``"auto"``."""
    return (linear or problem.solver.linear or "auto").lower().strip()


def resolve_linear(problem, linear: str | None, ranks: int | None = None) -> str:
    """The linear solver of a run: :func:`requested_linear`, whose ``"auto"`` becomes ``petsc-gamg`` where
    :func:`auto_amg` says so and it is installed, else stays ``"auto"`` (the first direct backend available).
    Run as several MPI ranks (``ranks``, by default what the launcher's environment says), ``"auto"`` becomes
    ``petsc-gamg`` where :func:`auto_amg` says so, else ``petsc`` (MUMPS): the distributed solvers."""
    from .linear import _probe

    name = requested_linear(problem, linear)
    if name != "auto":
        return name
    if auto_amg(problem) and _probe("petsc-gamg")[0]:
        return "petsc-gamg"
    return "petsc" if (ranks or ranks_from_env()) > 1 else name


#: a run that ``auto`` hands to petsc-gamg on several cores is started as one MPI rank per core, with at least this
#: many dofs per rank (GAMG's coarse levels and the ranks' shared interfaces cost more than they save below it)
AUTO_DOFS_PER_RANK = 50_000


def thread_budget() -> int:
    """The cores a run may use: those this process may run on, at most ``NUMBA_NUM_THREADS`` where it is set."""
    import os

    from ..parallel.launcher import cores_here

    budget = cores_here()
    value = os.environ.get("NUMBA_NUM_THREADS", "").strip()
    return max(1, min(budget, int(value))) if value.isdigit() else budget


def checkpoint_ranks(out: Path) -> int | None:
    """The number of ranks that wrote the checkpoint in ``out`` (None where there is none)."""
    if (out / "checkpoint.npz").is_file():
        return 1
    for path in sorted(out.glob("checkpoint.rank0-of-*.npz")):
        n = path.name[len("checkpoint.rank0-of-"):-len(".npz")]
        if n.isdigit():
            return int(n)
    return None


def auto_ranks(problem, linear: str | None, out: str | Path | None, resume: bool) -> int:
    """How many MPI ranks ``covcontact run`` starts without ``--ranks``: one (this process) unless ``auto`` hands
    the problem to ``petsc-gamg`` (:func:`auto_amg`), whose Krylov solves and GAMG run one thread per rank, and the
    run may use several cores (:func:`thread_budget`) and ``mpiexec`` is on the PATH: then one rank per core, at
    most one per ``AUTO_DOFS_PER_RANK`` dofs. ``--resume`` takes the number of ranks of the checkpoint it resumes.
    A process that an MPI launcher started is a rank itself: one."""
    import shutil

    from ..parallel.launcher import under_launcher

    if under_launcher() or requested_linear(problem, linear) != "auto":
        return 1
    folder = Path(out) if out is not None else Path("results") / problem.name
    if resume and (n := checkpoint_ranks(folder)) is not None:
        return n
    if resolve_linear(problem, linear, ranks=1) != "petsc-gamg" or shutil.which("mpiexec") is None:
        return 1
    dofs = 3 * sum(b.mesh.points.shape[0] for b in problem.bodies)
    return max(1, min(thread_budget(), dofs // AUTO_DOFS_PER_RANK))


def _distributes(linear: str) -> bool:
    """Whether the linear solver ``linear`` runs the distributed model (``petsc*``)."""
    from .linear import REGISTRY, backend_class

    return linear in REGISTRY and getattr(backend_class(linear), "distributed", False)


def auto_line(linear: str, ranks: int, one_core_hint: bool = False, started: bool = False) -> str:
    """The line a run prints when ``auto`` picked ``linear`` (``petsc-gamg``, or ``petsc`` on several ranks);
    ``started``: the ranks were started by :func:`auto_ranks`, not asked for."""
    if linear != "petsc-gamg":
        return f"linear solver: {linear} (auto, {ranks} MPI ranks: MUMPS, distributed)"
    why = "a large frictionless problem of bulky solid bodies"
    if ranks > 1:
        how = "; one per core, `--ranks 1` keeps one process" if started else ""
        return f"linear solver: {linear} (auto, {ranks} MPI ranks: {why}{how})"
    hint = "; its solves run on one core, `--ranks 2` runs two MPI ranks" if one_core_hint else ""
    return (f"linear solver: {linear} (auto: {why}; --solver with a direct one, `covcontact info` lists them, to "
            f"factorise instead{hint})")


def check_distributable(problem, linear: str, ranks: int) -> None:
    """Raise InputError where ``ranks`` MPI ranks cannot run ``problem`` with the solver ``linear``."""
    where = problem.source or problem.name
    if ranks > 1 and not _distributes(linear):
        raise InputError(f"{where}: {ranks} MPI ranks, but the linear solver {linear!r} runs in one process; "
                         f"use --solver petsc or petsc-gamg (or leave the solver to auto)")
    if _distributes(linear) and any(rb.free for rb in problem.rigid):
        raise InputError(f"{where}: rigid bodies with free components (reference nodes) are not available with "
                         f"the distributed solver {linear!r} yet; use a serial solver")


def _make_model(problem, tangent: str | None, linear: str) -> Model:
    """The serial Model, or the distributed one for a backend that distributes (``petsc*``)."""
    check_distributable(problem, linear, ranks_from_env())
    if _distributes(linear):
        from ..allocator import keep_freed_memory
        from ..parallel.model import DistributedModel

        keep_freed_memory()  # PETSc's matrices and hierarchies of each iteration reuse memory (allocator.py)
        return DistributedModel(problem, tangent=tangent)
    return Model(problem, tangent=tangent)


def _pop_prefixed(arrays: dict[str, np.ndarray], prefix: str) -> dict[str, np.ndarray]:
    """The checkpoint arrays whose keys start with ``prefix``, taken out of ``arrays``."""
    return {k: arrays.pop(k) for k in [k for k in arrays if k.startswith(prefix)]}


def _tangent_name(problem, tangent: str | None) -> str:
    """The tangent case of the run: the override, else the pairs' common case (or "per-pair")."""
    if tangent:
        return tangent
    cases = {c.tangent for c in problem.contacts}
    return cases.pop() if len(cases) == 1 else ("a" if not cases else "per-pair")


def solve_problem(problem, out=None, tangent=None, quiet=True, linear=None, resume=False, probe=None) -> Result:
    """Solve ``problem`` and write its results; see ``Problem.run``.

    With a distributing backend (``petsc``, ``petsc-gamg``) every MPI rank runs this function; only
    rank 0 writes files and prints. ``probe`` (``covcontact.tangent_check``): an object with ``step`` (the
    step, counted over all stages, after which the run stops with status ``"stopped"``) and
    ``increment(u, lam_a, lam_b, committed, trial)``, called for every converged increment of that step.
    """
    # numpy's and scipy's OpenBLAS on one thread for the run: no vector operation of a run gains from threads,
    # but a threaded call leaves OpenBLAS's workers spinning for a while afterwards, and they take the cores
    # from numba's element assembly and PARDISO (measured: assembly 1.5-2x slower on 2 cores); MKL untouched
    with ThreadpoolController().select(internal_api="openblas").limit(limits=1):
        return _solve_problem(problem, out, tangent, quiet, linear, resume, probe)


def _solve_problem(problem, out, tangent, quiet, linear, resume, probe=None) -> Result:
    t_start = time.perf_counter()
    out = Path(out) if out is not None else Path("results") / problem.name
    requested = requested_linear(problem, linear)
    linear = resolve_linear(problem, linear)
    model = _make_model(problem, tangent, linear)
    if linear != requested and not quiet and model.is_root:
        print(auto_line(linear, model.size, numba.get_num_threads() > 1), file=sys.stderr, flush=True)
    if model.size > 1:
        try:
            return _run(problem, model, out, tangent, quiet, linear, t_start, resume, probe)
        except InputError:  # a refused checkpoint: raised on every rank alike (exit 2)
            raise
        except Exception:  # noqa: BLE001  (maybe on one rank only: the others would wait forever)
            traceback.print_exc()
            sys.stderr.flush()
            model.comm.Abort(3)
    return _run(problem, model, out, tangent, quiet, linear, t_start, resume, probe)


def _run(problem, model, out: Path, tangent: str | None, quiet: bool, linear, t_start: float,
         resume: bool, probe=None) -> Result:
    newton = Newton(model, problem.solver, linear=linear)
    root = model.is_root
    rank, size = model.rank, model.size
    writer = ResultWriter(out) if root else _NoWriter()
    case = _tangent_name(problem, tangent)
    problem_hash = checkpoint.fingerprint(problem) + ":" + case

    def say(msg: str) -> None:
        if root:
            print(msg, file=sys.stderr, flush=True)
    u = model.prescribed(0.0)
    state = model.initial_state()
    summary = {
        "problem": problem.name,
        "status": "running",
        "converged": False,
        "tangent": case,
        "dofs": model.n_dofs,
        "free_dofs": int(model.free.sum()),
        "linear_solver": newton.linear.name,
        **({"units": problem.units} if problem.units else {}),
        "total_iterations": 0,
        "wall_time_s": 0.0,
        "steps": [],
    }
    report = model.partition_report()  # collective under mpiexec
    if report is not None:
        summary["parallel"] = report
    t_out = 0.0
    t_before = 0.0  # wall time of the runs before a resume
    if resume:
        u, arrays, meta = checkpoint.load(out, problem_hash, rank, size)
        last_increment = arrays.pop("newton.last_increment", None)
        couplings = _pop_prefixed(arrays, "coupling.")
        if getattr(model, "coupling", None) is not None:  # the serial model's contact couplings met so far
            model.coupling.restore(couplings)
        newton.linear.restore_history(_pop_prefixed(arrays, "linear."))
        if last_increment is not None and meta.get("last_step_lams"):
            newton._last = (*(float(v) for v in meta["last_step_lams"]), np.array(last_increment))
        try:
            state = State.from_arrays(arrays, like=state)
        except (KeyError, ValueError) as exc:
            raise checkpoint.CheckpointError(f"{checkpoint.path_for(out, rank, size)}: does not match the "
                                             f"problem ({exc})") from None
        if size > 1:
            from ..parallel.comm import gather_all

            steps = gather_all(model.comm, state.step)
            if len(set(steps)) > 1:
                raise checkpoint.CheckpointError(f"{out}: the ranks' checkpoints end at different steps "
                                                 f"{sorted(set(steps))} (a rank stopped while writing); "
                                                 f"start again without --resume")
        summary = meta["summary"]
        t_before = float(meta.get("wall_time_s", 0.0))
        newton.scale_seen = float(meta.get("force_scale", 0.0))
        writer.restore(meta["pvd"], state.step)
        say(f"resuming {problem.name} after step {state.step} (load factor {state.lam:.4g})")
    else:
        warnings = model.start_warnings(u, state)
        if problem.solver.factorization_precision == "single" and newton.linear.precision_report() is None:
            warnings.append(f'factorization_precision = "single" is for PARDISO; the linear solver '
                            f'{newton.linear.name} factorises in double precision')
        if warnings:
            summary["warnings"] = warnings
            for w in warnings:
                say(f"warning: {w}")
        if problem.output.vtu:
            t0 = time.perf_counter()
            _write_vtu(writer, model, u, 0.0, 0, state)
            t_out += time.perf_counter() - t0
    plan = model.stages
    nsteps = sum(len(spec.factors) for spec in plan.stages)
    staged = len(plan) > 1
    if resume:
        model.set_stage(state)
    status = "completed"
    code = 0
    work_before = model.plastic_work(state)  # plastic work of the committed state (collective)
    with StopSignals(comm=model.comm if size > 1 else None) as stops:
        newton.poll = stops.poll  # distributed: every rank stops at the same Newton iteration
        try:
            for si in range(state.stage, len(plan)):
                spec = plan[si]
                before = sum(len(q.factors) for q in plan.stages[:si])  # steps of the earlier stages
                t_stage = sum(q.lam_end for q in plan.stages[:si])    # their total pseudo-time
                if si > state.stage:
                    state = model.enter_stage(u, state)
                    newton.linear.set_near_null_space(model.near_null_space())
                    if not quiet:
                        say(f"stage {si + 1}/{len(plan)} {spec.name!r}"
                            + (f": releasing {', '.join(spec.release_names)}" if spec.release_names else ""))
                if staged:
                    _stage_entry(summary, spec)
                for k in range(state.step + 1, before + len(spec.factors) + 1):
                    lam = spec.factors[k - before - 1]
                    stats0, time0 = dict(newton.stats), dict(newton.timing)
                    if probe is not None and k == probe.step:
                        newton.on_converged = probe.increment
                    success, outcomes, cutbacks, why, new = newton.advance(u, state.lam, lam, state)
                    conv = [o for o in outcomes if o.converged]
                    iters = sum(o.iterations for o in outcomes)
                    entry = {
                        "step": k,
                        "load_factor": lam,
                        "converged": success,
                        "iterations": iters,
                        "residual_norms": [r / max(o.residual_norms[0], 1e-300) for o in conv[-1:]
                                           for r in o.residual_norms] if conv else [],
                        "cutbacks": cutbacks,
                        "factorizations": newton.stats["factorizations"] - stats0["factorizations"],
                        "krylov_iterations": newton.stats["krylov_iterations"] - stats0["krylov_iterations"],
                        "factor_s": round(newton.timing["factor"] - time0["factor"], 6),
                        "krylov_s": round(newton.timing["krylov"] - time0["krylov"], 6),
                    }
                    if staged:
                        entry["stage"] = spec.name
                        entry["time"] = t_stage + lam
                    if any(c.method == "augmented" for c in problem.contacts):
                        entry["uzawa_iterations"] = sum(1 for o in outcomes if o.augmentation > 0)
                    if cutbacks:
                        entry["cutback_reasons"] = [o.reason for o in outcomes if not o.converged]
                    if success:
                        work = model.plastic_work(new)
                        if work is not None:
                            entry["plastic_dissipation"] = work - work_before
                            entry["plastic_work"] = work_before = work
                        state = new
                        state.step = k
                        entry.update(model.step_report(u, lam, state))
                        entry["reactions"] = _reactions(model, u, lam, state)
                        rigid = model.rigid_report(u, lam, state)
                        if rigid:
                            entry["rigid_bodies"] = rigid
                    else:
                        entry["failure"] = why
                    with stops.critical():
                        summary["steps"].append(entry)
                        summary["total_iterations"] += iters
                        if staged:
                            _stage_add(summary, entry)
                        writer.add_iterations(k, [r for o in outcomes for r in o.records])
                        if not quiet:
                            rn = conv[-1].residual_norms[-1] if conv else float("nan")
                            msg = ((f"stage {spec.name}  " if staged else "")
                                   + f"step {k:4d}/{nsteps}  lambda {lam:.4g}  iterations {iters:3d}  "
                                   f"residual {rn:.2e}  active {model.active_count(state):5d}"
                                   + (f"  cutbacks {cutbacks}" if cutbacks else ""))
                            say(msg + (f"  FAILED: {why}" if not success else ""))
                        if not success:
                            status, code = "failed", 1
                            break
                        last = k == before + len(spec.factors)
                        if problem.output.vtu and (k % problem.output.every == 0 or k == nsteps or last):
                            t0 = time.perf_counter()
                            _write_vtu(writer, model, u, lam, k, state, t_stage + lam)
                            t_out += time.perf_counter() - t0
                        summary["wall_time_s"] = t_before + time.perf_counter() - t_start
                        writer.write_summary(summary)
                        if k % problem.output.checkpoint_every == 0 or k == nsteps or last:
                            extra, lams = {}, None
                            if newton._last is not None and problem.solver.predictor == "extrapolate":
                                extra["newton.last_increment"] = newton._last[2]
                                lams = [newton._last[0], newton._last[1]]
                            coupling = getattr(model, "coupling", None)
                            if coupling is not None:
                                extra.update(coupling.arrays())
                            extra.update(newton.linear.history())  # the distributed matrix's contact entries
                            checkpoint.save(out, u, {**state.arrays(), **extra},
                                            {"problem_hash": problem_hash, "summary": json.loads(
                                                json.dumps(summary, default=_jsonable)),
                                             "pvd": writer.pvd_entries, "wall_time_s": summary["wall_time_s"],
                                             "force_scale": newton.scale_seen, "last_step_lams": lams},
                                            rank, size)
                    stops.poll()
                    if probe is not None and k == probe.step:
                        status = "stopped"
                        break
                if status in ("failed", "stopped"):
                    break
        except (Interrupted, SystemError) as exc:
            stop = _interruption(exc)
            if stop is None:
                raise
            status, code = "interrupted", stop.exit_code
            say(f"{stop}: the step in flight is dropped; resume with --resume")
        with stops.critical():
            _finish(problem, model, newton, summary, status, t_before, t_start, t_out, writer, root, quiet, say, out)
    return Result(summary=summary, u=u, out=out, exit_code=code, model=model, state=state)


def _interruption(exc: BaseException) -> Interrupted | None:
    """The Interrupted behind ``exc``: itself, or the cause of a SystemError (a signal that arrived while
    compiled code called back into Python, e.g. numba loading a cached function, comes out wrapped so)."""
    while exc is not None:
        if isinstance(exc, Interrupted):
            return exc
        exc = exc.__cause__ or exc.__context__
    return None


def _stage_entry(summary: dict, spec) -> None:
    """The totals of stage ``spec`` in the summary (created when the stage starts; kept on a resume)."""
    stages = summary.setdefault("stages", [])
    if not any(st["name"] == spec.name for st in stages):
        stages.append({"name": spec.name, "index": spec.index, "steps": 0, "iterations": 0, "cutbacks": 0,
                       "converged": False, "released": list(spec.release_names)})


def _stage_add(summary: dict, entry: dict) -> None:
    st = next(s for s in summary["stages"] if s["name"] == entry["stage"])
    st["steps"] += 1 if entry["converged"] else 0
    st["iterations"] += entry["iterations"]
    st["cutbacks"] += entry["cutbacks"]
    st["converged"] = entry["converged"]
    for key in ("plastic_dissipation",):
        if key in entry:
            st[key] = st.get(key, 0.0) + entry[key]


def _finish(problem, model, newton, summary, status, t_before, t_start, t_out, writer, root, quiet, say, out):
    summary["status"] = status
    summary["converged"] = status == "completed"
    if "parallel" in summary:
        lin = newton.linear
        summary["parallel"]["linear"] = {"analyses": lin.n_analyses, "factorizations": lin.n_factorizations,
                                         "krylov_iterations": getattr(lin, "krylov_iterations", 0)}
    precision = newton.linear.precision_report()
    if precision is not None and precision["single_factorizations"]:
        summary["factorization_precision"] = precision
        if "single_given_up" in precision and not quiet:
            say(f"note: factorising in double precision after a {precision['single_given_up']}")
    timing = dict(newton.timing)
    split = model.contact.timing
    timing["contact_search"] = split["search"]
    timing["contact_projection"] = split["projection"]
    timing["contact_assembly"] = max(timing["contact"] - split["search"] - split["projection"], 0.0)
    timing["output"] = t_out
    timing["total"] = time.perf_counter() - t_start
    summary["timing"] = {k: round(v, 4) for k, v in timing.items()}
    summary["wall_time_s"] = t_before + timing["total"]
    writer.write_summary(summary)
    if status == "completed" and problem.output.pictures and problem.output.vtu and root:
        from ..io.pictures import render_pictures

        for path in render_pictures(out):
            if not quiet:
                say(f"picture {path}")
    if not quiet:
        say("time: " + "  ".join(f"{k} {v:.2f}s" for k, v in summary["timing"].items()))
