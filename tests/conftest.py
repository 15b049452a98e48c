"""Shared helpers: integrate a compiled system with SciPy (the reference integrator here)."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp


def integrate(system, t_end, q0, qd0, *, rtol=1e-12, atol=1e-12, t_eval=None, events=None, method="DOP853"):
    """solve_ivp of system.rhs from (q0, qd0); returns the OdeResult (dense output on)."""
    y0 = np.concatenate([np.asarray(q0, float), np.asarray(qd0, float)])
    sol = solve_ivp(
        system.rhs, (0.0, t_end), y0, method=method, rtol=rtol, atol=atol, t_eval=t_eval, events=events,
        dense_output=True,
    )
    assert sol.success, sol.message
    return sol


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)
