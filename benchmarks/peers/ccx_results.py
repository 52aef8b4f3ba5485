"""Read what a CalculiX run of ``ccx_deck.hertz_deck`` prints: the .dat tables, the .sta summary, stdout.

The .dat file holds one block per converged increment and request, each a title line naming the
quantity and the time, then one line of numbers per node (or a single line of totals).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

_TIME = re.compile(r"time\s+([-+0-9.Ee]+)\s*$")


@dataclass
class DatResults:
    """Per printed time: total flat-face reaction, curved-surface displacements, contact pressures."""

    times: list[float] = field(default_factory=list)
    rf: dict[float, np.ndarray] = field(default_factory=dict)            # time -> (3,)
    u: dict[float, dict[int, np.ndarray]] = field(default_factory=dict)  # time -> node -> (3,)
    p: dict[float, dict[int, float]] = field(default_factory=dict)       # time -> slave node -> pressure


def _numbers(line: str) -> list[float] | None:
    parts = line.split()
    try:
        return [float(x) for x in parts]
    except ValueError:
        return None


def parse_dat(text: str) -> DatResults:
    """Parse the blocks "total force", "displacements" and "contact stress" of a .dat file."""
    out = DatResults()
    kind, t = None, None
    for line in text.splitlines():
        s = line.strip()
        if not s:
            continue
        m = _TIME.search(s)
        if m and not s[0].isdigit() and s[0] != "-":
            t = float(m.group(1))
            if s.startswith("total force"):
                kind = "rf"
            elif s.startswith("displacements"):
                kind = "u"
                out.u.setdefault(t, {})
            elif s.startswith("contact stress"):
                kind = "p"
                out.p.setdefault(t, {})
            else:
                kind = None
            if t not in out.times:
                out.times.append(t)
            continue
        vals = _numbers(s)
        if vals is None or kind is None:
            continue
        if kind == "rf" and len(vals) == 3:
            out.rf[t] = np.array(vals)
        elif kind == "u" and len(vals) == 4:
            out.u[t][int(vals[0])] = np.array(vals[1:])
        elif kind == "p" and len(vals) == 4:
            out.p[t][int(vals[0])] = vals[1]
    return out


def parse_sta(text: str) -> list[int]:
    """Iterations of every converged increment (column ITRS of the .sta file)."""
    iters = []
    for line in text.splitlines():
        vals = _numbers(line)
        if vals is not None and len(vals) == 7:
            iters.append(int(vals[3]))
    return iters


def parse_stdout(text: str) -> dict:
    """Number of equations, CalculiX's own total time, the solver it factorised with and the largest thread count it reports."""
    m = re.search(r"Total CalculiX Time:\s*([-+0-9.Ee]+)", text)
    solvers = sorted(set(re.findall(r"using the (\w+ \w+) solver", text)))
    cpus = [int(x) for x in re.findall(r"Using up to (\d+) cpu", text)]
    eq = re.search(r"number of equations\s+(\d+)", text)
    return {"equations": int(eq.group(1)) if eq else None, "ccx_time_s": float(m.group(1)) if m else None, "solver": ", ".join(solvers),
            "cpus": max(cpus) if cpus else None,
            "error": "*ERROR" in text}
