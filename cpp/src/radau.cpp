/// The collocation tableaus (radau.hpp). Radau IIA's of 3 stages: c and a from √6, and the eigen-decomposition
/// a = P diag(d) P⁻¹ as constants.
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

// Radau IIA of 5 stages from a 60-digit computation (mpmath), each number rounded to the nearest double: c the zeros
// of d⁴/dx⁴ (x⁴ (x − 1)⁵), a_ij = ∫₀^{c_i} l_j (l_j Lagrange's basis on c), b the last row of a; dd the embedded
// estimate's weights, (b̂ − b)ᵀ a⁻¹/d₁ for the order-5 quadrature b̂ on (0, c) with b̂₀ = d₁ (as radau5's); the
// real eigenvalue first, then the pairs with Im d > 0; P's columns unit eigenvectors whose largest component is real
// and positive.
Radau9Tableau::Radau9Tableau() {
  using C = std::complex<double>;
  c << 0x1.d3cc2dd8d6d32p-5, 0x1.1b7cbc26ceaaep-2, 0x1.2acc5d7a90e51p-1, 0x1.b8716522b33bep-1, 0x1.0000000000000p+0;
  a << 0x1.2b00db6e3fa2dp-4, -0x1.b6081b30682a0p-6, 0x1.3200b8a1aa037p-6, -0x1.a605c5bc79bfcp-7, 0x1.4a7ccd96a885cp-8,  //
      0x1.3aee82311a74fp-3, 0x1.2b72b35cc0671p-3, -0x1.2a8dccf20f1a7p-5, 0x1.5be1ebec3e8bdp-6, -0x1.040878141910fp-7,  //
      0x1.1ed95fc4c15b4p-3, 0x1.3224706ef9eacp-2, 0x1.5736d75c3ae6dp-3, -0x1.16465e9a31545p-5, 0x1.669f591dfd1acp-7,  //
      0x1.28be58d5a7ef5p-3, 0x1.1b22d582aaa26p-2, 0x1.4d9df880051b7p-2, 0x1.07b19ee2f3ab4p-3, -0x1.015ff99971365p-6,  //
      0x1.26534b9cb85e2p-3, 0x1.201bca8e66374p-2, 0x1.3f4f73b8d3267p-2, 0x1.c8eab2b61c94ap-3, 0x1.47ae147ae147bp-5;
  dd << -0x1.bc7eb4976180bp+4, 0x1.d21bf7a91ab27p+1, -0x1.40a6f7ab19c6fp+0, 0x1.2f1b0a045f3f9p-1,
      -0x1.999999999999ap-3;
  d << C(0x1.45c4503dd015ap-3, 0x0.0p+0), C(0x1.0a8269ef157e3p-4, 0x1.dd0e1a5a86e24p-4),
      C(0x1.0a8269ef157e3p-4, -0x1.dd0e1a5a86e24p-4), C(0x1.10c0312270c45p-3, 0x1.332d71fb6de09p-4),
      C(0x1.10c0312270c45p-3, -0x1.332d71fb6de09p-4);
  P << C(0x1.9a2d1fb890948p-7, 0x0.0p+0), C(-0x1.17db4b4074e02p-7, 0x1.45a9e3de9eac1p-5),
      C(-0x1.17db4b4074e02p-7, -0x1.45a9e3de9eac1p-5), C(-0x1.555c23db6aa42p-7, -0x1.a0efe084575a6p-7),
      C(-0x1.555c23db6aa42p-7, 0x1.a0efe084575a6p-7), C(0x1.87084a1342ef1p-10, 0x0.0p+0),
      C(0x1.56bc011e2390ap-5, -0x1.4231945a1be5ap-4), C(0x1.56bc011e2390ap-5, 0x1.4231945a1be5ap-4),
      C(-0x1.c8208fac3b4c1p-8, 0x1.6f6793486bf33p-6), C(-0x1.c8208fac3b4c1p-8, -0x1.6f6793486bf33p-6),
      C(0x1.2aef0b4499ccep-4, 0x0.0p+0), C(-0x1.89b53daec1bb1p-3, 0x1.5ec9300e7ec54p-4),
      C(-0x1.89b53daec1bb1p-3, -0x1.5ec9300e7ec54p-4), C(0x1.20721d76582e4p-6, 0x1.30153972900bap-4),
      C(0x1.20721d76582e4p-6, -0x1.30153972900bap-4), C(0x1.8536b0c138302p-2, 0x0.0p+0),
      C(0x1.42ad70ca8dcb6p-2, 0x1.8e8b9750d7823p-2), C(0x1.42ad70ca8dcb6p-2, -0x1.8e8b9750d7823p-2),
      C(0x1.7acd4faf2d941p-2, 0x1.7325ca79ebf08p-3), C(0x1.7acd4faf2d941p-2, -0x1.7325ca79ebf08p-3),
      C(0x1.d80da0c71ef28p-1, 0x0.0p+0), C(0x1.aaf1222f365a6p-1, 0x0.0p+0), C(0x1.aaf1222f365a6p-1, 0x0.0p+0),
      C(0x1.d0ac1fd8318aep-1, 0x0.0p+0), C(0x1.d0ac1fd8318aep-1, 0x0.0p+0);
  Pinv << C(0x1.e0aa42ea49a39p+4, 0x0.0p+0), C(0x1.bbaef6abc6593p+3, 0x0.0p+0), C(0x1.bd70bb1dde069p+1, 0x0.0p+0),
      C(-0x1.0831ba83d8022p+0, 0x0.0p+0), C(0x1.9bcd9bd554fe0p-1, 0x0.0p+0),
      C(0x1.9a2b3d12c4b60p+1, -0x1.1faa5829c8758p+1), C(0x1.608fedceb19ffp+1, 0x1.31d919fb282a9p+1),
      C(-0x1.d21591b3c467dp+0, 0x1.40a33b940e65ap-1), C(0x1.428e01e4956f6p-1, -0x1.6b85433d24adap-1),
      C(-0x1.4ef968913f734p-3, 0x1.144052553e8aap-2), C(0x1.9a2b3d12c4b60p+1, 0x1.1faa5829c8758p+1),
      C(0x1.608fedceb19ffp+1, -0x1.31d919fb282a9p+1), C(-0x1.d21591b3c467dp+0, -0x1.40a33b940e65ap-1),
      C(0x1.428e01e4956f6p-1, 0x1.6b85433d24adap-1), C(-0x1.4ef968913f734p-3, -0x1.144052553e8aap-2),
      C(-0x1.23420c209b1ddp+4, 0x1.2fa21140e03f2p+2), C(-0x1.325964baf6668p+3, -0x1.5603b29d8d636p+2),
      C(-0x1.846cd2d7ba82dp-4, -0x1.0e0c2f8da4f2bp+0), C(-0x1.bf924cc9c20e9p-5, -0x1.552005ab4a2d2p+0),
      C(0x1.2bb0f8ef8d931p-2, 0x1.27765508377dfp-1), C(-0x1.23420c209b1ddp+4, -0x1.2fa21140e03f2p+2),
      C(-0x1.325964baf6668p+3, 0x1.5603b29d8d636p+2), C(-0x1.846cd2d7ba82dp-4, 0x1.0e0c2f8da4f2bp+0),
      C(-0x1.bf924cc9c20e9p-5, 0x1.552005ab4a2d2p+0), C(0x1.2bb0f8ef8d931p-2, -0x1.27765508377dfp-1);
  b = a.row(4).transpose();
  stiffly_accurate = true;
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
