#include "lash/signals/signal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace lash {

Waveform parse_waveform(const std::string& name) {
  if (name == "sine") return Waveform::sine;
  if (name == "square") return Waveform::square;
  if (name == "triangle") return Waveform::triangle;
  if (name == "randomized" || name == "random") return Waveform::randomized;
  if (name == "steps") return Waveform::steps;
  if (name == "constant") return Waveform::constant;
  throw std::invalid_argument("unknown input kind '" + name +
                              "' (expected sine, square, triangle, randomized, steps, constant)");
}

const char* to_string(Waveform w) noexcept {
  switch (w) {
    case Waveform::sine: return "sine";
    case Waveform::square: return "square";
    case Waveform::triangle: return "triangle";
    case Waveform::randomized: return "randomized";
    case Waveform::steps: return "steps";
    case Waveform::constant: return "constant";
  }
  return "?";
}

double max_abs_value(const SignalSpec& s) noexcept {
  const double off = std::fabs(s.offset);
  switch (s.kind) {
    case Waveform::sine:
    case Waveform::square:
    case Waveform::triangle: return std::fabs(s.amplitude) + off;
    case Waveform::constant: return std::fabs(s.amplitude + s.offset);
    case Waveform::randomized: return off + 12.1 * std::sqrt(s.variance);
    case Waveform::steps: {
      double m = 0.0;
      for (const auto& l : s.steps) m = std::isnan(l.value) ? l.value : std::max(m, std::fabs(l.value));
      return m + off;
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

Signal::Signal(SignalSpec spec, double dt_s) : spec_(std::move(spec)), dt_s_(dt_s), rng_(spec_.seed) {
  auto finite = [](double x) { return std::isfinite(x); };
  if (!(finite(dt_s) && dt_s > 0)) throw std::invalid_argument("dt must be > 0");
  if (!finite(spec_.amplitude)) throw std::invalid_argument("amplitude must be finite");
  if (!finite(spec_.offset) || !finite(spec_.phase_rad)) throw std::invalid_argument("offset/phase must be finite");
  if (!finite(spec_.frequency_rad_s) || spec_.frequency_rad_s < 0)
    throw std::invalid_argument("frequency must be >= 0 [rad/s]");
  if (spec_.kind == Waveform::randomized) {
    if (!finite(spec_.variance) || spec_.variance < 0) throw std::invalid_argument("variance must be >= 0");
    if (!finite(spec_.tau_s) || spec_.tau_s <= 0) throw std::invalid_argument("tau must be > 0 [s]");
    lp_a_ = std::exp(-dt_s / spec_.tau_s);
    lp_sigma_ = std::sqrt(spec_.variance);
  }
  if (spec_.kind == Waveform::steps) {
    for (std::size_t i = 0; i < spec_.steps.size(); ++i) {
      if (!finite(spec_.steps[i].t_s) || !finite(spec_.steps[i].value))
        throw std::invalid_argument("step levels must be finite");
      if (i > 0 && !(spec_.steps[i].t_s > spec_.steps[i - 1].t_s))
        throw std::invalid_argument("step times must increase");
    }
  }
}

double Signal::next() noexcept {
  const double t = static_cast<double>(k_) * dt_s_;
  ++k_;
  const double A = spec_.amplitude;
  const double arg = spec_.frequency_rad_s * t + spec_.phase_rad;
  double v = 0.0;
  switch (spec_.kind) {
    case Waveform::sine: v = A * std::sin(arg); break;
    case Waveform::square: {
      const double s = std::sin(arg);
      v = s > 0 ? A : (s < 0 ? -A : 0.0);
      break;
    }
    case Waveform::triangle: v = A * (2.0 / std::numbers::pi) * std::asin(std::sin(arg)); break;  // eq. (37)
    case Waveform::randomized:
      // Zero-order-hold discretisation of 1/(τs + 1) driven by N(0, variance) each step.
      lp_ = lp_a_ * lp_ + (1.0 - lp_a_) * lp_sigma_ * rng_.gaussian();
      v = lp_;
      break;
    case Waveform::steps:
      while (step_pos_ < spec_.steps.size() && spec_.steps[step_pos_].t_s <= t + 1e-9 * dt_s_) ++step_pos_;
      v = step_pos_ == 0 ? 0.0 : spec_.steps[step_pos_ - 1].value;
      break;
    case Waveform::constant: v = A; break;
  }
  return v + spec_.offset;
}

}  // namespace lash
