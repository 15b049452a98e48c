"""The gallery's cards: each notebook's first figure as a thumbnail, made by the build (``conf.py`` calls
:func:`write`) from the outputs the notebook was committed with.

``_generated/static/thumbnails/<notebook>.png`` (copied by Sphinx into the site's ``_static``) and
``_generated/gallery_cards.md``, a grid of cards in plain HTML (``docs/_static/gallery.css``) that
``gallery.md`` includes: the thumbnail, the notebook's number and title, a link to its page.
"""

from __future__ import annotations

import base64
import html
import io
import json
from pathlib import Path

from PIL import Image

#: The thumbnails' largest size in pixels (width, height), twice the card's for sharp screens
SIZE = (480, 320)


def _first_figure(notebook: dict) -> bytes | None:
    """The PNG of the first figure among the code cells' outputs, or None."""
    for cell in notebook["cells"]:
        if cell["cell_type"] == "code":
            for output in cell.get("outputs", []):
                png = output.get("data", {}).get("image/png")
                if png:
                    return base64.b64decode("".join(png) if isinstance(png, list) else png)
    return None


def _title(notebook: dict, stem: str) -> tuple[str, str]:
    """(number, title) from the first level-1 heading, "NN · Title"; the file's name otherwise."""
    number, _, rest = stem.partition("_")
    for cell in notebook["cells"]:
        if cell["cell_type"] == "markdown":
            for line in "".join(cell["source"]).splitlines():
                if line.startswith("# "):
                    heading = line[2:].strip()
                    return number, heading.split("·", 1)[1].strip() if "·" in heading else heading
    return number, rest.replace("_", " ")


def _thumbnail(png: bytes, path: Path) -> None:
    image = Image.open(io.BytesIO(png))
    if image.mode in ("RGBA", "LA", "P"):
        image = image.convert("RGBA")
        background = Image.new("RGBA", image.size, "white")
        image = Image.alpha_composite(background, image)
    image = image.convert("RGB")
    image.thumbnail(SIZE, Image.LANCZOS)
    buffer = io.BytesIO()
    image.save(buffer, format="PNG", optimize=True)
    if not path.exists() or path.read_bytes() != buffer.getvalue():
        path.write_bytes(buffer.getvalue())


def write(notebooks: Path, generated: Path) -> list[str]:
    """Thumbnails and cards for every notebook in ``notebooks``; returns the notebooks' stems in order."""
    thumbnails = generated / "static" / "thumbnails"
    thumbnails.mkdir(parents=True, exist_ok=True)
    cards, stems = [], []
    for path in sorted(Path(notebooks).glob("*.ipynb")):
        notebook = json.loads(path.read_text(encoding="utf-8"))
        number, title = _title(notebook, path.stem)
        png = _first_figure(notebook)
        if png is not None:
            _thumbnail(png, thumbnails / f"{path.stem}.png")
            picture = (f'<img src="_static/thumbnails/{path.stem}.png" alt="The first figure of notebook {number}" '
                       f'loading="lazy">')
        else:
            picture = '<span class="rigidfem-card-empty">no figure</span>'
        cards.append(f'<a class="rigidfem-card" href="notebooks/{path.stem}.html">{picture}'
                     f'<span class="rigidfem-card-title"><b>{number}</b> {html.escape(title)}</span></a>')
        stems.append(path.stem)
    text = "\n".join(["```{raw} html", '<div class="rigidfem-gallery">', *cards, "</div>", "```", ""])
    out = generated / "gallery_cards.md"
    if not out.exists() or out.read_text(encoding="utf-8") != text:
        out.write_text(text, encoding="utf-8")
    return stems
