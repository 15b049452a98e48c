"""The named stages of forward dynamics, for looking inside the book's equations.

>>> d = system.make_data()
>>> stages.set_state(system, d, t, q, qd)   # drives evaluated: d.qa, d.qda, d.qdda
>>> stages.kinematics(system, d)            # d.T, d.Td, d.Tdd (bodies), d.U (coordinates)
>>> f = stages.generalized_forces(system, d)  # loads − velocity terms − springs − dampers
>>> A = stages.mass_matrix(system, d)       # a_ij = Σ_p tr(T_p,i H_p T_p,jᵀ)
>>> qdd = stages.accelerations(system, d)   # A q̈ = f
>>> tau = stages.driving_forces(system, d)  # forces of the prescribed coordinates
"""

from . import _contract
from ._core import stages as _stages

set_state = _contract.guard("set_state", _stages.set_state, ("system", "data", "t", "q", "qd"), method=False)
kinematics = _contract.guard("kinematics", _stages.kinematics, ("system", "data"), method=False)
generalized_forces = _contract.guard("generalized_forces", _stages.generalized_forces, ("system", "data"),
                                     method=False)
mass_matrix = _contract.guard("mass_matrix", _stages.mass_matrix, ("system", "data"), method=False)
accelerations = _contract.guard("accelerations", _stages.accelerations, ("system", "data"), method=False)
driving_forces = _contract.guard("driving_forces", _stages.driving_forces, ("system", "data"), method=False)

__all__ = ["accelerations", "driving_forces", "generalized_forces", "kinematics", "mass_matrix", "set_state"]
