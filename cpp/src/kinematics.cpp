#include "rigidfem/kinematics.hpp"

#include <algorithm>
#include <cmath>

#include "rigidfem/errors.hpp"

namespace rigidfem {

void set_state(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
               const Eigen::Ref<const VecX>& qd) {
  check_data(sys, d);
  if (!std::isfinite(t)) throw std::invalid_argument("t: expected a finite time in s, got NaN or inf");
  check_vector(q, sys.nq, "q", "nq");
  check_vector(qd, sys.nq, "qd", "nq");
  d.state_ok = false;  // until every drive has answered: bad input above leaves the old state
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
  if (!sys.flows.empty()) update_flows(sys, d, false);
  d.state_ok = true;
}

void set_static_state(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q) {
  set_state(sys, d, t, q, VecX::Zero(sys.nq));
  for (int i : sys.drive_coords) d.qda(i) = d.qdda(i) = 0.0;
  if (!sys.flows.empty()) update_flows(sys, d, true);
}

namespace {

// H(λ L₀) of a uniform rfe from H(L₀): ∫ s² dm ∝ λ³, ∫ s dm ∝ λ², the rest (∫ y² dm, m) ∝ λ, s
// being the coordinate along the rfe (x).
Mat4 scaled_pseudo_inertia(const Mat4& H0, double lambda) {
  Mat4 H = H0 * lambda;
  H.row(0) *= lambda;
  H.col(0) *= lambda;
  return H;
}

// Angular velocity ω of body b: from v_b (spatial) or Ṙ Rᵀ = [ω]×.
Vec3 angular_velocity(const Data& d, int b, bool spatial) {
  if (spatial) return d.v[b].head<3>();
  const Mat3 W = d.Td[b].topLeftCorner<3, 3>() * d.T[b].topLeftCorner<3, 3>().transpose();
  return Vec3(W(2, 1), W(0, 2), W(1, 0));
}

}  // namespace

void update_flows(const System& sys, Data& d, bool at_rest) {
  for (std::size_t f = 0; f < sys.flows.size(); ++f) {
    const Flow& F = sys.flows[f];
    MotionState L = F.length->at(d.t);
    if (!(L.q > 0.0 && std::isfinite(L.q) && std::isfinite(L.qd) && std::isfinite(L.qdd)))
      throw SimulationError(d.t, "the free length of the beam of '" + sys.body_names[F.first] + "' is L = " +
                                     num(L.q) + " m (a link of varying length needs 0 < L(t) < inf)");
    if (at_rest) L.qd = L.qdd = 0.0;
    d.flow[f] = L;
    const double lambda = L.q / F.length0;
    for (int k = 0; k <= F.elements; ++k) {
      const int b = F.first + k;
      const Mat4 H = scaled_pseudo_inertia(sys.H[b], lambda);
      const double m = H(3, 3);
      const Vec3 c = H.block<3, 1>(0, 3) / m;
      const Mat3 Hs = H.topLeftCorner<3, 3>();
      const Mat3 IO = Hs.trace() * Mat3::Identity() - Hs;  // H = [[½ tr(I_O) 1 − I_O, m c], [m cᵀ, m]]
      d.H[b] = H;
      d.mass[b] = m;
      d.com[b] = c;
      d.inertia[b] = IO - m * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
      if (k > 0)
        for (int i = sys.coord_start[b]; i < sys.coord_start[b + 1]; ++i) d.spring_scale(i) = 1.0 / lambda;
    }
  }
}

FlowTerm flow_term(const System& sys, const Data& d, int flow, int k, bool spatial) {
  const Flow& F = sys.flows[flow];
  const MotionState& L = d.flow[flow];
  const int b = F.first + k, prev = k > 0 ? b - 1 : sys.parent[b];
  const double slip = 1.0 - F.xi(k);
  // The axis the material comes from: rfe k − 1's, or for rfe 0 the guide's (x of T_parent B_0).
  const Vec3 e_prev = k > 0 ? Vec3(d.T[prev].block<3, 1>(0, 0))
                            : Vec3((prev >= 0 ? d.T[prev] : Mat4::Identity()).topLeftCorner<3, 3>() *
                                   sys.B[b].block<3, 1>(0, 0));
  return {b, prev, d.mass[b], d.mass[F.first] / (F.share(0) * L.q), L.qd * slip, L.qdd * slip,
          d.T[b].block<3, 1>(0, 0), e_prev, angular_velocity(d, b, spatial),
          (d.T[b] * d.com[b].homogeneous()).head<3>(), d.T[b].block<3, 1>(0, 3)};
}

std::pair<AppliedLoad, AppliedLoad> flow_loads(const FlowTerm& f) {
  return {{f.xc, -f.m * (2.0 * f.alpha * f.omega.cross(f.e) + f.beta * f.e), Vec3::Zero()},
          {f.origin, -f.rhoA * f.alpha * f.alpha * (f.e - f.e_prev), Vec3::Zero()}};
}

void set_accelerations(const System& sys, Data& d, const Eigen::Ref<const VecX>& qdd) {
  for (int k = 0; k < sys.nq; ++k) d.qdda(sys.free_coords[k]) = qdd(k);
}

void kinematics(const System& sys, Data& d, bool rates) {
  check_state(sys, d);
  static const Mat4 I4 = Mat4::Identity(), O4 = Mat4::Zero();
  Mat4 Tj, Tjd, Tjdd;
  for (int p = 0; p < sys.nbodies; ++p) {
    // Joint frame F = T_parent B_p; T_p = F T̃.
    const Mat4 F = parent_value(sys, d.T, p, I4) * sys.B[p];
    const JointUses j = joint_uses(sys, p);
    joint_motion(j, d.qa, d.qda, d.qdda, rates, Tj, Tjd, Tjdd, d.X.data());
    d.T[p].noalias() = F * Tj;
    if (rates) {
      // Ṫ_p = Ḟ T̃ + F Ṫ̃, T̈_p = F̈ T̃ + 2 Ḟ Ṫ̃ + F T̃̈ with Ḟ = Ṫ_parent B_p, F̈ = T̈_parent B_p.
      const Mat4 Fd = parent_value(sys, d.Td, p, O4) * sys.B[p];
      const Mat4 Fdd = parent_value(sys, d.Tdd, p, O4) * sys.B[p];
      d.Td[p].noalias() = Fd * Tj + F * Tjd;
      d.Tdd[p].noalias() = Fdd * Tj + 2.0 * Fd * Tjd + F * Tjdd;
    }
    // ∂T_k/∂q = F X_u F⁻¹ T_k = U_u T_k for every body k at or below p. F is affine but
    // not always rigid (below a linear joint), hence the affine inverse.
    if (j.n == 0) continue;
    const Mat4 Fi = affine_inverse(F);
    const int u0 = sys.use_start[p];
    for (int k = 0; k < j.n; ++k) {
      const Mat4& U = d.U[u0 + k] = F * d.X[k] * Fi;
      d.axes[u0 + k] << U(2, 1), U(0, 2), U(1, 0), U.block<3, 1>(0, 3);  // s = (ω, v_O) of U
    }
  }
}

void frames_and_axes(const System& sys, Data& d) {
  static const Mat4 I4 = Mat4::Identity();
  Mat4 T = I4;  // the previous body's frame: the parent's in a chain (no reload of d.T)
  for (int p = 0; p < sys.nbodies; ++p) {
    if (sys.parent[p] != p - 1) T = parent_value(sys, d.T, p, I4);
    Mat4 G;
    if (sys.shift_only[p]) {  // B_p = [[1, r], [0, 1]]: G = [[R, R r + o], [0, 1]] (compose's values, its M 1 left out)
      G = T;
      G.topRightCorner<3, 1>().noalias() += T.topLeftCorner<3, 3>() * sys.B[p].topRightCorner<3, 1>();
    } else {
      compose(T, sys.B[p], G);
    }
    joint_frames(joint_uses(sys, p), d.qa, G, d.axes.data() + sys.use_start[p]);  // data(): valid for none
    d.T[p] = T = G;
  }
}

void frames(const System& sys, Data& d) {
  static const Mat4 I4 = Mat4::Identity();
  Mat4 Tj, unused;
  for (int p = 0; p < sys.nbodies; ++p) {
    Mat4 G = parent_value(sys, d.T, p, I4) * sys.B[p];
    const JointUses j = joint_uses(sys, p);
    if (j.linear) {
      joint_motion(j, d.qa, d.qda, d.qdda, false, Tj, unused, unused, d.X.data());
      d.T[p].noalias() = G * Tj;
      continue;
    }
    for (int k = 0; k < j.n; ++k) apply_elementary(G, j.axis[k], d.qa(j.coord[k]));
    d.T[p] = G;
  }
}

AppliedLoad applied_load(const Data& d, const Load& L) {
  const double s = d.load_factor * (L.scale ? L.scale->at(d.t).q : 1.0);
  const Mat3 R = d.T[L.body].topLeftCorner<3, 3>();
  return {(d.T[L.body] * L.point.homogeneous()).head<3>(), s * (L.follower ? Vec3(R * L.force) : L.force),
          s * (L.follower ? Vec3(R * L.torque) : L.torque)};
}

namespace {

// Position and velocity of a point p (body frame) of body b: from v_b = (ω, v_O) (spatial) or Ṫ_b.
void moving_point(const Data& d, int b, const Vec3& p, bool spatial, Vec3& x, Vec3& v) {
  if (b < 0) {
    x = p;
    v.setZero();
    return;
  }
  x = (d.T[b] * p.homogeneous()).head<3>();
  v = spatial ? Vec3(d.v[b].tail<3>() + d.v[b].head<3>().cross(x)) : Vec3((d.Td[b] * p.homogeneous()).head<3>());
}

}  // namespace

ElementState element_state(const System& sys, const Data& d, const ForceElement& element, bool spatial) {
  ElementState s;
  moving_point(d, element.body_a, element.point_a, spatial, s.xa, s.va);
  moving_point(d, element.body_b, element.point_b, spatial, s.xb, s.vb);
  const Vec3 r = s.xb - s.xa;
  s.l = r.norm();
  if (!(s.l > 1e-12 * std::max(1.0, s.xa.norm())))
    throw SimulationError(d.t, "the points of force element '" + element.name +
                                   "' coincide (l = 0: its line of action is undefined)");
  s.e = r / s.l;
  s.ld = s.e.dot(s.vb - s.va);
  for (const Winding& w : element.windings) s.s += w.radius * d.qa(w.coord), s.sd += w.radius * d.qda(w.coord);
  element.law->check(d.t, s.extension(), element.name);
  s.F = element.law->force(d.t, s.extension(), d.load_factor);
  // a heavy span: w_B = ½ λ m g, w_A = λ (½ m − μ s) g; P = P_law + ½ λ μ g·(r_B − r_A) on its drums
  const Vec3 g = d.load_factor * sys.gravity;
  const double mu = element.law->span_mass_rate();
  if (const double m = element.law->span_mass(d.t, s.extension()); m != 0.0)
    s.wb = 0.5 * m * g, s.wa = (0.5 * m - mu * s.s) * g;
  if (!element.windings.empty()) s.P = element.law->pull(d.t, s.extension()) + 0.5 * mu * g.dot(r);
  return s;
}

std::pair<AppliedLoad, AppliedLoad> element_loads(const ElementState& s) {
  return {{s.xb, s.F * s.e + s.wb, Vec3::Zero()}, {s.xa, -s.F * s.e + s.wa, Vec3::Zero()}};
}

double further_force(const System& sys, const Data& d, int i, bool spatial) {
  const Coordinate& c = sys.coords[i];
  double Q = 0.0;
  for (const auto& law : c.laws) Q += law->force(d.t, d.qa(i), d.qda(i), d.load_factor);
  for (const auto& [k, j] : c.windings) {
    const ForceElement& E = sys.elements[k];
    const Winding& w = E.windings[j];
    Q += w.radius * element_state(sys, d, E, spatial).P * w.factor(d.qda(i)).first;
  }
  return Q;
}

std::pair<double, double> coordinate_derivatives(const System& sys, const Data& d, int i) {
  const Coordinate& c = sys.coords[i];
  std::pair<double, double> dQ{0.0, 0.0};
  for (const auto& law : c.laws) {
    const auto [dq, dqd] = law->derivatives(d.t, d.qa(i), d.qda(i), d.load_factor);
    dQ.first += dq, dQ.second += dqd;
  }
  return dQ;
}

namespace {

// "body" of the coordinate name "body.ry".
std::string joint_name(const Coordinate& c) { return c.name.substr(0, c.name.size() - 3); }

}  // namespace

std::string gimbal_lock_hint(const System& sys, const VecX& q, double tol) {
  std::string hint;
  for (int i : sys.zyx_pitch) {
    const int k = sys.coords[i].free_index;
    if (k < 0 || k >= q.size() || std::abs(std::cos(q(k))) >= tol) continue;
    hint += "; the ZYX angles of " + joint_name(sys.coords[i]) + " are at pitch phi2 = " + std::to_string(q(k)) +
            " rad, near +-pi/2 where they are singular (gimbal lock): turn the joint frame (placement) so "
            "the motion keeps away from it";
  }
  return hint;
}

void check_gimbal_lock(const System& sys, const Data& d) {
  // |cos φ2| < 1e-9 where φ2 = π/2 + kπ + r with |r| < 1e-9 (|cos φ2| = |sin r|): no cosine per call. r carries an
  // error of about |φ2| ε, so beyond 1e3 rad (a run blowing up) the cosine decides, with its exact reduction.
  constexpr double pi = 3.14159265358979323846;
  auto locked = [](double phi) {
    const double x = phi - 0.5 * pi;
    return std::abs(phi) < 1e3 ? std::abs(x - pi * std::round(x / pi)) < 1e-9 : std::abs(std::cos(phi)) < 1e-9;
  };
  for (int i : sys.zyx_pitch)
    if (locked(d.qa(i)))
      throw SimulationError(d.t, "gimbal lock: the ZYX angles of " + joint_name(sys.coords[i]) +
                                     " reached pitch phi2 = +-pi/2, where the mass matrix is singular; turn the joint "
                                     "frame (placement) so the motion keeps away from it");
}

}  // namespace rigidfem
