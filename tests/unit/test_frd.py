"""The .frd result file of a deck's run and ``covcontact ccx`` (decks of our own, written here): the frd's nodes,
elements (CalculiX's element types, a 20-node brick's node order) and result blocks read back and checked against the
.dat table, the VTU files and equilibrium; ``covcontact ccx -i JOB``'s files (.dat, .frd, .sta, .cvg), standard output
and exit codes; where CalculiX (ccx) and CalculiX GraphiX (cgx) are installed, the frd against ccx's own and read by
cgx."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from covcontact.io.ccx_job import STA_HEAD, fortran_e, increments
from covcontact.io.frd import FRD_CELLS, frd_time, read_frd

#: the frd element types of C3D8, C3D20, C3D10 (CalculiX's)
HEX8, HEX20, TET10 = 1, 4, 6


def _hex8_block(nx, ny, nz, lx, ly, lz, origin, first):
    i, j, k = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), np.arange(nz + 1), indexing="ij")
    X = np.column_stack([i.ravel() * lx / nx, j.ravel() * ly / ny, k.ravel() * lz / nz]) + origin
    lab = first + np.arange(len(X))
    idx = lab.reshape(nx + 1, ny + 1, nz + 1)
    els = [[idx[a, b, c], idx[a + 1, b, c], idx[a + 1, b + 1, c], idx[a, b + 1, c],
            idx[a, b, c + 1], idx[a + 1, b, c + 1], idx[a + 1, b + 1, c + 1], idx[a, b + 1, c + 1]]
           for a in range(nx) for b in range(ny) for c in range(nz)]
    return lab, X, els


_CUBE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
_HEX20_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
_TET = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
_TET10_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]

#: the deck's C3D20 (element 11, nodes 101..120 in the deck's order) and C3D10 (element 21, nodes 201..210)
HEX20_NODES = list(range(101, 121))
TET10_NODES = list(range(201, 211))


def write_deck(path: Path, top: float = -0.01, static: str = "0.5, 1.0") -> Path:
    """Three separate bodies: a plastic C3D8 block 2 x 1 x 1 (elements 1, 2), an elastic C3D20 unit cube (element 11)
    and an elastic C3D10 tetrahedron (element 21); bottoms clamped, tops pushed down by ``top`` in step 1 (increments
    ``static``) and by twice that in step 2; U and RF printed for all nodes."""
    lab8, X8, els8 = _hex8_block(2, 1, 1, 2.0, 1.0, 1.0, [0.0, 0.0, 0.0], 1)
    X20 = np.vstack([_CUBE, [(_CUBE[a] + _CUBE[b]) / 2 for a, b in _HEX20_EDGES]]) + [4.0, 0.0, 0.0]
    X10 = np.vstack([_TET, [(_TET[a] + _TET[b]) / 2 for a, b in _TET10_EDGES]]) + [7.0, 0.0, 0.0]
    labels = np.concatenate([lab8, HEX20_NODES, TET10_NODES])
    X = np.vstack([X8, X20, X10])

    def listed(values):
        return ",\n".join(", ".join(map(str, values[i: i + 8])) for i in range(0, len(values), 8))

    nodes = "\n".join(f"{n}, {x:.6g}, {y:.6g}, {z:.6g}" for n, (x, y, z) in zip(labels, X))
    bricks = "\n".join(", ".join(map(str, [k + 1, *row])) for k, row in enumerate(els8))
    path.write_text(f"""*HEADING
three blocks (a deck of the tests)
*NODE, NSET=NALL
{nodes}
*ELEMENT, TYPE=C3D8, ELSET=BRICKS
{bricks}
*ELEMENT, TYPE=C3D20, ELSET=QUAD
11, {", ".join(map(str, HEX20_NODES[:10]))},
{", ".join(map(str, HEX20_NODES[10:]))}
*ELEMENT, TYPE=C3D10, ELSET=TET
21, {", ".join(map(str, TET10_NODES))}
*NSET, NSET=BOTTOM
{listed(labels[np.isclose(X[:, 2], 0.0)].tolist())}
*NSET, NSET=TOP
{listed(labels[np.isclose(X[:, 2], 1.0)].tolist())}
*MATERIAL, NAME=SOFT
*ELASTIC
1000.0, 0.3
*PLASTIC
5.0, 0.0
10.0, 0.1
*MATERIAL, NAME=STEEL
*ELASTIC
1000.0, 0.3
*SOLID SECTION, ELSET=BRICKS, MATERIAL=SOFT
*SOLID SECTION, ELSET=QUAD, MATERIAL=STEEL
*SOLID SECTION, ELSET=TET, MATERIAL=STEEL
*BOUNDARY
BOTTOM, 1, 3
*STEP, NLGEOM
*STATIC
{static}
*BOUNDARY
TOP, 3, 3, {top}
*NODE PRINT, NSET=NALL
U, RF
*NODE FILE
U, RF
*EL FILE
S, E, PEEQ
*END STEP
*STEP, NLGEOM
*STATIC
1.0, 1.0
*BOUNDARY
TOP, 3, 3, {2 * top}
*NODE PRINT, NSET=NALL
U
*NODE FILE
U, RF
*EL FILE
S, E, PEEQ
*END STEP
""")
    return path


def _cli(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "covcontact.cli", *map(str, args)], capture_output=True, text=True,
                          timeout=300, cwd=cwd)


def _dat_blocks(path: Path) -> dict:
    """{(quantity, time): {node label: (3,) values}} of a .dat table."""
    out, key = {}, None
    for line in path.read_text().splitlines():
        s = line.split()
        if not s:
            continue
        if s[0] in ("displacements", "forces"):
            key = (s[0], float(s[-1]))
            out[key] = {}
        elif key is not None and len(s) == 4:
            out[key][int(s[0])] = np.array([float(v) for v in s[1:]])
    return out


def _same_to_printed_digits(frd_value: np.ndarray, dat_value: np.ndarray) -> bool:
    """The frd's 6 significant digits against the .dat's 7: the two roundings together differ by at most 0.55 units in
    the frd's last digit."""
    scale = np.where(dat_value != 0.0, 10.0 ** np.floor(np.log10(np.abs(dat_value) + 1e-300)), 0.0)
    return bool(np.all(np.abs(frd_value - dat_value) <= 0.55e-5 * scale + 1e-300))


@pytest.fixture(scope="module")
def deck_run(tmp_path_factory):
    """The deck run by ``covcontact run`` (its output folder) and by ``covcontact ccx -i JOB`` (its folder)."""
    base = tmp_path_factory.mktemp("frd")
    deck = write_deck(base / "blocks.inp")
    proc = _cli("run", deck, "--out", base / "out", "--quiet")
    assert proc.returncode == 0, proc.stderr
    job = base / "job"
    job.mkdir()
    write_deck(job / "blocks.inp")
    ccx = _cli("ccx", "-i", "blocks", cwd=job)
    return base / "out", job, ccx


def test_frd_mesh_is_the_decks(deck_run):
    """The frd's nodes are the deck's (labels, coordinates), its elements the deck's with CalculiX's types, the
    20-node brick with its vertical mid-edge nodes (deck nodes 17-20) before the top ones (13-16)."""
    out, _, _ = deck_run
    frd = read_frd(out / "blocks.frd")
    deck_nodes = {}
    for line in (out.parent / "blocks.inp").read_text().split("*NODE, NSET=NALL\n")[1].split("*")[0].splitlines():
        n, *xyz = line.split(",")
        deck_nodes[int(n)] = np.array([float(v) for v in xyz])
    assert sorted(frd.nodes) == sorted(deck_nodes)
    for n, xyz in deck_nodes.items():
        assert np.allclose(frd.nodes[n], xyz, atol=1e-6)
    assert sorted(frd.elements) == [1, 2, 11, 21]
    assert [frd.elements[e][0] for e in (1, 2, 11, 21)] == [HEX8, HEX8, HEX20, TET10]
    assert frd.elements[11][2] == HEX20_NODES[:12] + HEX20_NODES[16:] + HEX20_NODES[12:16]
    assert frd.elements[21][2] == TET10_NODES
    assert frd.elements[1][2] == [1, 5, 7, 3, 2, 6, 8, 4]  # (the generator's first brick)
    # two materials: the plastic bricks' and the elastic steel's
    assert frd.elements[1][1] == frd.elements[2][1] != frd.elements[11][1] == frd.elements[21][1]
    assert FRD_CELLS["hex20"][0] == HEX20 and FRD_CELLS["tet10"][0] == TET10
    assert frd.closed


def test_frd_results_against_dat_vtu_and_equilibrium(deck_run):
    """One result set per deck step, DISP FORC STRESS TOSTRAIN PE; DISP and FORC equal the .dat's U and RF to the
    printed digits; STRESS is the VTU's nodal Cauchy stress, TOSTRAIN and PE the VTU's cell Green-Lagrange strain and
    plastic strain averaged at the nodes; the 20-node cube's stress satisfies sigma v = sum x (x) f (its element
    average) and its strain's EZZ is the mean of u_z,z + |u,z|^2 / 2 with u_z,z averaging the prescribed -0.01."""
    import meshio

    out, _, _ = deck_run
    frd = read_frd(out / "blocks.frd")
    names = [s.name for s in frd.sets]
    summary = json.loads((out / "summary.json").read_text())
    converged = [s for s in summary["steps"] if s["converged"]]
    # a result set at every converged increment, as the .dat prints (CalculiX's default FREQUENCY=1)
    assert names == ["DISP", "STRESS", "TOSTRAIN", "FORC", "PE"] * len(converged)
    ends = [b for b in frd.blocks("DISP") if b.time in (1.0, 2.0)]
    assert [(b.step, b.time) for b in ends] == [(1, 1.0), (2, 2.0)]
    assert frd.blocks("DISP")[0].components == ["D1", "D2", "D3"]
    assert frd.blocks("STRESS")[0].components == ["SXX", "SYY", "SZZ", "SXY", "SYZ", "SZX"]
    assert frd.blocks("TOSTRAIN")[0].components == ["EXX", "EYY", "EZZ", "EXY", "EYZ", "EZX"]
    per_stage = [sum(1 for s in summary["steps"] if s.get("stage") == name) for name in ("stage1", "step2")]
    assert [b.increment for b in ends] == per_stage  # (the step's last increment)
    first = [b.time for b in frd.blocks("DISP")].index(1.0)  # (the sets at the end of the first step)
    for s in frd.sets:
        assert sorted(s.values) == sorted(frd.nodes)

    dat = _dat_blocks(out / "blocks.dat")
    for s in frd.blocks("DISP"):
        u = dat[("displacements", s.time)]
        assert all(_same_to_printed_digits(s.values[n], u[n]) for n in frd.nodes)
    rf = dat[("forces", 1.0)]
    forc = frd.blocks("FORC")[first]
    assert all(_same_to_printed_digits(forc.values[n], rf[n]) for n in frd.nodes)

    labels = json.loads((out / "deck" / "blocks.nodes.json").read_text())["bodies"]
    order = np.concatenate([labels[b] for b in ("BRICKS", "QUAD", "TET")])
    at_one = [ln for ln in (out / "result.pvd").read_text().splitlines() if 'timestep="1"' in ln]
    vtu = meshio.read(out / at_one[0].split('file="')[1].split('"')[0])  # the end of the first step
    stress, strain, pe = frd.blocks("STRESS")[first], frd.blocks("TOSTRAIN")[first], frd.blocks("PE")[first]
    for k, n in enumerate(order):
        assert np.allclose(stress.values[n], vtu.point_data["cauchy_nodal"][k], rtol=1e-5, atol=1e-10)
    # element values averaged at the nodes, from the VTU's cells (an elastic body's plastic strain: NaN there, 0 here)
    total, count = np.zeros((len(order), 7)), np.zeros(len(order))
    for block, gl, p in zip(vtu.cells, vtu.cell_data["green_lagrange"], vtu.cell_data["equivalent_plastic_strain"]):
        for cell, e, q in zip(block.data, gl, p):
            total[cell] += np.append(e, np.nan_to_num(q))
            count[cell] += 1
    mean = total / count[:, None]
    for k, n in enumerate(order):
        assert np.allclose(strain.values[n], mean[k, :6], rtol=1e-5, atol=1e-10)
        assert pe.values[n][0] == pytest.approx(mean[k, 6], rel=1e-5, abs=1e-12)
    assert all(pe.values[n][0] > 1e-4 for n in labels["BRICKS"])  # (yielded: 5 / 1000 < 0.01)
    assert all(pe.values[n][0] == 0.0 for n in labels["QUAD"] + labels["TET"])

    disp = frd.blocks("DISP")[first]
    x = np.array([frd.nodes[n] + disp.values[n] for n in HEX20_NODES])
    f = np.array([forc.values[n] for n in HEX20_NODES])
    moment = x.T @ f  # sum over the nodes of x (x) f: the integral of the Cauchy stress over the current volume
    s = stress.values[HEX20_NODES[0]]
    assert all(np.allclose(stress.values[n], s, rtol=1e-5) for n in HEX20_NODES)  # (one element: its average)
    for i in range(3):  # (the average weights the reference volume 1, the integral the current one: J within 1 %)
        assert s[i] == pytest.approx(moment[i, i], rel=2e-2)
    ezz = strain.values[HEX20_NODES[0]][2]
    assert -0.01 < ezz < -0.01 + 0.5 * 0.01 ** 2 * 3


def test_ccx_job_files_output_and_exit_code(deck_run):
    """``covcontact ccx -i JOB``: exit 0, a banner and ``Job finished`` on standard output; JOB.dat and JOB.frd as
    ``covcontact run`` writes them; JOB.sta a line per increment with Newton's iterations (summary.json's) and the
    times; JOB.cvg a line per iteration."""
    out, job, proc = deck_run
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert proc.stdout.lstrip().startswith("*" * 60)
    assert "covcontact" in proc.stdout.split("*" * 60)[1]
    assert "\n Job finished\n" in proc.stdout
    assert proc.stdout.count(" STEP ") == 2
    assert (job / "blocks.dat").read_text() == (out / "blocks.dat").read_text()
    ours, theirs = read_frd(job / "blocks.frd"), read_frd(out / "blocks.frd")
    assert ours.nodes.keys() == theirs.nodes.keys() and ours.elements == theirs.elements
    assert [(s.name, s.step, s.increment, s.time) for s in ours.sets] == \
        [(s.name, s.step, s.increment, s.time) for s in theirs.sets]
    assert all(np.array_equal(a.values[n], b.values[n]) for a, b in zip(ours.sets, theirs.sets) for n in a.values)

    summary = json.loads((job / "blocks.covcontact" / "summary.json").read_text())
    steps = summary["steps"]
    sta = (job / "blocks.sta").read_text()
    assert sta.startswith(STA_HEAD)
    rows = [ln.split() for ln in sta[len(STA_HEAD):].splitlines()]
    assert len(rows) == len(steps) and all(len(r) == 7 for r in rows)
    assert [int(r[0]) for r in rows] == [1 if s["stage"] == "stage1" else 2 for s in steps]
    for step in ("1", "2"):  # increments numbered within each step
        assert [int(r[1]) for r in rows if r[0] == step] == list(range(1, sum(r[0] == step for r in rows) + 1))
    assert [int(r[3]) for r in rows] == [s["iterations"] for s in steps]
    assert [int(r[2]) for r in rows] == [1 + s["cutbacks"] for s in steps]
    tot = [float(r[4]) for r in rows]
    assert tot[-1] == pytest.approx(2.0) and all(b > a for a, b in zip(tot, tot[1:]))
    assert sum(float(r[6]) for r in rows if r[0] == "1") == pytest.approx(1.0)
    cvg = (job / "blocks.cvg").read_text().splitlines()
    assert cvg[0] == "SUMMARY OF C0NVERGENCE INFORMATION"
    lines = [ln.split() for ln in cvg[4:]]
    assert len(lines) == summary["total_iterations"]
    for r in rows:  # each increment's iterations numbered 1.. its count
        its = [int(c[3]) for c in lines if (c[0], c[1]) == (r[0], r[1])]
        assert its == list(range(1, int(r[3]) + 1))
    first = [float(c[6]) for c in lines if c[3] == "1"]
    assert first == [100.0] * len(rows)  # (the first correction is the whole increment)


def test_ccx_input_errors_exit_201(tmp_path):
    """A deck that does not read, and a job without its deck: *ERROR on standard output, exit 201, the .sta and .cvg
    started with their headings; a job name given with its .inp suffix and as ``covcontact ccx JOB``."""
    write_deck(tmp_path / "bad.inp")
    text = (tmp_path / "bad.inp").read_text().replace("*SOLID SECTION, ELSET=TET, MATERIAL=STEEL",
                                                      "*SOLID SECTION, ELSET=TET, MATERIAL=GOLD")
    (tmp_path / "bad.inp").write_text(text)
    proc = _cli("ccx", "bad", cwd=tmp_path)
    assert proc.returncode == 201, proc.stdout + proc.stderr
    assert " *ERROR" in proc.stdout and "GOLD" in proc.stdout and "Job finished" not in proc.stdout
    assert (tmp_path / "bad.sta").read_text() == STA_HEAD
    assert (tmp_path / "bad.cvg").read_text().startswith("SUMMARY OF C0NVERGENCE INFORMATION")
    missing = _cli("ccx", "-i", "nothere.inp", cwd=tmp_path)
    assert missing.returncode == 201 and "*ERROR" in missing.stdout and "nothere.inp" in missing.stdout
    assert _cli("ccx", cwd=tmp_path).returncode == 201


def test_ccx_increment_that_does_not_converge_exits_201(tmp_path):
    """Tops pushed down by 1.5 (the bricks invert) with increments no smaller than half the step: the first attempt
    (the whole step) is cut back, the half converges, the second half fails twice; exit 201 with *ERROR, the failed
    attempts marked U in the .sta with their sizes, the frd with the result set of the converged half (a run that
    stops keeps what converged) and closed."""
    write_deck(tmp_path / "fail.inp", top=-1.5, static="0.5, 1.0, 0.5, 0.5")
    proc = _cli("ccx", "-i", "fail", cwd=tmp_path)
    assert proc.returncode == 201, proc.stdout + proc.stderr
    assert " *ERROR" in proc.stdout and "Job finished" not in proc.stdout
    rows = (tmp_path / "fail.sta").read_text()[len(STA_HEAD):].splitlines()
    failed = [r for r in rows if r.split()[2].endswith("U")]
    done = [r for r in rows if not r.split()[2].endswith("U")]
    assert failed and done
    summary = json.loads((tmp_path / "fail.covcontact" / "summary.json").read_text())
    assert summary["status"] == "failed"
    assert len(done) == sum(1 for s in summary["steps"] if s["converged"])
    assert len(failed) == sum(s["cutbacks"] for s in summary["steps"]) + 1  # (the last attempt fails for good)
    sizes = [float(r.split()[-1]) for r in rows if r.split()[1] == rows[-1].split()[1]]
    assert all(b == pytest.approx(a / 2) for a, b in zip(sizes, sizes[1:]))
    frd = read_frd(tmp_path / "fail.frd")
    assert frd.closed and len(frd.elements) == 4
    assert [(b.step, b.time) for b in frd.blocks("DISP")] == [(1, 0.5)] * len(done)


def test_resuming_a_completed_deck_run_keeps_the_frd(deck_run, tmp_path):
    """``--resume`` of a completed deck run goes on with the frd it finds: the file is the same, one closing record."""
    out, _, _ = deck_run
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    before = (copy / "blocks.frd").read_text()
    proc = _cli("run", out.parent / "blocks.inp", "--out", copy, "--quiet", "--resume")
    assert proc.returncode == 0, proc.stderr
    after = (copy / "blocks.frd").read_text()
    assert after == before and after.count(" 9999") == 1


def test_attempts_of_a_step():
    """An increment's attempts from Newton's solves: failures halve the increment, each converged increment (of a
    step split by cutbacks) numbered on its own, Uzawa updates joined to the increment they follow."""
    from covcontact.solvers.newton import StepOutcome

    fail, ok = StepOutcome(False, 3), StepOutcome(True, 4)
    uzawa = StepOutcome(True, 2, augmentation=1)
    incs = increments([fail, fail, ok, uzawa, ok], [(0.0, 0.25), (0.25, 0.5)], 0.0, 1.0)
    assert [[(a.number, a.converged, a.lam0, a.dlam) for a in inc] for inc in incs] == \
        [[(1, False, 0.0, 1.0), (2, False, 0.0, 0.5), (3, True, 0.0, 0.25)], [(1, True, 0.25, 0.25)]]
    assert incs[0][-1].iterations == 6
    broken = increments([ok, fail, fail], [(0.0, 0.5)], 0.0, 1.0)
    assert [(a.converged, a.lam0, a.dlam) for a in broken[1]] == [(False, 0.5, 0.5), (False, 0.5, 0.25)]
    # an Uzawa update that fails fails its attempt: cut back, the half converges
    uzawa_fails = StepOutcome(False, 5, augmentation=1)
    incs = increments([ok, uzawa_fails, ok], [(0.0, 0.5)], 0.0, 1.0)
    assert [[(a.number, a.converged, a.dlam, a.iterations) for a in inc] for inc in incs] == \
        [[(1, False, 1.0, 9), (2, True, 0.5, 4)]]


def test_number_formats():
    """The frd's time field (fixed point with ten digits between 1 and 1e10, else %12.5E) and Fortran's E edit of the
    .sta and .cvg, each against the value it prints."""
    for t in (0.5, 1.0, 2.0, 12.5, 123456.789, 2.5e10, 0.0):
        text = frd_time(t)
        assert len(text) == 12 and float(text) == pytest.approx(t, rel=1e-9 if 1 <= t < 1e10 else 1e-5)
        assert ("E" in text) == (not 1 <= t < 1e10)
    for x in (0.5, -0.5, 1.0, 2.0, 123.456, 1e-7, -3.2e5, 0.0):
        text = fortran_e(x, 13, 6)
        assert len(text) == 13 and text.strip().lstrip("-").startswith("0.") and float(text) == pytest.approx(x, rel=1e-6)


@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) is not installed")
def test_frd_layout_equals_calculix(deck_run, tmp_path):
    """The same deck run by CalculiX: our nodes and elements blocks are its records character for character, our
    result block headers its headers, and the displacements of the elastic bodies agree within 1e-3."""
    out, _, _ = deck_run
    write_deck(tmp_path / "blocks.inp")
    proc = subprocess.run(["ccx", "-i", "blocks"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout

    def mesh_records(path):
        text = path.read_text()
        return text[text.index("    2C"): text.index("    1PSTEP")]

    def headers(path):
        return [ln for ln in path.read_text().splitlines() if ln.startswith((" -4", " -5"))]

    assert mesh_records(out / "blocks.frd") == mesh_records(tmp_path / "blocks.frd")
    theirs = headers(tmp_path / "blocks.frd")
    ours = headers(out / "blocks.frd")
    assert set(ours) <= set(theirs)
    cl = [ln for ln in (out / "blocks.frd").read_text().splitlines() if ln.startswith("  100CL")]
    ccx_cl = [ln for ln in (tmp_path / "blocks.frd").read_text().splitlines() if ln.startswith("  100CL")]
    assert {len(ln) for ln in cl} == {len(ln) for ln in ccx_cl}
    # the last step's one increment: the same fields but the set number (CalculiX writes a set per increment)
    assert (cl[-1][:7], cl[-1][12:58], cl[-1][63:]) == (ccx_cl[-1][:7], ccx_cl[-1][12:58], ccx_cl[-1][63:])
    a, b = read_frd(out / "blocks.frd"), read_frd(tmp_path / "blocks.frd")
    last = [s for s in b.sets if s.name == "DISP" and s.step == 2][-1]
    for n in HEX20_NODES + TET10_NODES:
        assert np.allclose(a.blocks("DISP")[-1].values[n], last.values[n], atol=1e-3 * 0.02)


@pytest.mark.skipif(shutil.which("cgx") is None, reason="CalculiX GraphiX (cgx) is not installed")
def test_cgx_reads_the_frd(deck_run, tmp_path):
    """cgx (in batch mode, without a window) reads the frd and writes its mesh back as an Abaqus deck: the elements
    are the deck's, the 20-node brick's nodes in the deck's order again."""
    out, _, _ = deck_run
    shutil.copy(out / "blocks.frd", tmp_path / "blocks.frd")
    (tmp_path / "check.fbd").write_text("read blocks.frd\nsend all abq\nquit\n")
    proc = subprocess.run(["cgx", "-bg", "check.fbd"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert "ds:10" in proc.stdout or "Dataset No:10" in proc.stdout, proc.stdout[-2000:]
    text = (tmp_path / "all.msh").read_text()
    elements = {}
    kind = None
    numbers: list[int] = []
    for line in text.splitlines():
        if line.startswith("*"):
            kind = line.split("TYPE=")[1].split(",")[0] if "*ELEMENT" in line.upper() else None
            continue
        if kind:
            numbers += [int(v) for v in line.replace(",", " ").split()]
            need = {"C3D8": 9, "C3D20": 21, "C3D10": 11}[kind]
            if len(numbers) >= need:
                elements[numbers[0]] = (kind, numbers[1:need])
                numbers = []
    assert elements[11] == ("C3D20", HEX20_NODES)
    assert elements[21] == ("C3D10", TET10_NODES)
    assert elements[1] == ("C3D8", [1, 5, 7, 3, 2, 6, 8, 4])
    nodes = [ln for ln in text.split("*ELEMENT")[0].splitlines() if ln.strip() and not ln.startswith("*")]
    assert len(nodes) == 42
