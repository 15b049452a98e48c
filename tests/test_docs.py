"""The documentation site builds with Sphinx, warnings as errors (``docs/``; the README's link).

Checks what a reader opens: a page for every public name (from its docstring), the notebooks with
the figures they were committed with, the table of simulate's options written from its one source, a site
that loads nothing from outside (it works offline), an install page that names every extra, and pages that
speak of the package rather than of its development.
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
        # each page links its notebook for download, and the file is there, the repository's own
        assert f'href="{nb.name}" download' in page.read_text(encoding="utf-8"), nb.name
        assert (site / "notebooks" / nb.name).read_bytes() == nb.read_bytes(), nb.name
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


#: A script, a stylesheet, an @import or a font fetched from another host: http://, https:// or //.
EXTERNAL = r"""(?:https?:)?//"""
SCRIPT_SRC = re.compile(r"""<script\b[^>]*?\bsrc\s*=\s*["']?([^"'\s>]+)""", re.I)
LINK = re.compile(r"<link\b[^>]*>", re.I)
STYLESHEET_HREF = re.compile(r"""\bhref\s*=\s*["']?([^"'\s>]+)""", re.I)
CSS_URL = re.compile(r"""@import\s+(?:url\(\s*)?["']?\s*([^"')\s;]+)|\burl\(\s*["']?\s*([^"')\s]+)""", re.I)


def _loaded(page: str) -> list[tuple[str, str]]:
    """(kind, address) of what a page or a stylesheet makes the browser fetch by itself."""
    found = [("script", m.group(1)) for m in SCRIPT_SRC.finditer(page)]
    for tag in LINK.findall(page):
        rel = re.search(r"""\brel\s*=\s*["']?([^"'>]*)""", tag, re.I)
        href = STYLESHEET_HREF.search(tag)
        if rel and "stylesheet" in rel.group(1).lower() and href:
            found.append(("stylesheet", href.group(1)))
    found += [("@import" if m.group(1) else "url()", m.group(1) or m.group(2)) for m in CSS_URL.finditer(page)]
    return found


def test_the_site_loads_nothing_from_outside(site):
    """Every page works offline: no script, stylesheet, @import or font from another host (MathJax and the
    animations' Font Awesome are served from _static), and every local one it names is in the site. Links
    (<a href>) to outside are fine."""
    pages = sorted(site.rglob("*.html"))
    assert len(pages) >= len(rf.__all__) + len(list((ROOT / "notebooks").glob("*.ipynb")))
    external, missing = [], []
    for path in pages + sorted(site.glob("_static/**/*.css")):
        for kind, address in _loaded(path.read_text(encoding="utf-8")):
            where = f"{path.relative_to(site)}: {kind} {address}"
            if re.match(EXTERNAL, address, re.I):
                external.append(where)
            elif path.suffix == ".html" and not address.startswith(("data:", "#")):
                if not (path.parent / address.split("?")[0].split("#")[0]).exists():
                    missing.append(where)
    assert not external, f"{len(external)} external resources:\n" + "\n".join(external[:20])
    assert not missing, f"{len(missing)} local resources missing:\n" + "\n".join(missing[:20])
    assert (site / "_static" / "mathjax" / "tex-chtml.js").exists()
    assert (site / "_static" / "fontawesome" / "webfonts" / "fa-solid-900.woff2").exists()
    assert "github.com/rigidfem/rigidfem" in (site / "api" / "rigidfem.Model.html").read_text(encoding="utf-8")
    assert "Changelog" in text(site / "changelog.html")


#: The development's narrative, which the pages a user reads leave to the CHANGELOG and the history: an
#: issue's number, "the issue's ...", a "Before: ..." or "(... before)" / "now ..." of what the package did,
#: a previous run compared with this one.
NARRATIVE = [re.compile(r"\bissues?\s*#?\d", re.I), re.compile(r"\bthe issue's", re.I), re.compile(r"\bBefore:"),
             re.compile(r"[;(,]\s*before[,:)]|\d\S* before\)|\bnow \d|\bprevious run\b|\bfixed in this run\b")]


def _user_pages() -> list[tuple[str, list[str]]]:
    """(where, lines) of the README, the site's pages (docs/**/*.md, not the generated _folders) and the
    notebooks' markdown cells."""
    pages = [ROOT / "README.md"] + sorted(p for p in (ROOT / "docs").rglob("*.md")
                                          if not any(part.startswith("_") for part in p.relative_to(ROOT).parts))
    out = [(p.relative_to(ROOT).as_posix(), p.read_text(encoding="utf-8").splitlines()) for p in pages]
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        for k, cell in enumerate(json.loads(nb.read_text(encoding="utf-8"))["cells"]):
            if cell["cell_type"] == "markdown":
                out.append((f"notebooks/{nb.name}, cell {k}", "".join(cell["source"]).splitlines()))
    return out


def test_the_pages_speak_of_the_package_not_of_its_development():
    found = [f"{where}:{n}: {line.strip()[:120]}" for where, lines in _user_pages()
             for n, line in enumerate(lines, 1) if any(p.search(line) for p in NARRATIVE)]
    assert not found, "development narrative on a user's page:\n" + "\n".join(found)


def test_the_install_page_names_every_extra_and_the_project_its_addresses():
    tomllib = pytest.importorskip("tomllib")
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    page = (ROOT / "docs" / "install.md").read_text(encoding="utf-8")
    extras = project["optional-dependencies"]
    assert [e for e in extras if f'".[{e}]"' not in page] == []
    assert set(extras["docs"]) <= set(extras["test"])  # the test extra builds the site as the docs extra does
    assert {"Homepage", "Documentation", "Repository", "Changelog"} <= set(project["urls"])


def test_the_citation_file_names_the_package_and_the_book():
    yaml = pytest.importorskip("yaml")
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["cff-version"] == "1.2.0" and cff["title"] == "rigidfem" and cff["version"] == rf.__version__
    assert cff["authors"] == [{"name": "rigidfem developers"}]
    (book,) = cff["references"]
    assert book["type"] == "book" and book["year"] == 2006 and "Rigid Finite Element Method" in book["title"]


def test_the_gallery_embeds_the_viewers_standalone_pages(site):
    """The site's gallery shows pages of rf.view (written by the build from docs/viewer_gallery.py) in iframes, each
    page in the site, self-contained (its three.js inline, packed), and the notebooks that show the viewer carry its
    page."""
    import base64
    import zlib

    gallery = (site / "gallery.html").read_text(encoding="utf-8")
    shown = re.findall(r'<iframe src="(viewer/\w+\.html)"', gallery)
    assert len(shown) == 4, shown
    for page in shown:
        body = (site / page).read_text(encoding="utf-8")
        packed = re.search(r'rigidfemUnpack\("([A-Za-z0-9+/=]+)"\)', body)
        assert "window.RIGIDFEM" in body and packed, page
        assert "REVISION" in zlib.decompress(base64.b64decode(packed.group(1))).decode("utf-8"), page
    for nb in ("06_offshore_crane", "09_cantilever_frequencies", "11_kane", "12_whippy_beam"):
        assert "<iframe srcdoc=" in (site / "notebooks" / f"{nb}.html").read_text(encoding="utf-8"), nb


def test_code_blocks_have_copy_buttons_served_from_the_site(site):
    """sphinx-copybutton's script, with its clipboard library, is in the site's _static and loaded by the pages
    that show code (the copied text leaves out the >>> prompts and the outputs)."""
    for name in ("copybutton.js", "clipboard.min.js", "copybutton.css"):
        assert (site / "_static" / name).exists(), name
    for page in ("tour.html", "simulation.html", "api/rigidfem.simulate.html"):
        body = (site / page).read_text(encoding="utf-8")
        assert "_static/copybutton.js" in body and "highlight" in body, page
    script = (site / "_static" / "copybutton.js").read_text(encoding="utf-8")
    assert ">>> " in script.replace("\\\\", "\\") or "&gt;&gt;&gt;" in script


def test_the_method_page_shows_the_rfe_figure_drawn_by_the_build(site):
    """The figure of two rfes, their frames and the sde between them is drawn by docs/figures.py at each build
    (conf.py calls it); no picture of the site is committed."""
    page = (site / "method.html").read_text(encoding="utf-8")
    assert re.search(r'<img[^>]*src="_images/rfe_sde\.png"', page)
    png = (site / "_images" / "rfe_sde.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
    assert width > 900 and 0.2 < height / width < 0.6, (width, height)
    committed = subprocess.run(["git", "ls-files", "docs"], cwd=ROOT, capture_output=True, text=True).stdout.split()
    assert not [f for f in committed if f.endswith((".png", ".jpg", ".svg", ".gif"))]


@pytest.mark.parametrize("page, count", [("simulation.html", 1), ("verification.html", 1)])
def test_the_guides_plots_are_drawn_by_the_build(site, page, count):
    """The guides' {plot} blocks run when the site is built (matplotlib's plot directive): each page shows its
    figures, PNGs made by the build whose pixels vary (not blank), beside the code that drew them."""
    article = _article(site / page)
    images = re.findall(r'<img[^>]*src="([^"]*plot_directive[^"]*\.png|_images/[^"]*-\d+\.png)"', article)
    assert len(images) >= count, images
    import matplotlib.image

    for src in images:
        pixels = matplotlib.image.imread(site / src)
        assert pixels.shape[1] > 400 and pixels[..., :3].std() > 0.05, (src, pixels.shape)
    assert "rf.plots." in text(site / page) or "modal_analysis" in text(site / page)


def _article(path: Path) -> str:
    page = path.read_text(encoding="utf-8")
    return page[page.find("<article"):page.find("</article>")]


APILINK = re.compile(r'<a class="rigidfem-apilink[^"]*" href="([^"]*)"')


def test_api_names_and_notebooks_in_the_text_are_links(site):
    """docs/apilinks.py turns inline code naming a public object (``rf.simulate``, ``Result.sensitivity``,
    ``system.mass_matrix(t, q)``) into a link to its entry on its API page, and every ``notebooks/NN_name.ipynb``
    into a link to the notebook's page; every such link reaches an anchor that exists."""
    simulation = _article(site / "simulation.html")
    links = APILINK.findall(simulation)
    assert len([h for h in links if h.startswith("api/")]) >= 50, len(links)
    assert 'href="api/rigidfem.simulate.html#rigidfem.simulate"' in simulation
    assert 'href="api/rigidfem.Result.html#rigidfem.Result.sensitivity"' in simulation or \
        "Result.sensitivity" not in (ROOT / "docs" / "simulation.md").read_text(encoding="utf-8")
    anchors: dict[Path, set[str]] = {}
    pages = sorted(site.glob("*.html")) + sorted(site.glob("chapters/*.html")) + sorted(site.glob("notebooks/*.html"))
    for path in pages + sorted(site.glob("api/*.html")):
        article = _article(path)
        for href in APILINK.findall(article):
            target, _, anchor = href.partition("#")
            file = (path.parent / target).resolve() if target else path
            if file not in anchors:
                anchors[file] = set(re.findall(r'\bid="([^"]+)"', file.read_text(encoding="utf-8")))
            assert not anchor or anchor in anchors[file], (path.name, href)
        outside_links = re.sub(r"<a\b[^>]*>.*?</a>", "", article, flags=re.S)
        unlinked = re.findall(r"notebooks/\d\d_\w+\.ipynb", outside_links)
        assert not unlinked, (path.relative_to(site).as_posix(), unlinked)
    # a page of the guide and a notebook link both ways
    assert 'href="notebooks/08_sweeps.html"' in simulation
    assert APILINK.search(_article(site / "notebooks" / "02_cantilever.html"))


#: Public names whose docstrings are written in the C++ bindings (cpp/bindings): their Examples sections belong
#: there, with the bindings' owner. Remove a name from this set once its docstring has one (the test below fails
#: on a name listed here that has one, and on any other public name without one).
EXAMPLES_IN_CPP: set[str] = set()


def _public_objects() -> dict:
    """Every name of rigidfem.__all__, and the public methods of Result, System and Model (decorators unwrapped)."""
    import inspect

    objects = {name: getattr(rf, name) for name in rf.__all__}
    for cls in (rf.Result, rf.System, rf.Model):
        for name in dir(cls):
            static = inspect.getattr_static(cls, name)
            if name.startswith("_") or isinstance(static, property) or not callable(getattr(cls, name)):
                continue
            if not (inspect.isroutine(static) or isinstance(static, (staticmethod, classmethod))):
                continue
            objects[f"{cls.__name__}.{name}"] = inspect.unwrap(getattr(static, "__func__", static))
    return objects


def test_every_public_name_has_an_examples_section():
    """numpydoc's Examples section in every public docstring (the names documented in C++ aside, listed above)."""
    missing = {name for name, obj in _public_objects().items()
               if not re.search(r"^\s*Examples\n\s*-{8,}\n\s*>>> ", obj.__doc__ or "", re.M)}
    assert missing - EXAMPLES_IN_CPP == set(), f"no Examples section: {sorted(missing - EXAMPLES_IN_CPP)}"
    assert EXAMPLES_IN_CPP - missing == set(), f"has one now, drop from the list: {sorted(EXAMPLES_IN_CPP - missing)}"


def test_the_public_examples_run_and_print_what_they_show():
    """Every >>> line of the public names' docstrings runs and prints what it shows (doctest, each docstring in a
    fresh namespace). The modules' docstrings are also run by the test of every module above; the methods that a
    decorator wraps (Model.add_*) only here."""
    import doctest

    finder = doctest.DocTestFinder(recurse=False)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    names_run, report = 0, []
    for name, obj in _public_objects().items():
        for test in finder.find(obj, name, globs={}):
            if test.examples:
                names_run += 1
                runner.run(test, out=report.append)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, "".join(report)[-4000:]
    assert names_run >= len(_public_objects()) - len(EXAMPLES_IN_CPP), (result, names_run)


def test_the_gallery_shows_a_card_with_a_thumbnail_per_notebook(site):
    """docs/notebook_gallery.py makes, at each build, a thumbnail of each notebook's first figure (from its committed
    outputs) and a card linking the notebook's page; the cards are plain HTML and CSS served by the site."""
    gallery = (site / "gallery.html").read_text(encoding="utf-8")
    cards = re.findall(r'<a class="rigidfem-card" href="(notebooks/\w+\.html)"><img src="(_static/thumbnails/\w+\.png)"',
                       gallery)
    notebooks = sorted(p.stem for p in (ROOT / "notebooks").glob("*.ipynb"))
    assert [Path(href).stem for href, _ in cards] == notebooks
    for href, thumbnail in cards:
        assert (site / href).exists(), href
        png = (site / thumbnail).read_bytes()
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and 100 <= int.from_bytes(png[16:20], "big") <= 480, thumbnail
    assert '_static/gallery.css' in gallery and (site / "_static" / "gallery.css").exists()


#: Guide pages whose paragraphs are still to be cut to WORDS_PER_PARAGRAPH: none, no page is exempted. A page
#: listed here would be skipped by the test.
PARAGRAPHS_TO_DO: set[str] = set()
WORDS_PER_PARAGRAPH = 120


def _paragraphs(text: str) -> list[tuple[int, str]]:
    """(first line, text) of each paragraph and list item of a markdown page: fenced blocks (code, directives),
    display math ($$), tables, HTML blocks and headings are left out."""
    found, current, start, fence, math = [], [], 0, None, False

    def flush():
        if current:
            found.append((start, " ".join(current)))
        current.clear()

    for n, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if fence:
            fence = None if s.startswith(fence) else fence
            continue
        if m := re.match(r"^(`{3,}|~{3,})", s):
            flush()
            fence = m.group(1)
            continue
        if math:
            math = not s.endswith("$$")
            continue
        if s.startswith("$$"):
            flush()
            math = not (s.endswith("$$") and len(s) > 2)
            continue
        if not s or s.startswith(("#", "|", "<")):
            flush()
            continue
        if re.match(r"^([-*+]|\d+[.)])\s", s):  # a list item starts a paragraph of its own
            flush()
            s = re.sub(r"^([-*+]|\d+[.)])\s+", "", s)
        if not current:
            start = n
        current.append(s)
    flush()
    return found


def test_the_guide_pages_paragraphs_are_short_enough_to_scan():
    """No paragraph or list item of a guide page (docs/*.md but the changelog and the generated API index) holds more
    than 120 words; inline math counts as one word."""
    pages = sorted(p for p in (ROOT / "docs").glob("*.md") if p.name not in {"changelog.md", "api.md"})
    assert len(pages) >= 15
    long = []
    for page in pages:
        if page.name in PARAGRAPHS_TO_DO:
            continue
        for line, paragraph in _paragraphs(page.read_text(encoding="utf-8")):
            count = len(re.sub(r"\$[^$]+\$", " x ", paragraph).split())
            if count > WORDS_PER_PARAGRAPH:
                long.append(f"docs/{page.name}:{line}: {count} words: {paragraph[:60]}...")
    assert not long, "paragraphs over 120 words (split them or make a list):\n" + "\n".join(long)
    # the counter sees what it should: code, math and tables apart, list items one by one
    sample = "```python\n" + "x = 1\n" * 200 + "```\n\n$$\n" + "a + " * 200 + "b\n$$\n\n| a | b |\n\n" + \
        "- " + "word " * 100 + "\n- " + "word " * 100 + "\n\n" + "long " * 121
    assert [len(p.split()) for _, p in _paragraphs(sample)] == [100, 100, 121]
