/// Radau IIA of order 5 (implicit_rk.cpp) as the adjoint (adjoint.hpp) drives it: its tableau, the converged
/// stages of a step, and its state to keep at checkpoints and to start again from.
#pragma once

#include <cmath>

#include "rigidfem/system.hpp"

namespace rigidfem {

/// The tableau: c, a, and a = P diag(d) P⁻¹ (the transformed real/complex form of Hairer & Wanner IV.8).
struct RadauTableau {
  static constexpr int s = 3;
  Eigen::Matrix3d a;
  Eigen::Vector3d c, dd;       // dd: the estimate's weights on the stage increments (Y_i − y_n)/h
  Eigen::Matrix3cd P, Pinv;    // a = P diag(d) P⁻¹
  Eigen::Vector3cd d;          // d(0) real, d(2) = conj d(1), Im d(1) > 0
  RadauTableau();  // radau.cpp: d, P and P⁻¹ as constants
};

/// What a radau5 stepper shows besides the Stepper interface.
class RadauAccess {
 public:
  virtual ~RadauAccess() = default;
  /// The converged stages Q, V, A (nq, 3) of the last attempted step, at t + c_i h.
  virtual void stages(MatX& Q, MatX& V, MatX& A) const = 0;
  /// The converged stages' multipliers Λ (nl, 3) of the last attempted step (closed loops).
  virtual void stage_multipliers(MatX& L) const = 0;
  /// q, q̇, q̈ after the last accepted step.
  virtual void current(VecX& q, VecX& v, VecX& a) const = 0;
  /// Makes (q, q̇, q̈) at t the current state (a checkpoint's; no Maxwell arms), without the last step's stages
  /// for the first iterate.
  virtual void restore(double t, const VecX& q, const VecX& v, const VecX& a) = 0;
};

}  // namespace rigidfem
