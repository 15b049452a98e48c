"""Every Python block of the README and of the documentation's pages (docs/*.md) runs as a user copies
it: each alone, as a script in an empty folder (so that a block with Dask's ``if __name__ ==
"__main__"`` guard runs as written), with the non-interactive matplotlib backend."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md"] + sorted(p for p in (ROOT / "docs").rglob("*.md") if not p.parts[-2].startswith("_"))
BLOCKS = [(page.relative_to(ROOT).as_posix(), k, block) for page in PAGES
          for k, block in enumerate(re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.S))]
#: What a page shows a block prints: a ```text block right after it, or after "It prints:" (page, block
#: index) -> the text.
SHOWN = {(page.relative_to(ROOT).as_posix(), k): m.group(2)
         for page in PAGES
         for k, m in enumerate(re.finditer(r"```python\n(.*?)```(?:\s*(?:It prints(?: \([^)\n]*\))?:\s*)?```text\n(.*?)```)?", page.read_text(encoding="utf-8"),
                                           flags=re.S))
         if m.group(2) is not None}


def test_the_readme_starts_with_a_quick_start_that_runs():
    assert any(page == "README.md" for page, _, _ in BLOCKS)
    assert len(BLOCKS) >= 15


@pytest.mark.parametrize("page, k, block", BLOCKS, ids=[f"{p}:{k}" for p, k, _ in BLOCKS])
def test_documented_block_runs_as_copied(page, k, block, tmp_path):
    script = tmp_path / f"block{k}.py"
    script.write_text(block, encoding="utf-8")
    env = dict(os.environ, MPLBACKEND="Agg", OPENBLAS_NUM_THREADS="1")
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                         env=env)
    assert run.returncode == 0, f"{page}, block {k}:\n{block[:400]}\n--- stderr:\n{run.stderr[-3000:]}"
    if (page, k) in SHOWN:  # what the page says it prints, it prints
        assert run.stdout == SHOWN[page, k], f"{page}, block {k} printed:\n{run.stdout}"
