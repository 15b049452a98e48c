/// Newton's matrix of the implicit methods: S = M + c₁ C + c₂ K + diag(e), with C = ∂r/∂q̇ and K = ∂r/∂q
/// of the residual r(q, q̇, q̈) = M(q) q̈ − f(q, q̇, t) at a state (the tangent), c₁ and c₂ real (the
/// Newmark family, esdirk43, radau5's real block) or complex (radau5's complex block), e a diagonal the
/// caller adds (the Maxwell arms' stiffness over the step). Two forms behind one interface:
///
///  - Dense: M, C and K formed (analytic derivatives for recursive systems), S factorised by LU:
///    O(n²) for the tangent and O(n³) per factorisation.
///  - Krylov (recursive systems): nothing formed. The tangent's action is the residual's directional
///    derivative, K δq + C δq̇ + M δq̈ = (r(q + ε δq, q̇ + ε δq̇, q̈ + ε δq̈) − r(q, q̇, q̈))/ε (forward
///    differences, one inverse dynamics, O(n)), and S⁻¹ b is solved by GMRES preconditioned with
///    P = M + diag(c₁ b + c₂ k + e) — the coordinates' dampers b and springs k as armature of the
///    articulated-body algorithm, in complex arithmetic for a complex shift — factorised in O(n). For
///    a beam P holds the mass and the stiff springs exactly, so P⁻¹S is the identity but for the
///    geometric, gyroscopic and gravity terms and GMRES converges in a few iterations, whatever n.
///    O(n) per iteration: the implicit steps of a 5,000-element beam cost what implicit_spring's do.
#pragma once

#include <complex>
#include <memory>

#include "rigidfem/dense_lu.hpp"
#include "rigidfem/integrators.hpp"
#include "rigidfem/system.hpp"

namespace rigidfem {

using cplx = std::complex<double>;
using VecXc = Eigen::VectorXcd;

/// iteration_matrix=auto takes Krylov for recursive systems above this many free coordinates, the
/// dense tangent below (measured: the dense factorisation is the cheaper up to about this size).
constexpr int krylov_from_nq = 200;

/// Whether the exact tangent of the run's implicit method is matrix-free (Krylov) rather than dense.
bool krylov_tangent(const System& sys, const IntegratorOptions& o);

/// δ_k = s_i (c₁ b_i + c₂ k_i): the damper b_i and spring k_i of each free coordinate i, scaled as in its
/// force (Data::spring_scale), as the armature of the spring matrix M + diag δ (implicit_spring's Newton
/// matrix, esdirk43's with iteration_matrix="spring", the Krylov form's preconditioner).
template <class Scalar>
void spring_armature(const System& sys, const Data& d, Scalar c1, Scalar c2, Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& delta) {
  delta.resize(sys.nq);
  for (int k = 0; k < sys.nq; ++k) {
    const int i = sys.free_coords[k];
    delta(k) = sys.coords[i].spring.armature(c1, c2, d.spring_scale(i));
  }
}

class NewtonMatrix {
 public:
  /// Dense or Krylov (krylov_tangent) for the system and options; factorisations and the tangent's
  /// evaluations counted in stats (a Krylov iteration as one residual evaluation).
  static std::unique_ptr<NewtonMatrix> make(const System& sys, const IntegratorOptions& o, IntegratorStats& stats);
  virtual ~NewtonMatrix() = default;

  /// The tangent at (t, q, q̇, q̈) with the arms' forces s (nz).
  virtual void linearize(double t, const VecX& q, const VecX& qd, const VecX& qdd, const VecX& s) = 0;
  /// out = K δq + C δq̇ + M δq̈ at the tangent.
  virtual void derivative(const VecX& dq, const VecX& dqd, const VecX& dqdd, VecX& out) = 0;
  /// Factorises S = M + c₁ C + c₂ K + diag(e) of the tangent (e empty: none) in slot 0 (real) ...
  /// Returns a measure of regularity that falls below 1e-15 for a singular S: for a dense factorisation the
  /// pivots' spread, or the reciprocal condition number where the spread is below 1e-8 (newton_matrix.cpp's
  /// regularity); 1 for Krylov's, whose recursion throws SimulationError at a singular pivot. The caller
  /// names the failure.
  virtual double factor(double c1, double c2, const VecX& e) = 0;
  /// ... or a complex slot (no e): one per complex pair of eigenvalues of a collocation tableau (radau9's two).
  static constexpr int complex_slots = 2;
  virtual double factor(cplx c1, cplx c2, int slot = 0) = 0;
  /// x = S⁻¹ b with slot 0's matrix (x may not be b).
  virtual void solve(const VecX& b, VecX& x) = 0;
  /// x = S⁻¹ b with a complex slot's matrix.
  virtual void solve(const VecXc& b, VecXc& x, int slot = 0) = 0;
  /// x = P⁻ᵀ b with slot 0's factorisation P: S itself (dense), the preconditioner M + diag(c₁ b + c₂ k + e),
  /// symmetric (Krylov). The adjoint's preconditioner for Sᵀ (adjoint.cpp).
  virtual void precondition_transposed(const VecX& b, VecX& x) = 0;
  /// ... with complex slot 0's factorisation.
  virtual void precondition_transposed(const VecXc& b, VecXc& x) = 0;
  /// X = S⁻¹ B column by column with slot 0's matrix.
  MatX solve(const MatX& B);
  /// Whether the tangent is matrix-free.
  virtual bool krylov() const = 0;
  /// Slot 0's dense LU, shared (a new one at each factorisation: an old one stays valid for whoever keeps it), or
  /// none (Krylov): what the adjoint keeps of the forward run's Newton matrices to precondition its transposes.
  virtual std::shared_ptr<const DenseLU> dense_factor() const { return nullptr; }
};

}  // namespace rigidfem
