"""The README's Python snippets run as written, from a folder that holds the examples, and print what their
comments say."""

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def snippets() -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), flags=re.DOTALL)


def run_snippet(code: str, cwd: Path) -> str:
    proc = subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True, text=True, timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc.stdout


def test_readme_has_the_snippets():
    assert len(snippets()) == 2


def test_python_api_snippet(tmp_path):
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    out = run_snippet(snippets()[0], tmp_path).split()
    assert int(out[0]) > 0  # total Newton iterations
    assert (tmp_path / "results" / "two-blocks" / "summary.json").exists()


def test_contact_element_snippet(tmp_path):
    code = snippets()[1]
    lines = run_snippet(code, tmp_path).splitlines()
    gap, xi, inside = lines[0].split(" ", 1)[0], lines[0].split("[", 1)[1].split("]")[0], lines[0].split()[-1]
    # the comment's values: the facet is the unit square (xi = 2 x - 1), the node 0.01 below it
    assert abs(float(gap) + 0.01) < 1e-12 and inside == "True"
    assert [round(float(v), 12) for v in xi.split()] == [-0.4, 0.2]
    assert lines[1].replace(" ", "") == "(15,)(15,15)(15,15)"
    assert "(15,) (15, 15) (15, 15)" in code and "-0.01, xi = (-0.4, 0.2), True" in code
