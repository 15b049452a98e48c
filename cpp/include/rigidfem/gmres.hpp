/// Restarted GMRES(m): the Krylov form of Newton's matrix (newton_matrix.cpp) and the adjoint's transposed solves
/// (adjoint.cpp).
#pragma once

#include <cmath>
#include <complex>

#include "rigidfem/errors.hpp"
#include "rigidfem/system.hpp"

namespace rigidfem {

/// Restarted GMRES(m) with right preconditioning (Saad & Schultz; Saad, Iterative Methods, 9.3.2) in the
/// arithmetic of Scalar: x = P⁻¹ y minimising ‖b − S P⁻¹ y‖ over the Krylov space of S P⁻¹ from x = 0,
/// Arnoldi by modified Gram–Schmidt, the least-squares problem by Givens rotations. Stops when
/// ‖b − S x‖ <= rtol ‖b‖ or after max_iterations; returns the iterations taken.
template <class Scalar>
class Gmres {
  using VecS = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  using MatS = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;

 public:
  static constexpr int restart = 30;

  template <class Op, class Prec>
  int solve(const Op& S, const Prec& Pinv, const VecS& b, VecS& x, double rtol, int max_iterations) {
    const Eigen::Index n = b.size();
    V_.resize(n, restart + 1), H_.setZero(restart + 1, restart), g_.resize(restart + 1), cs_.resize(restart),
        sn_.resize(restart);
    x.setZero(n);
    first_cycle_ = true, y_.resize(0);
    const double bnorm = b.norm();
    if (bnorm == 0.0) return 0;
    r_ = b;
    int iterations = 0;
    bool converged = false;
    for (;;) {  // a cycle of at most `restart` Arnoldi steps from the residual r_
      const double beta = r_.norm();
      if (!(beta > rtol * bnorm)) return iterations;
      V_.col(0) = r_ / beta;
      g_.setZero();
      g_(0) = beta;
      H_.setZero();
      int j = 0;
      for (; j < restart && iterations < max_iterations; ++j, ++iterations) {
        interruption_point();
        Pinv(VecS(V_.col(j)), z_);
        S(z_, w_);
        for (int i = 0; i <= j; ++i) {  // h_ij = v_iᴴ w, w −= h_ij v_i
          H_(i, j) = V_.col(i).dot(w_);
          w_.noalias() -= H_(i, j) * V_.col(i);
        }
        const double h_next = w_.norm();
        H_(j + 1, j) = h_next;
        if (h_next > 0.0) V_.col(j + 1) = w_ / h_next;
        for (int i = 0; i < j; ++i) rotate(i, H_(i, j), H_(i + 1, j));
        // the rotation that zeroes h_{j+1,j}: c = |a|/t, s = (a/|a|) conj(b)/t, t = √(|a|² + |b|²)
        const Scalar a = H_(j, j), bb = H_(j + 1, j);
        const double t = std::sqrt(std::norm(a) + std::norm(bb));
        if (t == 0.0) {
          cs_(j) = 1.0, sn_(j) = Scalar(0);
        } else if (std::abs(a) == 0.0) {
          cs_(j) = 0.0, sn_(j) = Scalar(1);
        } else {
          cs_(j) = std::abs(a) / t, sn_(j) = (a / std::abs(a)) * conj(bb) / t;
        }
        rotate(j, H_(j, j), H_(j + 1, j));
        rotate(j, g_(j), g_(j + 1));
        if (!(std::abs(g_(j + 1)) > rtol * bnorm) || h_next == 0.0) {
          converged = true;
          ++j, ++iterations;
          break;
        }
      }
      // x += P⁻¹ V y, H y = g on the first j rows; |g_{j+1}| is the residual's norm (in exact arithmetic)
      const VecS y = H_.topLeftCorner(j, j).template triangularView<Eigen::Upper>().solve(g_.head(j));
      Pinv(VecS(V_.leftCols(j) * y), z_);
      x += z_;
      if (converged && first_cycle_) y_ = y;
      if (converged || iterations >= max_iterations || !x.allFinite()) {
        first_cycle_ = first_cycle_ && converged;
        return iterations;
      }
      first_cycle_ = false;
      S(x, w_);
      r_ = b - w_;
    }
  }

  /// After a solve that converged in its first cycle: y with x = Σ_i y_i z_i over the vectors z_i the operator was
  /// applied to, in the order it was (z_i = P⁻¹ v_i), so a linear map of x is the same combination of the maps of the
  /// z_i; empty when x = 0 (b = 0). False after a restart or a solve that did not converge.
  bool combination(VecS& y) const {
    if (!first_cycle_) return false;
    y = y_;
    return true;
  }

 private:
  static Scalar conj(const Scalar& z) { return Eigen::numext::conj(z); }
  /// [x; y] ← [c x + s y; −conj(s) x + c y] with rotation i.
  void rotate(int i, Scalar& x, Scalar& y) const {
    const Scalar xi = x;
    x = cs_(i) * xi + sn_(i) * y;
    y = -conj(sn_(i)) * xi + cs_(i) * y;
  }

  bool first_cycle_ = true;
  MatS V_, H_;
  VecS g_, sn_, r_, z_, w_, y_;
  Eigen::VectorXd cs_;
};

}  // namespace rigidfem
