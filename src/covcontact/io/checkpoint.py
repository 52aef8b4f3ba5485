"""Checkpoints: the committed state of a run after a converged step, to resume it after a stop.

One file per rank in the output folder (``checkpoint.npz``; ``checkpoint.rank<r>-of-<n>.npz`` under
mpiexec), written atomically (temporary name, then rename). It holds the displacement, every committed
state array (docs/theory.md section 10), the stage, step and load factor, what the
output files held at that step (the summary and the list of VTU files) and a fingerprint of the problem
(every parameter and mesh array that decides the results). ``load`` refuses a checkpoint of another or a changed
problem, of another number of ranks, or a damaged one with a one-line :class:`CheckpointError`.
"""

from __future__ import annotations

import hashlib
import json
import zipfile
from dataclasses import fields, is_dataclass
from pathlib import Path

import numpy as np

from .atomic import replacing
from .validate import InputError

VERSION = 1


class CheckpointError(InputError):
    """A checkpoint that cannot be resumed (exit code 2)."""


def _describe(obj, h) -> None:
    """Feed a canonical description of a problem component into the hash ``h``."""
    if isinstance(obj, np.ndarray):
        h.update(str(obj.dtype).encode() + str(obj.shape).encode())
        h.update(np.ascontiguousarray(obj).tobytes())
    elif is_dataclass(obj) and not isinstance(obj, type):
        h.update(type(obj).__name__.encode())
        for f in fields(obj):
            if f.name in ("source", "description", "output", "units"):
                continue
            h.update(f.name.encode())
            _describe(getattr(obj, f.name), h)
    elif isinstance(obj, dict):
        for k in sorted(obj, key=str):
            h.update(str(k).encode())
            _describe(obj[k], h)
    elif isinstance(obj, (list, tuple)):
        h.update(b"[")
        for v in obj:
            _describe(v, h)
        h.update(b"]")
    elif hasattr(obj, "__dict__") and not callable(obj):
        h.update(type(obj).__name__.encode())
        _describe({k: v for k, v in vars(obj).items() if not k.startswith("_")}, h)
    else:
        h.update(repr(obj).encode())


def fingerprint(problem) -> str:
    """sha256 of everything that decides the results: every body, mesh (coordinates, cells, sets),
    material, condition, load, contact pair, step and solver option; not the output options (what is
    written, how often) nor comments and descriptions, which a resumed run may change."""
    h = hashlib.sha256()
    _describe(problem, h)
    return h.hexdigest()


def path_for(out: Path, rank: int = 0, size: int = 1) -> Path:
    return Path(out) / ("checkpoint.npz" if size == 1 else f"checkpoint.rank{rank}-of-{size}.npz")


def save(out: Path, u: np.ndarray, arrays: dict[str, np.ndarray], meta: dict, rank: int = 0,
         size: int = 1) -> Path:
    """Write the checkpoint of one rank atomically."""
    path = path_for(out, rank, size)
    meta = dict(meta, version=VERSION, ranks=size)
    with replacing(path) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, u=u, meta=np.array(json.dumps(meta)), **arrays)
    return path


def load(out: Path, problem_hash: str, rank: int = 0, size: int = 1) -> tuple[np.ndarray, dict, dict]:
    """(u, arrays, meta) of the checkpoint in ``out``; CheckpointError if it cannot be resumed."""
    out = Path(out)
    path = path_for(out, rank, size)
    if not path.is_file():
        others = sorted(p.name for p in out.glob("checkpoint*.npz")) if out.is_dir() else []
        if others:
            raise CheckpointError(f"{path}: no checkpoint for {size} rank(s); {out} holds {others[0]} "
                                  f"(resume with the number of ranks that wrote it)")
        raise CheckpointError(f"{path}: no checkpoint to resume from (run without --resume first)")
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: np.array(data[k]) for k in data.files}
        meta = json.loads(str(arrays.pop("meta")))
        u = arrays.pop("u")
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, json.JSONDecodeError, EOFError) as exc:
        raise CheckpointError(f"{path}: damaged checkpoint ({type(exc).__name__}: {exc}); "
                              f"start the run again without --resume") from None
    if meta.get("version") != VERSION:
        raise CheckpointError(f"{path}: checkpoint version {meta.get('version')!r}, this covcontact writes "
                              f"{VERSION}; start the run again without --resume")
    if meta.get("ranks") != size:
        raise CheckpointError(f"{path}: written by {meta.get('ranks')} rank(s), this run has {size}")
    if meta.get("problem_hash") != problem_hash:
        raise CheckpointError(f"{path}: the checkpoint belongs to another problem or the problem file or its "
                              f"meshes changed since; start again without --resume or use another --out")
    return u, arrays, meta
