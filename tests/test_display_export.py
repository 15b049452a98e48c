"""Notebook displays (``_repr_html_``) and export (DataFrame, CSV, NPZ, the modes' table).

The expected contents are the model's own names and the arrays of the objects displayed,
read from the objects here: the displays and tables must carry them unchanged.
"""

import html

import numpy as np
import pytest

import rigidfem as rf
from rigidfem import display


def crane():
    """A hub turning about z (prescribed), a beam on it, a payload on a revolute joint: names
    with dots and an ampersand to escape."""
    model, h = rf.samples.kane_beam(elements=3)
    payload = model.add_body("pay&load", h["beam"].rfes[-1], rf.Joint.revolute("y", stiffness=5.0), mass=1.0,
                             inertia=(0.1, 0.1, 0.1), placement=rf.transform((1.0, 0, 0)))
    return model, h["beam"], payload


def test_model_and_system_html_list_every_body_coordinate_and_joint():
    model, beam, payload = crane()
    system = model.compile()
    for page in (model._repr_html_(), system._repr_html_()):
        for name in system.coordinate_names + system.body_names:
            assert html.escape(name) in page
        assert "pay&load" not in page and "pay&amp;load" in page  # escaped
        assert "revolute y" in page and "revolute z" in page and "fixed" in page  # payload, rfes; rfe0
        assert "beam (4 rfes)" in page
        assert f"free coordinates (nq): {system.nq}" in page and f"prescribed coordinates: {system.np}" in page


def test_long_tables_are_cut_with_the_number_left_out():
    model, _ = rf.samples.cantilever(elements=30)
    page = rf.Model._repr_html_(model)
    n = model.nbodies - display.MAX_ROWS
    assert f"… {n} more bodies" in page
    assert "beam.rfe19<" in page and "beam.rfe20<" not in page


def test_a_model_that_does_not_compile_says_why():
    page = rf.Model()._repr_html_()
    assert "does not compile" in page and "empty model" in page


def test_loops_and_force_elements_are_counted():
    model = rf.Model(gravity=None)
    a = model.add_body("a", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1))
    b = model.add_body("b", model.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1, 1, 1),
                       placement=rf.transform((1.0, 0, 0)))
    model.add_spring_damper("element0", a.point((0.5, 0, 0)), b.point((0.5, 0, 0)), stiffness=10.0, length=1.0)
    page = model.compile()._repr_html_()
    assert "force elements: 1" in page and "loops: 0" in page


@pytest.fixture(scope="module")
def run():
    model, beam, _ = crane()
    system = model.compile()
    res = rf.simulate(system, 0.2, t_eval=np.linspace(0.0, 0.2, 11), q0=0.01 * np.ones(system.nq))
    return system, beam, res


def test_result_html_shows_the_method_and_counters(run):
    _, _, res = run
    page = res._repr_html_()
    s = res.stats
    for text in ("dop853", f"outputs: {len(res.t)}", f"steps: {s['steps']}", f"rejected steps: {s['rejected_steps']}",
                 f"rhs evaluations: {s['rhs_evaluations']}", "interrupted: False"):
        assert text in page


def test_dataframe_columns_and_values_are_the_result_arrays(run):
    system, beam, res = run
    df = res.to_dataframe(points={"tip": beam.tip})
    names = system.coordinate_names
    assert list(df.columns) == names + [n + ".dot" for n in names] + ["tip.x", "tip.y", "tip.z"]
    assert df.index.name == "t"
    np.testing.assert_array_equal(df.index.to_numpy(), res.t)
    np.testing.assert_array_equal(df[names].to_numpy(), res.q)
    np.testing.assert_array_equal(df[[n + ".dot" for n in names]].to_numpy(), res.qd)
    tip = np.array([system.position(beam.tip, t, q) for t, q in zip(res.t, res.q)])
    np.testing.assert_allclose(df[["tip.x", "tip.y", "tip.z"]].to_numpy(), tip, rtol=0, atol=1e-13)


def test_csv_round_trips_through_numpy(run, tmp_path):
    system, beam, res = run
    path = res.to_csv(tmp_path / "run.csv", points={"tip": beam.tip})
    with open(path) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    assert header == ["t", *res.to_dataframe(points={"tip": beam.tip}).columns]
    np.testing.assert_array_equal(data[:, 0], res.t)
    np.testing.assert_array_equal(data[:, 1:1 + system.nq], res.q)
    np.testing.assert_array_equal(data[:, 1 + system.nq:1 + 2 * system.nq], res.qd)


def test_npz_round_trips(run, tmp_path):
    system, _, res = run
    back = rf.load_npz(res.to_npz(tmp_path / "run.npz"), system)
    for name in ("t", "q", "qd"):
        np.testing.assert_array_equal(getattr(back, name), getattr(res, name))
    assert back.method == res.method and back.interrupted == res.interrupted
    assert back.stats.keys() == res.stats.keys()
    np.testing.assert_array_equal(list(back.stats.values()), list(res.stats.values()))  # NaN == NaN here
    np.testing.assert_array_equal(back.energy, res.energy)  # the loaded result computes with the system
    bare = rf.load_npz(tmp_path / "run.npz")
    np.testing.assert_array_equal(bare.q, res.q)
    assert bare.to_dataframe().equals(res.to_dataframe())  # the coordinates' table needs only the saved names
    with pytest.raises(ValueError, match=r"rigidfem.load_npz\(path, system\) gives it"):
        bare.energy
    other = rf.samples.cantilever(elements=2)[0].compile()
    with pytest.raises(ValueError, match="system: expected a System with the coordinates"):
        rf.load_npz(tmp_path / "run.npz", other)


def test_bad_points_are_value_errors_naming_the_argument(run, tmp_path):
    _, beam, res = run
    with pytest.raises(ValueError, match="points: expected None or a dict"):
        res.to_dataframe(points=[beam.tip])
    other = rf.samples.cantilever(elements=2)[1]["beam"]
    with pytest.raises(ValueError, match="point: expected"):
        res.to_dataframe(points={"tip": other.tip})
    with pytest.raises(ValueError, match="without ','"):
        res.to_csv(tmp_path / "x.csv", points={"a,b": beam.tip})


def test_missing_pandas_is_an_import_error_saying_how_to_install(run, monkeypatch):
    import builtins

    real = builtins.__import__

    def no_pandas(name, *args, **kwargs):
        if name == "pandas":
            raise ImportError("No module named 'pandas'")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_pandas)
    with pytest.raises(ImportError, match="pip install pandas"):
        run[2].to_dataframe()


def test_modes_table_and_html_carry_the_frequencies():
    model, _ = rf.samples.cantilever(elements=25)
    modes = rf.modal_analysis(model.compile())
    page = modes._repr_html_()
    shown = modes.frequencies_hz[:display.MAX_ROWS]
    for f, w in zip(shown, modes.omega):
        assert f"<td>{f:.6g}</td>" in page and f"<td>{w:.6g}</td>" in page
    assert f"… {len(modes.omega) - display.MAX_ROWS} more modes" in page
    rows = modes.table()
    assert [r["mode"] for r in rows] == list(range(1, len(modes.omega) + 1))
    np.testing.assert_array_equal([r["f (Hz)"] for r in rows], modes.frequencies_hz)
    df = modes.to_dataframe()
    assert list(df.columns) == ["omega (rad/s)", "f (Hz)", "zeta"]
    np.testing.assert_array_equal(df["omega (rad/s)"].to_numpy(), modes.omega)
    np.testing.assert_array_equal(df["zeta"].to_numpy(), modes.damping_ratios)


def test_the_documented_section_runs_as_copied(tmp_path, monkeypatch):
    """The "Notebook displays, export and linearisation" code block of docs/flexible_links.md, run
    standalone: it writes the files it says."""
    import pathlib

    text = (pathlib.Path(__file__).parent.parent / "docs" / "flexible_links.md").read_text()
    section = text[text.index("## Notebook displays, export and linearisation"):]
    block = section.split("```python\n", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(tmp_path)
    exec(compile(block, "flexible_links.md", "exec"), {})
    assert (tmp_path / "run.csv").exists() and (tmp_path / "run.npz").exists()
