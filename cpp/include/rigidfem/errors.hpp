/// Errors: bad input is std::invalid_argument (Python ValueError) with the message
/// "argument: expected X, got Y"; numerical failure is SimulationError, naming the time and the cause.
#pragma once

#include <Eigen/Core>
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
/// "q: expected 12 (nq) finite values, got NaN or inf".
inline void check_vector(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Index n, const std::string& name,
                         const std::string& size_name) {
  const std::string expected = std::to_string(n) + " (" + size_name + ")";
  if (v.size() != n) bad(name, expected + " values", std::to_string(v.size()));
  if (!v.allFinite()) bad(name, expected + " finite values", "NaN or inf");
}

}  // namespace rigidfem
