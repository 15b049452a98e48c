// The sensitivity equations' directional derivatives and projection (sensitivities.hpp).
#include "rigidfem/sensitivities.hpp"

#include <algorithm>
#include <cmath>

#include "rigidfem/constraints.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/kinematics.hpp"

namespace rigidfem {

namespace {

double max_abs(const VecX& v) { return v.size() ? v.cwiseAbs().maxCoeff() : 0.0; }

// The step ε of a central difference along (δq, δq̇): the largest relative change of q or q̇ is 6e-6, relative
// to max(1, |x|) (0: the direction is zero).
double direction_step(const VecX& q, const VecX& qd, const VecX& dq, const VecX& dqd) {
  const double size = std::max(max_abs(dq) / std::max(1.0, max_abs(q)), max_abs(dqd) / std::max(1.0, max_abs(qd)));
  const double eps = 6e-6 / size;
  return size > 0.0 && std::isfinite(eps) ? eps : 0.0;  // a subnormal direction: none (its ε would overflow)
}

// R = M q̈ − f − Gᵀλ (nq) at (t, q, q̇, q̈, λ) on the workspace d of sys; with loops g, G, γ left in d.
VecX step_residual(const System& sys, Data& d, double t, const VecX& q, const VecX& qd, const VecX& qdd,
                   const VecX& lambda) {
  set_state(sys, d, t, q, qd);
  set_accelerations(sys, d, qdd);
  dynamics_kinematics(sys, d);
  VecX r = inverse_dynamics(sys, d);
  if (sys.nl > 0) r -= free_jacobian(sys, d).transpose() * lambda;
  return r;
}

// γ − G q̈ (nl) at (t, q, q̇) for the free accelerations q̈: the constraints' acceleration residual.
VecX acceleration_constraint(const System& sys, Data& d, double t, const VecX& q, const VecX& qd, const VecX& qdd) {
  loop_equations(sys, d, t, q, qd);
  return d.gamma - free_jacobian(sys, d) * qdd;
}

}  // namespace

SensitivityEquations::SensitivityEquations(const System& sys, const std::vector<SensitivityParameter>& parameters)
    : sys_(sys), parameters_(parameters), d_(sys), e_(sys) {
  for (const SensitivityParameter& p : parameters_) {
    plus_.push_back(p.plus ? std::make_unique<Data>(*p.plus) : nullptr);
    minus_.push_back(p.minus ? std::make_unique<Data>(*p.minus) : nullptr);
  }
}

VecX SensitivityEquations::initial() const {
  const int m = 2 * sys_.nq;
  VecX S(m * count());
  for (int j = 0; j < count(); ++j) S.segment(m * j, m) = parameters_[j].S0;
  return S;
}

void SensitivityEquations::rates(Data& fd, double t, const VecX& q, const VecX& qd, const Eigen::Ref<const VecX>& S,
                                 Eigen::Ref<VecX> Sd) {
  const int n = sys_.nq, nl = sys_.nl;
  const VecX qdd = fd.qdd, lambda = nl ? VecX(fd.lambda) : VecX();
  MatX G, Y, GY;
  if (nl > 0) {  // Y = A⁻¹ Gᵀ with the forward dynamics' factorisation
    G = free_jacobian(sys_, fd);
    Y = solve_armature(sys_, fd, G.transpose());
    GY = G * Y;
  }
  const VecX zero = VecX::Zero(n);
  for (int j = 0; j < count(); ++j) {
    const VecX dq = S.segment(2 * n * j, n), dqd = S.segment(2 * n * j + n, n);
    VecX b = residual_derivative(j, t, q, qd, qdd, lambda, dq, dqd, zero, VecX::Zero(nl));
    VecX x(n);
    solve_armature(sys_, fd, -b, x);
    if (nl > 0) x += Y * least_norm(GY, acceleration_constraint_derivative(j, t, q, qd, qdd, dq, dqd) - G * x);
    Sd.segment(2 * n * j, n) = dqd;
    Sd.segment(2 * n * j + n, n) = x;
  }
}

VecX SensitivityEquations::residual_derivative(int j, double t, const VecX& q, const VecX& qd, const VecX& qdd,
                                               const VecX& lambda, const VecX& dq, const VecX& dqd,
                                               const VecX& dqdd, const VecX& dlambda) {
  // K δq + C δq̇ + M δq̈: the RNEA's forward mode (recursive), central differences (Lagrange)
  VecX R = inverse_dynamics_direction(sys_, e_, t, q, qd, qdd, dq, dqd, dqdd);
  if (sys_.nl > 0) {  // −∂(Gᵀλ)/∂q δq by a central difference of G(q)ᵀλ (constraint forces: small terms), −Gᵀδλ
    if (const double eps = direction_step(q, qd, dq, VecX::Zero(sys_.nq)); eps > 0.0) {
      loop_equations(sys_, e_, t, q + eps * dq, qd);
      const VecX up = free_jacobian(sys_, e_).transpose() * lambda;
      loop_equations(sys_, e_, t, q - eps * dq, qd);
      R -= (up - free_jacobian(sys_, e_).transpose() * lambda) / (2.0 * eps);
    }
    loop_equations(sys_, e_, t, q, qd);
    R -= free_jacobian(sys_, e_).transpose() * dlambda;
  }
  // ∂R/∂p = (R(p + h) − R(p))/h: R is linear in the constants the parameter sets; a profile's coefficient by
  // the central difference (R(p + h) − R(p − h))/(2h)
  const SensitivityParameter& p = parameters_[j];
  if (p.plus) {
    const VecX up = step_residual(*p.plus, *plus_[j], t, q, qd, qdd, lambda);
    if (p.minus) {
      R += (up - step_residual(*p.minus, *minus_[j], t, q, qd, qdd, lambda)) / (2.0 * p.h);
    } else {
      // the base residual once per state, for every parameter
      if (!(base_r_.size() && t == base_t_ && q == base_q_ && qd == base_qd_ && qdd == base_qdd_ &&
            lambda == base_lambda_)) {
        base_r_ = step_residual(sys_, e_, t, q, qd, qdd, lambda);
        base_t_ = t, base_q_ = q, base_qd_ = qd, base_qdd_ = qdd, base_lambda_ = lambda;
      }
      R += (up - base_r_) / p.h;
    }
  }
  return R;
}

double SensitivityEquations::difference_noise(int j) const {
  const SensitivityParameter& p = parameters_[j];
  if (!p.plus || !(p.h > 0.0)) return 0.0;
  return p.minus ? 1.0 / (2.0 * p.h) : 1.0 / p.h;
}

VecX SensitivityEquations::force_sizes(double t, const VecX& q, const VecX& qd) {
  return generalized_forces(sys_, e_, t, q, qd, 1.0).cwiseAbs();
}

VecX SensitivityEquations::acceleration_constraint_derivative(int j, double t, const VecX& q, const VecX& qd,
                                                               const VecX& qdd, const VecX& dq, const VecX& dqd) {
  VecX c = VecX::Zero(sys_.nl);
  if (const double eps = direction_step(q, qd, dq, dqd); eps > 0.0) {
    const VecX up = acceleration_constraint(sys_, e_, t, q + eps * dq, qd + eps * dqd, qdd);
    c = (up - acceleration_constraint(sys_, e_, t, q - eps * dq, qd - eps * dqd, qdd)) / (2.0 * eps);
  }
  if (parameters_[j].minus) c += loop_parameter_derivative(j, t, q, qd, qdd).c;
  return c;
}

SensitivityEquations::LoopRates SensitivityEquations::loop_parameter_derivative(int j, double t, const VecX& q,
                                                                                const VecX& qd, const VecX& qdd) {
  const SensitivityParameter& p = parameters_[j];
  const int nl = sys_.nl;
  if (!p.minus) return {VecX::Zero(nl), VecX::Zero(nl), VecX::Zero(nl)};
  // (x(p + h) − x(p − h))/(2h) of x = g, ġ, γ − G q̈ at the same state
  Data& up = *plus_[j];
  Data& down = *minus_[j];
  loop_equations(*p.plus, up, t, q, qd);
  loop_equations(*p.minus, down, t, q, qd);
  const double w = 1.0 / (2.0 * p.h);
  return {w * (up.g - down.g), w * (up.gd - down.gd),
          w * ((up.gamma - free_jacobian(*p.plus, up) * qdd) - (down.gamma - free_jacobian(*p.minus, down) * qdd))};
}

void SensitivityEquations::project(int j, double t, const VecX& q, const VecX& qd, Eigen::Ref<VecX> S) {
  if (sys_.nl == 0) return;
  const int n = sys_.nq;
  VecX dq = S.head(n), dqd = S.tail(n);
  const LoopRates direct = loop_parameter_derivative(j, t, q, qd, VecX::Zero(n));
  loop_equations(sys_, d_, t, q, qd);
  const MatX G = free_jacobian(sys_, d_);
  factor_mass(sys_, d_);
  const MatX Y = solve_armature(sys_, d_, G.transpose());
  const MatX GY = G * Y;
  dq -= Y * least_norm(GY, G * dq + direct.g);
  // ∂ġ/∂q δq along the projected δq, by a central difference of ġ(q ± ε δq, q̇)
  VecX dgd_dq = VecX::Zero(sys_.nl);
  const VecX zero = VecX::Zero(n);
  if (const double eps = direction_step(q, qd, dq, zero); eps > 0.0) {
    loop_equations(sys_, e_, t, q + eps * dq, qd);
    const VecX up = e_.gd;
    loop_equations(sys_, e_, t, q - eps * dq, qd);
    dgd_dq = (up - e_.gd) / (2.0 * eps);
  }
  dqd -= Y * least_norm(GY, G * dqd + dgd_dq + direct.gd);
  S.head(n) = dq;
  S.tail(n) = dqd;
}

}  // namespace rigidfem
