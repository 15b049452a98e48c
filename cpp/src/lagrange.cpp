#include "rigidfem/lagrange.hpp"

namespace rigidfem {

namespace {

// tr(U M) for U = [[S(w), v], [0, 0]]: only the first three rows of U are non-zero.
inline double trace_product(const Mat4& U, const Mat4& M) {
  return (U.topRows<3>().cwiseProduct(M.leftCols<3>().transpose())).sum();
}

}  // namespace

void inertia_composites(const System& sys, Data& d) {
  for (int p = 0; p < sys.nbodies; ++p) d.Wbar[p].noalias() = d.T[p] * d.H[p] * d.Tdd[p].transpose();
  accumulate_subtrees(sys, d.Wbar);
}

void load_composites(const System& sys, Data& d) {
  const Vec3 gl = d.load_factor * sys.gravity;
  const Vec4 g(gl.x(), gl.y(), gl.z(), 0.0);
  // Gravity: V = −Σ m gᵀ r_C, so Q_i = g̃ᵀ U_i T_p H_p e₄ = tr(U_i (T_p H_p e₄) g̃ᵀ).
  for (int p = 0; p < sys.nbodies; ++p) d.Zbar[p].noalias() = (d.T[p] * d.H[p].col(3)) * g.transpose();
  for_each_body_load(sys, d, false, [&](int body, const AppliedLoad& a, bool) {
    // Force F at point x: Q_i = F̃ᵀ U_i x = tr(U_i x F̃ᵀ); torque τ: tr(U_i [[−½S(τ), 0], [0, 0]]) = w_i · τ.
    Mat4& Z = d.Zbar[body];
    Z.leftCols<3>() += Vec4(a.x.homogeneous()) * a.F.transpose();
    Z.topLeftCorner<3, 3>() -= 0.5 * skew(a.tau);
  });
  accumulate_subtrees(sys, d.Zbar);
}

void lagrange_forces(const System& sys, Data& d) {
  load_composites(sys, d);
  inertia_composites(sys, d);
  // f_i = Σ_{uses of q_i} tr(U_u (Z̄_b − W̄_b)) + Q_i^passive.
  for (int k = 0; k < sys.nq; ++k) d.f(k) = passive_force(sys, d, sys.free_coords[k], false);
  for (int b = 0; b < sys.nbodies; ++b)
    for (int u = sys.use_start[b]; u < sys.use_start[b + 1]; ++u)
      if (sys.use_q[u] >= 0) d.f(sys.use_q[u]) += trace_product(d.U[u], d.Zbar[b] - d.Wbar[b]);
}

void lagrange_mass_matrix(const System& sys, Data& d) {
  for (int p = 0; p < sys.nbodies; ++p) d.Hbar[p].noalias() = d.T[p] * d.H[p] * d.T[p].transpose();
  accumulate_subtrees(sys, d.Hbar);
  // a_ij = Σ tr(U_u H̄_b U_vᵀ) over the pairs of uses u of q_i and v of q_j (on body b)
  // with u on the path from the root to b: each pair once, mirrored.
  d.A.setZero(sys.nq, sys.nq);
  for (int b = 0; b < sys.nbodies; ++b) {
    for (int v = sys.use_start[b]; v < sys.use_start[b + 1]; ++v) {
      interruption_point();
      const int l = sys.use_q[v];
      if (l < 0) continue;  // prescribed
      const Mat4 P = d.Hbar[b] * d.U[v].transpose();
      for (int body = b; body >= 0; body = sys.parent[body]) {
        const int last = body == b ? v : sys.use_start[body + 1] - 1;
        for (int u = sys.use_start[body]; u <= last; ++u) {
          const int k = sys.use_q[u];
          if (k < 0) continue;
          const double a = trace_product(d.U[u], P);
          d.A(k, l) += a;
          if (u != v) d.A(l, k) += a;
        }
      }
    }
  }
}

void lagrange_driving_forces(const System& sys, Data& d) {
  inertia_composites(sys, d);
  for (int k = 0; k < sys.np; ++k) d.tau(k) = -passive_force(sys, d, sys.drive_coords[k], false);
  for (int b = 0; b < sys.nbodies; ++b)
    for (int u = sys.use_start[b]; u < sys.use_start[b + 1]; ++u)
      if (sys.use_drive[u] >= 0) d.tau(sys.use_drive[u]) += trace_product(d.U[u], d.Wbar[b] - d.Zbar[b]);
}

}  // namespace rigidfem
