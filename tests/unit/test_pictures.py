"""Pictures: labels with the problem's units, one picture per stage end, and study curves that stay
distinguishable when cases coincide."""

from __future__ import annotations

import json
from pathlib import Path

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

    def spy(path, state, lo, hi, vmax, title, view, length=""):
        labels.append((path.name, title, length))
        return draw(path, state, lo, hi, vmax, title, view, length)

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
