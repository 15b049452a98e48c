"""The maintainers' benchmarks in the checkout's benchmarks/ (not part of the package): the
scaling studies' tables and the ``python -m benchmarks`` runner. Moved here from
test_study.py with the studies (formerly ``rigidfem.study.dynamics_scaling`` and
``rigidfem.study.implicit_step_scaling``)."""

import csv
import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import scaling  # noqa: E402
from benchmarks.__main__ import main  # noqa: E402


def test_dynamics_scaling_table():
    """The scaling study's structure (its numbers are benchmarks, reported, not asserted)."""
    table = scaling.dynamics_scaling(elements=(20, 40, 80), lagrange_up_to=40)
    assert [r["nq"] for r in table.rows] == [60, 120, 240] and "lagrange_s" not in table.rows[-1]
    assert all(r["recursive_s"] > 0 for r in table.rows)
    assert np.isfinite(table.rows[0]["recursive_exponent"]) and np.isfinite(table.rows[0]["lagrange_exponent"])


def test_implicit_step_scaling_table():
    """The implicit-step study's structure; its Newton iterations per step stay few at h = T1/50."""
    table = scaling.implicit_step_scaling(elements=(20, 40), tangent_up_to=20, steps=10)
    assert [r["nq"] for r in table.rows] == [60, 120] and "tangent_s_per_step" not in table.rows[-1]
    assert all(r["spring_s_per_step"] > 0 and 1 <= r["spring_iterations_per_step"] <= 10 for r in table.rows)
    assert np.isfinite(table.rows[0]["spring_exponent"])


def test_runner_writes_and_prints_the_scaling_tables(tmp_path, capsys):
    assert main(["scaling", "--quick", "--output", str(tmp_path)]) == 0
    for name in ("dynamics_scaling", "implicit_step_scaling"):
        with open(tmp_path / f"{name}.csv") as f:
            assert [int(r["m"]) for r in csv.DictReader(f)] == list(scaling.QUICK_ELEMENTS)
    out = capsys.readouterr().out
    assert "machine:" in out and "| m | nq | recursive_s |" in out and "| m | nq | spring_s_per_step |" in out


def test_runner_writes_each_table_as_a_page_with_its_provenance(tmp_path):
    """Each table is also a markdown page (title, command, date, processor, versions, load at start and end, the
    table, the CSV linked): what docs/benchmarks/ holds for the site."""
    import rigidfem as rf

    assert main(["scaling", "--quick", "--output", str(tmp_path)]) == 0
    page = (tmp_path / "dynamics_scaling.md").read_text(encoding="utf-8")
    assert page.startswith("# ") and "`python -m benchmarks scaling --quick --output" in page
    assert f"rigidfem {rf.__version__} (core build {rf._core.build})" in page and "load average" in page
    assert "at the end" in page
    assert "[dynamics_scaling.csv](dynamics_scaling.csv)" in page
    with open(tmp_path / "dynamics_scaling.csv") as f:
        rows = list(csv.DictReader(f))
    table = [line for line in page.splitlines() if line.startswith("| ")]
    assert len(table) == 1 + len(rows) and table[0].startswith("| m | nq | recursive_s |")


def test_the_sites_benchmark_pages_are_written_by_the_benchmarks():
    """docs/benchmarks/: every page besides the index is a benchmark's output, with its CSV beside it."""
    folder = Path(__file__).resolve().parents[1] / "docs" / "benchmarks"
    pages = sorted(p for p in folder.glob("*.md") if p.name != "index.md")
    assert pages
    for page in pages:
        text = page.read_text(encoding="utf-8")
        assert "Written by `python -m benchmarks " in text and " UTC: " in text, page.name
        assert (folder / f"{page.stem}.csv").exists(), page.name


def test_the_guides_include_the_benchmark_pages_from_their_provenance_line():
    """A guide that includes a benchmark's page skips its heading, description and CSV link (:start-line: N) and
    starts at the "Written by" line, so that the table shows with its command, date, machine and load."""
    import re

    docs = Path(__file__).resolve().parents[1] / "docs"
    found = 0
    for guide in sorted(docs.glob("*.md")):
        text = guide.read_text(encoding="utf-8")
        for name, start in re.findall(r"\{include\} benchmarks/(\w+)\.md\n\s*:start-line: (\d+)", text):
            lines = (docs / "benchmarks" / f"{name}.md").read_text(encoding="utf-8").splitlines()
            assert lines[int(start)].startswith("Written by `python -m benchmarks "), (guide.name, name, start)
            found += 1
    assert found >= 20


@pytest.mark.filterwarnings("ignore")  # a LocalCluster's start-up notices (ports, dashboards)
def test_sweep_scaling_table():
    """The sweep benchmark's structure: four executors, all giving the serial results (asserted
    inside), speed-up 1 for serial."""
    pytest.importorskip("distributed")
    from benchmarks import sweep

    table = sweep.scaling(spins=(4.0, 6.0), elements=4, rounds=1, tiny=10)
    assert [r["executor"] for r in table.rows][0] == "serial (1 thread)" and len(table.rows) == 4
    assert table.rows[0]["speed_up"] == 1.0 and all(r["wall_time_s"] > 0 for r in table.rows)
    assert table.rows[-1]["startup_s"] > 0


def test_implicit_step_breakdown_table():
    """The implicit-step breakdown's structure: its columns and positive parts (its timings are the
    benchmark's to print, not the test's to bound: a ratio of two timings failed on a loaded machine)."""
    from benchmarks import implicit_step

    table = implicit_step.step_breakdown(elements=(10,), t_end=0.5)
    row = table.rows[0]
    assert row["nq"] == 10 and row["iterations_per_step"] >= 1
    assert all(row[k] > 0 for k in ("residual_s", "lu_solve_s", "tangent_s", "lu_factor_s", "floor_s"))
    assert np.isfinite(row["step_over_floor"]) and row["step_over_floor"] > 0


def test_kane_peers_models_agree():
    """Kane's spin-up beam (m = 4, 20 s) rebuilt in Exudyn and MuJoCo: their tip histories in
    the hub frame agree with rigidfem's within 1e-6 m (RK4 at a quarter of its stability
    limit, flywheel hub) and 2e-5 m (Exudyn's generalised-α at h = 1.56 ms, constraint hub:
    its own O(h²) error, ~5e-6 m); the benchmark's forward kinematics is rigidfem's."""
    pytest.importorskip("exudyn")
    pytest.importorskip("mujoco")
    from benchmarks import kane_peers as kp
    from rigidfem import simulate

    scene = kp.kane(4)
    r = simulate(scene.system, kp.T_END, method="dopri5", rtol=1e-10, atol=1e-12, t_eval=scene.t_eval)
    assert np.array_equal(kp.RigidfemKane(scene).run("dopri5", "rtol", 1e-10), r.q)
    tip = kp.tip_in_hub(scene, r.q)
    assert np.allclose(r.position(scene.tip, frame=scene.hub), tip, rtol=0, atol=1e-12)
    assert np.max(np.abs(tip[:, 1])) > 0.5  # the beam does deflect
    h = kp._divide(0.25 * 2.785 / scene.omega_max)
    exudyn, mujoco = kp.ExudynKane(scene), kp.MujocoKane(scene)
    for name, q, tol in [("Exudyn RK44", exudyn.run("RK44", "dt", h), 1e-6),
                         ("Exudyn GeneralizedAlpha", exudyn.run("GeneralizedAlpha", "dt", kp.INTERVAL / 64), 2e-5),
                         ("MuJoCo RK4", mujoco.run("RK4", "dt", h), 1e-6)]:
        error = np.max(np.linalg.norm(kp.tip_in_hub(scene, q) - tip, axis=1))
        assert error < tol, f"{name}: tip differs from rigidfem's by {error:.3g} m"


def test_loop_peers_models_agree():
    """The closed loops of loop_peers rebuilt in Exudyn and MuJoCo: on a short run of the slider-crank
    (m = 2, 0.1 s) and of the Bricard linkage (0.5 s) their points agree with rigidfem's within 1e-5
    of the point's motion amplitude (Exudyn's generalised-α and MuJoCo's RK4 at moderate steps;
    measured 4e-8 to 4e-7), rigidfem and Exudyn keep the loops closed to round-off and MuJoCo (soft
    constraints) within 1e-6 m, and MuJoCo's crank servo follows the prescribed angle."""
    pytest.importorskip("exudyn")
    pytest.importorskip("mujoco")
    from benchmarks import loop_peers as lp

    for scene in (lp.slider_crank(2, outputs=21, t_end=0.1), lp.bricard(outputs=11, t_end=0.5)):
        runners = lp.runners_for(scene)
        reference = runners["rigidfem"].run("dopri5", "rtol", 1e-10)
        p = scene.positions(reference)
        scene.amplitude = float(np.max(np.linalg.norm(p - p[0], axis=1)))
        assert scene.amplitude > 0.05 and scene.closure(reference) < 1e-12
        for code, method, divisions, closure in (("Exudyn", "GeneralizedAlpha", 64, 1e-10),
                                                 ("MuJoCo", "RK4", 16, 1e-6)):
            Q = runners[code].run(method, "dt", scene.interval / divisions)
            assert lp.error(scene, Q, p) < 1e-5, f"{scene.name}, {code}: {lp.error(scene, Q, p):.3g}"
            assert scene.closure(Q) < closure, f"{scene.name}, {code}: closure {scene.closure(Q):.3g}"
            if scene.drive is not None:  # the crank on θ(t): Exudyn's constraint, MuJoCo's servo (5e-9 rad)
                assert scene.drive_error(Q) < 1e-7


def test_sweep_peers_structure():
    """sweep_peers on a tiny case (m = 4, 3 spin rates, a tip error of 1e-3 m, one round, no Dask):
    each code's setting chosen where it reaches the error at the lowest and highest Ω, MuJoCo's
    per-rollout control array driving the hub exactly as kane_peers' callback, every executor of a
    code giving the same results and each peer's tips agreeing with rigidfem's per Ω (asserted
    inside), a timing row per executor (its numbers are the benchmark's, not asserted)."""
    pytest.importorskip("exudyn")
    pytest.importorskip("mujoco")
    from benchmarks import sweep_peers as sp

    tables = sp.measure(4, (4.0, 7.5, 11.0), rounds=1, dask=False, target=1e-3, log=lambda *_: None)
    chosen = [r for r in tables["settings"].rows if r["chosen"] == "yes"]
    assert sorted({r["code"] for r in chosen}) == ["Exudyn", "MuJoCo", "rigidfem"]
    assert len(chosen) == 6 and all(r["tip_rms_error_m"] <= 1e-3 for r in chosen)
    assert tables["settings"].rows[-1]["max_m"] < 1e-9  # rollout's control array = the callback
    rows = tables["timing"].rows
    assert len(rows) == 9 and all(r["runs"] == 3 and r["wall_time_s"] > 0 for r in rows)
    assert min(r["time_over_rigidfem_best"] for r in rows) == 1.0 and rows[0]["speed_up_over_serial"] == 1.0
    assert [r["omega"] for r in tables["agreement"].rows] == [4.0, 7.5, 11.0]
    assert all(r["MuJoCo_vs_rigidfem_rms_m"] < 2e-3 and r["Exudyn_vs_rigidfem_rms_m"] < 2e-3
               for r in tables["agreement"].rows)


def test_strip_peers_models_agree():
    """The whippy strip of strip_peers (m = 4, 0.5 s) in its five models: the section read from the
    System is the strip's; Exudyn's KinematicTree and MuJoCo's chain (RK4 at interval/64) give
    rigidfem's tip within 1e-9 m (measured 1.6e-11 m), by the benchmark's forward kinematics,
    itself rigidfem's; Exudyn's ANCF cable, another discretisation, is within 1e-2 m (4.4e-3 m);
    MuJoCo's flex rod runs and bends (its clamp's first-order error puts it far off at m = 4)."""
    pytest.importorskip("exudyn")
    pytest.importorskip("mujoco")
    from benchmarks import strip_peers as sp
    from rigidfem import simulate

    s = sp.whippy_strip(4)
    sec = s.section
    assert np.allclose([sec.length, sec.E, sec.width, sec.thickness, sec.rhoA], [1.0, 2.1e11, 0.02, 0.002, 7850 * 4e-5],
                       rtol=1e-9)
    runners = {code: cls(s) for code, cls in sp.RUNNERS.items()}
    t_end = 0.5
    q = runners["rigidfem"].run("radau5", "rtol", 1e-11, t_end=t_end)
    r = simulate(s.system, t_end, method="radau5", rtol=1e-11, atol=1e-13, t_eval=s.t_eval[:101])
    assert np.array_equal(q, r.q)
    tip = sp.tip_position(s, q)
    assert np.allclose(r.position(s.scene.tip), tip, rtol=0, atol=1e-12)
    assert tip[:, 1].min() < -0.2  # the strip does swing down
    for code, method, tol in [("Exudyn", "RK44", 1e-9), ("MuJoCo", "RK4", 1e-9), ("Exudyn ANCF", "GeneralizedAlpha", 1e-2)]:
        error = sp.max_error(runners[code].tip(runners[code].run(method, "dt", s.interval / 64, t_end=t_end)), tip)
        assert error < tol, f"{code} {method}: tip differs from rigidfem's by {error:.3g} m"
    flex = runners["MuJoCo flex"]
    bent = flex.tip(flex.run("RK4", "dt", s.interval / 64, t_end=t_end))
    assert bent.shape == tip.shape and np.all(np.isfinite(bent)) and bent[:, 1].min() < -0.2


def test_crane_peers_models_agree():
    """The crane of crane_peers on a short run (0.5 s): the welded bodies merged into one-axis links
    keep the chain's mass; Exudyn's KinematicTree (the base on coordinate constraints, the rope a
    symbolic spring law) and MuJoCo's MJCF (servoed base, tendon rope set in the callback) give
    rigidfem's payload within 1e-7 m and 5e-7 m (measured 2.2e-8 m, generalised-α's own error at this
    step, and 1.4e-7 m: MuJoCo's servos hold the base within 2.5e-9 rad of its profiles, from the
    start), Exudyn's base follows its profiles to round-off and MuJoCo's servo within 1e-8."""
    pytest.importorskip("exudyn")
    pytest.importorskip("mujoco")
    from benchmarks import crane_peers as cp

    scene = cp.crane(t_end=0.5, outputs=11)
    tree, _ = cp.single_axis_tree(cp.peer_chain(scene))
    assert np.isclose(sum(t["mass"] for t in tree), sum(link.mass for link in scene.chain.links), rtol=1e-12)
    runners = cp.runners_for(scene)
    p = runners["rigidfem"].reference(1e-10)
    assert np.ptp(p[:, 1]) > 3e-4  # the payload starts to swing sideways with the roll
    for code, method, options in (("Exudyn", "GeneralizedAlpha", {"newton": cp.TIGHT_NEWTON}), ("MuJoCo", "RK4", {})):
        Q = runners[code].run(method, "dt", scene.interval / 128, **options)
        distance = float(np.max(np.linalg.norm(Q - p, axis=1)))
        limit = 5e-7 if code == "MuJoCo" else 1e-7
        assert distance < limit, f"{code}: payload differs from rigidfem's by {distance:.3g} m"
        scene.amplitude = 1.0
        assert cp.base_error(scene, runners[code]) < (1e-8 if code == "MuJoCo" else 1e-12)


def test_size_peers_models_agree():
    """size_peers' three identical chains on a small strip (m = 8, 0.1 s): Exudyn's chain in redundant
    coordinates (sparse solver) gives rigidfem's tip within 1e-8 m at interval/64 (3.9 µs) (measured 5e-10 m,
    generalised-α's and TrapezoidalIndex2's own errors), MuJoCo's chain built by MjSpec within 1e-11 m
    by RK4 (2e-13 m) and equals the MJCF chain of strip_peers (the same accelerations); verify passes;
    the sweep's rows reach the thresholds in order."""
    pytest.importorskip("exudyn")
    pytest.importorskip("mujoco")
    from benchmarks import size_peers as zp
    from benchmarks.strip_peers import MujocoChain

    s = zp.size_strip(8, t_end=0.1)
    assert len(s.t_eval) == 401 and s.omega_max > 1e3
    runners = zp.runners_for(s)
    assert set(runners) == {"rigidfem", "Exudyn", "MuJoCo"}
    tip = runners["rigidfem"].tip(runners["rigidfem"].run("radau5", "rtol", 1e-11))
    assert tip[:, 1].min() < -0.05  # it falls
    for code, method, tol in [("Exudyn", "GeneralizedAlpha", 1e-8), ("Exudyn", "TrapezoidalIndex2", 1e-8),
                              ("MuJoCo", "RK4", 1e-11)]:
        error = zp.max_error(runners[code].tip(runners[code].run(method, "dt", s.interval / 64)), tip)
        assert error < tol, f"{code} {method}: tip differs from rigidfem's by {error:.3g} m"
    q, qd = np.linspace(-0.01, 0.01, 8), np.linspace(1.0, -1.0, 8)
    xml = MujocoChain(s)
    xml.data.qpos[xml.address], xml.data.qvel[xml.address] = q, qd
    xml.mujoco.mj_forward(xml.model, xml.data)
    assert runners["MuJoCo"].residual(q, qd, xml.data.qacc[xml.address]) < 1e-12
    checks = zp.verify(s, runners).rows
    assert [r["code"] for r in checks] == ["Exudyn", "MuJoCo"] and all(r["difference"] < r["allowed"] for r in checks)


def test_evaluations_quick(tmp_path, capsys):
    """python -m benchmarks evaluations --quick: per model (slider-crank, Bricard, strip m = 16, crane) the
    per-call table's and the forward-dynamics table's columns, positive finite times and shares in [0, 1]
    (the timings are the benchmark's to print, not the test's to compare); Pinocchio's column on the
    strip only, when it is installed."""
    pytest.importorskip("mujoco")
    from benchmarks import evaluations

    assert main(["evaluations", "--quick", "--output", str(tmp_path)]) == 0
    models = ["slider-crank m=4", "Bricard", "strip m=16", "crane m=6"]
    with open(tmp_path / "evaluations_per_call.csv") as f:
        reader = csv.DictReader(f)
        assert tuple(reader.fieldnames) == evaluations.PER_CALL_COLUMNS
        rows = list(reader)
    assert [r["model"] for r in rows] == models and [int(r["nl"]) for r in rows] == [5, 5, 0, 0]
    times = ("rigidfem_fd_us", "rigidfem_rk4_step_us", "newton_iteration_us", "residual_us", "lu_solve_us",
             "tangent_us", "lu_factor_us", "mujoco_forward_us", "mujoco_rk4_step_us", "fd/mujoco_forward",
             "rk4_step/mujoco_rk4_step", "dt_s")
    for r in rows:
        assert all(np.isfinite(float(r[k])) and float(r[k]) > 0 for k in times), r
        assert float(r["rk4_rhs_per_step"]) >= 4 and "unstable" not in r["note"]
        with_pinocchio = r["model"].startswith("strip") and importlib.util.find_spec("pinocchio") is not None
        for k in ("pinocchio_aba_us", "fd/pinocchio_aba"):
            assert (float(r[k]) > 0) if with_pinocchio else r[k] == "-", (k, r)
    with open(tmp_path / "evaluations_forward_dynamics.csv") as f:
        reader = csv.DictReader(f)
        assert tuple(reader.fieldnames) == evaluations.FORWARD_COLUMNS
        split = list(reader)
    assert [r["model"] for r in split] == models
    for r in split:
        assert all(float(r[k]) > 0 for k in ("fd_cpp_us", "fd_python_us", "mass_matrix_python_us",
                                             "generalized_forces_python_us"))
        # two timings' ratio (under load the tree alone can time above the whole): their shares add up to one
        assert float(r["tree_share"]) + float(r["loops_share"]) == pytest.approx(1.0)
        assert (float(r["tree_fd_cpp_us"]) > 0) if int(r["nl"]) else r["tree_fd_cpp_us"] == "-"
    out = capsys.readouterr().out
    assert "| model | nq | nl | rigidfem_fd_us |" in out and "| model | nq | nl | fd_cpp_us |" in out


def test_orders_study_table():
    """The high-order study's structure on a 4-element beam: every method reaches 1e-4 m, and the
    summary keeps the least time per method and target."""
    from benchmarks import orders

    sweep, summary = orders.study(elements=(4,), quick=True, repeats=0)
    assert {r["method"] for r in sweep.rows} == {"esdirk43", "esdirk43 (spring)", "radau5", "radau9", "dopri5",
                                                 "generalized_alpha"}
    assert all(np.isfinite(r["tip_error_rms_m"]) and r["wall_time_s"] > 0 for r in sweep.rows)
    assert len(summary.rows) == 6 and all(r["time_s_to_0.0001"] != "-" for r in summary.rows)
    orders = {r["method"].split(" (")[0]: r["order"] for r in summary.rows}  # each method's order, from rf.methods()
    assert orders == {"esdirk43": 4, "radau5": 5, "radau9": 9, "dopri5": 5, "generalized_alpha": 2}


def test_tolerance_study_quick(tmp_path, capsys):
    """The tolerance benchmark's quick run (m = 10, 2 tolerances, 3 methods, one fixed step): the
    table's columns, a finite error and delivered/asked per run, and the fixed-step table."""
    from benchmarks import tolerance

    tables = tolerance.run(tmp_path, quick=True)
    table, fixed = tables["tolerance"], tables["tolerance_fixed_steps"]
    assert table.columns[:7] == ("method", "rtol", "tip_error_rms_m", "delivered_over_asked", "warned", "steps",
                                 "rejected_steps") and "wall_time_s" in table.columns
    methods, rtols, *_ = tolerance.settings(quick=True)
    assert [(r["method"], r["rtol"]) for r in table.rows] == [(m, r) for m in methods for r in rtols]
    assert all(np.isfinite(r["tip_error_rms_m"]) and np.isfinite(r["delivered_over_asked"])
               and r["delivered_over_asked"] > 0 and r["steps"] > 0 for r in table.rows)
    assert all(r["warned"] in ("no", "warning") for r in table.rows)
    assert [r["method"] for r in fixed.rows] == ["implicit_spring"] and fixed.rows[0]["finished"] in ("yes", "no")
    assert (tmp_path / "tolerance.csv").exists() and "| method | rtol | tip_error_rms_m |" in capsys.readouterr().out


def test_accuracy_study_quick(tmp_path, capsys):
    """The accuracy benchmark's quick run (the strip at m = 8, the modified cantilever at m = 6, to 1e-4 m):
    the default asked for the target delivers it, its error bar is within a factor 3 of its true error,
    and the best run of the sweep is at least as accurate as the target."""
    from benchmarks import accuracy

    tables = accuracy.run(tmp_path, quick=True)
    table, runs = tables["accuracy"], tables["accuracy_sweep"]
    assert table.columns == accuracy.COLUMNS and [r["scene"] for r in table.rows] == ["strip m=8", "cantilever modified m=6"]
    for row in table.rows:
        assert row["delivered_over_asked"] <= 1.0 and 1 / 3 < row["estimate_over_true"] < 3, row
        assert row["best_error_m"] <= row["target_m"] and row["auto_over_best"] > 0
    assert {r["method"] for r in runs.rows} >= {"auto", "radau5", "radau5 (state)", "esdirk43", "generalized_alpha"}
    assert (tmp_path / "accuracy.csv").exists() and "| scene | target_m | auto_error_m |" in capsys.readouterr().out


def test_viewer_benchmark_quick(tmp_path, capsys):
    """python -m benchmarks viewer --quick: the table of build time, file size and time per frame."""
    from benchmarks import viewer

    table = viewer.run(tmp_path, quick=True)["viewer_scaling"]
    row = table.rows[0]
    assert (row["m"], row["bodies"], row["frames"]) == (20, 22, 101)
    # the packed scripts (0.25 MB) and 64 bytes a body and frame (0.14 MB), besides the markup
    assert 0.38 < row["file_MB"] < 0.6 and (tmp_path / "viewer_scaling.csv").exists()
    assert "ms_per_frame" in capsys.readouterr().out


def test_contact_benchmark_quick():
    """The contact benchmark's table: every capsule of the strip on the ground touches it by its two ends."""
    from benchmarks import contact

    table = contact.contact_cost((10,))
    row = table.rows[0]
    assert row["overlaps"] == 2 * 11 and row["fd_us_with"] > 0 and row["jac_ms_with"] > 0
    for row in contact.impact_accuracy(("dopri5",), (1e-6,)).rows:  # p = 1 and 1.5
        assert row["error_located"] < row["error_crossed"] and 1 / 3 < row["estimate_over_error_located"] < 3


def test_energy_benchmark_quick():
    """The energy benchmark's table (a tenth of each run): a row per scene and setting, every run finished or
    failed with its time; on the pendulum gauss6's energy error stays where it started while rk4's grows."""
    from benchmarks import energy

    table = energy.study(quick=True)
    scenes = {r["scene"] for r in table.rows}
    assert len(scenes) == 4
    assert len(table.rows) == 4 * (len(energy.FIXED) + len(energy.COARSER) + len(energy.ADAPTIVE_RTOLS))
    for r in table.rows:
        assert r.get("note", "").startswith("failed at t = ") or r["last_fifth_J"] >= 0.0
    pendulum = {r["method"] + " " + r["setting"]: r for r in table.rows if r["scene"].startswith("pendulum")}
    assert pendulum["gauss6 dt=0.05"]["last_over_first"] < 1.2
    assert pendulum["rk4 dt=0.05"]["last_over_first"] > 3


def test_limits_quick():
    """python -m benchmarks limits' strip study at m = 8: the stage residuals, timed apart in C++, are counted three
    (radau5) or five (radau9) per Newton iteration (their time against the run's is a timing, left to the benchmark:
    under load the two differ by more than the residuals' share); the tighter run's error is smaller and its observed
    order in the step count between 1 and the method's own; and the first mode carries the tip's swing about the
    sag: half its range is beam theory's static sag w L⁴ / 8EI to 5 %, each other mode's under a tenth of it."""
    from benchmarks import limits

    runs = (("radau5", 1e-5), ("radau5", 2e-6), ("radau9", 1e-4), ("radau9", 1e-5))
    rows, modes = limits.strip_study(8, runs)
    limits._orders(rows)
    stages = {"radau5": 3, "radau9": 5}
    for r in rows:
        assert r["residuals_ms"] > 0.0 and r["cpu_ms"] > 0.0
        assert r["residuals"] == pytest.approx(stages[r["method"]] * r["newton_per_step"] * r["steps"], abs=5)
    assert rows[1]["error"] < rows[0]["error"] and 1.0 < rows[1]["order"] < 5.0
    assert rows[3]["error"] < rows[2]["error"] and 1.0 < rows[3]["order"] < 9.0
    E, rho, width, thickness = 2.1e11, 7850.0, 0.02, 0.002
    EI, w = E * width * thickness**3 / 12, rho * width * thickness * 9.81
    first, *others = modes.rows
    assert first["tip_amplitude_m"] == pytest.approx(w / (8 * EI), rel=0.05)
    assert all(r["tip_amplitude_m"] < first["tip_amplitude_m"] / 10 for r in others)
