/// Prescribed motions q(t), q̇(t), q̈(t) of a joint coordinate (drives), also used
/// as time scalings of loads. Units follow the coordinate: m or rad, per s, per s².
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace rigidfem {

/// Value, rate and second rate of a profile at one instant.
struct MotionState {
  double q = 0.0, qd = 0.0, qdd = 0.0;
};

/// How a profile was made: the name of its maker below (e.g. "harmonic_profile") and the maker's
/// arguments, enough to make it again bit for bit (pickling). Empty maker: not remakeable (a
/// Python function, an internal profile).
struct ProfileRecipe {
  std::string maker;
  std::vector<std::variant<double, std::vector<double>>> arguments;
};

class Profile {
 public:
  virtual ~Profile() = default;
  virtual MotionState at(double t) const = 0;
  virtual std::string describe() const = 0;
  virtual ProfileRecipe recipe() const { return {}; }
};

using ProfilePtr = std::shared_ptr<Profile>;  // profiles are immutable: only const methods

/// q = value.
ProfilePtr constant_profile(double value);
/// q = Σ_k c_k t^k.
ProfilePtr polynomial_profile(const std::vector<double>& coefficients);
/// q = offset + amplitude · sin(ω t + phase).
ProfilePtr harmonic_profile(double amplitude, double omega, double phase, double offset);
/// q = c + Σ_k a_k sin(ω_k t + φ_k): a sum of harmonics (a base motion, a sea state's response);
/// q̇ and q̈ are its exact derivatives. ω_k in rad/s, φ_k in rad.
ProfilePtr harmonic_series_profile(const std::vector<double>& amplitudes, const std::vector<double>& omegas,
                                   const std::vector<double>& phases, double offset);
/// Kane's spin-up of a hub (Kane, Ryan & Banerjee 1987):
/// θ = (Ω/T)[t²/2 + (T/2π)²(cos(2πt/T) − 1)] for t < T, θ = Ω(t − T/2) after.
ProfilePtr spin_up_profile(double omega, double duration);
/// Natural cubic spline through (t_k, q_k); beyond the table q continues linearly
/// with the end slope (q̈ = 0).
ProfilePtr spline_profile(const std::vector<double>& t, const std::vector<double>& q);
/// A user function t -> (q, q̇, q̈): the slow path (called through Python).
ProfilePtr callback_profile(std::function<MotionState(double)> f);

}  // namespace rigidfem
