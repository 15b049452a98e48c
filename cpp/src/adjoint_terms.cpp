// The adjoint's terms besides the residual's reverse mode: the objective's outputs and their transposed
// Jacobian, and μᵀ ∂r/∂p of every parameter in one pass (adjoint.hpp).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "rigidfem/adjoint.hpp"
#include "rigidfem/constraints.hpp"
#include "rigidfem/derivatives.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/recursive.hpp"

namespace rigidfem {

int output_size(const std::vector<OutputSpec>& outputs) {
  int K = 0;
  for (const OutputSpec& o : outputs) K += o.kind == OutputSpec::Kind::Point ? 3 : 1;
  return K;
}

void objective_outputs(const System& sys, const Data& d, const std::vector<OutputSpec>& outputs, Eigen::Ref<VecX> y) {
  int k = 0;
  for (const OutputSpec& o : outputs) {
    if (o.kind == OutputSpec::Kind::Point) {
      y.segment<3>(k) = (d.T[o.index] * o.r.homogeneous()).head<3>();
      k += 3;
    } else {
      y(k++) = d.qa(sys.free_coords[o.index]);
    }
  }
}

void objective_outputs_vjp(const System& sys, const Data& d, const std::vector<OutputSpec>& outputs,
                           const VecX& ybar, Eigen::Ref<VecX> qbar, VecX& pbar) {
  int k = 0;
  for (const OutputSpec& o : outputs) {
    if (o.kind != OutputSpec::Kind::Point) {
      qbar(o.index) += ybar(k++);
      continue;
    }
    // x = T_b r moves by δx = Σ_u δq_u (ω_u × x + v_u) over the uses u on b's path: ȳ·δx = Σ δq_u s_uᵀ (x × ȳ, ȳ)
    const Vec3 x = (d.T[o.index] * o.r.homogeneous()).head<3>(), yb = ybar.segment<3>(k);
    k += 3;
    Vec6 w;
    w << x.cross(yb), yb;
    for (int p = o.index; p >= 0; p = sys.parent[p])
      for (int u = sys.use_start[p]; u < sys.use_start[p + 1]; ++u) {
        const double c = d.axes[u].dot(w);
        if (sys.use_q[u] >= 0)
          qbar(sys.use_q[u]) += c;
        else if (sys.use_drive[u] >= 0)
          pbar(sys.use_drive[u]) += c;
      }
  }
}

ParameterVjp::ParameterVjp(const System& sys, const std::vector<SensitivityParameter>& parameters)
    : sys_(sys), parameters_(parameters), touched_(parameters.size()), whole_(parameters.size(), false),
      V_(sys.nbodies),
      base_{std::vector<double>(sys.nbodies), std::vector<double>(sys.nc), std::vector<double>(sys.elements.size()),
            std::vector<double>(sys.loads.size()), std::vector<double>()},
      inertia_rates_(parameters.size()), rated_(sys.nbodies, 0), W_(sys.nbodies), own_(sys.coords.size()),
      own_at_t_(sys.coords.size(), 0) {
  for (std::size_t j = 0; j < parameters_.size(); ++j) {
    for (const auto& X : {parameters_[j].plus, parameters_[j].minus}) {
      if (!X) continue;
      std::vector<Component>& touched = touched_[j];
      auto add = [&](Component::Kind kind, int index) {
        for (const Component& c : touched)
          if (c.kind == kind && c.index == index) return;
        touched.push_back({kind, index});
      };
      for (int b = 0; b < sys.nbodies; ++b)
        if (X->H[b] != sys.H[b]) add(Component::Body, b);
      for (int i = 0; i < sys.nc; ++i) {
        const Coordinate &a = X->coords[i], &c = sys.coords[i];
        if (c.free_index >= 0 && (a.spring != c.spring || a.laws != c.laws)) add(Component::Coordinate, i);
        if (a.drive != c.drive) add(Component::Drive, i);
      }
      for (std::size_t e = 0; e < sys.elements.size(); ++e)
        if (X->elements[e].law != sys.elements[e].law) add(Component::Element, static_cast<int>(e));
      for (std::size_t l = 0; l < sys.loads.size(); ++l) {
        const Load &a = X->loads[l], &c = sys.loads[l];
        if (a.force != c.force || a.torque != c.torque || a.scale != c.scale) add(Component::Load, static_cast<int>(l));
      }
      for (std::size_t k = 0; k < sys.loops.size(); ++k)
        if (X->loops[k].drive != sys.loops[k].drive) add(Component::Actuator, static_cast<int>(k));
      // a contact's law reaches the forces of every overlap, found anew at each state: such a parameter
      // differences μᵀr whole
      for (std::size_t k = 0; k < sys.contacts.size(); ++k)
        if (X->contacts[k].law != sys.contacts[k].law) whole_[j] = true;
      // a link of varying length's rfes' inertias and flow loads scale with L(t) (d's, not X's constants), and
      // its length reaches every term: such a parameter differences μᵀr whole
      for (std::size_t f = 0; f < sys.flows.size(); ++f) {
        const Flow& F = sys.flows[f];
        if (X->flows[f].length != F.length) whole_[j] = true;
        for (const Component& c : touched)
          if (c.kind == Component::Body && c.index >= F.first && c.index <= F.first + F.elements) whole_[j] = true;
      }
    }
    for (Component& c : touched_[j])
      if (c.kind == Component::Drive) c.slot = static_cast<int>(rates_.size()), rates_.emplace_back();
    rated_at_t_.assign(rates_.size(), 0);
    if (whole_[j]) continue;
    // the bodies' inertias moved by p_j: İ = (I(p + h) − I(p ∓ h)) / (2h or h) in each body's frame
    const SensitivityParameter& p = parameters_[j];
    for (const Component& c : touched_[j]) {
      if (c.kind != Component::Body) continue;
      const int b = c.index;
      auto inertia = [b](const System& X) { return spatial_inertia(X.mass[b], X.com[b], X.inertia[b]); };
      const Mat6 rate = p.minus ? Mat6((inertia(*p.plus) - inertia(*p.minus)) / (2.0 * p.h))
                                : Mat6((inertia(*p.plus) - inertia(sys)) / p.h);
      inertia_rates_[j].push_back({b, rate});
      rated_[b] = 1;
    }
  }
}

double ParameterVjp::power(const System& X, const Data& d, const Component& c, const VecX& mu) const {
  auto velocity = [&](int b, const Vec3& x) -> Vec3 {  // the point x of body b under the virtual velocity
    return b < 0 ? Vec3::Zero() : Vec3(V_[b].tail<3>() + V_[b].head<3>().cross(x));
  };
  switch (c.kind) {
    case Component::Body: {  // V_bᵀ (I a + v ×* I v), gravity in a (a_0 = −g)
      const int b = c.index;
      const Mat3 R = d.T[b].topLeftCorner<3, 3>();
      const Mat6 I = spatial_inertia(X.mass[b], R * X.com[b] + d.T[b].topRightCorner<3, 1>(),
                                     R * X.inertia[b] * R.transpose());
      return V_[b].dot(I * d.a[b] + crossf(d.v[b], I * d.v[b]));
    }
    case Component::Coordinate:  // −μ_k Q_k
      return -mu(X.coords[c.index].free_index) * passive_force(X, d, c.index, true);
    case Component::Element: {  // −(F e + w_B)·V_b(x_b) + (F e − w_A)·V_a(x_a), and each winding's −μ_k r P c
      const ForceElement& E = X.elements[c.index];
      const ElementState s = element_state(X, d, E, true);
      double p = -(s.F * s.e + s.wb).dot(velocity(E.body_b, s.xb)) + (s.F * s.e - s.wa).dot(velocity(E.body_a, s.xa));
      for (const Winding& w : E.windings)
        if (const int k = X.coords[w.coord].free_index; k >= 0)
          p -= mu(k) * w.radius * s.P * w.factor(d.qda(w.coord)).first;
      return p;
    }
    case Component::Load: {  // −V_bᵀ (x × F + τ, F)
      const Load& L = X.loads[c.index];
      const AppliedLoad a = applied_load(d, L);
      return -(V_[L.body].head<3>().dot(a.x.cross(a.F) + a.tau) + V_[L.body].tail<3>().dot(a.F));
    }
    case Component::Drive:     // by the prescribed coordinate's derivatives (add)
    case Component::Actuator:  // not in r: in the loops' g, G, γ (add_loops)
      return 0.0;
  }
  return 0.0;
}

double ParameterVjp::base_power(const Data& d, const Component& c, const VecX& mu) {
  double& cached = base_[c.kind][c.index];  // a component many parameters change (E: every sde) is evaluated once
  if (std::isnan(cached)) cached = power(sys_, d, c, mu);
  return cached;
}

MotionState ParameterVjp::drive_derivative(int j, int coord, double t) {
  const SensitivityParameter& p = parameters_[j];
  const MotionState up = p.plus->coords[coord].drive->at(t);
  const MotionState down = p.minus ? p.minus->coords[coord].drive->at(t) : own_drive(coord, t);
  const double h = p.minus ? 2.0 * p.h : p.h;
  return {(up.q - down.q) / h, (up.qd - down.qd) / h, (up.qdd - down.qdd) / h};
}

const MotionState& ParameterVjp::own_drive(int coord, double t) {
  if (!(t == own_t_)) own_t_ = t, std::fill(own_at_t_.begin(), own_at_t_.end(), 0);
  if (!own_at_t_[coord]) own_[coord] = sys_.coords[coord].drive->at(t), own_at_t_[coord] = 1;
  return own_[coord];
}

const MotionState& ParameterVjp::drive_rate(int j, const Component& c, double t) {
  if (!(t == rates_t_)) {
    rates_t_ = t;
    std::fill(rated_at_t_.begin(), rated_at_t_.end(), 0);
  }
  if (!rated_at_t_[c.slot]) rates_[c.slot] = drive_derivative(j, c.index, t), rated_at_t_[c.slot] = 1;
  return rates_[c.slot];
}

double ParameterVjp::residual_power(const System& X, const Data& d, const VecX& mu) {
  if (!e_) e_ = std::make_unique<Data>(sys_);
  VecX q(sys_.nq), qd(sys_.nq), qdd(sys_.nq);
  for (int k = 0; k < sys_.nq; ++k) {
    const int i = sys_.free_coords[k];
    q(k) = d.qa(i), qd(k) = d.qda(i), qdd(k) = d.qdda(i);
  }
  set_state(X, *e_, d.t, q, qd);
  set_accelerations(X, *e_, qdd);
  dynamics_kinematics(X, *e_);
  return mu.dot(inverse_dynamics(X, *e_));
}

void ParameterVjp::add(const Data& d, const VecX& mu, const ResidualVjp& r, double w, Eigen::Ref<VecX> grad) {
  // V_b = V_parent + Σ_{free uses u of b's joint} s_u μ_u: each body's velocity for q̇ = μ
  for (int b = 0; b < sys_.nbodies; ++b) {
    V_[b] = sys_.parent[b] >= 0 ? V_[sys_.parent[b]] : Vec6::Zero();
    for (int u = sys_.use_start[b]; u < sys_.use_start[b + 1]; ++u)
      if (sys_.use_q[u] >= 0) V_[b] += d.axes[u] * mu(sys_.use_q[u]);
  }
  // V̂, â, v̂ and ŷ = −v̂ ×m V̂ in each rated body's frame: (ω, v_O) ↦ (Rᵀω, Rᵀ(v_O + ω × o)), o its origin; a
  // parameter's part V̂ᵀ İ â + ŷᵀ İ v̂ is ⟨İ, W⟩ (the sum of the entries' products) with W = V̂ âᵀ + ŷ v̂ᵀ, once a body
  for (int b = 0; b < sys_.nbodies; ++b) {
    if (!rated_[b]) continue;
    const Mat3 Rt = d.T[b].topLeftCorner<3, 3>().transpose();
    const Vec3 o = d.T[b].topRightCorner<3, 1>();
    auto local = [&](const Vec6& m) {
      Vec6 x;
      x << Rt * m.head<3>(), Rt * (m.tail<3>() + m.head<3>().cross(o));
      return x;
    };
    const Vec6 V = local(V_[b]), a = local(d.a[b]), v = local(d.v[b]), y = -crossm(v, V);
    W_[b].noalias() = V * a.transpose();
    W_[b].noalias() += y * v.transpose();
  }
  const double t = d.t;
  for (auto& cache : base_) std::fill(cache.begin(), cache.end(), std::numeric_limits<double>::quiet_NaN());
  double base = std::numeric_limits<double>::quiet_NaN();  // μᵀr of the run's system, for whole differences
  for (std::size_t j = 0; j < parameters_.size(); ++j) {
    const SensitivityParameter& p = parameters_[j];
    if (!p.plus) continue;
    if (whole_[j]) {  // μᵀ(r(p + h) − r(p ∓ h))
      const double up = residual_power(*p.plus, d, mu);
      if (!p.minus && std::isnan(base)) base = residual_power(sys_, d, mu);
      grad(j) += w * (p.minus ? (up - residual_power(*p.minus, d, mu)) / (2.0 * p.h) : (up - base) / p.h);
      continue;
    }
    double sum = 0.0;
    for (const InertiaRate& r : inertia_rates_[j]) sum += r.rate.cwiseProduct(W_[r.body]).sum();
    for (const Component& c : touched_[j]) {
      if (c.kind == Component::Actuator || c.kind == Component::Body) continue;
      if (c.kind == Component::Drive) {  // the reverse mode's ∂(μᵀr)/∂ of the prescribed coordinate's motion
        const int k = sys_.coords[c.index].drive_index;
        const MotionState& dp = drive_rate(static_cast<int>(j), c, t);
        sum += r.pq(k) * dp.q + r.pqd(k) * dp.qd + r.pqdd(k) * dp.qdd;
      } else if (p.minus) {
        sum += (power(*p.plus, d, c, mu) - power(*p.minus, d, c, mu)) / (2.0 * p.h);
      } else {
        sum += (power(*p.plus, d, c, mu) - base_power(d, c, mu)) / p.h;
      }
    }
    grad(j) += w * sum;
  }
}

bool ParameterVjp::moves_loops(int j) const {
  return std::any_of(touched_[j].begin(), touched_[j].end(), [](const Component& c) {
    return c.kind == Component::Drive || c.kind == Component::Actuator;
  });
}

void ParameterVjp::add_loops(double t, const VecX& q, const VecX& qd, const VecX& qdd, const VecX& lambda,
                             const VecX& mu, const VecX& nu, bool acceleration, Eigen::Ref<VecX> grad) {
  // μᵀ(−Gᵀλ) + νᵀ c on a system at p ± h
  add_loop_difference([&](const System& X) {
    loop_equations(X, *e_, t, q, qd);
    const MatX G = free_jacobian(X, *e_);
    const VecX c = acceleration ? VecX(G * qdd - e_->gamma) : VecX(e_->g);
    return -mu.dot(G.transpose() * lambda) + nu.dot(c);
  }, grad);
}

void ParameterVjp::add_projection(double t, const VecX& q, const VecX& qd, const VecX& a, const VecX& b,
                                  Eigen::Ref<VecX> grad) {
  add_loop_difference([&](const System& X) {  // aᵀg + bᵀġ on a system at p ± h
    loop_equations(X, *e_, t, q, qd);
    return a.dot(e_->g) + b.dot(e_->gd);
  }, grad);
}

void ParameterVjp::add_prescribed(double t, const VecX& pbar, Eigen::Ref<VecX> grad) {
  for (std::size_t j = 0; j < parameters_.size(); ++j)
    for (const Component& c : touched_[j])
      if (c.kind == Component::Drive)
        grad(j) += pbar(sys_.coords[c.index].drive_index) * drive_rate(static_cast<int>(j), c, t).q;
}

}  // namespace rigidfem
