"""Every ```python block of docs/python.md runs, from the repository root
(the examples name files such as examples/building.cga)."""

import os
import re

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DOC = os.path.join(ROOT, "docs", "python.md")


def blocks():
    with open(DOC, encoding="utf-8") as f:
        text = f.read()
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_the_page_has_examples():
    assert len(blocks()) >= 6


@pytest.mark.parametrize("index", range(len(blocks())))
def test_example(index, monkeypatch):
    pytest.importorskip("geopandas")
    pytest.importorskip("dask_geopandas")
    monkeypatch.chdir(ROOT)
    code = blocks()[index]
    exec(compile(code, f"docs/python.md example {index + 1}", "exec"), {"__name__": "__doc_example__"})
