/// One exception for numerical failure; bad input is std::invalid_argument (Python ValueError).
#pragma once

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

}  // namespace rigidfem
