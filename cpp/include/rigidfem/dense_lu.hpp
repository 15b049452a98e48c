/// LU factorisations with partial pivoting of the dense Newton matrices S (newton_matrix.hpp): P S = L U, L unit
/// lower, U upper, P the rows' permutation. Written out for the small systems the dense form mostly serves: at
/// n = 21 (the crane) Eigen's blocked PartialPivLU took 2.1 µs where the column loops below take 1.1, and the
/// complex factorisation in (re, im) pairs of complex<double> 4.5 µs where split into a real and an imaginary
/// matrix it takes 3.3 (its solve 0.92 against 0.61 µs). From dense_lu_blocked_from on the real one is Eigen's
/// (blocked: 52 against 80 µs at n = 100). Unlike LAPACK's, the loops take every pivot's reciprocal, also below the
/// smallest normal number (2.2e-308), where LAPACK divides: such matrices (unreachable for M + c₁ C + c₂ K) give NaN.
#pragma once

#include <complex>

#include "rigidfem/transforms.hpp"

namespace rigidfem {

/// The real LU by the column loops below this size, by Eigen's blocked PartialPivLU from it.
constexpr Eigen::Index dense_lu_blocked_from = 48;

/// P S = L U of a real S: each column's pivot the entry of largest magnitude (LAPACK's dgetf2), L's column scaled
/// by the pivot's reciprocal, then the trailing columns less l u_kj. A zero pivot is left in U and its column's
/// multipliers unscaled: the solves then return inf or NaN (the callers test regularity, rcond, before solving).
class DenseLU {
 public:
  void compute(const MatX& S);
  /// The diagonal of U.
  auto pivots() const { return LU_.diagonal(); }
  /// x = S⁻¹ b: L U x = P b (forward, then back substitution by columns).
  void solve(const VecX& b, VecX& x) const;
  /// x = S⁻ᵀ b: Uᵀ Lᵀ P x = b.
  void solve_transposed(const VecX& b, VecX& x) const;

 private:
  MatX LU_;  // L below the diagonal (unit diagonal implied), U on and above it
  Eigen::PermutationMatrix<Eigen::Dynamic> P_;
};

/// P S = L U of a complex S kept as two real matrices (S = S_re + i S_im), each column's pivot the entry of
/// largest |re| + |im| (LAPACK's izamax), its multipliers scaled by the pivot's reciprocal: a complex product
/// l u is four real products over contiguous columns. A zero pivot's reciprocal is kept as 0: the solves then
/// return finite values with that unknown 0 (the callers test regularity, rcond, before solving).
class ComplexLU {
 public:
  using cplx = std::complex<double>;
  void compute(const Eigen::MatrixXcd& S);
  /// The diagonal of U.
  Eigen::VectorXcd pivots() const;
  /// x = S⁻¹ b.
  void solve(const Eigen::VectorXcd& b, Eigen::VectorXcd& x) const;
  /// x = S⁻ᵀ b (the transpose, not the adjoint).
  void solve_transposed(const Eigen::VectorXcd& b, Eigen::VectorXcd& x) const;

 private:
  MatX re_, im_;  // L and U as DenseLU's, in real and imaginary parts
  Eigen::VectorXcd inverse_;  // the pivots' reciprocals
  Eigen::PermutationMatrix<Eigen::Dynamic> P_;
  mutable VecX xr_, xi_;  // a solve's real and imaginary parts
};

}  // namespace rigidfem
