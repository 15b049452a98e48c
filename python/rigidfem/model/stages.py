"""The named stages of forward dynamics, for looking inside the book's equations.

In outline (``system`` compiled, ``t, q, qd`` a state)::

    d = system.make_data()
    stages.set_state(system, d, t, q, qd)   # drives evaluated: d.qa, d.qda, d.qdda
    stages.kinematics(system, d)            # d.T, d.Td, d.Tdd (bodies), d.U (coordinates)
    f = stages.generalized_forces(system, d)  # loads − velocity terms − springs − dampers
    A = stages.mass_matrix(system, d)       # a_ij = Σ_p tr(T_p,i H_p T_p,jᵀ)
    qdd = stages.accelerations(system, d)   # A q̈ = f
    tau = stages.driving_forces(system, d)  # forces of the prescribed coordinates

Examples
--------
>>> import rigidfem as rf
>>> model, h = rf.samples.pendulum()
>>> system = model.compile()
>>> data = system.make_data()
>>> rf.stages.set_state(system, data, 0.0, [0.5], [0.0])
>>> rf.stages.kinematics(system, data)
>>> rf.stages.mass_matrix(system, data).round(6)
array([[0.333333]])
"""

from .._core.stages import accelerations, driving_forces, generalized_forces, kinematics, mass_matrix, set_state

__all__ = ["accelerations", "driving_forces", "generalized_forces", "kinematics", "mass_matrix", "set_state"]
