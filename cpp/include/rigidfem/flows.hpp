/// Flexible links of time-varying free length L(t) (book ch. 7.2, the telescopic rapier): a beam
/// whose material slides out of (or back into) a guide at the speed v = L̇.
///
/// A fixed number m of sdes is spread over the current free length: the rfe frames sit at the
/// normalised positions ξ_k (ξ_0 = 0 at the guide, ξ_k = (k − ½)/m), rfe k spans the fraction σ_k
/// of L (½/m at the ends, 1/m between), and the distance between consecutive frames grows with
/// L through a prescribed translation x_k(t) = κ_k (L(t) − L₀) of each sde joint (κ_k the
/// frames' spacing over L). A material point moves through the chain as ξ̇ = v (1 − ξ)/L, so
/// relative to the frame of its rfe k it slides along the rfe's axis e_k at
///   u_k = v (1 − ξ_k) e_k,   with the relative acceleration  v̇ (1 − ξ_k) e_k,
/// and turns at each sde by the kink between e_{k−1} and e_k. d'Alembert's principle over the
/// material particles (their accelerations: the frame's point, Coriolis 2 ω_k × u_k, relative,
/// and the kinks) gives the tree's equations with
///   - the rfes' mass properties at L(t): H_k(t) = H_k(L₀) with the entries scaled by
///     λ^(1 + [i = x] + [j = x]), λ = L/L₀ (a uniform rfe of length σ_k L);
///   - the load −m_k (2 ω_k × u_k + v̇ (1 − ξ_k) e_k) at rfe k's centre of mass;
///   - the load −ρA v² (1 − ξ_k)² (e_k − e_{k−1}) at rfe k's origin (the sde; e_{−1} the guide's axis);
///   - the sdes' springs and dampers scaled by L₀/L (c = EI/Δ with Δ = L/m).
/// No events and a fixed number of coordinates: O(n) kept.
#pragma once

#include <vector>

#include "rigidfem/profiles.hpp"

namespace rigidfem {

/// A beam of varying free length as the model describes it (its rfes are bodies first ..
/// first + elements, built at the length L₀ = length(0) with an "x" coordinate first in every sde
/// joint, which Model::add_flow prescribes).
struct Flow {
  ProfilePtr length;  ///< L(t), m
  double length0 = 0.0;  ///< L₀ = L(0), m: the length of the bodies' and sdes' values
  int first = 0;         ///< body index of rfe 0
  int elements = 0;      ///< m
  /// ξ_k of rfe k's frame and σ_k, its length over L.
  double xi(int k) const { return k == 0 ? 0.0 : (k - 0.5) / elements; }
  double share(int k) const { return (k == 0 || k == elements) ? 0.5 / elements : 1.0 / elements; }
  /// κ_k: the distance from rfe k − 1's frame to rfe k's over L (k ≥ 1).
  double spacing(int k) const { return k == 1 ? 0.5 / elements : 1.0 / elements; }
};

/// The growth x_k(t) = κ (L(t) − L₀) of the distance between two rfe frames (the prescribed "x" coordinate
/// first in rfe k's sde joint), with its rates κ L̇ and κ L̈.
ProfilePtr growth_profile(ProfilePtr length, double kappa, double length0);

}  // namespace rigidfem
