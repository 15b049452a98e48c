"""The package's structure: no import cycles among its Python modules, and a docstring on
every public class and function."""

import ast
import inspect
from pathlib import Path

import rigidfem as rf

PACKAGE = Path(rf.__file__).resolve().parent


#: The Python package's layers, bottom to top: a module imports from its own layer or the layers below (and the
#: compiled core) only, lazily or not.
PYTHON_LAYERS = ["base", "model", "simulation", "analysis", "viz", "studies"]


def _modules() -> dict:
    """{"layer.module": path} of the package's modules (the top package's own files as "top.<name>")."""
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        out["top." + parts[0] if len(parts) == 1 else ".".join(parts)] = path
    return out


def _imports(name: str, path: Path, modules: dict) -> set:
    """The package's modules that module ``name`` imports (relative imports anywhere in the file, lazy ones too):
    "layer.module", or the layer itself for an import of its face (``from ..model import X``)."""
    layer = None if name.startswith("top.") else name.split(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):  # the compiled core only, by its absolute name
            assert all(a.name == "rigidfem._core" or not a.name.startswith("rigidfem") for a in node.names), name
            continue
        if isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").startswith("rigidfem"):
            raise AssertionError(f"{name}: imports {node.module} by its absolute name (relative imports in the package)")
        if not isinstance(node, ast.ImportFrom) or node.level == 0:
            continue
        if node.level == 1 and layer is not None:
            base = [layer]
        elif (node.level == 2 and layer is not None) or (node.level == 1 and layer is None):
            base = []
        else:
            raise AssertionError(f"{name}: an import from {node.level} levels up")
        target = base + (node.module.split(".") if node.module else [])
        if not target or target[0] == "_core":
            continue
        if len(target) == 1:  # from .layer import module, from . import module
            candidates = [f"{target[0]}.{a.name}" for a in node.names]
            known = [c for c in candidates if c in modules]
            found |= set(known) if known else {target[0]}
        else:
            found.add(".".join(target[:2]))
    return found


def _layer(module: str) -> int:
    head = module.split(".")[0]
    return len(PYTHON_LAYERS) if head == "top" else PYTHON_LAYERS.index(head)


def _cycle(graph: dict) -> list:
    """A cycle of ``graph`` (module -> imported modules) as a list of modules, or []."""
    state = dict.fromkeys(graph, 0)  # 0 unvisited, 1 on the current path, 2 done
    path = []

    def visit(node):
        state[node], _ = 1, path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if nxt not in state:
                continue
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


def test_python_layers_import_downwards_only_and_without_cycles():
    modules = _modules()
    assert {m.split(".")[0] for m in modules} == {"top", *PYTHON_LAYERS}, "a module outside the layers"
    graph = {name: _imports(name, path, modules) - {name} for name, path in modules.items()}
    upward = sorted((name, imported) for name, targets in graph.items() for imported in targets
                    if _layer(imported) > _layer(name))
    assert not upward, f"imports of a higher layer: {upward}"
    faces = {f"{layer}.__init__" for layer in PYTHON_LAYERS}
    assert not any(graph[name] & set(PYTHON_LAYERS) for name in modules if name.split(".")[0] in PYTHON_LAYERS
                   and name not in faces and name.split(".")[0] in graph[name]), "a module imports its own face"
    module_graph = {n: {t for t in g if t in modules} for n, g in graph.items()}
    assert not _cycle(module_graph), f"import cycle: {' -> '.join(_cycle(module_graph))}"
    assert "model.beams" in graph["model.model"] and "model.model" not in graph["model.beams"]


def test_the_simulation_and_the_analyses_are_split_by_topic():
    """simulate, its Result and SciPy's adapter are three files; statics, modes and what they share likewise."""
    sizes = {name: len(path.read_text(encoding="utf-8").splitlines()) for name, path in _modules().items()}
    for name in ("simulation.integration", "simulation.result", "simulation.scipy_ivp", "analysis.statics",
                 "analysis.modes", "analysis.operating_point"):
        assert name in sizes and sizes[name] < 500, (name, sizes.get(name))


def test_public_classes_and_functions_have_docstrings():
    missing = [name for name in rf.__all__
               if (inspect.isclass(obj := getattr(rf, name)) or (callable(obj) and not inspect.ismodule(obj)))
               and not (obj.__doc__ or "").strip()]
    assert not missing, f"public names without a docstring: {missing}"


# The C++ core's layers, bottom to top: a file includes headers of its own layer or below only.
CPP = PACKAGE.parents[1] / "cpp"
LAYERS = [
    {"errors", "transforms", "profiles", "laws", "dense_lu"},
    {"joint_motion", "loops", "force_elements", "coordinate_laws", "flows", "contact"},
    {"model"},
    {"system", "parameters"},                  # a compiled system, and its copies with other constants
    {"arms"},                                  # internal variables of the state (system level)
    {"kinematics", "constraints", "contact_forces"},
    {"lagrange", "recursive", "derivatives"},  # the formulations
    {"dynamics"},                              # the only place that chooses one
    {"error_measure", "sensitivities"},        # the outputs an error is measured on; the sensitivity equations
    {"integrators", "stepper", "newton_matrix", "gmres", "outputs", "timing", "auto_method", "newmark", "radau",
     "events"},
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

    from rigidfem import loops
    from rigidfem.analysis import operating_point

    table = rf._core._Model._loop_kinds()
    assert loops.KINDS == tuple(table) and operating_point._LOOP_ROWS == table
    documented = dict((k, int(r)) for k, r in re.findall(r'``"(\w+)"``\s+(\d+)', loops.__doc__))
    assert documented == table
    for kind, rows in table.items():  # each kind's rows as the compiled system counts them
        m = rf.Model(gravity=None)
        a = m.add_body("a", m.ground, rf.Joint.free(), mass=1.0, inertia=(1, 1, 1))
        if kind == "distance":
            m.add_loop_joint("loop0", kind, m.ground, a.point((1.0, 0, 0)), length=1.0)
        else:
            m.add_loop_joint("loop0", kind, m.ground, a)
        assert m.compile().nl == rows, kind
