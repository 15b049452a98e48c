/// Events: zeros of scalar functions g(t, q, q̇) that a run locates (rf.simulate(..., events=...), as SciPy's
/// solve_ivp does).
///
/// After every accepted step t → t1 each event's g is evaluated at t1; where its sign differs from the side it was
/// on (and the crossing goes the event's direction), its root t* in [t, t1] is located on the method's dense output
/// y(t) by the Illinois method, to a bracket of 1e-12 of the step (or the rounding of t). A terminal event ends the
/// run there. An event that `restarts` (a contact's onset and separation: the contact force begins or ends, the
/// right-hand side is not smooth there) has the step taken again from its start by adaptive methods, ending a hair
/// (1e-9 of the step) before t* so that all its stages see the old side; the run then goes on from just past t*
/// (integrate.cpp: past_root), so that the next step's first stage sees the new side. Each step covers a smooth
/// stretch: its error estimate holds across the impact as anywhere else, and the sensitivities, whose equations take
/// the Jacobian (a linear contact's jumps from 0 to k), stay exact. Such a root is recorded where that step ends, within
/// 1e-9 of the step of t*. Fixed-step runs keep their grid and locate only.
///
/// With forward sensitivities S_j = ∂y/∂p_j the event time's own, from g(t*(p), y(t*(p), p)) = 0:
///   dt*/dp_j = −(∂g/∂y · S_j)/ġ,   ġ = ∂g/∂t + ∂g/∂y · ẏ,
/// both by central differences of g (along S_j at t*, and along the dense output across t*).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "rigidfem/system.hpp"

namespace rigidfem {

struct EventSpec {
  enum class Kind {
    Coordinate,  ///< q_index − value (m or rad)
    Rate,        ///< q̇_index − value (m/s or rad/s)
    Point,       ///< axis · x_P − value: the global position of point r of body `index` along `axis` (m)
    Contact,     ///< the smallest gap between the shapes of contact `index` (m): negative once they overlap
    Function,    ///< function(t, q, q̇) − value (a Python function: the slow path)
  };
  Kind kind = Kind::Coordinate;
  std::string name;
  int index = -1;
  Vec3 r = Vec3::Zero(), axis = Vec3::UnitZ();
  double value = 0.0;
  int direction = 0;      ///< +1: only where g rises through zero, −1: only where it falls, 0: both
  bool terminal = false;  ///< the run ends at its first root
  bool restarts = false;  ///< adaptive runs end a step at its roots (the right-hand side changes there)
  std::function<double(double, const VecX&, const VecX&)> function;
};

/// One located root: which event, when, the direction g crossed in (+1 rising, −1 falling), the state there
/// [q, q̇, s, S] (dense output, or the step's end where the step was taken again to end there) and dt*/dp_j (P).
struct EventRecord {
  int event = -1;
  double t = 0.0;
  int direction = 0;
  VecX y, dt_dp;
  double located = 0.0;  ///< the root's time on the dense output (t itself, unless a step was cut before it)
};

/// The state of a run's events: the side each g is on, and their roots.
class EventLocator {
 public:
  /// Judges the events (std::invalid_argument naming `events`); nq, nz, P: the state's layout.
  EventLocator(const System& sys, std::vector<EventSpec> events, int sensitivities);
  bool empty() const { return events_.empty(); }
  const EventSpec& spec(int k) const { return events_[k]; }
  /// The sides at the run's start (an event exactly at zero there takes the side it goes to, later).
  void start(double t0, const VecX& y0);
  /// The roots within the accepted step (t, t1] (y1 at t1, `dense` its dense output), earliest first. `arrived`: the
  /// roots the step was cut before (they fire at t1 with the step's end state), or null. The sides the step crossed
  /// to are taken by commit() (not where the step is taken again). An event whose function is on the same side at
  /// both ends of the step, other than the side it is taken to be on (an arrival the state had not yet completed),
  /// takes that side without a record.
  std::vector<EventRecord> roots(double t, double t1, const VecX& y1, const std::function<VecX(double)>& dense,
                                 const std::vector<EventRecord>* arrived);
  /// The step of the last roots() call stands: its end values and sides become the current ones.
  void commit();
  /// g_k(t, y) (y = [q, q̇, ...]).
  double g(int k, double t, const VecX& y);

 private:
  /// t* in [a, b] with g(a) = ga, g(b) = gb of opposite signs, by the Illinois method on the dense output.
  double locate(int k, double a, double ga, double b, double gb, const std::function<VecX(double)>& dense);
  /// dt*/dp_j of a root (see the file comment).
  VecX time_sensitivities(int k, double t, const VecX& y, double h, const std::function<VecX(double)>& dense);

  const System& sys_;
  std::vector<EventSpec> events_;
  int P_;
  Data d_;
  std::vector<int> side_, next_side_;  ///< the sign each g is taken to have (0: not yet known); after the step
  std::vector<double> g_, next_g_;     ///< each g at the current time; at the step's end
};

}  // namespace rigidfem
