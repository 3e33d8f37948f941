"""The README's Python example runs as written (the fenced block after the
`python-example` marker in the repository's README.md)."""

import pathlib
import re
import subprocess
import sys

README = pathlib.Path(__file__).resolve().parents[3] / "README.md"


def example() -> str:
    text = README.read_text(encoding="utf-8")
    m = re.search(r"<!-- python-example[^>]*-->\s*```python\n(.*?)```", text, re.S)
    assert m, "README.md: no ```python block after a <!-- python-example --> marker"
    return m.group(1)


def test_readme_example_runs_as_written(tmp_path):
    code = example()
    assert "inertia.estimate(" in code
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "relative error vs truth:" in p.stdout
