"""The Python examples of the README's "Python" section and of docs/python.md run as written
(from the repository root, each in a fresh interpreter)."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from conftest import ROOT


def python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def readme_blocks() -> list[str]:
    text = (ROOT / "README.md").read_text()
    section = text[text.index("\n## Python\n"):]
    nxt = section.find("\n## ", 1)
    return python_blocks(section if nxt < 0 else section[:nxt])


EXAMPLES = [("README", i, b) for i, b in enumerate(readme_blocks())] + [
    ("docs/python.md", i, b) for i, b in enumerate(python_blocks((ROOT / "docs/python.md").read_text()))
]


def test_readme_has_an_example():
    assert len(readme_blocks()) == 1


@pytest.mark.parametrize("where,index,code", EXAMPLES, ids=[f"{w}-{i}" for w, i, _ in EXAMPLES])
def test_example_runs(where, index, code, request, monkeypatch):
    if "distributed" in code:
        # In this process, on the session's Ray cluster (the example uses a running Ray; starting
        # a fresh one in a subprocess costs ~25 s).
        request.getfixturevalue("cluster")
        monkeypatch.chdir(ROOT)
        exec(compile(code, f"{where} example {index}", "exec"), {"__name__": "__example__"})
        return
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, f"{where} example {index} failed:\n{done.stderr[-3000:]}"
