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
    // The eigenvalues of a in closed form (Hairer & Wanner IV.8, radau5.f): one real, u = (6 + ∛81 − ∛9)/30, and
    // α ± iβ with α = (12 − ∛81 + ∛9)/60, β = √3 (∛81 + ∛9)/60. (An EigenSolver here would cost each file that
    // includes this header seconds of compile time.)
    const double c81 = std::cbrt(81.0), c9 = std::cbrt(9.0);
    d << (6 + c81 - c9) / 30, std::complex<double>((12 - c81 + c9) / 60, std::sqrt(3.0) * (c81 + c9) / 60), 0;
    d(2) = std::conj(d(1));
    // Each eigenvector spans the null space of a − λI (rank 2): v = r₀ × r₁ of two of its rows, unconjugated
    // (r₀ · v = r₁ · v = 0; Eigen's cross() conjugates complex results).
    for (int k = 0; k < 2; ++k) {
      const Eigen::Matrix3cd m = a.cast<std::complex<double>>() - d(k) * Eigen::Matrix3cd::Identity();
      const Eigen::Vector3cd v(m(0, 1) * m(1, 2) - m(0, 2) * m(1, 1), m(0, 2) * m(1, 0) - m(0, 0) * m(1, 2),
                               m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0));
      P.col(k) = v / v.norm();
    }
    P.col(2) = P.col(1).conjugate();
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
