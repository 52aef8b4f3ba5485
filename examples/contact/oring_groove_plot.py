"""Plot the O-ring example's result (docs/img/oring_groove.png): the deformed section coloured by the von Mises
stress with the contact pressure along the lid, and the force-squeeze curve against Lindley's relation.

    covcontact run examples/contact/oring_groove.toml --out oring
    python examples/contact/oring_groove_plot.py oring docs/img/oring_groove.png [FREE]

FREE: optionally the result folder of the same problem with the side walls moved out of reach (wall points at
x = 10 and 30), drawn beside it.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

E, D_SEC, D_MEAN = 6.0, 5.0, 40.0  # 3 mu0 (MPa), section and mean diameters (mm)


def main(out: Path, png: Path, free: Path | None = None) -> None:
    summary = json.loads((out / "summary.json").read_text())
    last = sorted(out.glob("step_*.vtu"))[-1]
    m = meshio.read(last)
    x = m.points[:, :2] + m.point_data["displacement"][:, :2]
    quads = [(b, c.data) for b, c in enumerate(m.cells) if c.type == "quad"]
    b, conn = quads[0]
    vm = np.asarray(m.cell_data["von_mises"][b]).ravel()
    fig, ax = plt.subplots(1, 3, figsize=(13.5, 4.2))
    pc = PolyCollection(x[conn], array=vm, cmap="viridis", edgecolors="k", linewidths=0.2)
    ax[0].add_collection(pc)
    fig.colorbar(pc, ax=ax[0], label="von Mises stress [MPa]", shrink=0.8)
    for y in (-2.5, 2.5 - 1.25):
        ax[0].axhline(y, color="0.4", lw=1.5)
    for xw in (16.4, 23.6):
        ax[0].axvline(xw, color="0.6", lw=1.0, ls="--")
    ax[0].set_aspect("equal")
    ax[0].set_xlim(15.8, 24.2)
    ax[0].set_ylim(-3.0, 2.0)
    ax[0].set_xlabel("radius [mm]")
    ax[0].set_ylabel("axis [mm]")
    ax[0].set_title("25 % squeeze: section, lid, bottom, walls")
    p = np.asarray(m.point_data["contact_pressure[lid]"]).ravel()
    on = p > 0
    order = np.argsort(x[on, 0])
    ax[1].plot(x[on, 0][order], p[on][order], "o-")
    ax[1].set_xlabel("radius [mm]")
    ax[1].set_ylabel("contact pressure [MPa]")
    ax[1].set_title("contact pressure on the lid, 25 % squeeze")
    s = np.array([0.25 * st["load_factor"] for st in summary["steps"]])
    f = np.array([-st["pairs"]["lid"]["contact_force"][1] for st in summary["steps"]]) / (math.pi * D_MEAN)
    ss = np.linspace(0.0, 0.25, 100)
    ax[2].plot(100 * s, f, "o-", label="covcontact (groove, F-bar quad4)")
    if free is not None:  # the same ring with the side walls out of reach
        sf = json.loads((free / "summary.json").read_text())["steps"]
        ax[2].plot(100 * np.array([0.25 * st["load_factor"] for st in sf]),
                   np.array([-st["pairs"]["lid"]["contact_force"][1] for st in sf]) / (math.pi * D_MEAN), "s-",
                   ms=4, label="covcontact (no side walls)")
    ax[2].plot(100 * ss, E * D_SEC * (1.25 * ss**1.5 + 50 * ss**6), "k--", label="Lindley (unrestrained)")
    ax[2].set_xlabel("squeeze [%]")
    ax[2].set_ylabel("force per unit circumference [N/mm]")
    ax[2].set_title("force-squeeze")
    ax[2].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3]) if len(sys.argv) > 3 else None)
