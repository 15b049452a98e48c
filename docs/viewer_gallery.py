"""The 3D viewer's pages of the site's gallery (docs/gallery.md), written by ``docs/conf.py`` into the built
site's ``viewer/`` folder at each build: each a standalone page of ``rf.view`` (three.js inside, nothing fetched).

Each model is small and its run short (the four pages take about a second and 4 MB)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import rigidfem as rf


def strip():
    """The README's quick start: a steel strip clamped at the ground, released from rest under gravity -y; its
    deformation magnified 5 times and its sdes coloured by their bending moment."""
    model = rf.Model(gravity=(0.0, -9.81, 0.0))
    beam = model.add_beam("strip", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0),
                          rf.Section.rectangle(0.005, 0.02), 20, deform="bend_z")
    system = model.compile()
    result = rf.simulate(system, 2.0, t_eval=np.linspace(0.0, 2.0, 201))
    return rf.view(system, result, trails=[beam.tip], scale=5.0, color="bending_moment",
                   title="README strip, deformation x5")


def four_bar():
    """``rf.samples.four_bar`` released from an assembled position, the coupler's midpoint traced."""
    model, h = rf.samples.four_bar()
    system = model.compile()
    q0, _ = system.assemble([0.4, -1.9, 4.6])
    result = rf.simulate(system, 4.0, q0=q0, t_eval=np.linspace(0.0, 4.0, 201))
    return rf.view(system, result, trails=[h["coupler"].point((0.4, 0.0, 0.0))], title="four-bar")


def kane():
    """Kane's beam spun up to 6 rad/s: the nonlinear and the linear model overlaid until the linear one diverges."""
    runs, tips = [], []
    for linear in (False, True):
        model, h = rf.samples.kane_beam(omega=6.0, duration=15.0, elements=10, linear=linear)
        system = model.compile()
        runs.append(rf.simulate(system, 6.0, t_eval=np.linspace(0.0, 6.0, 121)))
        tips.append(h["beam"].tip)
    return rf.view(runs, labels=["nonlinear", "linear"], trails=tips[:1], title="Kane's beam, nonlinear and linear")


def modes():
    """The first three modes of a cantilever bending in both planes and twisting."""
    model = rf.Model(gravity=None)
    model.add_beam("beam", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0, nu=0.3),
                   rf.Section(A=1e-4, Iy=2e-12, Iz=1e-12, J=3e-12), 10, deform=("bend_y", "bend_z", "torsion"))
    return rf.view(rf.modal_analysis(model.compile()), mode=(0, 1, 2), title="cantilever modes")


PAGES = {"strip": strip, "four_bar": four_bar, "kane": kane, "modes": modes}


def write(folder) -> list[Path]:
    """Writes every page into ``folder`` as <name>.html; returns their paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    return [make().to_html(folder / f"{name}.html") for name, make in PAGES.items()]
