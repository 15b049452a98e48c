"""The 3D viewer (rf.view): the scene it writes, its size, and the page in a real browser.

The browser tests open the exported file in headless Chromium (Debian's package; .ci/run installs it
and sets RIGIDFEM_REQUIRE_BROWSER, so that CI cannot skip them), move the time slider by script, and
read what the page recorded in its body's data attributes: no JavaScript error, the frame shown, and
the pixels of the picture (how many are not background, and their hash).
"""

import os
import re
import shutil
import subprocess

import numpy as np
import pytest

import rigidfem as rf

BROWSER = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.fixture(scope="module")
def kane(tmp_path_factory):
    model, h = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=20)
    system = model.compile()
    result = rf.simulate(system, 20.0, t_eval=np.linspace(0.0, 20.0, 401))
    viewer = rf.view(system, result, trails=[h["beam"].tip])
    path = viewer.to_html(tmp_path_factory.mktemp("view") / "kane.html")
    return system, h, result, viewer, path


def test_the_scene_holds_every_frame_and_the_beam(kane):
    system, h, result, viewer, path = kane
    d = viewer.data
    assert viewer.frames == 401 and len(d["bodies"]) == system.nbodies == 22
    assert [b["bodies"] for b in d["beams"]] == [[system.body_names.index(f"beam.rfe{k}") for k in range(21)]]
    # the poses are the system's transforms (float32)
    import base64
    poses = np.frombuffer(base64.b64decode(d["poses"]), dtype="<f4").reshape(401, 22, 12)
    k, b = 137, 9
    T = system.transform(b, result.t[k], result.q[k])
    np.testing.assert_allclose(poses[k, b, :9], T[:3, :3].ravel(), atol=1e-6)
    np.testing.assert_allclose(poses[k, b, 9:], T[:3, 3], rtol=1e-6, atol=1e-6)
    # the tube ends at the tip: the last rfe's origin plus the tip offset is the beam's tip
    last = d["beams"][0]["bodies"][-1]
    T = system.transform(last, result.t[k], result.q[k])
    tip = T[:3, :3] @ d["beams"][0]["tip"] + T[:3, 3]
    np.testing.assert_allclose(tip, system.position(h["beam"].tip, result.t[k], result.q[k]), atol=1e-12)


def test_the_page_is_offline_and_small(kane):
    *_, viewer, path = kane
    page = path.read_text(encoding="utf-8")
    assert not re.search(r'(src|href)\s*=\s*["\']?(https?:)?//', page), "the page fetches something"
    size = path.stat().st_size
    assert size < 5e6, size  # the bound for this run (a 20 s Kane run, m = 20, 401 frames)
    # poses: 48 bytes per frame and body, 4/3 in base64; the rest is three.js and the viewer
    assert abs(len(viewer.data["poses"]) - 4 / 3 * 48 * 401 * 22) < 4


def test_other_scenes_and_one_state():
    m = rf.Model(gravity=(0.0, 0.0, -9.81))
    crank = m.add_body("crank", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1e-3, 0.01, 0.01),
                       com=(0.15, 0, 0))
    rocker = m.add_body("rocker", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(1e-3, 0.03, 0.03),
                        com=(0.3, 0, 0), placement=rf.transform((0.7, 0, 0)))
    m.add_spring_damper("element0", crank.point((0.3, 0, 0)), rocker.point((0.6, 0, 0)), stiffness=100.0, length=0.5)
    m.add_loop_joint("loop0", "distance", crank.point((0.3, 0, 0)), rocker.point((0.6, 0, 0)), length=0.55)
    s = m.compile()
    v = rf.view(s, q=np.zeros(s.nq))
    assert v.frames == 1 and [seg["kind"] for seg in v.data["segments"]] == ["spring", "loop"]
    assert v.data["segments"][0]["a"] == [crank.index, [0.3, 0.0, 0.0]]
    assert "iframe" in v._repr_html_() and "RIGIDFEM" in v.html()


def _poses(viewer):
    import base64
    d = viewer.data
    return np.frombuffer(base64.b64decode(d["poses"]), dtype="<f4").reshape(len(d["t"]), len(d["bodies"]), 12)


def test_every_documented_beam_shows_and_its_tube_ends_at_its_tip():
    """A link of varying length (a profile), a tapered section (a function of s), stepped sections and
    materials (lists): the viewer read the builder's arguments and failed on them (TypeError,
    AttributeError); it reads the Beam handles and the system. The tube's end, the last rfe's pose times
    the tip offset, is the beam's tip at every frame (Beam.tip_positions: the point positions in C++)."""
    steel = rf.Material(2.1e11, 7850.0)
    m = rf.Model(gravity=(0.0, -9.81, 0.0))
    hub = m.add_body("hub", m.ground, rf.Joint.revolute("z"), mass=1.0, inertia=(0.1, 0.1, 0.1))
    beams = [m.add_beam("slide", hub, rf.motion.polynomial([0.5, 0.2]), steel, rf.Section.circle(0.01), 6),
             m.add_beam("taper", hub, 1.0, steel, lambda s: rf.Section.circle(0.02 - 0.01 * s), 6,
                        placement=rf.transform((0.0, 0.0, 0.1))),
             m.add_beam("stepped", hub, 1.0, [steel] * 3, [rf.Section.circle(0.01)] * 3, 3,
                        placement=rf.transform((0.0, 0.0, 0.2)))]
    system = m.compile()
    result = rf.simulate(system, 0.5, t_eval=np.linspace(0.0, 0.5, 11), qd0=np.r_[1.0, np.zeros(system.nq - 1)])
    viewer = rf.view(system, result)
    poses = _poses(viewer).astype(float)
    assert [b["name"] for b in viewer.data["beams"]] == ["slide", "taper", "stepped"]
    for beam, shown in zip(beams, viewer.data["beams"]):
        assert shown["bodies"] == [b.index for b in beam.rfes]
        tips = shown["tips"] if beam.varying else [shown["tip"]] * len(result.t)
        last = poses[:, shown["bodies"][-1]]
        ends = np.einsum("kij,kj->ki", last[:, :9].reshape(-1, 3, 3), np.asarray(tips)) + last[:, 9:]
        np.testing.assert_allclose(ends, beam.tip_positions(result), atol=2e-6)  # float32 poses
    assert "tips" in viewer.data["beams"][0] and viewer.data["beams"][0]["tips"][-1][0] > viewer.data["beams"][0]["tips"][0][0]


def test_a_round_beams_tube_has_its_radius():
    """The tube's radius is sqrt(2 I_x/m) of the rfes: a round section's radius (here 0.1 m of a 10 m
    beam, within the bounds the scene's size sets)."""
    m = rf.Model(gravity=None)
    m.add_beam("b", m.ground, 10.0, rf.Material(2.1e11, 7850.0), rf.Section.circle(0.2), 5)
    system = m.compile()
    assert viewer_radius(system) == pytest.approx(0.1, rel=1e-12)


def viewer_radius(system):
    return rf.view(system).data["beams"][0]["radius"]


def test_a_large_system_is_shown_in_linear_time_and_its_frames_are_bounded():
    """One kinematics pass per frame in C++ for every body's pose (it was a full pass per body: 112 s per
    frame at 10,000 bodies, benchmarks/viewer.py); frames × bodies within MAX_POSES, the default
    frames reduced to fit, more asked for refused before anything is computed."""
    from rigidfem.viz.viewer import MAX_POSES

    model, h = rf.samples.cantilever(elements=4000, deform=("bend_z",))
    system = model.compile()
    t = np.linspace(0.0, 1.0, 1001)
    result = rf.Result(system, t, np.zeros((len(t), system.nq)), np.zeros((len(t), system.nq)), {}, "none")
    viewer = rf.view(system, result)
    assert viewer.frames == MAX_POSES // system.nbodies == 499
    with pytest.raises(ValueError, match=r"^frames: expected an integer in \[1, 499\], got 500"):
        rf.view(system, result, frames=500)
    T = system.transform(4000, 0.0, np.zeros(system.nq))
    np.testing.assert_allclose(_poses(viewer)[-1, 4000, 9:], T[:3, 3], rtol=1e-6)


def test_an_animation_bounds_its_frames_before_computing_them():
    model, h = rf.samples.pendulum()
    system = model.compile()
    result = rf.simulate(system, 1.0, method="rk4", dt=0.01, q0=[0.3])
    with pytest.raises(ValueError, match=r"^fps: expected at most 100,000 frames over the 1 s"):
        rf.animate(result, fps=1e300)
    with pytest.raises(ValueError, match=r"^fps: expected at most"):
        rf.animate(result, fps=1e6)


@pytest.mark.parametrize("call, name", [
    (lambda s, r: rf.view("system"), "system"),
    (lambda s, r: rf.view(s, "result"), "result"),
    (lambda s, r: rf.view(s, r, trails=["tip"]), "trails"),
    (lambda s, r: rf.view(s, r, frames=0), "frames"),
    (lambda s, r: rf.view(s, q=[1.0, 2.0, 3.0, 4.0]), "q"),
    (lambda s, r: rf.view(s, r, q=np.zeros(s.nq)), "q"),
    (lambda s, r: rf.view(s, r, height=10), "height"),
])
def test_bad_input_is_named(call, name):
    model, h = rf.samples.pendulum()
    s = model.compile()
    r = rf.simulate(s, 0.1, method="rk4", dt=0.01, q0=[0.3])
    with pytest.raises(ValueError, match=rf"^{name}"):
        call(s, r)


def _open(path, fragment):
    """The body's data attributes after the page ran (headless Chromium, software WebGL)."""
    if BROWSER is None:
        if os.environ.get("RIGIDFEM_REQUIRE_BROWSER"):
            pytest.fail("RIGIDFEM_REQUIRE_BROWSER is set but no chromium was found")
        pytest.skip("no chromium on this machine (.ci/run installs Debian's)")
    run = subprocess.run([BROWSER, "--headless", "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
                          "--enable-unsafe-swiftshader", "--virtual-time-budget=5000", "--window-size=800,600",
                          "--dump-dom", f"{path.as_uri()}#{fragment}"], capture_output=True, text=True, timeout=120)
    body = re.search(r"<body([^>]*)>", run.stdout)
    assert body, run.stderr[-2000:]
    return dict(re.findall(r'data-([\w-]+)="([^"]*)"', body.group(1)))


def test_the_page_renders_and_the_slider_moves_the_scene(kane):
    *_, path = kane
    start = _open(path, "probe=1")
    moved = _open(path, "slide=200&probe=1")
    for state in (start, moved):
        assert "error" not in state, state.get("error")
        assert state.get("ready") == "1"
        assert int(state["ink"]) > 500, state  # the scene is drawn, not a blank canvas
    assert (start["frame"], moved["frame"]) == ("0", "200") and moved["time"] == "10.000000"
    assert start["hash"] != moved["hash"]  # the beam moved between t = 0 and t = 10 s


def test_the_widget_holds_the_page_and_checks_its_frame():
    anywidget = pytest.importorskip("anywidget")
    model, h = rf.samples.pendulum()
    s = model.compile()
    r = rf.simulate(s, 1.0, method="rk4", dt=0.01, q0=[0.3])
    w = rf.view(s, r).widget()
    assert isinstance(w, anywidget.AnyWidget) and w.frames == 101 and w.frame == 0 and "RIGIDFEM" in w.page
    w.frame = 100
    import traitlets
    with pytest.raises(traitlets.TraitError, match="frame: expected an index in"):
        w.frame = 101


def test_the_widget_and_the_page_follow_each_other_in_a_browser(kane, tmp_path):
    """widget.js run in Chromium with a stand-in for anywidget's model: setting ``frame`` from the
    Python side shows that frame in the page, and moving the page's slider sets ``frame``."""
    import json

    from rigidfem.viz.viewer import ASSETS

    *_, viewer, _ = kane
    esm = (ASSETS / "widget.js").read_text(encoding="utf-8")
    host = tmp_path / "host.html"
    host.write_text("""<!DOCTYPE html><html><body><div id="host"></div>
<script type="module">
const esm = %s;
const url = URL.createObjectURL(new Blob([esm], {type: "text/javascript"}));
const widget = (await import(url)).default;
const state = {page: %s, height: 300, frames: %d, frame: 0}, on = {};
const model = {get: (k) => state[k], set: (k, v) => { state[k] = v; }, on: (e, f) => { on[e] = f; },
               save_changes: () => { document.body.dataset.saved = state.frame; }};
window.addEventListener("message", (e) => { if (e.data && e.data.rigidfem === "shown") document.body.dataset.shown = e.data.frame; });
widget.render({model, el: document.getElementById("host")});
const iframe = document.querySelector("iframe");
setTimeout(() => { state.frame = 150; on["change:frame"](); }, 1500);
setTimeout(() => {
  document.body.dataset.inner = iframe.contentDocument.body.dataset.frame;
  const slider = iframe.contentDocument.getElementById("rf-slider");
  slider.value = 300; slider.dispatchEvent(new Event("input"));
}, 2500);
</script></body></html>""" % (*(json.dumps(x).replace("</", "<\\/") for x in (esm, viewer.html())), viewer.frames),
                    encoding="utf-8")
    state = _open(host, "")
    assert state.get("inner") == "150"  # the Python side's frame, shown by the page
    assert state.get("saved") == "300" and state.get("shown") == "300"  # the slider's frame, back in the model


# -- trails and paths: TypeError ('not iterable', pathlib's) before, ValueError naming the argument now -------

@pytest.fixture(scope="module")
def pendulum_run():
    model, h = rf.samples.pendulum()
    system = model.compile()
    return h, system, rf.simulate(system, 0.1, method="rk4", dt=0.01, q0=[0.3])


def _no_render(anim):
    anim._draw_was_started = True  # checked, not rendered: no "deleted without rendering" warning
    import matplotlib.pyplot as plt
    plt.close("all")
    return anim


def test_trails_of_one_handle_or_a_sequence_are_taken_alike_by_view_and_animate(pendulum_run):
    """One Point or Body is one trail in both (view refused it: 'Point' object is not iterable)."""
    h, system, result = pendulum_run
    for trails, n in (((), 0), (h["tip"], 1), (h["link"], 1), ([h["tip"], h["link"]], 2)):
        assert len(rf.view(system, result, trails=trails).data["trails"]) == n
        anim = _no_render(rf.animate(result, trails=trails, frames=2))
        assert len([line for line in anim._fig.axes[0].lines if line.get_label().startswith("trail")]) == n


@pytest.mark.parametrize("trails, said", [(3, "3"), (None, "None"), (1.5, "1.5"), ("tip", "'tip'"),
                                          ({"tip": 1}, "{'tip': 1}"), (np.float64(2.0), r"np.float64\(2.0\)")])
def test_trails_that_are_not_handles_or_sequences_are_named(pendulum_run, trails, said):
    """TypeError ('int' object is not iterable) before; None is refused as for beams and segments (() is none)."""
    _, system, result = pendulum_run
    expected = (r"^trails: expected a Point or Body, or a sequence of Point or Body handles \(\(\) for none\), "
                rf"got {said}$")
    with pytest.raises(ValueError, match=expected):
        rf.view(system, result, trails=trails)
    with pytest.raises(ValueError, match=expected):
        rf.animate(result, trails=trails, frames=2)


def test_bad_items_and_foreign_handles_in_trails_are_named_alike(pendulum_run):
    _, system, result = pendulum_run
    foreign = rf.samples.pendulum()[1]["tip"]
    for call in (lambda tr: rf.view(system, result, trails=tr), lambda tr: rf.animate(result, trails=tr, frames=2)):
        with pytest.raises(ValueError, match=r"^trails: expected a sequence of Point or Body handles, got None at "
                                             r"trails\[0\]"):
            call([None])
        with pytest.raises(ValueError, match=r"^trails: expected a sequence of Point or Body handles of the model this "
                                             r"system was compiled from \(trails\[0\]\), got .* of another model"):
            call([foreign])


@pytest.mark.parametrize("wrong, said", [(None, "None"), (3, "3")])
def test_to_html_names_a_path_that_is_not_one(pendulum_run, wrong, said, tmp_path):
    _, system, result = pendulum_run
    with pytest.raises(ValueError, match=rf"^path: expected a file path \(str or os\.PathLike\), got {said}$"):
        rf.view(system, result).to_html(wrong)
    assert rf.view(system, result).to_html(str(tmp_path / "v.html")) == tmp_path / "v.html"


def test_the_shapes_of_contacts_are_drawn_in_their_bodies_frames(tmp_path):
    """Every shape goes into the scene with its body and geometry (a body with shapes is drawn by them, not by its
    inertia's box), and the page draws them without an error."""
    model = rf.Model()
    arm = model.add_body("arm", model.ground, rf.Joint.revolute("y"), 1.0, (0.01, 0.05, 0.05), com=(0.3, 0.0, 0.0),
                         placement=rf.transform((0.0, 0.0, 0.6)))
    ball = model.add_body("ball", model.ground, rf.Joint.free(), 0.5, (0.002, 0.002, 0.002),
                          placement=rf.transform((0.3, 0.3, 0.5)))
    other = model.add_body("other", model.ground, rf.Joint.revolute("z"), 1.0, (0.1, 0.1, 0.1))
    shapes = [model.add_shape("rod", arm, rf.shapes.Capsule(0.05, (0.0, 0.0, 0.0), (0.6, 0.0, 0.0))),
              model.add_shape("shell", ball, rf.shapes.Sphere(0.08)),
              model.add_shape("brick", other, rf.shapes.Box((0.1, 0.06, 0.04), rotation=rf.euler_zyx(0.3, 0.0, 0.0)))]
    floor = model.add_shape("floor", model.ground, rf.shapes.HalfSpace())
    model.add_contact("on floor", shapes, floor, rf.laws.Contact(stiffness=1e5, restitution=0.6, mu_s=0.5, mu_k=0.4))
    s = model.compile()
    r = rf.simulate(s, 0.5, t_eval=np.linspace(0.0, 0.5, 11))
    viewer = rf.view(s, r)
    drawn = viewer.data["shapes"]
    assert [(d["kind"], d["body"]) for d in drawn] == [("capsule", 0), ("sphere", 1), ("box", 2), ("half_space", -1)]
    assert drawn[0]["b"] == [0.6, 0.0, 0.0] and drawn[1]["radius"] == 0.08
    np.testing.assert_allclose(np.reshape(drawn[2]["rotation"], (3, 3)), rf.euler_zyx(0.3, 0.0, 0.0))
    assert all(b["box"] is None for b in viewer.data["bodies"])
    state = _open(viewer.to_html(tmp_path / "contact.html"), "slide=10&probe=1")
    assert "error" not in state, state.get("error")
    assert state.get("ready") == "1" and int(state["ink"]) > 500
