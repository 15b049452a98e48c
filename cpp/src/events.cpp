// Events: their functions g(t, y), the sides they are on, and their roots on the dense output (events.hpp).
#include "rigidfem/events.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "rigidfem/contact_forces.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/kinematics.hpp"
#include "rigidfem/outputs.hpp"

namespace rigidfem {

namespace {

int sign(double x) { return x > 0.0 ? 1 : (x < 0.0 ? -1 : 0); }

// std::invalid_argument naming `events` and the event.
[[noreturn]] void bad_event(const EventSpec& e, const std::string& expected, const std::string& got) {
  bad("events", expected + " (event '" + e.name + "')", got);
}

}  // namespace

EventLocator::EventLocator(const System& sys, std::vector<EventSpec> events, int sensitivities)
    : sys_(sys), events_(std::move(events)), P_(sensitivities), d_(sys), side_(events_.size(), 0),
      g_(events_.size(), 0.0) {
  using K = EventSpec::Kind;
  for (EventSpec& e : events_) {
    const int count = e.kind == K::Point     ? sys.nbodies
                      : e.kind == K::Contact ? static_cast<int>(sys.contacts.size())
                      : e.kind == K::Function ? 1
                                              : sys.nq;
    if (e.kind != K::Function && !(e.index >= 0 && e.index < count))
      bad_event(e, "an index in [0, " + std::to_string(count) + ")", std::to_string(e.index));
    if (e.kind == K::Function && !e.function) bad_event(e, "a function g(t, q, qd)", "none");
    if (!std::isfinite(e.value)) bad_event(e, "a finite value", num(e.value));
    if (e.direction < -1 || e.direction > 1) bad_event(e, "a direction -1, 0 or 1", std::to_string(e.direction));
    if (e.kind == K::Point) {
      const double norm = e.axis.norm();
      if (!(norm > 0.0 && std::isfinite(norm))) bad_event(e, "a finite non-zero axis", num(norm));
      e.axis /= norm;
    }
  }
}

double EventLocator::g(int k, double t, const VecX& y) {
  const EventSpec& e = events_[k];
  const int n = sys_.nq;
  switch (e.kind) {
    case EventSpec::Kind::Coordinate: return y(e.index) - e.value;
    case EventSpec::Kind::Rate: return y(n + e.index) - e.value;
    case EventSpec::Kind::Point: return e.axis.dot(point_position(sys_, d_, Point(e.index, e.r), t, y.head(n))) - e.value;
    case EventSpec::Kind::Contact:
      set_state(sys_, d_, t, y.head(n), VecX::Zero(n));
      frames(sys_, d_);
      return contact_gap(sys_, d_, e.index) - e.value;
    case EventSpec::Kind::Function: {
      const double value = e.function(t, y.head(n), y.segment(n, n));
      if (!std::isfinite(value))
        throw SimulationError(t, "the event function '" + e.name + "' returned " + num(value) + " (expected a finite "
                                 "number)");
      return value - e.value;
    }
  }
  throw std::logic_error("EventLocator::g: an event of no kind");
}

void EventLocator::start(double t0, const VecX& y0) {
  for (int k = 0; k < static_cast<int>(events_.size()); ++k) {
    g_[k] = g(k, t0, y0);
    side_[k] = sign(g_[k]);
  }
}

double EventLocator::locate(int k, double a, double ga, double b, double gb, const std::function<VecX(double)>& dense) {
  // Illinois: the secant of the bracket's ends, the end kept twice in a row has its value halved. The root is taken
  // as b, the bracket's end on the new side: the first time (to the bracket) at which g has its new sign.
  const double tol = std::max(1e-12 * (b - a), 4.0 * std::numeric_limits<double>::epsilon() * std::max(std::abs(a), std::abs(b)));
  int kept = 0;
  for (int it = 0; it < 200 && b - a > tol; ++it) {
    double c = (a * gb - b * ga) / (gb - ga);
    if (!(c > a && c < b)) c = 0.5 * (a + b);
    const double gc = g(k, c, dense(c));
    if (gc == 0.0) return c;
    if (sign(gc) == sign(gb)) {
      b = c, gb = gc;
      if (kept == -1) ga *= 0.5;
      kept = -1;
    } else {
      a = c, ga = gc;
      if (kept == 1) gb *= 0.5;
      kept = 1;
    }
  }
  return b;
}

VecX EventLocator::time_sensitivities(int k, double t, const VecX& y, double h,
                                      const std::function<VecX(double)>& dense) {
  VecX dt_dp = VecX::Zero(P_);
  const int m = 2 * sys_.nq, first = m + sys_.nz;
  if (P_ == 0 || m == 0) return dt_dp;  // nothing moves (nq = 0): the roots are the functions' of t alone
  // ġ by central differences along the dense output, δ = 1e-5 h
  const double delta = 1e-5 * h;
  const double gdot = (g(k, t + delta, dense(t + delta)) - g(k, t - delta, dense(t - delta))) / (2.0 * delta);
  VecX yp = y, ym = y;
  for (int j = 0; j < P_; ++j) {
    const auto S = y.segment(first + m * j, m);
    const double size = S.cwiseAbs().maxCoeff();
    if (size == 0.0) {
      dt_dp(j) = 0.0;
      continue;
    }
    // ∂g/∂y · S_j by central differences along S_j, steps of 1e-6 of the state's size
    const double eps = 1e-6 * (1.0 + y.head(m).cwiseAbs().maxCoeff()) / size;
    yp.head(m) = y.head(m) + eps * S, ym.head(m) = y.head(m) - eps * S;
    dt_dp(j) = -(g(k, t, yp) - g(k, t, ym)) / (2.0 * eps) / gdot;
  }
  return dt_dp;
}

std::vector<EventRecord> EventLocator::roots(double t, double t1, const VecX& y1,
                                             const std::function<VecX(double)>& dense,
                                             const std::vector<EventRecord>* arrived) {
  std::vector<EventRecord> found;
  next_side_ = side_, next_g_.assign(events_.size(), 0.0);
  for (int k = 0; k < static_cast<int>(events_.size()); ++k) {
    const double g1 = next_g_[k] = g(k, t1, y1);
    const int s1 = sign(g1);
    const auto cut = arrived ? std::find_if(arrived->begin(), arrived->end(),
                                            [k](const EventRecord& r) { return r.event == k; })
                             : std::vector<EventRecord>::const_iterator();
    if (arrived && cut != arrived->end()) {  // the step was cut before its root: it fires at t1, with the step's end
      next_side_[k] = cut->direction;
      found.push_back({k, t1, cut->direction, y1, time_sensitivities(k, t1, y1, t1 - t, dense), cut->located});
      continue;
    }
    if (s1 == 0 || s1 == side_[k]) continue;
    next_side_[k] = s1;
    if (side_[k] == 0 || (events_[k].direction != 0 && events_[k].direction != s1)) continue;  // not a root it asks
    if (sign(g_[k]) == s1) continue;  // on side s1 at both ends: no crossing within the step (see roots())
    // g went to side s1 within the step, from g_k(t) on the old side
    const double root = locate(k, t, g_[k], t1, g1, dense);
    const VecX y = root == t1 ? y1 : dense(root);
    found.push_back({k, root, s1, y, time_sensitivities(k, root, y, t1 - t, dense), root});
  }
  std::stable_sort(found.begin(), found.end(), [](const EventRecord& a, const EventRecord& b) { return a.t < b.t; });
  return found;
}

void EventLocator::commit() { side_ = next_side_, g_ = next_g_; }

}  // namespace rigidfem
