"""Read what kratos_run.py writes: per step the time, Newton iterations, convergence and total reactions."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class KratosResults:
    """One Kratos run: the step times, iterations, convergence flags and reactions of the reported parts."""

    times: np.ndarray
    iterations: list[int]
    converged: list[bool]
    reactions: dict[str, np.ndarray]  # "Structure.<part>" -> (steps, 3)
    analysis_s: float                 # Kratos's own time from building the analysis to its end
    threads: int
    version: str

    @property
    def all_converged(self) -> bool:
        return bool(self.converged) and all(self.converged)

    def force(self, part: str, component: int = 2, sign: float = -1.0) -> np.ndarray:
        """``sign`` times one component of the total reaction of ``part`` per step (default: -R_z, the force
        the body pushes its support with)."""
        return sign * self.reactions[f"Structure.{part}"][:, component]


def read_results(path: Path | str) -> KratosResults:
    """Parse the JSON file of kratos_run.py."""
    raw = json.loads(Path(path).read_text())
    steps = raw["steps"]
    names = steps[0]["reaction"].keys() if steps else []
    return KratosResults(times=np.array([s["time"] for s in steps]),
                         iterations=[int(s["iterations"]) for s in steps],
                         converged=[bool(s["converged"]) for s in steps],
                         reactions={n: np.array([s["reaction"][n] for s in steps]) for n in names},
                         analysis_s=float(raw["analysis_s"]), threads=int(raw["threads"]),
                         version=str(raw.get("kratos_version", "")))
