#include "rigidfem/profiles.hpp"

#include "rigidfem/errors.hpp"
#include "rigidfem/transforms.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace rigidfem {

namespace {

void require_finite(double x, const char* name) {
  if (!std::isfinite(x)) throw std::invalid_argument(std::string(name) + ": expected a finite number, got " + std::to_string(x));
}

/// The duration T of a timed law: a positive, finite time in s.
void require_duration(double duration) {
  if (!(duration > 0.0) || !std::isfinite(duration))
    throw std::invalid_argument("duration: expected a positive time in s, got " + num(duration));
}

class ConstantProfile final : public Profile {
 public:
  explicit ConstantProfile(double v) : v_(v) {}
  MotionState at(double) const override { return {v_, 0.0, 0.0}; }
  std::string describe() const override { return "constant(" + std::to_string(v_) + ")"; }
  ProfileRecipe recipe() const override { return {"constant_profile", {v_}}; }

 private:
  double v_;
};

class Polynomial final : public Profile {
 public:
  explicit Polynomial(std::vector<double> c) : c_(std::move(c)) {}
  MotionState at(double t) const override {
    // Horner's scheme for q, q̇ = Σ k c_k t^{k−1}, q̈ = Σ k(k−1) c_k t^{k−2}.
    MotionState s;
    for (int k = static_cast<int>(c_.size()) - 1; k >= 0; --k) {
      s.qdd = s.qdd * t + 2.0 * s.qd;
      s.qd = s.qd * t + s.q;
      s.q = s.q * t + c_[k];
    }
    return s;
  }
  std::string describe() const override { return "polynomial(degree " + std::to_string(c_.size() - 1) + ")"; }
  ProfileRecipe recipe() const override { return {"polynomial_profile", {c_}}; }

 private:
  std::vector<double> c_;
};

class Harmonic final : public Profile {
 public:
  Harmonic(double a, double w, double ph, double off) : a_(a), w_(w), ph_(ph), off_(off) {}
  MotionState at(double t) const override {
    const double s = std::sin(w_ * t + ph_), c = std::cos(w_ * t + ph_);
    return {off_ + a_ * s, a_ * w_ * c, -a_ * w_ * w_ * s};
  }
  std::string describe() const override {
    std::ostringstream o;
    o << "harmonic(amplitude=" << a_ << ", omega=" << w_ << ")";
    return o.str();
  }

  ProfileRecipe recipe() const override { return {"harmonic_profile", {a_, w_, ph_, off_}}; }

 private:
  double a_, w_, ph_, off_;
};

/// A linear sweep (chirp) of amplitude A from f0 to f1 (Hz) over T from t0: with τ = t − t0 in [0, T],
///   q = A sin φ(τ),  φ = 2π (f0 τ + (f1 − f0) τ² / (2T)),  φ̇ = 2π (f0 + (f1 − f0) τ/T),  φ̈ = 2π (f1 − f0)/T,
/// q̇ = A φ̇ cos φ, q̈ = A (φ̈ cos φ − φ̇² sin φ); zero before t0 (the sweep starts at q = 0 with the rate 2π A f0),
/// and after t0 + T it goes on at f1 (φ linear). The input of a frequency response or an identification.
class Chirp final : public Profile {
 public:
  Chirp(double a, double f0, double f1, double t0, double T) : a_(a), f0_(f0), f1_(f1), t0_(t0), T_(T) {}
  MotionState at(double t) const override {
    const double tau = t - t0_;
    if (tau < 0.0) return {0.0, 0.0, 0.0};
    const double k = 2.0 * M_PI, u = std::min(tau, T_);  // the sweep's part, then f1 on
    const double phi = k * (f0_ * u + 0.5 * (f1_ - f0_) * u * u / T_) + k * f1_ * (tau - u);
    const double dphi = k * (f0_ + (f1_ - f0_) * u / T_), ddphi = tau < T_ ? k * (f1_ - f0_) / T_ : 0.0;
    const double s = std::sin(phi), c = std::cos(phi);
    return {a_ * s, a_ * dphi * c, a_ * (ddphi * c - dphi * dphi * s)};
  }
  std::string describe() const override {
    std::ostringstream o;
    o << "chirp(amplitude=" << a_ << ", " << f0_ << " -> " << f1_ << " Hz over " << T_ << " s)";
    return o.str();
  }
  ProfileRecipe recipe() const override { return {"chirp_profile", {a_, f0_, f1_, t0_, T_}}; }

 private:
  double a_, f0_, f1_, t0_, T_;
};

ProfilePtr chirp_profile(double amplitude, double f0, double f1, double t0, double duration) {
  require_finite(amplitude, "amplitude");
  for (const auto& [f, name] : {std::pair<double, const char*>{f0, "f0"}, {f1, "f1"}})
    if (!(f >= 0.0 && std::isfinite(f))) throw std::invalid_argument(std::string(name) + ": expected a frequency >= 0 in Hz, got " + num(f));
  require_finite(t0, "t0");
  require_duration(duration);
  return std::make_shared<Chirp>(amplitude, f0, f1, t0, duration);
}

class HarmonicSeries final : public Profile {
 public:
  HarmonicSeries(std::vector<double> a, std::vector<double> w, std::vector<double> ph, double off)
      : a_(std::move(a)), w_(std::move(w)), ph_(std::move(ph)), off_(off) {}
  MotionState at(double t) const override {
    // q = c + Σ a_k sin(ω_k t + φ_k), q̇ = Σ a_k ω_k cos(ω_k t + φ_k), q̈ = −Σ a_k ω_k² sin(ω_k t + φ_k).
    MotionState m{off_, 0.0, 0.0};
    for (size_t k = 0; k < a_.size(); ++k) {
      double s, c;
      sin_cos(w_[k] * t + ph_[k], s, c);
      m.q += a_[k] * s;
      m.qd += a_[k] * w_[k] * c;
      m.qdd -= a_[k] * w_[k] * w_[k] * s;
    }
    return m;
  }
  std::string describe() const override {
    std::ostringstream o;
    o << "harmonics(" << a_.size() << " components, offset=" << off_ << ")";
    return o.str();
  }

  ProfileRecipe recipe() const override { return {"harmonic_series_profile", {a_, w_, ph_, off_}}; }

 private:
  std::vector<double> a_, w_, ph_;
  double off_;
};

class SpinUp final : public Profile {
 public:
  SpinUp(double omega, double T) : W_(omega), T_(T) {}
  MotionState at(double t) const override {
    if (t >= T_) return {W_ * (t - 0.5 * T_), W_, 0.0};
    // θ = (Ω/T)[t²/2 + (T/2π)²(cos(2πt/T) − 1)], θ̇ = (Ω/T)[t − (T/2π) sin(2πt/T)],
    // θ̈ = (Ω/T)[1 − cos(2πt/T)].
    const double k = 2.0 * M_PI / T_, a = W_ / T_;
    return {a * (0.5 * t * t + (std::cos(k * t) - 1.0) / (k * k)), a * (t - std::sin(k * t) / k),
            a * (1.0 - std::cos(k * t))};
  }
  std::string describe() const override {
    std::ostringstream o;
    o << "spin_up(omega=" << W_ << " rad/s, duration=" << T_ << " s)";
    return o.str();
  }

  ProfileRecipe recipe() const override { return {"spin_up_profile", {W_, T_}}; }

 private:
  double W_, T_;
};

class Spline final : public Profile {
 public:
  Spline(std::vector<double> t, std::vector<double> q) : t_(std::move(t)), q_(std::move(q)), m_(t_.size(), 0.0) {
    // Natural cubic spline: second derivatives m_k from the tridiagonal system
    // h_{k−1} m_{k−1} + 2(h_{k−1}+h_k) m_k + h_k m_{k+1} = 6(δ_k − δ_{k−1}), m_0 = m_n = 0.
    const size_t n = t_.size();
    if (n < 3) return;
    std::vector<double> diag(n, 1.0), upper(n, 0.0), rhs(n, 0.0);
    for (size_t k = 1; k + 1 < n; ++k) {
      const double h0 = t_[k] - t_[k - 1], h1 = t_[k + 1] - t_[k];
      const double lower = h0;
      diag[k] = 2.0 * (h0 + h1);
      upper[k] = h1;
      rhs[k] = 6.0 * ((q_[k + 1] - q_[k]) / h1 - (q_[k] - q_[k - 1]) / h0);
      // Thomas algorithm, forward elimination (row 0 is m_0 = 0).
      const double w = lower / diag[k - 1];
      diag[k] -= w * upper[k - 1];
      rhs[k] -= w * rhs[k - 1];
    }
    for (size_t k = n - 2; k >= 1; --k) m_[k] = (rhs[k] - upper[k] * m_[k + 1]) / diag[k];
  }
  MotionState at(double t) const override {
    const size_t n = t_.size();
    if (t <= t_.front() || t >= t_.back()) {
      const bool left = t <= t_.front();
      const size_t k = left ? 0 : n - 2;
      const double te = left ? t_.front() : t_.back();
      const double slope = segment(k, te).qd;
      return {(left ? q_.front() : q_.back()) + slope * (t - te), slope, 0.0};
    }
    return segment(interval(t), t);
  }
  std::string describe() const override { return "spline(" + std::to_string(t_.size()) + " points)"; }
  ProfileRecipe recipe() const override { return {"spline_profile", {t_, q_}}; }

 private:
  /// The knot interval [t_k, t_k+1) holding t (t_0 < t < t_n): guessed as if the knots were evenly spaced (one
  /// look for np.linspace's), checked, else found by bisection; a NaN t reads no knot beyond the table.
  size_t interval(double t) const {
    const size_t n = t_.size();
    const double guess = (t - t_.front()) / (t_.back() - t_.front()) * static_cast<double>(n - 1);
    if (guess >= 0.0 && guess < static_cast<double>(n - 1)) {
      const size_t k = static_cast<size_t>(guess);
      if (t_[k] <= t && t < t_[k + 1]) return k;
    }
    const size_t after = static_cast<size_t>(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin());
    return std::min(std::max(after, size_t{1}), n - 1) - 1;
  }
  MotionState segment(size_t k, double t) const {
    const double h = t_[k + 1] - t_[k], a = (t_[k + 1] - t) / h, b = (t - t_[k]) / h;
    const double m0 = m_[k], m1 = m_[k + 1];
    return {a * q_[k] + b * q_[k + 1] + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0,
            (q_[k + 1] - q_[k]) / h + ((1.0 - 3.0 * a * a) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0,
            a * m0 + b * m1};
  }
  std::vector<double> t_, q_, m_;
};

/// A normalised point-to-point law s(τ) on τ ∈ [0, 1], s(0) = 0, s(1) = 1, symmetric (s(τ) + s(1 − τ) = 1),
/// with s', s'' and S(τ) = ∫₀^τ s (S(1) = 1/2).
struct MotionLaw {
  enum class Kind { Quintic, Cycloidal, Trapezoidal } kind;
  double f = 0.0;  // trapezoidal: the fraction of T spent accelerating (and decelerating), 0 < f ≤ 1/2; else 0

  std::string name() const { return point_to_point_laws()[static_cast<int>(kind)]; }
  /// (s, s', s'') at τ.
  MotionState at(double tau) const {
    switch (kind) {
      case Kind::Quintic: {  // s = 10τ³ − 15τ⁴ + 6τ⁵, s' = 30τ²(1 − τ)², s'' = 60τ(1 − τ)(1 − 2τ)
        const double u = 1.0 - tau;
        return {tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau), 30.0 * tau * tau * u * u,
                60.0 * tau * u * (1.0 - 2.0 * tau)};
      }
      case Kind::Cycloidal: {  // s = τ − sin(2πτ)/(2π), s' = 1 − cos(2πτ), s'' = 2π sin(2πτ)
        const double k = 2.0 * M_PI;
        return {tau - std::sin(k * tau) / k, 1.0 - std::cos(k * tau), k * std::sin(k * tau)};
      }
      case Kind::Trapezoidal: {  // peak rate v = 1/(1 − f): s'' = v/f, 0, −v/f on [0, f), [f, 1 − f], (1 − f, 1]
        const double v = 1.0 / (1.0 - f);
        if (tau < f) return {v * tau * tau / (2.0 * f), v * tau / f, v / f};
        if (tau <= 1.0 - f) return {v * (tau - 0.5 * f), v, 0.0};
        const double u = 1.0 - tau;
        return {1.0 - v * u * u / (2.0 * f), v * u / f, -v / f};
      }
    }
    return {};
  }
  /// S(τ) = ∫₀^τ s; beyond τ = 1/2 from the symmetry, S(τ) = τ − 1/2 + S(1 − τ).
  double integral(double tau) const {
    if (tau > 0.5) return tau - 0.5 + integral(1.0 - tau);
    switch (kind) {
      case Kind::Quintic:  // 5τ⁴/2 − 3τ⁵ + τ⁶
        return tau * tau * tau * tau * (2.5 - 3.0 * tau + tau * tau);
      case Kind::Cycloidal: {  // τ²/2 + (cos(2πτ) − 1)/(2π)²
        const double k = 2.0 * M_PI;
        return 0.5 * tau * tau + (std::cos(k * tau) - 1.0) / (k * k);
      }
      case Kind::Trapezoidal: {  // v τ³/(6f) on [0, f), then S(f) + v [(τ² − f²)/2 − f (τ − f)/2]
        const double v = 1.0 / (1.0 - f);
        if (tau < f) return v * tau * tau * tau / (6.0 * f);
        return v * f * f / 6.0 + v * (0.5 * (tau * tau - f * f) - 0.5 * f * (tau - f));
      }
    }
    return 0.0;
  }
};

// "one of 'quintic', 'cycloidal', 'trapezoidal'": what a law's name is, for the messages.
const char* law_names() {
  static const std::string names = [] {
    std::string s = "one of ";
    for (const std::string& n : point_to_point_laws()) s += (s.size() > 7 ? ", '" : "'") + n + "'";
    return s;
  }();
  return names.c_str();
}

MotionLaw make_law(const std::string& name, double fraction) {
  const auto& names = point_to_point_laws();
  const auto k = std::find(names.begin(), names.end(), name) - names.begin();
  if (k == static_cast<long>(names.size()))
    throw std::invalid_argument(std::string("law: expected ") + law_names() + ", got '" + name + "'");
  const MotionLaw::Kind kind = static_cast<MotionLaw::Kind>(k);
  if (kind != MotionLaw::Kind::Trapezoidal) return {kind, 0.0};
  if (!(fraction > 0.0 && fraction <= 0.5))
    throw std::invalid_argument("fraction: expected the share of the duration spent accelerating, in (0, 0.5], got " +
                                num(fraction));
  return {kind, fraction};
}

class RestToRest final : public Profile {
 public:
  RestToRest(MotionLaw law, double q0, double q1, double t0, double T) : law_(law), q0_(q0), q1_(q1), t0_(t0), T_(T) {}
  MotionState at(double t) const override {
    const double tau = (t - t0_) / T_, d = q1_ - q0_;
    if (!(tau > 0.0)) return {q0_, 0.0, 0.0};  // also NaN: at rest
    if (tau >= 1.0) return {q1_, 0.0, 0.0};
    const MotionState s = law_.at(tau);  // q = q0 + Δ s, q̇ = Δ s'/T, q̈ = Δ s''/T²
    return {q0_ + d * s.q, d * s.qd / T_, d * s.qdd / (T_ * T_)};
  }
  std::string describe() const override {
    std::ostringstream o;
    o << "rest_to_rest(" << law_.name() << ", " << q0_ << " -> " << q1_ << ", t = " << t0_ << " ... " << t0_ + T_ << " s)";
    return o.str();
  }
  ProfileRecipe recipe() const override { return {"rest_to_rest_profile", {law_.name(), q0_, q1_, t0_, T_, law_.f}}; }

 private:
  MotionLaw law_;
  double q0_, q1_, t0_, T_;
};

class Ramp final : public Profile {
 public:
  Ramp(MotionLaw law, double rate, double t0, double T, double start) : law_(law), v_(rate), t0_(t0), T_(T), q0_(start) {}
  MotionState at(double t) const override {
    const double tau = (t - t0_) / T_;
    if (!(tau > 0.0)) return {q0_, 0.0, 0.0};
    if (tau >= 1.0) return {q0_ + v_ * (t - t0_ - 0.5 * T_), v_, 0.0};
    const MotionState s = law_.at(tau);  // q = q0 + v T S(τ), q̇ = v s(τ), q̈ = v s'(τ)/T
    return {q0_ + v_ * T_ * law_.integral(tau), v_ * s.q, v_ * s.qd / T_};
  }
  std::string describe() const override {
    std::ostringstream o;
    o << "ramp(" << law_.name() << ", rate " << v_ << " from t = " << t0_ << " s over " << T_ << " s)";
    return o.str();
  }
  ProfileRecipe recipe() const override {
    return {"ramp_profile", {law_.name(), v_, t0_, T_, q0_, law_.f}};
  }

 private:
  MotionLaw law_;
  double v_, t0_, T_, q0_;
};

class Sum final : public Profile {
 public:
  Sum(std::vector<double> w, std::vector<ProfilePtr> parts, double offset)
      : w_(std::move(w)), parts_(std::move(parts)), offset_(offset) {}
  MotionState at(double t) const override {
    MotionState m{offset_, 0.0, 0.0};  // Σ w_k p_k + offset, term by term in q, q̇, q̈
    for (size_t k = 0; k < parts_.size(); ++k) {
      const MotionState p = parts_[k]->at(t);
      m.q += w_[k] * p.q, m.qd += w_[k] * p.qd, m.qdd += w_[k] * p.qdd;
    }
    return m;
  }
  std::string describe() const override {
    // "a − 2·b + 1": unit weights left out (sums are flat: sum_profile)
    std::ostringstream o;
    for (size_t k = 0; k < parts_.size(); ++k) {
      const double w = std::abs(w_[k]);
      o << (k ? (w_[k] < 0 ? " − " : " + ") : (w_[k] < 0 ? "−" : ""));
      if (w != 1.0) o << w << "·";
      o << parts_[k]->describe();
    }
    if (offset_ != 0.0 || parts_.empty())
      o << (parts_.empty() ? (offset_ < 0 ? "−" : "") : (offset_ < 0 ? " − " : " + ")) << std::abs(offset_);
    return o.str();
  }
  ProfileRecipe recipe() const override { return {"sum_profile", {w_, parts_, offset_}}; }
  const std::vector<double>& weights() const { return w_; }
  const std::vector<ProfilePtr>& parts() const { return parts_; }
  double offset() const { return offset_; }

 private:
  std::vector<double> w_;
  std::vector<ProfilePtr> parts_;
  double offset_;
};

class Shifted final : public Profile {
 public:
  Shifted(ProfilePtr p, double delay) : p_(std::move(p)), delay_(delay) {}
  MotionState at(double t) const override { return p_->at(t - delay_); }
  std::string describe() const override {
    std::ostringstream o;
    o << p_->describe() << " delayed by " << delay_ << " s";
    return o.str();
  }
  ProfileRecipe recipe() const override { return {"shifted_profile", {p_, delay_}}; }

 private:
  ProfilePtr p_;
  double delay_;
};

class Piecewise final : public Profile {
 public:
  Piecewise(std::vector<ProfilePtr> pieces, std::vector<double> breaks, int continuity)
      : pieces_(std::move(pieces)), breaks_(std::move(breaks)), continuity_(continuity) {}
  MotionState at(double t) const override {
    // the piece k with breaks[k−1] ≤ t < breaks[k]
    const auto k = std::upper_bound(breaks_.begin(), breaks_.end(), t) - breaks_.begin();
    return pieces_[static_cast<size_t>(k)]->at(t);
  }
  std::string describe() const override {
    return "piecewise(" + std::to_string(pieces_.size()) + " pieces, continuity " + std::to_string(continuity_) + ")";
  }
  ProfileRecipe recipe() const override {
    return {"piecewise_profile", {pieces_, breaks_, continuity_}};
  }

 private:
  std::vector<ProfilePtr> pieces_;
  std::vector<double> breaks_;
  int continuity_;
};

class Callback final : public Profile {
 public:
  explicit Callback(std::function<MotionState(double)> f) : f_(std::move(f)) {}
  MotionState at(double t) const override { return f_(t); }
  std::string describe() const override { return "callable (slow path)"; }

 private:
  std::function<MotionState(double)> f_;
};

}  // namespace

ProfilePtr constant_profile(double value) {
  require_finite(value, "value");
  return std::make_shared<ConstantProfile>(value);
}

ProfilePtr polynomial_profile(const std::vector<double>& coefficients) {
  if (coefficients.empty()) throw std::invalid_argument("coefficients: expected at least one coefficient, got none");
  for (double c : coefficients) require_finite(c, "coefficients");
  return std::make_shared<Polynomial>(coefficients);
}

ProfilePtr harmonic_profile(double amplitude, double omega, double phase, double offset) {
  require_finite(amplitude, "amplitude");
  require_finite(omega, "omega");
  require_finite(phase, "phase");
  require_finite(offset, "offset");
  return std::make_shared<Harmonic>(amplitude, omega, phase, offset);
}

ProfilePtr harmonic_series_profile(const std::vector<double>& amplitudes, const std::vector<double>& omegas,
                                   const std::vector<double>& phases, double offset) {
  const size_t n = amplitudes.size();
  if (n == 0) throw std::invalid_argument("amplitudes: expected at least one amplitude, got none");
  if (omegas.size() != n)
    throw std::invalid_argument("omegas: expected " + std::to_string(n) + " values (len(amplitudes)), got " +
                                std::to_string(omegas.size()));
  if (phases.size() != n)
    throw std::invalid_argument("phases: expected " + std::to_string(n) + " values (len(amplitudes)), got " +
                                std::to_string(phases.size()));
  for (size_t k = 0; k < n; ++k) {
    require_finite(amplitudes[k], "amplitudes");
    require_finite(omegas[k], "omegas");
    require_finite(phases[k], "phases");
  }
  require_finite(offset, "offset");
  return std::make_shared<HarmonicSeries>(amplitudes, omegas, phases, offset);
}

ProfilePtr spin_up_profile(double omega, double duration) {
  require_finite(omega, "omega");
  require_duration(duration);
  return std::make_shared<SpinUp>(omega, duration);
}

ProfilePtr spline_profile(const std::vector<double>& t, const std::vector<double>& q) {
  if (t.size() < 2) throw std::invalid_argument("t: expected at least 2 points, got " + std::to_string(t.size()));
  if (q.size() != t.size())
    throw std::invalid_argument("q: expected " + std::to_string(t.size()) + " values (len(t)), got " + std::to_string(q.size()));
  for (size_t k = 0; k < t.size(); ++k) {
    require_finite(t[k], "t");
    require_finite(q[k], "q");
    if (k > 0 && !(t[k] > t[k - 1])) throw std::invalid_argument("t: expected strictly increasing times");
  }
  return std::make_shared<Spline>(t, q);
}

ProfilePtr rest_to_rest_profile(const std::string& law, double start, double end, double t0, double duration,
                                double fraction) {
  const MotionLaw l = make_law(law, fraction);
  require_finite(start, "start");
  require_finite(end, "end");
  require_finite(t0, "t0");
  require_duration(duration);
  return std::make_shared<RestToRest>(l, start, end, t0, duration);
}

ProfilePtr ramp_profile(const std::string& law, double rate, double t0, double duration, double start,
                        double fraction) {
  const MotionLaw l = make_law(law, fraction);
  require_finite(rate, "rate");
  require_finite(t0, "t0");
  require_finite(start, "start");
  require_duration(duration);
  return std::make_shared<Ramp>(l, rate, t0, duration, start);
}

ProfilePtr sum_profile(const std::vector<double>& weights, const std::vector<ProfilePtr>& parts, double offset) {
  if (weights.size() != parts.size())
    throw std::invalid_argument("weights: expected " + std::to_string(parts.size()) + " values (one per part), got " +
                                std::to_string(weights.size()));
  for (double w : weights) require_finite(w, "weights");
  for (const ProfilePtr& p : parts)
    if (!p) throw std::invalid_argument("parts: expected profiles, got None");
  require_finite(offset, "offset");
  // A sum of sums is one sum: w·(Σ v_j r_j + c) adds the terms w v_j r_j and the offset w c.
  std::vector<double> w;
  std::vector<ProfilePtr> terms;
  for (size_t k = 0; k < parts.size(); ++k) {
    if (const auto* inner = dynamic_cast<const Sum*>(parts[k].get())) {
      for (size_t j = 0; j < inner->parts().size(); ++j)
        w.push_back(weights[k] * inner->weights()[j]), terms.push_back(inner->parts()[j]);
      offset += weights[k] * inner->offset();
    } else {
      w.push_back(weights[k]), terms.push_back(parts[k]);
    }
  }
  // the products of weights (and the offset) may overflow where the factors did not: 1e200 · 1e200
  for (double x : w)
    if (!std::isfinite(x)) throw std::invalid_argument("weights: expected finite products of the weights, got " + num(x));
  if (!std::isfinite(offset)) throw std::invalid_argument("offset: expected a finite sum of the offsets, got " + num(offset));
  return std::make_shared<Sum>(std::move(w), std::move(terms), offset);
}

ProfilePtr shifted_profile(const ProfilePtr& profile, double delay) {
  if (!profile) throw std::invalid_argument("profile: expected a profile, got None");
  require_finite(delay, "delay");
  return std::make_shared<Shifted>(profile, delay);
}

ProfilePtr piecewise_profile(const std::vector<ProfilePtr>& pieces, const std::vector<double>& breaks, int continuity) {
  if (pieces.empty()) throw std::invalid_argument("pieces: expected at least one profile, got none");
  for (const ProfilePtr& p : pieces)
    if (!p) throw std::invalid_argument("pieces: expected profiles, got None");
  if (breaks.size() + 1 != pieces.size())
    throw std::invalid_argument("breaks: expected " + std::to_string(pieces.size() - 1) +
                                " times (one between each two pieces), got " + std::to_string(breaks.size()));
  if (continuity < 0 || continuity > 2)
    throw std::invalid_argument("continuity: expected 0 (q), 1 (q and q̇) or 2 (q, q̇ and q̈), got " +
                                std::to_string(continuity));
  for (size_t k = 0; k < breaks.size(); ++k) {
    require_finite(breaks[k], "breaks");
    if (k > 0 && !(breaks[k] > breaks[k - 1])) throw std::invalid_argument("breaks: expected strictly increasing times");
    // The two pieces meeting at the break must agree to 1e-9 (1 + |x|) in q, q̇, q̈ up to the continuity asked.
    const MotionState a = pieces[k]->at(breaks[k]), b = pieces[k + 1]->at(breaks[k]);
    const double left[3] = {a.q, a.qd, a.qdd}, right[3] = {b.q, b.qd, b.qdd};
    static const char* names[3] = {"q", "qd", "qdd"};
    for (int i = 0; i <= continuity; ++i)
      if (!(std::abs(left[i] - right[i]) <= 1e-9 * (1.0 + std::max(std::abs(left[i]), std::abs(right[i])))))
        throw std::invalid_argument("pieces: expected pieces " + std::to_string(k) + " and " + std::to_string(k + 1) +
                                    " to meet at the break t = " + num(breaks[k]) + " s with continuity " +
                                    std::to_string(continuity) + ", got " + names[i] + " = " + num(left[i]) +
                                    " before and " + num(right[i]) + " after");
  }
  return std::make_shared<Piecewise>(pieces, breaks, continuity);
}

ProfilePtr callback_profile(std::function<MotionState(double)> f) {
  if (!f) throw std::invalid_argument("function: expected a callable, got None");
  return std::make_shared<Callback>(std::move(f));
}

const std::vector<std::string>& point_to_point_laws() {
  static const std::vector<std::string> names{"quintic", "cycloidal", "trapezoidal"};  // the order of MotionLaw::Kind
  return names;
}

namespace {

// The arguments of a maker's row, by type.
using Arguments = std::vector<ProfileValue>;
double number(const Arguments& a, int k) { return std::get<double>(a[k]); }
const std::vector<double>& numbers(const Arguments& a, int k) { return std::get<std::vector<double>>(a[k]); }
const std::string& name(const Arguments& a, int k) { return std::get<std::string>(a[k]); }

}  // namespace

const std::vector<ProfileKind>& profile_kinds() {
  using P = ProfileArgument;
  static const char* finite = "a finite number";
  static const char* values = "a 1-D sequence of finite numbers";
  static const std::vector<ProfileKind> kinds = {
      {"constant_profile", {{"value", P::Number, finite, true}}, [](const Arguments& a) { return constant_profile(number(a, 0)); }},
      {"polynomial_profile", {{"coefficients", P::Numbers, values, true}},
       [](const Arguments& a) { return polynomial_profile(numbers(a, 0)); }},
      {"harmonic_profile",
       {{"amplitude", P::Number, finite, true}, {"omega", P::Number, finite}, {"phase", P::Number, finite},
        {"offset", P::Number, finite, true}},
       [](const Arguments& a) { return harmonic_profile(number(a, 0), number(a, 1), number(a, 2), number(a, 3)); }},
      {"harmonic_series_profile",
       {{"amplitudes", P::Numbers, values, true}, {"omegas", P::Numbers, values}, {"phases", P::Numbers, values},
        {"offset", P::Number, finite, true}},
       [](const Arguments& a) {
         return harmonic_series_profile(numbers(a, 0), numbers(a, 1), numbers(a, 2), number(a, 3));
       }},
      {"chirp_profile",
       {{"amplitude", P::Number, finite, true}, {"f0", P::Number, "a frequency >= 0 in Hz"},
        {"f1", P::Number, "a frequency >= 0 in Hz"}, {"t0", P::Number, finite},
        {"duration", P::Number, "a positive time in s"}},
       [](const Arguments& a) { return chirp_profile(number(a, 0), number(a, 1), number(a, 2), number(a, 3), number(a, 4)); }},
      {"spin_up_profile", {{"omega", P::Number, finite}, {"duration", P::Number, "a positive time in s"}},
       [](const Arguments& a) { return spin_up_profile(number(a, 0), number(a, 1)); }},
      {"spline_profile", {{"t", P::Numbers, values}, {"q", P::Numbers, values, true}},
       [](const Arguments& a) { return spline_profile(numbers(a, 0), numbers(a, 1)); }},
      {"rest_to_rest_profile",
       {{"law", P::Name, law_names()}, {"start", P::Number, finite, true}, {"end", P::Number, finite, true},
        {"t0", P::Number, finite}, {"duration", P::Number, "a positive time in s"}, {"fraction", P::Number, finite}},
       [](const Arguments& a) {
         return rest_to_rest_profile(name(a, 0), number(a, 1), number(a, 2), number(a, 3), number(a, 4), number(a, 5));
       }},
      {"ramp_profile",
       {{"law", P::Name, law_names()}, {"rate", P::Number, finite, true}, {"t0", P::Number, finite},
        {"duration", P::Number, "a positive time in s"}, {"start", P::Number, finite, true},
        {"fraction", P::Number, finite}},
       [](const Arguments& a) {
         return ramp_profile(name(a, 0), number(a, 1), number(a, 2), number(a, 3), number(a, 4), number(a, 5));
       }},
      {"sum_profile",
       {{"weights", P::Numbers, values, true}, {"parts", P::Parts, "a list of rigidfem.motion profiles"},
        {"offset", P::Number, finite, true}},
       [](const Arguments& a) {
         return sum_profile(numbers(a, 0), std::get<std::vector<ProfilePtr>>(a[1]), number(a, 2));
       }},
      {"shifted_profile", {{"profile", P::Part, "a rigidfem.motion profile"}, {"delay", P::Number, "a finite time in s"}},
       [](const Arguments& a) { return shifted_profile(std::get<ProfilePtr>(a[0]), number(a, 1)); }},
      {"piecewise_profile",
       {{"pieces", P::Parts, "a list of rigidfem.motion profiles"}, {"breaks", P::Numbers, values},
        {"continuity", P::Integer, "0 (q), 1 (q and qd) or 2 (q, qd and qdd)"}},
       [](const Arguments& a) {
         return piecewise_profile(std::get<std::vector<ProfilePtr>>(a[0]), numbers(a, 1), std::get<int>(a[2]));
       }},
  };
  return kinds;
}

}  // namespace rigidfem
