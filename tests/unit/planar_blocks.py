"""Two planar blocks pressed together, the set-up the planar contact tests share (tests/unit/test_planar_laws.py,
test_planar_sts.py, test_planar_self_contact.py): a lower block 1 x 0.5 (4 x 2 cells) on the x axis, held along y at
its bottom, and an upper one (``upper``: its size and cells) on top of it, shifted by ``ox_up`` along x and lifted by
``gap``; in the plane cases both held along x at their left edges (an axisymmetric model starts at the radius 1)."""

from __future__ import annotations


def two_blocks(form: str, contact: str, *, cell: str = "quad4", material: str = 'model = "svk", E = 1000.0, nu = 0.3',
               upper: str = "lx = 1.0, ly = 0.5, nx = 4", ox_up: float = 0.0, gap: float = 0.0,
               load: str = '[[pressure]]\nset = "up.ymax"\nvalue = 1.0\n', hold: bool = True, steps: int = 4,
               name: str = "blocks") -> str:
    """The problem file: the bodies "low" and "up", ``load`` on them, the ``contact`` entries, ``steps`` equal steps
    (``hold`` False: no x supports at the left edges)."""
    ox = 1.0 if form == "axisymmetric" else 0.0
    holds = "" if form == "axisymmetric" or not hold else "".join(
        f'[[dirichlet]]\nset = "{b}.xmin"\ncomponents = "x"\nvalue = 0.0\n' for b in ("low", "up"))
    body = """
[[bodies]]
name = "{n}"
formulation = "{form}"
element = "{cell}"
mesh = {{ generator = "rectangle", {size}, ny = 2, origin = [{ox}, {oy}] }}
material = {{ {material} }}
"""
    return (f'[problem]\nname = "{name}"\n'
            + body.format(n="low", form=form, cell=cell, size="lx = 1.0, ly = 0.5, nx = 4", ox=ox, oy=0.0,
                          material=material)
            + body.format(n="up", form=form, cell=cell, size=upper, ox=ox + ox_up, oy=0.5 + gap, material=material)
            + '[[dirichlet]]\nset = "low.ymin"\ncomponents = "y"\nvalue = 0.0\n' + holds + load + contact
            + f"[steps]\ncount = {steps}\n")
