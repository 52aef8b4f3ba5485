"""Pictures: labels with the problem's units, one picture per stage end, and study curves that stay
distinguishable when cases coincide."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from covcontact.io import pictures
from covcontact.io.loader import problem_from_dict
from covcontact.study import plot_iterations


def _staged(tmp_path: Path):
    raw = {
        "problem": {"name": "pics", "units": "mm, N, MPa", "stage": "press"},
        "bodies": [{"name": "block", "material": {"model": "neo-hooke", "E": 1000.0, "nu": 0.3},
                    "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 2, "ny": 2, "nz": 2}}],
        "dirichlet": [{"set": "block.zmin"}, {"name": "push", "set": "block.zmax", "components": "z",
                                               "value": -0.05}],
        "stages": [{"name": "release", "release": ["push"]}],
        "output": {"pictures": True},
    }
    return problem_from_dict(raw, tmp_path / "p.toml").run(out=tmp_path / "out")


def test_staged_run_draws_every_stage_end_with_units(tmp_path, monkeypatch):
    labels = []
    draw = pictures._draw

    def spy(path, state, lo, hi, vmax, title, view, length="", plastic=False):
        labels.append((path.name, title, length))
        return draw(path, state, lo, hi, vmax, title, view, length, plastic)

    monkeypatch.setattr(pictures, "_draw", spy)
    res = _staged(tmp_path)
    assert res.exit_code == 0
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["units"] == "mm, N, MPa"
    names = {n for n, _, _ in labels}
    assert names == {"initial.png", "final.png", "press.png"}
    assert all(length == "mm" for _, _, length in labels)
    assert dict((n, t) for n, t, _ in labels)["press.png"] == "end of stage 'press': step 1"
    for n in names:
        assert (tmp_path / "out" / n).stat().st_size > 10_000


def test_coinciding_study_curves_are_told_apart(tmp_path, monkeypatch):
    import matplotlib.axes

    labels = []
    plot = matplotlib.axes.Axes.plot

    def spy(self, *args, **kwargs):
        labels.append((kwargs.get("label"), kwargs.get("marker"), kwargs.get("linestyle")))
        return plot(self, *args, **kwargs)

    monkeypatch.setattr(matplotlib.axes.Axes, "plot", spy)
    runs = {"a": [5, 6], "b": [5, 6], "c": [4, 4]}
    results = {c: {"steps": [{"step": i + 1, "iterations": n} for i, n in enumerate(its)]}
               for c, its in runs.items()}
    plot_iterations(results, tmp_path / "iterations.png", "t")
    assert (tmp_path / "iterations.png").exists()
    cumulative = [entry for entry in labels if entry[0] and "(" in entry[0]]
    assert [e[0] for e in cumulative] == ["case a (11) = b", "case b (11) = a", "case c (8)"]
    assert len({(e[1], str(e[2])) for e in cumulative}) == 3  # three different marker/line styles


def test_plastic_problem_is_coloured_by_the_plastic_strain(tmp_path, monkeypatch):
    """A plastic run's pictures show the equivalent plastic strain (its colour scale up to the largest value
    on the surface), an elastic run's the displacement magnitude."""
    from covcontact.io.loader import load_problem

    seen = []
    draw = pictures._draw

    def spy(path, state, lo, hi, vmax, title, view, length="", plastic=False):
        seen.append((path.name, plastic, vmax, float(np.nanmax(state[4])) if np.isfinite(state[4]).any() else 0.0))
        return draw(path, state, lo, hi, vmax, title, view, length, plastic)

    monkeypatch.setattr(pictures, "_draw", spy)
    root = Path(__file__).resolve().parents[2]
    res = load_problem(root / "examples" / "plasticity" / "bend_and_release.toml").run(out=tmp_path / "p")
    assert res.exit_code == 0
    pictures.render_pictures(tmp_path / "p")
    final = [s for s in seen if s[0] == "final.png"][0]
    assert final[1] and final[2] == pytest.approx(final[3]) and final[2] > 0.0
