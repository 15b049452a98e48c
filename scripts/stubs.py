"""The typing stubs of the compiled core, ``python/rigidfem/_core/*.pyi``, generated from the bindings.

    python scripts/stubs.py            writes them (pybind11-stubgen on the installed rigidfem._core)
    python scripts/stubs.py --check    exits 1, listing the differences, where the committed stubs and the
                                       bindings disagree on a name or a parameter

The check compares what the stubs declare — every class, function, method and attribute with its parameters'
names — not how pybind11 spells the types, so a new pybind11 release does not fail it; tests/test_stubs.py runs it.
"""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

STUBS = Path(__file__).resolve().parents[1] / "python" / "rigidfem" / "_core"


def generate(into: Path) -> Path:
    """The stubs of rigidfem._core written under ``into``; returns their folder."""
    subprocess.run([sys.executable, "-m", "pybind11_stubgen", "rigidfem._core", "-o", str(into)], check=True,
                   capture_output=True, text=True)
    folder = into / "rigidfem" / "_core"
    # `build` is the loaded build's name, which depends on the processor: declared, not valued
    init = folder / "__init__.pyi"
    init.write_text(re.sub(r"(?m)^build: str = .*$", 'build: str  # "baseline" or "x86-64-v3" (rigidfem/_load_core.py)',
                           init.read_text()))
    return folder


def declared(folder: Path) -> dict[str, tuple]:
    """{"module:qualified.name": parameter names (functions) or ()} of every .pyi in ``folder``."""
    out = {}
    for path in sorted(folder.glob("*.pyi")):
        module = path.stem

        def visit(nodes, prefix):
            for node in nodes:
                if isinstance(node, ast.ClassDef):
                    out[f"{module}:{prefix}{node.name}"] = ()
                    visit(node.body, f"{prefix}{node.name}.")
                elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    a = node.args
                    names = tuple(x.arg for x in a.posonlyargs + a.args + a.kwonlyargs)
                    key = f"{module}:{prefix}{node.name}"
                    out[key] = out.get(key, ()) + (names,)  # overloads: each signature
                elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                    out[f"{module}:{prefix}{node.target.id}"] = ()
                elif isinstance(node, ast.Assign):
                    for target in node.targets:
                        if isinstance(target, ast.Name) and target.id != "__all__":
                            out[f"{module}:{prefix}{target.id}"] = ()

        visit(ast.parse(path.read_text(encoding="utf-8")).body, "")
    return out


def differences(committed: Path, generated: Path) -> list[str]:
    """What the committed stubs declare differently from the generated ones, a line each."""
    a, b = declared(committed), declared(generated)
    lines = [f"missing from the stubs: {k}{'' if not b[k] else b[k]}" for k in sorted(set(b) - set(a))]
    lines += [f"in the stubs, not bound: {k}" for k in sorted(set(a) - set(b))]
    lines += [f"other parameters: {k}: stubs {a[k]}, bindings {b[k]}" for k in sorted(set(a) & set(b)) if a[k] != b[k]]
    return lines


def main(argv: list[str]) -> int:
    with tempfile.TemporaryDirectory() as tmp:
        generated = generate(Path(tmp))
        if "--check" in argv:
            lines = differences(STUBS, generated)
            print("\n".join(lines) if lines else "the stubs match the bindings")
            return 1 if lines else 0
        for path in generated.glob("*.pyi"):
            shutil.copyfile(path, STUBS / path.name)
        print(f"wrote {', '.join(sorted(p.name for p in generated.glob('*.pyi')))} into {STUBS}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
