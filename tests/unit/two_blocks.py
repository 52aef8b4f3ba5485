"""The two-blocks contact problem of the contact unit tests, as TOML text: a 1 x 1 x 0.5 punch (3 x 3 x 1 cells)
pressed onto and dragged across a 2 x 2 x 0.5 base (4 x 4 x 1 cells), Neo-Hooke E = 1000, nu = 0.3, in 3 steps to
the punch top's displacement (0.03, 0.01, -0.01) with the base's bottom held."""

TEMPLATE = """
[problem]
name = "two-blocks"
[[bodies]]
name = "base"
element = "BASE"
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 2.0, ly = 2.0, lz = 0.5, nx = 4, ny = 4, nz = 1, origin = [-1.0, -1.0, -0.5] }
[[bodies]]
name = "punch"
element = "PUNCH"
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 3, ny = 3, nz = 1, origin = [-0.5, -0.5, 0.0] }
[[contact]]
PAIR
penalty = 2.0e4
tangent = "exact"
EXTRA
[[dirichlet]]
set = "base.zmin"
components = "xyz"
[[dirichlet]]
set = "punch.zmax"
components = "xyz"
value = [0.03, 0.01, -0.01]
[steps]
count = 3
"""

#: the pair of the punch's bottom on the base's top
PAIR = 'slave = "punch.zmin"\nmaster = "base.zmax"'


def two_blocks(base: str = "hex8", punch: str = "hex8", extra: str = "", pair: str = PAIR) -> str:
    """The problem's TOML with the blocks' cell types, the contact pair's slave and master (or ``self``) and its
    further keys ``extra``."""
    return TEMPLATE.replace("BASE", base).replace("PUNCH", punch).replace("PAIR", pair).replace("EXTRA", extra)
