"""Docs that run (issue 44): every ```python block of README.md and docs/*.md runs as a
script, from an empty temporary directory, with this venv's Python (the extras installed:
scripts/py-requirements.txt). A snippet that needs a resource CI has not (a Slurm cluster,
a scheduler address) guards that part itself and says so in its text."""

import pathlib
import re
import subprocess
import sys

import pytest

from conftest import ROOT

BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


def snippets(path: pathlib.Path) -> list[tuple[str, str]]:
    """The python blocks of a Markdown file as (name, code), in order."""
    text = path.read_text()
    return [(f"{path.relative_to(ROOT)}#{i + 1}", m.group(1))
            for i, m in enumerate(BLOCK.finditer(text))]


ALL = [s for p in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
       for s in snippets(p)]


def test_the_docs_hold_python_snippets():
    names = [n for n, _ in ALL]
    assert any(n.startswith("README.md") for n in names)
    assert sum(n.startswith("docs/distributed.md") for n in names) >= 3, names


@pytest.mark.parametrize("name, code", ALL, ids=[n for n, _ in ALL])
def test_a_doc_snippet_runs_as_a_script(name, code, tmp_path):
    script = tmp_path / "snippet.py"
    script.write_text(code)
    out = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                         text=True, timeout=300, env={"MPLBACKEND": "Agg",
                                                      **__import__("os").environ})
    assert out.returncode == 0, f"{name}:\n{code}\n--- stderr:\n{out.stderr[-3000:]}"
