"""Sphinx configuration of rigidfem's documentation site.

Build: ``pip install ".[docs]" && sphinx-build -W -b html docs docs/_build/html``
(``tests/test_docs.py`` builds it with warnings as errors).

The notebooks are rendered with the outputs they were committed with (myst-nb, no execution); the API
reference is generated from the docstrings (autosummary, numpydoc style through napoleon); the table of
simulate's options is written from ``rigidfem.options`` at build time.
"""

from __future__ import annotations

import importlib
import re
import shutil
import sys
from pathlib import Path

import rigidfem
from rigidfem import options

# rf.animation is imported on first use (matplotlib.animation costs 0.1 s); its page needs its short path too
sys.modules.setdefault("rigidfem.animation", importlib.import_module("rigidfem.viz.animation"))

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

project = "rigidfem"
author = "the rigidfem developers"
copyright = "2026, the rigidfem developers"  # noqa: A001 (Sphinx's name)
release = rigidfem.__version__

extensions = ["myst_nb", "sphinx.ext.autodoc", "sphinx.ext.autosummary", "sphinx.ext.napoleon",
              "sphinx.ext.mathjax"]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "**.ipynb_checkpoints"]
html_theme = "furo"
html_title = f"rigidfem {release}"

myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3
nb_execution_mode = "off"  # the notebooks' outputs as committed

autosummary_generate = True
autodoc_default_options = {"members": True, "undoc-members": False}
autodoc_member_order = "bysource"
napoleon_numpy_docstring = True
napoleon_google_docstring = False


def _copy_notebooks() -> None:
    """The repository's notebooks into docs/notebooks (generated, not committed)."""
    target = HERE / "notebooks"
    target.mkdir(exist_ok=True)
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        if not (target / nb.name).exists() or (target / nb.name).read_bytes() != nb.read_bytes():
            shutil.copyfile(nb, target / nb.name)


def _write_options_table() -> None:
    """docs/_generated/options.md, methods.md and laws.md: simulate's options and methods and the kinds of law,
    from the C++ descriptions (rigidfem.options and rigidfem.laws read them)."""
    out = HERE / "_generated"
    out.mkdir(exist_ok=True)
    for name, text in (("options.md", options.table()), ("methods.md", options.method_table()),
                       ("laws.md", rigidfem.laws.table())):
        path = out / name
        if not path.exists() or path.read_text() != text + "\n":
            path.write_text(text + "\n")


def _write_api_page() -> None:
    """docs/api.md: every name of ``rigidfem.__all__``, by kind, through autosummary (generated, so that a
    new public name cannot be left out)."""
    import inspect

    kinds = {"Classes": [], "Functions": [], "Modules": []}
    for name in rigidfem.__all__:
        obj = getattr(rigidfem, name)
        kind = "Modules" if inspect.ismodule(obj) else "Classes" if inspect.isclass(obj) else "Functions"
        kinds[kind].append(name)
    lines = ["# API reference", "", "Every public name of `rigidfem` (`rigidfem.__all__`), from its docstring.", ""]
    for kind, names in kinds.items():
        lines += [f"## {kind}", "", "```{eval-rst}", ".. currentmodule:: rigidfem", "", ".. autosummary::",
                  "   :toctree: api", ""] + [f"   {n}" for n in names] + ["```", ""]
    text = "\n".join(lines)
    path = HERE / "api.md"
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


_copy_notebooks()
_write_options_table()
_write_api_page()
exclude_patterns.append("_generated")

# The docstrings write |x| for norms and absolute values, as mathematics reads in help(); reST would take
# |x| for a substitution. Escaped here, outside inline literals, for the site only.
_LITERAL = re.compile(r"(``.*?``)")


def _escape_bars(app, what, name, obj, opts, lines) -> None:
    for k, line in enumerate(lines):
        parts = _LITERAL.split(line)
        lines[k] = "".join(p if p.startswith("``") else p.replace("|", r"\|") for p in parts)


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars)
