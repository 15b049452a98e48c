"""Plots and animations (rigidfem.plots, rigidfem.animation) on the Agg backend: what is drawn is
checked against the result's arrays and against positions and poses computed independently by
System.position and System.transform."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from PIL import Image  # noqa: E402

import rigidfem as rf  # noqa: E402
from rigidfem import animation, plots  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def pendulum():
    """A spatial double pendulum swinging for 1 s: (system, result, handles)."""
    model, h = rf.samples.double_pendulum(spatial=True)
    system = model.compile()
    q0 = np.array([0.4, 0.2, 0.1, -0.3, 0.5, 0.2])
    res = rf.simulate(system, 1.0, q0=q0, t_eval=np.linspace(0.0, 1.0, 41))
    return system, res, h


@pytest.fixture(scope="module")
def kane():
    """Kane's beam (4 elements) spun up over 1 s, 1.2 s simulated: a drive and a beam."""
    model, h = rf.samples.kane_beam(omega=2.0, duration=1.0, elements=4)
    system = model.compile()
    res = rf.simulate(system, 1.2, t_eval=np.linspace(0.0, 1.2, 25))
    return system, res, h


@pytest.fixture(scope="module")
def cantilever():
    model, h = rf.samples.cantilever(elements=8, deform=("bend_y", "bend_z"))
    return model.compile(), h["beam"]


def lines_by_label(ax) -> dict:
    return {line.get_label(): line for line in ax.get_lines()}


def legend_texts(ax) -> list:
    return [t.get_text() for t in ax.get_legend().get_texts()]


# --- time histories -------------------------------------------------------------------------------

def test_coordinate_lines_are_the_result_arrays(pendulum):
    system, res, _ = pendulum
    ax = plots.coordinates(res, ["link1.rz", 4])
    lines = ax.get_lines()
    assert [line.get_label() for line in lines] == ["link1.rz (rad)", "link2.ry (rad)"]
    assert legend_texts(ax) == ["link1.rz (rad)", "link2.ry (rad)"]
    for line, i in zip(lines, (0, 4)):
        np.testing.assert_array_equal(line.get_xdata(), res.t)
        np.testing.assert_array_equal(line.get_ydata(), res.q[:, i])
    assert ax.get_xlabel() == "t (s)" and ax.get_ylabel() == "q (rad)"


def test_coordinates_default_to_the_first_six_and_rates_carry_their_units(pendulum, kane):
    system, res, _ = pendulum
    ax = plots.coordinates(res, quantity="qd")
    assert len(ax.get_lines()) == system.nq == 6
    np.testing.assert_array_equal(ax.get_lines()[5].get_ydata(), res.qd[:, 5])
    assert ax.get_lines()[5].get_label() == "link2.rx (rad/s)" and ax.get_ylabel() == "q̇ (rad/s)"
    model, _ = rf.samples.spring_mass()
    res = rf.simulate(model.compile(), 0.1, q0=[0.01], t_eval=np.linspace(0, 0.1, 5))
    ax = plots.coordinates(res, "block.x", quantity="qdd")
    assert ax.get_lines()[0].get_label() == "block.x (m/s²)" and ax.get_ylabel() == "q̈ (m/s²)"
    np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(), res.qdd[:, 0])


def test_position_lines_are_the_point_positions(pendulum):
    system, res, h = pendulum
    ax = plots.position(res, h["tip"], "xz", label="tip")
    x, z = ax.get_lines()
    assert (x.get_label(), z.get_label()) == ("tip x (m)", "tip z (m)") and ax.get_ylabel() == "position (m)"
    k = 17  # against System.position at one output
    np.testing.assert_allclose([x.get_ydata()[k], z.get_ydata()[k]],
                               system.position(h["tip"], 0.0, res.q[k])[[0, 2]], rtol=1e-12, atol=1e-14)
    np.testing.assert_array_equal(x.get_xdata(), res.t)


def test_energy_lines_add_up_to_the_total(pendulum):
    system, res, _ = pendulum
    ax = plots.energies(res)
    lines = lines_by_label(ax)
    assert list(lines) == ["kinetic (J)", "gravity (J)", "elastic (J)", "total (J)"] == legend_texts(ax)
    assert ax.get_ylabel() == "energy (J)"
    k = 23
    np.testing.assert_allclose(lines["kinetic (J)"].get_ydata()[k], system.kinetic_energy(0.0, res.q[k], res.qd[k]),
                               rtol=1e-12)
    parts = sum(lines[n].get_ydata() for n in ("kinetic (J)", "gravity (J)", "elastic (J)"))
    np.testing.assert_allclose(lines["total (J)"].get_ydata(), parts, rtol=1e-12, atol=1e-12)
    assert len(plots.energies(res, ["total"]).get_lines()) == 1


def test_driving_force_lines_are_the_drive_torques(kane):
    system, res, _ = kane
    ax = plots.driving_forces(res)
    (line,) = ax.get_lines()
    assert line.get_label() == "hub.rz (N·m)" and ax.get_ylabel() == "driving force (N·m)"
    k = 9
    np.testing.assert_allclose(line.get_ydata()[k], system.driving_forces(res.t[k], res.q[k], res.qd[k])[0],
                               rtol=1e-10)


def test_histories_draw_into_given_axes(pendulum):
    _, res, _ = pendulum
    fig, ax = plt.subplots()
    assert plots.coordinates(res, 0, ax=ax) is ax and plots.energies(res, ["kinetic"], ax=ax) is ax
    assert len(ax.get_lines()) == 2 and len(fig.axes) == 1


# --- shapes ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("plane", [None, "xz"])
def test_beam_centreline_is_drawn_through_the_rfe_origins_and_the_tip(cantilever, plane):
    system, beam = cantilever
    q = np.random.default_rng(3).uniform(-0.1, 0.1, system.nq)
    ax = plots.shape(system, q, beams=[beam], plane=plane)
    line = lines_by_label(ax)["beam"]
    drawn = np.column_stack(line.get_data_3d() if plane is None else line.get_data())
    # modified formulation: the sdes are at the rfes' origins
    expected = np.array([system.position(b.origin, 0.0, q) for b in beam.rfes] + [system.position(beam.tip, 0.0, q)])
    np.testing.assert_allclose(drawn, expected if plane is None else expected[:, [0, 2]], rtol=1e-12, atol=1e-15)
    labels = [ax.get_xlabel(), ax.get_ylabel()] + ([ax.get_zlabel()] if plane is None else [])
    assert labels == (["x (m)", "y (m)", "z (m)"] if plane is None else ["x (m)", "z (m)"])


def test_bodies_are_drawn_as_their_frames_and_links(pendulum):
    system, _, h = pendulum
    q = np.array([0.3, -0.2, 0.4, 0.5, 0.1, -0.6])
    ax = plots.shape(system, q, frame_size=0.1)
    lines = lines_by_label(ax)
    for a, name in enumerate(("_x axes", "_y axes", "_z axes")):
        X = np.column_stack(lines[name].get_data_3d())
        for n, body in enumerate((h["link1"], h["link2"])):
            T = system.transform(body, 0.0, q)
            np.testing.assert_allclose(X[3 * n], T[:3, 3], atol=1e-14)  # from the origin ...
            np.testing.assert_allclose(X[3 * n + 1], T[:3, 3] + 0.1 * T[:3, a], atol=1e-14)  # ... along axis a
            assert np.all(np.isnan(X[3 * n + 2]))  # then a break
    links = np.column_stack(lines["_links"].get_data_3d())
    link2 = links[np.all(np.isfinite(links), axis=1)][-2:]  # link2's origin and centre of mass
    np.testing.assert_allclose(link2, [system.transform(h["link2"], 0.0, q)[:3, 3],
                                       system.position(h["link2"].point(system.centres_of_mass[1]), 0.0, q)], atol=1e-14)
    lo, hi = (np.array([getattr(ax, f"get_{c}lim")() for c in "xyz"]).T)
    np.testing.assert_allclose(hi - lo, (hi - lo)[0])  # equal aspect: a cube


def test_segments_join_their_two_points(pendulum):
    system, res, h = pendulum
    anchor = rf.Body().point((0.5, 0.2, 0.0))  # on the ground
    q = res.q[30]
    ax = plots.shape(system, q, segments=[(anchor, h["tip"]), (h["link1"], h["link2"].point((0.1, 0, 0)))])
    X = np.column_stack(lines_by_label(ax)["_segments"].get_data_3d())
    np.testing.assert_allclose(X[[0, 1, 3, 4]], [(0.5, 0.2, 0.0), system.position(h["tip"], 0.0, q),
                                                 system.transform(h["link1"], 0.0, q)[:3, 3],
                                                 system.position(h["link2"].point((0.1, 0, 0)), 0.0, q)], atol=1e-14)
    assert np.all(np.isnan(X[[2, 5]]))


def test_plane_shape_has_equal_aspect_and_rfes_without_triads(kane):
    system, res, h = kane
    ax = plots.shape(system, res.q[-1], t=res.t[-1], plane="xy")
    assert ax.get_aspect() == 1.0
    lines = lines_by_label(ax)
    x_axes = np.column_stack(lines["_x axes"].get_data())
    assert len(x_axes) == 3  # only the hub's triad; the beam's rfes are drawn as links
    np.testing.assert_allclose(x_axes[0], system.transform(h["hub"], res.t[-1], res.q[-1])[:2, 3], atol=1e-14)


def test_shapes_drawn_into_one_axes_all_stay_in_view(kane):
    system, res, h = kane
    ax = plt.figure().add_subplot()
    tips = []
    for k in (0, 12, 24):  # the beam turns from along x towards y
        plots.shape(system, res.q[k], t=res.t[k], plane="xy", ax=ax, beams=h["beam"])
        tips.append(system.position(h["beam"].tip, res.t[k], res.q[k])[:2])
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert all(x0 < x < x1 and y0 < y < y1 for x, y in tips)
    assert x1 - x0 == pytest.approx(y1 - y0)


def test_mode_shapes_are_titled_with_their_frequencies(cantilever):
    system, beam = cantilever
    modes = rf.modal_analysis(system)
    axes = plots.modes(system, modes, which=(0, 2), scale=0.05, plane="xy", beams=beam)
    assert len(axes) == 2
    for ax, i in zip(axes, (0, 2)):
        assert ax.get_title() == f"mode {i + 1}: {modes.frequencies_hz[i]:.4g} Hz"
        lines = lines_by_label(ax)
        deformed = np.column_stack(lines["beam"].get_data())
        np.testing.assert_allclose(deformed, beam.centerline(system, modes.q + 0.05 * modes.shapes[:, i])[:, :2],
                                   atol=1e-14)
        np.testing.assert_allclose(np.column_stack(lines["_beam reference"].get_data()),
                                   beam.centerline(system, modes.q)[:, :2], atol=1e-14)


def test_default_mode_scale_moves_the_shape_by_a_visible_fraction(cantilever):
    system, beam = cantilever
    modes = rf.modal_analysis(system)
    (ax,) = plots.modes(system, modes, which=0, beams=beam)
    tip = np.column_stack(lines_by_label(ax)["beam"].get_data_3d())[-1]
    assert 0.09 < np.linalg.norm(tip - [1.0, 0.0, 0.0]) < 0.11  # 10 % of the 1 m beam


# --- animations -----------------------------------------------------------------------------------

def test_animation_frames_and_growing_trail(kane):
    system, res, h = kane
    beam = h["beam"]
    anim = rf.animate(res, beams=beam, trails=[beam.tip], frames=7, plane="xy")
    assert len(anim.indices) == 7 and len(list(anim.new_frame_seq())) == 7
    np.testing.assert_array_equal(anim.indices, [0, 4, 8, 12, 16, 20, 24])
    ax = anim._fig.axes[0]
    path = res.position(beam.tip)
    for k in (2, 5):
        anim.update(k)
        i = anim.indices[k]
        trail = np.column_stack(lines_by_label(ax)["trail 0"].get_data())
        np.testing.assert_allclose(trail, path[: i + 1, :2], atol=1e-14)  # the path so far, growing
        drawn = np.column_stack(lines_by_label(ax)["beam"].get_data())
        np.testing.assert_allclose(drawn, beam.centerline(system, res.q[i], t=res.t[i])[:, :2], atol=1e-14)
        assert ax.texts[0].get_text() == f"t = {res.t[i]:.3f} s"
    html = anim.to_jshtml()
    assert "<img" in html or "animation" in html.lower()


def test_fps_picks_the_outputs_nearest_to_the_frame_times(kane):
    _, res, _ = kane
    anim = animation.animate(res, fps=3.0)  # frames at 0, 1/3, 2/3, 1 s; outputs every 0.05 s
    np.testing.assert_array_equal(anim.indices, [0, 7, 13, 20])  # 0, 0.35, 0.65, 1.0 s
    assert anim._interval == pytest.approx(1000.0 / 3)  # real time
    anim.update(3)
    anim._draw_was_started = True  # checked, not rendered: no "deleted without rendering" warning


def test_save_writes_a_gif_with_one_image_per_frame(pendulum, tmp_path):
    _, res, h = pendulum
    fig = plt.figure(figsize=(2, 2), dpi=40)
    anim = rf.animate(res, trails=h["tip"], frames=4, ax=fig.add_subplot(projection="3d"))
    path = animation.save(anim, tmp_path / "swing.gif")
    with Image.open(path) as gif:
        assert gif.n_frames == 4


# --- bad input ------------------------------------------------------------------------------------

def test_bad_input_names_the_argument_and_the_expected_values(pendulum, kane, cantilever):
    system, res, h = pendulum
    with pytest.raises(ValueError, match=r"which: expected coordinate names from \['link1.rz', 'link1.ry'.*'nope'"):
        plots.coordinates(res, "nope")
    with pytest.raises(ValueError, match=r"which: .*indices 0..5, got 6"):
        plots.coordinates(res, [0, 6])
    with pytest.raises(ValueError, match="quantity: expected one of"):
        plots.coordinates(res, quantity="q_dot")
    with pytest.raises(ValueError, match="components: expected"):
        plots.position(res, h["tip"], "xw")
    with pytest.raises(ValueError, match=r"which: expected energies from \['kinetic'"):
        plots.energies(res, ["potential"])
    with pytest.raises(ValueError, match="result: expected a system with prescribed coordinates"):
        plots.driving_forces(res)
    with pytest.raises(ValueError, match=r"plane: expected None \(3D\) or one of \['xy', 'xz', 'yz'\], got 'zx'"):
        plots.shape(system, res.q[0], plane="zx")
    with pytest.raises(ValueError, match="ax: expected 3D axes"):
        plots.shape(system, res.q[0], ax=plt.figure().add_subplot())
    with pytest.raises(ValueError, match="beams: expected Beam handles"):
        plots.shape(system, res.q[0], beams=[h["link1"]])
    with pytest.raises(ValueError, match=r"segments: expected pairs \(a, b\) of Point or Body"):
        plots.shape(system, res.q[0], segments=[h["tip"]])
    with pytest.raises(ValueError, match="frame_size: expected a positive number in m"):
        plots.shape(system, res.q[0], frame_size=-1.0)
    kane_system, kane_res, _ = kane
    with pytest.raises(ValueError, match="t: required"):
        plots.shape(kane_system, kane_res.q[0])
    beam_system, beam = cantilever
    with pytest.raises(ValueError, match=r"which: expected mode indices in 0..15"):
        plots.modes(beam_system, rf.modal_analysis(beam_system), which=(0, 16))
    with pytest.raises(ValueError, match="trails: expected a sequence of Point or Body"):
        animation.animate(res, trails=[(0, 0, 1)])
    with pytest.raises(ValueError, match="fps: expected None when frames is given"):
        animation.animate(res, frames=5, fps=10)
    with pytest.raises(ValueError, match="frames: expected an integer"):
        animation.animate(res, frames=0)


def test_save_refuses_unknown_extensions_and_missing_writers(pendulum, tmp_path, monkeypatch):
    _, res, _ = pendulum
    anim = animation.animate(res, frames=2)
    anim._draw_was_started = True  # never rendered on purpose
    with pytest.raises(ValueError, match=r"path: expected a file name ending in one of \['.gif'"):
        animation.save(anim, tmp_path / "movie.xyz")
    monkeypatch.setattr(animation.writers, "is_available", lambda name: False)
    with pytest.raises(ValueError, match=r"path: expected a format whose movie writer is available, got '.mp4', whose writer 'ffmpeg'"):
        animation.save(anim, tmp_path / "movie.mp4")
    assert not (tmp_path / "movie.mp4").exists()
