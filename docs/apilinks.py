"""Sphinx extension: inline code that names a public object becomes a link to its API page.

The pages write names as they are typed in Python: ``rf.simulate``, ``rigidfem.gradient``,
``Result.sensitivity``, ``simulate(..., error_estimate=True)``, ``system.mass_matrix(t, q)``,
``rf.samples.pendulum()``. After all pages are read (``doctree-resolved``), each inline literal whose text is
such a name, with or without a call's arguments, is wrapped in a link to the object's entry on its API page,
found in the Python domain that autodoc filled:

- ``rf.`` is read as ``rigidfem.``; a dotted name is looked up as written, then after ``rigidfem.``;
- ``var.member`` where ``var`` is a conventional variable name (``system``, ``model``, ``res``, ...) is looked up
  as a member of the class the name stands for (:data:`VARIABLES`);
- a bare name links when it is a class or function of ``rigidfem`` (``Result``, ``simulate``), or when exactly
  one documented object has that last name and it holds an underscore (``to_dataframe``), is written as a call
  (``chirp(...)``, four letters or more) or is capitalised (``Sphere``, three letters or more: ``A`` and ``T`` are
  the book's symbols), unless it is one of simulate's parameters or options or a word as generic as ``function``;
- a name that is no documented object (an option such as ``t_eval``, a file, a variable) stays as it is.

Mentions of a notebook, ``notebooks/NN_name.ipynb`` (in code or in text), become links to the notebook's page.
Literals already inside a link, in a signature or in a code block are left alone.
"""

from __future__ import annotations

import inspect
import re

import rigidfem
from rigidfem import options

from docutils import nodes
from sphinx import addnodes

#: Conventional variable names of the pages' code, and the class each stands for
VARIABLES = {
    "system": "System", "sys": "System", "model": "Model", "res": "Result", "result": "Result",
    "beam": "Beam", "modes": "Modes", "viewer": "Viewer", "data": "Data", "body": "Body", "joint": "Joint",
    "point": "Point", "profile": "Profile", "plan": "Plan", "material": "Material", "section": "Section",
    "event": "Event", "grad": "Gradient", "gradient": "Gradient", "estimate": "ErrorEstimate", "eq": "Equilibrium",
    "equilibrium": "Equilibrium",
}

#: A name as code writes it: dotted identifiers, then optionally a call's arguments (anything in parentheses)
#: Bare names that are words of the text's own (``function(**case)`` is the user's function)
GENERIC = {"function"}
NAME = re.compile(r"^(?P<name>[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*)(?P<call>\(.*\))?$", re.S)
NOTEBOOK = re.compile(r"(?:\.\./)?notebooks/(?P<stem>\d\d_\w+)\.ipynb")


class _Index:
    """The Python domain's objects by full name, and the methods' names for bare calls."""

    def __init__(self, env):
        objects = env.get_domain("py").objects
        self.objects = {name: (e.docname, e.node_id) for name, e in objects.items() if not e.aliased}
        self.modules = {name for name, e in objects.items() if e.objtype == "module"}
        last: dict[str, list[str]] = {}
        for name in self.objects:
            if name.startswith("rigidfem.") and name not in self.modules:
                last.setdefault(name.rsplit(".", 1)[1], []).append(name)
        self.unique = {m: names[0] for m, names in last.items() if len(names) == 1}
        #: simulate's parameters and options: a bare ``error_estimate`` is the option, not Result.error_estimate
        self.options = set(inspect.signature(rigidfem.simulate).parameters) | {o.name for o in options.OPTIONS}
        self.notebooks = {d.split("/", 1)[1] for d in env.found_docs if d.startswith("notebooks/")}

    def resolve(self, text: str) -> str | None:
        """The full name of the documented object ``text`` names, or None."""
        m = NAME.match(text.strip())
        if not m:
            return None
        name, call = m.group("name"), m.group("call")
        if name.startswith("rf."):
            name = "rigidfem." + name[3:]
        head, _, rest = name.partition(".")
        candidates = [name, f"rigidfem.{name}"]
        if rest and head in VARIABLES:
            candidates.append(f"rigidfem.{VARIABLES[head]}.{rest}")
        for full in candidates:
            if full in self.objects and (rest or full not in self.modules):  # a bare module name stays text
                return full
        if (not rest and name in self.unique and name not in self.options and name not in GENERIC
                and ("_" in name or len(name) >= 4 and call or len(name) >= 3 and name[:1].isupper())):
            return self.unique[name]
        return None


def _uri(builder, fromdoc: str, todoc: str, anchor: str = "") -> str:
    uri = "" if todoc == fromdoc else builder.get_relative_uri(fromdoc, todoc)
    return f"{uri}#{anchor}" if anchor else uri or "#"


def _skip(node) -> bool:
    """A node inside a link, a signature, a code block or a title is left alone."""
    parent = node.parent
    while parent is not None:
        if isinstance(parent, (nodes.reference, addnodes.desc_signature, nodes.literal_block, nodes.title,
                               addnodes.pending_xref, nodes.raw, nodes.FixedTextElement)):
            return True
        parent = parent.parent
    return False


def link(app, doctree, fromdoc: str) -> None:
    if app.builder.format != "html":
        return
    index = getattr(app.env, "_rigidfem_apilinks", None)
    if index is None:
        index = app.env._rigidfem_apilinks = _Index(app.env)
    builder = app.builder

    for literal in list(doctree.findall(nodes.literal)):
        if _skip(literal):
            continue
        text = literal.astext()
        nb = NOTEBOOK.fullmatch(text.strip())
        if nb and nb.group("stem") in index.notebooks:
            uri, title = _uri(builder, fromdoc, f"notebooks/{nb.group('stem')}"), f"notebook {nb.group('stem')}"
        else:
            full = index.resolve(text)
            if full is None:
                continue
            docname, anchor = index.objects[full]
            uri, title = _uri(builder, fromdoc, docname, anchor), full
        ref = nodes.reference("", "", internal=True, refuri=uri, reftitle=title, classes=["rigidfem-apilink"])
        literal.replace_self(ref)
        ref += literal

    # notebook mentions in running text
    for text in list(doctree.findall(nodes.Text)):
        if not NOTEBOOK.search(text) or _skip(text) or isinstance(text.parent, nodes.literal):
            continue
        pieces, at = [], 0
        for m in NOTEBOOK.finditer(text):
            if m.group("stem") not in index.notebooks:
                continue
            pieces.append(nodes.Text(text[at:m.start()]))
            ref = nodes.reference("", m.group(0), internal=True,
                                  refuri=_uri(builder, fromdoc, f"notebooks/{m.group('stem')}"))
            pieces.append(ref)
            at = m.end()
        if pieces:
            pieces.append(nodes.Text(text[at:]))
            text.parent.replace(text, pieces)


def _reset(app, env, docnames) -> None:
    env._rigidfem_apilinks = None


def setup(app):
    app.connect("env-before-read-docs", _reset)
    app.connect("doctree-resolved", link)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
