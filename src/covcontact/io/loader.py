"""Read a TOML problem file into a ``covcontact.problem.Problem``, validating everything first.

The schema is documented in docs/input.md. Every error is an ``InputError`` whose message names the file,
the key path (or line) and what is wrong. One module reads each section: ``bodies_input`` ([[bodies]]),
``rigid_input`` ([[rigid]]), ``conditions_input`` ([[dirichlet]], [[force]], [[pressure]], [[traction]]),
``contact_input`` ([[contact]]), ``stage_input`` ([[stages]]), ``options_input`` ([solver], [output]); the
fields they share are read by ``fields``.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from ..problem import Problem
from .bodies_input import read_bodies
from .conditions_input import SetRefs, read_body_forces, read_dirichlet, read_equations, read_loads
from .contact_input import read_contacts
from .dynamics_input import check_densities, read_dynamics, read_initial_velocities
from .fields import read_steps
from .mpc_input import read_mpcs
from .options_input import read_output, read_solver
from .rigid_input import check_attached, knot_bodies, read_rigid
from .springs_input import read_springs
from .stage_input import named_conditions, stage
from .validate import InputError, Section, suggest


def load_problem(path: str | Path) -> Problem:
    """Parse and validate a problem file; raise InputError with a one-line message on any problem."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: file does not exist")
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: TOML syntax error: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read: {exc}") from None
    return problem_from_dict(raw, path)


_TOP_LEVEL = ("problem", "bodies", "rigid", "dirichlet", "force", "pressure", "traction", "body_force", "contact",
              "equation", "mpc", "spring", "dashpot", "steps", "stages", "initial_velocity", "solver", "output")


def problem_from_dict(raw: dict, path: Path) -> Problem:
    base = path.parent
    top = Section(raw, "", path)
    stray = sorted(set(top.data) - set(_TOP_LEVEL))
    if stray:  # before anything else: a misspelt section would otherwise surface as a missing name elsewhere
        top.fail("unknown section" + suggest(stray[0], _TOP_LEVEL, f" (known: {', '.join(_TOP_LEVEL)})"), stray[0])
    meta = top.get("problem", "table")
    name = meta.get("name", "str")
    description = meta.get("description", "str", "")
    meta_stage = meta.get("stage", "str", "stage1")
    units = meta.get("units", "str", "")
    dynamics = read_dynamics(meta)
    gravity = meta.get("gravity", "vector", None)
    ramp = meta.get("ramp", "bool", True)
    meta.done()

    bodies = read_bodies(top, base)
    rigid = read_rigid(top, base, bodies)
    rigid += knot_bodies(bodies, rigid)  # (shells with creases = "knots": a rigid body per knot)
    sets = SetRefs(bodies, rigid)
    dirichlet = read_dirichlet(top, sets)
    forces, pressures, tractions = read_loads(top, sets)
    body_forces = read_body_forces(top, bodies)
    contacts = read_contacts(top, sets, rigid)
    planar = {b.name: b.formulation for b in bodies if b.formulation in ("plane_strain", "plane_stress",
                                                                          "axisymmetric")}
    for i, c in enumerate(contacts):  # contact in the plane: node-to-segment (covcontact.contact.planar)
        names = [b for b, _ in c.self_surfaces] if c.self_surfaces else [c.slave[0], c.master[0]]
        if any(n in planar for n in names):
            from ..contact.planar import check_pair
            why = check_pair(c, bodies, rigid)
            if why is not None:
                top.fail(why, f"contact[{i}]")
    equations = read_equations(top, sets, dirichlet)
    springs, dashpots = read_springs(top, sets)
    mpcs = read_mpcs(top, sets, bodies, dirichlet, equations, rigid)

    for i, r in enumerate(rigid):
        if r.free and not r.attach and not any(r.name in (c.slave[0], c.master[0]) for c in contacts):
            top.fail(f"rigid body {r.name!r} has free components but no contact pair: nothing would restrain "
                     f"it; add a [[contact]] with it or drop 'free'", f"rigid[{i}].free")
    if dynamics is not None and top.has("steps"):
        top.fail("a dynamic first stage takes its steps from dt and t_end in [problem]: remove [steps]", "steps")
    steps = dynamics.steps() if dynamics is not None else read_steps(top.get("steps", "table", None))
    velocities = read_initial_velocities(top, sets)

    named = named_conditions(top, dirichlet, forces, pressures, tractions, body_forces, equations)
    for r in rigid:  # rigid bodies with free components: their force is a load later stages may change
        if r.free and r.name not in named:
            named[r.name] = ("rigid", r)
    stage_name = meta_stage
    stages = []
    for st in top.get("stages", "array", []):
        stages.append(stage(st, named, dirichlet, rigid, contacts, stages, stage_name))

    later = [st.name for st in stages]
    for i, bc in enumerate(dirichlet):  # conditions that start in a later stage
        if bc.stage is not None and bc.stage not in later:
            top.fail(f"no later stage named {bc.stage!r}{suggest(bc.stage, later)} (the stages after the first: "
                     f"{', '.join(later) or 'none'})", f"dirichlet[{i}].stage")
    dynamic = dynamics is not None or any(st.dynamics is not None for st in stages)
    for i, eq in enumerate(equations):  # (a right-hand side's rate would be missing from the eliminated velocity)
        if dynamic and (eq.value != 0.0 or any(eq.name and eq.name in st.targets for st in stages)):
            top.fail("a right-hand side (value, or a stage's target) in a problem with dynamic stages: not available "
                     "yet; keep the equation homogeneous there", f"equation[{i}].value")
    if dynamic or gravity is not None:
        check_densities(top, bodies, "a dynamic stage" if dynamic else "gravity")
        for i, r in enumerate(rigid):  # a free rigid body moves by its mass and inertia
            if r.attach:  # (its inertia is its attached nodes')
                continue
            if any(c < 3 for c in r.free) and r.mass is None:
                top.fail("missing: a rigid body with free translations needs its mass in a dynamic stage (or with "
                         "gravity)", f"rigid[{i}].mass")
            if any(c >= 3 for c in r.free) and r.inertia is None and dynamic:
                top.fail("missing: a rigid body with free rotations needs its principal moments of inertia "
                         "[Ixx, Iyy, Izz] about its reference point in a dynamic stage", f"rigid[{i}].inertia")
    elif velocities:
        top.fail("initial velocities need a dynamic stage (procedure = \"dynamic\")", "initial_velocity")
    if dashpots and not dynamic:
        top.fail("dashpots act in dynamic stages only (their force is c times a velocity), and this problem has none "
                 "(procedure = \"dynamic\")", "dashpot")
    check_attached(top, rigid, bodies, dirichlet, equations)
    solver = read_solver(top)
    output = read_output(top)
    top.done()
    return Problem(name=name, description=description, bodies=bodies, dirichlet=dirichlet, forces=forces,
                   pressures=pressures, tractions=tractions, rigid=rigid, contacts=contacts, steps=steps, solver=solver,
                   output=output, source=path, stages=stages, stage_name=stage_name,
                   units=units, dynamics=dynamics, initial_velocity=velocities, gravity=gravity, equations=equations,
                   body_forces=body_forces, ramp=ramp, springs=springs, dashpots=dashpots, mpcs=mpcs)
