"""Runs every ```python block of docs/python.md, each in a fresh namespace and directory. A
block whose first line is '# needs: PATH' is skipped when PATH does not exist."""
import os
import re
from pathlib import Path

import pytest

PAGE = Path(__file__).resolve().parents[2] / "docs" / "python.md"
BLOCKS = re.findall(r"```python\n(.*?)```", PAGE.read_text(), re.S)


def test_the_page_has_examples():
    assert len(BLOCKS) >= 4


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_example(index, tmp_path, monkeypatch):
    code = BLOCKS[index]
    first = code.splitlines()[0]
    if first.startswith("# needs: "):
        needed = first[len("# needs: "):].split()[0]
        if not os.path.exists(needed):
            pytest.skip(f"{needed} is not installed")
    if "distributed." in code and "asan" in os.environ.get("LD_PRELOAD", ""):
        pytest.skip("Dask's worker processes are not run under the sanitizers (test_distributed.py)")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, f"docs/python.md block {index + 1}", "exec"), {"__name__": "__docs__"})
