/// The collocation methods (implicit_rk.cpp): their tableaus (Radau IIA of 3 and 5 stages, Gauss–Legendre), and what the
/// adjoint (adjoint.hpp) reads of a radau5 stepper: the converged stages of a step, and its state to keep at
/// checkpoints and to start again from.
#pragma once

#include <cmath>
#include <complex>

#include "rigidfem/system.hpp"

namespace rigidfem {

/// A collocation tableau of S stages (S odd): c, a, b, and a = P diag(d) P⁻¹ (the transformed real/complex form of
/// Hairer & Wanner IV.8), which Radau IIA and Gauss–Legendre share: one real eigenvalue, then (S − 1)/2 complex pairs.
template <int S>
struct CollocationTableau {
  static_assert(S % 2 == 1, "one real eigenvalue and complex pairs");
  static constexpr int s = S;
  using Real = Eigen::Matrix<double, S, 1>;
  using Complex = Eigen::Matrix<std::complex<double>, S, 1>;
  Eigen::Matrix<double, S, S> a;
  Real c, b;
  Real dd;                                        // Radau IIA: the estimate's weights on the stage increments (Y_i − y_n)/h
  Eigen::Matrix<std::complex<double>, S, S> P, Pinv;  // a = P diag(d) P⁻¹
  Complex d;            // d(0) real, then pairs d(2k + 2) = conj d(2k + 1), Im d(2k + 1) > 0
  bool stiffly_accurate;  // b = the last row of a: the step ends at the last stage
};

/// Radau IIA, 3 stages, order 5: stiffly accurate, L-stable.
struct RadauTableau : CollocationTableau<3> {
  RadauTableau();  // radau.cpp: d, P and P⁻¹ as constants
};

/// Radau IIA, 5 stages, order 9: stiffly accurate, L-stable.
struct Radau9Tableau : CollocationTableau<5> {
  Radau9Tableau();  // radau.cpp: every number as a constant
};

/// Gauss–Legendre, order 6: symmetric, A-stable (|R(iy)| = 1: an undamped oscillation keeps its amplitude); the
/// step ends at y_n + h Σ b_i f(Y_i).
struct GaussTableau : CollocationTableau<3> {
  GaussTableau();  // radau.cpp: d, P and P⁻¹ as constants
};

/// What a radau5 stepper shows besides the Stepper interface.
class RadauAccess {
 public:
  virtual ~RadauAccess() = default;
  /// The converged stages Q, V, A (nq, s) of the last attempted step, at t + c_i h.
  virtual void stages(MatX& Q, MatX& V, MatX& A) const = 0;
  /// The converged stages' multipliers Λ (nl, s) of the last attempted step (closed loops).
  virtual void stage_multipliers(MatX& L) const = 0;
  /// q, q̇, q̈ after the last accepted step.
  virtual void current(VecX& q, VecX& v, VecX& a) const = 0;
  /// Makes (q, q̇, q̈) at t the current state (a checkpoint's; no Maxwell arms), without the last step's stages
  /// for the first iterate.
  virtual void restore(double t, const VecX& q, const VecX& v, const VecX& a) = 0;
};

}  // namespace rigidfem
