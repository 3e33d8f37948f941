"""The documentation's Python and Dask examples run as written: the fenced blocks after
the `python-example` and `dask-example` markers in the repository's README.md or in its
book (book/src/*.md; the book's Python chapter includes the README's example)."""

import pathlib
import re
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
DOCS = [ROOT / "README.md", *sorted((ROOT / "book" / "src").glob("*.md"))]


def example(marker: str = "python-example") -> str:
    for doc in DOCS:
        m = re.search(r"<!-- " + marker + r"[^>]*-->\s*```python\n(.*?)```", doc.read_text(encoding="utf-8"), re.S)
        if m:
            return m.group(1)
    raise AssertionError(f"README.md, book/src/*.md: no ```python block after a <!-- {marker} --> marker")


def test_readme_example_runs_as_written(tmp_path):
    code = example()
    assert "inertia.estimate(" in code
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "relative error vs truth:" in p.stdout


def test_readme_dask_example_runs_as_written(tmp_path):
    pytest.importorskip("distributed")
    code = example("dask-example")
    assert "inertia.fleet.estimate_files(" in code and "LocalCluster(n_workers=2" in code
    script = tmp_path / "fleet_example.py"
    script.write_text(code)
    p = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    out = p.stdout
    assert all(f"sat{k}.csv" in out for k in range(4))
    assert "discrete-momentum" in out and "error_p50" in out
