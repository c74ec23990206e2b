"""The Python blocks of docs/extending.md and the README run, in order, as the pages promise.

docs/extending.md says its blocks "run one after the other, as one script";
its TOML example must load (a segment without a material is steel, the one
rule of code and docs).  The component types the page registers are removed
afterwards, so that no other test sees them.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from substructure.components import COMPONENT_TYPES

ROOT = Path(__file__).parent.parent


def python_blocks(page: Path) -> str:
    return "\n".join(re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.DOTALL))


@pytest.fixture
def registry():
    saved = dict(COMPONENT_TYPES)
    yield
    COMPONENT_TYPES.clear()
    COMPONENT_TYPES.update(saved)


def test_extending_page_runs(registry, capsys, monkeypatch, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    code = python_blocks(ROOT / "docs" / "extending.md")
    namespace = {"__name__": "extending_md"}
    exec(compile(code, "docs/extending.md", "exec"), namespace)
    out = capsys.readouterr().out
    assert "shrink.toml, line 12: components[1].bore: got '12'" in out
    assert namespace["from_file"].component("spindle").segments[0].material.name == "steel"


def test_readme_python_runs(monkeypatch, tmp_path, capsys):
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(ROOT)
    code = python_blocks(ROOT / "README.md").replace('fig.savefig("tool_point_frf.png")',
                                                    f'fig.savefig({str(tmp_path / "t.png")!r})')
    exec(compile(code, "README.md", "exec"), {"__name__": "readme"})
    import matplotlib.pyplot as plt

    plt.close("all")
    assert "[1058. 1500. 3168. 3844.]" in capsys.readouterr().out
