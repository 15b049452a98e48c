#include "rigidfem/lagrange.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "rigidfem/errors.hpp"

namespace rigidfem {

namespace {

void check_vector(const Eigen::Ref<const VecX>& v, int n, const char* name, const char* size_name) {
  if (v.size() != n)
    throw std::invalid_argument(std::string(name) + ": expected size " + std::to_string(n) + " (" + size_name +
                                "), got " + std::to_string(v.size()));
  if (!v.allFinite()) throw std::invalid_argument(std::string(name) + ": expected finite values, got NaN or inf");
}

// Every stage checks its workspace: a Data made for another system would be written out of bounds.
void check_data(const System& sys, const Data& d) {
  if (static_cast<int>(d.T.size()) != sys.nbodies || d.qa.size() != sys.nc || d.A.rows() != sys.nq ||
      d.f.size() != sys.nq || d.qdd.size() != sys.nq || d.tau.size() != sys.np)
    throw std::invalid_argument("data: expected a workspace made by this system's make_data(), got one of another system");
}

// tr(U M) for U = [[S(w), v], [0, 0]]: only the first three rows of U are non-zero.
inline double trace_product(const Mat4& U, const Mat4& M) {
  return (U.topRows<3>().cwiseProduct(M.leftCols<3>().transpose())).sum();
}

// Sums a per-body quantity over subtrees, children before parents: X̄_p = X_p + Σ_children X̄_c.
void accumulate_subtrees(const System& sys, std::vector<Mat4>& X) {
  for (int p = sys.nbodies - 1; p >= 0; --p)
    if (sys.parent[p] >= 0) X[sys.parent[p]] += X[p];
}

const Mat4& frame_of_parent(const System& sys, const std::vector<Mat4>& X, int p, const Mat4& ground) {
  return sys.parent[p] >= 0 ? X[sys.parent[p]] : ground;
}

}  // namespace

void set_state(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
               const Eigen::Ref<const VecX>& qd) {
  check_data(sys, d);
  if (!std::isfinite(t)) throw std::invalid_argument("t: expected a finite time in s, got NaN or inf");
  check_vector(q, sys.nq, "q", "nq");
  check_vector(qd, sys.nq, "qd", "nq");
  d.t = t;
  for (int k = 0; k < sys.nq; ++k) {
    const int i = sys.free_coords[k];
    d.qa(i) = q(k);
    d.qda(i) = qd(k);
    d.qdda(i) = 0.0;
  }
  for (int k = 0; k < sys.np; ++k) {
    const int i = sys.drive_coords[k];
    const MotionState m = sys.coords[i].drive->at(t);
    if (!std::isfinite(m.q) || !std::isfinite(m.qd) || !std::isfinite(m.qdd))
      throw SimulationError(t, "drive of " + sys.coords[i].name + " returned NaN or inf");
    d.qa(i) = m.q;
    d.qda(i) = m.qd;
    d.qdda(i) = m.qdd;
  }
}

void kinematics(const System& sys, Data& d) {
  check_data(sys, d);
  static const Mat4 I4 = Mat4::Identity(), O4 = Mat4::Zero();
  for (int p = 0; p < sys.nbodies; ++p) {
    // Joint frame F = T_parent B_p and its time derivatives.
    Mat4 P = frame_of_parent(sys, d.T, p, I4) * sys.B[p];
    Mat4 Pd = frame_of_parent(sys, d.Td, p, O4) * sys.B[p];
    Mat4 Pdd = frame_of_parent(sys, d.Tdd, p, O4) * sys.B[p];
    // Multiply in the elementary factors E_k of T̃_p, product rule in time:
    // Ė = E Q q̇, Ë = E (Q q̈ + Q² q̇²); (PE)¨ = P̈E + 2ṖĖ + PË.
    for (int i = sys.coord_start[p]; i < sys.coord_start[p + 1]; ++i) {
      const Axis a = sys.coords[i].axis;
      const double qd = d.qda(i), qdd = d.qdda(i);
      const Mat4 E = elementary(a, d.qa(i)), Q = generator(a);
      const Mat4 EQ = E * Q;
      const Mat4 Ed = EQ * qd, Edd = EQ * qdd + EQ * Q * (qd * qd);
      Pdd = Pdd * E + 2.0 * Pd * Ed + P * Edd;
      Pd = Pd * E + P * Ed;
      P = P * E;
      // U_i = F_i Q_i F_i⁻¹ with F_i the frame just after E_i: rotation about the
      // global axis w = R e through the frame origin p, U = [[S(w), p × w], [0, 0]];
      // translation along v = R e, U = [[0, v], [0, 0]].
      const Vec3 e = P.topLeftCorner<3, 3>() * axis_direction(a);
      Mat4& U = d.U[i];
      U.setZero();
      if (is_rotation(a)) {
        U.topLeftCorner<3, 3>() = skew(e);
        U.topRightCorner<3, 1>() = P.topRightCorner<3, 1>().cross(e);
      } else {
        U.topRightCorner<3, 1>() = e;
      }
    }
    d.T[p] = P;
    d.Td[p] = Pd;
    d.Tdd[p] = Pdd;
  }
}

void inertia_composites(const System& sys, Data& d) {
  check_data(sys, d);
  for (int p = 0; p < sys.nbodies; ++p) d.Wbar[p].noalias() = d.T[p] * sys.H[p] * d.Tdd[p].transpose();
  accumulate_subtrees(sys, d.Wbar);
}

void load_composites(const System& sys, Data& d) {
  check_data(sys, d);
  const Vec4 g(sys.gravity.x(), sys.gravity.y(), sys.gravity.z(), 0.0);
  // Gravity: V = −Σ m gᵀ r_C, so Q_i = g̃ᵀ U_i T_p H_p e₄ = tr(U_i (T_p H_p e₄) g̃ᵀ).
  for (int p = 0; p < sys.nbodies; ++p) d.Zbar[p].noalias() = (d.T[p] * sys.H[p].col(3)) * g.transpose();
  for (const Load& L : sys.loads) {
    const double s = L.scale ? L.scale->at(d.t).q : 1.0;
    const Mat3 R = d.T[L.body].topLeftCorner<3, 3>();
    const Vec3 F = s * (L.follower ? Vec3(R * L.force) : L.force);
    const Vec3 tau = s * (L.follower ? Vec3(R * L.torque) : L.torque);
    // Force F at point x: Q_i = F̃ᵀ U_i x = tr(U_i x F̃ᵀ); torque τ: tr(U_i [[−½S(τ), 0], [0, 0]]) = w_i · τ.
    const Vec4 x = d.T[L.body] * L.point.homogeneous();
    Mat4& Z = d.Zbar[L.body];
    Z.leftCols<3>() += x * F.transpose();
    Z.topLeftCorner<3, 3>() -= 0.5 * skew(tau);
  }
  accumulate_subtrees(sys, d.Zbar);
}

double passive_force(const System& sys, const Data& d, int i) {
  const Coordinate& c = sys.coords[i];
  double Q = -c.stiffness * (d.qa(i) - c.rest) - c.damping * d.qda(i) + c.force;
  if (c.force_law) Q += c.force_law(d.t, d.qa(i), d.qda(i));
  return Q;
}

void generalized_forces(const System& sys, Data& d) {
  check_data(sys, d);
  load_composites(sys, d);
  inertia_composites(sys, d);
  // f_i = tr(U_i (Z̄_b − W̄_b)) + Q_i^passive: loads minus the velocity (and drive) terms.
  for (int k = 0; k < sys.nq; ++k) {
    const int i = sys.free_coords[k], b = sys.coords[i].body;
    d.f(k) = trace_product(d.U[i], d.Zbar[b] - d.Wbar[b]) + passive_force(sys, d, i);
  }
}

void mass_matrix(const System& sys, Data& d) {
  check_data(sys, d);
  for (int p = 0; p < sys.nbodies; ++p) d.Hbar[p].noalias() = d.T[p] * sys.H[p] * d.T[p].transpose();
  accumulate_subtrees(sys, d.Hbar);
  // a_ij = tr(U_i H̄_b U_jᵀ) for coordinate i on the path from the root to j's body b.
  for (int l = 0; l < sys.nq; ++l) {
    const int j = sys.free_coords[l], b = sys.coords[j].body;
    const Mat4 P = d.Hbar[b] * d.U[j].transpose();
    for (int body = b; body >= 0; body = sys.parent[body]) {
      const int last = body == b ? j : sys.coord_start[body + 1] - 1;
      for (int i = sys.coord_start[body]; i <= last; ++i) {
        const int k = sys.coords[i].free_index;
        if (k < 0) continue;  // prescribed
        d.A(k, l) = d.A(l, k) = trace_product(d.U[i], P);
      }
    }
  }
}

void accelerations(const System& sys, Data& d) {
  check_data(sys, d);
  if (sys.nq == 0) return;
  d.llt.compute(d.A);
  if (d.llt.info() != Eigen::Success)
    throw SimulationError(d.t, "mass matrix is not positive definite (singular configuration or massless chain)");
  d.qdd = d.llt.solve(d.f);
  if (!d.qdd.allFinite()) throw SimulationError(d.t, "accelerations are NaN or inf");
}

void driving_forces(const System& sys, Data& d) {
  check_data(sys, d);
  if (sys.np == 0) return;
  for (int k = 0; k < sys.nq; ++k) d.qdda(sys.free_coords[k]) = d.qdd(k);
  kinematics(sys, d);  // T̈ now holds the full accelerations
  inertia_composites(sys, d);
  // Row i of the full equations: Σ tr(T_{p,i} H T̈ᵀ) = Q_i^loads + Q_i^passive + τ_i.
  for (int k = 0; k < sys.np; ++k) {
    const int i = sys.drive_coords[k], b = sys.coords[i].body;
    d.tau(k) = trace_product(d.U[i], d.Wbar[b] - d.Zbar[b]) - passive_force(sys, d, i);
  }
}

const VecX& forward_dynamics(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                             const Eigen::Ref<const VecX>& qd) {
  set_state(sys, d, t, q, qd);
  kinematics(sys, d);
  generalized_forces(sys, d);
  mass_matrix(sys, d);
  accelerations(sys, d);
  return d.qdd;
}

VecX rhs(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& y) {
  check_vector(y, 2 * sys.nq, "y", "2 nq");
  VecX ydot(2 * sys.nq);
  ydot.head(sys.nq) = y.tail(sys.nq);
  ydot.tail(sys.nq) = forward_dynamics(sys, d, t, y.head(sys.nq), y.tail(sys.nq));
  return ydot;
}

MatX rhs_jacobian(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& y) {
  const int n = 2 * sys.nq;
  MatX J(n, n);
  VecX yp = y;
  for (int j = 0; j < n; ++j) {
    // Central differences, step ∝ ε^(1/3) for O(ε^(2/3)) error.
    const double h = 6e-6 * std::max(1.0, std::abs(y(j)));
    yp(j) = y(j) + h;
    const VecX fp = rhs(sys, d, t, yp);
    yp(j) = y(j) - h;
    const VecX fm = rhs(sys, d, t, yp);
    yp(j) = y(j);
    J.col(j) = (fp - fm) / (2.0 * h);
  }
  return J;
}

double kinetic_energy(const System& sys, const Data& d) {
  check_data(sys, d);
  double E = 0.0;
  for (int p = 0; p < sys.nbodies; ++p) E += 0.5 * (d.Td[p] * sys.H[p] * d.Td[p].transpose()).trace();
  return E;
}

double gravity_energy(const System& sys, const Data& d) {
  check_data(sys, d);
  double V = 0.0;
  for (int p = 0; p < sys.nbodies; ++p) V -= sys.gravity.dot((d.T[p] * sys.H[p].col(3)).head<3>());
  return V;
}

double elastic_energy(const System& sys, const Data& d) {
  check_data(sys, d);
  double V = 0.0;
  for (int i = 0; i < sys.nc; ++i) V += 0.5 * sys.coords[i].stiffness * std::pow(d.qa(i) - sys.coords[i].rest, 2);
  return V;
}

double dissipated_power(const System& sys, const Data& d) {
  check_data(sys, d);
  double P = 0.0;
  for (int i = 0; i < sys.nc; ++i) P += sys.coords[i].damping * d.qda(i) * d.qda(i);
  return P;
}

}  // namespace rigidfem
