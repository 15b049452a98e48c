/// The 3-stage collocation methods (implicit_rk.cpp): their tableaus (Radau IIA, Gauss–Legendre), and what the
/// adjoint (adjoint.hpp) reads of a radau5 stepper: the converged stages of a step, and its state to keep at
/// checkpoints and to start again from.
#pragma once

#include <cmath>

#include "rigidfem/system.hpp"

namespace rigidfem {

/// A 3-stage collocation tableau: c, a, b, and a = P diag(d) P⁻¹ (the transformed real/complex form of Hairer &
/// Wanner IV.8), which Radau IIA and Gauss–Legendre share: one real eigenvalue and a complex pair.
struct CollocationTableau {
  static constexpr int s = 3;
  Eigen::Matrix3d a;
  Eigen::Vector3d c, b;
  Eigen::Vector3d dd;          // Radau IIA: the estimate's weights on the stage increments (Y_i − y_n)/h
  Eigen::Matrix3cd P, Pinv;    // a = P diag(d) P⁻¹
  Eigen::Vector3cd d;          // d(0) real, d(2) = conj d(1), Im d(1) > 0
  bool stiffly_accurate;       // b = the last row of a: the step ends at the last stage
};

/// Radau IIA, order 5: stiffly accurate, L-stable.
struct RadauTableau : CollocationTableau {
  RadauTableau();  // radau.cpp: d, P and P⁻¹ as constants
};

/// Gauss–Legendre, order 6: symmetric, A-stable (|R(iy)| = 1: an undamped oscillation keeps its amplitude); the
/// step ends at y_n + h Σ b_i f(Y_i).
struct GaussTableau : CollocationTableau {
  GaussTableau();  // radau.cpp: d, P and P⁻¹ as constants
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
