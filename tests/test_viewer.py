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
    import base64
    import zlib

    *_, viewer, path = kane
    page = path.read_text(encoding="utf-8")
    packed = re.search(r'rigidfemUnpack\("([A-Za-z0-9+/=]+)"\)', page).group(1)
    scripts = zlib.decompress(base64.b64decode(packed)).decode("utf-8")  # what the page runs, unpacked
    for text in (page, scripts):
        assert not re.search(r'(src|href)\s*=\s*["\']?(https?:)?//', text), "the page fetches something"
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
    (lambda s, r: rf.view(s, trails=[rf.Point(4, (0.3, 0.0, 0.0))]), "trails"),  # a body the system has not
    (lambda s, r: rf.view(s, r, trails=[rf.Point(-2, (0.3, 0.0, 0.0))]), "trails"),
    (lambda s, r: rf.view(s, r, frames=0), "frames"),
    (lambda s, r: rf.view(s, frames=10**30), "frames"),  # one state: judged as a result's frames would be
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


def _widget_in_browser(viewer, tmp_path, frame, then):
    """The body data attributes after widget.js rendered ``viewer``'s page in Chromium, with a stand-in for
    anywidget's model (its ``frame`` first at ``frame``; ``on`` keeps the handlers, ``save_changes`` records the
    frame in data-saved, the page's "shown" messages go to data-shown) and the script ``then`` run after it."""
    import json

    from rigidfem.viz.viewer import ASSETS

    esm = (ASSETS / "widget.js").read_text(encoding="utf-8")
    host = tmp_path / "host.html"
    host.write_text("""<!DOCTYPE html><html><body><div id="host"></div>
<script type="module">
const esm = %s;
const url = URL.createObjectURL(new Blob([esm], {type: "text/javascript"}));
const widget = (await import(url)).default;
const state = {page: %s, height: 300, frames: %d, frame: %d}, on = {};
const model = {get: (k) => state[k], set: (k, v) => { state[k] = v; }, on: (e, f) => { on[e] = f; },
               save_changes: () => { document.body.dataset.saved = state.frame; }};
window.addEventListener("message", (e) => { if (e.data && e.data.rigidfem === "shown") document.body.dataset.shown = e.data.frame; });
widget.render({model, el: document.getElementById("host")});
const iframe = document.querySelector("iframe");
%s
</script></body></html>""" % (*(json.dumps(x).replace("</", "<\\/") for x in (esm, viewer.html())), viewer.frames, frame,
                              then), encoding="utf-8")
    return _open(host, "")


def test_the_widget_and_the_page_follow_each_other_in_a_browser(kane, tmp_path):
    """widget.js run in Chromium with a stand-in for anywidget's model: setting ``frame`` from the
    Python side shows that frame in the page, and moving the page's slider sets ``frame``."""
    *_, viewer, _ = kane
    state = _widget_in_browser(viewer, tmp_path, 0, """
setTimeout(() => { state.frame = 150; on["change:frame"](); }, 1500);
setTimeout(() => {
  document.body.dataset.inner = iframe.contentDocument.body.dataset.frame;
  const slider = iframe.contentDocument.getElementById("rf-slider");
  slider.value = 300; slider.dispatchEvent(new Event("input"));
}, 2500);""")
    assert state.get("inner") == "150"  # the Python side's frame, shown by the page
    assert state.get("saved") == "300" and state.get("shown") == "300"  # the slider's frame, back in the model


def test_the_page_packs_its_scripts_and_unpacks_them_whole(kane):
    """three.js, its orbit controls and viewer.js travel as one zlib stream in base64: the page holds them at under
    30 % of their size, and the stream decodes to the three files as shipped."""
    import base64
    import zlib

    from rigidfem.viz.viewer import ASSETS, SCRIPTS

    *_, viewer, path = kane
    page = viewer.html()
    packed = re.search(r'rigidfemUnpack\("([A-Za-z0-9+/=]+)"\)', page).group(1)
    code = zlib.decompress(base64.b64decode(packed)).decode("utf-8")
    texts = [(ASSETS / name).read_text(encoding="utf-8") for name in SCRIPTS]
    assert code == "\n;\n".join(texts)
    assert not any(text[:200] in page for text in texts)  # not also inline as text
    shipped = sum(len(t.encode("utf-8")) for t in texts)
    assert len(packed) < 0.3 * shipped


def test_a_frame_sent_at_the_iframes_load_is_shown(kane, tmp_path):
    """The notebook widget sends its frame when the iframe loads: the page's scripts have unpacked and run by then
    (synchronously, where they stand), so the page shows that frame, not frame 0."""
    *_, viewer, _ = kane
    state = _widget_in_browser(viewer, tmp_path, 250, """
setTimeout(() => {
  const inner = iframe.contentDocument.body.dataset;
  document.body.dataset.inner = inner.frame;
  document.body.dataset.innerReady = inner.ready;
}, 2500);""")
    assert state.get("inner-ready") == "1" and state.get("inner") == "250"


def test_the_pages_inflate_decodes_what_zlib_encodes(tmp_path):
    """unpack.js's zlib decoder, run in Chromium on streams of Python's zlib: stored blocks (level 0, 70 kB: two),
    the fixed codes (a short text), dynamic codes (three.js), overlapping copies (distance 1) and an empty input
    decode to the bytes encoded. A stream cut short, one with any of 40 single bits flipped (the Adler-32 catches
    what DEFLATE decodes), a bad header, and hand-made codes that zlib refuses (over-subscribed, incomplete, no
    end-of-block code) are errors, not wrong text."""
    import base64
    import json
    import zlib

    from rigidfem.viz.viewer import ASSETS

    def dynamic_block(literal_lengths, data):
        """A zlib stream of one dynamic block whose literal/length code has ``literal_lengths`` ({symbol: bits},
        257 symbols, no distance code), then ``data``: the codes (str of 0/1, most significant first) of the
        symbols written. The code-length code gives lengths 0, 1, 2 the codes 0, 10, 11. Ends with 'A's Adler-32."""
        bits = []

        def put(value, n):  # a header field, least significant bit first
            bits.extend((value >> i) & 1 for i in range(n))

        order = [16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15]
        put(1, 1), put(2, 2), put(0, 5), put(0, 5), put(18 - 4, 4)  # last block, dynamic; 257, 1, 18 lengths
        for symbol in order[:18]:
            put({0: 1, 1: 2, 2: 2}.get(symbol, 0), 3)
        for L in [literal_lengths.get(k, 0) for k in range(257)] + [0]:
            bits.extend(int(c) for c in {0: "0", 1: "10", 2: "11"}[L])
        bits.extend(int(c) for c in data)
        bits += [0] * (-len(bits) % 8)
        body = bytes(sum(b << i for i, b in enumerate(bits[k:k + 8])) for k in range(0, len(bits), 8))
        return b"\x78\x9c" + body + zlib.adler32(b"A").to_bytes(4, "big")

    rng = np.random.default_rng(1)
    three = (ASSETS / "three.min.js").read_bytes()[:200_000]
    cases = {"stored": (rng.integers(0, 256, 70_000, dtype=np.uint8).tobytes(), 0),
             "fixed": (b"rigid finite elements", 9), "dynamic": (three, 9),
             "overlap": (b"a" * 100_000 + b"ab" * 5_000, 9), "empty": (b"", 9)}
    streams = {name: zlib.compress(data, level) for name, (data, level) in cases.items()}
    assert [streams[k][2] >> 1 & 3 for k in ("stored", "fixed", "dynamic")] == [0, 1, 2]  # each block type is met
    # a valid hand-made block (the builder's check: 'A' is code 0, the end of block 1), then codes zlib refuses
    made = {"made": dynamic_block({65: 1, 256: 1}, "01")}
    bad = {"cut": streams["dynamic"][:5_000], "header": b"\x78\x9d" + streams["fixed"][2:],
           "oversubscribed": dynamic_block({65: 1, 66: 1, 256: 1}, "01"),
           "incomplete": dynamic_block({65: 1, 256: 2}, "010"),
           "no end of block": dynamic_block({65: 1, 66: 1}, "0")}
    flips = rng.choice(8 * (len(streams["dynamic"]) - 6), 40, replace=False) + 16  # in the DEFLATE data only
    for k, at in enumerate(flips):
        damaged = bytearray(streams["dynamic"])
        damaged[at // 8] ^= 1 << (at % 8)
        bad[f"flip{k}"] = bytes(damaged)
    streams.update(made)
    cases["made"] = (b"A", None)
    encoded = {k: base64.b64encode(v).decode() for k, v in {**streams, **bad}.items()}
    expected = {k: base64.b64encode(data).decode() for k, (data, _) in cases.items()}
    host = tmp_path / "inflate.html"
    host.write_text("""<!DOCTYPE html><html><body><script>%s</script><script>
const streams = %s, expected = %s, results = {};
const bytes = (b64) => Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
const b64 = (u8) => {
  let s = "";
  for (let i = 0; i < u8.length; i += 8192) s += String.fromCharCode(...u8.subarray(i, i + 8192));
  return btoa(s);
};
for (const k in streams) {
  try {
    const out = b64(rigidfemInflate(bytes(streams[k])));
    results[k] = k in expected ? (out === expected[k] ? "same" : "differs") : "no error";
  } catch (e) { results[k] = String(e.message); }
}
document.body.dataset.results = JSON.stringify(results);
</script></body></html>""" % ((ASSETS / "unpack.js").read_text(encoding="utf-8"), json.dumps(encoded),
                                 json.dumps(expected)), encoding="utf-8")
    import html as html_
    results = json.loads(html_.unescape(_open(host, "")["results"]))
    assert {k: results[k] for k in cases} == dict.fromkeys(cases, "same")
    assert results["cut"].startswith("unpack: the stream ends early")
    assert results["header"].startswith("unpack: a zlib header")
    assert results["oversubscribed"].startswith("unpack: an over-subscribed literal/length code")
    assert results["incomplete"].startswith("unpack: an incomplete literal/length code")
    assert results["no end of block"].startswith("unpack: no end-of-block code")
    assert all(results[f"flip{k}"].startswith("unpack: ") for k in range(40)), results


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


# -- what the picture shows: framing, the grid and scale, deformation, modes, overlays, colours, arrows -------------
#
# The pages are opened together, each in an iframe of one host page in one Chromium (a launch costs 2-4 s), and
# each records the snapshots asked for in its fragment (#shots=0,-1: the PNGs of the first and the last frame,
# what the snapshot button saves); #helpers=0 leaves out the grid and the global triad, so that the pixels that
# are not background are the model's.

def _open_pages(pages, tmp_path):
    """The body data attributes of each (path, fragment) page after it ran, all in one Chromium."""
    import json

    if BROWSER is None:
        if os.environ.get("RIGIDFEM_REQUIRE_BROWSER"):
            pytest.fail("RIGIDFEM_REQUIRE_BROWSER is set but no chromium was found")
        pytest.skip("no chromium on this machine (.ci/run installs Debian's)")
    host = tmp_path / "host.html"
    frames = "".join(f'<iframe style="width: 800px; height: 470px; border: 0; display: block" src="{p.as_uri()}#{f}">'
                     f'</iframe>' for p, f in pages)
    host.write_text(f"""<!DOCTYPE html><html><body>{frames}<script>
function copy() {{
  const all = [...document.querySelectorAll("iframe")].map((f) => f.contentDocument && f.contentDocument.body
                                                          ? {{...f.contentDocument.body.dataset}} : {{}});
  if (all.every((d) => d.ready === "1" || d.error)) document.body.dataset.pages = JSON.stringify(all);
  else setTimeout(copy, 100);
}}
window.addEventListener("load", copy);
</script></body></html>""", encoding="utf-8")
    run = subprocess.run([BROWSER, "--headless", "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
                          "--enable-unsafe-swiftshader", "--allow-file-access-from-files",
                          f"--virtual-time-budget={4000 + 2000 * len(pages)}", "--window-size=800,600",
                          "--dump-dom", host.as_uri()], capture_output=True, text=True, timeout=120, check=False)
    found = re.search(r'<body data-pages="([^"]*)"', run.stdout)
    assert found, run.stderr[-2000:]
    import html as html_
    return json.loads(html_.unescape(found.group(1)))


def _image(data_url):
    """The PNG of a data URL as an (h, w, 3) uint8 array."""
    import base64
    import io

    from PIL import Image

    assert data_url.startswith("data:image/png;base64,"), data_url[:40]
    return np.asarray(Image.open(io.BytesIO(base64.b64decode(data_url.split(",", 1)[1]))).convert("RGB"))


def _ink(img):
    """The pixels that are not the white background."""
    return np.any(img < 245, axis=2)


def _box(mask):
    """(top, bottom, left, right) of the True pixels."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    return rows[0], rows[-1], cols[0], cols[-1]


def _strip():
    """The README's quick start: a steel strip clamped at the ground, gravity along -y, released from rest."""
    E, rho, b, h, L = 2.1e11, 7850.0, 0.02, 0.005, 1.0
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    beam = model.add_beam("strip", model.ground, L, rf.Material(E=E, rho=rho), rf.Section.rectangle(h, b), 20,
                          deform="bend_z")
    system = model.compile()
    return system, rf.simulate(system, 2.0, t_eval=np.linspace(0.0, 2.0, 101)), [beam.tip]


def _four_bar():
    model, h = rf.samples.four_bar()
    system = model.compile()
    q0, _ = system.assemble([0.4, -1.9, 4.6])
    return system, rf.simulate(system, 3.0, q0=q0, t_eval=np.linspace(0.0, 3.0, 61)), [h["coupler"].point((0.4, 0, 0))]


def _kane(linear=False):
    model, h = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=10, linear=linear)
    system = model.compile()
    return system, rf.simulate(system, 20.0, t_eval=np.linspace(0.0, 20.0, 101)), [h["beam"].tip]


def _crane():
    """Notebook 06's crane at sea's rest: a column slewing 30° in 3 s, a 24 m boom of 6 rfes luffed by an actuator,
    a 5 t payload on a 14 m rope (z up)."""
    g, crane, h_col, pin, L, lug_at, th = 9.81, (0.0, 8.0, 4.0), 12.0, 1.0, 24.0, 7.0, np.radians(45.0)
    anchor, m_pay, lu, EA = (-0.5, 0.0, 4.0), 5000.0, 14.0, 1.0e8
    lug = lug_at * np.array([np.cos(th), 0.0, np.sin(th)])
    tip = np.array(crane) + [pin + L * np.cos(th), 0.0, h_col + L * np.sin(th)]
    model = rf.Model(gravity=(0.0, 0.0, -g))
    vessel = model.add_moving_base("vessel", {})
    column = model.add_body("column", vessel, rf.Joint.revolute("z"), mass=8000.0, inertia=(1e5, 1e5, 5e3),
                            com=(0.0, 0.0, h_col / 2), placement=rf.transform(crane))
    times = np.linspace(0.0, 3.0, 31)
    model.prescribe(column, rf.motion.spline(times, np.radians(30.0) * (times / 3.0) ** 2))
    boom = model.add_beam("boom", column, L, rf.Material(E=210e9, rho=7850.0, nu=0.3, retardation=2e-3),
                          rf.Section.tube(0.8, 0.75), 6, deform=("bend_y", "bend_z", "torsion"),
                          joint=rf.Joint.revolute("y"), placement=rf.transform((pin, 0.0, h_col), (0.0, -th, 0.0)))
    model.add_actuator("luff", column.point(anchor), boom.point(lug_at),
                       np.linalg.norm(lug - (np.array(anchor) - [pin, 0.0, h_col])))
    payload = model.add_body("payload", model.ground, rf.Joint.custom(["x", "y", "z"]), mass=m_pay,
                             inertia=(1.0, 1.0, 1.0), placement=rf.transform(tip - [0.0, 0.0, lu * (1 + m_pay * g / EA)]))
    rope = model.add_rope("rope", boom.tip, payload, EA=EA, length=lu, DA=0.05 * 2 * np.sqrt(EA / lu * m_pay) * lu)
    system = model.compile()
    q0 = rf.static_equilibrium(system, q0=np.zeros(system.nq), load_steps=2, t=0.0).q
    result = rf.simulate(system, 3.0, method="generalized_alpha", dt=0.01, q0=q0, t_eval=np.linspace(0.0, 3.0, 31))
    return system, result, [payload], rope


@pytest.fixture(scope="module")
def four_models():
    return {"README strip": _strip(), "four-bar": _four_bar(), "Kane's beam": _kane(), "crane": _crane()[:3]}


def test_the_camera_is_set_from_gravity_and_the_drawn_geometry(four_models):
    """The up axis is -gravity (z without gravity, or up=); the camera stands above the model; the scene's box holds
    the trails (the strip's sagging tip, below every body's origin at some frame) and the beam's tip."""
    for name, (system, result, trails) in four_models.items():
        d = rf.view(system, result, trails=trails).data
        g = np.asarray(system.gravity)
        up = -g / np.linalg.norm(g) if np.linalg.norm(g) else np.array([0.0, 0.0, 1.0])
        np.testing.assert_allclose(d["up"], up, atol=1e-12, err_msg=name)
        assert np.dot(d["camera"]["dir"], up) > 0.2, name  # from above
        lo, hi = np.asarray(d["camera"]["lo"]), np.asarray(d["camera"]["hi"])
        path = result.position(trails[0])
        assert np.all(path >= lo - 1e-6) and np.all(path <= hi + 1e-6), name
    system, result, trails = four_models["README strip"]
    assert rf.view(system, result, up=(0, 0, 1)).data["up"] == [0.0, 0.0, 1.0]
    grid = rf.view(system, result).data["grid"]
    assert grid["step"] == 0.1 and np.dot(grid["origin"], [0, 1, 0]) < result.position(trails[0])[:, 1].min()


def test_every_model_is_drawn_whole_inside_the_picture_and_fills_it(four_models, tmp_path):
    """The README's strip and the four-bar (gravity along -y), Kane's beam (no gravity) and the crane (z up), each
    at its first, middle and last frame (the last with the whole trail): the model's pixels lie inside the
    picture with a margin of 4 px, and together they span at least half its width or height."""
    pages = []
    for k, (name, (system, result, trails)) in enumerate(four_models.items()):
        path = rf.view(system, result, trails=trails, title=name).to_html(tmp_path / f"model{k}.html")
        pages.append((path, f"helpers=0&shots=0,{len(result.t) // 2},-1"))
    pages.append((pages[0][0], "shots=-1"))  # with the grid, as users see it
    states = _open_pages(pages, tmp_path)
    fills = {}
    for name, state in zip(four_models, states):
        assert "error" not in state, (name, state.get("error"))
        union = None
        for shot in ("shot0", "shot1", "shot2"):
            ink = _ink(_image(state[shot]))
            h, w = ink.shape
            assert ink.sum() > 300, (name, shot)
            top, bottom, left, right = _box(ink)
            assert top >= 4 and left >= 4 and bottom <= h - 5 and right <= w - 5, (name, shot, _box(ink), (h, w))
            union = ink if union is None else union | ink
        top, bottom, left, right = _box(union)
        fills[name] = max((right - left + 1) / w, (bottom - top + 1) / h)
    assert all(f >= 0.5 for f in fills.values()), fills
    grid = _image(states[-1]["shot0"])
    assert _ink(grid).sum() > 2 * _ink(_image(states[0]["shot2"])).sum()  # the grid is drawn


def _values(b64):
    import base64
    return np.frombuffer(base64.b64decode(b64), dtype="<f4")


@pytest.fixture(scope="module")
def stiff():
    """A stiff steel cantilever (20 mm along y, bending about z) at rest under gravity -y: a 1.4 mm sag over 1 m."""
    model, h = rf.samples.cantilever(elements=20, gravity=(0.0, -9.81, 0.0))
    system = model.compile()
    return system, h["beam"], rf.static_equilibrium(system).q


def test_the_deformation_scale_magnifies_each_rfes_pose_relative_to_the_rigid_beam(stiff):
    """At scale s the rfes' origins are the rigid beam's plus s times their displacements (exactly: the beam is
    clamped, so its first rfe does not move), and the tip's sag is s times the computed one to the second order
    in the tip's rotation s θ (here 0.2 rad: 1 %)."""
    system, beam, q = stiff
    rfes = [b.index for b in beam.rfes]
    base, big = (_poses(rf.view(system, q=q, scale=s)).astype(float)[0] for s in (1.0, 100.0))
    rigid = np.c_[beam.frames, np.zeros((len(rfes), 2))]
    np.testing.assert_allclose(big[rfes, 9:], rigid + 100.0 * (base[rfes, 9:] - rigid), atol=1e-5)
    tip = big[rfes[-1], :9].reshape(3, 3) @ [beam.length - beam.frames[-1], 0, 0] + big[rfes[-1], 9:]
    sag = system.position(beam.tip, 0.0, q)[1]
    assert sag < -1e-3 and tip[1] == pytest.approx(100.0 * sag, rel=0.01)
    with pytest.raises(ValueError, match=r"^scale: expected a positive"):
        rf.view(system, q=q, scale=0.0)


def test_the_sdes_are_coloured_by_their_bending_moment_from_their_laws(stiff):
    """The values are the sdes' c φ: at rest under its own weight w the moment at an sde at s is w (L - s)^2 / 2
    (the weight beyond it times its arm), to float32's round-off; the colour bar spans them."""
    system, beam, q = stiff
    d = rf.view(system, q=q, color="bending_moment").data
    w = 7850.0 * 0.02 * 0.005 * 9.81
    s = beam.frames[1:]
    np.testing.assert_allclose(_values(d["beams"][0]["values"]), w * (1.0 - s) ** 2 / 2, rtol=1e-5)
    bar = d["colour_bars"][0]
    assert bar["label"].startswith("bending moment") and bar["hi"] == pytest.approx(w * (1 - s[0]) ** 2 / 2, rel=1e-6)
    curvature = _values(rf.view(system, q=q, color="curvature").data["beams"][0]["values"])
    np.testing.assert_allclose(curvature, w * (1.0 - s) ** 2 / 2 / (2.1e11 * 0.005 * 0.02**3 / 12), rtol=1e-4)
    with pytest.raises(ValueError, match=r"^color: expected None or one of \['axial_force'"):
        rf.view(system, q=q, color="stress")
    with pytest.raises(ValueError, match=r"^color: expected beams with the deformations 'axial_force' reads"):
        rf.view(system, q=q, color="axial_force")


def test_mode_shapes_are_animated_over_a_period():
    """rf.view(modes): q0 + a sin(2 pi phase) shape at 48 phases, a such that the largest displacement of a body's
    origin along the shape (to first order) is 10 % of the model's size (1 m); several modes side by side, each
    labelled by its frequency."""
    model, _ = rf.samples.cantilever(elements=10)
    system = model.compile()
    modes = rf.modal_analysis(system)
    v = rf.view(modes)
    assert v.frames == 48 and v.data["clock"] == "phase" and v.data["loop"] and v.data["t"][12] == 0.25
    shape, eps = modes.shapes[:, 0], 1e-7
    rate = max(np.linalg.norm(system.transform(i, 0.0, modes.q + eps * shape)[:3, 3]
                              - system.transform(i, 0.0, modes.q)[:3, 3]) / eps for i in range(system.nbodies))
    a = v.data["amplitudes"][0]
    assert a * rate == pytest.approx(0.1, rel=1e-4)
    poses = _poses(v).astype(float)
    for k in (12, 30):  # a quarter period, and a phase where the sine is negative
        T = system.transform(system.nbodies - 1, 0.0, modes.q + a * np.sin(2 * np.pi * k / 48) * shape)
        np.testing.assert_allclose(poses[k, -1, 9:], T[:3, 3], atol=1e-6)
    three = rf.view(system, modes, mode=(0, 1, 2))
    assert [x["label"] for x in three.data["legend"]] == [f"mode {m + 1}: {modes.frequencies_hz[m]:.4g} Hz"
                                                          for m in range(3)]
    offsets = [three.data["offset"]] + [x["offset"] for x in three.data["layers"]]
    assert offsets[0] != offsets[1] != offsets[2]
    with pytest.raises(ValueError, match=r"^mode: expected an integer in \[0, 9\], got 10"):
        rf.view(modes, mode=10)
    with pytest.raises(ValueError, match=r"^scale: expected 1 with modes"):
        rf.view(modes, scale=10.0)


def test_two_results_are_overlaid_at_the_first_ones_times():
    """A nonlinear and a linear model of Kane's beam (two systems) in one scene: each with its own bodies and poses,
    the second at its outputs nearest the first's times; named in the legend."""
    a, b = _kane_pair()
    v = rf.view([a, b], labels=["nonlinear", "linear"], frames=11)
    assert v.frames == 11 and len(v.data["layers"]) == 1
    assert [x["label"] for x in v.data["legend"]] == ["nonlinear", "linear"]
    second = np.frombuffer(__import__("base64").b64decode(v.data["layers"][0]["poses"]), "<f4").reshape(11, -1, 12)
    k = np.searchsorted(b.t, v.data["t"][5])
    T = b.system.transform(b.system.nbodies - 1, b.t[k], b.q[k])
    np.testing.assert_allclose(second[5, -1, 9:], T[:3, 3], rtol=1e-5, atol=1e-5)
    side = rf.view(a.system, [a, b], layout="side")
    assert side.data["offset"] != side.data["layers"][0]["offset"]
    with pytest.raises(ValueError, match=r"^labels: expected a sequence of 2 names"):
        rf.view([a, b], labels=["one"])


def _kane_pair():
    runs = []
    for linear in (False, True):
        model, _ = rf.samples.kane_beam(omega=2.0, duration=15.0, elements=6, linear=linear)
        system = model.compile()
        runs.append(rf.simulate(system, 10.0, t_eval=np.linspace(0.0, 10.0, 51)))
    return runs


def test_ropes_are_coloured_by_their_tension_and_forces_drawn_as_arrows():
    """The crane's rope carries -element_forces (its tension, N) at each frame; with forces=True its pull on the
    boom's tip and on the payload are arrows of that size, opposite, along the rope."""
    system, result, _, _ = _crane()
    v = rf.view(system, result, forces=True)
    seg = next(s for s in v.data["segments"] if s["kind"] == "rope")
    T = -result.element_forces[:, 0]
    np.testing.assert_allclose(_values(seg["values"]), T, rtol=1e-6)
    assert v.data["colour_bars"][-1]["label"] == "rope tension T (N)" and v.data["colour_bars"][-1]["hi"] == \
        pytest.approx(T.max(), rel=1e-6)
    on = [_values(a["vectors"]).reshape(-1, 3) for a in v.data["arrows"] if a["kind"] == "element"][:2]
    np.testing.assert_allclose(np.linalg.norm(on[0], axis=1), T, rtol=1e-5)
    np.testing.assert_allclose(on[0], -on[1], rtol=1e-6)
    assert v.data["arrow_scale"]["largest"] == pytest.approx(T.max(), rel=1e-6)


def test_what_cannot_be_shown_is_named_not_drawn_blank(pendulum_run, tmp_path):
    """A result with NaN coordinates, one loaded without its system, modes without their system: a ValueError saying
    which output and coordinate, or what to pass, where the page was blank."""
    _, system, result = pendulum_run
    bad = rf.Result(system, result.t, result.q.copy(), result.qd, {}, "rk4")
    bad.q[4, 0] = np.nan
    with pytest.raises(ValueError, match=r"^result: expected finite coordinates to show, got nan in 'link\.ry' at "
                                         r"t = 0\.04 s \(output 4\)"):
        rf.view(system, bad)
    with pytest.raises(ValueError, match=r"^result\[1\]: expected finite coordinates"):
        rf.view([result, bad])
    with pytest.raises(ValueError, match=r"^q: expected finite coordinates to show, got inf in .link\.ry."):
        rf.view(system, q=[np.inf])
    result.to_npz(tmp_path / "run.npz")
    with pytest.raises(ValueError, match=r"^result: expected a Result with its System for the 3D view"):
        rf.view(rf.load_npz(tmp_path / "run.npz"))
    import pickle
    modes = pickle.loads(pickle.dumps(rf.modal_analysis(system)))
    with pytest.raises(ValueError, match=r"^system: expected the System the modes are of \(rf\.view\(system, modes\)\)"):
        rf.view(modes)
    assert rf.view(system, modes).frames == 48
    with pytest.raises(ValueError, match=r"^result: expected a Result or a non-empty sequence"):
        rf.view(system, [])


def test_the_picture_shows_deformation_colours_modes_overlays_and_arrows(stiff, tmp_path):
    """In Chromium: the stiff cantilever's tip is drawn level with its clamp at scale 1 and far below it at 100; coloured
    by bending moment, its clamped end's colour differs from its free end's; a mode's quarter period differs from
    its start; two overlaid runs show both palettes; the crane's arrows draw; the snapshot button saves a PNG of the
    picture; a URDF arm's yellow base box, magenta STL cube and cyan STL cube show in their colours from left to right
    (x runs to the right), and without its mesh files the cubes are gone and the forearm's inertia box is drawn."""
    from test_urdf import write_meshed_robot

    system, _, q = stiff
    runs = _kane_pair()
    crane = _crane()
    arms = [rf.Model.from_urdf(write_meshed_robot(tmp_path / name, mesh_dir=meshes)).compile()
            for name, meshes in (("arm", None), ("lost", tmp_path / "elsewhere" / "meshpkg" / "meshes"))]
    pages = [(rf.view(system, q=q).to_html(tmp_path / "one.html"), "helpers=0&shots=0"),
             (rf.view(system, q=q, scale=100, color="bending_moment").to_html(tmp_path / "hundred.html"),
              "helpers=0&shots=0"),
             (rf.view(rf.modal_analysis(system, q=q), mode=(0, 1)).to_html(tmp_path / "modes.html"),
              "helpers=0&shots=0,12"),
             (rf.view(runs, labels=["nonlinear", "linear"]).to_html(tmp_path / "both.html"), "helpers=0&shots=25"),
             (rf.view(*crane[:2], forces=True, color="bending_moment", scale=20).to_html(tmp_path / "crane.html"),
              "shots=-1&click=snapshot&download=0")]
    pages += [(rf.view(arm).to_html(tmp_path / f"arm{k}.html"), "helpers=0&shots=0") for k, arm in enumerate(arms)]
    one, hundred, modes, both, crane_state, arm, lost = _open_pages(pages, tmp_path)
    for state in (one, hundred, modes, both, crane_state, arm, lost):
        assert "error" not in state, state.get("error")
    drops = []  # how far the tip's end of the picture's beam is below its clamped end (pixel rows)
    for s in (one, hundred):
        ink = _ink(_image(s["shot0"]))
        *_, left, right = _box(ink)
        rows = [np.flatnonzero(ink[:, c0:c1].any(axis=1)).mean() for c0, c1 in ((left, left + 10), (right - 9, right + 1))]
        drops.append(rows[1] - rows[0])
    assert abs(drops[0]) < 6 and drops[1] > 40, drops
    img = _image(hundred["shot0"])
    ink = _ink(img)
    *_, left, right = _box(ink)
    ends = [img[:, c0:c1][ink[:, c0:c1]].mean(axis=0) for c0, c1 in ((left, left + 12), (right - 12, right + 1))]
    assert np.linalg.norm(ends[0] - ends[1]) > 100, ends  # yellow (high |M|) at the clamp, purple at the tip
    assert not np.array_equal(_image(modes["shot0"]), _image(modes["shot1"]))
    img = _image(both["shot0"]).astype(int)
    orange = (img[..., 0] > img[..., 1] + 40) & (img[..., 1] > img[..., 2] + 20)
    teal = (img[..., 1] > img[..., 0] + 40) & (img[..., 2] > img[..., 0] + 30)
    assert orange.sum() > 20 and teal.sum() > 20, (orange.sum(), teal.sum())
    assert crane_state.get("snapshots") == "1" and _ink(_image(crane_state["shot0"])).sum() > 1000
    assert crane_state["snapshot"] == "rigidfem_30.png data:image/png;base64,"  # the button's file: title_frame.png
    regions = []
    for state in (arm, lost):
        img = _image(state["shot0"]).astype(int)
        r, g, b = img[..., 0], img[..., 1], img[..., 2]
        regions.append({"yellow": (r > b + 50) & (g > b + 50), "magenta": (r > g + 50) & (b > g + 50),
                        "cyan": (g > r + 60) & (b > r + 60) & (abs(g - b) < 30), "blue": (b > g + 40) & (b > r + 80)})
    shown, missing = regions
    counts = {k: int(v.sum()) for k, v in shown.items()}
    assert min(counts.values()) > 200, counts
    columns = [np.flatnonzero(shown[k].any(axis=0)).mean() for k in ("yellow", "magenta", "cyan")]
    assert columns == sorted(columns), columns
    assert missing["magenta"].sum() == 0 and missing["cyan"].sum() == 0 and missing["yellow"].sum() > 200
    assert missing["blue"].sum() > counts["blue"] + 200, (int(missing["blue"].sum()), counts)  # the forearm's box


def test_the_widget_shows_as_the_page_where_no_widget_runs(kane, tmp_path):
    """Rendered as static HTML (nbconvert, the site: no widget manager), the widget's output is its text/html, the
    page with its frames in an iframe, which draws the scene; its text is a line naming it, not an object's address."""
    pytest.importorskip("anywidget")
    *_, viewer, _ = kane
    w = viewer.widget()
    data, _ = w._repr_mimebundle_()
    assert data["text/plain"] == repr(w) == "<rigidfem Viewer widget: 401 frames, frame 0 shown>"
    assert "application/vnd.jupyter.widget-view+json" in data and data["text/html"].startswith("<iframe srcdoc=")
    page = tmp_path / "static.html"
    page.write_text(f"""<!DOCTYPE html><html><body>{data['text/html']}<script>
function copy() {{
  const d = document.querySelector("iframe").contentDocument;
  if (d && d.body && d.body.dataset.ready) {{ d.defaultView.rigidfemProbe(); Object.assign(document.body.dataset, d.body.dataset); }}
  else setTimeout(copy, 100);
}}
window.addEventListener("load", copy);
</script></body></html>""", encoding="utf-8")
    state = _open(page, "")
    assert "error" not in state and state.get("ready") == "1" and int(state["ink"]) > 500, state


#: The largest a committed notebook may be (bytes): a page of the viewer adds 0.33-0.42 MB (its scripts packed, 0.25
#: MB, and the frames), so a notebook shows one viewer and a few figures.
NOTEBOOK_BYTES = 1_200_000


def test_the_notebooks_show_the_viewer_and_stay_small():
    """Notebooks 06 (the crane), 09 (modes), 11 (Kane) and 12 (the whippy strip) are committed with a viewer's page
    in an output (an iframe whose frames are embedded: it shows on the site and in any notebook viewer that runs
    HTML), and every notebook is below NOTEBOOK_BYTES."""
    import json
    from pathlib import Path

    folder = Path(__file__).resolve().parents[1] / "notebooks"
    for name in ("06_offshore_crane", "09_cantilever_frequencies", "11_kane", "12_whippy_beam"):
        cells = json.loads((folder / f"{name}.ipynb").read_text(encoding="utf-8"))["cells"]
        pages = ["".join(o.get("data", {}).get("text/html", "")) for c in cells if c["cell_type"] == "code"
                 for o in c.get("outputs", [])]
        pages = [p for p in pages if "window.RIGIDFEM" in p]
        assert len(pages) == 1 and "rigidfemUnpack(" in pages[0], name  # its scripts packed
    sizes = {p.name: p.stat().st_size for p in folder.glob("*.ipynb")}
    assert max(sizes.values()) < NOTEBOOK_BYTES, sizes
