/// method="auto", the whole policy in one place: the stiff method it hands over to, the spectral radius
/// at t0, when dopri5 hands over (or the stiff method takes the run from t0), the tolerances dopri5 holds,
/// the hand-over itself and the sentence of stats.method. integrate.cpp's run() asks it after each
/// accepted step and otherwise knows nothing of it.
#pragma once

#include <memory>
#include <string>

#include "rigidfem/stepper.hpp"

namespace rigidfem {

/// auto's stiff method: o.stiff_method when one is set, else radau5 — or esdirk43 for a system with
/// Maxwell arms or when the spring matrix is asked for (radau5 takes neither).
Method auto_stiff_method(const System& sys, const IntegratorOptions& o);

/// auto's explicit method: dop853 where the tightest rtol asked is at most 1e-6, the default (where its order 8
/// takes fewer evaluations than dopri5's 5), else dopri5. Measured at rtol 1e-6 (CPU time, best of 3, dop853 against
/// dopri5): a double pendulum over 10 s 2.49 against 2.75 ms, the Bricard linkage over 10 s 5.82 against 7.18 ms, a
/// chain of six stiff springs over 0.05 s 2.61 against 4.15 ms; at 3e-6 the double pendulum went to dopri5 (1.96
/// against 2.29 ms).
Method auto_explicit_method(const IntegratorOptions& o);

/// What auto ran, for stats.method: its explicit method ("dopri5"), the hand-over ("dopri5, then radau5 from
/// t = 0.3 s"), or the stiff method from the start (on ω_max, or after a probe of the explicit method found the
/// problem stiff), with the number of lost trials.
std::string auto_description(Method stiff, Method explicit_method, const IntegratorStats& stats, double t0);

/// The spectral radius ρ (rad/s) of the Jacobian of y' = (q̇, q̈) at (t, q, q̇, s) by power iteration on
/// J² (auto_method.cpp), its forward-dynamics evaluations counted in `evaluations`.
double spectral_radius(const System& sys, double t, const VecX& q, const VecX& v, const VecX& s, long& evaluations);

/// method="auto": which of dopri5 and its stiff method runs (the rules: auto_method.cpp).
class AutoChoice {
 public:
  /// What a change of method leaves to the run: the new stepper, started; the step h to go on with;
  /// from_start: it starts again from (t0, y0) (dopri5 was a probe), the outputs recorded so far void.
  struct HandOver {
    std::unique_ptr<Stepper> stepper;
    double h;
    bool from_start;
  };
  static constexpr int window = 20, probe = 100;
  static constexpr double margin = 1.25;  // a near tie goes to dopri5, whose error control is the surer
  static constexpr double loosest_explicit = 1e-3;  // dopri5's rtol at most (looser ones are tightened)
  /// dopri5 is stable for h ρ up to about 3.3 (its region meets the real axis at −3.3; Hairer's test: 3.25).
  static constexpr double dopri5_stability = 3.3;
  /// The stiff method starts at t0 without a dopri5 probe when dopri5 would need this many steps for
  /// stability alone (see auto_method.cpp).
  static constexpr double direct_steps = 200;

  /// Estimates ω_max at (t0, y0) = [q0, q̇0, s0] into stats (its evaluations counted there); `asked`: the
  /// run's tolerances, which the stiff method holds (dopri5 holds the state's, tightened).
  AutoChoice(const System& sys, const IntegratorOptions& o, const Tolerances& asked, double t0, const VecX& y0,
             IntegratorStats& stats);
  /// The options of the method that starts the run: the stiff method when it takes the run from t0 on ω_max
  /// alone, else dopri5.
  IntegratorOptions first(IntegratorStats& stats);
  /// The tolerances of the method running now.
  const Tolerances& tolerances() const { return stiff_running_ ? asked_ : explicit_tol_; }
  /// After an accepted step at t: true when the run should change method (then call hand_over).
  bool after_step(double t, double h_rho, const IntegratorStats& stats);
  /// The change of method after the accepted step to t (state y, step h): the other method, started from
  /// (t, y), or from (t0, y0) when dopri5 was a probe.
  HandOver hand_over(double t, double h, const VecX& y, IntegratorStats& stats);

 private:
  IntegratorOptions switched(double t, double h, IntegratorStats& stats);
  bool restart(const IntegratorStats& stats) const;
  void switched_at(double t0, IntegratorStats& stats);
  double work(const IntegratorStats& s) const;
  void mark(double t, const IntegratorStats& stats);

  const System& sys_;
  IntegratorOptions o_;
  Tolerances asked_, explicit_tol_;
  Method explicit_;     // dopri5 or dop853 (auto_explicit_method)
  double near_ = 2.0;   // h ρ counted near the explicit method's stability boundary (0.6 of it)
  double t0_, span_;
  VecX y0_;
  bool direct_ = false;  // the stiff method from t0 on ρ alone
  bool krylov_ = false;  // the stiff method's tangent is matrix-free
  bool stiff_running_ = false, spring_ = false, restarted_ = false, first_window_ = true;
  double probe_end_ = 0.0, probe_rate_ = 0.0;  // the restarted trial's comparison (switched_at)
  // A window whose steps reach the stability boundary starts a trial: the first at once (dopri5 was a probe), a
  // later one after `backoff_` windows.
  int steps_ = 0, near_boundary_ = 0, windows_since_trial_ = -1, backoff_ = 1;
  double t_mark_ = 0.0, work_mark_ = 0.0, h_explicit_ = 0.0;
};

}  // namespace rigidfem
