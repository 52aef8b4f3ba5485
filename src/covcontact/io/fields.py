"""Readers of the fields that several sections of a problem file share: motions, set references, Dirichlet
values, component names, name lists and load steps (docs/input.md)."""

from __future__ import annotations

from dataclasses import replace

import math

from ..description import Steps
from ..motion import RigidMotion
from .validate import Section


def read_motion(sec: Section | None) -> RigidMotion:
    """A ``motion = { translation, rotation, center, path, total }`` table (none: standing still)."""
    if sec is None:
        return RigidMotion()
    translation = sec.get("translation", "vector", (0.0, 0.0, 0.0))
    rotation = sec.get("rotation", "vector", (0.0, 0.0, 0.0))
    center = sec.get("center", "vector", (0.0, 0.0, 0.0))
    path = None
    if sec.has("path"):
        raw = sec.get("path", "any")
        ok = isinstance(raw, list) and all(
            isinstance(r, list) and len(r) == 4 and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in r)
            for r in raw)
        if not ok:
            sec.fail("must be an array of rows [lam, tx, ty, tz]", "path")
        path = raw
    total = sec.get("total", "bool", False)
    sec.done()
    try:
        return RigidMotion(translation=translation, rotation=rotation, center=center, path=path, total=total)
    except ValueError as exc:
        sec.fail(str(exc), "path" if path is not None else None)


def split_ref(sec: Section, key: str, value: str) -> tuple[str, str]:
    """``"body.set"`` -> (body, set); a name without a dot -> (name, "")."""
    if "." in value:
        body, name = value.split(".", 1)
        return body, name
    return value, ""


def dirichlet_values(sec: Section, key: str, n: int) -> tuple:
    """A Dirichlet value: one number for every component, or an array of one per component."""
    if sec.has(key) and isinstance(sec.data[key], list):
        return tuple(sec.get(key, "floats", length=n))
    return (sec.get(key, "float", 0.0),) * n


COMPONENT_NAMES = ("x", "y", "z", "rx", "ry", "rz")


def free_components(sec: Section) -> tuple[int, ...]:
    """``free = ["z", "rx", ...]``: the rigid body's components left to equilibrium."""
    given = names(sec, "free")
    for n in given:
        if n not in COMPONENT_NAMES:
            sec.fail(f"{n!r} is not a component (x, y, z, rx, ry, rz)", "free")
    if len(set(given)) != len(given):
        sec.fail("names a component twice", "free")
    return tuple(sorted(COMPONENT_NAMES.index(n) for n in given))


def names(sec: Section, key: str) -> tuple[str, ...]:
    """An array of names (strings) under ``key`` (default: none)."""
    raw = sec.get(key, "any", [])
    if not isinstance(raw, list) or not all(isinstance(v, str) for v in raw):
        sec.fail("must be an array of names (strings)", key)
    return tuple(raw)


def read_steps(sec: Section | None) -> Steps:
    """A ``[steps]`` table: ``count`` (and ``final``), ``factors``, or automatic increments ``initial``, ``min``,
    ``max`` (and ``final``); none: one step to 1."""
    if sec is None:
        return Steps.equal(1)
    auto = [k for k in ("initial", "min", "max") if sec.has(k)]
    fixed = [k for k in ("count", "factors") if sec.has(k)]
    if auto and fixed:
        sec.fail(f"give either {' / '.join(fixed)} or automatic increments (initial, min, max), not both", auto[0])
    marks = sec.get("output_at", "floats", ())
    if any(b <= a for a, b in zip((0.0,) + marks, marks)):
        sec.fail("must be a strictly increasing list of positive load factors", "output_at")
    if sec.has("factors"):
        factors = sec.get("factors", "floats")
        sec.done()
        if not factors or any(b <= a for a, b in zip((0.0,) + factors, factors)):
            sec.fail("must be a non-empty, strictly increasing list of positive load factors", "factors")
        _marks_on_steps(sec, marks, factors)
        return Steps(factors, output_at=marks)
    if auto:
        final = sec.get("final", "float", 1.0, positive=True)
        initial = sec.get("initial", "float", positive=True)
        lo = sec.get("min", "float", min(initial, 1e-5 * final), positive=True)
        hi = sec.get("max", "float", final, positive=True)
        sec.done()
        if lo > hi:
            sec.fail(f"min = {lo:g} is above max = {hi:g}; min must not exceed max", "min")
        if not lo <= initial <= hi:
            sec.fail(f"must lie between min = {lo:g} and max = {hi:g}, got {initial:g}", "initial")
        if hi > final:
            sec.fail(f"must not exceed the stage's final load factor {final:g}, got {hi:g}", "max")
        if marks and marks[-1] > final:
            sec.fail(f"{marks[-1]:g} lies beyond the stage's final load factor {final:g}", "output_at")
        return replace(Steps.automatic(initial, lo, hi, final), output_at=marks)
    n = sec.get("count", "int", 1, positive=True)
    final = sec.get("final", "float", 1.0, positive=True)
    sec.done()
    steps = Steps.equal(n, final)
    _marks_on_steps(sec, marks, steps.factors)
    return replace(steps, output_at=marks)


def _marks_on_steps(sec: Section, marks: tuple, factors: tuple) -> None:
    """With fixed steps every ``output_at`` value must be the end of a step."""
    for m in marks:
        if not any(abs(m - f) <= 1e-9 * max(1.0, abs(f)) for f in factors):
            sec.fail(f"{m:g} is not the end of a step ({', '.join(f'{f:g}' for f in factors[:6])}"
                     f"{', ...' if len(factors) > 6 else ''}); with fixed steps list step ends, or use automatic "
                     "increments (initial, min, max), which end exactly at each output_at", "output_at")
