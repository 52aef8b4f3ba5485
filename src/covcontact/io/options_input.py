"""The ``[solver]`` and ``[output]`` sections (docs/input.md)."""

from __future__ import annotations

from ..description import OutputOptions, SolverOptions
from .validate import Section


def _reuse_option(sec: Section, default):
    """[solver] reuse_factorization: true, false or "auto"."""
    value = sec.get("reuse_factorization", "any", default)
    if not (isinstance(value, bool) or value == "auto"):
        sec.fail(f'must be true, false or "auto", got {value!r}', "reuse_factorization")
    return value


def read_solver(top: Section) -> SolverOptions:
    """The ``[solver]`` table (none: the defaults)."""
    s = top.get("solver", "table", None)
    solver = SolverOptions()
    if s is not None:
        solver = SolverOptions(
            linear=s.get("linear", "str", solver.linear),
            max_iterations=s.get("max_iterations", "int", solver.max_iterations, positive=True),
            rtol=s.get("rtol", "float", solver.rtol, positive=True),
            atol=s.get("atol", "float", solver.atol, nonnegative=True),
            etol=s.get("etol", "float", solver.etol, nonnegative=True),
            criterion=s.get("criterion", "str", solver.criterion, choices=("residual", "energy", "both")),
            max_cutbacks=s.get("max_cutbacks", "int", solver.max_cutbacks, nonnegative=True),
            line_search=s.get("line_search", "bool", solver.line_search),
            divergence_factor=s.get("divergence_factor", "float", solver.divergence_factor, positive=True),
            reuse_factorization=_reuse_option(s, solver.reuse_factorization),
            krylov_max=s.get("krylov_max", "int", solver.krylov_max, positive=True),
            predictor=s.get("predictor", "str", solver.predictor, choices=("auto", "tangent", "extrapolate")),
            factorization_precision=s.get("factorization_precision", "str", solver.factorization_precision,
                                          choices=("auto", "double", "single")),
            reproducible=s.get("reproducible", "bool", solver.reproducible),
        )
        if solver.factorization_precision == "single" and solver.linear.lower().strip() not in ("auto", "pardiso"):
            s.fail(f'"single" is PARDISO\'s; linear = {solver.linear!r} factorises in double precision '
                   f'(use linear = "pardiso", or leave factorization_precision out)', "factorization_precision")
        s.done()
    return solver


def read_output(top: Section) -> OutputOptions:
    """The ``[output]`` table (none: the defaults)."""
    o = top.get("output", "table", None)
    output = OutputOptions()
    if o is not None:
        output = OutputOptions(vtu=o.get("vtu", "bool", True), every=o.get("every", "int", 1, positive=True),
                               pictures=o.get("pictures", "bool", False),
                               checkpoint_every=o.get("checkpoint_every", "int", 1, positive=True))
        o.done()
    return output
