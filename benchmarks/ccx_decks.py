"""CalculiX's own test decks run by covcontact: the printed displacements against the reference results.

Install the decks and their references first (they are not downloaded here):

    apt-get install calculix-ccx-test      # the decks sit in /usr/share/doc/calculix-ccx-test/examples/test

Each deck named (default: every deck in that folder whose keywords covcontact reads) is run with
``covcontact run DECK.inp`` in a folder of its own; the ``.dat`` table it writes is compared with the deck's
``.dat.ref``: for every block both print at the same time (U, RF, S, PEEQ, E, ENER, ELSE, EVOL, the contact blocks
CSTR, CDIS, CELS, CNUM, the *SECTION PRINT table: ``dat_blocks``), the largest difference over the largest value of
the reference block (a deck that prints no displacements there: those of its
``.frd.ref`` at the end of each step, against covcontact's VTU of that step). covcontact is always geometrically nonlinear; a deck
whose steps are linear (no NLGEOM) is also run by CalculiX itself (``ccx``, ``apt-get install calculix-ccx``) with
NLGEOM added to its steps, and the displacements compared with that run as well. Decks that covcontact refuses (unsupported keywords, one
line each) or that fail are listed with the reason. Results: a JSON file and a markdown table
(docs/verification.md, "CalculiX test decks").

    python benchmarks/ccx_decks.py [--decks contact1,contact4] [--folder DIR] [--out results/ccx_decks] [--add-prints]

``--add-prints`` asks every step of each deck for E, ENER, ELSE, EVOL over all elements (and CDIS, CSTR, CELS, CNUM
where the deck has contact pairs) and has CalculiX run the same deck (NLGEOM added), so that the blocks its
references lack are compared too.
"""

from __future__ import annotations

import argparse
import gzip
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

FOLDER = Path("/usr/share/doc/calculix-ccx-test/examples/test")


def _text(path: Path) -> str | None:
    if path.is_file():
        return path.read_text(errors="replace")
    gz = path.with_name(path.name + ".gz")
    if gz.is_file():
        return gzip.decompress(gz.read_bytes()).decode(errors="replace")
    return None


#: the blocks compared, by the start of their header: kind, and how a row is keyed ("node": its first number, "point":
#: element and integration point, "single": one row)
_HEADS = (("displacements", "displacements", "node"), ("forces", "forces", "node"), ("stresses", "stresses", "point"),
          ("equivalent plastic strain", "equivalent", "point"), ("strains", "strains", "point"),
          ("internal energy density", "energy density", "point"), ("internal energy", "internal energy", "node"),
          ("total internal energy", "total internal energy", "single"), ("volume", "volume", "node"),
          ("total volume", "total volume", "single"))
#: *CONTACT PRINT blocks: header start -> (kind of the first value, kind of the tangential pair's magnitude)
_CONTACT = (("contact stress", ("contact", "tangential")), ("relative contact displacement", ("clearance", "slip")),
            ("contact print energy", ("contact energy", None)))


def dat_blocks(text: str) -> dict[tuple[str, str, float], dict]:
    """The blocks of a .dat file that the survey compares: (kind, set, time) -> row key -> values. Nodal blocks (U, RF)
    and element blocks (ELSE, EVOL) by label, Gauss-point blocks (S, E, PEEQ, ENER) by (element, integration point),
    totals as one row. *CONTACT PRINT: CSTR's pressure ("contact") and shear stresses ("tangential"), CDIS's clearance
    ("clearance") and tangential displacements ("slip"; both codes take CalculiX's tangential axes), CELS ("contact
    energy"), per slave node, or per slave face (element, face) of surface-to-surface contact, whose integration points
    are each code's own (the mean over the face's points; energies: their sum); their totals ("total contact energy",
    "contact elements": CNUM). *SECTION PRINT: the surface's force ("section force"), moment about its centre
    ("section moment"), centre and area."""
    out: dict = {}
    key, mode, section, faces, table = None, None, 0, {}, []

    def flush():  # surface-to-surface rows: the mean (energies: the sum) of each face's points
        for k, rows in faces.items():
            total = k[0] == "contact energy"
            out[k] = {f: (np.sum(v, axis=0) if total else np.mean(v, axis=0)) for f, v in rows.items()}
        faces.clear()

    for line in text.splitlines():
        s = line.strip()
        if "all contact elements and time" in line or s.startswith("total contact spring energy for time") or \
                s.startswith("total number of contact elements for time"):
            flush()
            time = float(line.split("time")[-1])
            key, mode = None, None
            for head, kinds in _CONTACT:
                if s.startswith(head):
                    mode = ("face", kinds) if "element+face" in s else ("slave", kinds)
                    key = (kinds[0], "ALL", time)
                    for kind in kinds:
                        if kind:
                            (faces if mode[0] == "face" else out)[(kind, "ALL", time)] = {}
            if s.startswith("total contact spring energy"):
                key, mode = ("total contact energy", "ALL", time), ("single", None)
                out[key] = {}
            elif s.startswith("total number of contact elements"):
                key, mode = ("contact elements", "ALL", time), ("single", None)
                out[key] = {}
            continue
        if s.startswith("statistics for surface set ") and " and time " in s:
            flush()
            key = (None, s.split("set ")[1].split()[0], float(line.split("time")[1]))
            mode, section = ("section", None), 0
            continue
        if "for set " in line and " and time " in line:  # (CalculiX writes PEEQ's header without a space)
            flush()
            kind, how = next(((k, h) for head, k, h in sorted(_HEADS, key=lambda x: -len(x[0])) if s.startswith(head)),
                             (None, None))
            key = (kind, line.split("for set ")[1].split()[0], float(line.split("time")[1]))
            mode = (how, None) if kind else None
            if kind:
                out[key] = {}
            continue
        if key is None or mode is None or not s:
            continue
        f = line.split()
        try:
            if mode[0] == "section":
                if not f[0][-1].isdigit():   # (the table's text lines)
                    continue
                table = [float(x) for x in f] if section == 0 else table + [float(x) for x in f]
                section += 1
                if section == 4:   # force, moment about the origin; centre, normal; moment about the centre; area, ...
                    name, time = key[1], key[2]
                    force, area = np.array(table[:3]), table[15]
                    out[("section force", name, time)] = {0: force}
                    out[("section centre", name, time)] = {0: np.array(table[6:9])}
                    out[("section area", name, time)] = {0: np.array([area])}
                    # (the moment about the centre beside the force times the section's size, its scale: a moment
                    # that vanishes is compared on that scale)
                    out[("section moment", name, time)] = {0: np.array(table[12:15]),
                                                           1: np.full(3, np.linalg.norm(force) * np.sqrt(area))}
            elif mode[0] == "point":
                out[key][(int(f[0]), int(f[1]))] = np.array([float(v) for v in f[2:8]])
            elif mode[0] == "single":
                out[key][0] = np.array([float(v) for v in f])
            elif mode[0] in ("slave", "face"):
                label = int(f[0]) if mode[0] == "slave" else (int(f[0]), int(f[1]))
                v = [float(x) for x in f[1 if mode[0] == "slave" else 2:]]
                first, tang = mode[1]
                rows = [(first, np.array(v[:1]))] + ([(tang, np.array(v[1:3]))] if tang else [])
                for kind, val in rows:
                    if mode[0] == "slave":
                        out[(kind, "ALL", key[2])][label] = val
                    else:
                        faces[(kind, "ALL", key[2])].setdefault(label, []).append(val)
            else:
                out[key][int(f[0])] = np.array([float(v) for v in f[1:4]])
        except (ValueError, IndexError, KeyError):
            key = None
    flush()
    return {k: v for k, v in out.items() if v}


def frd_displacements(text: str) -> dict[tuple[str, str, float], dict[int, np.ndarray]]:
    """The DISP blocks of a CalculiX .frd result file (ASCII): ("displacements", "FRD", time) -> node -> (3,)."""
    out: dict = {}
    lines = text.splitlines()
    time = None
    k = 0
    while k < len(lines):
        ln = lines[k]
        if ln.startswith("  100C"):
            time = float(ln[12:24])
        elif ln.startswith(" -4  DISP") and time is not None:
            block = {}
            k += 1
            while k < len(lines) and not lines[k].startswith(" -3"):
                row = lines[k]
                if row.startswith(" -1"):
                    block[int(row[3:13])] = np.array([float(row[13 + 12 * i: 25 + 12 * i]) for i in range(3)])
                k += 1
            out[("displacements", "FRD", time)] = block
        k += 1
    return out


def ours_at_step_ends(run: Path) -> dict[tuple[str, str, float], dict[int, np.ndarray]]:
    """covcontact's displacements at the end of each deck step (the VTU of the last step of the stage that ends it),
    by the deck's node labels: ("displacements", "FRD", total time) -> node -> (3,)."""
    import meshio

    name = next(run.glob("deck/*.nodes.json"))
    info = json.loads(name.read_text())
    summary = json.loads((run / "summary.json").read_text())
    order: list[str] = []
    last: dict[str, int] = {}
    for st in summary["steps"]:
        stage = st.get("stage", "")
        if stage not in last:
            order.append(stage)
        last[stage] = st["step"]
    labels = [lab for body in info["bodies"].values() for lab in body]
    out = {}
    ends = info.get("deck_step", list(range(len(info["periods"]))))
    for k, stage in enumerate(order):
        if k + 1 < len(ends) and ends[k + 1] == ends[k]:
            continue  # (a stage that does not end a deck step)
        vtu = run / f"step_{last[stage]:04d}.vtu"
        if not vtu.is_file():
            continue
        u = meshio.read(vtu).point_data["displacement"][: len(labels)]
        time = float(sum(info["periods"][: k + 1]))
        out[("displacements", "FRD", time)] = dict(zip(labels, u))
    return out


def compare_blocks(a: dict, b: dict) -> list[dict]:
    """The blocks of ``b`` (reference) that ``a`` has at the same time: max |difference| / max |reference|."""
    rows = []
    for key, rb in b.items():
        match = [k for k in a if k[0] == key[0] and k[1] == key[1] and abs(k[2] - key[2]) <= 1e-6 * abs(key[2])]
        if not match:
            continue
        ab = a[match[0]]
        nodes = sorted(set(rb) & set(ab))
        if not nodes:
            continue
        R = np.array([rb[n] for n in nodes])
        A = np.array([ab[n] for n in nodes])
        scale = float(np.abs(R).max())
        rows.append({"kind": key[0], "set": key[1], "time": key[2], "nodes": len(nodes), "max_ref": scale,
                     "rel_diff": float(np.abs(A - R).max() / scale) if scale > 0 else 0.0})
    return rows


def compare(ours: str, ref: str) -> list[dict]:
    """Per block both .dat texts print at the same time: max |difference| / max |reference|."""
    return compare_blocks(dat_blocks(ours), dat_blocks(ref))


def candidates(folder: Path) -> list[str]:
    """The decks of ``folder`` whose keywords and element types covcontact reads."""
    import tempfile

    from covcontact.io.deck import read_deck
    from covcontact.io.deck_model import ELEMENTS, SUPPORTED

    out = []
    with tempfile.TemporaryDirectory() as tmp_dir:
        for p in sorted(folder.glob("*.inp")) + sorted(folder.glob("*.inp.gz")):
            name = p.name.removesuffix(".gz").removesuffix(".inp")
            try:  # (a gzipped deck is read from a plain copy)
                tmp = Path(tmp_dir) / f"{name}.inp"
                tmp.write_text(_text(folder / f"{name}.inp"))
                cards = read_deck(tmp)
            except Exception:  # noqa: BLE001 (a deck the survey cannot read is simply not a candidate)
                continue
            names = {c.name for c in cards}
            types = {c.params.get("TYPE", "").upper() for c in cards if c.name == "ELEMENT"}
            if names <= set(SUPPORTED) | {"MPC"} and types and types <= set(ELEMENTS):  # (*MPC: deck_mpc)
                out.append(name)
    return sorted(set(out))


#: the blocks beside U, RF, S, PEEQ and CSTR (docs/input.md, the .dat's variables), for the second table
NEW_KINDS = ("strains", "energy density", "internal energy", "total internal energy", "volume", "total volume",
             "clearance", "slip", "contact energy", "total contact energy", "contact elements", "section force",
             "section moment", "section area", "section centre")
#: what ``--add-prints`` asks of every step: the element blocks over all elements, with contact pairs the contact ones
EXTRA_EL = "*EL PRINT, ELSET=SURVEYALL, TOTALS=YES\nE, ENER, ELSE, EVOL\n"
EXTRA_CONTACT = "*CONTACT PRINT, TOTALS=YES\nCDIS, CSTR, CELS, CNUM\n"


def with_prints(text: str, deck: Path) -> str:
    """The deck with EXTRA_EL (over a set SURVEYALL of every element, defined before the first *STEP) and, if it has
    contact pairs, EXTRA_CONTACT at the end of every step (a step's first *EL PRINT or *CONTACT PRINT replaces the
    requests carried over from the step before: both codes read the same deck)."""
    from covcontact.io.deck_model import read_model

    labels = np.unique(np.concatenate([b[2] for b in read_model(deck).blocks]))
    rows = [", ".join(map(str, labels[k: k + 12])) for k in range(0, len(labels), 12)]
    extra = EXTRA_EL + (EXTRA_CONTACT if "*CONTACTPAIR" in text.upper().replace(" ", "") else "")
    out, first = [], True
    for ln in text.splitlines():
        key = ln.upper().replace(" ", "")
        if key.startswith("*STEP") and first:
            out += ["*ELSET, ELSET=SURVEYALL", *rows]
            first = False
        if key.startswith("*ENDSTEP"):
            out += extra.splitlines()
        out.append(ln)
    return "\n".join(out) + "\n"


def _summary(row: dict, blocks: list[dict], suffix: str = "") -> None:
    """max_rel_<kind><suffix> of every kind the comparison has."""
    for kind in sorted({b["kind"] for b in blocks}):
        row[f"max_rel_{kind}{suffix}"] = max(b["rel_diff"] for b in blocks if b["kind"] == kind)


def run_deck(name: str, folder: Path, out: Path, add_prints: bool = False) -> dict:
    work = out / name
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    deck = work / f"{name}.inp"
    deck.write_text(_text(folder / f"{name}.inp"))
    if add_prints:
        deck.write_text(with_prints(deck.read_text(), deck))
    ref = _text(folder / f"{name}.dat.ref")
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(deck), "--out", str(work / "run"),
                           "--quiet"], capture_output=True, text=True, timeout=1800)
    row = {"deck": name, "exit_code": proc.returncode, "seconds": round(time.perf_counter() - t0, 2)}
    if proc.returncode == 2:
        lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
        row["why"] = "; ".join(ln.split(": ", 1)[-1] for ln in lines[:3])
        return row
    dat = work / "run" / f"{name}.dat"
    if proc.returncode != 0 or not dat.is_file():
        row["why"] = (proc.stderr.strip().splitlines() or ["no output"])[-1][:300]
        return row
    blocks = compare(dat.read_text(), ref or "")
    frd = _text(folder / f"{name}.frd.ref")
    if frd and not any(b["kind"] == "displacements" for b in blocks):  # only the .frd holds displacements
        blocks += compare_blocks(ours_at_step_ends(work / "run"), frd_displacements(frd))
    row["blocks"] = blocks
    _summary(row, blocks)
    text = deck.read_text()
    linear = [ln for ln in text.splitlines() if ln.upper().replace(" ", "").startswith("*STEP")
              and "NLGEOM" not in ln.upper()]
    row["nlgeom"] = not linear
    ccx = shutil.which("ccx")
    if (linear or add_prints) and ccx:  # CalculiX itself with NLGEOM on every step (covcontact is nonlinear)
        nl = work / "ccx_nlgeom"
        nl.mkdir()
        lines = [ln + (", NLGEOM" if ln.upper().replace(" ", "").startswith("*STEP") and "NLGEOM" not in ln.upper()
                       else "") for ln in text.splitlines()]
        (nl / f"{name}.inp").write_text("\n".join(lines) + "\n")
        subprocess.run([ccx, "-i", name], cwd=nl, capture_output=True, timeout=1800, check=False)
        if (nl / f"{name}.dat").is_file():
            nb = compare(dat.read_text(), (nl / f"{name}.dat").read_text())
            if not any(b["kind"] == "displacements" for b in nb) and (nl / f"{name}.frd").is_file():
                nb += compare_blocks(ours_at_step_ends(work / "run"),
                                     frd_displacements((nl / f"{name}.frd").read_text(errors="replace")))
            row["blocks_vs_ccx_nlgeom"] = nb
            _summary(row, nb, "_vs_ccx_nlgeom")
    return row


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--decks", default=None, help="comma-separated deck names (default: the candidates)")
    ap.add_argument("--folder", default=str(FOLDER))
    ap.add_argument("--out", default="results/ccx_decks")
    ap.add_argument("--add-prints", action="store_true",
                    help="ask every step for E, ENER, ELSE, EVOL (and CDIS, CSTR, CELS, CNUM with contact pairs) and "
                         "compare them with CalculiX run on the same deck")
    args = ap.parse_args()
    folder, out = Path(args.folder), Path(args.out)
    if not folder.is_dir():
        print(f"{folder}: no such folder (apt-get install calculix-ccx-test)", file=sys.stderr)
        return 2
    names = args.decks.split(",") if args.decks else candidates(folder)
    rows = []
    for name in names:
        row = run_deck(name, folder, out, args.add_prints)
        rows.append(row)
        u = row.get("max_rel_displacements")
        sv = row.get("max_rel_stresses")
        print(f"{name:16s} exit {row['exit_code']}  U {u if u is None else f'{u:.2e}'}  S {sv if sv is None else f'{sv:.2e}'}"
              f"  {row.get('why', '')}", flush=True)
    out.mkdir(parents=True, exist_ok=True)
    (out / "ccx_decks.json").write_text(json.dumps(rows, indent=1))
    lines = ["| deck | NLGEOM | exit | U vs .dat.ref | RF vs .dat.ref | S vs .dat.ref | contact pressure, |tangential| "
             "vs .dat.ref | U vs ccx NLGEOM | RF vs ccx NLGEOM | S vs ccx NLGEOM | note |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]

    def fmt(v):
        return "" if v is None else f"{v:.1e}"

    for r in rows:
        lines.append(f"| {r['deck']} | {'yes' if r.get('nlgeom') else 'no'} | {r['exit_code']} | "
                     f"{fmt(r.get('max_rel_displacements'))} | {fmt(r.get('max_rel_forces'))} | "
                     f"{fmt(r.get('max_rel_stresses'))} | {fmt(r.get('max_rel_contact'))}"
                     f"{', ' + fmt(r.get('max_rel_tangential')) if r.get('max_rel_tangential') is not None else ''} | "
                     f"{fmt(r.get('max_rel_displacements_vs_ccx_nlgeom'))} | "
                     f"{fmt(r.get('max_rel_forces_vs_ccx_nlgeom'))} | {fmt(r.get('max_rel_stresses_vs_ccx_nlgeom'))} | "
                     f"{r.get('why', '')} |")
    # the other blocks: per deck and kind, against the reference and against CalculiX with NLGEOM
    lines += ["", "| deck | block | vs .dat.ref | vs ccx NLGEOM |", "|---|---|---|---|"]
    for r in rows:
        for kind in NEW_KINDS:
            a, b = r.get(f"max_rel_{kind}"), r.get(f"max_rel_{kind}_vs_ccx_nlgeom")
            if a is not None or b is not None:
                lines.append(f"| {r['deck']} | {kind} | {fmt(a)} | {fmt(b)} |")
    (out / "ccx_decks.md").write_text("\n".join(lines) + "\n")
    print(f"wrote {out / 'ccx_decks.md'}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
