#include "rigidfem/outputs.hpp"

#include <cmath>
#include <stdexcept>

#include "rigidfem/arms.hpp"
#include "rigidfem/constraints.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/kinematics.hpp"

namespace rigidfem {

double kinetic_energy(const System& sys, const Data& d) {
  check_data(sys, d);
  double E = 0.0;
  for (int p = 0; p < sys.nbodies; ++p) E += 0.5 * (d.Td[p] * d.H[p] * d.Td[p].transpose()).trace();
  return E;
}

double gravity_energy(const System& sys, const Data& d) {
  check_data(sys, d);
  double V = 0.0;
  for (int p = 0; p < sys.nbodies; ++p) V -= sys.gravity.dot((d.T[p] * d.H[p].col(3)).head<3>());
  // heavy ropes' spans: −½ m g·(r_A + r_B) + μ s g·r_A (kinematics.hpp: ElementState)
  for (const ForceElement& E : sys.elements)
    if (E.law->span_mass_rate() != 0.0) {
      const ElementState s = element_state(sys, d, E, false);
      const double m = E.law->span_mass(d.t, s.extension()), mu = E.law->span_mass_rate();
      V -= sys.gravity.dot(0.5 * m * (s.xa + s.xb) - mu * s.s * s.xa);
    }
  return V;
}

double elastic_energy(const System& sys, const Data& d) {
  check_data(sys, d);
  double V = 0.0;
  for (int i = 0; i < sys.nc; ++i) {  // what each coordinate's laws store (coordinate_laws.hpp)
    const Coordinate& c = sys.coords[i];
    V += c.spring.energy(d.qa(i), d.spring_scale(i));
    for (const auto& law : c.laws) V += law->energy(d.t, d.qa(i));
  }
  for (const ForceElement& E : sys.elements)  // what each element's law stores (force_elements.hpp)
    if (E.law->elastic()) V += E.law->energy(d.t, element_state(sys, d, E, false).extension());
  if (!sys.contacts.empty()) V += contact_energy(sys, d);  // what the contacts store (contact.hpp)
  return V;
}

double dissipated_power(const System& sys, const Data& d) {
  check_data(sys, d);
  double P = 0.0;
  for (int i = 0; i < sys.nc; ++i) {  // what each coordinate's laws dissipate (coordinate_laws.hpp)
    const Coordinate& c = sys.coords[i];
    P += c.spring.power(d.qda(i), d.spring_scale(i));
    for (const auto& law : c.laws) P += law->power(d.t, d.qa(i), d.qda(i));
  }
  for (const ForceElement& E : sys.elements) {  // what each element's law dissipates (force_elements.hpp)
    if (E.law->dissipative()) {
      const ElementState s = element_state(sys, d, E, false);
      P += E.law->power(d.t, s.extension(), s.F);
    }
    // a capstan's friction: of the generalised force r P c on its coordinate, r P (c − 1) opposes q̇
    for (const Winding& w : E.windings)
      if (w.capstan != 0.0) {
        const double qd = d.qda(w.coord);
        P -= w.radius * element_state(sys, d, E, false).P * (w.factor(qd).first - 1.0) * qd;
      }
  }
  if (!sys.contacts.empty()) P += contact_power(sys, d);  // what the contacts dissipate (contact.hpp)
  return P;
}

Energies energies(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                  const Eigen::Ref<const VecX>& qd) {
  set_state(sys, d, t, q, qd);
  kinematics(sys, d);
  return {kinetic_energy(sys, d), gravity_energy(sys, d), elastic_energy(sys, d), dissipated_power(sys, d)};
}

const Mat4& body_pose(const System& sys, Data& d, int body, double t, const Eigen::Ref<const VecX>& q) {
  check_body(sys, body, "body");
  set_state(sys, d, t, q, VecX::Zero(sys.nq));
  frames(sys, d);
  return d.T[body];
}

Vec3 point_position(const System& sys, Data& d, const Point& point, double t, const Eigen::Ref<const VecX>& q) {
  return (body_pose(sys, d, point.body, t, q) * point.r.homogeneous()).head<3>();
}

MatX point_positions(const System& sys, Data& d, const std::vector<Point>& points, double t,
                     const Eigen::Ref<const VecX>& q) {
  for (const Point& p : points) check_body(sys, p.body, "points");
  set_state(sys, d, t, q, VecX::Zero(sys.nq));
  frames(sys, d);
  MatX X(points.size(), 3);
  for (std::size_t k = 0; k < points.size(); ++k)
    X.row(k) = (d.T[points[k].body] * points[k].r.homogeneous()).head<3>().transpose();
  return X;
}

Vec3 point_velocity(const System& sys, Data& d, const Point& point, double t, const Eigen::Ref<const VecX>& q,
                    const Eigen::Ref<const VecX>& qd) {
  check_body(sys, point.body, "body");
  set_state(sys, d, t, q, qd);
  kinematics(sys, d);
  return (d.Td[point.body] * point.r.homogeneous()).head<3>();
}

MatX element_states(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                    const Eigen::Ref<const VecX>& qd) {
  set_state(sys, d, t, q, qd);
  kinematics(sys, d);  // with rates: l̇ needs Ṫ
  MatX S(sys.elements.size(), 3);
  for (std::size_t k = 0; k < sys.elements.size(); ++k) {
    const ElementState e = element_state(sys, d, sys.elements[k], false);
    S.row(k) << e.l, e.ld, e.F;
  }
  return S;
}

StateOutputs evaluate_outputs(const System& sys, const Eigen::Ref<const VecX>& t, const Eigen::Ref<const RowMatX>& Q,
                              const Eigen::Ref<const RowMatX>& QD, const Eigen::Ref<const RowMatX>& S,
                              const Eigen::Ref<const RowMatX>& L) {
  const Eigen::Index N = t.size();
  if (Q.rows() != N || QD.rows() != N || Q.cols() != sys.nq || QD.cols() != sys.nq)
    throw std::invalid_argument("q, qd: expected (len(t), nq) arrays");
  if (S.rows() != N || S.cols() != sys.nz) throw std::invalid_argument("s: expected a (len(t), nz) array");
  if ((L.rows() != N && L.rows() != 0) || L.cols() != sys.nl)
    throw std::invalid_argument("lambda: expected a (len(t), nl) or (0, nl) array");
  const Eigen::Index nloops = static_cast<Eigen::Index>(sys.loops.size());
  StateOutputs out{MatX(N, sys.nq), MatX(N, sys.np), VecX(N), VecX(N), VecX(N), VecX(N), MatX(N, 6 * nloops),
                   MatX(N, sys.elements.size())};
  Data d(sys);
  VecX s(sys.nz);
  for (Eigen::Index k = 0; k < N; ++k) {
    interruption_point();
    s = S.row(k).transpose();
    set_arm_forces(sys, d, s);
    set_state(sys, d, t(k), Q.row(k).transpose(), QD.row(k).transpose());
    kinematics(sys, d);  // with rates: the kinetic energy needs Ṫ
    out.kinetic(k) = kinetic_energy(sys, d);
    out.gravity(k) = gravity_energy(sys, d);
    out.elastic(k) = elastic_energy(sys, d) + arm_energy(sys, s);
    out.power(k) = dissipated_power(sys, d) + arm_power(sys, s);
    for (std::size_t e = 0; e < sys.elements.size(); ++e)
      out.element_forces(k, static_cast<Eigen::Index>(e)) = element_state(sys, d, sys.elements[e], false).F;
    forward_dynamics(sys, d, t(k), Q.row(k).transpose(), QD.row(k).transpose());
    out.qdd.row(k) = d.qdd.transpose();
    driving_forces(sys, d);
    out.tau.row(k) = d.tau.transpose();
    if (nloops) {
      // (nloops, 6) from the integrator's λ where it has its own, else this forward dynamics'
      const bool own = L.rows() && L.row(k).allFinite();
      const RowMatX w = loop_reactions(sys, d, own ? VecX(L.row(k).transpose()) : d.lambda);
      out.reactions.row(k) = Eigen::Map<const Eigen::RowVectorXd>(w.data(), w.size());
    }
  }
  return out;
}

MatX point_positions(const System& sys, int body, const Vec3& r, int frame, const Eigen::Ref<const VecX>& t,
                     const Eigen::Ref<const RowMatX>& Q) {
  if (body < 0 || body >= sys.nbodies || frame < -1 || frame >= sys.nbodies)
    throw std::invalid_argument("point, frame: expected bodies of this system");
  if (Q.rows() != t.size() || Q.cols() != sys.nq) throw std::invalid_argument("q: expected a (len(t), nq) array");
  MatX P(t.size(), 3);
  Data d(sys);
  const VecX zero = VecX::Zero(sys.nq);
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    if (k % 64 == 0) interruption_point();
    set_state(sys, d, t(k), Q.row(k).transpose(), zero);
    frames(sys, d);
    Vec4 x = d.T[body] * r.homogeneous();
    if (frame >= 0) x = affine_inverse(d.T[frame]) * x;
    P.row(k) = x.head<3>().transpose();
  }
  return P;
}

RowMatX body_poses(const System& sys, const Eigen::Ref<const VecX>& t, const Eigen::Ref<const RowMatX>& Q) {
  if (Q.rows() != t.size() || Q.cols() != sys.nq) throw std::invalid_argument("q: expected a (len(t), nq) array");
  RowMatX P(t.size() * sys.nbodies, 12);
  Data d(sys);
  const VecX zero = VecX::Zero(sys.nq);
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    interruption_point();
    set_state(sys, d, t(k), Q.row(k).transpose(), zero);
    frames(sys, d);  // one positions-only pass gives every body's T_i
    for (int i = 0; i < sys.nbodies; ++i) {
      const Mat4& T = d.T[i];
      P.row(k * sys.nbodies + i) << T(0, 0), T(0, 1), T(0, 2), T(1, 0), T(1, 1), T(1, 2), T(2, 0), T(2, 1), T(2, 2),
          T(0, 3), T(1, 3), T(2, 3);
    }
  }
  return P;
}

}  // namespace rigidfem
