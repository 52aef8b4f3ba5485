"""The observers that record a run (docs/architecture.md): summary.json, convergence.csv, the VTU series,
checkpoints, pictures and the progress lines on stderr. Each listens to the run's events
(``covcontact.observer.Observer``) and keeps its own part of a checkpoint.
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from ..fem.cells import FACE_BY_NODES
from ..observer import Observer
from . import checkpoint
from .output import ResultWriter, _jsonable, body_blocks, summary_text
from .rigid_visual import rigid_visual


class Summary(Observer):
    """summary.json: the run's header, a record per step (the procedure's report), per-stage totals, and at
    the end the status and the time split. ``writer`` None: kept (a checkpoint holds it) but not written
    (the ranks other than the first of a distributed run)."""

    def __init__(self, writer: ResultWriter | None):
        self.writer = writer
        self.data: dict = {}
        self.t_before = 0.0  # wall time of the runs before a resume
        self._steps: list[str] = []  # the encoded records of the steps before the last (complete: never encoded again)

    def header(self, run) -> None:
        newton, model, problem = run.newton, run.model, run.problem
        self.data = {"problem": problem.name, "status": "running", "converged": False, "tangent": run.case,
                     "dofs": model.n_dofs, "free_dofs": int(model.free.sum()), "linear_solver": newton.linear.name,
                     **({"units": problem.units} if problem.units else {}),
                     "total_iterations": 0, "wall_time_s": 0.0, "steps": []}
        self._steps = []
        if run.partition is not None:
            self.data["parallel"] = run.partition

    def started(self, run) -> None:
        if run.warnings:
            self.data["warnings"] = list(run.warnings)

    def stage_entered(self, run, procedure, entering: bool) -> None:
        mass = getattr(procedure, "mass", None)
        if mass is not None:  # (a dynamic stage: the mass matrix it resolved, "auto" made explicit)
            self.data.setdefault("mass", {})[procedure.spec.name] = mass
        if not procedure.staged:
            return
        spec = procedure.spec
        stages = self.data.setdefault("stages", [])
        if not any(st["name"] == spec.name for st in stages):
            stages.append({"name": spec.name, "index": spec.index, "steps": 0, "iterations": 0, "cutbacks": 0,
                           "converged": False, "released": list(spec.release_names)})

    def _add(self, inc) -> None:
        entry = inc.entry
        self.data["steps"].append(entry)
        self.data["total_iterations"] += inc.iterations
        if "stage" in entry:
            st = next(s for s in self.data["stages"] if s["name"] == entry["stage"])
            st["steps"] += 1 if entry["converged"] else 0
            st["iterations"] += entry["iterations"]
            st["cutbacks"] += entry["cutbacks"]
            st["converged"] = entry["converged"]
            if "plastic_dissipation" in entry:
                st["plastic_dissipation"] = st.get("plastic_dissipation", 0.0) + entry["plastic_dissipation"]

    def increment_converged(self, run, inc) -> None:
        self._add(inc)
        growth = inc.entry.get("energy_warning")
        if growth is not None and "energy_growth" not in self.data:  # (the first one of the run)
            self.data["energy_growth"] = {"step": inc.step, "time": inc.entry.get("time"), "message": growth}
            self.data.setdefault("warnings", []).append(f"step {inc.step}: {growth}")
        self.data["wall_time_s"] = self.t_before + time.perf_counter() - run.t_start
        self._write()

    def increment_failed(self, run, inc) -> None:
        self._add(inc)

    def _status(self, run, status: str) -> None:
        """``status`` and ``converged``; of a failed run also ``reason``, ``last_converged`` (step, stage, load factor,
        time of the last converged step; step 0: none) and ``failed_step`` (a step that did not converge) or ``error``
        (an exception: type, message, where, the traceback's file)."""
        s = self.data
        s["status"] = status
        s["converged"] = status == "completed"
        if status == "failed":
            failure = getattr(run, "failure", None) or {"reason": "unknown"}
            s["reason"] = failure["reason"]
            s["last_converged"] = run.last_converged()
            for key in ("failed_step", "error"):
                if key in failure:
                    s[key] = failure[key]

    def ended_status(self, run, status: str) -> None:
        """The status alone, written: what a run that an exception ended records when the other observers cannot
        finish."""
        self._status(run, status)
        self._write()

    def ended(self, run, status: str) -> None:
        s = self.data
        self._status(run, status)
        lin = run.newton.linear
        if "parallel" in s:
            s["parallel"]["linear"] = {"analyses": lin.n_analyses, "factorizations": lin.n_factorizations,
                                       "krylov_iterations": getattr(lin, "krylov_iterations", 0)}
        precision = lin.precision_report()
        if precision is not None and precision["single_factorizations"]:
            s["factorization_precision"] = precision
        s["timing"] = dict(run.summary_timing)
        s["wall_time_s"] = self.t_before + run.total_time
        self._write()

    def text(self) -> str:
        """summary.json's text; each step's record is encoded once, when a later step follows it (a run of n steps
        would otherwise encode n^2 / 2 records: a third of a 364-step run's time, with the checkpoint's copy)."""
        steps = self.data.get("steps", [])
        while len(self._steps) < len(steps) - 1:
            self._steps.append(json.dumps(steps[len(self._steps)], default=_jsonable))
        return summary_text(self.data, self._steps)

    def _write(self) -> None:
        if self.writer is not None:
            self.writer.write_summary(self.data, self.text())

    def checkpoint(self) -> tuple[dict, dict]:
        return {}, {"summary_text": self.text(), "wall_time_s": self.data["wall_time_s"]}

    def restore(self, arrays: dict, meta: dict) -> None:
        self.data = json.loads(meta["summary_text"]) if "summary_text" in meta else meta["summary"]
        self._steps = []
        self.t_before = float(meta.get("wall_time_s", 0.0))


class Convergence(Observer):
    """convergence.csv: every Newton iteration of every step (the failed attempts before cutbacks too)."""

    def __init__(self, writer: ResultWriter):
        self.writer = writer

    def increment_converged(self, run, inc) -> None:
        self.writer.add_iterations(inc.step, inc.records)

    increment_failed = increment_converged

    def restore(self, arrays: dict, meta: dict) -> None:
        self.writer.restore_iterations(int(arrays["step.step"]))


class Results(Observer):
    """The VTU series and result.pvd: the start (step 0), every ``every``-th converged step and the steps that
    end at an ``output_at`` load factor, the last step of each stage and of the run always. ``writer`` None (the ranks other than the first of a distributed run):
    the fields are computed (their gathering is collective) but not written."""

    def __init__(self, writer: ResultWriter | None, every: int):
        self.writer = writer
        self.every = every
        self.seconds = 0.0  # time spent writing

    def started(self, run) -> None:
        self._write(run, 0.0, 0, 0.0)

    def increment_converged(self, run, inc) -> None:
        k, proc = inc.step, run.procedure
        if k % self.every == 0 or inc.ends_stage or inc.output:  # stage ends (so the run's end), output_at
            dyn = run.state.dynamics  # a dynamic stage's files carry its time
            self._write(run, inc.lam, k, float(dyn["time"]) if dyn else proc.t_stage + inc.lam)

    def _write(self, run, lam: float, step: int, time_value: float) -> None:
        t0 = time.perf_counter()
        points, blocks, pdata = result_fields(run.model, run.u, lam, run.state)
        if self.writer is not None:
            self.writer.write_vtu(step, time_value, points, blocks, pdata)
        self.seconds += time.perf_counter() - t0

    def checkpoint(self) -> tuple[dict, dict]:
        return {}, {"pvd": self.writer.pvd_entries if self.writer is not None else []}

    def restore(self, arrays: dict, meta: dict) -> None:
        if self.writer is not None:
            self.writer.restore_series(meta.get("pvd", []))


def result_fields(model, u: np.ndarray, lam: float, state) -> tuple:
    """(points, cell blocks, point data) of the VTU file of ``state``: the deformable bodies (displacement,
    Cauchy stress, cell fields, contact gap/pressure/status on slave nodes), then the rigid bodies."""
    sysm = model.system
    n = getattr(sysm, "n_deformable", sysm.n_nodes)  # not the reference nodes of rigid bodies
    U = u.reshape(-1, 3)[:n]
    cauchy = np.zeros((n, 6))
    blocks = []
    for body_id, (blk, body, est) in enumerate(zip(sysm.blocks, model.problem.bodies, state.elements)):
        sl = slice(blk.offset, blk.offset + blk.n_nodes)
        st = blk.solid.stress(U[sl], est)
        cauchy[sl] = st.cauchy_nodal
        cd = st.cell_data()
        cd.update(blk.solid.plastic_fields(est))
        cd["body_id"] = np.full(body.mesh.n_cells, body_id, dtype=float)
        blocks += body_blocks(body.mesh, blk.offset, cd)
    per_pass: dict = {}  # (each pass's own fields, for slave surfaces in several pairs)
    fields = model.contact.node_fields(state.contact, per_pass)  # (gap, pressure, status) over the extended nodes
    if model.contact.passes:  # the slave surfaces with their facets' mean contact pressure
        for faces, pressure in model.contact.facet_fields(state.contact, fields[1]):
            keep = (faces < n).all(axis=1)
            if keep.any():
                planar = np.isin(3 * faces[keep][:, 0] + 2, getattr(sysm, "planar_dofs", ())).all()
                blocks.append((("line", "line3")[faces.shape[1] - 2] if planar else FACE_BY_NODES[faces.shape[1]],
                               faces[keep],
                               {"contact_facet_pressure": pressure[keep]}))
    points = sysm.X[:n].copy()
    pdata = {"displacement": U.copy(), "cauchy_nodal": cauchy}
    if state.dynamics:  # a dynamic stage: velocities and accelerations
        pdata["velocity"] = state.dynamics["v"].reshape(-1, 3)[:n].copy()
        pdata["acceleration"] = state.dynamics["a"].reshape(-1, 3)[:n].copy()
    pdata.update(model.contact.point_data(n, state.contact, fields, per_pass) if model.contact.passes else {})
    points = _append(points, pdata, blocks, *shell_mid_surfaces(sysm, model.problem.bodies, U, state))
    extra_pts, extra_blocks, extra_pdata = rigid_visual(model.contact, lam, fields)
    if extra_pts is not None:
        points = _append(points, pdata, blocks, extra_pts, extra_blocks, extra_pdata)
    return points, blocks, pdata


def _append(points, pdata, blocks, extra_pts, extra_blocks, extra_pdata):
    """``points`` with ``extra_pts`` appended: the point data padded (their values where ``extra_pdata`` has them,
    else zero displacement and NaN), the extra blocks' connectivity shifted past the points."""
    if not len(extra_pts):
        return points
    n, m = len(points), len(extra_pts)
    for key, arr in list(pdata.items()):
        pad = extra_pdata.get(key, np.zeros((m,) + arr.shape[1:]) if key == "displacement" else
                              np.full((m,) + arr.shape[1:], np.nan))
        pdata[key] = np.concatenate([arr, pad])
    blocks += [(ctype, conn + n, cd) for ctype, conn, cd in extra_blocks]
    return np.vstack([points, extra_pts])


def shell_mid_surfaces(sysm, bodies, U: np.ndarray, state) -> tuple:
    """The mid-surfaces of the solid-shell bodies (each bottom-top node pair's mid-point, deformed by the pair's
    mean displacement; quad4 cells of hex8, quad9 of hex18) with their elements' thickness, membrane forces N,
    bending moments M, transverse shear forces Q and bottom and top stresses in the elements' shell frames
    (:meth:`SolidShellBody.shell_resultants`; docs/input.md, "Output"): (points, blocks, point data)."""
    from ..elements.solidshell import SolidShellBody

    pts, blocks, disp = [], [], []
    count = 0
    for body_id, (blk, body, est) in enumerate(zip(sysm.blocks, bodies, state.elements)):
        if not isinstance(blk.solid, SolidShellBody):
            continue
        cells = blk.solid.cells
        h = cells.shape[1] // 2
        pairs, mid = np.unique(np.stack([cells[:, :h], cells[:, h:]], axis=2).reshape(-1, 2), axis=0,
                               return_inverse=True)
        sl = slice(blk.offset, blk.offset + blk.n_nodes)
        u = U[sl]
        r = blk.solid.shell_resultants(u, est)
        pts.append(0.5 * (blk.solid.X[pairs[:, 0]] + blk.solid.X[pairs[:, 1]]))
        disp.append(0.5 * (u[pairs[:, 0]] + u[pairs[:, 1]]))
        cd = {"shell_thickness": r["thickness"], "membrane_force": r["N"], "bending_moment": r["M"],
              "transverse_shear_force": r["Q"], "stress_bottom": r["bottom"], "stress_top": r["top"],
              "shell_frame_e1": r["frame"][:, 0], "body_id": np.full(len(cells), body_id, dtype=float),
              **blk.solid.plastic_fields(est)}
        blocks.append(("quad4" if h == 4 else "quad9", count + mid.reshape(len(cells), h), cd))
        count += len(pairs)
    if not pts:
        return np.zeros((0, 3)), [], {}
    return np.vstack(pts), blocks, {"displacement": np.vstack(disp)}


class Checkpoints(Observer):
    """checkpoint.npz after every ``every``-th converged step (the last step of each stage and of the run
    always): the displacement, the committed state and what every part of the run keeps (``parts``: objects
    with ``checkpoint()``), per rank of a distributed run."""

    def __init__(self, out, every: int, problem_hash: str, parts: list, rank: int = 0, size: int = 1):
        self.out, self.every, self.problem_hash = out, every, problem_hash
        self.parts, self.rank, self.size = parts, rank, size

    def increment_converged(self, run, inc) -> None:
        k = inc.step
        if not (k % self.every == 0 or inc.ends_stage):
            return
        arrays, meta = {}, {"problem_hash": self.problem_hash}
        for part in self.parts:
            a, m = part.checkpoint()
            arrays.update(a)
            meta.update(m)
        checkpoint.save(self.out, run.u, {**run.state.arrays(), **arrays}, meta, self.rank, self.size)


class Pictures(Observer):
    """initial.png / final.png (and the stages' pictures) of a completed run, where the problem asks for them."""

    def __init__(self, out, say):
        self.out, self.say = out, say

    def ended(self, run, status: str) -> None:
        if status != "completed":
            return
        from .pictures import render_pictures

        for path in render_pictures(self.out):
            self.say(f"picture {path}")


class Progress(Observer):
    """The lines on stderr: a line per step, the stages, and at the end the time split. Warnings, the
    resume and an interruption are said even with ``quiet``."""

    def __init__(self, quiet: bool, enabled: bool = True):
        self.quiet = quiet
        self.enabled = enabled

    def say(self, msg: str, always: bool = False) -> None:
        if self.enabled and (always or not self.quiet):
            print(msg, file=sys.stderr, flush=True)

    def started(self, run) -> None:
        for w in run.warnings:
            self.say(f"warning: {w}", always=True)
        from ..materials.fit import fit_notes
        from ..materials.rubber import moduli_notes

        for note in fit_notes(run.problem.bodies):  # (constants fitted to test data: the fit's report, once)
            self.say(note, always=True) if note.startswith("warning: ") else self.say(f"note: {note}")
        for note in moduli_notes(run.problem.bodies):  # (the rubber models' initial moduli, to check the constants)
            self.say(f"note: {note}")

    def resumed(self, run) -> None:
        self.say(f"resuming {run.problem.name} after step {run.state.step} (load factor {run.state.lam:.4g})",
                 always=True)

    def stage_entered(self, run, procedure, entering: bool) -> None:
        for note in getattr(procedure, "notes", ()):
            self.say(f"note: {note}")
        if entering:
            spec = procedure.spec
            self.say(f"stage {spec.index + 1}/{run.n_stages} {spec.name!r}"
                     + (f": releasing {', '.join(spec.release_names)}" if spec.release_names else ""))

    def increment_converged(self, run, inc) -> None:
        growth = inc.entry.get("energy_warning")
        if growth is not None and not getattr(run, "energy_said", False):  # (said once per run, even with --quiet)
            run.energy_said = True
            self.say(f"warning: step {inc.step}: {growth}", always=True)
        self._step_line(run, inc)

    def _step_line(self, run, inc) -> None:
        if self.quiet:
            return
        # computed on every rank of a distributed run alike (the count is collective), printed by the first
        active = run.model.active_count(run.state)
        self.say(("" if not run.procedure.staged else f"stage {run.procedure.spec.name}  ")
                 + f"step {inc.step:4d}" + (f"/{run.n_steps}" if run.n_steps is not None else "")
                 + f"  lambda {inc.lam:.4g}" + (f"  increment {inc.lam - inc.lam_a:.3g}" if run.procedure.automatic else "")
                 + f"  iterations {inc.iterations:3d}  "
                 f"residual {inc.residual:.2e}  active {active:5d}"
                 + (f"  cutbacks {inc.cutbacks}" if inc.cutbacks else "")
                 + (f"  FAILED: {inc.why}" if not inc.success else ""))

    def increment_failed(self, run, inc) -> None:
        if not self.quiet:
            self._step_line(run, inc)
        else:  # --quiet silences the progress, never why a run failed
            self.say(f"step {inc.step} (load factor {inc.lam:.4g}) failed after {inc.cutbacks} cutbacks: {inc.why}",
                     always=True)

    def ended(self, run, status: str) -> None:
        if run.interruption is not None:
            self.say(f"{run.interruption}: the step in flight is dropped; resume with --resume", always=True)
        precision = run.newton.linear.precision_report()
        if precision is not None and precision["single_factorizations"] and "single_given_up" in precision:
            self.say(f"note: factorising in double precision after a {precision['single_given_up']}")
        self.say("time: " + "  ".join(f"{k} {v:.2f}s" for k, v in run.summary_timing.items()))
