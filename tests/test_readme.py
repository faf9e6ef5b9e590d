"""The Python examples in README.md run as written, and its speed figures are the
benchmark summary written by benches/run_all.py, unchanged."""

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)


def test_readme_has_an_example():
    # the taste of the API; the tutorials and docstring examples cover the rest
    assert len(BLOCKS) >= 1


def test_readme_quotes_the_benchmark_summary_unchanged():
    summary = README.parent / "docs" / "_generated" / "benchmarks_summary.md"
    text = README.read_text(encoding="utf-8")
    begin = "<!-- benchmarks-summary: begin (written by benches/run_all.py) -->\n"
    end = "<!-- benchmarks-summary: end -->"
    assert begin in text and end in text
    quoted = text.split(begin, 1)[1].split(end, 1)[0]
    assert quoted == summary.read_text(encoding="utf-8")


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_example_runs(index, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(BLOCKS[index], f"README.md[python block {index}]", "exec"), namespace)
    assert "manakov" in namespace
