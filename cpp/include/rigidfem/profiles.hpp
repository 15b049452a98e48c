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

class Profile;
using ProfilePtr = std::shared_ptr<Profile>;  // profiles are immutable: only const methods

/// A value a profile's maker takes and its recipe keeps: a number, an integer, numbers, a name, a profile or profiles
/// (the order of ProfileArgument::Type).
using ProfileValue = std::variant<double, int, std::vector<double>, std::string, ProfilePtr, std::vector<ProfilePtr>>;

/// How a profile was made: the name of its maker (a row of profile_kinds(), e.g. "harmonic_profile") and the
/// maker's arguments, enough to make it again bit for bit (pickling; a composite names its parts). Empty
/// maker: not remakeable (a Python function, an internal profile).
struct ProfileRecipe {
  std::string maker;
  std::vector<ProfileValue> arguments;
};

class Profile {
 public:
  virtual ~Profile() = default;
  virtual MotionState at(double t) const = 0;
  virtual std::string describe() const = 0;
  virtual ProfileRecipe recipe() const { return {}; }
};

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
/// The point-to-point laws of rest_to_rest_profile and ramp_profile, by name.
const std::vector<std::string>& point_to_point_laws();
/// Rest to rest: q = start for t ≤ t0, q = end for t ≥ t0 + T, and in between
/// q = start + (end − start) s(τ), τ = (t − t0)/T, q̇ = (end − start) s'(τ)/T, q̈ = (end − start) s''(τ)/T², with
/// the law s named: "quintic" (10τ³ − 15τ⁴ + 6τ⁵: q̇ = q̈ = 0 at both ends),
/// "cycloidal" (τ − sin(2πτ)/(2π): likewise) or "trapezoidal" (constant acceleration over the first
/// and last `fraction` of T, constant rate between: q̈ jumps at four instants). T in s.
ProfilePtr rest_to_rest_profile(const std::string& law, double start, double end, double t0, double duration,
                                double fraction);
/// A smooth ramp of the rate: q̇ = rate s(τ) rising from 0 at t0 to `rate` at t0 + T by the law s, then
/// constant; q = start + rate T S(τ), S(τ) = ∫₀^τ s, and q = start + rate (t − t0 − T/2) after the ramp (every
/// law here has S(1) = 1/2). A winch paying out, a hub spun up (cycloidal: Kane's spin_up_profile).
ProfilePtr ramp_profile(const std::string& law, double rate, double t0, double duration, double start,
                        double fraction);
/// Σ_k w_k p_k(t) + offset, with the rates alike.
ProfilePtr sum_profile(const std::vector<double>& weights, const std::vector<ProfilePtr>& parts, double offset);
/// p(t − delay): the same motion `delay` s later.
ProfilePtr shifted_profile(const ProfilePtr& profile, double delay);
/// pieces[k] on [breaks[k−1], breaks[k]) (the first from −∞, the last on to +∞), each evaluated at the time t
/// itself (shift a piece to start it later). At every break the two pieces must agree to 1e-9 (1 + |x|) in q
/// (continuity 0), and q̇ (1), and q̈ (2); std::invalid_argument names the first break where they do not.
ProfilePtr piecewise_profile(const std::vector<ProfilePtr>& pieces, const std::vector<double>& breaks, int continuity);
/// A user function t -> (q, q̇, q̈): the slow path (called through Python).
ProfilePtr callback_profile(std::function<MotionState(double)> f);

/// One argument of a profile's maker: its name (also its numbers' path as named parameters), which of
/// ProfileValue's alternatives it takes, and what it takes, for the messages.
struct ProfileArgument {
  enum Type { Number, Integer, Numbers, Name, Part, Parts };
  const char* name;
  Type type;
  const char* expected;
  /// Whether the profile is affine in this argument's numbers, the others fixed (a spline's values, a harmonic's
  /// amplitude): a difference of two profiles by any step is then its derivative, to round-off.
  bool affine = false;
};

/// A kind of profile, described once: its maker's name, its arguments in order (its recipe's), and the maker, which
/// judges them (std::invalid_argument naming the first bad one). The bindings make every kind through this table
/// (rigidfem._core._make_profile) and the named parameters read a profile's numbers by these names, so a new kind
/// is its class and its row in profiles.cpp, and its builder in rigidfem.motion.
struct ProfileKind {
  const char* maker;
  std::vector<ProfileArgument> arguments;
  ProfilePtr (*make)(const std::vector<ProfileValue>& arguments);
};
const std::vector<ProfileKind>& profile_kinds();

}  // namespace rigidfem
