// The discrete adjoint of the Newmark family with checkpointing (adjoint.hpp).
#include "rigidfem/adjoint.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "rigidfem/derivatives.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/gmres.hpp"
#include "rigidfem/newton_matrix.hpp"

namespace rigidfem {

namespace {

using Clock = std::chrono::steady_clock;

StepState step_state(double t, double h, const NewmarkState& s) { return {t, h, s.q, s.v, s.qdd}; }

// The run's grid: t_k = t0 + k dt, the last step landing on t_end (as integrate() takes fixed steps).
std::vector<double> grid(double t0, double t_end, double dt) {
  const double span = t_end - t0, near_end = t_end - 1e-12 * span;
  std::vector<double> t{t0};
  while (t.back() < t_end) {
    double t1 = t0 + static_cast<double>(t.size()) * dt;
    if (t1 > near_end) t1 = t_end;
    t.push_back(t1);
  }
  return t;
}

}  // namespace

NewmarkAdjoint::NewmarkAdjoint(std::shared_ptr<const System> sys, const IntegratorOptions& o,
                               std::vector<OutputSpec> outputs, double memory)
    : sys_(std::move(sys)), o_(o), outputs_(std::move(outputs)), memory_(memory), d_(*sys_) {
  const System& s = *sys_;
  if (s.algorithm != Algorithm::Recursive)
    throw std::invalid_argument("system: expected a system compiled with algorithm='recursive' (the adjoint "
                                "transposes the recursive engine's derivatives), got algorithm='lagrange'");
  if (s.nl > 0) throw std::invalid_argument("system: expected no loop closures (not implemented for the adjoint yet)");
  if (s.nz > 0) throw std::invalid_argument("system: expected no Maxwell arms (not implemented for the adjoint yet)");
  if (!s.flows.empty())
    throw std::invalid_argument("system: expected no link of varying length (not implemented for the adjoint yet)");
  if (!(o.dt > 0.0)) bad("dt", "a fixed step > 0 (s)", num(o.dt));
  if (!(memory > 0.0)) bad("memory", "a number of bytes > 0", num(memory));
  for (const OutputSpec& out : outputs_) {
    if (out.kind == OutputSpec::Kind::Point) {
      check_body(s, out.index, "outputs");
    } else if (out.kind != OutputSpec::Kind::Coordinate || out.index < 0 || out.index >= s.nq) {
      bad("outputs", "points and free coordinates", "another output");
    }
  }
  params_ = std::make_unique<ParameterVjp>(s, o.sensitivities);
  o_.sensitivities.clear();  // the stepper runs the state alone
  o_.adaptive = 0;
  matrix_ = NewtonMatrix::make(s, o_, istats_);
}

void NewmarkAdjoint::forward(double t0, double t_end, const VecX& q0, const VecX& qd0) {
  const auto start = Clock::now();
  const System& s = *sys_;
  const int n = s.nq, K = output_size(outputs_);
  if (!(t_end > t0)) bad("t_end", "a time after t0 = " + num(t0) + " s", num(t_end));
  t_ = grid(t0, t_end, o_.dt);
  const long N = static_cast<long>(t_.size()) - 1;
  // every state if they fit, else checkpoints every k = ⌈√N⌉ steps and one segment of k states
  const double state_bytes = 8.0 * (4.0 * n + 16.0) + 8.0 * (3.0 * n + 2.0);
  interval_ = 1;
  if ((N + 1) * state_bytes > memory_) {
    interval_ = static_cast<long>(std::ceil(std::sqrt(static_cast<double>(N))));
    const double need = (N / interval_ + 2 + interval_) * state_bytes;
    if (need > memory_)
      bad("memory", "at least " + num(need) + " bytes (2√N states of this run's " + std::to_string(N) + " steps)",
          num(memory_));
  }
  stepper_ = make_newmark_stepper(s, o_, istats_);
  VecX y0(2 * n);
  y0 << q0, qd0;
  stepper_->start(t0, y0);
  checkpoints_.assign(1, stepper_->current());
  Y_.resize(N + 1, K);
  auto record = [&](long k) {
    set_state(s, d_, t_[k], stepper_->current().q, stepper_->current().v);
    tree_kinematics(s, d_);
    objective_outputs(s, d_, outputs_, Y_.row(k).transpose());
  };
  record(0);
  for (long k = 0; k < N; ++k) {
    double err = 0.0;
    if (!stepper_->attempt(t_[k], t_[k + 1] - t_[k], nullptr, err))
      step_failure(t_[k], t_[k + 1] - t_[k],
                   "Newton iterations did not converge in newton_max_iterations = " +
                       std::to_string(o_.newton_max_iterations) + "; reduce dt or raise newton_max_iterations");
    stepper_->accept();
    if ((k + 1) % interval_ == 0) checkpoints_.push_back(stepper_->current());
    record(k + 1);
  }
  stats_ = {};
  stats_.steps = N;
  stats_.checkpoints = static_cast<long>(checkpoints_.size());
  stats_.interval = interval_;
  stats_.forward_time = std::chrono::duration<double>(Clock::now() - start).count();
}

void NewmarkAdjoint::replay(long first, long last, std::vector<StepState>& states) {
  states.clear();
  const NewmarkState& c = checkpoints_[first / interval_];
  states.push_back(step_state(t_[first], first ? t_[first] - t_[first - 1] : 0.0, c));
  if (last == first) return;
  if (interval_ == 1) {  // every state kept
    states.push_back(step_state(t_[last], t_[last] - t_[first], checkpoints_[last]));
    return;
  }
  stepper_->restore(t_[first], c);
  for (long k = first; k < last; ++k) {
    double err = 0.0;
    if (!stepper_->attempt(t_[k], t_[k + 1] - t_[k], nullptr, err))
      step_failure(t_[k], t_[k + 1] - t_[k], "Newton iterations did not converge when the run was repeated");
    stepper_->accept();
    ++stats_.recomputed_steps;
    states.push_back(step_state(t_[k + 1], t_[k + 1] - t_[k], stepper_->current()));
  }
}

VecX NewmarkAdjoint::transposed_solve(const StepState& s, const VecX& g, double c1, double c2) {
  const System& sys = *sys_;
  // Sᵀ v = M v + c₁ Cᵀ v + c₂ Kᵀ v by the reverse mode at the step's end
  at(s);  // the reverse mode's passes start from the state and its axes
  auto S = [&](const VecX& v, VecX& out) {
    const ResidualVjp r = rnea_vector_jacobian_product(sys, d_, v);
    out = r.qdd + c1 * r.qd + c2 * r.q;
  };
  // a preconditioner from an earlier step while GMRES converges in a few iterations with it
  if (!preconditioner_ || last_iterations_ > 8) {
    matrix_->linearize(s.t, s.q, s.v, s.qdd, VecX());
    if (!(matrix_->factor(c1, c2, VecX()) > 1e-15))
      throw SimulationError(s.t, "the adjoint's Newton matrix M + γh C + βh² K is singular");
    preconditioner_ = true;
    ++stats_.preconditioner_refreshes;
  }
  auto P = [&](const VecX& v, VecX& out) { matrix_->precondition_transposed(v, out); };
  Gmres<double> gmres;
  VecX mu;
  last_iterations_ = gmres.solve(S, P, g, mu, 1e-11, 200);
  stats_.gmres_iterations += last_iterations_;
  if (!mu.allFinite()) throw SimulationError(s.t, "the adjoint became NaN or inf");
  return mu;
}

void NewmarkAdjoint::at(const StepState& s) {
  set_state(*sys_, d_, s.t, s.q, s.v);
  set_accelerations(*sys_, d_, s.qdd);
  tree_kinematics(*sys_, d_);
}

void NewmarkAdjoint::output_vjp(const StepState& s, const VecX& ybar, VecX& qbar, VecX& grad) {
  const System& sys = *sys_;
  set_state(sys, d_, s.t, s.q, s.v);
  tree_kinematics(sys, d_);
  VecX pbar = VecX::Zero(sys.np);
  objective_outputs_vjp(sys, d_, outputs_, ybar, qbar, pbar);
  if (sys.np > 0) params_->add_prescribed(s.t, pbar, grad);
}

VecX NewmarkAdjoint::backward(const Eigen::Ref<const RowMatX>& ybar) {
  const auto start = Clock::now();
  const System& sys = *sys_;
  const int n = sys.nq;
  const long N = static_cast<long>(t_.size()) - 1;
  if (N < 1 || checkpoints_.empty()) throw std::logic_error("NewmarkAdjoint::backward before forward");
  if (ybar.rows() != N + 1 || ybar.cols() != Y_.cols())
    bad("ybar", "an array (" + std::to_string(N + 1) + ", " + std::to_string(Y_.cols()) + ")",
        "(" + std::to_string(ybar.rows()) + ", " + std::to_string(ybar.cols()) + ")");
  const NewmarkCoefficients k = stepper_->coefficients();
  const double z = (1.0 - k.af) / (1.0 - k.am);
  const int P = params_->count();
  VecX grad = VecX::Zero(P), qb = VecX::Zero(n), vb = VecX::Zero(n), ab = VecX::Zero(n), zb = VecX::Zero(n);
  std::vector<StepState> states;
  for (long last = N; last > 0;) {
    const long first = ((last - 1) / interval_) * interval_;
    replay(first, last, states);
    for (long m = last; m > first; --m) {
      interruption_point();
      const StepState& s = states[m - first];
      output_vjp(s, ybar.row(m).transpose(), qb, grad);
      const double h = s.h;
      // the step m−1 → m transposed (adjoint.hpp)
      const VecX at = ab + (k.beta * h * h) * qb + (k.gamma * h) * vb;
      const VecX g = zb + z * at;
      const VecX mu = transposed_solve(s, g, k.gamma * z * h, k.beta * z * h * h);
      const ResidualVjp r = rnea_vector_jacobian_product(sys, d_, mu);
      const VecX qh = qb - r.q, vh = vb - r.qd;
      const VecX A = ab + (k.beta * h * h) * qh + (k.gamma * h) * vh;
      qb = qh;
      vb = h * qh + vh;
      ab = (h * h * (0.5 - k.beta)) * qh + (h * (1.0 - k.gamma)) * vh - (k.am / (1.0 - k.am)) * A;
      zb = (k.af / (1.0 - k.am)) * A;
      params_->add(s.t, s.q, s.v, s.qdd, mu, r, -1.0, grad);
    }
    last = first;
  }
  // t0: the objective there, and a_0 = q̈_0 from r(q_0, q̇_0, q̈_0) = 0
  replay(0, 0, states);
  const StepState& s0 = states[0];
  output_vjp(s0, ybar.row(0).transpose(), qb, grad);
  set_state(sys, d_, s0.t, s0.q, s0.v);
  tree_kinematics(sys, d_);
  factor_mass(sys, d_);
  VecX mu0(n);
  solve_armature(sys, d_, VecX(ab + zb), mu0);
  at(s0);
  const ResidualVjp r0 = rnea_vector_jacobian_product(sys, d_, mu0);
  qb -= r0.q;
  vb -= r0.qd;
  params_->add(s0.t, s0.q, s0.v, s0.qdd, mu0, r0, -1.0, grad);
  q0bar_ = qb, qd0bar_ = vb;
  for (int j = 0; j < P; ++j) grad(j) += params_->initial(j).head(n).dot(qb) + params_->initial(j).tail(n).dot(vb);
  stats_.backward_time = std::chrono::duration<double>(Clock::now() - start).count();
  return grad;
}

}  // namespace rigidfem
