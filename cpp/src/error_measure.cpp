// The local error of a step measured on outputs of the system (error_measure.hpp).
#include "rigidfem/error_measure.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "rigidfem/arms.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/force_elements.hpp"
#include "rigidfem/kinematics.hpp"

namespace rigidfem {

namespace {

using Kind = OutputSpec::Kind;

void check_output(const System& sys, const OutputSpec& o) {
  const auto in = [](int i, int n) { return i >= 0 && i < n; };
  switch (o.kind) {
    case Kind::Bodies: return;
    case Kind::Point:
      if (!in(o.index, sys.nbodies) || !o.r.allFinite())
        bad("error_on", "points on bodies of the system", "a point on body " + std::to_string(o.index));
      return;
    case Kind::Coordinate:
      if (!in(o.index, sys.nq)) bad("error_on", "free coordinates 0 ... nq - 1 = " + std::to_string(sys.nq - 1),
                                    std::to_string(o.index));
      return;
    case Kind::Element:
      if (!in(o.index, static_cast<int>(sys.elements.size())))
        bad("error_on", "force elements of the system", "element " + std::to_string(o.index));
      return;
    case Kind::Loop:
      if (!in(o.index, static_cast<int>(sys.loops.size())))
        bad("error_on", "loops of the system", "loop " + std::to_string(o.index));
      return;
  }
}

/// The RMS displacement of a body's material under the small rigid motion δ = (δθ, δo) of its frame
/// (ground coordinates at the origin): √(|δo + δθ × c|² + δθᵀ G δθ), G = R I_C Rᵀ / m (m²).
double material_displacement(const Vec6& delta, const Vec3& c, const Mat3& G) {
  const Vec3 dth = delta.head<3>();
  const Vec3 dc = delta.tail<3>() + dth.cross(c);
  return std::sqrt(dc.squaredNorm() + std::max(0.0, dth.dot(G * dth)));
}

/// The displacement δo + δθ × x of the point x (global) under δ = (δθ, δo).
Vec3 point_displacement(const Vec6& delta, const Vec3& x) { return delta.tail<3>() + delta.head<3>().cross(x); }

}  // namespace

ErrorMeasure::ErrorMeasure(const System& sys, std::vector<OutputSpec> outputs, double t0, const VecX& q0)
    : sys_(sys), outputs_(std::move(outputs)), d_(sys), dq_(sys.nbodies), dv_(sys.nbodies), xc_(sys.nbodies),
      xc0_(sys.nbodies),
      gyration_(sys.nbodies), element_e_(sys.elements.size()), element_dF_(sys.elements.size()),
      scale_(VecX::Zero(outputs_.size())) {
  if (outputs_.empty()) bad("error_on", "at least one output", "none");
  for (const OutputSpec& o : outputs_) {
    check_output(sys, o);
    need_loops_ = need_loops_ || o.kind == Kind::Loop;
    need_elements_ = need_elements_ || o.kind == Kind::Element;
  }
  // L: the diagonal of the box around the origins, centres of mass and joint frames on the ground at t0
  set_state(sys, d_, t0, q0, VecX::Zero(sys.nq));
  frames(sys, d_);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  const auto hold = [&](const Vec3& x) { lo = lo.cwiseMin(x), hi = hi.cwiseMax(x); };
  for (int p = 0; p < sys.nbodies; ++p) {
    xc0_[p] = (d_.T[p] * d_.com[p].homogeneous()).head<3>();
    hold(d_.T[p].block<3, 1>(0, 3));
    hold(xc0_[p]);
    if (sys.parent[p] < 0) hold(sys.B[p].block<3, 1>(0, 3));
  }
  const double L = sys.nbodies ? (hi - lo).norm() : 0.0;
  L_ = L > 0.0 && std::isfinite(L) ? L : 1.0;
}

void ErrorMeasure::at(double t, const VecX& y) {
  const int n = sys_.nq;
  t_ = t;
  y_ = y;
  set_state(sys_, d_, t, y.head(n), y.segment(n, n));
  // T and the axes (the formulation's kinematics), with Ṫ where the elements' rates need it.
  if (need_elements_)
    kinematics(sys_, d_, true);
  else
    tree_kinematics(sys_, d_);
  for (int p = 0; p < sys_.nbodies; ++p) {
    xc_[p] = (d_.T[p] * d_.com[p].homogeneous()).head<3>();
    const double moved = (xc_[p] - xc0_[p]).norm();
    if (std::isfinite(moved)) moved_ = std::max(moved_, moved);
    const Mat3 R = d_.T[p].topLeftCorner<3, 3>();
    gyration_[p] = d_.mass[p] > 0.0 ? Mat3(R * d_.inertia[p] * R.transpose() / d_.mass[p]) : Mat3::Zero();
  }
  if (need_elements_)
    for (std::size_t j = 0; j < sys_.elements.size(); ++j) {
      const ElementState s = element_state(sys_, d_, sys_.elements[j], false);
      element_e_[j] = s.e;
      element_dF_[j] = sys_.elements[j].law->derivatives(t, s.extension(), 1.0);
    }
  if (need_loops_) {
    if (!dl_) dl_ = std::make_unique<Data>(sys_);
    set_arm_forces(sys_, *dl_, y.segment(2 * n, sys_.nz));
    forward_dynamics(sys_, *dl_, t, y.head(n), y.segment(n, n));
    lambda_ = dl_->lambda;
  }
  // the running scales: the largest |z_k| so far
  for (std::size_t k = 0; k < outputs_.size(); ++k) {
    const OutputSpec& o = outputs_[k];
    double z = 0.0;
    if (o.kind == Kind::Coordinate) z = std::abs(y(o.index));
    if (o.kind == Kind::Element) z = std::abs(element_state(sys_, d_, sys_.elements[o.index], false).F);
    if (o.kind == Kind::Loop)
      z = lambda_.segment(sys_.loop_row[o.index], sys_.loop_row[o.index + 1] - sys_.loop_row[o.index])
              .cwiseAbs()
              .maxCoeff();
    if (std::isfinite(z)) scale_(k) = std::max(scale_(k), z);
  }
}

void ErrorMeasure::twists(const Eigen::Ref<const VecX>& dq, std::vector<Vec6>& out) const {
  for (int p = 0; p < sys_.nbodies; ++p) {
    out[p] = sys_.parent[p] >= 0 ? out[sys_.parent[p]] : Vec6::Zero();
    for (int u = sys_.use_start[p]; u < sys_.use_start[p + 1]; ++u)
      if (sys_.use_q[u] >= 0) out[p] += d_.axes[u] * dq(sys_.use_q[u]);
  }
}

double ErrorMeasure::norm(const Eigen::Ref<const VecX>& e, double h, double atol, double rtol) {
  const int n = sys_.nq;
  if (n == 0) return 0.0;
  twists(e.head(n), dq_);
  twists(e.segment(n, n), dv_);
  const double length_tol = atol + rtol * reach();
  double worst = 0.0;
  for (std::size_t k = 0; k < outputs_.size(); ++k) {
    const OutputSpec& o = outputs_[k];
    const double tol = o.kind == Kind::Bodies || o.kind == Kind::Point ? length_tol : atol + rtol * scale_(k);
    double eps = 0.0;  // |δz| and h |δż| (bodies, points, coordinates)
    switch (o.kind) {
      case Kind::Bodies:
        for (int p = 0; p < sys_.nbodies; ++p)
          if (d_.mass[p] > 0.0)
            eps = std::max({eps, material_displacement(dq_[p], xc_[p], gyration_[p]),
                            h * material_displacement(dv_[p], xc_[p], gyration_[p])});
        break;
      case Kind::Point: {
        const Vec3 x = (d_.T[o.index] * o.r.homogeneous()).head<3>();
        eps = std::max(point_displacement(dq_[o.index], x).norm(), h * point_displacement(dv_[o.index], x).norm());
        break;
      }
      case Kind::Coordinate: eps = std::max(std::abs(e(o.index)), h * std::abs(e(n + o.index))); break;
      case Kind::Element: {
        // δF = F_l δl + F_l̇ δl̇ (+ F_s δs + F_ṡ δṡ of a rope's drum), δl = e·(δr_B − δr_A), δl̇ = e·(δṙ_B − δṙ_A)
        const ForceElement& E = sys_.elements[o.index];
        const auto moved = [&](const std::vector<Vec6>& tw, int body, const Vec3& r) -> Vec3 {
          if (body < 0) return Vec3::Zero();
          return point_displacement(tw[body], (d_.T[body] * r.homogeneous()).head<3>());
        };
        const Vec3& u = element_e_[o.index];
        const double dl = u.dot(moved(dq_, E.body_b, E.point_b) - moved(dq_, E.body_a, E.point_a));
        const double dld = u.dot(moved(dv_, E.body_b, E.point_b) - moved(dv_, E.body_a, E.point_a));
        const ExtensionDerivatives& F = element_dF_[o.index];
        double ds = 0.0, dsd = 0.0;
        for (const Winding& w : E.windings)
          if (const int k = sys_.coords[w.coord].free_index; k >= 0) ds += w.radius * e(k), dsd += w.radius * e(n + k);
        eps = std::abs(F.l * dl + F.ld * dld + F.s * ds + F.sd * dsd);
        break;
      }
      case Kind::Loop: {
        // δλ = (λ(y + s e) − λ(y)) / s, s making |s e| about 1e-7 (1 + |y|)
        const double size = e.head(2 * n).cwiseAbs().maxCoeff();
        if (size == 0.0) break;
        const double s = 1e-7 * (1.0 + y_.head(2 * n).cwiseAbs().maxCoeff()) / size;
        ye_ = y_.head(2 * n) + s * e.head(2 * n);
        set_arm_forces(sys_, *dl_, y_.segment(2 * n, sys_.nz));
        forward_dynamics(sys_, *dl_, t_, ye_.head(n), ye_.tail(n));
        const int r0 = sys_.loop_row[o.index], rows = sys_.loop_row[o.index + 1] - r0;
        eps = ((dl_->lambda.segment(r0, rows) - lambda_.segment(r0, rows)) / s).cwiseAbs().maxCoeff();
        break;
      }
    }
    worst = std::max(worst, eps / tol);
  }
  return worst;
}

}  // namespace rigidfem
