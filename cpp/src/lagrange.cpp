#include "rigidfem/lagrange.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "rigidfem/derivatives.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/recursive.hpp"

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
  if (static_cast<int>(d.T.size()) != sys.nbodies || d.qa.size() != sys.nc ||
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

void set_static_state(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q) {
  set_state(sys, d, t, q, VecX::Zero(sys.nq));
  for (int i : sys.drive_coords) d.qda(i) = d.qdda(i) = 0.0;
}

namespace {

// Motion of body p's joint in its own frame ("jcalc", the one place that knows joint
// types): T̃, Ṫ̃, T̃̈ and, per use u, the local twist X_u = (∂T̃/∂q_u) T̃⁻¹ (in d.X).
void jcalc(const System& sys, int p, Data& d, Mat4& T, Mat4& Td, Mat4& Tdd, bool rates) {
  const int u0 = sys.use_start[p], n = sys.use_start[p + 1] - u0;
  if (sys.joint[p].linear) {
    // T̃ = 1 + Σ_u G_u q_u: Ṫ̃ = Σ G_u q̇_u, T̃̈ = Σ G_u q̈_u, ∂T̃/∂q_u = G_u.
    T.setIdentity();
    Td.setZero();
    Tdd.setZero();
    for (int k = 0; k < n; ++k) {
      const int i = sys.use_coord[u0 + k];
      const Mat4& G = sys.use_G[u0 + k];
      T += G * d.qa(i);
      Td += G * d.qda(i);
      Tdd += G * d.qdda(i);
    }
    const Mat4 Ti = affine_inverse(T);
    for (int k = 0; k < n; ++k) d.X[k].noalias() = sys.use_G[u0 + k] * Ti;
    return;
  }
  // Exact: T̃ = Π_k E_k(q_k); multiply in the elementary factors with the product rule
  // in time, Ė = E Q q̇, Ë = E (Q q̈ + Q² q̇²), (P E)¨ = P̈ E + 2 Ṗ Ė + P Ë.
  Mat4 P = Mat4::Identity(), Pd = Mat4::Zero(), Pdd = Mat4::Zero();
  for (int k = 0; k < n; ++k) {
    const int i = sys.use_coord[u0 + k];
    const Mat4& Q = sys.use_G[u0 + k];
    const Mat4 E = elementary(sys.coords[i].axis, d.qa(i));
    if (rates) {
      const Mat4 EQ = E * Q;
      const double qd = d.qda(i);
      const Mat4 Ed = EQ * qd, Edd = EQ * d.qdda(i) + EQ * Q * (qd * qd);
      Pdd = Pdd * E + 2.0 * Pd * Ed + P * Edd;
      Pd = Pd * E + P * Ed;
    }
    P = P * E;
    // ∂T̃/∂q_k = P_k Q_k (E_{k+1} ...) = (P_k Q_k P_k⁻¹) T̃ with P_k = E_1 ... E_k rigid.
    d.X[k].noalias() = P * Q * inverse(P);
  }
  T = P;
  Td = Pd;
  Tdd = Pdd;
}

// G ← G E_a(q), the elementary factor applied to the columns of G: a translation moves the
// origin along column a; a rotation turns the two other columns (right-handed pair).
void apply_elementary(Mat4& G, Axis a, double q) {
  const int k = axis_index(a);
  if (!is_rotation(a)) {
    G.col(3).head<3>() += q * G.col(k).head<3>();
    return;
  }
  const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;  // (y, z) about x, (z, x) about y, (x, y) about z
  const double c = std::cos(q), s = std::sin(q);
  const Vec4 c1 = G.col(k1), c2 = G.col(k2);
  G.col(k1) = c * c1 + s * c2;
  G.col(k2) = -s * c1 + c * c2;
}

// The recursive engine's kinematics: T_p and the axes s_u of its coordinates, from the frame
// G after each elementary factor: (e, o × e) for a rotation about the unit vector e through
// the origin o of G, (0, e) for a translation along e (e a column of G), without 4x4 twists.
void frames_and_axes(const System& sys, Data& d) {
  static const Mat4 I4 = Mat4::Identity();
  for (int p = 0; p < sys.nbodies; ++p) {
    Mat4 G = frame_of_parent(sys, d.T, p, I4) * sys.B[p];
    for (int u = sys.use_start[p]; u < sys.use_start[p + 1]; ++u) {
      const int i = sys.use_coord[u];
      const Axis a = sys.coords[i].axis;
      apply_elementary(G, a, d.qa(i));
      const Vec3 e = G.col(axis_index(a)).head<3>();
      if (is_rotation(a))
        d.axes[u] << e, G.col(3).head<3>().cross(e);
      else
        d.axes[u] << Vec3::Zero(), e;
    }
    d.T[p] = G;
  }
}

}  // namespace

void kinematics(const System& sys, Data& d, bool rates) {
  check_data(sys, d);
  if (!rates && sys.algorithm == Algorithm::Recursive) return frames_and_axes(sys, d);
  static const Mat4 I4 = Mat4::Identity(), O4 = Mat4::Zero();
  Mat4 Tj, Tjd, Tjdd;
  for (int p = 0; p < sys.nbodies; ++p) {
    // Joint frame F = T_parent B_p; T_p = F T̃.
    const Mat4 F = frame_of_parent(sys, d.T, p, I4) * sys.B[p];
    jcalc(sys, p, d, Tj, Tjd, Tjdd, rates);
    d.T[p].noalias() = F * Tj;
    if (rates) {
      // Ṫ_p = Ḟ T̃ + F Ṫ̃, T̈_p = F̈ T̃ + 2 Ḟ Ṫ̃ + F T̃̈ with Ḟ = Ṫ_parent B_p, F̈ = T̈_parent B_p.
      const Mat4 Fd = frame_of_parent(sys, d.Td, p, O4) * sys.B[p];
      const Mat4 Fdd = frame_of_parent(sys, d.Tdd, p, O4) * sys.B[p];
      d.Td[p].noalias() = Fd * Tj + F * Tjd;
      d.Tdd[p].noalias() = Fdd * Tj + 2.0 * Fd * Tjd + F * Tjdd;
    }
    // ∂T_k/∂q = F X_u F⁻¹ T_k = U_u T_k for every body k at or below p. F is affine but
    // not always rigid (below a linear joint), hence the affine inverse.
    const int u0 = sys.use_start[p], n = sys.use_start[p + 1] - u0;
    if (n == 0) continue;
    const Mat4 Fi = affine_inverse(F);
    for (int k = 0; k < n; ++k) {
      const Mat4& U = d.U[u0 + k] = F * d.X[k] * Fi;
      d.axes[u0 + k] << U(2, 1), U(0, 2), U(1, 0), U.block<3, 1>(0, 3);  // s = (ω, v_O) of U
    }
  }
}

void inertia_composites(const System& sys, Data& d) {
  check_data(sys, d);
  for (int p = 0; p < sys.nbodies; ++p) d.Wbar[p].noalias() = d.T[p] * sys.H[p] * d.Tdd[p].transpose();
  accumulate_subtrees(sys, d.Wbar);
}

void load_composites(const System& sys, Data& d) {
  check_data(sys, d);
  const Vec3 gl = d.load_factor * sys.gravity;
  const Vec4 g(gl.x(), gl.y(), gl.z(), 0.0);
  // Gravity: V = −Σ m gᵀ r_C, so Q_i = g̃ᵀ U_i T_p H_p e₄ = tr(U_i (T_p H_p e₄) g̃ᵀ).
  for (int p = 0; p < sys.nbodies; ++p) d.Zbar[p].noalias() = (d.T[p] * sys.H[p].col(3)) * g.transpose();
  for (const Load& L : sys.loads) {
    // Force F at point x: Q_i = F̃ᵀ U_i x = tr(U_i x F̃ᵀ); torque τ: tr(U_i [[−½S(τ), 0], [0, 0]]) = w_i · τ.
    const AppliedLoad a = applied_load(d, L);
    Mat4& Z = d.Zbar[L.body];
    Z.leftCols<3>() += Vec4(a.x.homogeneous()) * a.F.transpose();
    Z.topLeftCorner<3, 3>() -= 0.5 * skew(a.tau);
  }
  accumulate_subtrees(sys, d.Zbar);
}

AppliedLoad applied_load(const Data& d, const Load& L) {
  const double s = d.load_factor * (L.scale ? L.scale->at(d.t).q : 1.0);
  const Mat3 R = d.T[L.body].topLeftCorner<3, 3>();
  return {(d.T[L.body] * L.point.homogeneous()).head<3>(), s * (L.follower ? Vec3(R * L.force) : L.force),
          s * (L.follower ? Vec3(R * L.torque) : L.torque)};
}

double passive_force(const System& sys, const Data& d, int i) {
  const Coordinate& c = sys.coords[i];
  double applied = c.force;
  if (c.force_law) applied += c.force_law(d.t, d.qa(i), d.qda(i));
  return -c.stiffness * (d.qa(i) - c.rest) - c.damping * d.qda(i) + d.load_factor * applied;
}

void generalized_forces(const System& sys, Data& d) {
  check_data(sys, d);
  if (sys.algorithm == Algorithm::Recursive) return rnea_forces(sys, d);
  load_composites(sys, d);
  inertia_composites(sys, d);
  // f_i = Σ_{uses of q_i} tr(U_u (Z̄_b − W̄_b)) + Q_i^passive: loads minus the velocity (and drive) terms.
  for (int k = 0; k < sys.nq; ++k) d.f(k) = passive_force(sys, d, sys.free_coords[k]);
  for (int b = 0; b < sys.nbodies; ++b)
    for (int u = sys.use_start[b]; u < sys.use_start[b + 1]; ++u) {
      const int k = sys.coords[sys.use_coord[u]].free_index;
      if (k >= 0) d.f(k) += trace_product(d.U[u], d.Zbar[b] - d.Wbar[b]);
    }
}

void mass_matrix(const System& sys, Data& d) {
  check_data(sys, d);
  if (sys.algorithm == Algorithm::Recursive) return crba(sys, d);
  for (int p = 0; p < sys.nbodies; ++p) d.Hbar[p].noalias() = d.T[p] * sys.H[p] * d.T[p].transpose();
  accumulate_subtrees(sys, d.Hbar);
  // a_ij = Σ tr(U_u H̄_b U_vᵀ) over the pairs of uses u of q_i and v of q_j (on body b)
  // with u on the path from the root to b: each pair once, mirrored.
  d.A.setZero(sys.nq, sys.nq);
  for (int b = 0; b < sys.nbodies; ++b) {
    for (int v = sys.use_start[b]; v < sys.use_start[b + 1]; ++v) {
      const int l = sys.coords[sys.use_coord[v]].free_index;
      if (l < 0) continue;  // prescribed
      const Mat4 P = d.Hbar[b] * d.U[v].transpose();
      for (int body = b; body >= 0; body = sys.parent[body]) {
        const int last = body == b ? v : sys.use_start[body + 1] - 1;
        for (int u = sys.use_start[body]; u <= last; ++u) {
          const int k = sys.coords[sys.use_coord[u]].free_index;
          if (k < 0) continue;
          const double a = trace_product(d.U[u], P);
          d.A(k, l) += a;
          if (u != v) d.A(l, k) += a;
        }
      }
    }
  }
}

std::string gimbal_lock_hint(const System& sys, const VecX& q, double tol) {
  std::string hint;
  for (int i : sys.zyx_pitch) {
    const int k = sys.coords[i].free_index;
    if (k < 0 || k >= q.size() || std::abs(std::cos(q(k))) >= tol) continue;
    hint += "; the ZYX angles of " + sys.coords[i].name.substr(0, sys.coords[i].name.size() - 3) +
            " are at pitch phi2 = " + std::to_string(q(k)) +
            " rad, near +-pi/2 where they are singular (gimbal lock): turn the joint frame (placement) so "
            "the motion keeps away from it";
  }
  return hint;
}

void check_gimbal_lock(const System& sys, const Data& d) {
  for (int i : sys.zyx_pitch)
    if (std::abs(std::cos(d.qa(i))) < 1e-9)
      throw SimulationError(d.t, "gimbal lock: the ZYX angles of " +
                                     sys.coords[i].name.substr(0, sys.coords[i].name.size() - 3) +
                                     " reached pitch phi2 = +-pi/2, where the mass matrix is singular; turn the joint "
                                     "frame (placement) so the motion keeps away from it");
}

void accelerations(const System& sys, Data& d) {
  check_data(sys, d);
  if (sys.nq == 0) return;
  check_gimbal_lock(sys, d);
  d.llt.compute(d.A);
  if (d.llt.info() != Eigen::Success)
    throw SimulationError(d.t, "mass matrix is not positive definite (singular configuration or massless chain)");
  d.qdd = d.llt.solve(d.f);
  if (!d.qdd.allFinite()) throw SimulationError(d.t, "accelerations are NaN or inf");
}

void driving_forces(const System& sys, Data& d) {
  check_data(sys, d);
  if (sys.np == 0) return;
  if (sys.algorithm == Algorithm::Recursive) {
    for (int k = 0; k < sys.nq; ++k) d.qdda(sys.free_coords[k]) = d.qdd(k);
    return rnea_driving_forces(sys, d);
  }
  for (int k = 0; k < sys.nq; ++k) d.qdda(sys.free_coords[k]) = d.qdd(k);
  kinematics(sys, d);  // T̈ now holds the full accelerations
  inertia_composites(sys, d);
  // Row i of the full equations: Σ tr(T_{p,i} H T̈ᵀ) = Q_i^loads + Q_i^passive + τ_i.
  for (int k = 0; k < sys.np; ++k) d.tau(k) = -passive_force(sys, d, sys.drive_coords[k]);
  for (int b = 0; b < sys.nbodies; ++b)
    for (int u = sys.use_start[b]; u < sys.use_start[b + 1]; ++u) {
      const int k = sys.coords[sys.use_coord[u]].drive_index;
      if (k >= 0) d.tau(k) += trace_product(d.U[u], d.Wbar[b] - d.Zbar[b]);
    }
}

const VecX& forward_dynamics(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                             const Eigen::Ref<const VecX>& qd) {
  set_state(sys, d, t, q, qd);
  if (sys.algorithm == Algorithm::Recursive) {
    kinematics(sys, d, false);  // ABA needs only T_p and the axes U_i
    aba(sys, d);
    return d.qdd;
  }
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
  if (sys.algorithm == Algorithm::Recursive) {
    check_vector(y, n, "y", "2 nq");
    auto [dq, dqd] = acceleration_derivatives(sys, d, t, y.head(sys.nq), y.tail(sys.nq));
    J << MatX::Zero(sys.nq, sys.nq), MatX::Identity(sys.nq, sys.nq), dq, dqd;
    return J;
  }
  VecX yp = y;
  for (int j = 0; j < n; ++j) J.col(j) = central_difference([&] { return rhs(sys, d, t, yp); }, yp, j);
  return J;
}

std::pair<MatX, MatX> force_jacobians(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                      const Eigen::Ref<const VecX>& qd, bool static_drives) {
  if (sys.algorithm == Algorithm::Recursive) {
    // f = −r(q, q̇, q̈ = 0): the analytic derivatives of the recursive inverse dynamics.
    if (static_drives)
      set_static_state(sys, d, t, q);
    else
      set_state(sys, d, t, q, qd);
    kinematics(sys, d, false);
    auto [dq, dqd] = inverse_dynamics_derivatives(sys, d);
    return {-dq, -dqd};
  }
  // The springs and dampers, −c_i (q_i − q_i⁰) − b_i q̇_i, are differentiated exactly; only the
  // rest (loads, inertia, force laws) by central differences, so stiff sdes (EA/Δ ~ 1e10)
  // add no round-off to the soft terms.
  VecX x = q, xd = static_drives ? VecX::Zero(sys.nq) : VecX(qd);
  auto f = [&]() -> VecX {
    if (static_drives)
      set_static_state(sys, d, t, x);
    else
      set_state(sys, d, t, x, xd);
    kinematics(sys, d);
    generalized_forces(sys, d);
    VecX g = d.f;
    for (int k = 0; k < sys.nq; ++k) {
      const Coordinate& c = sys.coords[sys.free_coords[k]];
      g(k) += c.stiffness * (x(k) - c.rest) + c.damping * xd(k);
    }
    return g;
  };
  MatX dq(sys.nq, sys.nq), dqd = MatX::Zero(sys.nq, sys.nq);
  for (int j = 0; j < sys.nq; ++j) {
    dq.col(j) = central_difference(f, x, j);
    if (!static_drives) dqd.col(j) = central_difference(f, xd, j);
  }
  for (int k = 0; k < sys.nq; ++k) {
    const Coordinate& c = sys.coords[sys.free_coords[k]];
    dq(k, k) -= c.stiffness;
    dqd(k, k) -= c.damping;
  }
  return {dq, dqd};
}

StateOutputs evaluate_outputs(const System& sys, const VecX& t, const MatX& Q, const MatX& QD) {
  const Eigen::Index N = t.size();
  if (Q.rows() != N || QD.rows() != N || Q.cols() != sys.nq || QD.cols() != sys.nq)
    throw std::invalid_argument("q, qd: expected (len(t), nq) arrays");
  StateOutputs out{MatX(N, sys.nq), MatX(N, sys.np), VecX(N), VecX(N), VecX(N)};
  Data d(sys);
  for (Eigen::Index k = 0; k < N; ++k) {
    set_state(sys, d, t(k), Q.row(k).transpose(), QD.row(k).transpose());
    kinematics(sys, d);  // with rates: the kinetic energy needs Ṫ
    out.kinetic(k) = kinetic_energy(sys, d);
    out.gravity(k) = gravity_energy(sys, d);
    out.elastic(k) = elastic_energy(sys, d);
    forward_dynamics(sys, d, t(k), Q.row(k).transpose(), QD.row(k).transpose());
    out.qdd.row(k) = d.qdd.transpose();
    driving_forces(sys, d);
    out.tau.row(k) = d.tau.transpose();
  }
  return out;
}

MatX point_positions(const System& sys, int body, const Vec3& r, int frame, const VecX& t, const MatX& Q) {
  if (body < 0 || body >= sys.nbodies || frame < -1 || frame >= sys.nbodies)
    throw std::invalid_argument("point, frame: expected bodies of this system");
  if (Q.rows() != t.size() || Q.cols() != sys.nq) throw std::invalid_argument("q: expected a (len(t), nq) array");
  MatX P(t.size(), 3);
  Data d(sys);
  const VecX zero = VecX::Zero(sys.nq);
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    set_state(sys, d, t(k), Q.row(k).transpose(), zero);
    kinematics(sys, d);
    Vec4 x = d.T[body] * r.homogeneous();
    if (frame >= 0) x = affine_inverse(d.T[frame]) * x;
    P.row(k) = x.head<3>().transpose();
  }
  return P;
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
