"""The typing stubs of the compiled core are the bindings': scripts/stubs.py generates them with pybind11-stubgen,
and this test fails when a binding is added, removed or renamed without them (python scripts/stubs.py rewrites
them)."""

import importlib.util
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _stubs_module():
    spec = importlib.util.spec_from_file_location("stubs", ROOT / "scripts" / "stubs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_committed_stubs_declare_what_the_bindings_bind():
    stubs = _stubs_module()
    with tempfile.TemporaryDirectory() as tmp:
        generated = stubs.generate(Path(tmp))
        declared = stubs.declared(generated)
        assert "__init__:_System.forward_dynamics" in declared and "__init__:Profile" in declared  # it read them
        lines = stubs.differences(stubs.STUBS, generated)
    assert not lines, "the stubs drift from the bindings (python scripts/stubs.py rewrites them):\n" + "\n".join(lines)


def test_the_check_finds_a_drift():
    stubs = _stubs_module()
    with tempfile.TemporaryDirectory() as tmp:
        generated = stubs.generate(Path(tmp) / "a")
        edited = Path(tmp) / "b"
        edited.mkdir()
        for path in generated.glob("*.pyi"):
            text = path.read_text(encoding="utf-8")
            if path.name == "__init__.pyi":
                text = text.replace("def _make_profile(", "def _made_profile(")
            (edited / path.name).write_text(text, encoding="utf-8")
        lines = stubs.differences(edited, generated)
    assert any("missing from the stubs: __init__:_make_profile" in line for line in lines), lines
    assert any("not bound: __init__:_made_profile" in line for line in lines), lines
