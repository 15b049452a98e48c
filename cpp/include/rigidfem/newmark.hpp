/// The Newmark family's stepper (newmark.cpp) as the adjoint (adjoint.hpp) drives it: its full state, to keep
/// at checkpoints and to start again from, and its coefficients, which the adjoint's recursion transposes.
#pragma once

#include <memory>

#include "rigidfem/dense_lu.hpp"
#include "rigidfem/stepper.hpp"

namespace rigidfem {

/// The state the method carries from step to step (generalised-α in the form of Arnold & Brüls, newmark.cpp).
struct NewmarkState {
  VecX q, v, qdd, a, lambda;  // lambda (nl): the loops' multipliers at the same time
  VecX s;                     // (nz) the Maxwell arms' forces
  MatX Sq, Sv, Sqdd, Sa, Slambda;  // (nq, P) and (nl, P): their derivatives by each parameter (sensitivities.hpp)
};

/// The coefficients of (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) q̈_{n+1} + α_f q̈_n,
/// q_{n+1} = q_n + h q̇_n + h² [(½ − β) a_n + β a_{n+1}], q̇_{n+1} = q̇_n + h [(1 − γ) a_n + γ a_{n+1}].
struct NewmarkCoefficients {
  double am, af, beta, gamma;
};

class NewmarkStepper : public Stepper {
 public:
  /// The state after the last accepted step (or start).
  virtual const NewmarkState& current() const = 0;
  /// Makes s, at time t, the current state (a checkpoint's: the steps from it repeat the run's).
  virtual void restore(double t, const NewmarkState& s) = 0;
  virtual NewmarkCoefficients coefficients() const = 0;
  /// Its Newton matrix's dense factorisation now (NewtonMatrix::dense_factor), or none.
  virtual std::shared_ptr<const DenseLU> dense_factor() const = 0;
};

/// newmark, hht, generalized_alpha or implicit_spring by o.method.
std::unique_ptr<NewmarkStepper> make_newmark_stepper(const System& sys, const IntegratorOptions& o,
                                                     IntegratorStats& stats);

}  // namespace rigidfem
