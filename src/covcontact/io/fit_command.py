"""``covcontact fit-material DATA.toml``: the command that fits the rubber models to the test data of a file's
material tables (materials/fit.py does the fitting; this module reads the file and reports, so that bad input is an
InputError of the input layer: one line, exit 2)."""

from __future__ import annotations

import re
from pathlib import Path

from ..materials.fit import FitError, _d_keys, fit, plot_fit, read_tests
from ..materials.rubber import RubberError
from .validate import InputError


def _materials_with_data(doc: dict) -> list[tuple[str, dict]]:
    """(where, table) of every material table with test_data: a top-level [material], [materials.NAME], or the
    [[bodies]] material and materials of a problem file."""
    out = []
    if isinstance(doc.get("material"), dict):
        out.append(("material", doc["material"]))
    if isinstance(doc.get("materials"), dict):
        out += [(f"materials.{k}", v) for k, v in doc["materials"].items() if isinstance(v, dict)]
    for i, b in enumerate(doc.get("bodies", []) if isinstance(doc.get("bodies"), list) else []):
        if isinstance(b, dict) and isinstance(b.get("material"), dict):
            out.append((f"bodies[{i}].material", b["material"]))
        if isinstance(b, dict) and isinstance(b.get("materials"), dict):
            out += [(f"bodies[{i}].materials.{k}", v) for k, v in b["materials"].items() if isinstance(v, dict)]
    return [(w, t) for w, t in out if "test_data" in t]


def fit_material_command(path: str | Path, model: str | None = None, n: int | None = None,
                         plot: str | Path | None = None, error: str | None = None, out=None, err=None) -> int:
    """``covcontact fit-material DATA.toml``: fit every material table with test_data (or ``model``, ``n`` in
    place of its own), print the constants, the error per test, the stability verdict and the problem-file line;
    ``plot``: a PNG of data and fit. Bad input raises InputError (exit 2); instabilities are warnings (exit 0)."""
    import sys
    import tomllib

    out = out or sys.stdout
    err = err or sys.stderr
    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not a TOML file: {exc}") from None
    tables = _materials_with_data(doc)
    if not tables:
        raise InputError(f"{path}: no material with test_data (a [material] table with model, test_data = [{{ kind "
                         f"= \"uniaxial\", file = \"uni.csv\" }}, ...]; docs/input.md)")
    fits = []
    for where, t in tables:
        def fail(exc, where=where):
            return InputError(f"{path}: {where}.{exc.key}: {exc}" if getattr(exc, "key", None) else f"{path}: {where}: {exc}")

        own = t.get("model")
        m = model or own
        if not isinstance(m, str):
            raise InputError(f"{path}: {where}.model: missing required key (or give --model)")
        nn = n if n is not None else (t.get("n") if (model is None or model == own) else None)
        try:
            tests = read_tests(t["test_data"], path.parent)
            e = error or t.get("error", "relative")
            f = fit(m, tests, nn, e)
        except (FitError, RubberError) as exc:
            raise fail(exc) from None
        fits.append((where, t, f))
        lines = f.lines()
        print(f"{where}: {lines[0]}", file=out)
        for line in lines[1:] + [f"  {x}" for x in f.notes]:
            print(line, file=out)
        for w in f.warnings:
            print(f"covcontact: warning: {path}: {where}: {w}", file=err)
        dk = _d_keys(f.model)
        d = {k: t[k] for k in dk if k in t and (model is None or model == own)}
        dtext = ", ".join(f"{k} = {v}" for k, v in d.items()) or f"{dk[0]} = ... (the compressibility)"
        const = []
        for k, v in f.keys.items():
            const.append(f"{k} = [{', '.join(f'{x:.8g}' for x in v)}]" if isinstance(v, list) else f"{k} = {v:.8g}")
        extra = f", n = {f.n}" if f.model in ("polynomial", "reduced-polynomial") else ""
        print(f"  problem file: material = {{ model = \"{f.model}\"{extra}, {', '.join(const)}, {dtext} }}", file=out)
    if plot is not None:
        for k, (where, _, f) in enumerate(fits):
            p = Path(plot)
            if len(fits) > 1:
                p = p.with_name(f"{p.stem}-{re.sub(r'[^A-Za-z0-9_-]+', '_', where)}{p.suffix}")
            plot_fit(f, p, title=f"{path.name}: {where}")
            print(f"plot: {p}", file=out)
    return 0
