"""Contact at scale: ``python -m benchmarks contact [--quick]``.

A steel strip of m rfes lying on the ground, one capsule per rfe against the ground's half-space (m + 1 pairs, all
touching): the cost of one forward dynamics (timed in C++) and of the force Jacobians (from Python) with and without
the contact, against m. The contacts' share grows linearly with m: the broad phase of a half-space against n shapes
is the n narrow tests themselves. Then two strips crossing, a contact between their two groups of capsules: sweep and
prune keeps the cost per capsule flat where the pairs grow as m². Last, a ball bouncing on the ground: the error at
a tolerance with the contact's onsets and separations located as events (the steps end there) and crossed by the
steps, and the error estimate's ratio to the true error.
"""

from __future__ import annotations

import time

import numpy as np

import rigidfem as rf
from rigidfem.studies.study import Table

from ._common import cpp_seconds_per_call, machine, report

SIZES = (10, 100, 1000)
QUICK_SIZES = (10, 100)


def strip_on_ground(m: int, contact: bool):
    """A 1 m strip (20 × 5 mm, 5 mm up) of m sdes on a free-floating root, its capsules resting on the ground."""
    model = rf.Model()
    strip = model.add_beam("strip", model.ground, 1.0, rf.Material(E=2.1e11, rho=7850.0), rf.Section.rectangle(0.02, 0.005),
                           m, joint=rf.Joint.free(), placement=rf.transform((0.0, 0.0, 0.004)))
    if contact:
        model.add_contact("on ground", model.add_shape("capsules", strip, rf.shapes.Capsules()),
                          model.add_shape("floor", model.ground, rf.shapes.HalfSpace()),
                          rf.laws.Contact(stiffness=1e7, exponent=1.0, restitution=0.5, impact_speed=0.1, mu_s=0.3,
                                          mu_k=0.3))
    return model.compile()


def contact_cost(sizes=SIZES) -> Table:
    rows = []
    for m in sizes:
        row = {"m": m}
        for contact in (False, True):
            s = strip_on_ground(m, contact)
            q, qd = np.zeros(s.nq), np.full(s.nq, 1e-3)
            key = "with" if contact else "without"
            row[f"fd_us_{key}"] = cpp_seconds_per_call(s, q, qd) * 1e6
            t0, n = time.perf_counter(), 3
            for _ in range(n):
                s.force_jacobians(0.0, q, qd)
            row[f"jac_ms_{key}"] = (time.perf_counter() - t0) / n * 1e3
            if contact:
                row["overlaps"] = len(s.contact_states(0.0, q, qd))
        row["fd_us_per_pair"] = (row["fd_us_with"] - row["fd_us_without"]) / (m + 1)
        rows.append(row)
    return Table(rows, ("m", "overlaps", "fd_us_without", "fd_us_with", "fd_us_per_pair", "jac_ms_without",
                        "jac_ms_with"))


def crossing_strips(m: int, contact: bool):
    """Two strips of m sdes crossing at right angles, one lying on the other, a capsule per rfe: one contact between
    the two groups of m + 1 capsules (sweep and prune)."""
    model = rf.Model()
    steel, section = rf.Material(E=2.1e11, rho=7850.0), rf.Section.circle(0.01)
    one = model.add_beam("one", model.ground, 1.0, steel, section, m, joint=rf.Joint.spherical())
    two = model.add_beam("two", model.ground, 1.0, steel, section, m, joint=rf.Joint.spherical(),
                         placement=rf.transform((0.5, -0.5, 0.0099), euler_zyx=(np.pi / 2, 0.0, 0.0)))
    if contact:
        model.add_contact("touch", model.add_shape("one's", one, rf.shapes.Capsules()),
                          model.add_shape("two's", two, rf.shapes.Capsules()), rf.laws.Contact(stiffness=1e7))
    return model.compile()


def crossing_cost(sizes=SIZES) -> Table:
    rows = []
    for m in sizes:
        row = {"m": m, "pairs": (m + 1) ** 2}
        for contact in (False, True):
            s = crossing_strips(m, contact)
            q, qd = np.zeros(s.nq), np.zeros(s.nq)
            row[f"fd_us_{'with' if contact else 'without'}"] = cpp_seconds_per_call(s, q, qd) * 1e6
            if contact:
                row["overlaps"] = len(s.contact_states(0.0, q, qd))
        row["contact_us_per_capsule"] = (row["fd_us_with"] - row["fd_us_without"]) / (2 * (m + 1))
        rows.append(row)
    return Table(rows, ("m", "pairs", "overlaps", "fd_us_without", "fd_us_with", "contact_us_per_capsule"))


def bouncing_ball(exponent: float):
    """A 2 kg ball of 0.1 m on a vertical slide over the ground under gravity: k = 1e6, e = 0.8 at 2 m/s."""
    model = rf.Model(gravity=(0.0, 0.0, -9.81))
    ball = model.add_body("ball", model.ground, rf.Joint.prismatic("z"), 2.0, (0.01, 0.01, 0.01),
                          placement=rf.transform((0.0, 0.0, 0.1)))
    model.add_contact("bounce", model.add_shape("shell", ball, rf.shapes.Sphere(0.1)),
                      model.add_shape("floor", model.ground, rf.shapes.HalfSpace()),
                      rf.laws.Contact(stiffness=1e6, exponent=exponent, restitution=0.8, impact_speed=2.0))
    return model.compile()


def impact_accuracy(methods=("dopri5", "radau5", "esdirk43"), rtols=(1e-4, 1e-6, 1e-8)) -> Table:
    """The ball dropped from 0.2 m for 1 s (three bounces): the height's largest error over 2001 outputs against a run
    at rtol = 1e-13, with the contact's onsets and separations located (the steps end there) and without (the steps
    cross them), and the error estimate (``Result.error_estimate``) over the true error."""
    rows = []
    t_eval = np.linspace(0.0, 1.0, 2001)
    for exponent in (1.0, 1.5):
        s = bouncing_ball(exponent)
        truth = rf.simulate(s, 1.0, "dopri5", q0=[0.2], rtol=1e-13, atol=1e-15, t_eval=t_eval).q[:, 0]
        for method in methods:
            for rtol in rtols:
                row = {"p": exponent, "method": method, "rtol": rtol}
                for located in (True, False):
                    r = rf.simulate(s, 1.0, method, q0=[0.2], rtol=rtol, atol=1e-2 * rtol, t_eval=t_eval,
                                    contact_events=located)
                    error = np.abs(r.q[:, 0] - truth).max()
                    key = "located" if located else "crossed"
                    row[f"steps_{key}"], row[f"error_{key}"] = r.stats["steps"], error
                    row[f"estimate_over_error_{key}"] = np.abs(r.error_estimate.of(lambda x: x.q[:, 0])).max() / error
                rows.append(row)
    return Table(rows, ("p", "method", "rtol", "steps_located", "error_located", "estimate_over_error_located",
                        "steps_crossed", "error_crossed", "estimate_over_error_crossed"))


def run(output_dir="bench", quick: bool = False) -> dict:
    print(machine())
    return report({"contact_cost": ("Contact, its cost on a strip: one forward dynamics (µs, in C++) and the force Jacobians (ms, from "
                                    "Python) of a strip of m rfes on the ground, without and with a capsule per rfe against it",
                                    contact_cost(QUICK_SIZES if quick else SIZES)),
                   "contact_groups": ("Contact between two bodies' groups: one forward dynamics (µs, in C++) of two strips of m rfes "
                                      "crossing, one on the other, without and with a contact between their capsules (sweep and "
                                      "prune over (m + 1)² pairs)", crossing_cost(QUICK_SIZES if quick else SIZES)),
                   "impact_accuracy": ("Impacts located: a ball bouncing three times, the height's error (m) at the same tolerance with "
                                       "the contact's onsets and separations located and crossed, and the error "
                                       "estimate over the true error",
                                       impact_accuracy(("dopri5",), (1e-6,)) if quick else impact_accuracy())},
                  output_dir)
