"""One argument order and one list of options (docs/conventions.md).

A state is passed as (t, q, qd, qdd), t first, in every method of a System and every function that
evaluates the system at a state; analyses about an operating point take t by keyword; simulate takes
its integrator options by keyword from one table (``rigidfem.options``, read from the C++ core).
"""

import importlib.util
import inspect
import re
from pathlib import Path

import numpy as np
import pytest

import rigidfem as rf
from rigidfem import options

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def compiled_signatures() -> dict:
    """{method: parameter names after self} of the compiled System methods, from the stubs the bindings generate
    (scripts/stubs.py; tests/test_stubs.py holds them to the bindings)."""
    spec = importlib.util.spec_from_file_location("stubs", ROOT / "scripts" / "stubs.py")
    stubs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(stubs)
    return {key.split(".", 1)[1]: signatures[0][1:] for key, signatures in stubs.declared(stubs.STUBS).items()
            if key.startswith("__init__:_System.") and signatures}


def pendulum(prescribed: bool = False):
    """A double pendulum (spherical joint and a revolute), its second joint prescribed if asked."""
    m = rf.Model(gravity=(0, 0, -9.81))
    a = m.add_body("a", m.ground, rf.Joint.revolute("x"), mass=1.0, inertia=(0.1, 0.1, 0.02), com=(0, 0, -0.5))
    b = m.add_body("b", a, rf.Joint.revolute("y"), mass=0.5, inertia=(0.05, 0.05, 0.01), com=(0.1, 0, -0.4),
                   placement=rf.transform((0, 0, -1.0)))
    m.add_spring_damper("element0", b.point((0, 0, -0.8)), m.ground.point((0.3, 0.2, 0.0)), stiffness=50.0, length=1.5,
                        damping=0.3)
    if prescribed:
        m.prescribe(b, rf.motion.polynomial([0.1, 0.5]))
    return m.compile(), a, b


def test_every_compiled_method_takes_t_before_the_state():
    """The parameters of every compiled System method (read from the bindings' stubs): t, then q, qd, qdd."""
    signatures = compiled_signatures()
    assert {"forward_dynamics", "mass_matrix", "transform", "_position"} <= set(signatures)
    for name, parameters in signatures.items():
        state = [p for p in parameters if p in ("t", "q", "qd", "qdd", "y")]
        if "t" in state:
            assert state[0] == "t", (name, parameters)


def test_functions_about_an_operating_point_take_t_by_keyword():
    system, _, _ = pendulum()
    beam_model, handles = rf.samples.cantilever(elements=2)
    beam = handles["beam"]
    functions = [rf.modal_analysis, rf.linearize, rf.static_equilibrium, system.assemble, rf.plots.shape,
                 beam.centerline, beam.rates_at_rest]
    for f in functions:
        t = inspect.signature(f).parameters["t"]
        assert t.kind is inspect.Parameter.KEYWORD_ONLY, f.__name__
    for f in (system.position, system.velocity, system.transform):
        names = list(inspect.signature(f).parameters)
        assert names.index("t") < names.index("q"), f.__name__


def test_the_orders_of_version_0_1_are_refused():
    """Version 0.1 took the state first and t last (or left out): such calls now name t or miss an argument, and
    options by position are refused (0.1.0 had no users to migrate: CHANGELOG.md)."""
    system, a, b = pendulum()
    q, qd = np.array([0.3, -0.4]), np.array([1.0, 0.5])
    with pytest.raises(ValueError, match="^t: expected a finite time in s, got array"):
        system.kinetic_energy(q, qd, 0.0)
    for call in (lambda: system.mass_matrix(q), lambda: system.position(b.point((0, 0, -0.8)), q),
                 lambda: rf.modal_analysis(system, q, None, 0.0), lambda: rf.simulate(system, 0.1, "rk4", 1e-3, 1e-6)):
        with pytest.raises(TypeError):
            call()


def test_simulate_takes_the_options_of_the_table_and_names_an_unknown_one():
    system, _, _ = pendulum()
    q0 = np.array([0.3, -0.4])
    with pytest.raises(TypeError, match=r"unexpected options \['rtool'\].*'rtol'"):
        rf.simulate(system, 0.1, q0=q0, rtool=1e-8)
    # the defaults of the table are simulate's: the same run bit for bit when they are given
    for method in ("dopri5", "generalized_alpha", "radau5"):
        given = {name: o.default for name, o in rf.integrator_options(method).items() if name != "dt"}
        step = {"dt": 1e-3} if method == "generalized_alpha" else {}
        a = rf.simulate(system, 0.2, method, q0=q0, **step)
        b = rf.simulate(system, 0.2, method, q0=q0, **step, **given)
        np.testing.assert_array_equal(a.q, b.q)
        assert a.stats["steps"] == b.stats["steps"]
    # an option is read by the methods the table says: rho_inf changes generalized_alpha, not rk4
    base = rf.simulate(system, 0.2, "generalized_alpha", dt=1e-2, q0=q0).q
    assert np.abs(rf.simulate(system, 0.2, "generalized_alpha", dt=1e-2, q0=q0, rho_inf=0.3).q - base).max() > 1e-8
    rk4 = rf.simulate(system, 0.2, "rk4", dt=1e-2, q0=q0).q
    np.testing.assert_array_equal(rf.simulate(system, 0.2, "rk4", dt=1e-2, q0=q0, rho_inf=0.3).q, rk4)
    assert "rho_inf" in rf.integrator_options("generalized_alpha") and "rho_inf" not in rf.integrator_options("rk4")


def test_integrator_options_names_an_unknown_method():
    with pytest.raises(ValueError, match="method: expected one of"):
        rf.integrator_options("rk5")


def test_every_option_is_documented_once_in_simulate_and_on_the_site():
    """simulate's docstring lists each option once; the site's pages include the table written from
    rigidfem.options at build time (tests/test_docs.py checks the built page), never a copy of it."""
    doc = rf.simulate.__doc__
    for o in options.OPTIONS:
        assert len(re.findall(rf"^ +{o.name} : default", doc, flags=re.M)) == 1, o.name
    for page in ("conventions.md", "simulation.md"):
        text = (DOCS / page).read_text()
        assert "{include} _generated/options.md" in text and "| option | default |" not in text, page


def test_a_bad_t_of_the_new_order_is_named_t_not_read_as_the_old_order():
    """Found by scripts/fuzz.py: a vector t (of another size than nq, or with a vector where the old order
    had t) is the new order's bad t, and the ValueError names t."""
    system, a, b = pendulum()
    q, qd = np.zeros(2), np.zeros(2)
    for call in (lambda: system.dissipated_power(np.ones(3), q, qd), lambda: system.kinetic_energy(q, q, qd),
                 lambda: system.mass_matrix(np.ones(5), q), lambda: system.transform(b, np.ones(3), q),
                 lambda: system.position(b, [0.1, 0.2, 0.3], q), lambda: system.velocity(b, q, q, qd)):
        with pytest.raises(ValueError, match=r"^t: expected a finite time"):
            call()


def test_one_bad_option_is_named_before_a_pair_that_is_wrong_only_together():
    """Found by scripts/fuzz.py: with rtol = atol = 0 (wrong together) and max_steps = 0, the ValueError
    named atol; the options are checked one at a time first (C++ check_options)."""
    system, _, _ = pendulum()
    with pytest.raises(ValueError, match="^max_steps: expected a positive number of steps, got 0"):
        rf.simulate(system, 0.01, method="scipy:Radau", dt=0.01, rtol=0.0, atol=0.0, max_steps=0)
    with pytest.raises(ValueError, match="^atol: expected positive values when rtol is zero"):
        rf.simulate(system, 0.01, rtol=0.0, atol=0.0)


def _refusals(tree):
    """(line, message template) of every refusal a module makes: the first argument of ``_checks.refuse`` and
    of ResolveError, its f-string's fields written {}."""
    import ast

    def template(node):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            return node.value
        if isinstance(node, ast.JoinedStr):
            return "".join(v.value if isinstance(v, ast.Constant) else "{}" for v in node.values)
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):  # "..." + "..."
            left, right = template(node.left), template(node.right)
            return None if left is None or right is None else left + right
        return None

    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and node.args and (
                (isinstance(node.func, ast.Attribute) and node.func.attr == "refuse") or
                (isinstance(node.func, ast.Name) and node.func.id == "ResolveError")):
            yield node.lineno, template(node.args[0])


def test_every_refusal_of_the_python_layer_is_one_form_through_one_function():
    """The Python layer refuses through ``_checks.refuse`` only (no module raises a ValueError of its own; a
    ResolveError carries the runs too), and every message has the contract's form, "<argument>: expected ...",
    as the core's do: checked on the source, so that a new refusal is held to it without a test of its own."""
    import ast

    argument = r"([A-Za-z_{][\w.{}]*(\[[^\]]*\])?)"  # a name, a field ({name}, frame_{name}), an element (cases[0])
    form = re.compile(rf"^{argument}(, ?{argument})*: expected ")
    own, bad, count = [], [], 0
    for path in sorted((ROOT / "python" / "rigidfem").rglob("*.py")):
        source = path.read_text()
        where = path.relative_to(ROOT)
        if path.name != "_checks.py":
            own += [f"{where}:{n}" for n, line in enumerate(source.splitlines(), 1) if "raise ValueError(" in line]
        for line, message in _refusals(ast.parse(source)):
            count += 1
            if message is None or not form.match(message):
                bad.append(f"{where}:{line}: {message!r}")
    assert not own, f"ValueErrors raised outside _checks.refuse: {own}"
    assert count > 150, count  # (the scan sees them)
    assert not bad, "refusals not of the form '<argument>: expected ...':\n" + "\n".join(bad)


def test_every_builder_takes_the_name_of_what_it_adds_first():
    """Every Model builder that adds something named (``add_*`` returning a handle with ``.name``, but not the
    coordinate's own laws, which the coordinate names) takes ``name`` first, required, and refuses a number, None,
    "" and a name given already, naming ``name``."""
    named = [n for n in dir(rf.Model) if n.startswith("add_") and n not in ("add_generalized_force", "add_maxwell_arm")]
    assert len(named) == 15, named  # bodies, beams and bases; loads, loops, actuators, elements, laws; shapes,
    # contacts; sheaves
    for n in named:
        first = list(inspect.signature(getattr(rf.Model, n)).parameters.values())[1]
        assert (first.name, first.default, first.kind) == ("name", inspect.Parameter.empty,
                                                          inspect.Parameter.POSITIONAL_OR_KEYWORD), n
    model = rf.Model()
    body = model.add_body("b", model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1))
    model.add_force("push", body, (1.0, 0.0, 0.0))
    calls = {"add_body": lambda nm: model.add_body(nm, model.ground, rf.Joint.revolute("z"), 1.0, (1, 1, 1)),
             "add_force": lambda nm: model.add_force(nm, body, (1.0, 0.0, 0.0)),
             "add_torque": lambda nm: model.add_torque(nm, body, (1.0, 0.0, 0.0)),
             "add_rope": lambda nm: model.add_rope(nm, model.ground, body.point((1, 0, 0)), EA=1e3, length=1.0),
             "add_joint_law": lambda nm: model.add_joint_law(nm, body, rf.laws.Friction()),
             "add_sheave": lambda nm: model.add_sheave(nm, *ropes, mu=0.2, wrap=3.0)}
    ropes = [model.add_rope(f"span {k}", model.ground, body.point((1, 0, 0)), EA=1e3, length=1.0) for k in (1, 2)]
    for n, call in calls.items():
        for bad in (3, None, "", "push"):
            with pytest.raises(ValueError, match="^name: expected"):
                call(bad)
