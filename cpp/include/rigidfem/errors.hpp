/// Errors: bad input is std::invalid_argument (Python ValueError) with the message
/// "argument: expected X, got Y"; numerical failure is SimulationError, naming the time and the cause.
#pragma once

#include <Eigen/Core>
#include <chrono>
#include <exception>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rigidfem {

/// Numerical failure (singular mass matrix, NaN state, step-size underflow, Newton
/// divergence ...), naming the time and the cause. Python: rigidfem.SimulationError.
class SimulationError : public std::runtime_error {
 public:
  SimulationError(double t, const std::string& cause)
      : std::runtime_error(format(t, cause)), time(t), cause(cause) {}
  double time;
  std::string cause;

 private:
  static std::string format(double t, const std::string& cause) {
    std::ostringstream o;
    o.precision(10);
    o << "at t = " << t << " s: " << cause;
    return o.str();
  }
};

/// x with `digits` significant digits, for messages.
inline std::string num(double x, int digits = 6) {
  std::ostringstream o;
  o.precision(digits);
  o << x;
  return o.str();
}

/// Throws std::invalid_argument("argument: expected X, got Y").
[[noreturn]] inline void bad(const std::string& argument, const std::string& expected, const std::string& got) {
  throw std::invalid_argument(argument + ": expected " + expected + ", got " + got);
}

/// The size check of every entry point: "q: expected 12 (nq) values, got 10", then
/// "q: expected 12 (nq) finite values, got NaN or inf". The message is built only on failure: the check runs at
/// every stage residual of an integration (set_state).
inline void check_vector(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Index n, const char* name,
                         const char* size_name) {
  const auto expected = [&] { return std::to_string(n) + " (" + size_name + ")"; };
  if (v.size() != n) bad(name, expected() + " values", std::to_string(v.size()));
  if (!v.allFinite()) bad(name, expected() + " finite values", "NaN or inf");
}

// Ctrl-C in long computations. Whoever can be interrupted installs a check for the running thread
// with an InterruptScope (the bindings: Python's signals; an integration: its monitor); the long loops
// call interruption_point() between their pieces (a tangent's columns, the power iterations of ω_max,
// Newton's and GMRES's iterations, the loops' Gauss–Newton), which runs the check at most every 0.05 s.
// The check stops the computation by throwing (Interrupted, or the caller's own exception).

/// Thrown by a check to stop: integrate() returns the partial trajectory, marked interrupted.
class Interrupted : public std::exception {
 public:
  const char* what() const noexcept override { return "interrupted"; }
};

namespace detail {
struct InterruptState {
  const std::function<void()>* check = nullptr;
  std::chrono::steady_clock::time_point last;
};
inline thread_local InterruptState interrupt_state;
}  // namespace detail

/// Installs `check` for this thread while it lives (the previous one again after).
class InterruptScope {
 public:
  explicit InterruptScope(std::function<void()> check)
      : check_(std::move(check)), previous_(detail::interrupt_state.check) {
    detail::interrupt_state.check = &check_;
    detail::interrupt_state.last = std::chrono::steady_clock::now();
  }
  ~InterruptScope() { detail::interrupt_state.check = previous_; }
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

 private:
  std::function<void()> check_;
  const std::function<void()>* previous_;
};

/// Runs the thread's check if 0.05 s have passed since the last one.
inline void interruption_point() {
  detail::InterruptState& s = detail::interrupt_state;
  if (!s.check) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - s.last < std::chrono::milliseconds(50)) return;
  s.last = now;
  (*s.check)();
}

}  // namespace rigidfem
