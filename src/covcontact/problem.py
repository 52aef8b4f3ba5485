"""The Python API: a Problem made of bodies, boundary conditions, loads, contact pairs and steps.

The TOML loader (``covcontact.io.loader``) builds exactly these objects; ``Problem.run`` does what
``covcontact run`` does.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from .description import (
    COMPONENTS,
    TANGENT_CASES,
    Body,
    ContactPair,
    Dynamics,
    InitialVelocity,
    OutputOptions,
    RigidBody,
    SolverOptions,
    Stage,
    Steps,
)
from .loads import Dirichlet, NodalForce, Pressure, Traction
from .mesh import Mesh
from .motion import RigidMotion

__all__ = ["COMPONENTS", "TANGENT_CASES", "Body", "ContactPair", "Dirichlet", "Dynamics", "InitialVelocity", "Mesh",
           "NodalForce", "OutputOptions", "Pressure", "Problem", "RigidBody", "RigidMotion", "SolverOptions", "Stage",
           "Steps", "Traction"]

@dataclass
class Problem:
    """A complete problem; ``run`` solves it and writes the results."""

    name: str
    bodies: list[Body]
    dirichlet: list[Dirichlet] = field(default_factory=list)
    #: linear multi-point constraints (``covcontact.loads.Equation``)
    equations: list = field(default_factory=list)
    #: nonlinear multi-point constraints (``covcontact.loads.MPC``)
    mpcs: list = field(default_factory=list)
    forces: list[NodalForce] = field(default_factory=list)
    pressures: list[Pressure] = field(default_factory=list)
    tractions: list[Traction] = field(default_factory=list)
    #: body forces (``covcontact.loads.BodyForce``)
    body_forces: list = field(default_factory=list)
    #: the first stage's loads ramp with the load factor (False: they act in full at once)
    ramp: bool = True
    rigid: list[RigidBody] = field(default_factory=list)
    contacts: list[ContactPair] = field(default_factory=list)
    steps: Steps = field(default_factory=lambda: Steps.equal(1))
    solver: SolverOptions = field(default_factory=SolverOptions)
    output: OutputOptions = field(default_factory=OutputOptions)
    description: str = ""
    source: Path | None = None
    stages: list[Stage] = field(default_factory=list)  # the stages after the first (this object's own)
    stage_name: str = "stage1"                           # the name of the first stage
    units: str = ""  # as stated by the user, e.g. "mm, N, MPa" (length first): labels of the pictures
    dynamics: Dynamics | None = None  # the first stage dynamic (None: quasi-static)
    gravity: tuple[float, float, float] | None = None  # a body force rho g on every body, in full from the start
    initial_velocity: list[InitialVelocity] = field(default_factory=list)
    #: springs and dashpots between nodes or to ground (``covcontact.elements.springs`` Spring, Dashpot)
    springs: list = field(default_factory=list)
    dashpots: list = field(default_factory=list)

    def stage_dynamics(self, index: int) -> Dynamics | None:
        """The time stepping of stage ``index`` (0: the first), None for a quasi-static stage."""
        return self.dynamics if index == 0 else self.stages[index - 1].dynamics

    def stage_list(self) -> list[tuple[str, Steps]]:
        """(name, steps) of every stage, the first included."""
        return [(self.stage_name, self.steps)] + [(s.name, s.steps) for s in self.stages]

    @property
    def loads(self) -> list:
        """Every nodal force, pressure, traction and body force, in that order."""
        return [*self.forces, *self.pressures, *self.tractions, *self.body_forces]

    def body(self, name: str) -> Body:
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(f"no deformable body named {name!r}")

    def run(self, out: str | Path | None = None, tangent: str | None = None, quiet: bool = True,
            solver: str | None = None, resume: bool = False, strict: bool = False):
        """Solve the problem and write the results to ``out`` (default ``results/<name>``).

        ``tangent`` overrides every contact pair's tangent case; ``resume`` continues from the last
        checkpoint in ``out`` (``covcontact.io.checkpoint.CheckpointError`` if there is none that fits);
        ``strict`` ends the run as failed (exit code 1) at the first step whose energy grows beyond what was brought
        in (a dynamic stage's energy account, docs/input.md "Dynamics").
        """
        from .solvers.run import solve_problem

        return solve_problem(self, out=out, tangent=tangent, quiet=quiet, linear=solver, resume=resume,
                            strict=strict)
