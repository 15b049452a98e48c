/// The collocation tableaus (radau.hpp). Radau IIA's: c and a from √6, and the eigen-decomposition a = P diag(d) P⁻¹
/// as constants.
/// The decomposition's numbers are the bits that Eigen's EigenSolver<Matrix3d> and P.inverse() computed for this a
/// in this library, written as hexadecimal literals (exact). The solver cost 7 s of compile time; every other way of
/// writing the same decomposition (a closed form, eigenvectors in another complex phase, decimal digits from a
/// standalone program's solver) changed the last bits of radau5's runs. tests/test_higher_order.py reads these
/// literals and checks P diag(d) P⁻¹ = a and P P⁻¹ = I to round-off.
#include "rigidfem/radau.hpp"

#include <cmath>
#include <complex>

namespace rigidfem {

RadauTableau::RadauTableau() {
  using C = std::complex<double>;
  const double r6 = std::sqrt(6.0);
  c << (4 - r6) / 10, (4 + r6) / 10, 1;
  a << (88 - 7 * r6) / 360, (296 - 169 * r6) / 1800, (-2 + 3 * r6) / 225,  //
      (296 + 169 * r6) / 1800, (88 + 7 * r6) / 360, (-2 - 3 * r6) / 225,   //
      (16 - r6) / 36, (16 + r6) / 36, 1.0 / 9;
  b = a.row(2).transpose();
  stiffly_accurate = true;
  dd << -(13 + 7 * r6) / 3, (-13 + 7 * r6) / 3, -1.0 / 3;
  // d: the real eigenvalue, then the complex pair with Im d(1) > 0; P's columns their eigenvectors (row by row)
  d << C(0x1.197c751498bb2p-2, 0x0p+0),
      C(0x1.4ce9f151cdab6p-3, 0x1.7ac6b61df7bccp-3),
      C(0x1.4ce9f151cdab6p-3, -0x1.7ac6b61df7bccp-3);
  P << C(0x1.75b01984e65f7p-4, 0x0p+0), C(0x1.41477959c51c3p-6, -0x1.09f23473c553cp-3),
      C(0x1.41477959c51c3p-6, 0x1.09f23473c553cp-3),
      C(0x1.ef09cfbeab873p-3, 0x0p+0), C(-0x1.58a6f3ab9ef26p-2, 0x1.a5fc647e64b74p-3),
      C(-0x1.58a6f3ab9ef26p-2, -0x1.a5fc647e64b74p-3),
      C(0x1.ee9dde0d6255bp-1, 0x0p+0), C(0x1.bbb4a11382bdbp-5, 0x1.d0c9bc7ecc4d8p-1),
      C(0x1.bbb4a11382bdbp-5, -0x1.d0c9bc7ecc4d8p-1);
  Pinv << C(0x1.14d64d09039e1p+2, 0x0p+0), C(0x1.5b570c75819bp-2, 0x0p+0),
      C(0x1.1562f2bdebf4p-1, 0x0p+0),
      C(0x1.1cfe2989c69b4p-3, 0x1.27aa99a27bcdep+1), C(-0x1.6c1b6ff2f4c66p+0, 0x1.87abc1224b8e4p-4),
      C(0x1.5ef5dc29e1be4p-2, -0x1.efc22e02839a4p-3),
      C(0x1.1cfe2989c69b4p-3, -0x1.27aa99a27bcdep+1), C(-0x1.6c1b6ff2f4c66p+0, -0x1.87abc1224b8e4p-4),
      C(0x1.5ef5dc29e1be4p-2, 0x1.efc22e02839a4p-3);
}

// Gauss–Legendre's decomposition from a 60-digit eigen-decomposition (mpmath), each number rounded to the nearest
// double: the real eigenvalue first, then the pair with Im d(1) > 0; P's columns unit eigenvectors whose largest
// component is real and positive.
GaussTableau::GaussTableau() {
  using C = std::complex<double>;
  const double r15 = std::sqrt(15.0);
  c << 0.5 - r15 / 10, 0.5, 0.5 + r15 / 10;
  a << 5.0 / 36, 2.0 / 9 - r15 / 15, 5.0 / 36 - r15 / 30,  //
      5.0 / 36 + r15 / 24, 2.0 / 9, 5.0 / 36 - r15 / 24,    //
      5.0 / 36 + r15 / 30, 2.0 / 9 + r15 / 15, 5.0 / 36;
  b << 5.0 / 18, 4.0 / 9, 5.0 / 18;
  dd.setZero();  // no embedded estimate
  stiffly_accurate = false;
  d << C(0x1.b8f6c4ad20601p-3, 0.0), C(0x1.23849da96fd00p-3, 0x1.161e457db9db4p-3),
      C(0x1.23849da96fd00p-3, -0x1.161e457db9db4p-3);
  P << C(0x1.24b804de9c7e7p-4, 0.0), C(-0x1.3f46c6e744ee7p-4, -0x1.d2cd033453626p-5),
      C(-0x1.3f46c6e744ee7p-4, 0x1.d2cd033453626p-5),
      C(0x1.e21a0b03659d2p-4, 0.0), C(0x1.9c049dbf43ba1p-5, 0x1.32e474166ce03p-2),
      C(0x1.9c049dbf43ba1p-5, -0x1.32e474166ce03p-2),
      C(0x1.fb1f734563ef9p-1, 0.0), C(0x1.e5463b49cafd8p-1, 0.0), C(0x1.e5463b49cafd8p-1, 0.0);
  Pinv << C(0x1.83281761a40b2p+2, 0.0), C(0x1.2671920f386adp+0, 0.0), C(0x1.bef1ef6a1747dp-2, 0.0),
      C(-0x1.94966a715bcd4p+1, 0x1.5099c52b7f89cp-1), C(-0x1.33b34ba530934p-1, -0x1.8b18535f54068p+0),
      C(0x1.32a9e1371b9ecp-2, 0x1.1674b1bea9ab3p-3),
      C(-0x1.94966a715bcd4p+1, -0x1.5099c52b7f89cp-1), C(-0x1.33b34ba530934p-1, 0x1.8b18535f54068p+0),
      C(0x1.32a9e1371b9ecp-2, -0x1.1674b1bea9ab3p-3);
}

}  // namespace rigidfem
