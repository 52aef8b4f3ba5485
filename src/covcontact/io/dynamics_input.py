"""Dynamic stages and initial velocities (docs/input.md, "Dynamics"): ``procedure = "dynamic"`` with ``dt``,
``t_end``, ``method``, ``rho_inf``, ``mass`` in ``[problem]`` (the first stage) or a ``[[stages]]`` entry, and
``[[initial_velocity]]``."""

from __future__ import annotations

from ..description import DYNAMIC_METHODS, MASSES, Dynamics, InitialVelocity
from .validate import Section

#: the keys of a dynamic stage besides ``procedure``
DYNAMIC_KEYS = ("dt", "t_end", "method", "rho_inf", "mass", "dt_min", "dt_max", "tolerance")


def read_dynamics(sec: Section) -> Dynamics | None:
    """The time stepping of a stage from its table (``[problem]`` or a ``[[stages]]`` entry); None for a quasi-static
    one. Dynamic keys without ``procedure = "dynamic"`` are one line."""
    procedure = sec.get("procedure", "str", "static", choices=("static", "dynamic"))
    if procedure == "static":
        given = [k for k in DYNAMIC_KEYS if sec.has(k)]
        if given:
            sec.fail(f"{given[0]!r} belongs to a dynamic stage: add procedure = \"dynamic\"", given[0])
        return None
    dt = sec.get("dt", "float", positive=True)
    t_end = sec.get("t_end", "float", positive=True)
    if dt > t_end:
        sec.fail(f"the time step {dt:g} exceeds the stage's duration t_end = {t_end:g}", "dt")
    method = sec.get("method", "str", "generalized-alpha", choices=DYNAMIC_METHODS)
    given = sec.has("rho_inf")
    rho = sec.get("rho_inf", "float", 1.0)
    if method == "newmark" and given:
        sec.fail("the Newmark trapezoidal rule has no numerical damping (rho_inf = 1); use method = "
                 "\"generalized-alpha\" or \"hht\" to damp high frequencies", "rho_inf")
    lo = 0.5 if method == "hht" else 0.0
    if not lo <= rho <= 1.0:
        sec.fail(f"must lie in [{lo:g}, 1] for method = \"{method}\", got {rho:g}", "rho_inf")
    mass = sec.get("mass", "str", "auto", choices=MASSES)
    auto = [k for k in ("dt_min", "dt_max") if sec.has(k)]
    if len(auto) == 1:
        sec.fail(f"automatic time steps need both dt_min and dt_max (and dt, the first step); add "
                 f"{'dt_max' if auto[0] == 'dt_min' else 'dt_min'}", auto[0])
    lo = sec.get("dt_min", "float", None, positive=True)
    hi = sec.get("dt_max", "float", None, positive=True)
    tol = sec.get("tolerance", "float", 1e-3, positive=True)
    if auto:
        if lo > hi:
            sec.fail(f"dt_min = {lo:g} is above dt_max = {hi:g}", "dt_min")
        if not lo <= dt <= hi:
            sec.fail(f"the first time step must lie between dt_min = {lo:g} and dt_max = {hi:g}, got {dt:g}", "dt")
        if hi > t_end:
            sec.fail(f"must not exceed the stage's duration t_end = {t_end:g}, got {hi:g}", "dt_max")
    return Dynamics(dt=dt, t_end=t_end, method=method, rho_inf=rho, mass=mass, dt_min=lo, dt_max=hi, tolerance=tol)


def read_initial_velocities(top: Section, sets) -> list[InitialVelocity]:
    """Every ``[[initial_velocity]]``: ``set = "BODY.SET"`` (a node set) or ``body = "BODY"`` (all its nodes), and
    ``value = [vx, vy, vz]``."""
    out = []
    for sec in top.get("initial_velocity", "array", []):
        value = sec.get("value", "vector")
        if sec.has("set") == sec.has("body"):
            sec.fail("give either set = \"BODY.SET\" (a node set) or body = \"BODY\" (all its nodes)")
        if sec.has("body"):
            name = sec.get("body", "str")
            if name not in {b.name for b in sets.bodies}:
                known = ", ".join(b.name for b in sets.bodies)
                sec.fail(f"no deformable body {name!r} (known: {known})", "body")
            out.append(InitialVelocity(name, "", value))
        else:
            body, nset = sets.body_set(sec, "set", "node")
            sets.deformable(sec, "set", body)
            out.append(InitialVelocity(body, nset, value))
        sec.done()
    return out


def check_densities(top: Section, bodies, why: str = "a dynamic stage") -> None:
    """A problem with a dynamic stage (or gravity, ``why``) needs the mass density of every material that has cells:
    one line naming the first one without."""
    for i, body in enumerate(bodies):
        for name, _, material, _ in body.material_parts():
            if getattr(material, "density", None) is None:
                key = f"bodies[{i}].materials.{name}.density" if name else f"bodies[{i}].material.density"
                top.fail(f"missing: {why} needs the mass density of every material (e.g. density = 7.85e-9 "
                         f"in t/mm^3 with mm, N, MPa)", key)
