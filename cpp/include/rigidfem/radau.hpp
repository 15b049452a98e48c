/// Radau IIA of order 5 (implicit_rk.cpp) as the adjoint (adjoint.hpp) drives it: its tableau, the converged
/// stages of a step, and its state to keep at checkpoints and to start again from.
#pragma once

#include <cmath>
#include <complex>

#include "rigidfem/system.hpp"

namespace rigidfem {

/// The tableau: c, a, and a = P diag(d) P⁻¹ (the transformed real/complex form of Hairer & Wanner IV.8).
struct RadauTableau {
  static constexpr int s = 3;
  Eigen::Matrix3d a;
  Eigen::Vector3d c, dd;       // dd: the estimate's weights on the stage increments (Y_i − y_n)/h
  Eigen::Matrix3cd P, Pinv;    // a = P diag(d) P⁻¹
  Eigen::Vector3cd d;          // d(0) real, d(2) = conj d(1), Im d(1) > 0
  RadauTableau() {
    const double r6 = std::sqrt(6.0);
    c << (4 - r6) / 10, (4 + r6) / 10, 1;
    a << (88 - 7 * r6) / 360, (296 - 169 * r6) / 1800, (-2 + 3 * r6) / 225,  //
        (296 + 169 * r6) / 1800, (88 + 7 * r6) / 360, (-2 - 3 * r6) / 225,   //
        (16 - r6) / 36, (16 + r6) / 36, 1.0 / 9;
    dd << -(13 + 7 * r6) / 3, (-13 + 7 * r6) / 3, -1.0 / 3;
    // d and P are the eigenvalues and unit eigenvectors of a as Eigen 3.4's EigenSolver<Matrix3d> gives them,
    // ordered (real, Im > 0, Im < 0) and written to 17 digits (round trip): the solver cost each file including
    // this header about 7 s of compile time. Their complex phase is the solver's on purpose: eigenvectors of
    // another phase, equal in exact arithmetic, made radau5's sensitivity to a mass fail on a planar chain whose
    // sensitivity is exactly zero (tests/fuzz_corpus/rejected_valid_rf_simulate_valueerror_qdd.json).
    using C = std::complex<double>;
    d << 0.2748888295956774, C(0.16255558520216135, 0.18494932440714107), C(0.16255558520216135, -0.18494932440714107);
    P << 0.091232394870892949, C(0.019609325891978956, -0.12985650041870567),
        C(0.019609325891978956, 0.12985650041870567),  //
        0.24171793270710715, C(-0.33657437071791418, 0.20604780684206114),
        C(-0.33657437071791418, -0.20604780684206114),  //
        0.96604818261509295, C(0.054163279153804665, 0.90778912589862681),
        C(0.054163279153804665, -0.90778912589862681);
    Pinv = P.inverse();
  }
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
