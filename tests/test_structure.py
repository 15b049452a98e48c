"""The package's structure: no import cycles among its Python modules, and a docstring on
every public class and function."""

import ast
import inspect
from pathlib import Path

import rigidfem as rf

PACKAGE = Path(rf.__file__).resolve().parent


def _imports(path: Path, modules: set) -> set:
    """The package's modules that ``path`` imports relatively (``from . import x``,
    ``from .x import y``, ``from .x.y import z``), anywhere in the file (lazy imports too);
    a name that is not a module (``from . import __version__``) is the package itself."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not isinstance(node, ast.ImportFrom) or node.level != 1:
            continue
        if node.module:
            found.add(node.module.split(".")[0])
        else:
            found |= {a.name if a.name in modules else "__init__" for a in node.names}
    return found & modules


def _cycle(graph: dict) -> list:
    """A cycle of ``graph`` (module -> imported modules) as a list of modules, or []."""
    state = dict.fromkeys(graph, 0)  # 0 unvisited, 1 on the current path, 2 done
    path = []

    def visit(node):
        state[node], _ = 1, path.append(node)
        for nxt in sorted(graph[node]):
            if state[nxt] == 1:
                return path[path.index(nxt):] + [nxt]
            if state[nxt] == 0 and (found := visit(nxt)):
                return found
        state[node], _ = 2, path.pop()
        return []

    for node in sorted(graph):
        if state[node] == 0 and (found := visit(node)):
            return found
    return []


def test_python_modules_import_without_cycles():
    files = {p.stem: p for p in PACKAGE.glob("*.py")}
    modules = set(files) | {"_core"}  # the compiled core imports nothing of the package
    graph = {name: _imports(path, modules) - {name} for name, path in files.items()}
    graph["_core"] = set()
    # The package imports its submodules; a submodule importing the package back is a cycle too.
    for name in graph:
        if name != "__init__":
            assert "__init__" not in graph[name], f"{name}.py imports names from the package's __init__"
    graph["__init__"] = set()  # the entry point: its edges close no cycle once no submodule imports it
    assert not _cycle(graph), f"import cycle: {' -> '.join(_cycle(graph))}"
    assert "beams" in graph["model"] and "model" not in graph["beams"]  # the cycle this test was written for


def test_public_classes_and_functions_have_docstrings():
    missing = [name for name in rf.__all__
               if (inspect.isclass(obj := getattr(rf, name)) or (callable(obj) and not inspect.ismodule(obj)))
               and not (obj.__doc__ or "").strip()]
    assert not missing, f"public names without a docstring: {missing}"


# The C++ core's layers, bottom to top: a file includes headers of its own layer or below only.
CPP = PACKAGE.parents[1] / "cpp"
LAYERS = [
    {"errors", "transforms", "profiles", "laws"},
    {"joint_motion", "loops", "force_elements", "coordinate_laws", "flows"},
    {"model"},
    {"system", "parameters"},                  # a compiled system, and its copies with other constants
    {"arms"},                                  # internal variables of the state (system level)
    {"kinematics", "constraints"},
    {"lagrange", "recursive", "derivatives"},  # the formulations
    {"dynamics"},                              # the only place that chooses one
    {"error_measure", "sensitivities"},        # the outputs an error is measured on; the sensitivity equations
    {"integrators", "stepper", "newton_matrix", "gmres", "outputs", "timing", "auto_method", "newmark", "radau"},
    {"adjoint"},                               # the methods' transposes over whole runs
]
RANK = {name: k for k, layer in enumerate(LAYERS) for name in layer}
# Sources named after their family rather than a header.
RANK.update({"integrate": RANK["stepper"], "runge_kutta": RANK["stepper"], "implicit_rk": RANK["stepper"],
             "adjoint_terms": RANK["adjoint"]})


def _cpp_includes(path: Path) -> set:
    import re

    return set(re.findall(r'#include "rigidfem/(\w+)\.hpp"', path.read_text(encoding="utf-8")))


def test_cpp_layers_include_downwards_only():
    files = sorted((CPP / "include" / "rigidfem").glob("*.hpp")) + sorted((CPP / "src").glob("*.cpp"))
    assert {p.stem for p in files} <= set(RANK), f"files without a layer: {({p.stem for p in files}) - set(RANK)}"
    upward = [(p.name, inc) for p in files for inc in _cpp_includes(p) if RANK[inc] > RANK[p.stem]]
    assert not upward, f"includes of a higher layer: {upward}"
    headers = {p.stem: _cpp_includes(p) - {p.stem} for p in (CPP / "include" / "rigidfem").glob("*.hpp")}
    assert not _cycle(headers), f"include cycle: {' -> '.join(_cycle(headers))}"


def test_only_the_dynamics_layer_chooses_a_formulation():
    """The engine dispatch (Algorithm::Recursive / Lagrange) lives in dynamics.cpp; system.cpp sets the
    algorithm at compile time and recursive.cpp only asserts it."""
    choosing = [p.name for p in (CPP / "src").glob("*.cpp") if "Algorithm::" in p.read_text(encoding="utf-8")]
    assert set(choosing) <= {"dynamics.cpp", "system.cpp", "recursive.cpp"}, choosing


def test_trajectories_are_row_major_for_the_batch_outputs():
    """A Result's q and q̇ are C-contiguous (N, nq) arrays: the batch outputs (energies, points) read
    them through Eigen::Ref<const RowMatX> in place, without a copy."""
    model, h = rf.samples.pendulum()
    res = rf.simulate(model.compile(), 0.1, method="rk4", dt=0.01, q0=[0.3])
    assert res.q.flags["C_CONTIGUOUS"] and res.qd.flags["C_CONTIGUOUS"] and res.q.shape == (11, 1)
    assert res.position(h["tip"]).shape == (11, 3) and res.energy.shape == (11,)


def test_one_table_of_loop_kinds():
    """Python's loop kinds and row counts are the C++ table's (constraints.cpp, through the binding), and the
    documented table of rigidfem.loops says the same."""
    import re

    from rigidfem import analysis, loops

    table = rf._core._Model._loop_kinds()
    assert loops.KINDS == tuple(table) and analysis._LOOP_ROWS == table
    documented = dict((k, int(r)) for k, r in re.findall(r'``"(\w+)"``\s+(\d+)', loops.__doc__))
    assert documented == table
    for kind, rows in table.items():  # each kind's rows as the compiled system counts them
        m = rf.Model(gravity=None)
        a = m.add_body("a", m.ground, rf.Joint.free(), mass=1.0, inertia=(1, 1, 1))
        if kind == "distance":
            m.add_loop_joint(kind, m.ground, a.point((1.0, 0, 0)), length=1.0)
        else:
            m.add_loop_joint(kind, m.ground, a)
        assert m.compile().nl == rows, kind
