/// Adjoint gradients of a scalar objective of a run, J = Σ_n ȳ-weighted outputs (a quadrature of ∫ L(t, y) dt
/// plus Φ(y(t_end)), formed in Python from the outputs y_n the forward run records), with respect to many
/// parameters at the cost of a few runs: the discrete adjoints of the Newmark family (generalised-α in the form of
/// Arnold & Brüls, newmark.cpp) and of radau5 (implicit_rk.cpp) at fixed steps.
///
/// A step n → n+1 solves r(q_{n+1}, q̇_{n+1}, q̈_{n+1}, t_{n+1}; p) = 0 for z = q̈_{n+1}, with
///   a_{n+1} = [(1 − α_f) z + α_f q̈_n − α_m a_n]/(1 − α_m),
///   q_{n+1} = q_n + h q̇_n + h² [(½ − β) a_n + β a_{n+1}],   q̇_{n+1} = q̇_n + h [(1 − γ) a_n + γ a_{n+1}].
/// With the adjoints (q̄, q̇̄, ā, q̈̄) of the state = ∂J/∂(q, q̇, a, q̈) by everything after it, the step transposed:
///   ã = ā_{n+1} + βh² q̄_{n+1} + γh q̇̄_{n+1},      g = q̈̄_{n+1} + (1 − α_f)/(1 − α_m) ã,
///   Sᵀ μ = g,   S = M + γ'h C + β'h² K (Newton's matrix at the step's end; β' = β(1 − α_f)/(1 − α_m), γ' alike),
///   q̂ = q̄_{n+1} − Kᵀμ,   q̇̂ = q̇̄_{n+1} − Cᵀμ,   A = ā_{n+1} + βh² q̂ + γh q̇̂,
///   q̄_n = q̂ + ∂J/∂q_n,  q̇̄_n = h q̂ + q̇̂ + ∂J/∂q̇_n,  ā_n = h²(½ − β) q̂ + h(1 − γ) q̇̂ − α_m/(1 − α_m) A,
///   q̈̄_n = α_f/(1 − α_m) A,   dJ/dp −= μᵀ ∂r/∂p (at t_{n+1}).
/// At t0, a_0 = q̈_0 solves r(q_0, q̇_0, q̈_0) = 0: M μ_0 = ā_0 + q̈̄_0, q̄_0 −= Kᵀμ_0, q̇̄_0 −= Cᵀμ_0,
/// dJ/dp −= μ_0ᵀ ∂r/∂p. Kᵀμ, Cᵀμ, Mμ come from the RNEA's reverse mode (derivatives.hpp: O(n)); Sᵀμ = g is
/// solved by GMRES on those products, preconditioned by the transposed factorisation of a Newton matrix kept
/// from an earlier step (dense) or by M + diag(γ'h b + β'h² k) (Krylov), to 1e-11; μᵀ∂r/∂p for every parameter
/// in one pass (ParameterVjp). Recursive systems without Maxwell arms.
///
/// Closed loops (the Newmark family, index 3: r − Gᵀλ = 0 and g(q_{n+1}) = 0 for (z, λ)): the transposed saddle
/// system A₁₁ᵀμ + β'h² Gᵀν = g, G μ = 0 with A₁₁ = S − β'h² ∂(Gᵀλ)/∂q (the Hessian of λᵀg: symmetric, by central
/// differences along the direction), by its Schur complement (nl + 1 transposed solves; least-norm ν for
/// redundant rows), then q̂ = q̄ − (Kᵀμ − ∂(Gᵀλ)/∂q μ) − Gᵀν. At t0 the constrained forward dynamics transposed:
/// Mμ₀ + Gᵀν₀ = ā₀ + q̈̄₀, Gμ₀ = 0, and ∂(G q̈ − γ)/∂(q, q̇)ᵀν₀ by central differences (O(n²), once).
///
/// radau5 with loops: the projection of each step's end transposed (RadauSteps::transpose_projection), then the
/// stages' saddle system 𝒮ᵀμ + Zν = g, G_i μ_i = 0 (Z = (∂c/∂A)ᵀ of c_i = G_i A_i − γ_i, whose derivatives by V_i
/// and Q_i are 2 dG/dt and d²G/dt² along the stage's motion) by its Schur complement (3 nl + 1 transposed solves).
///
/// Radau IIA (3 stages; implicit_rk.cpp): V = q̇_n 1ᵀ + h A aᵀ, Q = q_n 1ᵀ + h V aᵀ, r_i(Q_i, V_i, A_i) = 0, and
/// (q, q̇)_{n+1} = (Q_3, V_3). With Q̄ = [0, 0, q̄_{n+1}], V̄ = [0, 0, q̇̄_{n+1}]:
///   V̄' = V̄ + h Q̄ a,   𝒮ᵀ μ = h V̄' a,   (𝒮ᵀμ)_j = M_j μ_j + h Σ_i a_ij C_iᵀ μ_i + h² Σ_i (a²)_ij K_iᵀ μ_i
/// (each stage's own tangent), Q̂ = Q̄ − [K_iᵀμ_i], V̂ = V̄ − [C_iᵀμ_i], q̄_n = Σ_i Q̂_i, q̇̄_n = Σ_i V̂_i + h Σ_i c_i Q̂_i,
/// dJ/dp −= Σ_i μ_iᵀ ∂r_i/∂p. 𝒮ᵀμ = g by GMRES on those products, preconditioned by the transposed real and
/// complex blocks of one tangent: X̃ = X P, (M + h d_k C + h² d_k² K)ᵀ ỹ_k = x̃_k, Y = Re(Ỹ P⁻¹).
///
/// Checkpointing: the forward run keeps every state while they fit into `memory` bytes, else every k-th (k = ⌈√N⌉,
/// about 2√N states in all) and the backward sweep runs each segment again from its checkpoint: memory O(√N)
/// states, one extra forward run's work.
#pragma once

#include <limits>

#include <memory>
#include <vector>

#include "rigidfem/derivatives.hpp"
#include "rigidfem/error_measure.hpp"
#include "rigidfem/integrators.hpp"
#include "rigidfem/sensitivities.hpp"

namespace rigidfem {

/// The objective's outputs: a point's global position (Point: 3 numbers, m) or a free coordinate (Coordinate: 1).
/// y (K) at the state of d (set_state and tree_kinematics done).
int output_size(const std::vector<OutputSpec>& outputs);
void objective_outputs(const System& sys, const Data& d, const std::vector<OutputSpec>& outputs, Eigen::Ref<VecX> y);
/// (∂y/∂q)ᵀ ȳ added into qbar (nq) and its part by the prescribed coordinates into pbar (np), at the state of d.
void objective_outputs_vjp(const System& sys, const Data& d, const std::vector<OutputSpec>& outputs,
                           const VecX& ybar, Eigen::Ref<VecX> qbar, VecX& pbar);

/// μᵀ ∂r/∂p_j of r = M q̈ − f for every parameter of a run in one O(n) pass: each parameter's system at p ± h
/// differs from the run's in a few components (bodies' inertias, coordinates' springs and forces, elements'
/// laws, loads, drives), each component's part of μᵀr is its virtual power under the virtual velocity μ
/// (a body's V_bᵀ(I a + v ×* I v) with V_b = Σ_{path} s_u μ_u; −μ_k Q_k of a coordinate; −F δl of an element;
/// −V_bᵀ w of a load), and only those are evaluated again. A drive's numbers enter through the prescribed
/// coordinate's (q, q̇, q̈): ∂(μᵀr)/∂ of those from the reverse mode, times the profile's own difference.
/// A parameter that sets a link of varying length's rfes' inertias (its material's density, its section) or its
/// length L(t) differences μᵀr whole (O(n) per parameter): their inertias and flow loads scale with L(t).
class ParameterVjp {
 public:
  ParameterVjp(const System& sys, const std::vector<SensitivityParameter>& parameters);
  /// grad_j += w μᵀ ∂r/∂p_j at the state of d, r the reverse mode's products there (d: after
  /// rnea_vector_jacobian_product, whose spatial kinematics and RNEA pass it reads; r's part by the prescribed
  /// coordinates' motion: a drive's numbers).
  void add(const Data& d, const VecX& mu, const ResidualVjp& r, double w, Eigen::Ref<VecX> grad);
  /// grad_j += pbarᵀ ∂q_p(t)/∂p_j: the prescribed coordinates' values moved by a drive's numbers.
  void add_prescribed(double t, const VecX& pbar, Eigen::Ref<VecX> grad);
  /// Closed loops: grad_j −= [μᵀ ∂(−Gᵀλ)/∂p_j + νᵀ ∂c/∂p_j] for the parameters that move a drive (the loops' terms
  /// see the prescribed coordinates), c = g(q, t) (`acceleration` false) or G q̈ − γ (true), by central differences
  /// of the systems at p ± h at (t, q, q̇, q̈, λ).
  void add_loops(double t, const VecX& q, const VecX& qd, const VecX& qdd, const VecX& lambda, const VecX& mu,
                 const VecX& nu, bool acceleration, Eigen::Ref<VecX> grad);
  /// Loops, radau5's projection: grad_j −= aᵀ ∂g/∂p_j + bᵀ ∂ġ/∂p_j at (t, q, q̇) for the parameters that move the
  /// loops (a drive's or an actuator's numbers), by central differences of the systems at p ± h.
  void add_projection(double t, const VecX& q, const VecX& qd, const VecX& a, const VecX& b, Eigen::Ref<VecX> grad);
  int count() const { return static_cast<int>(parameters_.size()); }
  /// [∂q₀/∂p_j, ∂q̇₀/∂p_j] (2 nq).
  const VecX& initial(int j) const { return parameters_[j].S0; }
  const std::vector<SensitivityParameter>& parameters() const { return parameters_; }

 private:
  struct Component {
    enum Kind { Body, Coordinate, Element, Load, Drive, Actuator } kind;
    int index;      // body, coordinate (in coords), element, load, loop (an actuator's: only in g, G, γ)
    int slot = -1;  // a Drive's: its place among all parameters' Drive components (drive_rate)
  };
  double power(const System& X, const Data& d, const Component& c, const VecX& mu) const;
  double residual_power(const System& X, const Data& d, const VecX& mu);  // μᵀ r of X at the state of d
  bool moves_loops(int j) const;  // a drive's or an actuator's numbers: in the loops' g, G, γ
  /// grad_j −= ∂f/∂p_j of a scalar f(X) of the loops' terms (on e_), by the difference of the systems at p ± h, for
  /// the parameters that move the loops.
  template <class F>
  void add_loop_difference(F&& f, Eigen::Ref<VecX> grad) {
    if (!e_) e_ = std::make_unique<Data>(sys_);
    for (std::size_t j = 0; j < parameters_.size(); ++j) {
      if (!moves_loops(static_cast<int>(j))) continue;
      const SensitivityParameter& p = parameters_[j];
      const double up = f(*p.plus), down = p.minus ? f(*p.minus) : f(sys_);
      grad(j) -= (up - down) / (p.minus ? 2.0 * p.h : p.h);
    }
  }
  double base_power(const Data& d, const Component& c, const VecX& mu);
  /// (q, q̇, q̈) of the drive of coordinate `coord` at t differenced between parameter j's systems (one-sided against
  /// the run's own drive where j has no system at p − h: a number the profile is affine in).
  MotionState drive_derivative(int j, int coord, double t);
  /// The run's own drive of coordinate `coord` at t, kept while t stays (the other side of every one-sided difference
  /// of that drive).
  const MotionState& own_drive(int coord, double t);
  /// drive_derivative of a Drive component at t, kept while t stays (the objective's outputs and the step's end ask
  /// at the same t).
  const MotionState& drive_rate(int j, const Component& c, double t);
  const System& sys_;
  std::vector<SensitivityParameter> parameters_;
  std::vector<std::vector<Component>> touched_;  // per parameter
  std::vector<bool> whole_;                       // per parameter: μᵀr differenced whole (links of varying length)
  std::vector<Vec6> V_;                           // (nbodies) V_b = Σ s_u μ_u along the path
  std::vector<double> base_[5];                   // per kind of component in r: its power on the run's system, or NaN
  /// A body's part of μᵀr, V_bᵀ(I_b a_b + v_b ×* I_b v_b) = V̂ᵀ I a + ŷᵀ I v with ŷ = −v ×m V, is linear in its spatial
  /// inertia I_b, constant in the body's own frame (^: about its origin, in its axes): a parameter's part is
  /// V̂ᵀ İ â + ŷᵀ İ v̂ with İ = ∂I_b/∂p_j, differenced once when the parameters are set.
  struct InertiaRate {
    int body;
    Mat6 rate;  // İ in the body's frame
  };
  std::vector<std::vector<InertiaRate>> inertia_rates_;  // per parameter
  std::vector<char> rated_;                              // per body: some parameter moves its inertia
  std::vector<Mat6> W_;                                  // per rated body: V̂ âᵀ + ŷ v̂ᵀ at the state
  double rates_t_ = std::numeric_limits<double>::quiet_NaN();  // the time of the drive rates kept
  std::vector<MotionState> rates_;                             // per Drive component (its slot)
  std::vector<char> rated_at_t_;                               // per slot: kept at rates_t_
  double own_t_ = std::numeric_limits<double>::quiet_NaN();    // the time of the own drives kept
  std::vector<MotionState> own_;                               // per coordinate (in coords): own_drive at own_t_
  std::vector<char> own_at_t_;                                 // per coordinate: kept at own_t_
  std::unique_ptr<Data> e_;                       // the loops' terms on the systems at p ± h (same sizes)
};

/// What the backward sweep needs of a step, and what a replay starts again from: the state at the step's end
/// (q, q̇, q̈; a: the Newmark family's pseudo-acceleration) and the step's stages (radau5: Q, V, A (nq, 3)).
struct StepRecord {
  double t = 0.0, h = 0.0;  // h: the step that reached t (0 at t0)
  VecX q, v, qdd, a;
  VecX lambda;              // (nl) the loops' multipliers (the Newmark family)
  MatX Q, V, A;             // radau5: the step's stages (nq, 3)
  MatX L;                   // radau5 with loops: the stages' multipliers (nl, 3)
};

struct AdjointStats {
  long steps = 0, recomputed_steps = 0, checkpoints = 0, interval = 1;
  long linear_iterations = 0, preconditioner_refreshes = 0;
  double forward_time = 0.0, backward_time = 0.0;  // s
};

/// One method's steps and their transposes (adjoint.cpp: the Newmark family, radau5). The adjoint state is
/// k nq long, q̄ and q̇̄ first (the Newmark family's also ā and q̈̄).
class AdjointSteps {
 public:
  virtual ~AdjointSteps() = default;
  virtual void start(double t0, const VecX& q0, const VecX& qd0) = 0;
  /// The step t → t + h from the current state (SimulationError if Newton fails).
  virtual void step(double t, double h) = 0;
  /// The current state after start or a step of h to t, with that step's stages.
  virtual StepRecord record(double t, double h) const = 0;
  virtual void restore(const StepRecord& r) = 0;
  virtual int adjoint_size() const = 0;
  /// The state at a step's end (q, q̇, q̈ and the frames), on the Data it returns: what the objective's outputs and
  /// transpose read.
  virtual const Data& at_end(const StepRecord& end) = 0;
  /// The adjoint state at a step's end (its record `end`, after at_end(end)) into the one at its start; grad += its
  /// parameters' part.
  virtual void transpose(const StepRecord& end, VecX& bars, VecX& grad) = 0;
  /// At t0: what the start (q̈_0 from the dynamics) adds; bars keeps (q̄_0, q̇̄_0) in front.
  virtual void transpose_start(const StepRecord& start, VecX& bars, VecX& grad) = 0;
  AdjointStats* stats = nullptr;
};

/// One forward run recording the outputs and its checkpoints, then any number of backward sweeps.
class Adjoint {
 public:
  /// o: generalized_alpha, newmark, hht, implicit_spring or radau5 at fixed steps dt, o.sensitivities the
  /// parameters (their systems at p ± h and S0); memory: bytes for the states kept.
  Adjoint(std::shared_ptr<const System> sys, const IntegratorOptions& o, std::vector<OutputSpec> outputs,
          double memory);
  ~Adjoint();
  /// Runs from (t0, q0, q̇0) to t_end: times() and outputs() (N + 1, K), the checkpoints.
  void forward(double t0, double t_end, const VecX& q0, const VecX& qd0);
  const std::vector<double>& times() const { return t_; }
  const RowMatX& outputs() const { return Y_; }
  /// dJ/dp_j (P) for ȳ_n = ∂J/∂y_n (N + 1, K); q0bar(), qd0bar() the gradient by the initial state.
  VecX backward(const Eigen::Ref<const RowMatX>& ybar);
  const VecX& q0bar() const { return q0bar_; }
  const VecX& qd0bar() const { return qd0bar_; }
  const AdjointStats& stats() const { return stats_; }

 private:
  void replay(long first, long last, std::vector<StepRecord>& states);
  void output_vjp(const Data& d, const VecX& ybar, Eigen::Ref<VecX> qbar, VecX& grad);  // at d's state

  std::shared_ptr<const System> sys_;
  IntegratorOptions o_;
  std::vector<OutputSpec> outputs_;
  double memory_;
  std::unique_ptr<ParameterVjp> params_;
  std::unique_ptr<AdjointSteps> steps_;
  Data d_;
  std::vector<double> t_;
  RowMatX Y_;
  long interval_ = 1;                      // steps between checkpoints
  std::vector<StepRecord> checkpoints_;    // at steps 0, k, 2k, ... (all: k = 1)
  MatX initial_;                           // (2 nq, P) the initial values' directions (along the loops)
  VecX q0bar_, qd0bar_;
  AdjointStats stats_;
};

}  // namespace rigidfem
