/// The Maxwell arms of the viscoelastic sde laws (model.hpp: MaxwellArm): their forces s (nz) are
/// internal variables integrated with the state by every integrator,
///   ṡ_j = k_j q̇_{i(j)} − s_j / τ_j,        Q_i −= Σ_{j on i} s_j,
/// the arm j a spring k_j in series with a dashpot k_j τ_j on coordinate i(j). The explicit methods
/// carry s in y = [q, q̇, s]; the Newmark family advances it exactly for a q linear over the step
/// (arm_step); esdirk43 by its stages (arm_stage).
#pragma once

#include <cmath>

#include "rigidfem/system.hpp"

namespace rigidfem {

/// d.arm_force (nc) = Σ s_j of each coordinate's arms: the input of passive_force.
inline void set_arm_forces(const System& sys, Data& d, const Eigen::Ref<const VecX>& s) {
  if (sys.nz == 0) return;
  d.arm_force.setZero();
  for (int j = 0; j < sys.nz; ++j) d.arm_force(sys.arms[j].coord) += s(j);
}

/// ṡ_j = k_j q̇_{i(j)} − s_j / τ_j into sd (nz).
inline void arm_rates(const System& sys, const Eigen::Ref<const VecX>& qd, const Eigen::Ref<const VecX>& s,
                      Eigen::Ref<VecX> sd) {
  for (int j = 0; j < sys.nz; ++j) {
    const Arm& a = sys.arms[j];
    sd(j) = a.stiffness * qd(a.q) - s(j) / a.tau;
  }
}

/// (1 − e^{−x}) / x, accurate for small x.
inline double relaxed_fraction(double x) { return x > 1e-8 ? -std::expm1(-x) / x : 1.0 - 0.5 * x; }

/// The arms' forces after a time h over which q moves linearly from q0 to q1 (exact for that path):
///   s_j(h) = e^{−h/τ} s_j + k_j (1 − e^{−h/τ}) / (h/τ) (q1 − q0)_{i(j)}   (h = 0: s).
inline void arm_step(const System& sys, double h, const VecX& s0, const VecX& q0, const VecX& q1, VecX& s1) {
  s1.resize(sys.nz);
  for (int j = 0; j < sys.nz; ++j) {
    const Arm& a = sys.arms[j];
    const double x = h / a.tau;
    s1(j) = std::exp(-x) * s0(j) + a.stiffness * relaxed_fraction(x) * (q1(a.q) - q0(a.q));
  }
}

/// The stiffness the arms add over a step h of arm_step, ∂s(h)/∂q1 on each free coordinate, into
/// k (nq): Σ_j k_j (1 − e^{−h/τ_j}) / (h/τ_j), added to the Newton matrix's K.
inline void arm_step_stiffness(const System& sys, double h, VecX& k) {
  k.setZero(sys.nq);
  for (const Arm& a : sys.arms) k(a.q) += a.stiffness * relaxed_fraction(h / a.tau);
}

/// Stored energy Σ s² / (2k) (J) and dissipated power Σ s² / (k τ) (W) of the arms.
inline double arm_energy(const System& sys, const Eigen::Ref<const VecX>& s) {
  double V = 0.0;
  for (int j = 0; j < sys.nz; ++j) V += 0.5 * s(j) * s(j) / sys.arms[j].stiffness;
  return V;
}
inline double arm_power(const System& sys, const Eigen::Ref<const VecX>& s) {
  double P = 0.0;
  for (int j = 0; j < sys.nz; ++j) P += s(j) * s(j) / (sys.arms[j].stiffness * sys.arms[j].tau);
  return P;
}

}  // namespace rigidfem
