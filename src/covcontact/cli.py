"""Command line: covcontact run | study | check-tangent | compile | info | import | ccx.

Exit codes: 0 done; 1 a step did not converge even after cutbacks (converged steps are written);
2 bad input or a checkpoint that cannot be resumed (one line on stderr); 3 anything else (a bug: one line on
stderr, the traceback in the run's traceback.txt, summary status "failed"); 130 / 143 stopped by SIGINT / SIGTERM
(files valid, summary status "interrupted").
"""

from __future__ import annotations

import argparse
import os
import sys
import traceback
from pathlib import Path

from . import __version__
from .io.validate import InputError
from .problem import TANGENT_CASES


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, exit 2
        print(f"covcontact: {message}", file=sys.stderr)
        raise SystemExit(2)


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="covcontact", description="Covariant node-to-surface contact for large deformations.")
    p.add_argument("--version", action="version", version=f"covcontact {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    cases = ("tangent of the contact element: a = main + rotational + curvature (the paper's full tangent), "
             "b = main + rotational, c = main + curvature, d = main only, exact = exact Hessian")
    solver = ("linear solver: auto (default), pardiso, superlu, cg-amg, petsc, petsc-gamg, ... "
              "(`covcontact info` lists those available here)")
    r = sub.add_parser("run", help="solve a problem file", description="Solve a problem file; results, "
                       "summary.json and checkpoints go to the output folder.")
    r.add_argument("problem", help="the problem file (TOML; keys in docs/input.md), or an Abaqus / CalculiX deck "
                   "(.inp: imported into the output folder first, a .dat table of its *NODE PRINT requests written)")
    r.add_argument("--out", default=None, metavar="DIR",
                   help="output folder (default: results/NAME, NAME from [problem] name)")
    r.add_argument("--tangent", choices=TANGENT_CASES, default=None,
                   help=cases + " (default: the file's [[contact]] tangent, else a)")
    r.add_argument("--solver", default=None, metavar="NAME", help=solver)
    r.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    r.add_argument("--resume", action="store_true",
                   help="continue from the last checkpoint in the output folder (same problem, same ranks)")
    r.add_argument("--ranks", type=_ranks_arg, default="auto", metavar="N",
                   help="run as N MPI ranks of the distributed model (starts mpiexec itself; the `mpi` extra): "
                        "petsc-gamg where auto picks it, else petsc (MUMPS), or the --solver given; 1: one "
                        "process (default auto: one rank per core where the solver auto picks petsc-gamg, else "
                        "one process)")
    r.add_argument("--strict", action="store_true",
                   help="a step whose energy grows beyond what was brought in (a dynamic stage's energy account) "
                        "ends the run as failed, exit code 1, instead of a warning")
    r.add_argument("--ignore-unsupported", action="store_true",
                   help="a deck: go on without what covcontact does not support (each ignored line is listed)")
    r.add_argument("--dialect", choices=("auto", "calculix", "abaqus"), default="auto",
                   help="a deck: read it as CalculiX or Abaqus does where the two differ (default auto: Abaqus "
                        "where the deck has *PART / *ASSEMBLY / *INSTANCE, else CalculiX)")
    d = sub.add_parser("import", help="write the covcontact problem of an Abaqus / CalculiX deck",
                       description="Read an Abaqus or CalculiX input deck and write the equivalent problem file, its "
                       "meshes (NAME.mesh.K.inp, one per body) and node labels (NAME.nodes.json) beside it "
                       "(docs/input.md, \"Abaqus and CalculiX decks\"). What the deck has and covcontact does not "
                       "support is listed with its line, and nothing is written (exit 2) unless --ignore-unsupported.")
    d.add_argument("deck", help="the deck (.inp)")
    d.add_argument("--out", default=None, metavar="FILE", help="the problem file to write (default: NAME.toml "
                   "beside the deck)")
    d.add_argument("--ignore-unsupported", action="store_true",
                   help="write the problem without what covcontact does not support (each ignored line is listed)")
    d.add_argument("--dialect", choices=("auto", "calculix", "abaqus"), default="auto",
                   help="read the deck as CalculiX or Abaqus does where the two differ (default auto)")
    s = sub.add_parser("study", help="run a problem once per tangent case and tabulate the iterations",
                       description="Run a problem once per tangent case; writes table.md, table.csv "
                       "(the layout of the paper's Table 1) and iterations.png.")
    s.add_argument("problem", help="the problem file (TOML)")
    s.add_argument("--cases", default="a,b,c,d,exact", metavar="LIST",
                   help="comma-separated tangent cases (default: a,b,c,d,exact); " + cases)
    s.add_argument("--out", default=None, metavar="DIR", help="output folder (default: results/NAME-study)")
    s.add_argument("--solver", default=None, metavar="NAME", help=solver)
    s.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    c = sub.add_parser("check-tangent", help="compare the assembled tangent with finite differences",
                       description="Solve up to a step, then compare the assembled tangent (bodies + contact) "
                       "with central finite differences of the residual. Prints the relative error and a "
                       "verdict; exit 1 when the error exceeds --tol.")
    c.add_argument("problem", help="the problem file (TOML)")
    c.add_argument("--step", type=int, default=1, metavar="K",
                   help="the converged load step to check at, counted over all stages (default 1; 0 = the "
                   "undeformed start); with --stage, the K-th step of that stage. The step is reached as "
                   "`covcontact run` reaches it, cutbacks included")
    c.add_argument("--stage", default=None, metavar="NAME",
                   help="count --step within this stage (the first stage's name is [problem] stage)")
    c.add_argument("--tangent", choices=TANGENT_CASES, default="exact",
                   help=cases + " (default: exact; cases a-d leave out parts of the exact Hessian by design)")
    c.add_argument("--run-tangent", choices=TANGENT_CASES, default=None, metavar="CASE",
                   help="the tangent case the run to the step solves with, as `covcontact run --tangent` (default: "
                   "each pair's own case, as `covcontact run` without it)")
    c.add_argument("--columns", default="60", metavar="N|all",
                   help="tangent columns to difference: a share from the contact zone, one from the plastic "
                   "zone, the rest drawn at random (default 60); `all`: every free dof")
    c.add_argument("--h", type=float, default=None, metavar="H",
                   help="the first difference step (default 1e-7 times the largest coordinate); the check also "
                   "differences at H/10 and H/100")
    c.add_argument("--tol", type=float, default=1e-6,
                   help="largest relative error (Frobenius norm over the judged columns) that passes "
                   "(default 1e-6)")
    c.add_argument("--solver", default=None, metavar="NAME", help=solver)
    c.add_argument("--json", default=None, metavar="FILE", help="also write the whole report as JSON to FILE")
    w = sub.add_parser("compile", help="compile every numerical kernel into numba's cache (once, after installing)",
                       description="Run tiny problems that call every compiled kernel, so that numba's cache "
                       "holds them all and the first real run starts at once (and compiles covcontact's modules to "
                       "bytecode where the installation has none). Run it once after installing covcontact or "
                       "upgrading numba.")
    w.add_argument("--only", default=None, metavar="TEXT",
                   help="only the warm-up problems whose label contains TEXT (default: all)")
    w.add_argument("--jobs", default=None, type=int, metavar="N",
                   help="compile in N worker processes (default: one per core, at most one per group of kernels)")
    f = sub.add_parser("fit-material", help="fit a rubber model to test data: constants, errors, stability, plot",
                       description="Fit the rubber models of the material tables with test_data (uniaxial, "
                       "equibiaxial, planar nominal stress against nominal strain; docs/input.md) by least squares, "
                       "incompressible as Abaqus fits; print the constants, the error of every test, Drucker's "
                       "stability verdict and the problem-file line. An unstable fit is a warning (exit 0).")
    f.add_argument("data", help="a TOML file with a [material] table (model, n, test_data) or a problem file")
    f.add_argument("--model", default=None, help="fit this model instead of the table's (neo-hooke, mooney-rivlin, "
                   "polynomial, reduced-polynomial, yeoh, arruda-boyce, gent, ogden)")
    f.add_argument("--n", type=int, default=None, help="the order N (polynomial, reduced polynomial) or the number "
                   "of Ogden terms")
    f.add_argument("--error", default=None, choices=("relative", "absolute"),
                   help="the error minimised (default: the table's, else relative, as Abaqus)")
    f.add_argument("--plot", default=None, metavar="PNG", help="write a plot of the data and the fit")
    sub.add_parser("info", help="version, linear solvers, threads",
                   description="Print the version, the linear solvers available here and the thread count.")
    x = sub.add_parser("ccx", help="run a CalculiX deck as `ccx -i JOB` does (for pre-processors)",
                       description="Run JOB.inp as CalculiX's `ccx -i JOB` does, for the pre-processors that start "
                       "ccx (FreeCAD FEM, PrePoMax): writes JOB.dat, JOB.frd, JOB.sta and JOB.cvg beside the deck, "
                       "CalculiX's lines on standard output, and exits as ccx does: 0 done, 201 an input error "
                       "(*ERROR lines) or an increment that did not converge. covcontact's own results (summary.json, "
                       "VTU files) go to JOB.covcontact/ (docs/input.md, \"Abaqus and CalculiX decks\").")
    x.add_argument("-i", dest="job_i", default=None, metavar="JOB", help="the job: its deck is JOB.inp")
    x.add_argument("job", nargs="?", default=None, help="the job, as `ccx JOB`")
    x.add_argument("--out", default=None, metavar="DIR",
                   help="covcontact's own results (default: JOB.covcontact beside the deck)")
    x.add_argument("--solver", default=None, metavar="NAME", help=solver)
    x.add_argument("--ignore-unsupported", action="store_true",
                   help="go on without what covcontact does not support (each ignored line is a *WARNING)")
    return p


def _ranks_arg(text: str) -> int | str:
    """``--ranks``: ``auto`` or a whole number (checked by the run: at least 1)."""
    text = text.strip().lower()
    if text == "auto":
        return text
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of ranks or auto, got {text!r}") from None


def _check_solver(name: str | None) -> None:
    if name is None or name == "auto":
        return
    from .solvers.linear import available

    if name not in available():
        hint = " (needs petsc4py and mpi4py: the `mpi` extra)" if name.startswith("petsc") else ""
        raise InputError(f"--solver: unknown or unavailable linear solver {name!r}{hint} "
                         f"(available here: {', '.join(available())})")


def _import(deck: Path, out: Path, ignore: bool, dialect: str = "auto") -> object | None:
    """Import ``deck`` into ``out``; None (after listing them on stderr) when it has unsupported parts and ``ignore``
    is not given. The notes (defaults filled in) are listed too."""
    from .io.deck_import import import_deck

    imported = import_deck(deck, out, dialect)
    for line in imported.notes:
        print(f"covcontact: note: {line}", file=sys.stderr)
    for line in imported.unsupported:
        print(f"covcontact: {'ignored' if ignore else 'unsupported'}: {line}", file=sys.stderr)
    if imported.unsupported and not ignore:
        print(f"covcontact: error: {deck}: {len(imported.unsupported)} unsupported keywords or parameters (listed "
              f"above); --ignore-unsupported goes on without them", file=sys.stderr)
        return None
    return imported


def cmd_import(args) -> int:
    deck = Path(args.deck)
    out = Path(args.out) if args.out else deck.with_suffix(".toml")
    imported = _import(deck, out, args.ignore_unsupported, args.dialect)
    if imported is None:
        for f in [out, out.with_suffix(".nodes.json"), *out.parent.glob(f"{out.stem}.mesh.*.inp")]:
            f.unlink(missing_ok=True)
        return 2
    print(f"wrote {imported.problem}, {', '.join(p.name for p in imported.meshes)}, {imported.labels.name}",
          file=sys.stderr)
    return 0


def _run_deck(args) -> int:
    """``covcontact run DECK.inp``: the deck imported into OUT/deck/, run in one process, the .dat table and the .frd
    results beside."""
    from .io.deck_dat import DatTable
    from .io.frd import FrdFile
    from .io.loader import load_problem
    from .solvers.run import solve_problem

    deck = Path(args.problem)
    if args.ranks not in ("auto", 1):  # (said, not ignored)
        raise InputError(f"--ranks {args.ranks}: a deck runs in one process; import it (covcontact import "
                         f"{deck.name}) and run the problem file with --ranks")
    out = Path(args.out) if args.out else Path("results") / deck.stem
    imported = _import(deck, out / "deck" / f"{deck.stem}.toml", args.ignore_unsupported,
                       getattr(args, "dialect", "auto"))
    if imported is None:
        return 2
    from .io.bodies_input import preload

    preload(imported.read)  # (the meshes the import built: not read back from its files)
    problem = load_problem(imported.problem)
    _check_solver(args.solver or problem.solver.linear)
    table = DatTable(imported.labels, out / f"{deck.stem}.dat",
                     deck={"file": deck.name, "ignored": imported.unsupported, "notes": imported.notes})
    frd = FrdFile(imported.labels, out / f"{deck.stem}.frd")
    result = solve_problem(problem, out=out, tangent=args.tangent, quiet=args.quiet, linear=args.solver,
                           resume=args.resume, observers=[table, frd], strict=getattr(args, "strict", False))
    if not args.quiet:
        print(f"results in {result.out}", file=sys.stderr)
    return result.exit_code


def cmd_ccx(args) -> int:
    """``covcontact ccx -i JOB``: JOB.inp run as ``ccx -i JOB`` runs it (io/ccx_job.py): JOB.dat, JOB.frd, JOB.sta,
    JOB.cvg, CalculiX's lines on standard output, its exit codes (0; 201 for an input error or an increment that did
    not converge; 130 / 143 stopped by a signal)."""
    import time

    from . import __version__
    from .io.bodies_input import preload
    from .io.ccx_job import CcxStatus, banner, finished, start_files
    from .io.deck_dat import DatTable
    from .io.deck_import import import_deck
    from .io.frd import FrdFile
    from .io.loader import load_problem
    from .solvers.run import solve_problem

    t0 = time.perf_counter()
    name = args.job_i or args.job
    if not name:
        print("Usage: covcontact ccx -i jobname", flush=True)
        return 201
    name = name[:-4] if name.lower().endswith(".inp") else name
    job = Path(name)
    deck, dat, frd, sta, cvg = (job.with_name(job.name + ext) for ext in (".inp", ".dat", ".frd", ".sta", ".cvg"))
    print(banner(__version__), end="", flush=True)
    try:
        start_files(sta, cvg)
        dat.write_text("")
        frd.unlink(missing_ok=True)
    except OSError as exc:
        print(f" *ERROR in openfile: could not open file {exc.filename}", flush=True)
        return 201
    if not deck.is_file():
        print(f" *ERROR in openfile: could not open file {deck}", flush=True)
        return 201
    out = Path(args.out) if args.out else job.with_name(job.name + ".covcontact")
    try:
        imported = import_deck(deck, out / "deck" / f"{job.name}.toml", "calculix")
        for line in getattr(imported, "notes", []):
            print(f" *INFO: {line}", flush=True)
        for line in imported.unsupported:
            print(f" *{'WARNING' if args.ignore_unsupported else 'ERROR'}: not supported by covcontact: {line}",
                  flush=True)
        if imported.unsupported and not args.ignore_unsupported:
            print(f" *ERROR: {deck}: {len(imported.unsupported)} unsupported keywords or parameters (listed above); "
                  f"--ignore-unsupported goes on without them", flush=True)
            return 201
        preload(imported.read)
        problem = load_problem(imported.problem)
        _check_solver(args.solver or problem.solver.linear)
        status = CcxStatus(imported.labels, sta, cvg)
        observers = [DatTable(imported.labels, dat, deck={"file": deck.name, "ignored": imported.unsupported,
                                                          "notes": list(getattr(imported, "notes", []))}),
                     FrdFile(imported.labels, frd), status]
        result = solve_problem(problem, out=out, quiet=True, linear=args.solver, observers=observers)
    except InputError as exc:
        print(f" *ERROR reading {deck}: {exc}", flush=True)
        return 201
    if result.exit_code == 0:
        print(finished(time.perf_counter() - t0), flush=True)
        return 0
    if result.exit_code == 1:
        print(f"\n *ERROR: an increment did not converge even after cutbacks ({status.failure}); {frd.name} holds "
              f"the steps that converged\n", flush=True)
        return 201
    return result.exit_code


def cmd_run(args) -> int:
    from .io.loader import load_problem

    if Path(args.problem).suffix.lower() == ".inp":
        return _run_deck(args)
    problem = load_problem(args.problem)
    _check_solver(args.solver or problem.solver.linear)
    started = args.ranks == "auto"
    if started:  # one rank per core where auto picks petsc-gamg (solvers/run.py auto_ranks), else this process
        from .solvers.choice import auto_ranks

        args.ranks = auto_ranks(problem, args.solver, args.out, args.resume)
    if args.ranks != 1:
        return _run_ranks(args, problem, started)
    result = problem.run(out=args.out, tangent=args.tangent, quiet=args.quiet, solver=args.solver,
                         resume=args.resume, strict=args.strict)
    if not args.quiet and result.model.is_root:  # one line from a distributed run
        print(f"results in {result.out}", file=sys.stderr)
    return result.exit_code


def _run_ranks(args, problem, started: bool = False) -> int:
    """``covcontact run --ranks N``: the same command under ``mpiexec -n N`` with a distributed solver; returns its
    exit code. SIGINT and SIGTERM are passed on to mpiexec: with Open MPI the first as SIGUSR2 and SIGUSR1, which
    it relays to the ranks without killing them, so that they stop together at their next Newton iteration and
    keep their converged steps, as a serial run does (solvers/signals.py); a second signal is passed on as it is
    and stops them at once."""
    import shutil
    import signal
    import subprocess

    from .parallel.launcher import (
        cores_here,
        environment_for_mpiexec,
        is_open_mpi,
        ranks_from_env,
        threads_per_rank,
    )
    from .solvers.choice import auto_line, check_distributable, requested_linear, resolve_linear
    from .solvers.linear import available
    from .solvers.signals import StopSignals

    n = args.ranks
    if n < 1:
        raise InputError(f"--ranks: the number of MPI ranks must be at least 1, got {n}")
    if ranks_from_env() > 1:
        raise InputError("--ranks: this command was itself started by mpiexec; use one of the two")
    cores = cores_here()
    if n > 8 * cores:
        raise InputError(f"--ranks {n}: only {cores} cores here; one rank per core is fastest")
    if "petsc" not in available():
        raise InputError(f"--ranks {n}: needs petsc4py and mpi4py (the `mpi` extra; bash tools/install-mpi.sh "
                         f"installs them)")
    mpiexec = shutil.which("mpiexec")
    if mpiexec is None:
        raise InputError(f"--ranks {n}: mpiexec not found on PATH (it comes with the MPI that mpi4py was built on)")
    requested = requested_linear(problem, args.solver)
    solver = resolve_linear(problem, args.solver, ranks=n)
    check_distributable(problem, solver, n)
    if solver != requested and not args.quiet:
        print(auto_line(solver, n, started=started), file=sys.stderr, flush=True)
    cmd = [mpiexec, "-n", str(n)]
    open_mpi = is_open_mpi(mpiexec)
    if n > cores:  # legal, but the ranks take turns on the cores
        print(f"covcontact: warning: --ranks {n} on {cores} cores: the ranks will share cores, which is slower than "
              f"--ranks {cores}", file=sys.stderr, flush=True)
        if open_mpi:  # Open MPI refuses more ranks than cores unless told
            cmd.append("--oversubscribe")
    cmd += [sys.executable, "-m", "covcontact.cli", "run", str(args.problem), "--solver", solver]
    cmd += ["--out", args.out] if args.out else []
    cmd += ["--tangent", args.tangent] if args.tangent else []
    cmd += [flag for flag, on in (("--quiet", args.quiet), ("--resume", args.resume), ("--strict", args.strict))
            if on]
    env = environment_for_mpiexec()  # each rank takes its share of the cores (parallel.comm.share_cores)
    if started:  # the run's thread budget is shared out: NUMBA_NUM_THREADS and the like become per rank
        env.update(threads_per_rank(env, n))
    proc = subprocess.Popen(cmd, env=env)
    received: list[int] = []

    relay = {v: k for k, v in StopSignals.RELAYED.items()} if open_mpi else {}

    def forward(sig, _frame):
        received.append(sig)
        proc.send_signal(relay.get(sig, sig) if len(received) == 1 else sig)

    previous = {sig: signal.signal(sig, forward) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        code = proc.wait()
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if received:  # stopped by a signal: its exit code (130 / 143), whatever mpiexec made of it
        return 128 + int(received[0])
    return 128 - code if code < 0 else code


def cmd_study(args) -> int:
    from .io.loader import load_problem
    from .study import run_study

    problem = load_problem(args.problem)
    _check_solver(args.solver or problem.solver.linear)
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    bad = [c for c in cases if c not in TANGENT_CASES]
    if bad or not cases:
        raise InputError(f"--cases: unknown case {bad[0] if bad else '(none)'!r} "
                         f"(choose from {', '.join(TANGENT_CASES)})")
    out = Path(args.out) if args.out else Path("results") / f"{problem.name}-study"
    return run_study(problem, cases, out, solver=args.solver, quiet=args.quiet)


def cmd_check_tangent(args) -> int:
    from .io.loader import load_problem
    from .tangent_check import check_tangent, report_lines, stage_steps

    problem = load_problem(args.problem)
    stages = stage_steps(problem)
    step, stage = args.step, None
    if args.stage is not None:
        names = [n for n, _ in stages]
        if args.stage not in names:
            raise InputError(f"--stage: no stage named {args.stage!r} in {args.problem} (stages: "
                             f"{', '.join(names)})")
        stage = names.index(args.stage)
        count = stages[stage][1]
        if step < 1 or (count is not None and step > count):
            raise InputError(f"--step: stage {args.stage!r} has steps 1 to {count if count is not None else 'N'}, "
                             f"got {step}")
    else:
        total = None if any(n is None for _, n in stages) else sum(n for _, n in stages)
        if step < 0 or (total is not None and step > total):
            raise InputError(f"--step: must lie between 0 and {total} (the steps of all stages), got {step}")
    if not args.tol > 0:
        raise InputError(f"--tol: must be > 0, got {args.tol}")
    if args.h is not None and not args.h > 0:
        raise InputError(f"--h: must be > 0, got {args.h}")
    cols = args.columns.strip().lower()
    if cols != "all" and not (cols.isdigit() and int(cols) > 0):
        raise InputError(f"--columns: a whole number > 0 or `all`, got {args.columns!r}")
    _check_solver(args.solver or problem.solver.linear)
    rep = check_tangent(problem, step=step, tangent=args.tangent, columns=None if cols == "all" else int(cols),
                        h=args.h, solver=args.solver, run_tangent=args.run_tangent, stage=stage)
    for line in report_lines(rep, args.tol):
        print(line)
    if args.json:
        import json

        from .io.atomic import replacing
        from .io.output import _jsonable

        with replacing(args.json) as tmp:
            Path(tmp).write_text(json.dumps(rep, indent=1, default=_jsonable))
    if not rep["converged"]:
        print(f"check-tangent: {rep['reason']}", file=sys.stderr)
        return rep.get("exit_code", 1)
    return 0 if rep["judged"] and rep["relative_error"] <= args.tol else 1


def cmd_compile(args) -> int:
    import time

    from .warmup import PROBLEMS, byte_compile, warm, warm_parallel

    if args.only is not None and not any(args.only in label for label, _ in PROBLEMS):
        raise InputError(f"--only: no warm-up problem matches {args.only!r} (labels: "
                         f"{'; '.join(label for label, _ in PROBLEMS)})")
    if args.jobs is not None and args.jobs < 1:
        raise InputError(f"--jobs {args.jobs}: the number of worker processes is 1 or more")
    jobs = args.jobs if args.jobs is not None else (os.cpu_count() or 1)
    t0 = time.perf_counter()
    byte_compile()  # the modules' bytecode too, where the installation lacks it (PYTHONDONTWRITEBYTECODE)
    done = warm(only=args.only) if args.only is not None or jobs == 1 else warm_parallel(jobs)
    print(f"covcontact: {len(done)} warm-up problems in {time.perf_counter() - t0:.1f} s; the kernels are in "
          f"numba's cache", file=sys.stderr)
    return 0


def _ranks_info() -> str:
    """What ``--ranks auto`` may start here: its thread budget, whether mpiexec and the PETSc solvers are there."""
    import shutil

    from .solvers.choice import AUTO_DOFS_PER_RANK, thread_budget
    from .solvers.linear import available

    budget = thread_budget()
    missing = [what for what, ok in (("mpiexec on the PATH", shutil.which("mpiexec") is not None),
                                     ("the PETSc solvers (the `mpi` extra)", "petsc-gamg" in available())) if not ok]
    if missing:
        return f"one process (no {' and no '.join(missing)}); `--ranks auto` needs them"
    if budget < 2:
        return "one process (one core for this run: its affinity, CPU quota or NUMBA_NUM_THREADS)"
    return (f"`--ranks auto` starts up to {budget} (one per core, at most one per {AUTO_DOFS_PER_RANK:,} dofs) "
            f"where auto picks petsc-gamg")


def cmd_fit_material(args) -> int:
    from .io.fit_command import fit_material_command

    return fit_material_command(args.data, args.model, args.n, args.plot, args.error)


def cmd_info(args) -> int:
    import numba

    from .solvers.linear import describe

    print(f"covcontact {__version__}")
    print(f"numba {numba.__version__}, threads {numba.get_num_threads()}")
    print(f"MPI ranks: {_ranks_info()}")
    print("linear solvers:")
    for d in describe():
        mark = "yes" if d.get("available") else "no "
        print(f"  {mark}  {d['name']:<10} {d.get('version') or '':<12} {d.get('note', '')}")
    return 0


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    handler = {"run": cmd_run, "study": cmd_study, "check-tangent": cmd_check_tangent,
               "compile": cmd_compile, "info": cmd_info, "import": cmd_import, "ccx": cmd_ccx,
               "fit-material": cmd_fit_material}[args.command]
    if args.command not in ("info", "compile"):
        from .compile_notice import install

        install()  # one line on stderr when this run has to compile kernels (a new installation)
    try:
        return handler(args)
    except InputError as exc:
        print(f"covcontact: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # the reader of the standard output left (``covcontact info | head``)
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no error at exit either
        except OSError:
            pass
        return 141  # 128 + SIGPIPE, as the shell reports a program stopped by a closed pipe
    except Exception as exc:  # a bug: one line, the traceback in a file
        print(f"covcontact: internal error: {_one_line(exc)}", file=sys.stderr)
        return 3


def _one_line(exc: BaseException) -> str:
    """An unexpected exception in one line: its type and message, where it was raised, and the file that holds its
    traceback (the run's ``traceback.txt`` beside summary.json, else a temporary file)."""
    root = exc
    while isinstance(root, SystemError) and (root.__cause__ or root.__context__) is not None:
        root = root.__cause__ or root.__context__  # numba wraps an exception of compiled code in a SystemError
    frames = traceback.extract_tb(exc.__traceback__)
    where = f" at {Path(frames[-1].filename).name}:{frames[-1].lineno} in {frames[-1].name}" if frames else ""
    path = getattr(exc, "covcontact_traceback", None)
    if path is None:
        try:
            import tempfile

            with tempfile.NamedTemporaryFile("w", prefix="covcontact-traceback-", suffix=".txt", delete=False) as fh:
                fh.write("".join(traceback.format_exception(exc)))
            path = fh.name
        except OSError:
            path = None
    message = " ".join(str(root).split()) or "(no message)"
    return (f"{type(root).__name__}: {message}{where} (a bug, exit 3"
            + (f"; traceback in {path})" if path else ")"))


def entry() -> None:
    """The ``covcontact`` command (and ``python -m covcontact``): ``main`` and a quick exit.

    Tearing the interpreter down (its modules, numba's and LLVM's objects) takes about 0.25 s after the
    run's work is done and its files are closed; the command skips it: it flushes the standard streams, runs
    the ``atexit`` handlers and leaves. Runs that loaded MPI (PETSc) exit normally, MPI finalises at teardown.
    """
    code = main()
    if "mpi4py" in sys.modules or "petsc4py" in sys.modules:
        sys.exit(code)
    import atexit

    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(code)


if __name__ == "__main__":
    entry()
