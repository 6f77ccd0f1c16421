#include "lash/identify/auto.hpp"

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "lash/identify/auto_gate.hpp"

namespace lash {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

double quantile(std::vector<double> x, double q) {
  if (x.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(x.size() - 1));
  std::nth_element(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(k), x.end());
  return x[k];
}

bool uses_guesses(ModelKind m) noexcept { return model_traits(m).uses_guesses; }

}  // namespace

Preset parse_preset(std::string_view name) {
  if (name == "lash") return Preset::lash;
  if (name == "thesis") return Preset::thesis;
  throw std::invalid_argument("unknown preset '" + std::string(name) + "' (expected lash or thesis)");
}

const char* to_string(Preset p) noexcept { return p == Preset::thesis ? "thesis" : "lash"; }

const char* to_string(GuessSource s) noexcept {
  switch (s) {
    case GuessSource::given: return "given";
    case GuessSource::searched: return "searched";
    case GuessSource::unused: break;
  }
  return "unused";
}

EstimatorConfig preset_config(ModelKind model, Preset preset, double dt_s) {
  return preset == Preset::thesis ? EstimatorConfig::thesis(model, dt_s) : EstimatorConfig(model, dt_s);
}

DataTraits analyse_record(std::span<const double> v, std::span<const double> y, double dt_s) {
  DataTraits d;
  d.dt_s = dt_s;
  std::vector<double> vf, yf, d2, steps;
  vf.reserve(v.size());
  yf.reserve(y.size());
  for (std::size_t k = 0; k < v.size() && k < y.size(); ++k)
    if (std::isfinite(v[k]) && std::isfinite(y[k])) {
      vf.push_back(v[k]);
      yf.push_back(y[k]);
    }
  d.samples = vf.size();
  if (vf.size() < 3) return d;
  d.v_lo = quantile(vf, 0.001);
  d.v_hi = quantile(vf, 0.999);
  d.y_span = quantile(yf, 0.999) - quantile(yf, 0.001);
  d2.reserve(yf.size());
  for (std::size_t k = 2; k < yf.size(); ++k) d2.push_back(std::fabs(yf[k] - 2.0 * yf[k - 1] + yf[k - 2]));
  d.noise_sigma = quantile(d2, 0.5) / (0.6745 * std::sqrt(6.0));
  {
    std::vector<double> rates;
    rates.reserve(yf.size());
    for (std::size_t k = 40; k < yf.size(); ++k) rates.push_back(std::fabs(yf[k] - yf[k - 40]) / (40.0 * dt_s));
    d.ydot_p90 = quantile(rates, 0.9);
    std::vector<double> acc;
    for (std::size_t k = 2; k < yf.size(); ++k) {
      const double d1 = yf[k] - yf[k - 1], d0 = yf[k - 1] - yf[k - 2];
      if (d1 * d0 > 0.0) acc.push_back(std::fabs(d1 - d0) / (dt_s * dt_s));
    }
    d.yddot_p90 = quantile(acc, 0.9);
  }
  // quantised: the nonzero steps are integer multiples of the smallest one
  for (std::size_t k = 1; k < yf.size(); ++k) {
    const double s = std::fabs(yf[k] - yf[k - 1]);
    if (s > 0.0) steps.push_back(s);
  }
  if (steps.size() > 10) {
    const double q = *std::min_element(steps.begin(), steps.end());
    std::size_t on_grid = 0;
    for (double s : steps) on_grid += std::fabs(s / q - std::round(s / q)) < 1e-3 ? 1u : 0u;
    if (q > 0.0 && on_grid >= steps.size() * 99 / 100) d.quantum = q;
  }
  return d;
}

// Each model's choices are its policy's tune() (identify/models/; E3–E5: docs/method.md §A7).
void tune_to_data(EstimatorConfig& c, const DataTraits& d) {
  c.dt_s = d.dt_s > 0.0 ? d.dt_s : c.dt_s;
  with_model(c.model, [&]<class Model>() { Model::tune(c, d); });  // identify/models/
}

AutoRun estimate_auto(const EstimatorConfig& cfg0, std::span<const double> v, std::span<const double> y_raw,
                      bool keep_trace, double gate, std::span<const std::size_t> gap_rows) {
  AutoRun out;
  // The gate is causal (usable online); over a whole record the sample after a flagged one is also
  // known: when it lies nearer the flagged value than the last accepted one, the output really
  // stepped there (a square-wave input) and the sample is restored. gate 0 = off: y is used as is.
  std::vector<double> yc;
  std::uint64_t flagged = 0;
  if (gate > 0.0) {
    yc.assign(y_raw.begin(), y_raw.end());
    OutlierGateConfig gc;
    gc.gate = gate;
    OutlierGate gate_y(gc);
    for (std::size_t k = 0; k < yc.size(); ++k) {
      const std::uint64_t before = gate_y.rejected();
      yc[k] = gate_y.step(y_raw[k]);
      if (gate_y.rejected() == before) continue;
      const double next = k + 1 < yc.size() ? y_raw[k + 1] : yc[k];
      if (std::fabs(next - y_raw[k]) < std::fabs(next - yc[k])) yc[k] = y_raw[k];
      else ++flagged;
    }
  }
  out.outliers = flagged;
  const std::span<const double> y = gate > 0.0 ? std::span<const double>(yc) : y_raw;
  out.cfg = cfg0;
  EstimatorConfig& cfg = out.cfg;
  const bool search_r = uses_guesses(cfg.model) && std::isinf(cfg.guess_right);
  const bool search_l = uses_guesses(cfg.model) && std::isinf(cfg.guess_left);
  if (search_r || search_l) {
    const auto g = search_guesses(cfg, v, y, gap_rows);
    if (search_r) cfg.guess_right = g[0];
    if (search_l) cfg.guess_left = g[1];
  }
  // The edges each side's regression points at are read from the same run's final state (no second pass).
  out.run = run_estimator(cfg, v, y, keep_trace, [&](const AnyEstimator& est) {
    if (!uses_guesses(cfg.model)) return;
    out.right.edge = est.raw_edge(Side::right);
    out.left.edge = est.raw_edge(Side::left);
  }, gap_rows);
  if (uses_guesses(cfg.model)) {
    out.right.guess = cfg.guess_right;
    out.left.guess = cfg.guess_left;
    out.right.source = search_r ? GuessSource::searched : GuessSource::given;
    out.left.source = search_l ? GuessSource::searched : GuessSource::given;
    out.right.wrong_side = std::isfinite(out.right.edge) && out.right.edge >= cfg.guess_right;
    out.left.wrong_side = std::isfinite(out.left.edge) && out.left.edge <= cfg.guess_left;
  }
  return out;
}

std::array<double, 2> search_guesses(const EstimatorConfig& cfg0, std::span<const double> v,
                                     std::span<const double> y, std::span<const std::size_t> gap_rows) {
  if (!uses_guesses(cfg0.model)) return {kInf, -kInf};
  const DataTraits d = analyse_record(v, y, cfg0.dt_s);
  const double hi = std::max(d.v_hi, 0.0), lo = std::min(d.v_lo, 0.0);
  const double span = hi - lo;
  std::array<double, 2> g{0.7 * hi, 0.7 * lo};
  if (!(span > 0.0)) return {kInf, -kInf};
  EstimatorConfig cfg = cfg0;
  for (int pass = 0; pass < 5; ++pass) {
    cfg.guess_right = g[0] > 0.0 ? g[0] : kInf;
    cfg.guess_left = g[1] < 0.0 ? g[1] : -kInf;
    AnyEstimator est(cfg);
    step_through(est, v, y, 0, v.size(), gap_rows, [](std::size_t, const auto&) {});
    std::array<double, 2> next = g;
    for (int i = 0; i < 2; ++i) {
      const Side s = i == 0 ? Side::right : Side::left;
      const double ext = i == 0 ? hi : lo;   // the input's extreme on this side
      const double c = est.raw_edge(s);
      const double sg = i == 0 ? 1.0 : -1.0;  // outward
      if (!std::isfinite(c)) {
        next[i] = 0.5 * (g[i] + 0.0);       // no data beyond the guess: move it in
      } else if (sg * (c - g[i]) >= 0.0) {
        next[i] = 0.5 * (g[i] + ext);       // edge beyond the guess: the guess was inside the deadzone
      } else {
        const double cc = sg * c > 0.0 ? c : 0.0;  // an edge across zero means no deadzone there
        next[i] = cc + 0.15 * (ext - cc);
      }
    }
    const bool moved = std::fabs(next[0] - g[0]) > 0.01 * span || std::fabs(next[1] - g[1]) > 0.01 * span;
    g = next;
    if (!moved) break;
  }
  return {g[0] > 0.0 ? g[0] : kInf, g[1] < 0.0 ? g[1] : -kInf};
}

}  // namespace lash
