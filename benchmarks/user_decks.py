"""Decks written by users: the CalculiX example collection run by CalculiX and by covcontact, side by side.

The collection is the CalculiX project's public one (calculix/CalculiX-Examples on GitHub). Get a checkout first;
this script downloads nothing:

    git clone https://github.com/calculix/CalculiX-Examples

Every ``*.inp`` file of the checkout that holds a ``*STEP`` is a deck. A deck is structural when all of its steps are
``*STATIC`` or ``*DYNAMIC``; decks with a heat transfer, frequency, buckling, creep (``*VISCO``), coupled, steady
state or CFD step are listed as out of scope. A deck has contact when it, or a file it includes, holds
``*CONTACT PAIR`` or ``*TIE``; all structural decks count, the contact ones first. Only decks present as ``.inp``
files count (decks that the collection's cgx scripts write are not looked for).

Most decks ``*INCLUDE`` meshes, sets and surfaces (``all.msh``, ``*.nam``, ``*.sur``, ...) that the folder's cgx
pre-processing scripts write and the checkout does not hold: such a deck "needs pre-processing". Without
``--preprocess`` it stays out of the survey (it is no covcontact failure). With ``--preprocess`` the folder's
pre-processing runs in the deck's scratch copy as the folder's ``test.py`` runs it, in its order, until every file the
deck includes exists: the ``param.py`` templates (expanded here), ``cgx -bg`` on the scripts (their view and picture
commands left out, cgx's ``sys`` commands allowed, a ``ccx`` that does nothing first on the PATH, so that CalculiX runs
once, below), and the surface files of cgx 2.17, which lack their ``*SURFACE`` line, completed as later versions of
cgx write them. A deck whose files are still missing after that (gmsh or CAD tools not installed, ...) stays "needs
pre-processing".

Each deck of the survey is run in a scratch copy of its folder, first by CalculiX (``ccx -i JOB``; a deck that
CalculiX does not finish, ``Job finished``, within the timeout is out of the survey), then by ``covcontact run
JOB.inp``, and classified by covcontact's exit code: runs (0), refused (2: the first line covcontact does not support,
grouped by its keyword, e.g. ``*ELEMENT, TYPE=S8R`` or ``*BOUNDARY on dof 6``), fails (1: a step did not converge),
crashes (3: a bug; the last frame of traceback.txt) or timeout. For a deck that runs, the ``.dat`` blocks that both
print at the same time are compared as benchmarks/ccx_decks.py compares them (its ``dat_blocks`` and matching): the
largest difference over the block's largest CalculiX value, of U and of RF (where the deck prints none to the
``.dat``: DISP and FORC of the two ``.frd`` files at the ends of the steps, on the deck's own nodes: both codes
number the expanded nodes of shells anew, each its own way; a deck of shells alone, whose files share no own node,
on every label). covcontact is always geometrically
nonlinear: a deck with a linear step (no NLGEOM) that differs by more than 1e-2 is run by CalculiX once more with
NLGEOM added to its steps and compared with that run too.

A markdown table (a row per deck) and the counts go to stderr, everything to the JSON file (docs/verification.md,
"Decks written by users: the CalculiX example collection").

    python benchmarks/user_decks.py CHECKOUT [--preprocess] [--decks Contact,Tubes/solve] [--timeout 150]
        [--ccx-timeout 90] [--out results/user_decks.json] [--work results/user_decks]
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ccx_decks import compare, compare_blocks, frd_displacements  # noqa: E402  (dat_blocks and the matching)

#: procedures of a structural step, and of the steps of other analyses (out of scope)
STRUCTURAL = {"STATIC", "DYNAMIC"}
OTHER = {"FREQUENCY", "BUCKLE", "HEATTRANSFER", "COUPLEDTEMPERATURE-DISPLACEMENT",
         "UNCOUPLEDTEMPERATURE-DISPLACEMENT", "VISCO", "STEADYSTATEDYNAMICS", "MODALDYNAMIC", "CFD", "GREEN",
         "SENSITIVITY", "COMPLEXFREQUENCY", "ELECTROMAGNETICS", "NOANALYSIS", "THERMO-MECHANICAL"}
#: files of a folder not copied into its scratch copy (pictures, results)
IGNORE = shutil.ignore_patterns("*.png", "*.gif", "*.jpg", "*.jpeg", "*.svg", "*.ps", "*.eps", "*.pdf", "*.mp4",
                                "*.webm", "*.frd", "Refs", ".git")
#: the programs of a folder's test.py that pre-process (the rest: ccx, monitor.py, gnuplot, mv, ... are not run)
PRE = ("cgx", "param.py", "periodic.py", "separate.py", "gmsh")


# ---------------------------------------------------------------------------------------------------------------------
# reading decks


def _keyword(line: str) -> tuple[str, dict[str, str]]:
    """The keyword of a keyword line (upper case, without blanks) and its parameters."""
    parts = line[1:].split(",")
    params = {}
    for p in parts[1:]:
        k, _, v = p.partition("=")
        if k.strip():
            params[k.strip().upper().replace(" ", "")] = v.strip()
    return parts[0].strip().upper().replace(" ", ""), params


def scan(deck: Path) -> dict:
    """The keywords of ``deck`` and of the files it includes that exist: the procedures of its steps, whether it has
    contact, each step's NLGEOM, and the included files that are absent (relative to the deck's folder)."""
    cards: list[str] = []
    missing: list[str] = []
    steps: list[dict] = []
    contact: set[str] = set()
    types: set[str] = set()
    seen: set[Path] = set()

    def walk(path: Path):
        if path in seen:
            return
        seen.add(path)
        for line in path.read_text(errors="replace").splitlines():
            if not line.startswith("*") or line.startswith("**"):
                continue
            name, params = _keyword(line)
            cards.append(name)
            if name == "INCLUDE":
                inc = params.get("INPUT", "").strip().strip('"').strip("'")
                target = path.parent / inc
                if target.is_file():
                    walk(target)
                elif inc:
                    missing.append(os.path.relpath(target, deck.parent))
            elif name == "STEP":
                steps.append({"nlgeom": "NLGEOM" in params and params["NLGEOM"].upper() != "NO", "procedures": []})
            elif steps and (name in STRUCTURAL or name in OTHER):
                steps[-1]["procedures"].append(name)
            elif name == "ELEMENT" and params.get("TYPE"):
                types.add(params["TYPE"].upper())
            elif name in ("CONTACTPAIR", "TIE"):
                contact.add("*CONTACT PAIR" if name == "CONTACTPAIR" else "*TIE")

    walk(deck)
    procs = sorted({p for s in steps for p in s["procedures"]})
    return {"steps": len(steps), "procedures": procs, "contact": sorted(contact), "missing": sorted(set(missing)),
            "linear": any(not s["nlgeom"] for s in steps), "types": sorted(types)}


def find_decks(root: Path) -> list[dict]:
    """Every .inp of the checkout with a *STEP, with what ``scan`` says of it and whether it is structural."""
    out = []
    for path in sorted(root.rglob("*.inp")):
        if any(part.startswith(".") or part == "Refs" for part in path.relative_to(root).parts):
            continue
        info = scan(path)
        if not info["steps"]:
            continue
        other = [p for p in info["procedures"] if p not in STRUCTURAL]
        info.update(deck=str(path.relative_to(root).with_suffix("")), path=path,
                    structural=bool(info["procedures"]) and not other,
                    scope=("" if info["procedures"] and not other else
                           "steps: " + ", ".join("*" + p for p in other) if other else "no procedure"))
        out.append(info)
    return out


# ---------------------------------------------------------------------------------------------------------------------
# running


def _limit_memory(gib: float):
    def limit():
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (int(gib * 2**30), int(gib * 2**30)))
    return limit


def _run(cmd: list[str], cwd: Path, timeout: float, env: dict | None = None, log: Path | None = None,
         memory_gib: float | None = None) -> tuple[int | None, str, str, float]:
    """Run ``cmd`` in its own process group, its output into the files ``log``.out and ``log``.err (None: discarded):
    (exit code, None on timeout; the last 20,000 characters of stdout and of stderr; seconds). On timeout the group is
    sent SIGTERM (covcontact keeps its files) and SIGKILL 10 s later. ``memory_gib``: its address space limit."""
    t0 = time.perf_counter()
    files = [open(f"{log}.{x}", "w") if log else subprocess.DEVNULL for x in ("out", "err")]
    try:
        proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=files[0], stderr=files[1], start_new_session=True,
                                stdin=subprocess.DEVNULL, preexec_fn=_limit_memory(memory_gib) if memory_gib else None)
        try:
            code = proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            code = None
            for sig, wait in ((signal.SIGTERM, 10), (signal.SIGKILL, 30)):
                try:
                    os.killpg(proc.pid, sig)
                except ProcessLookupError:
                    break
                try:
                    proc.wait(timeout=wait)
                    break
                except subprocess.TimeoutExpired:
                    pass
    finally:
        for f in files:
            if f is not subprocess.DEVNULL:
                f.close()

    def tail(x):
        if not log:
            return ""
        with open(f"{log}.{x}", "rb") as f:
            f.seek(0, 2)
            f.seek(max(0, f.tell() - 20000))
            return f.read().decode(errors="replace")

    return code, tail("out"), tail("err"), time.perf_counter() - t0


def _leading_text(node) -> tuple[str, bool]:
    """The text of a string expression of test.py: (text, complete); an expression built from variables gives its
    leading literal part."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value, True
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        return _leading_text(node.left)[0], False
    if isinstance(node, ast.JoinedStr):
        text = ""
        for part in node.values:
            if not (isinstance(part, ast.Constant) and isinstance(part.value, str)):
                return text, False
            text += part.value
        return text, True
    return "", False


def preprocessing_commands(folder: Path, stem: str) -> list[list[str]]:
    """The pre-processing commands of a folder, in order: those of its test.py whose program is one of PRE (a
    command built from variables: its literal part up to the script's name), then its pre*.fbd / .fbl, the cgx script
    named as the deck and run*.fbd / .fbl that test.py did not name."""
    cmds: list[list[str]] = []
    test = folder / "test.py"
    if test.is_file():
        try:
            tree = ast.parse(test.read_text(errors="replace"))
        except SyntaxError:
            tree = None
        calls = sorted((n for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)
                        and n.func.attr == "system" and n.args),
                       key=lambda n: (n.lineno, n.col_offset)) if tree else []
        for call in calls:
            text, complete = _leading_text(call.args[0])
            words = text.split()
            if not complete and words and not text.endswith(" "):
                words = words[:-1]  # (the word the expression continues)
            if not words or words[0] not in PRE:
                continue
            if words[0] == "cgx":
                files = [w for w in words[1:] if not w.startswith("-")]
                if files:
                    cmds.append(["cgx", "-bg", files[0]])
            elif len(words) > 1:
                cmds.append(words)
    named = {c[-1] for c in cmds if c[0] == "cgx"}
    extra = sorted(p.name for p in folder.iterdir() if p.suffix in (".fbd", ".fbl")
                   and (p.stem in ("pre", stem) or p.stem.startswith(("pre", "run"))) and p.name not in named)
    cmds += [["cgx", "-bg", name] for name in extra]
    # the script named as the deck first (a folder of several decks: each has its own script, which writes the mesh)
    own = [c for c in cmds if (c[0] == "cgx" and Path(c[-1]).stem == stem) or
           (c[0] == "param.py" and len(c) > 1 and Path(c[1]).stem == f"par.{stem}")]
    return own + [c for c in cmds if c not in own]


#: cgx script lines that need a program beside cgx: (pattern, the programs, any one of which does)
TOOLS = ((re.compile(r"^\s*sys\s+gmsh\b", re.I), ("gmsh",)),
         (re.compile(r"^\s*sys\s+cad2fbd\b", re.I), ("cad2fbd",)),
         (re.compile(r"^\s*elty\s+\S+\s+te(4|10)", re.I), ("ng_vol", "tetgen")))


def tools_missing(folder: Path, scripts: list[str]) -> list[str]:
    """The programs that the cgx ``scripts`` of ``folder`` use and this machine lacks: gmsh (meshing), cad2fbd
    (CAD import), ng_vol or tetgen (cgx's tetrahedral meshing; without one cgx writes the surface triangles only)."""
    missing: list[str] = []
    for name in scripts:
        path = folder / name
        if not path.is_file():
            continue
        for line in path.read_text(errors="replace").splitlines():
            for pattern, programs in TOOLS:
                if pattern.match(line) and not any(shutil.which(p) for p in programs):
                    missing.append(" or ".join(programs))
    return sorted(set(missing))


#: cgx commands that change only the view or take pictures: cgx -bg, without a display, stops at some of them
VIEW = {"rot", "tra", "zoom", "view", "frame", "plot", "plus", "minus", "hcpy", "anim", "movi", "text", "ulin",
        "scal"}


def _headless(folder: Path) -> None:
    """Leave out the view and picture commands of the cgx scripts of ``folder`` (VIEW), so that cgx -bg runs them."""
    for script in list(folder.glob("*.fbd")) + list(folder.glob("*.fbl")):
        lines = script.read_text(errors="replace").splitlines()
        kept = [ln for ln in lines if (ln.split() or [""])[0].lower() not in VIEW]
        if len(kept) != len(lines):
            script.write_text("\n".join(kept) + "\n")


def param(folder: Path, args: list[str]) -> int:
    """The collection's Scripts/param.py (its templates ``par.NAME``: ``<name=expression>`` defines, ``<expression>``
    is replaced by its value, math's functions known; ``name=value`` arguments override definitions), written here
    because the script's own namespace is empty under Python 3.8 .. 3.11: 0 done, 1 an expression that fails."""
    import math

    source = folder / args[0]
    target = folder / (source.name[4:] if source.name.startswith("par.") else source.name.removesuffix(".par"))
    override = dict(a.split("=", 1) for a in args[1:] if "=" in a)
    names: dict = {k: getattr(math, k) for k in dir(math) if not k.startswith("_")} | {"abs": abs, "int": int}
    glob = {"__builtins__": None}
    out = []
    try:
        for line in source.read_text(errors="replace").splitlines(keepends=True):
            parts = re.split(r"<([^>]*)>", line)
            text = ""
            for i in range(0, len(parts), 2):
                text += parts[i]
                if i + 1 < len(parts):
                    active = parts[i + 1]
                    if "=" in active:
                        exec(active, glob, names)  # noqa: S102 (the collection's own templates)
                        key = active.split("=")[0].strip()
                        if key in override:
                            exec(f"{key}={override[key]}", glob, names)  # noqa: S102
                            active = f"{key}={override[key]}"
                        text += active
                    else:
                        text += str(eval(active, glob, names))  # noqa: S307
            out.append(text)
    except Exception:  # noqa: BLE001 (as param.py: the target stops at the failing line)
        target.write_text("".join(out))
        return 1
    target.write_text("".join(out))
    return 0


def _surface_headers(folder: Path) -> None:
    """Give the surfaces cgx wrote (``** Surfaces based on NAME`` and the faces, in a .sur file or gathered into
    another by a script) the ``*SURFACE, NAME=SNAME`` line that cgx 2.17 (Debian's calculix-cgx) leaves out and later
    versions write, as the decks expect."""
    for path in folder.iterdir():
        if not path.is_file() or path.suffix in (".fbd", ".fbl", ".py", ".md", ".frd") or path.stat().st_size > 5e7:
            continue
        text = path.read_text(errors="replace")
        if "** Surfaces based on " not in text:
            continue
        lines = text.splitlines()
        out = []
        for k, line in enumerate(lines):
            out.append(line)
            nxt = lines[k + 1] if k + 1 < len(lines) else ""
            if line.startswith("** Surfaces based on ") and not nxt.startswith("*"):
                out.append(f"*SURFACE, NAME=S{line.split('based on ', 1)[1].strip()}")
        if len(out) != len(lines):
            path.write_text("\n".join(out) + "\n")


def preprocess(work: Path, deck: Path, root: Path, timeout: float) -> tuple[list[str], list[str]]:
    """Run the folder's pre-processing in the scratch copy ``work`` until every file ``deck`` includes exists (each
    command at most ``timeout`` s, all of them at most 3 ``timeout``): (the commands run, the included files still
    missing and the programs the scripts run needed and this machine lacks, ``tools_missing``). cgx runs with a HOME of its own whose .cgx allows the scripts' ``sys`` commands (cgx asks at the first
    one otherwise), with a ``ccx`` that does nothing first on the PATH and with the collection's Scripts folder."""
    tools = work / ".preprocessing"
    (tools / "bin").mkdir(parents=True, exist_ok=True)
    (tools / "bin" / "ccx").write_text("#!/bin/sh\nexit 0\n")   # (cgx scripts that start ccx: CalculiX runs later)
    (tools / "bin" / "ccx").chmod(0o755)
    (tools / ".cgx").write_text("ALLOW_SYS\n")
    env = dict(os.environ, HOME=str(tools),
               PATH=os.pathsep.join([str(tools / "bin"), str(root / "Scripts"), os.environ.get("PATH", "")]))
    ran: list[str] = []
    scripts: list[str] = []
    missing = scan(deck)["missing"]
    t0 = time.perf_counter()
    for cmd in preprocessing_commands(work, deck.stem):
        if not missing or time.perf_counter() - t0 > 3 * timeout:
            break
        if cmd[0] == "cgx":
            if not (work / cmd[-1]).is_file():
                continue
            scripts.append(cmd[-1])
            _headless(work)
        shown = " ".join(cmd)
        if cmd[0] == "param.py":
            code = param(work, cmd[1:]) if len(cmd) > 1 and (work / cmd[1]).is_file() else 1
            ran.append(shown + ("" if code == 0 else " (fails)"))
            missing = scan(deck)["missing"]
            continue
        if cmd[0].endswith(".py"):
            cmd = [sys.executable, str(root / "Scripts" / cmd[0])] + cmd[1:]
        elif not shutil.which(cmd[0]):
            ran.append(f"{shown} (not installed)")
            continue
        code, _, _, _ = _run(cmd, work, timeout, env, memory_gib=4)
        _surface_headers(work)
        ran.append(shown + ("" if code == 0 else f" (exit {code})" if code is not None else " (timeout)"))
        missing = scan(deck)["missing"]
    shutil.rmtree(tools, ignore_errors=True)
    return ran, missing + [f"(a program: {p})" for p in tools_missing(work, scripts)]


def _ccx(work: Path, job: str, timeout: float) -> dict:
    code, out, err, secs = _run(["ccx", "-i", job], work, timeout, log=work / f"{job}.ccx")
    finished = code == 0 and "Job finished" in out and (work / f"{job}.dat").is_file()
    res = {"finishes": finished, "seconds": round(secs, 1)}
    if not finished:
        errors = [ln.strip() for ln in out.splitlines() if "*ERROR" in ln]
        res["why"] = ("timeout" if code is None else (errors[0] if errors else
                      (out.strip().splitlines() or err.strip().splitlines() or [f"exit {code}"])[-1]))[:200]
    return res


#: a refusal reason's location prefix (file:line: )
_WHERE = re.compile(r"^[^*:]*?\.[A-Za-z0-9]{1,5}(:\d+)?: ")


def reason_key(line: str) -> str:
    """The group of a line covcontact does not support: its keyword and what of it (``*ELEMENT, TYPE=S8R``,
    ``*BOUNDARY on dof 6``, ``*SURFACE: a shell face``), without the file, line, labels, names or explanation."""
    text = _WHERE.sub("", line.strip(), count=1)
    m = re.match(r"^S\S+ on element \d+, a (\S+) \(not read\)", text)
    if m:
        return f"*SURFACE: a face of a {m.group(1)} element"
    m = re.match(r"^the surface \S+ has element \d+, a (\S+) \(not read\)", text)
    if m:
        return f"*CONTACT PAIR / *TIE: a surface of {m.group(1)} elements"
    for cut in (" is not supported", " (", "; "):
        text = text.split(cut)[0]
    m = re.match(r"^(\*[A-Z][A-Z ]*?) (\S+): (.*)$", text)   # (*KEYWORD NAME: what)
    if m:
        text = f"{m.group(1)}: {re.sub(r'^[A-Z0-9]+, ', '', m.group(3))}"
    text = re.sub(r"\b(node|element|surface|set|body|NODE) [A-Z][A-Z0-9_.\-]*\b", r"\1 X", text)
    text = re.sub(r"\b(node|element) \d+", r"\1 N", text)
    text = re.sub(r"(/[^\s,:]*)?/([^/\s,:]+)", r"\2", text)     # (paths: the file's name)
    text = re.sub(r"(NAME)=[^,]*", r"\1=...", text)
    return text.strip()[:90]


def _family(etype: str) -> str:
    for prefix, name in (("CPS", "CPS* (plane stress)"), ("CPE", "CPE* (plane strain)"), ("CAX", "CAX* (axisymmetric)"),
                         ("S", "S* (shell)"), ("B", "B* (beam)"), ("T", "T* (truss)"), ("U", "U* (user element)")):
        if re.match(prefix + r"\d", etype):
            return name
    return etype


def reason_group(key: str) -> str:
    """A reason's group for the ranking: element types by family (``*ELEMENT, TYPE=CPS* (plane stress)``), the rest
    as it is."""
    m = re.match(r"^\*ELEMENT, TYPE=(\S+)", key)
    if not m:
        return key
    return "*ELEMENT, TYPE=" + " + ".join(sorted({_family(t) for t in m.group(1).split("/")}))


def classify(code: int | None, err: str, run: Path, types: list[str] = ()) -> dict:
    """covcontact's result from its exit code, stderr and output folder (``types``: the deck's element types)."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if code is None:
        return {"result": "timeout"}
    if code == 0:
        return {"result": "runs"}
    if code == 2:
        unsup = [ln.split("unsupported: ", 1)[1] for ln in lines if ln.startswith("covcontact: unsupported: ")]
        if unsup:
            keys = list(dict.fromkeys(reason_key(u) for u in unsup))
            return {"result": "refused", "reason": keys[0], "reasons": keys, "first_line": unsup[0][:300]}
        errs = [ln for ln in lines if "error" in ln.lower()] or lines or ["exit 2"]
        msg = errs[-1].split("error: ", 1)[-1]
        what = reason_key(msg)
        key = ("*ELEMENT, TYPE=" + "/".join(types) + " (no solid elements)" if what.startswith("no solid elements")
               and types else "input error: " + what)
        return {"result": "refused", "reason": key, "reasons": [key], "first_line": msg[:300]}
    if code == 1:
        why = lines[-1] if lines else "exit 1"
        summary = run / "summary.json"
        if summary.is_file():
            try:
                s = json.loads(summary.read_text())
                why = s.get("reason") or why
            except ValueError:
                pass
        return {"result": "fails", "reason": str(why)[:300]}
    if code == 3:
        tb = run / "traceback.txt"
        last = [ln for ln in (tb.read_text(errors="replace").splitlines() if tb.is_file() else []) if ln.strip()]
        frames = [ln.strip() for ln in last if ln.strip().startswith("File ")]
        return {"result": "crashes", "reason": (lines[-1] if lines else "exit 3")[:300],
                "traceback": (frames[-1] if frames else "") + (" | " + last[-1].strip() if last else "")}
    return {"result": "other", "reason": f"exit {code}: " + (lines[-1] if lines else "")[:300]}


def frd_blocks(path: Path, upto: int | None = None) -> dict:
    """The DISP and FORC blocks of an ASCII .frd (CalculiX's or covcontact's) in the form of ccx_decks' .dat blocks:
    ("displacements" / "forces", "FRD", time) -> node label -> (3,); with ``upto`` the nodes of labels up to it alone
    (the deck's own: both codes number the expanded nodes of shells and planar elements after the deck's largest
    label, each in its own way, so those labels name different nodes in the two files)."""
    from covcontact.io.frd import read_frd

    if not path.is_file():
        return {}
    try:
        sets = read_frd(path).sets
    except Exception:  # noqa: BLE001 (a file whose elements covcontact's reader does not know: its DISP blocks)
        blocks = frd_displacements(path.read_text(errors="replace"))
    else:
        kinds = {"DISP": "displacements", "FORC": "forces"}
        blocks = {(kinds[s.name], "FRD", s.time): {k: np.asarray(v)[:3] for k, v in s.values.items()}
                  for s in sets if s.name in kinds}
    if upto is None:
        return blocks
    return {key: {k: v for k, v in b.items() if int(k) <= upto} for key, b in blocks.items()}


def frd_compare(mine: Path, ref: Path, upto: int | None, shells: bool = False) -> list[dict]:
    """compare_blocks of the two .frd files on the deck's own nodes (labels up to ``upto``); where they share none
    and the deck has shells (``shells``: both files hold only the expanded nodes, numbered each in its own way), the
    displacements of the nodes whose reference positions coincide (both codes expand a shell node along the same
    normal to its bottom and top layer; the forces are shared out among the layers differently), marked
    ``expanded``."""
    blocks = compare_blocks(frd_blocks(mine, upto), frd_blocks(ref, upto)) if upto is not None else []
    if blocks or not shells:
        return blocks
    return [dict(b, expanded=True) for b in compare_blocks(*by_position(mine, ref)) if b["kind"] == "displacements"]


def by_position(mine: Path, ref: Path) -> tuple[dict, dict]:
    """(mine, ref) blocks of frd_blocks on the nodes of ``ref`` that have a node of ``mine`` at their reference
    position (within 1e-6 of the model's size), mine's values under ref's labels; positions that two nodes of
    ``ref`` share (a cut, a knot's layers) are left out."""
    from scipy.spatial import cKDTree

    from covcontact.io.frd import read_frd

    a, b = frd_blocks(mine), frd_blocks(ref)
    if not a or not b:
        return {}, {}
    try:
        xa, xb = read_frd(mine).nodes, read_frd(ref).nodes
    except Exception:  # noqa: BLE001 (elements the reader does not know: no positions)
        return {}, {}
    la, lb = np.array(sorted(xa)), np.array(sorted(xb))
    pa, pb = np.array([xa[k] for k in la]), np.array([xb[k] for k in lb])
    tol = 1e-6 * float(np.ptp(pb, axis=0).max())
    dist, near = cKDTree(pa).query(pb)
    shared = np.zeros(lb.size, dtype=bool)
    pairs = cKDTree(pb).query_pairs(tol, output_type="ndarray")
    shared[pairs.ravel()] = True
    ok = (dist <= tol) & ~shared
    match = dict(zip(lb[ok].tolist(), la[near[ok]].tolist()))
    mapped = {key: {k: blk[v] for k, v in match.items() if v in blk} for key, blk in a.items()}
    return mapped, {key: {k: v for k, v in blk.items() if k in match} for key, blk in b.items()}


def deck_labels_end(deck: Path) -> int | None:
    """The largest node label the deck itself defines (None where covcontact's reader cannot read it)."""
    from covcontact.io.deck_model import read_model

    try:
        labels = read_model(deck).node_labels
    except Exception:  # noqa: BLE001 (refused decks: their .frd comparison does not happen)
        return None
    return int(labels.max()) if labels.size else None


def _summarise_blocks(blocks: list[dict]) -> dict:
    """Per kind the largest relative difference and the block where it is. A block whose largest CalculiX value is
    round-off beside the largest of its kind over the run (below 1e-6 of it: a body at rest, a surface without force)
    is measured on that largest value instead (``scale``: "run")."""
    top: dict[str, float] = {}
    for b in blocks:
        top[b["kind"]] = max(top.get(b["kind"], 0.0), b["max_ref"])
    out: dict = {}
    for b in blocks:
        k, rel, scale = b["kind"], b["rel_diff"], "block"
        if b["max_ref"] < 1e-6 * top[k]:
            rel, scale = b["rel_diff"] * b["max_ref"] / top[k], "run"
        if k not in out or rel > out[k]["rel_diff"]:
            out[k] = {"rel_diff": rel, "set": b["set"], "time": b["time"], "max_ref": b["max_ref"], "rows": b["nodes"],
                      "scale": scale, "kind_max_ref": top[k]}
    return out


def run_deck(info: dict, root: Path, work_root: Path, args) -> dict:
    deck: Path = info["path"]
    row = {"deck": info["deck"], "contact": info["contact"], "needs_preprocessing": info["missing"], "linear":
           info["linear"], "types": info["types"]}
    work = work_root / info["deck"].replace("/", "__").replace(" ", "_")
    shutil.rmtree(work, ignore_errors=True)
    shutil.copytree(deck.parent, work, ignore=IGNORE)
    job = deck.stem
    if info["missing"]:
        if not args.preprocess:
            row["class"] = "needs pre-processing"
            return row
        ran, missing = preprocess(work, work / deck.name, root, args.pre_timeout)
        row["preprocessing"] = ran
        if missing:
            row.update({"class": "needs pre-processing", "still_missing": missing})
            return row
        again = scan(work / deck.name)
        row["contact"], row["linear"], row["types"] = again["contact"], again["linear"], again["types"]
        if again["procedures"] and not set(again["procedures"]) <= STRUCTURAL:
            row.update({"class": "out of scope", "why": "steps: " + ", ".join(again["procedures"])})
            return row
    ccx = _ccx(work, job, args.ccx_timeout or args.timeout)
    row["ccx"] = ccx
    if not ccx["finishes"]:
        row["class"] = "CalculiX does not finish"
        return row
    ref = work / f"{job}.ccx.dat"
    shutil.copy(work / f"{job}.dat", ref)
    out = work / "covcontact"
    code, _, err, secs = _run([sys.executable, "-m", "covcontact.cli", "run", str(work / deck.name), "--out",
                               str(out), "--quiet"], work, args.timeout, log=work / "covcontact")
    err = (work / "covcontact.err").read_text(errors="replace")   # (all of it: the first unsupported line)
    row.update(classify(code, err, out, scan(work / deck.name)["types"]), seconds=round(secs, 1), exit_code=code)
    row["class"] = row["result"]
    dat = out / f"{job}.dat"
    if dat.is_file() and row["result"] != "refused":
        blocks = compare(dat.read_text(errors="replace"), ref.read_text(errors="replace"))
        lacking = {"displacements", "forces"} - {b["kind"] for b in blocks}
        upto = deck_labels_end(work / deck.name)
        shells = any(str(t).upper().startswith("S") and str(t).upper()[1:2].isdigit() for t in row.get("types", ()))
        if lacking:   # (U or RF not printed to the .dat: those of the .frd files, at the ends of the deck's steps)
            blocks += [b for b in frd_compare(out / f"{job}.frd", work / f"{job}.frd", upto, shells)
                       if b["kind"] in lacking]
        row["blocks"] = len(blocks)
        row["diff"] = _summarise_blocks(blocks)
        worst = max([v["rel_diff"] for k, v in row["diff"].items() if k in ("displacements", "forces")], default=None)
        if row["result"] == "runs" and info["linear"] and worst is not None and worst > 1e-2:
            nl = work / "ccx_nlgeom"     # CalculiX once more, geometrically nonlinear as covcontact always is
            shutil.copytree(work, nl, ignore=shutil.ignore_patterns("covcontact", "ccx_nlgeom", "*.dat", "*.frd",
                                                                    "*.sta", "*.cvg"))
            text = (nl / deck.name).read_text(errors="replace").splitlines()
            (nl / deck.name).write_text("\n".join(
                ln + (", NLGEOM" if ln.upper().replace(" ", "").startswith("*STEP") and "NLGEOM" not in ln.upper()
                      else "") for ln in text) + "\n")
            c2 = _ccx(nl, job, args.ccx_timeout or args.timeout)
            row["ccx_nlgeom"] = c2
            if c2["finishes"]:
                nb = compare(dat.read_text(errors="replace"), (nl / f"{job}.dat").read_text(errors="replace"))
                lacking = {"displacements", "forces"} - {b["kind"] for b in nb}
                nb += [b for b in frd_compare(out / f"{job}.frd", nl / f"{job}.frd", upto, shells)
                       if b["kind"] in lacking]
                row["diff_vs_ccx_nlgeom"] = _summarise_blocks(nb)
    return row


# ---------------------------------------------------------------------------------------------------------------------
# reporting


def _e(v) -> str:
    return "" if v is None else f"{v:.1e}"


def _what(r: dict) -> str:
    c = r["class"]
    if c == "needs pre-processing":
        miss = r.get("still_missing", r["needs_preprocessing"])
        return f"absent: {', '.join(miss[:3])}{', ...' if len(miss) > 3 else ''}"
    if c == "CalculiX does not finish":
        return r["ccx"].get("why", "")
    if c == "out of scope":
        return r.get("why", "")
    if c == "refused":
        return (f"`{r['reason']}`" + (f" (+{len(r['reasons']) - 1} more)" if len(r.get("reasons", [])) > 1 else "")
                + (f" (elements: {', '.join(r['types'])})" if r["reason"].startswith("input error") else ""))
    if c in ("fails", "crashes", "other"):
        return r.get("traceback") or r.get("reason", "")
    d = r.get("diff")
    if c in ("runs", "timeout") and d is not None:
        text = _diff_text(d) or "no block printed by both at the same time"
        if r.get("diff_vs_ccx_nlgeom"):
            text += "; vs ccx NLGEOM: " + _diff_text(r["diff_vs_ccx_nlgeom"])
        return text
    return ""


def _diff_text(d: dict) -> str:
    """U and RF (from the .frd: marked so); without them the largest of the other kinds compared."""
    def one(k):
        b = d[k]
        return (_e(b["rel_diff"]) + (" (frd)" if b["set"] == "FRD" else "") +
                (" (on the run's largest value)" if b.get("scale") == "run" else ""))

    parts = [f"{name} {one(k)}" for k, name in (("displacements", "U"), ("forces", "RF")) if k in d]
    if not parts and d:
        k = max(d, key=lambda k: d[k]["rel_diff"])
        parts = [f"no U or RF; largest: {k} {one(k)}"]
    return ", ".join(parts)


def table(rows: list[dict]) -> str:
    lines = ["| deck | contact | pre-processing | CalculiX | covcontact | reason or difference (U, RF: max diff / max "
             "CalculiX value of the block) |", "|---|---|---|---|---|---|"]
    for r in rows:
        pre = ("by cgx" if r.get("preprocessing") is not None and r["class"] != "needs pre-processing" else
               "needed" if r["needs_preprocessing"] else "no")
        ccx = r.get("ccx")
        ccx_text = ("" if ccx is None else f"finishes ({ccx['seconds']:.0f} s)" if ccx["finishes"] else
                    "does not finish")
        ours = r["class"] if r["class"] in ("runs", "refused", "fails", "crashes", "timeout", "other") else ""
        if ours and "seconds" in r:
            ours += f" ({r['seconds']:.0f} s)"
        lines.append(f"| {r['deck']} | {', '.join(r['contact']) or 'no'} | {pre} | {ccx_text} | {ours} | "
                     f"{_what(r).replace('|', '/')} |")
    return "\n".join(lines)


def summary(decks: list[dict], rows: list[dict], threshold: float = 1e-2) -> dict:
    structural = [d for d in decks if d["structural"]]
    contact = {d["deck"]: bool(d["contact"]) for d in structural} | {r["deck"]: bool(r["contact"]) for r in rows}
    by = Counter(r["class"] for r in rows)
    runs = [r for r in rows if r["class"] == "runs"]
    large, compared = [], 0
    for r in runs:
        d = r.get("diff") or {}
        vals = {k: d[k]["rel_diff"] for k in ("displacements", "forces") if k in d}
        if vals:
            compared += 1
        if any(v > threshold for v in vals.values()):
            large.append({"deck": r["deck"], **vals})
    refused = [r for r in rows if r["class"] == "refused"]
    return {
        "decks_with_step": len(decks),
        "structural": len(structural),
        "structural_with_contact": sum(contact.values()),   # (also those whose pairs sit in files cgx writes)
        "out_of_scope": {d["deck"]: d["scope"] for d in decks if not d["structural"]},
        "needed_preprocessing": sum(1 for r in rows if r["needs_preprocessing"]),
        "preprocessed_by_cgx": sum(1 for r in rows if r["needs_preprocessing"] and r.get("preprocessing") is not None
                                   and r["class"] != "needs pre-processing"),
        "counts": dict(by),
        "surveyed": sum(by[c] for c in ("runs", "refused", "fails", "crashes", "timeout", "other")),
        "runs_compared": compared,
        "refused_by_first_reason": Counter(r["reason"] for r in refused).most_common(),
        "refused_by_first_reason_grouped": Counter(reason_group(r["reason"]) for r in refused).most_common(),
        "refused_decks_per_reason_grouped": Counter(
            g for r in refused for g in {reason_group(k) for k in (r.get("reasons") or [r["reason"]])}).most_common(),
        "crashes": [{"deck": r["deck"], "message": r.get("reason"), "traceback": r.get("traceback")}
                    for r in rows if r["class"] == "crashes"],
        "fails": [{"deck": r["deck"], "reason": r.get("reason")} for r in rows if r["class"] == "fails"],
        "differ_more_than_1e-2": large,
    }


def summary_text(s: dict) -> str:
    c = s["counts"]
    lines = [f"{s['decks_with_step']} decks with *STEP, {s['structural']} structural ({s['structural_with_contact']} "
             f"with contact), {len(s['out_of_scope'])} of other analyses",
             f"{s['needed_preprocessing']} include files that cgx writes ({s['preprocessed_by_cgx']} made by cgx "
             f"here), "
             f"{c.get('needs pre-processing', 0)} left needing pre-processing",
             f"CalculiX does not finish: {c.get('CalculiX does not finish', 0)}",
             f"surveyed {s['surveyed']}: runs {c.get('runs', 0)} ({s['runs_compared']} compared, "
             f"{len(s['differ_more_than_1e-2'])} differ by more than 1e-2), refused {c.get('refused', 0)}, fails "
             f"{c.get('fails', 0)}, crashes {c.get('crashes', 0)}, timeout {c.get('timeout', 0)}, other "
             f"{c.get('other', 0)}"]
    if s["refused_by_first_reason"]:
        lines.append("refused, by the first reason: " + "; ".join(f"{k} ({n})" for k, n in
                                                                    s["refused_by_first_reason_grouped"]))
        lines.append("refused, the decks each reason is found in: " + "; ".join(
            f"{k} ({n})" for k, n in s["refused_decks_per_reason_grouped"]))
    for x in s["crashes"]:
        lines.append(f"crash: {x['deck']}: {x['message']} [{x['traceback']}]")
    for x in s["fails"]:
        lines.append(f"fails: {x['deck']}: {x['reason']}")
    for x in s["differ_more_than_1e-2"]:
        lines.append(f"differs: {x['deck']}: " + ", ".join(f"{k} {v:.2e}" for k, v in x.items() if k != "deck"))
    return "\n".join(lines)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("checkout", help="the folder of a checkout of calculix/CalculiX-Examples")
    ap.add_argument("--out", default="results/user_decks.json", help="the JSON file written")
    ap.add_argument("--work", default="results/user_decks", help="the scratch folder (one copy per deck)")
    ap.add_argument("--decks", default=None, help="comma-separated parts of deck paths (e.g. Contact,Tubes/solve)")
    ap.add_argument("--timeout", type=float, default=150.0, help="seconds per deck for covcontact (and CalculiX)")
    ap.add_argument("--ccx-timeout", type=float, default=None, help="seconds per deck for CalculiX (default: "
                    "--timeout)")
    ap.add_argument("--preprocess", action="store_true", help="run the folders' cgx pre-processing scripts in the "
                    "scratch copies of decks that include files they write")
    ap.add_argument("--pre-timeout", type=float, default=120.0, help="seconds per pre-processing command")
    args = ap.parse_args()
    root = Path(args.checkout).resolve()
    if not root.is_dir():
        print(f"{root}: no such folder (git clone https://github.com/calculix/CalculiX-Examples)", file=sys.stderr)
        return 2
    if not shutil.which("ccx"):
        print("ccx not found (apt-get install calculix-ccx)", file=sys.stderr)
        return 2
    decks = find_decks(root)
    chosen = [d for d in decks if d["structural"] and (not args.decks or any(f in d["deck"] for f in
                                                                              args.decks.split(",")))]
    chosen.sort(key=lambda d: (not d["contact"], d["deck"]))   # (the contact decks first)
    work_root = Path(args.work).resolve()
    work_root.mkdir(parents=True, exist_ok=True)
    rows = []
    t0 = time.perf_counter()
    for info in chosen:
        row = run_deck(info, root, work_root, args)
        rows.append(row)
        print(f"{row['deck']:42s} {row['class']:26s} {_what(row)[:110]}  [{time.perf_counter() - t0:.0f} s]",
              file=sys.stderr, flush=True)
    s = summary(decks, rows)
    record = {"collection": root.name, "preprocess": args.preprocess, "timeout_s": args.timeout,
              "ccx": subprocess.run(["ccx", "-v"], capture_output=True, text=True).stdout.strip(),
              "summary": s, "decks": rows, "wall_s": round(time.perf_counter() - t0, 1)}
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(record, indent=1, default=str) + "\n")
    print(table(rows), file=sys.stderr)
    print(summary_text(s), file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
