/// Radau IIA's tableau (radau.hpp). The eigen-decomposition a = P diag(d) P⁻¹ is computed by Eigen's
/// EigenSolver, in this file alone: the solver costs about 7 s of compile time in each translation unit that
/// instantiates it. (Written as constants, or in closed form with eigenvectors of another complex phase, the
/// same decomposition changed radau5's runs: a sensitivity that is exactly zero failed, tests/fuzz_corpus.)
#include "rigidfem/radau.hpp"

#include <cmath>

namespace rigidfem {

RadauTableau::RadauTableau() {
  const double r6 = std::sqrt(6.0);
  c << (4 - r6) / 10, (4 + r6) / 10, 1;
  a << (88 - 7 * r6) / 360, (296 - 169 * r6) / 1800, (-2 + 3 * r6) / 225,  //
      (296 + 169 * r6) / 1800, (88 + 7 * r6) / 360, (-2 - 3 * r6) / 225,   //
      (16 - r6) / 36, (16 + r6) / 36, 1.0 / 9;
  dd << -(13 + 7 * r6) / 3, (-13 + 7 * r6) / 3, -1.0 / 3;
  Eigen::EigenSolver<Eigen::Matrix3d> es(a);
  Eigen::Vector3cd ev = es.eigenvalues();
  Eigen::Matrix3cd V = es.eigenvectors();
  int real = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(ev(k).imag()) < std::abs(ev(real).imag())) real = k;
  const int up = ev((real + 1) % 3).imag() > 0 ? (real + 1) % 3 : (real + 2) % 3, down = 3 - real - up;
  const int order[3] = {real, up, down};
  for (int k = 0; k < 3; ++k) d(k) = ev(order[k]), P.col(k) = V.col(order[k]);
  d(0) = d(0).real();
  Pinv = P.inverse();
}

}  // namespace rigidfem
