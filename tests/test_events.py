"""Events (rf.simulate(..., events=[...])): roots located on the dense output against closed forms, terminal
runs, directions, the event time's sensitivity against central differences of whole runs, the contacts' onsets
and separations, and bad input named."""

import dataclasses
import math

import numpy as np
import pytest

import rigidfem as rf
from test_contact import drop

G = 9.81


def oscillator(k=4.0, m=1.0):
    """A mass on a prismatic z joint with a spring k: z = A cos(ω t), ω = √(k/m), no gravity."""
    model = rf.Model(gravity=(0.0, 0.0, 0.0))
    body = model.add_body("mass", model.ground, rf.Joint.prismatic("z", stiffness=k), m, (0.1, 0.1, 0.1))
    return model.compile(), body


def falling(gravity=G):
    """A body on a vertical slide under gravity: z = z0 + v0 t − g t²/2."""
    model = rf.Model(gravity=(0.0, 0.0, -gravity))
    body = model.add_body("body", model.ground, rf.Joint.prismatic("z"), 1.0, (0.1, 0.1, 0.1))
    return model.compile(), body


@pytest.mark.parametrize("method", ["dopri5", "radau5", "esdirk43", "bs23", "dop853"])
def test_a_terminal_event_ends_a_fall_where_free_fall_says(method):
    """A coordinate, a point and a Python function crossing a level: t* = √(2 (z0 − h)/g), the run ends there."""
    system, body = falling()
    z0, h = 2.0, 0.5
    expected = math.sqrt(2.0 * (z0 - h) / G)
    for of, kw in (("body.z", {}), (body.point((0.3, 0.0, 0.0)), {"axis": "z"}),
                   (lambda t, q, qd: q[0], {})):
        event = rf.Event("low", of, value=h, direction=-1, terminal=True, **kw)
        r = rf.simulate(system, 5.0, method, q0=[z0], events=[event], rtol=1e-10, atol=1e-12)
        (fired,) = r.events
        assert fired.event == "low" and fired.direction == -1
        assert fired.t == pytest.approx(expected, abs=1e-10)
        assert r.t[-1] == fired.t and r.q[-1, 0] == pytest.approx(h, abs=1e-9)
        assert fired.qd[0] == pytest.approx(-G * expected, abs=1e-8)
    # with output times: those up to the root, none after
    r = rf.simulate(system, 5.0, method, q0=[z0], events=[event], t_eval=np.linspace(0.0, 5.0, 51))
    assert r.t[-1] <= expected < r.t[-1] + 0.1


def test_roots_in_one_direction_or_both_at_the_oscillators_zeros():
    """z = cos(2t): zeros at (j + 1/2) π/2, falling for even j, rising for odd; direction filters them."""
    system, _ = oscillator()
    kw = dict(q0=[1.0], rtol=1e-11, atol=1e-13)
    zeros = (np.arange(6) + 0.5) * math.pi / 2.0
    both = rf.simulate(system, 9.0, "dopri5", events=[rf.Event("zero", "mass.z")], **kw)
    assert np.abs(both.event_times("zero") - zeros).max() < 1e-9
    assert [f.direction for f in both.events] == [-1, 1, -1, 1, -1, 1]
    rising = rf.simulate(system, 9.0, "dopri5", events=[rf.Event("up", "mass.z", direction=1)], **kw)
    assert np.abs(rising.event_times("up") - zeros[1::2]).max() < 1e-9
    # a rate crossing: ż = −2 sin(2t) = −1 where sin(2t) = 1/2: at π/12 and 5π/12 within 3 s
    rate = rf.simulate(system, 3.0, "dopri5", events=[rf.Event("fast", "mass.z", value=-1.0, rate=True)], **kw)
    assert np.abs(rate.event_times("fast") - [math.pi / 12, 5 * math.pi / 12]).max() < 1e-9
    # fixed steps locate too (the grid kept): on rk4's dense output (cubic Hermite)
    fixed = rf.simulate(system, 9.0, "rk4", dt=1e-3, events=[rf.Event("zero", "mass.z")], q0=[1.0])
    assert np.abs(fixed.event_times("zero") - zeros).max() < 1e-9
    assert fixed.stats["steps"] == 9000


def test_the_event_times_sensitivity_agrees_with_differences_of_whole_runs():
    """dt*/dp = −(∂g/∂y S)/ġ against central differences of the located times: the fall's start (closed form
    1/(g t*)) and a contact's stiffness (the ball's separation after a bounce)."""
    system, _ = falling()
    event = rf.Event("low", "body.z", value=0.5, terminal=True)
    r = rf.simulate(system, 5.0, "dopri5", q0=[2.0], events=[event], sensitivities=["q0[body.z]"], rtol=1e-11,
                    atol=1e-13)
    t_star = r.events[0].t
    assert r.events[0].dt_dp["q0[body.z]"] == pytest.approx(1.0 / (G * t_star), rel=1e-7)

    law = rf.laws.Contact(stiffness=2e5, exponent=1.5, restitution=0.7, impact_speed=1.0)
    bounce = drop(law, gravity=G)
    up = rf.Event("up", "ball.z", value=0.01, direction=1, terminal=True)
    kw = dict(q0=[0.05], method="dopri5", rtol=1e-12, atol=1e-14, events=[up])
    r = rf.simulate(bounce, 1.0, sensitivities=["bounce.stiffness"], **kw)
    k, h = 2e5, 2e5 * 1e-4
    plus, minus = (rf.simulate(bounce.with_parameters({"bounce.stiffness": k + d}), 1.0, **kw).events[-1].t
                   for d in (h, -h))
    assert r.events[-1].event == "up"
    assert r.events[-1].dt_dp["bounce.stiffness"] == pytest.approx((plus - minus) / (2 * h), rel=1e-6)


@pytest.mark.parametrize("exponent", [1.0, 1.5])
def test_contacts_onsets_and_separations_are_located_and_keep_the_error_bar_honest(exponent):
    """A ball dropped from 0.2 m: the first onset at √(2 · 0.2/g) (free fall), onsets and separations alternating.
    Steps that end at each onset and separation: the error at the same tolerance is smaller than stepping across
    (10× for a linear law), and the error estimate is within 3× of the true error (a run at rtol = 1e-13)."""
    law = rf.laws.Contact(stiffness=1e6, exponent=exponent, restitution=0.8, impact_speed=2.0)
    system = drop(law, gravity=G)
    t_eval = np.linspace(0.0, 1.0, 2001)
    reference = rf.simulate(system, 1.0, "dopri5", q0=[0.2], rtol=1e-13, atol=1e-15, t_eval=t_eval)
    times = reference.event_times("bounce")
    assert times[0] == pytest.approx(math.sqrt(2 * 0.2 / G), abs=1e-10)
    assert [f.direction for f in reference.events] == [-1, 1] * (len(times) // 2) and len(times) >= 4
    errors = {}
    for located in (True, False):
        r = rf.simulate(system, 1.0, "dopri5", q0=[0.2], rtol=1e-6, atol=1e-8, t_eval=t_eval, contact_events=located)
        errors[located] = np.abs(r.q[:, 0] - reference.q[:, 0]).max()
        if located:
            assert r.stats["event_restarts"] >= len(times)
            estimated = np.abs(r.error_estimate.of(lambda x: x.q[:, 0])).max()
            assert errors[True] / 3 < estimated < 3 * errors[True]
        else:
            assert r.events == [] and r.stats["event_restarts"] == 0
    assert errors[True] < (0.1 if exponent == 1.0 else 0.5) * errors[False]


def test_a_terminal_runs_error_estimate_runs_to_its_end():
    """The error bar of a run ended by an event: its second run goes to the same end, at the same outputs, its events
    ending nothing, and the bar is within 10 times the true error (z = cos 2t) where that error is above round-off.
    A terminal event only the second run would see (the first run's coarser steps passed it) ends neither: the
    second run keeps the first's end (found by the fuzzer: the two runs' outputs had different lengths)."""
    system, _ = oscillator()
    event = rf.Event("zero", "mass.z", direction=1, terminal=True)
    r = rf.simulate(system, 9.0, "dopri5", q0=[1.0], events=[event], rtol=1e-6, error_estimate=True)
    assert r.t[-1] == pytest.approx(3 * math.pi / 4, abs=1e-6)
    second = r.estimate.reference
    assert np.array_equal(second.t, r.t)  # the same outputs, to the same end (the root is that end)
    bar, true = r.estimate.of(lambda x: x.q[:, 0]), np.abs(r.q[:, 0] - np.cos(2.0 * r.t))
    big = true > 1e-9
    assert big.sum() > 10 and np.all(bar[big] < 10 * true[big]) and np.all(bar[big] > true[big] / 10)
    # a level the coarse run steps over: the terminal event would end only the second run
    low = rf.Event("low", "mass.z", value=-0.9999, direction=-1, terminal=True)  # dt = 0.025 s sees it at 1.564 s
    coarse = rf.simulate(system, 2.0, "newmark", q0=[1.0], dt=0.05, events=[low])
    assert coarse.t[-1] == 2.0 and not coarse.events  # stepped over
    assert np.array_equal(coarse.error_estimate.reference.t, coarse.t)  # the second run does not stop at it


def test_bad_events_are_refused_by_name():
    system, body = falling()
    run = lambda *events, **kw: rf.simulate(system, 1.0, q0=[1.0], events=list(events), **kw)  # noqa: E731
    with pytest.raises(ValueError, match="events: expected a coordinate"):
        run(rf.Event("e", "nowhere"))
    with pytest.raises(ValueError, match="direction: expected -1, 0 or 1"):
        rf.Event("e", "body.z", direction=2)
    with pytest.raises(ValueError, match="axis: expected 'x', 'y', 'z' or a 3-vector for the point"):
        run(rf.Event("e", body.origin))
    with pytest.raises(ValueError, match="axis: expected None"):
        run(rf.Event("e", "body.z", axis="z"))
    with pytest.raises(ValueError, match="axis: expected a non-zero 3-vector"):
        run(rf.Event("e", body, axis=(0, 0, 0)))
    with pytest.raises(ValueError, match="events: expected events of different names"):
        run(rf.Event("e", "body.z"), rf.Event("e", "body.z", value=0.5))
    with pytest.raises(ValueError, match="events: expected a list of rigidfem.Event"):
        rf.simulate(system, 1.0, events=["body.z"])
    with pytest.raises(ValueError, match="method: expected a C.. method for a run with events"):
        run(rf.Event("e", "body.z"), method="scipy:RK45")
    with pytest.raises(ValueError, match="name: expected a non-empty str"):
        rf.Event("", "body.z")
    with pytest.raises(ValueError, match="events: expected the function of event 'e' to return a number"):
        run(rf.Event("e", lambda t, q, qd: "low"))
    with pytest.raises(ValueError, match="contact_events: expected True or False"):
        rf.simulate(system, 1.0, contact_events="yes")
    r = run(rf.Event("e", "body.z", value=0.5))
    with pytest.raises(ValueError, match="name: expected the name of one of the run's events"):
        r.event_times("f")
    assert dataclasses.replace(rf.Event("e", "body.z"), terminal=True).terminal


@pytest.mark.parametrize("method", ["dopri5", "radau5"])
def test_forward_sensitivities_through_located_impacts_agree_with_differences_of_whole_runs(method):
    """The forward sensitivities of the state after two bounces of a linear contact (every onset and separation
    located: the steps end on the old side, the next begins on the new, so that the sensitivities' equations take the
    Jacobian's jump from 0 to k where it happens) by the contact's stiffness, its restitution (a parameter the force is
    not linear in: differenced centrally) and the drop height, against central differences of whole runs: 1e-6
    (crossed by the steps instead: 1e-3). The compliant force is continuous at onset
    and separation, so the sensitivities themselves do not jump there."""
    law = rf.laws.Contact(stiffness=1e6, exponent=1.0, restitution=0.8, impact_speed=2.0)
    system = drop(law, gravity=G)
    kw = dict(method=method, rtol=1e-12, atol=1e-14, t_eval=[0.6])
    names = ["bounce.stiffness", "bounce.restitution", "q0[ball.z]"]
    r = rf.simulate(system, 0.6, q0=[0.2], sensitivities=names, **kw)
    assert len(r.event_times("bounce")) == 4 and r.stats["event_restarts"] >= 4
    for name, value in zip(names, (1e6, 0.8, 0.2)):
        h = 1e-4 * value
        ends = []
        for d in (h, -h):
            initial = name.startswith("q0")
            changed = system if initial else system.with_parameters({name: value + d})
            ends.append(rf.simulate(changed, 0.6, q0=[0.2 + (d if initial else 0.0)], **kw))
        dq, dqd = ((a - b)[-1, 0] / (2 * h) for a, b in ((ends[0].q, ends[1].q), (ends[0].qd, ends[1].qd)))
        S = r.sensitivity(name)
        assert S[0][-1, 0] == pytest.approx(dq, rel=1e-6)
        assert S[1][-1, 0] == pytest.approx(dqd, rel=1e-6)


def test_contacts_touching_at_the_same_instant_are_located_each_once():
    """Two balls dropped from the same height (and 1e-12 m apart) onto one floor, each its own contact: their onsets
    and separations come at the same instant; the steps end before them together and go on past them together, each
    event recorded once, onsets and separations alternating. A user's event on a contact's gap beside the contact's
    own, likewise."""
    model = rf.Model(gravity=(0.0, 0.0, -G))
    floor = model.add_shape("floor", model.ground, rf.shapes.HalfSpace())
    for i in range(2):
        ball = model.add_body(f"ball{i}", model.ground, rf.Joint.prismatic("z"), 2.0, (0.01, 0.01, 0.01),
                              placement=rf.transform((float(i), 0.0, 0.1)))
        model.add_contact(f"bounce{i}", model.add_shape(f"s{i}", ball, rf.shapes.Sphere(0.1)), floor,
                          rf.laws.Contact(stiffness=1e5, exponent=1.5, restitution=0.7))
    system = model.compile()
    for method in ("auto", "dopri5", "radau5", "esdirk43"):
        for dz in (0.0, 1e-12):
            r = rf.simulate(system, 1.0, method, q0=[0.5, 0.5 + dz])
            for name in ("bounce0", "bounce1"):
                directions = [f.direction for f in r.events if f.event == name]
                assert directions == [-1, 1] * 4, (method, dz, name, directions)
            np.testing.assert_allclose(r.event_times("bounce0"), r.event_times("bounce1"), atol=1e-9)
    r = rf.simulate(system, 1.0, "dopri5", q0=[0.5, 0.7], events=[rf.Event("gap", "bounce0")])
    np.testing.assert_allclose(r.event_times("gap"), r.event_times("bounce0"), atol=1e-12)
