"""The 3D viewer at scale: ``python -m benchmarks viewer [--quick]``.

For Kane's spin-up beam with m rfes and F output frames: the time to build the scene (s), the size of
the exported HTML file (MB), and the time to show one frame (ms: every frame shown once, as playing
does, in headless Chromium with software WebGL, SwiftShader, 800 × 600; a GPU is faster). Needs
Debian's ``chromium`` on the PATH. Then the scene of a long chain against its number of bodies (build
time per frame and per body and frame: linear), and a URDF double pendulum whose three links are drawn by
binary STL meshes of n triangles in all: the time to read the file and its meshes (s), to build the scene
(s), the triangles the page holds (at most ``rigidfem.viz.viewer.MAX_TRIANGLES``), its size (MB) and the time
per frame (ms).
"""

from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import rigidfem as rf
from rigidfem.studies.study import Table
from rigidfem.viz.viewer import _packed

from ._common import machine, report

CASES = ((20, 401), (80, 401), (20, 2001), (320, 401))
QUICK_CASES = ((20, 101),)
#: Triangles of the URDF pendulum's three meshes together.
MESH_CASES = (30_000, 300_000, 1_200_000)


def _ms_per_frame(path: Path) -> float:
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser is None:
        return float("nan")
    run = subprocess.run([browser, "--headless", "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
                          "--enable-unsafe-swiftshader", "--window-size=800,600", "--dump-dom",
                          f"{path.as_uri()}#bench=1"], capture_output=True, text=True, timeout=600)
    found = re.search(r'data-ms-per-frame="([\d.]+)"', run.stdout)
    return float(found.group(1)) if found else float("nan")


def viewer_scaling(cases=CASES) -> Table:
    _packed()  # the scripts packed once per process, not in the first case's build time
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for m, frames in cases:
            model, h = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=m)
            system = model.compile()
            result = rf.simulate(system, 20.0, method="generalized_alpha", dt=0.01,
                                 t_eval=np.linspace(0.0, 20.0, frames))
            t0 = time.perf_counter()
            viewer = rf.view(system, result, trails=[h["beam"].tip])
            path = viewer.to_html(Path(folder) / f"kane_{m}_{frames}.html")
            build = time.perf_counter() - t0
            rows.append({"m": m, "bodies": system.nbodies, "frames": frames, "build_s": build,
                         "file_MB": path.stat().st_size / 1e6, "ms_per_frame": _ms_per_frame(path)})
    return Table(rows, ("m", "bodies", "frames", "build_s", "file_MB", "ms_per_frame"))


def body_scaling(elements=(1000, 2000, 10000, 100000), frames: int = 10) -> Table:
    """The scene of a long chain (a cantilever of m rfes, m + 1 bodies) at ``frames`` frames: the time to
    build it (s), per frame (ms) and per body and frame (µs): linear in the bodies."""
    rows = []
    for m in elements:
        model, _ = rf.samples.cantilever(elements=m, deform=("bend_z",))
        system = model.compile()
        t = np.linspace(0.0, 1.0, frames)
        q = np.random.default_rng(0).uniform(-1e-4, 1e-4, (frames, system.nq))
        result = rf.Result(system, t, q, np.zeros_like(q), {}, "none")
        start = time.perf_counter()
        viewer = rf.view(system, result)
        build = time.perf_counter() - start
        rows.append({"bodies": system.nbodies, "frames": viewer.frames, "build_s": build,
                     "ms_per_frame": 1e3 * build / viewer.frames,
                     "us_per_body_frame": 1e6 * build / (viewer.frames * system.nbodies)})
    return Table(rows, ("bodies", "frames", "build_s", "ms_per_frame", "us_per_body_frame"))


def _sphere_stl(path: Path, triangles: int) -> None:
    """A binary STL of a unit sphere of about ``triangles`` triangles (latitude-longitude, 2 n² of them)."""
    n = max(4, int(np.sqrt(triangles / 2)))
    theta, phi = np.meshgrid(np.linspace(0, np.pi, n + 1), np.linspace(0, 2 * np.pi, n + 1), indexing="ij")
    v = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1).reshape(-1, 3)
    k = np.arange(n * (n + 1)).reshape(n, n + 1)[:, :n].ravel()
    t = np.r_[np.c_[k, k + n + 1, k + 1], np.c_[k + 1, k + n + 1, k + n + 2]]
    facets = np.zeros(len(t), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    facets["v"] = v[t]
    path.write_bytes(b"sphere".ljust(80) + np.uint32(len(t)).tobytes() + facets.tobytes())


def mesh_scaling(cases=MESH_CASES, frames: int = 401) -> Table:
    """A double pendulum from URDF (links 0.5 m, joints about y, swinging 4 s under gravity) whose base and two
    links are drawn by spheres (stretched along the links) of ``triangles`` / 3 each, in binary STL."""
    inertia = '<inertia ixx="0.002" iyy="0.04" izz="0.04" ixy="0" ixz="0" iyz="0"/>'
    link = ('<link name="{0}"><inertial><origin xyz="0.25 0 0"/><mass value="1"/>' + inertia + '</inertial>'
            '<visual><origin xyz="0.25 0 0"/><geometry><mesh filename="sphere.stl" scale="0.25 0.05 0.05"/>'
            '</geometry></visual></link>')
    text = ('<robot name="pendulum"><link name="base"><visual><geometry><mesh filename="sphere.stl" '
            'scale="0.08 0.08 0.08"/></geometry></visual></link>' + link.format("upper") + link.format("lower")
            + '<joint name="a" type="continuous"><parent link="base"/><child link="upper"/><axis xyz="0 1 0"/>'
            '</joint><joint name="b" type="continuous"><parent link="upper"/><child link="lower"/>'
            '<origin xyz="0.5 0 0"/><axis xyz="0 1 0"/></joint></robot>')
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for triangles in cases:
            _sphere_stl(Path(folder) / "sphere.stl", triangles // 3)
            (Path(folder) / "pendulum.urdf").write_text(text)
            t0 = time.perf_counter()
            model = rf.Model.from_urdf(Path(folder) / "pendulum.urdf")
            read = time.perf_counter() - t0
            system = model.compile()
            result = rf.simulate(system, 4.0, q0=[0.3, 0.5], t_eval=np.linspace(0.0, 4.0, frames))
            t0 = time.perf_counter()
            viewer = rf.view(system, result)
            path = viewer.to_html(Path(folder) / f"pendulum_{triangles}.html")
            build = time.perf_counter() - t0
            rows.append({"triangles": 3 * (triangles // 3), "read_s": read, "build_s": build,
                         "drawn": sum(v.get("triangles", 0) for v in viewer.data["visuals"]), "frames": frames,
                         "file_MB": path.stat().st_size / 1e6, "ms_per_frame": _ms_per_frame(path)})
    return Table(rows, ("triangles", "read_s", "build_s", "drawn", "frames", "file_MB", "ms_per_frame"))


def run(output_dir="bench", quick: bool = False) -> dict:
    print(machine(), flush=True)
    return report({"viewer_scaling": ("The 3D viewer, its cost: build time, file size, time per frame shown",
                                      viewer_scaling(QUICK_CASES if quick else CASES)),
                   "viewer_bodies": ("The 3D viewer against the number of bodies: the scene's build only",
                                     body_scaling((1000, 2000) if quick else (1000, 2000, 10000, 100000))),
                   "viewer_meshes": ("The 3D viewer with meshes: a URDF robot drawn by its STL meshes",
                                     mesh_scaling(MESH_CASES[:1] if quick else MESH_CASES))},
                  output_dir)
