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
  RadauTableau() {
    const double r6 = std::sqrt(6.0);
    c << (4 - r6) / 10, (4 + r6) / 10, 1;
    a << (88 - 7 * r6) / 360, (296 - 169 * r6) / 1800, (-2 + 3 * r6) / 225,  //
        (296 + 169 * r6) / 1800, (88 + 7 * r6) / 360, (-2 - 3 * r6) / 225,   //
        (16 - r6) / 36, (16 + r6) / 36, 1.0 / 9;
    dd << -(13 + 7 * r6) / 3, (-13 + 7 * r6) / 3, -1.0 / 3;
    // (An EigenSolver: about 7 s of compile time in each translation unit that includes this header, which the
    // build keeps to one, the adjoint's group. A closed form with eigenvectors of another complex phase, equal in
    // exact arithmetic, made radau5's sensitivities to a mass fail on a planar chain (tests/fuzz_corpus).)
    Eigen::EigenSolver<Eigen::Matrix3d> es(a);
    Eigen::Vector3cd ev = es.eigenvalues();
    Eigen::Matrix3cd V = es.eigenvectors();
    int real = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(ev(k).imag()) < std::abs(ev(real).imag())) real = k;
    const int up = ev((real + 1) % 3).imag() > 0 ? (real + 1) % 3 : (real + 2) % 3, down = 3 - real - up;
    const int order[3] = {real, up, down};
    for (int k = 0; k < 3; ++k) d(k) = ev(order[k]), P.col(k) = V.col(order[k]);
    d(0) = d(0).real();
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
