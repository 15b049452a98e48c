"""Sphinx configuration of rigidfem's documentation site.

Build: ``pip install ".[docs]" && sphinx-build -W -b html docs docs/_build/html``
(``tests/test_docs.py`` builds it with warnings as errors).

The notebooks are rendered with the outputs they were committed with (myst-nb, no execution); the API
reference is generated from the docstrings (autosummary, numpydoc style through napoleon); the table of
simulate's options is written from ``rigidfem.options`` at build time, and the drawings (``docs/figures.py``) are
drawn by it.

The site works offline: MathJax is served from its own ``_static/mathjax`` (the ``sphinx-mathjax-offline``
package, MathJax 3), the code blocks' copy buttons (``sphinx-copybutton``) from ``_static`` too, and the
animations' buttons (matplotlib's ``to_jshtml``, which links Font Awesome from a CDN) use Font Awesome's CSS and
fonts copied into ``_static/fontawesome`` (the ``fontawesomefree`` package).
``tests/test_docs.py`` fails on any script, stylesheet or font the built pages would fetch from outside.
"""

from __future__ import annotations

import importlib
import re
import shutil
import sys
from pathlib import Path

import rigidfem
from rigidfem import options

import fontawesomefree

# rf.animation is imported on first use (matplotlib.animation costs 0.1 s); its page needs its short path too
sys.modules.setdefault("rigidfem.animation", importlib.import_module("rigidfem.viz.animation"))

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))  # the site's own extension: apilinks (inline code naming an object links to its page)

project = "rigidfem"
author = "the rigidfem developers"
copyright = "2026, the rigidfem developers"  # noqa: A001 (Sphinx's name)
release = rigidfem.__version__

extensions = ["myst_nb", "sphinx.ext.autodoc", "sphinx.ext.autosummary", "sphinx.ext.napoleon",
              "sphinx.ext.mathjax", "sphinx-mathjax-offline", "sphinx_copybutton", "apilinks",
              "matplotlib.sphinxext.plot_directive"]
# The guides' plots: the code of each {plot} block runs when the site is built and its figures are embedded
plot_include_source = True
plot_html_show_source_link = False
plot_html_show_formats = False
plot_formats = [("png", 100)]
mathjax_path = "mathjax/tex-chtml.js"  # in _static, copied there by sphinx-mathjax-offline (no CDN)
# A copy button on every code block (its script and icons in _static); prompts and doctest outputs are not copied
copybutton_prompt_text = r">>> |\.\.\. |\$ "
copybutton_prompt_is_regexp = True
copybutton_exclude = ".linenos, .gp, .go"
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "**.ipynb_checkpoints"]
html_theme = "furo"
# the site's own stylesheet (the gallery's cards) and the thumbnails the build makes (_generated/static/thumbnails)
html_static_path = ["_static", "_generated/static"]
html_css_files = ["gallery.css"]
html_title = f"rigidfem {release}"
REPOSITORY = "https://github.com/rigidfem/rigidfem"
html_theme_options = {
    # the repository, linked from every page's footer (furo's GitHub mark)
    "footer_icons": [{
        "name": "GitHub", "url": REPOSITORY, "class": "",
        "html": '<svg stroke="currentColor" fill="currentColor" stroke-width="0" viewBox="0 0 16 16">'
                '<path fill-rule="evenodd" d="M8 0C3.58 0 0 3.58 0 8c0 3.54 2.29 6.53 5.47 7.59.4.07.55-.17.55-.38 '
                '0-.19-.01-.82-.01-1.49-2.01.37-2.53-.49-2.69-.94-.09-.23-.48-.94-.82-1.13-.28-.15-.68-.52-.01-.53.63-.01 '
                '1.08.58 1.23.82.72 1.21 1.87.87 2.33.66.07-.52.28-.87.51-1.07-1.78-.2-3.64-.89-3.64-3.95 0-.87.31-1.59.82-2.15'
                '-.08-.2-.36-1.02.08-2.12 0 0 .67-.21 2.2.82.64-.18 1.32-.27 2-.27.68 0 1.36.09 2 .27 1.53-1.04 2.2-.82 2.2-.82'
                '.44 1.1.16 1.92.08 2.12.51.56.82 1.27.82 2.15 0 3.07-1.87 3.75-3.65 3.95.29.25.54.73.54 1.48 0 1.07-.01 1.93'
                '-.01 2.2 0 .21.15.46.55.38A8.013 8.013 0 0 0 16 8c0-4.42-3.58-8-8-8z"></path></svg>',
    }],
}

myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3
nb_execution_mode = "off"  # the notebooks' outputs as committed
# A widget's HTML fallback before its view: the site runs no widget manager (rf.view(...).widget() shows its page)
nb_mime_priority_overrides = [("html", "text/html", 5)]

autosummary_generate = True
# A class's page documents the methods it inherits from its compiled base (System's mass_matrix, ...), not those of
# object or the exceptions' bases; a public module's page documents the functions and classes of the module it
# stands for (rigidfem.study is rigidfem.studies.study), which autodoc would take for imported ones
autodoc_default_options = {"members": True, "undoc-members": False, "imported-members": True,
                           "inherited-members": "pybind11_object,BaseException,object"}
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


def _draw_figures() -> None:
    """The pages' drawings (docs/figures.py) into docs/_generated/figures, made at each build."""
    sys.path.insert(0, str(HERE))
    try:
        import figures
    finally:
        sys.path.remove(str(HERE))
    figures.write(HERE / "_generated" / "figures")


def _write_gallery() -> None:
    """The gallery's thumbnails (each notebook's first figure) and cards (docs/notebook_gallery.py)."""
    import notebook_gallery

    notebook_gallery.write(HERE / "notebooks", HERE / "_generated")


_copy_notebooks()
_write_options_table()
_write_api_page()
_draw_figures()
_write_gallery()
exclude_patterns.append("_generated")

# The docstrings write |x| for norms and absolute values, as mathematics reads in help(); reST would take
# |x| for a substitution. Escaped here, outside inline literals, for the site only.
_LITERAL = re.compile(r"(``.*?``)")


def _escape_bars(app, what, name, obj, opts, lines) -> None:
    for k, line in enumerate(lines):
        parts = _LITERAL.split(line)
        lines[k] = "".join(p if p.startswith("``") else p.replace("|", r"\|") for p in parts)


# matplotlib's to_jshtml animations link Font Awesome 4 from a CDN for their buttons; the link is pointed at
# Font Awesome 6's CSS (which keeps the v4 names the buttons use) and fonts, copied into the site.
_FONT_AWESOME = Path(fontawesomefree.__file__).resolve().parent / "static" / "fontawesomefree"
_FONT_AWESOME_CDN = re.compile(r"<link\b[^>]*\bhref=[\"']?(?:https?:)?//[^\"'>\s]*font-?awesome[^>]*>", re.I)


def _local_font_awesome(app, pagename, templatename, context, doctree) -> None:
    body = context.get("body")
    if body and _FONT_AWESOME_CDN.search(body):
        href = context["pathto"]("_static/fontawesome/css/all.min.css", 1)
        context["body"] = _FONT_AWESOME_CDN.sub(f'<link rel="stylesheet" href="{href}">', body)


def _copy_font_awesome(app, exc) -> None:
    if exc is not None or app.builder.format != "html":
        return
    out = Path(app.outdir) / "_static" / "fontawesome"
    for rel in ["LICENSE.txt", "css/all.min.css"] + [f"webfonts/{f.name}" for f in
                                                      sorted((_FONT_AWESOME / "webfonts").iterdir())]:
        (out / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(_FONT_AWESOME / rel, out / rel)


def _download_link(app, pagename, templatename, context, doctree) -> None:
    """A notebook's page opens with a link to download it (the .ipynb itself, copied beside the page)."""
    if pagename.startswith("notebooks/") and context.get("body") and (HERE / f"{pagename}.ipynb").exists():
        name = pagename.split("/", 1)[1]
        link = (f'<p class="rigidfem-download"><a class="reference download" href="{name}.ipynb" download>'
                f'Download this notebook ({name}.ipynb)</a>, run it with <code>pip install ".[notebooks]"</code> '
                f'and <code>jupyter lab</code> from a checkout.</p>')
        context["body"] = link + context["body"]


def _copy_notebook_files(app, exc) -> None:
    if exc is not None or app.builder.format != "html":
        return
    out = Path(app.outdir) / "notebooks"
    out.mkdir(parents=True, exist_ok=True)
    for nb in sorted((HERE / "notebooks").glob("*.ipynb")):
        shutil.copyfile(nb, out / nb.name)


def _write_viewer_pages(app, exc) -> None:
    """The gallery's 3D pages (docs/viewer_gallery.py) into the site's viewer/ folder."""
    if exc is not None or app.builder.format != "html":
        return
    sys.path.insert(0, str(HERE))
    try:
        import viewer_gallery
    finally:
        sys.path.remove(str(HERE))
    viewer_gallery.write(Path(app.outdir) / "viewer")


_documented_module: list[str] = [""]


def _note_module(app, what, name, obj, opts, lines) -> None:
    if what == "module":
        _documented_module[0] = obj.__name__


def _only_the_modules_own(app, what, name, obj, skip, opts):
    """On a module's page, the functions and classes defined in the module it stands for, not what it imports
    nor the public names with a page of their own; on a class's page, no member inherited from outside the
    package (matplotlib's Animation)."""
    where = getattr(obj, "__module__", None)
    if what == "module" and isinstance(where, str) and (callable(obj) or isinstance(obj, type)):
        return skip or where != _documented_module[0] or getattr(rigidfem, name, None) is obj
    if what == "class" and isinstance(where, str) and not where.startswith("rigidfem"):
        return True
    return None


def setup(app):
    app.connect("autodoc-process-docstring", _note_module)
    app.connect("autodoc-skip-member", _only_the_modules_own)
    app.connect("build-finished", _write_viewer_pages)
    app.connect("autodoc-process-docstring", _escape_bars)
    app.connect("html-page-context", _download_link)
    app.connect("build-finished", _copy_notebook_files)
    app.connect("html-page-context", _local_font_awesome)
    app.connect("build-finished", _copy_font_awesome)
