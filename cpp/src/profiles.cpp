#include "rigidfem/profiles.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace rigidfem {

namespace {

void require_finite(double x, const char* name) {
  if (!std::isfinite(x)) throw std::invalid_argument(std::string(name) + ": expected a finite number, got " + std::to_string(x));
}

class Constant final : public Profile {
 public:
  explicit Constant(double v) : v_(v) {}
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

class HarmonicSeries final : public Profile {
 public:
  HarmonicSeries(std::vector<double> a, std::vector<double> w, std::vector<double> ph, double off)
      : a_(std::move(a)), w_(std::move(w)), ph_(std::move(ph)), off_(off) {}
  MotionState at(double t) const override {
    // q = c + Σ a_k sin(ω_k t + φ_k), q̇ = Σ a_k ω_k cos(ω_k t + φ_k), q̈ = −Σ a_k ω_k² sin(ω_k t + φ_k).
    MotionState m{off_, 0.0, 0.0};
    for (size_t k = 0; k < a_.size(); ++k) {
      const double s = std::sin(w_[k] * t + ph_[k]), c = std::cos(w_[k] * t + ph_[k]);
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
    // The knot interval [t_k, t_k+1) holding t; clamped, so a NaN t reads no knot beyond the table.
    const size_t after = static_cast<size_t>(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin());
    return segment(std::min(std::max(after, size_t{1}), n - 1) - 1, t);
  }
  std::string describe() const override { return "spline(" + std::to_string(t_.size()) + " points)"; }
  ProfileRecipe recipe() const override { return {"spline_profile", {t_, q_}}; }

 private:
  MotionState segment(size_t k, double t) const {
    const double h = t_[k + 1] - t_[k], a = (t_[k + 1] - t) / h, b = (t - t_[k]) / h;
    const double m0 = m_[k], m1 = m_[k + 1];
    return {a * q_[k] + b * q_[k + 1] + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0,
            (q_[k + 1] - q_[k]) / h + ((1.0 - 3.0 * a * a) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0,
            a * m0 + b * m1};
  }
  std::vector<double> t_, q_, m_;
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
  return std::make_shared<Constant>(value);
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
  if (!(duration > 0.0) || !std::isfinite(duration))
    throw std::invalid_argument("duration: expected a positive time in s, got " + std::to_string(duration));
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

ProfilePtr callback_profile(std::function<MotionState(double)> f) {
  if (!f) throw std::invalid_argument("function: expected a callable, got None");
  return std::make_shared<Callback>(std::move(f));
}

}  // namespace rigidfem
