"""Peer codes (benchmarks/peers.py of the checkout; pip install pin mujoco): equivalent chains
in Pinocchio and MuJoCo. Moved here from the package (formerly ``rigidfem.peers``)."""

import sys
from pathlib import Path

import numpy as np
import pytest

import rigidfem as rf
from rigidfem import Joint, transform

pinocchio = pytest.importorskip("pinocchio")
mujoco = pytest.importorskip("mujoco")

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import peers  # noqa: E402


@pytest.fixture(scope="module")
def beam():
    model, beam = peers.cantilever(4)
    return model.compile(), beam


def test_describe_reads_the_beam(beam):
    system, handle = beam
    chain = peers.describe(system)
    assert chain.nq == 12 and [link.coordinates for link in chain.links] == [()] + [("rz", "ry", "rx")] * 4
    for link, sde in zip(chain.links[1:], handle.sde):
        expected = [sde.stiffness[d] for d in ("bend_z", "bend_y", "torsion")]
        np.testing.assert_allclose(link.stiffness, expected, rtol=1e-14)
        np.testing.assert_allclose(link.damping, [sde.damping[d] for d in ("bend_z", "bend_y", "torsion")], rtol=1e-12)
        np.testing.assert_array_equal(link.rest, 0.0)
    for link, rfe in zip(chain.links, handle.rfe):
        assert link.mass == pytest.approx(rfe.mass, rel=1e-14)
        np.testing.assert_allclose(link.inertia, rfe.inertia, rtol=1e-9, atol=1e-15)


def test_peers_match_the_beam(beam):
    system, _ = beam
    for errors in (peers.check_pinocchio(system), peers.check_pinocchio(system, spherical=True),
                   peers.check_mujoco(system)):
        assert errors["forward"] < 1e-11 and errors["backward"] < 1e-12


def test_peers_match_a_tree_with_translations_and_rest_values():
    model = rf.Model(gravity=(1.0, -2.0, -9.81))
    rng = np.random.default_rng(3)

    def add(name, parent, joint):
        R = transform(euler_zyx=rng.uniform(-1, 1, 3))[:3, :3]
        return model.add_body(name, parent, joint, mass=rng.uniform(0.5, 2), com=rng.uniform(-0.3, 0.3, 3),
                              inertia=R @ np.diag([0.3, 0.4, 0.5]) @ R.T,
                              placement=transform(rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)))

    a = add("a", model.ground, Joint.spherical(stiffness=[10, 20, 30], damping=0.5, rest=[0.1, -0.2, 0.3]))
    b = add("b", a, Joint.planar("zx", stiffness=5.0, damping=[0.1, 0.2, 0.3], rest=0.05))
    c = add("c", a, Joint.fixed())
    add("d", b, Joint.free(stiffness=3.0, damping=0.2))
    add("e", c, Joint.universal(("x", "z"), stiffness=7.0, rest=[0.3, -0.1]))  # after d: MuJoCo orders e before d
    system = model.compile()
    chain = peers.describe(system)
    np.testing.assert_allclose(chain.rest[:6], [0.1, -0.2, 0.3, 0.05, 0.05, 0.05])
    for errors in (peers.check_pinocchio(system), peers.check_mujoco(system)):
        assert errors["forward"] < 1e-11


def test_a_hidden_load_is_caught():
    model, beam = peers.cantilever(3)
    model.add_force("push", beam.tip, (0.0, 0.0, 5.0))  # not visible on a System, so not in the peers' chains
    with pytest.raises(AssertionError, match="disagree"):
        peers.check_mujoco(model.compile())


def test_rk4_steps_the_same_in_both_codes():
    """Same model and same classical Runge-Kutta step: the same trajectory to rounding."""
    scene = peers.stiff_beam(2, t_end=0.02, outputs=3)
    table = peers.stiff_beam_accuracy(scene, [("rk4", "dt", [5e-5]), ("no_such_method", "dt", [1e-4])],
                                      [("RK4", "dt", [5e-5, 1e-3]), ("Euler", "dt", [1e-5])])
    rows = {(r["code"], r["method"], r["value"]): r for r in table.rows}
    ours, theirs = rows[("rigidfem", "rk4", 5e-5)], rows[("mujoco", "RK4", 5e-5)]
    assert ours["rel_error"] == pytest.approx(theirs["rel_error"], rel=1e-6)
    assert rows[("mujoco", "RK4", 1e-3)]["note"] == "unstable" and rows[("mujoco", "RK4", 1e-3)]["rel_error"] == np.inf
    assert rows[("rigidfem", "no_such_method", 1e-4)]["note"] == "not in this build"
    assert 0 < rows[("mujoco", "Euler", 1e-5)]["rel_error"] < 1e-2
    summary = peers.equal_accuracy(table, thresholds=(1e-3,))
    assert "| rigidfem | rk4 |" in summary.to_markdown()


def test_mjcf_joints_in_order(beam):
    system, handle = beam
    xml = peers.to_mjcf(peers.describe(system), {"tip": handle.tip})
    names = [line.split('name="')[1].split('"')[0] for line in xml.splitlines() if "<joint" in line]
    assert names == system.coordinate_names
    assert 'springref="0.0"' in xml and 'angle="radian"' in xml and '<site name="tip"' in xml


def test_missing_peer_names_the_install_command(monkeypatch, beam):
    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(ImportError, match=r"pip install pin mujoco"):
        peers.MujocoChain(peers.describe(beam[0]))
