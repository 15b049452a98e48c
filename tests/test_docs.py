"""The documentation site builds with Sphinx, warnings as errors (``docs/``; the README's link).

Checks what a reader opens: a page for every public name (from its docstring), the notebooks with
the figures they were committed with, and the table of simulate's options written from its one source.
"""

import html
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

import rigidfem as rf
from rigidfem import options

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("html")
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                          str(ROOT / "docs"), str(out)], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-4000:]
    return out


def text(path: Path) -> str:
    """The visible text of a page's article."""
    page = path.read_text(encoding="utf-8")
    page = page[page.find("<article"):page.find("</article>")]
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", page)))


def test_every_public_name_has_a_page_from_its_docstring(site):
    """Each page holds its name and the first (up to four) words of its docstring, inline markup removed."""
    for name in rf.__all__:
        page = site / "api" / f"rigidfem.{name}.html"
        assert page.exists(), name
        doc = (getattr(rf, name).__doc__ or "").strip()
        if re.match(rf"{name}\(.*\) ->", doc):  # pybind11's signature line comes first
            doc = doc.split("\n", 1)[1].strip() if "\n" in doc else ""
        words = doc.replace("``", "").split()[:4]
        assert len(words) >= 2, f"{name} has no docstring"
        shown = text(page).replace("’", "'").replace(" ", "")  # the tags leave spaces around linked words
        assert f"rigidfem.{name}" in shown and "".join(words) in shown, (name, words)


def test_the_notebooks_are_pages_with_their_figures(site):
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        page = site / "notebooks" / f"{nb.stem}.html"
        assert page.exists(), nb.name
        figures = sum("image/png" in out.get("data", {}) for cell in json.loads(nb.read_text())["cells"]
                      if cell["cell_type"] == "code" for out in cell.get("outputs", []))
        assert page.read_text(encoding="utf-8").count("<img") >= figures, nb.name


def test_the_options_table_is_the_one_of_rigidfem_options(site):
    page = text(site / "conventions.html")
    for o in options.OPTIONS:
        assert f" {o.name} " in page, o.name
    assert "rho_inf" in text(site / "api" / "rigidfem.simulate.html")


def test_the_examples_in_the_modules_docstrings_print_what_they_say():
    """Every ``>>>`` example of the package's docstrings runs and prints what it shows (doctest)."""
    import doctest
    import importlib
    import pkgutil

    failed, tried = 0, 0
    for info in pkgutil.walk_packages(rf.__path__, "rigidfem."):
        if info.name.startswith("rigidfem._core"):
            continue
        module = importlib.import_module(info.name)
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
        failed, tried = failed + result.failed, tried + result.attempted
    assert tried > 0 and failed == 0, f"{failed} of {tried} examples failed"
