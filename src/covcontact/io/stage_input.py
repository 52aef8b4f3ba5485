"""The ``[[stages]]`` entries of a problem file, each checked against the conditions, loads, rigid bodies
and contact pairs it names (docs/input.md, "Stages"). Used by :mod:`covcontact.io.loader`."""

from __future__ import annotations

import numpy as np

from .dynamics_input import read_dynamics
from .fields import COMPONENT_NAMES, dirichlet_values, names, read_motion, read_steps
from .validate import Section, suggest


def named_conditions(top: Section, dirichlet, forces, pressures, tractions, body_forces=(), equations=()) -> dict:
    """Name -> (kind, object) of the named Dirichlet conditions, loads and equations (one namespace)."""
    named: dict = {}
    for kind, items in (("dirichlet", dirichlet), ("force", forces), ("pressure", pressures),
                        ("traction", tractions), ("body_force", body_forces), ("equation", equations)):
        for i, obj in enumerate(items):
            if not obj.name:
                continue
            if obj.name in named:
                top.fail(f"the name {obj.name!r} is used twice (by a {named[obj.name][0]} and a {kind}); names of "
                         f"Dirichlet conditions and loads must differ", f"{kind}[{i}].name")
            named[obj.name] = (kind, obj)
    return named


def stage(st: Section, named: dict, dirichlet, rigid, contacts, earlier: list, first: str):
    """One ``[[stages]]`` entry, checked against the conditions, loads, bodies and pairs it names."""
    from ..description import Stage

    name = st.get("name", "str")
    if name == first or any(x.name == name for x in earlier):
        st.fail(f"duplicate stage name {name!r}", "name")
    dynamics = read_dynamics(st)
    if dynamics is not None and st.has("steps"):
        st.fail("a dynamic stage takes its steps from dt and t_end: remove 'steps'", "steps")
    steps = dynamics.steps() if dynamics is not None else read_steps(st.get("steps", "table", None))
    released_before = {n: x.name for x in earlier for n in x.release}

    def check_name(sec: Section, key: str, value: str, kinds: tuple[str, ...], what: str) -> tuple[str, object]:
        if value not in named or named[value][0] not in kinds:
            known = sorted(n for n, (k, _) in named.items() if k in kinds)
            sec.fail(f"no {what} named {value!r}{suggest(value, known)} (named ones: {', '.join(known) or 'none'})", key)
        starts = getattr(named[value][1], "stage", None)
        if starts is not None and starts != name and starts not in [x.name for x in earlier]:
            sec.fail(f"{value!r} holds from stage {starts!r} on, which comes later", key)
        if value in released_before:
            sec.fail(f"{value!r} was released in stage {released_before[value]!r}; a released condition "
                     f"stays free", key)
        return named[value]

    release = names(st, "release")
    pair_names = {c.name for c in contacts}
    pair_on = {c.name: bool(c.enabled) for c in contacts}  # as the stages before leave the pairs
    for x in earlier:
        pair_on.update(x.contacts)
        pair_on.update({n: False for n in x.release if n in pair_names})
    for n in release:
        is_condition = n in named and named[n][0] == "dirichlet"
        if is_condition and n in pair_names:
            st.fail(f"{n!r} names both a Dirichlet condition and a contact pair; rename one", "release")
        if not is_condition and n in pair_names:  # a pair: switched off, its forces ramped to zero
            if n in released_before:
                st.fail(f"contact pair {n!r} was released in stage {released_before[n]!r}", "release")
            if not pair_on[n]:
                st.fail(f"contact pair {n!r} is off at the start of this stage; there is nothing to release",
                        "release")
            if n in st.data.get("contacts", {}):
                st.fail(f"contact pair {n!r} is released and switched in 'contacts' in the same stage", "release")
            continue
        if n not in named or named[n][0] != "dirichlet":
            known = sorted({k for k, (kind, _) in named.items() if kind == "dirichlet"} | pair_names)
            st.fail(f"no Dirichlet condition or contact pair named {n!r}{suggest(n, known)} (named ones: "
                    f"{', '.join(known) or 'none'})", "release")
        check_name(st, "release", n, ("dirichlet",), "Dirichlet condition")
    if len(set(release)) != len(release):
        st.fail("names a condition twice", "release")
    remove = names(st, "remove")
    for n in remove:
        check_name(st, "remove", n, ("force", "pressure", "traction", "body_force", "rigid", "equation"),
                   "load or equation")
        if named[n][0] == "equation" and any(n in x.remove for x in earlier):
            st.fail(f"equation {n!r} was removed in an earlier stage", "remove")
    targets = {}
    tsec = st.get("targets", "table", None)
    if tsec is not None:
        for n in list(tsec.data):
            kind, obj = check_name(tsec, n, n, ("dirichlet", "force", "pressure", "traction", "body_force", "rigid",
                                                "equation"), "Dirichlet condition, load or equation")
            if n in release or n in remove:
                tsec.fail(f"{n!r} is {'released' if n in release else 'removed'} and given a target in the "
                          f"same stage", n)
            if kind == "dirichlet":
                if obj.motion is not None:
                    tsec.fail(f"{n!r} prescribes a motion; give it a new one in 'motions'", n)
                targets[n] = dirichlet_values(tsec, n, len(obj.components))
            elif kind in ("pressure", "equation"):  # (an equation's target: its right-hand side)
                targets[n] = tsec.get(n, "float")
            elif kind == "body_force" and obj.axis is not None:  # a spin: its new angular velocity omega
                omega = tsec.get(n, "float", nonnegative=True)
                targets[n] = (omega * omega, 0.0, 0.0)
            elif kind == "rigid":  # the force (a vector) or {force, moment} of a rigid body with free components
                if isinstance(tsec.data[n], dict):
                    t = tsec.get(n, "table")
                    targets[n] = {k: t.get(k, "vector") for k in ("force", "moment") if t.has(k)}
                    if not targets[n]:
                        t.fail("give 'force' and/or 'moment'")
                    t.done()
                else:
                    targets[n] = {"force": tsec.get(n, "vector")}
                for key, base in (("force", 0), ("moment", 3)):
                    vec = targets[n].get(key, (0.0, 0.0, 0.0))
                    bad = [i for i in range(3) if vec[i] != 0.0 and base + i not in obj.free]
                    if bad:
                        tsec.fail(f"{key} {'xyz'[bad[0]]} component given, but rigid body {n!r} is moved in "
                                  f"{COMPONENT_NAMES[base + bad[0]]!r}", n)
            else:
                targets[n] = tsec.get(n, "vector")
        tsec.done()
    motions = {}
    msec = st.get("motions", "table", None)
    if msec is not None:
        movable = {r.name for r in rigid} | {n for n, (k, o) in named.items() if k == "dirichlet"
                                              and o.motion is not None}
        for n in list(msec.data):
            if n not in movable:
                msec.fail(f"no rigid body or Dirichlet condition with a motion named {n!r}{suggest(n, movable)} (known: "
                          f"{', '.join(sorted(movable)) or 'none'})", n)
            if n in named and named[n][0] == "dirichlet" and n in {r.name for r in rigid}:
                msec.fail(f"{n!r} names both a rigid body and a Dirichlet condition; rename one", n)
            if n in release:
                msec.fail(f"{n!r} is released and given a motion in the same stage", n)
            if n in released_before:
                msec.fail(f"{n!r} was released in stage {released_before[n]!r}; a released condition stays "
                          f"free", n)
            motions[n] = read_motion(msec.get(n, "table"))
            body = next((r for r in rigid if r.name == n), None)
            if body is not None and body.free and not body.attach and (np.any(motions[n].rotation != 0.0)
                                                   or n in targets):
                msec.fail(f"rigid body {n!r} has free components: a stage motion holds them and may only "
                          f"translate it ({'no rotation' if n not in targets else 'no force target as well'})",
                          n)
        msec.done()
    switch = {}
    csec = st.get("contacts", "table", None)
    if csec is not None:
        pairs = {c.name for c in contacts}
        for n in list(csec.data):
            if n not in pairs:
                csec.fail(f"no contact pair named {n!r}{suggest(n, pairs)} (known: {', '.join(sorted(pairs)) or 'none'})", n)
            switch[n] = csec.get(n, "bool")
        csec.done()
    friction = {}
    fsec = st.get("friction", "table", None)
    if fsec is not None:  # a new Coulomb coefficient of a frictional pair (its stick history carries on)
        frictional = {c.name for c in contacts if c.friction > 0.0}
        for n in list(fsec.data):
            if n not in frictional:
                known = ", ".join(sorted(frictional)) or "none"
                fsec.fail(f"no frictional contact pair named {n!r}{suggest(n, frictional)} (a pair's friction changes "
                          f"only where it has friction from the start; frictional pairs: {known})", n)
            friction[n] = fsec.get(n, "float", nonnegative=True)
        fsec.done()
    ramp = st.get("ramp", "bool", True)
    st.done()
    return Stage(name, steps, tuple(release), targets, tuple(remove), motions, switch, dynamics, friction, ramp)
