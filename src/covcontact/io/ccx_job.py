"""What ``covcontact ccx JOB`` writes besides JOB.dat and JOB.frd, as CalculiX's ``ccx -i JOB`` does for the
pre-processors that start it (FreeCAD FEM, PrePoMax): the status file JOB.sta (a line per increment, and a line
marked ``U`` per attempt that did not converge), the convergence file JOB.cvg (a line per Newton iteration) and the
lines on standard output (a banner, each step and increment, ``Job finished``). Layouts are CalculiX's (docs/input.md,
"Abaqus and CalculiX decks").

Increments are numbered within each deck step; a covcontact step that Newton's cutbacks split into several converged
increments gives a line for each. The size of an attempt that failed is its increment before the cutback (twice the
size of the attempt after it).
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass, field
from pathlib import Path

from ..observer import Observer

STA_HEAD = ("SUMMARY OF JOB INFORMATION\n"
            "  STEP      INC     ATT  ITRS     TOT TIME     STEP TIME      INC TIME\n")
#: (CalculiX's own heading, its spelling kept: programs look for it)
CVG_HEAD = ("SUMMARY OF C0NVERGENCE INFORMATION\n"
            "  STEP   INC  ATT   ITER     CONT.   RESID.        CORR.      RESID.      CORR.\n"
            "                              EL.    FORCE         DISP       FLUX        TEMP.\n"
            "                              (#)     (%)           (%)        (%)         (%)\n")
RULE = "________________________________________"


def fortran_e(x: float, width: int, digits: int) -> str:
    """``x`` in Fortran's E``width``.``digits`` edit: 0.ddddE+xx, right-justified (three-digit exponents as 0.dd-100)."""
    if x == 0.0:
        mant, exp = "0" * digits, 0
    else:
        head, _, tail = f"{abs(x):.{digits - 1}e}".partition("e")
        mant, exp = head.replace(".", ""), int(tail) + 1
    expo = f"E{exp:+03d}" if abs(exp) < 100 else f"{exp:+04d}"
    return f"{'-' if x < 0 else ''}0.{mant}{expo}".rjust(width)


def start_files(sta: Path, cvg: Path) -> None:
    """JOB.sta and JOB.cvg with their headings (CalculiX writes them before it reads the deck)."""
    Path(sta).write_text(STA_HEAD)
    Path(cvg).write_text(CVG_HEAD)


def banner(version: str) -> str:
    stars = "*" * 60
    return (f"\n{stars}\n\ncovcontact {version}: the CalculiX deck run by covcontact (covcontact ccx)\n"
            f"covcontact comes with ABSOLUTELY NO WARRANTY.\n\n{stars}\n\n")


def finished(seconds: float) -> str:
    return f"\n Job finished\n\n{RULE}\n\nTotal covcontact Time: {seconds:f}\n{RULE}\n"


@dataclass
class Attempt:
    """One attempt at an increment: from load factor ``lam0`` by ``dlam``, its number within the increment (1 + the
    cutbacks before it), whether it converged and Newton's solves of it (the attempt and its Uzawa updates)."""

    lam0: float
    dlam: float
    number: int
    converged: bool
    outcomes: list = field(default_factory=list)

    @property
    def iterations(self) -> int:
        return sum(o.iterations for o in self.outcomes)


def increments(outcomes: list, converged: list, lam_a: float, target: float) -> list[list[Attempt]]:
    """The increments of one covcontact step in CalculiX's sense, each the list of its attempts (the last converged,
    except in a step that failed): ``outcomes`` Newton's solves in order (an attempt, then its Uzawa updates),
    ``converged`` the (start, end) load factors of the increments that converged (``Newton.converged_increments``),
    ``target`` the step's aim. An attempt converged when it and all its Uzawa updates did."""
    groups: list[list] = []
    for o in outcomes:
        if o.augmentation > 0 and groups:
            groups[-1].append(o)
        else:
            groups.append([o])
    out: list[list[Attempt]] = []
    current: list[Attempt] = []
    pending = iter(converged)
    lam0, size = lam_a, target - lam_a
    for group in groups:
        if all(o.converged for o in group):
            s, e = next(pending, (lam0, lam0 + size))
            for k, failed in enumerate(reversed(current)):  # each cutback halved the increment
                failed.lam0, failed.dlam = s, (e - s) * 2.0 ** (k + 1)
            current.append(Attempt(s, e - s, len(current) + 1, True, group))
            out.append(current)
            current, lam0, size = [], e, e - s
        else:
            current.append(Attempt(lam0, min(size, target - lam0), len(current) + 1, False, group))
            size /= 2.0
    if current:
        out.append(current)
    return out


class CcxStatus(Observer):
    """JOB.sta, JOB.cvg and the progress lines on ``stream`` (standard output) of a deck's run, from the labels file of
    :func:`covcontact.io.deck_import.import_deck` (each stage's deck step and duration)."""

    def __init__(self, labels: Path, sta: Path, cvg: Path, stream=None):
        info = json.loads(Path(labels).read_text())
        self.periods = info["periods"]
        self.deck_step = info.get("deck_step") or list(range(len(self.periods)))
        self.sta, self.cvg = Path(sta), Path(cvg)
        self.stream = stream if stream is not None else sys.stdout
        self.step = -1        # the deck step in hand
        self.count = 0        # its increments that converged
        self.target = 0.0     # the load factor the step in hand aims at
        self.lam_a = 0.0
        self.failure = ""     # why the run failed (the last increment's reason)

    def say(self, text: str) -> None:
        if self.stream is not None:
            self.stream.write(text)
            self.stream.flush()

    # -- times ------------------------------------------------------------------------------------------
    def _times(self, stage: int, lam: float) -> tuple[float, float]:
        """(total time, step time) at load factor ``lam`` of covcontact stage ``stage``."""
        first = self.deck_step.index(self.deck_step[stage])
        return (sum(self.periods[:stage]) + self.periods[stage] * lam,
                sum(self.periods[first:stage]) + self.periods[stage] * lam)

    # -- events -------------------------------------------------------------------------------------------
    def stage_entered(self, run, procedure, entering: bool) -> None:
        stage = run.state.stage
        if self.deck_step[stage] != self.step:
            self.step, self.count = self.deck_step[stage], 0
            kind = "Dynamic" if run.problem.stage_dynamics(stage) is not None else "Static"
            self.say(f"\n STEP {self.step + 1:12d}\n\n {kind} analysis was selected\n\n")

    def increment_started(self, run, step: int, lam: float) -> None:
        self.lam_a, self.target = run.state.lam, lam

    def increment_converged(self, run, inc) -> None:
        self._record(run, inc)

    def increment_failed(self, run, inc) -> None:
        self.failure = inc.why
        self._record(run, inc)

    # -- records ------------------------------------------------------------------------------------------
    def _record(self, run, inc) -> None:
        stage = inc.state.stage
        done = list(getattr(run.newton, "converged_increments", None) or [])
        sta, cvg, log = [], [], []
        for attempts in increments(inc.outcomes, done, inc.lam_a, max(self.target, inc.lam)):
            number = self.count + 1
            for a in attempts:
                t0, s0 = self._times(stage, a.lam0)
                dt = self.periods[stage] * a.dlam
                log.append(f" increment {number} attempt {a.number} \n increment size= {dt:e}\n sum of previous "
                           f"increments={s0:e}\n actual step time={s0 + dt:e}\n actual total time={t0 + dt:e}\n\n")
                it = 0
                for o in a.outcomes:
                    recs = o.records
                    ref = max((r.residual for r in recs[:2]), default=0.0)
                    e1 = recs[1].energy if len(recs) > 1 else 0.0
                    for r in recs[1:]:
                        it += 1
                        resid = 100.0 * r.residual / ref if ref > 0 else 0.0
                        corr = 100.0 * (r.energy / e1) ** 0.5 if e1 > 0 else 0.0
                        cvg.append(f"  {self.step + 1:4d}  {number:4d}  {a.number:4d}  {it:4d}  {r.active:7d}"
                                   f" {fortran_e(resid, 11, 4)} {fortran_e(corr, 11, 4)}"
                                   f" {fortran_e(0.0, 11, 4)} {fortran_e(0.0, 11, 4)}\n")
                        log.append(f" iteration {it}\n residual force= {r.residual:e} ({resid:.4g} % of the "
                                   f"increment's reference)\n contact elements= {r.active}\n\n")
                if a.converged:
                    self.count = number
                    sta.append(f" {self.step + 1:5d} {number:10d} {a.number:5d} {a.iterations:5d}"
                               f" {fortran_e(t0 + dt, 13, 6)} {fortran_e(s0 + dt, 13, 6)} {fortran_e(dt, 13, 6)}\n")
                    log.append(" convergence\n\n")
                else:
                    sta.append(f" {self.step + 1:5d} {number:10d} {a.number:5d}U {a.iterations:4d}"
                               f" {fortran_e(t0, 13, 6)} {fortran_e(s0, 13, 6)} {fortran_e(dt, 13, 6)}\n")
                    log.append(f" no convergence: {a.outcomes[-1].reason or 'cut back'}\n\n")
        if run.model.is_root:
            with open(self.sta, "a") as fh:
                fh.write("".join(sta))
            with open(self.cvg, "a") as fh:
                fh.write("".join(cvg))
            self.say("".join(log))
