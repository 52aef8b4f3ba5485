"""What meshio does not carry of an Abaqus/CalculiX input deck: ``*SURFACE`` definitions (docs/input.md,
"Mesh files"), read from the deck and its ``*INCLUDE`` files.

``*SURFACE, NAME=..., TYPE=ELEMENT`` (the default type) lists ``ELSET, Sn`` lines: the faces n of the
elements of that set, in Abaqus' face numbering of hexahedra (S1 = nodes 1-2-3-4, S2 = 5-8-7-6, S3 =
1-5-6-2, S4 = 2-6-7-3, S5 = 3-7-8-4, S6 = 4-8-5-1); ``TYPE=NODE`` lists node sets or node numbers.
"""

from __future__ import annotations

from pathlib import Path

#: corner nodes (0-based, in the element's node order) of Abaqus' faces S1..S6 of a hexahedron
HEX_FACES = {1: (0, 1, 2, 3), 2: (4, 7, 6, 5), 3: (0, 4, 5, 1), 4: (1, 5, 6, 2), 5: (2, 6, 7, 3), 6: (3, 7, 4, 0)}
#: the corners of the faces S1 .. S4 of a tetrahedron (C3D4, C3D10), in the Abaqus face numbering
TET_FACES = {1: (0, 1, 2), 2: (0, 3, 1), 3: (1, 3, 2), 4: (2, 3, 0)}
#: the corners of the faces S1 .. S5 of a wedge (C3D6): the triangles 1-2-3 and 4-6-5, the quadrilaterals
WEDGE_FACES = {1: (0, 1, 2), 2: (3, 5, 4), 3: (0, 3, 4, 1), 4: (1, 4, 5, 2), 5: (2, 5, 3, 0)}


def _options(line: str) -> dict[str, str]:
    out = {}
    for part in line.split(",")[1:]:
        key, _, value = part.partition("=")
        out[key.strip().upper()] = value.strip()
    return out


def _lines(path: Path, seen: set):
    """The deck's lines with ``*INCLUDE, INPUT=...`` files spliced in (comments dropped)."""
    if path in seen:
        raise ValueError(f"{path}: *INCLUDE includes itself")
    seen = seen | {path}
    for number, raw in enumerate(path.read_text(errors="replace").splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.upper().startswith("*INCLUDE"):
            name = _options(line).get("INPUT", "")
            if not name:
                raise ValueError(f"{path}, line {number}: *INCLUDE without INPUT=")
            yield from _lines((path.parent / name.strip('"')), seen)
            continue
        yield path, number, line


def read_surfaces(path: str | Path) -> tuple[dict[str, list[tuple[str, int]]], dict[str, list[str]]]:
    """(element surfaces: name -> [(elset, face number 1..6)], node surfaces: name -> [nset or node number])
    of the deck at ``path``. ValueError naming the file and line for a face identifier other than S1..S6 or
    an element number in place of an element set."""
    elem: dict[str, list[tuple[str, int]]] = {}
    node: dict[str, list[str]] = {}
    current = None
    for file, number, line in _lines(Path(path), set()):
        if line.startswith("*"):
            current = None
            if line.upper().startswith("*SURFACE") and not line.upper().startswith("*SURFACE "):
                opts = _options(line)
                name = opts.get("NAME")
                if not name:
                    raise ValueError(f"{file}, line {number}: *SURFACE without NAME=")
                kind = opts.get("TYPE", "ELEMENT").upper()
                if kind not in ("ELEMENT", "NODE"):
                    raise ValueError(f"{file}, line {number}: *SURFACE TYPE={kind} is not supported (ELEMENT, NODE)")
                current = (name, kind)
                (elem if kind == "ELEMENT" else node).setdefault(name, [])
            continue
        if current is None:
            continue
        name, kind = current
        items = [v.strip() for v in line.split(",") if v.strip()]
        if kind == "NODE":
            node[name].append(items[0])
            continue
        if len(items) < 2 or not items[1].upper().startswith("S") or not items[1][1:].isdigit() \
                or int(items[1][1:]) not in HEX_FACES:
            raise ValueError(f"{file}, line {number}: expected 'ELSET, S1'..'S6', got {line!r}")
        if items[0].isdigit():
            raise ValueError(f"{file}, line {number}: element numbers in *SURFACE are not supported; put the "
                             f"elements in an *ELSET and name it")
        elem[name].append((items[0], int(items[1][1:])))
    return elem, node
