#include "lash/identify/auto.hpp"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "lash/identify/auto_gate.hpp"
#include "lash/identify/estimators.hpp"
#include "lash/io/order_statistic.hpp"

namespace lash {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

bool uses_guesses(ModelKind m) noexcept { return model_traits(m).uses_guesses; }

/// The sequences analyse_record takes quantiles of, over the finite pairs (v, y) in order, one
/// value at a time: the last 41 values of y sit in a ring.
struct Streams {
  double dt_s;
  std::array<double, 64> ring{};
  std::size_t k = 0;  // finite pairs seen
  /// f(index, value) for index 0 v, 1 y, 2 |Δ²y|, 3 |Δ₄₀y|/(40T), 4 |Δ²y|/T² (same-direction moves)
  template <class F>
  void push(double v, double y, F&& f) {
    ring[k & 63] = y;
    f(0, v);
    f(1, y);
    if (k >= 2) {
      const double y1 = ring[(k - 1) & 63], y2 = ring[(k - 2) & 63];
      f(2, std::fabs(y - 2.0 * y1 + y2));
      const double d1 = y - y1, d0 = y1 - y2;
      if (d1 * d0 > 0.0) f(4, std::fabs(d1 - d0) / (dt_s * dt_s));
    }
    if (k >= 40) f(3, std::fabs(y - ring[(k - 40) & 63]) / (40.0 * dt_s));
    ++k;
  }
};

using SwitchSide = EstimatorConfig::SwitchSide;
constexpr int kSwitchBudget = 80;  // runs after which no further start is tried

/// A side's raw estimate of a model-switched run (no estimate: a default SwitchSide, not usable).
SwitchSide raw_switch_side(const AnyEstimator& est, Side s) {
  const auto* e = est.get<DeadzoneDeadbandEstimator>();
  return e ? e->pooled_params(s) : SwitchSide{};
}

/// The model-switching iteration (docs/method.md §A4.4b): each run's switching model is the
/// previous run's estimate (an edge across zero taken as 0, a negative d as 0, |a1| at most
/// 0.999). A side whose estimate is not usable (too few updates, unstable) keeps its model; the
/// iteration goes on unless that side also had none in the run before (an input that never
/// drives a side). Stops when no parameter moved by more than kTol of its scale: a1 by
/// (1 − |a1|), b1 by |b1|, c by max(|c|, 10⁻³ of the input span), d by max(|d|, 10⁻³ of the
/// output span). After kDamp runs the step towards the new estimate shrinks (1/2, 1/3, …): a
/// selection that flips between two sample sets then settles between them. Returns the last
/// model; `rep` gets passes and convergence.
PerSide<SwitchSide> iterate_switching(const EstimatorConfig& mc0, const RecordColumns& rec,
                                      PerSide<SwitchSide> model, const DataTraits& d,
                                      std::span<const std::size_t> gap_rows, YEdits edits, SwitchingReport& rep) {
  constexpr int kMaxPasses = 40, kDamp = 10;
  constexpr double kTol = 2e-3, kMaxPole = 0.999;
  EstimatorConfig mc = mc0;
  const double vspan = std::max(d.v_hi - d.v_lo, 1e-300), yspan = std::max(d.y_span, 1e-300);
  rep.tried = true;
  PerSide<bool> had{true, true};  // the side had an estimate in the last run (the start counts)
  for (int pass = 1; pass <= kMaxPasses; ++pass) {
    mc.switch_model = model;
    AnyEstimator est(mc);
    step_through(est, rec, 0, rec.size(), gap_rows, [](std::size_t, double, const auto&) {}, edits);
    rep.passes = pass;
    bool moved = false;
    PerSide<SwitchSide> next = model;
    for (const Side s : {Side::right, Side::left}) {
      SwitchSide q = raw_switch_side(est, s);
      // an edge across zero or a negative d: the nearest physical value (a start far off gives
      // such a first estimate; the next runs move on from it)
      if (!verdict_rules::physical_edge(q.c, s)) q.c = 0.0;
      q.d = std::max(q.d, 0.0);
      q.a1 = std::clamp(q.a1, -kMaxPole, kMaxPole);  // an integrator-like first estimate: the slowest stable lag
      if (!(q.usable() && est.updates(s) >= mc.min_updates)) {
        // a side that lost its estimate has not converged; one that had none in two runs in a row
        // (the input never drives it) does not hold the other up
        moved = moved || had[s];
        had[s] = false;
        continue;
      }
      had[s] = true;
      SwitchSide& m = model[s];
      if (pass > kDamp) {  // steps of 1/2, 1/3, …: the model settles where the estimates centre
        const double g = 1.0 / static_cast<double>(pass - kDamp + 1);
        q = {m.a1 + g * (q.a1 - m.a1), m.b1 + g * (q.b1 - m.b1), m.c + g * (q.c - m.c), m.d + g * (q.d - m.d)};
      }
      moved = moved || std::fabs(q.a1 - m.a1) > kTol * (1.0 - std::fabs(m.a1)) ||
              std::fabs(q.b1 - m.b1) > kTol * std::fabs(m.b1) ||
              std::fabs(q.c - m.c) > kTol * std::max(std::fabs(m.c), 1e-3 * vspan) ||
              std::fabs(q.d - m.d) > kTol * std::max(std::fabs(m.d), 1e-3 * yspan);
      next[s] = q;
    }
    model = next;
    if (!moved) {
      rep.converged = true;
      break;
    }
  }
  return model;
}

/// The side's start taken from the ẏ result `r`, if it identified it with usable values.
std::optional<SwitchSide> start_from(const EstimateReport& r, Side s) {
  const SideParams& p = r[s].params;
  if (const SwitchSide q{p.a1, p.b1, p.c, std::max(p.d, 0.0)}; p.identified && q.usable()) return q;
  return std::nullopt;
}

/// Where the model-switching iteration starts: an identified side's values, else a first-order
/// lag of `lag` samples (a1 = −exp(−1/lag)), b1 = (1 + a1)·K with K = output span / input span,
/// c = 0.3 × the input's extreme on that side, d = 0 (docs/method.md §A4.4b).
PerSide<SwitchSide> switching_start(const EstimateReport& r, const DataTraits& d, double lag) {
  const double vspan = d.v_hi - d.v_lo;
  const double k = vspan > 0.0 && d.y_span > 0.0 ? d.y_span / vspan : 1.0;
  const double a1 = -std::exp(-1.0 / lag);
  PerSide<SwitchSide> m;
  for (const Side s : {Side::right, Side::left}) {
    if (const auto q = start_from(r, s))
      m[s] = *q;
    else
      m[s] = {a1, (1.0 + a1) * k, 0.3 * (s == Side::right ? std::max(d.v_hi, 0.0) : std::min(d.v_lo, 0.0)), 0.0};
  }
  return m;
}

int sides_identified(const EstimateReport& r) {
  return (r.right.params.identified ? 1 : 0) + (r.left.params.identified ? 1 : 0);
}

// The check of a ẏ result (§A4.4b): the model-switched estimate `m` lies further from the ẏ
// estimate than the width of its 95 % interval (twice the half-width) in some parameter of a side.
bool departs(const EstimateReport& m, const EstimateReport& ydot, const PerSide<SideIntervals>& ci) {
  for (const Side s : {Side::right, Side::left}) {
    const SideParams &a = m[s].params, &b = ydot[s].params;
    const SideIntervals& i = ci[s];
    for (const auto& [x, y, iv] : {std::tuple{a.a1, b.a1, i.a1}, std::tuple{a.b1, b.b1, i.b1},
                                   std::tuple{a.c, b.c, i.c}, std::tuple{a.d, b.d, i.d}})
      if (iv.valid() && !(std::fabs(x - y) <= iv.hi - iv.lo)) return true;
  }
  return false;
}

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

const char* to_string(SwitchTrigger t) noexcept {
  switch (t) {
    case SwitchTrigger::asked: return "asked";
    case SwitchTrigger::side_open: return "side_open";
    case SwitchTrigger::no_interval: return "no_interval";
    case SwitchTrigger::check: return "check";
    case SwitchTrigger::none: break;
  }
  return "none";
}

EstimatorConfig preset_config(ModelKind model, Preset preset, double dt_s) {
  return preset == Preset::thesis ? EstimatorConfig::thesis(model, dt_s) : EstimatorConfig(model, dt_s);
}

// The quantiles are exact (the value std::nth_element puts at rank ⌊q·(n − 1)⌋ of a full copy of
// the sequence), in memory bounded whatever the record's length: see OrderStatistic
// (io/order_statistic.hpp) and docs/identification.md ("Defaults chosen from the data").
DataTraits analyse_record(std::span<const double> v, std::span<const double> y, double dt_s, YEdits ed) {
  const std::size_t n = std::min(v.size(), y.size());
  return analyse_record(RecordColumns::of(v.first(n), y.first(n)), dt_s, ed);
}

DataTraits analyse_record(const RecordColumns& rec, double dt_s, YEdits ed) {
  DataTraits d;
  d.dt_s = dt_s;
  const std::size_t n = rec.size();
  // y as the estimators see it: y[i], or the edit's value at an edited row (by bisection; the
  // passes below walk the edits with a cursor instead); the rows of a window [k0, k0 + m) are read
  // into `win` (views of a record in memory)
  ChunkBuffer<2> win;
  const auto y_at = [&](std::size_t i, double yi) {
    const auto it = std::lower_bound(ed.rows.begin(), ed.rows.end(), i);
    return it != ed.rows.end() && *it == i ? ed.values[static_cast<std::size_t>(it - ed.rows.begin())] : yi;
  };
  constexpr std::size_t kNoEdit = static_cast<std::size_t>(-1);
  // The five sequences' quantiles (index of the sequence, q)
  constexpr std::array<std::pair<int, double>, 7> kQ{{{0, 0.001}, {0, 0.999}, {1, 0.001}, {1, 0.999},
                                                      {2, 0.5}, {3, 0.9}, {4, 0.9}}};
  auto sel = [&]<std::size_t... I>(std::index_sequence<I...>) {
    return std::array<OrderStatistic, sizeof...(I)>{OrderStatistic::quantile(kQ[I].second)...};
  }(std::make_index_sequence<kQ.size()>{});
  {
    // A sample of each sequence at up to kSample evenly spaced rows (rows with a non-finite
    // value are passed over: the sample only places the brackets, the pass decides)
    constexpr std::size_t kSample = 4096;
    std::array<std::vector<double>, 5> smp;
    if (n >= 4 * kSample) {
      // one row drawn in each of kSample equal strata (a fixed LCG: deterministic; random, so that
      // a periodic record cannot alias with the stride)
      std::uint64_t rng = 0x853c49e6748fea9bULL;
      const double stratum = static_cast<double>(n - 40) / static_cast<double>(kSample);
      for (std::size_t j = 0; j < kSample; ++j) {
        rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
        const double u = static_cast<double>(rng >> 11) * 0x1p-53;
        const std::size_t k = std::min(n - 1, 40 + static_cast<std::size_t>((static_cast<double>(j) + u) * stratum));
        const auto w = win.get(rec.store, rec.vy, k - 40, 41);
        const auto vw = w[0], yw = w[1];  // vw[i], yw[i]: row k − 40 + i
        bool ok = true;
        for (std::size_t i = 0; i <= 40; ++i) ok = ok && std::isfinite(vw[i]) && std::isfinite(y_at(k - 40 + i, yw[i]));
        if (!ok) continue;
        Streams s{dt_s};
        for (std::size_t i = 0; i <= 40; ++i)
          s.push(vw[i], y_at(k - 40 + i, yw[i]), [&](int idx, double x) {
            if (i == 40) smp[static_cast<std::size_t>(idx)].push_back(x);
          });
      }
    }
    for (std::size_t i = 0; i < kQ.size(); ++i) {
      auto s = smp[static_cast<std::size_t>(kQ[i].first)];
      sel[i].bracket(s, n);
    }
  }
  // One pass over the record in chunks that stay in the L1 cache: the finite pairs of a chunk,
  // the derived sequences, then each selection counts its sequence's chunk; and the smallest
  // nonzero step of y. The last 40 finite values of y lead the next chunk's (rates, differences).
  constexpr std::size_t kChunk = 1024, kLead = 40;
  std::vector<double> vb(kChunk), yb(kLead + kChunk), d2(kChunk), rate(kChunk), acc(kChunk);
  std::size_t n_steps = 0;
  double min_step = std::numeric_limits<double>::infinity(), step_scale = 0.0;
  const double rate_div = 40.0 * dt_s, acc_div = dt_s * dt_s;
  // the pass over the selections `active` (a bit per selection); returns the count of finite pairs
  const auto pass = [&](unsigned active, bool first) {
    std::size_t k = 0;  // finite pairs before the chunk
    std::size_t e = 0, next_edit = ed.rows.empty() ? kNoEdit : ed.rows[0];
    // the record in chunks of rows (views when in memory); r counts rows of the whole record
    for_chunks(rec.store, rec.vy, 0, n, [&](std::size_t base, const auto& cols) {
      const std::span<const double> v = cols[0], y = cols[1];
      const std::size_t n_rows = v.size();
      for (std::size_t r = 0; r < n_rows;) {
        std::size_t m = 0;
        for (; r < n_rows && m < kChunk; ++r) {
          double yr = y[r];
          if (base + r == next_edit) [[unlikely]] {
            yr = ed.values[e++];
            next_edit = e < ed.rows.size() ? ed.rows[e] : kNoEdit;
          }
          if (std::isfinite(v[r]) && std::isfinite(yr)) {
            vb[m] = v[r];
            yb[kLead + m] = yr;
            ++m;
          }
        }
        const double* yc = yb.data() + kLead;  // yc[j] = the (k + j)-th finite y; yc[-40..-1] the ones before
        // |Δ²y| from finite index 2, |Δ₄₀y|/(40T) from 40, |Δ²y|/T² where y moved the same way twice
        const std::size_t j2 = k >= 2 ? 0 : std::min(m, 2 - k), j40 = k >= 40 ? 0 : std::min(m, 40 - k);
        const std::size_t j1 = k >= 1 ? 0 : std::min<std::size_t>(m, 1);
        std::size_t n_acc = 0;
        for (std::size_t j = j2; j < m; ++j) {
          d2[j - j2] = std::fabs(yc[j] - 2.0 * yc[j - 1] + yc[j - 2]);
          const double e1 = yc[j] - yc[j - 1], e0 = yc[j - 1] - yc[j - 2];
          acc[n_acc] = std::fabs(e1 - e0) / acc_div;
          n_acc += e1 * e0 > 0.0 ? 1 : 0;
        }
        for (std::size_t j = j40; j < m; ++j) rate[j - j40] = std::fabs(yc[j] - yc[j - 40]) / rate_div;
        if (first) {  // in locals: kept in registers (the selections' add is in another file)
          std::size_t ns = n_steps;
          double ms = min_step, sc = step_scale;
          for (std::size_t j = j1; j < m; ++j) {
            const double st = quantum_step(yc[j - 1], yc[j], sc);
            ns += st > 0.0 ? 1 : 0;
            ms = st > 0.0 ? std::min(ms, st) : ms;
          }
          n_steps = ns;
          min_step = ms;
          step_scale = sc;
        }
        const std::array<std::pair<const double*, std::size_t>, 5> seq{
            {{vb.data(), m}, {yc, m}, {d2.data(), m - j2}, {rate.data(), m - j40}, {acc.data(), n_acc}}};
        for (std::size_t i = 0; i < kQ.size(); ++i) {
          if (!(active >> i & 1u)) continue;
          const auto& [x, len] = seq[static_cast<std::size_t>(kQ[i].first)];
          sel[i].add(x, len);
        }
        k += m;
        if (m > 0) {  // the last 40 finite values of y lead the next chunk
          const auto from = yb.begin() + static_cast<std::ptrdiff_t>(m);
          std::copy(from, from + static_cast<std::ptrdiff_t>(kLead), yb.begin());
        }
      }
    });
    return k;
  };
  const std::size_t k = pass(0x7Fu, true);
  d.samples = k;
  if (d.samples < 3) return d;
  // A selection whose first pass did not settle its quantile (the sample's bracket missed it, or
  // more values fell inside than its cap: io/order_statistic.hpp) takes further passes; those
  // that need one share it.
  for (unsigned active = 0x7Fu; active != 0;) {
    unsigned next = 0;
    for (std::size_t i = 0; i < kQ.size(); ++i)
      if ((active >> i & 1u) && sel[i].end_pass()) next |= 1u << i;
    active = next;
    if (active != 0) pass(active, false);
  }
  std::array<double, 7> val{};
  for (std::size_t i = 0; i < kQ.size(); ++i) val[i] = sel[i].value();
  d.v_lo = val[0];
  d.v_hi = val[1];
  d.y_span = val[3] - val[2];
  d.noise_sigma = val[4] / (0.6745 * std::sqrt(6.0));
  d.ydot_p90 = val[5];
  d.yddot_p90 = val[6];
  // quantised: the nonzero steps are integer multiples of the smallest one (99 % of them); the
  // count stops as soon as more than 1 % are off the grid
  if (n_steps > 10 && min_step > 0.0) {
    const double q = min_step;
    const std::size_t off_allowed = n_steps - n_steps * 99 / 100;
    std::size_t off = 0, seen = 0;
    double y_prev = 0.0, scale = 0.0;
    const std::size_t n_all = n;
    std::size_t e = 0, next_edit = ed.rows.empty() ? kNoEdit : ed.rows[0];
    for_chunks(rec.store, rec.vy, 0, n_all, [&](std::size_t base, const auto& cols) {
      const std::span<const double> v = cols[0], y = cols[1];
      for (std::size_t j = 0; j < v.size() && off <= off_allowed; ++j) {
        const std::size_t i = base + j;
        double yi = y[j];
        if (i == next_edit) [[unlikely]] {
          yi = ed.values[e++];
          next_edit = e < ed.rows.size() ? ed.rows[e] : kNoEdit;
        }
        if (!(std::isfinite(v[j]) && std::isfinite(yi))) continue;
        if (seen++ >= 1) {
          const double s = quantum_step(y_prev, yi, scale);
          if (s > 0.0) off += std::fabs(s / q - std::round(s / q)) < 1e-3 ? 0u : 1u;
        }
        y_prev = yi;
      }
    });
    if (off <= off_allowed) d.quantum = q;
  }
  return d;
}

// Each model's choices are its policy's tune() (identify/models/; E3–E5: docs/method.md §A7).
void tune_to_data(EstimatorConfig& c, const DataTraits& d) {
  c.dt_s = d.dt_s > 0.0 ? d.dt_s : c.dt_s;
  with_model(c.model, [&]<class Model>() { Model::tune(c, d); });  // identify/models/
}

void gate_outliers(std::span<const double> y, double gate, std::vector<std::size_t>& rows,
                   std::vector<double>& values) {
  gate_outliers(RecordColumns::of(y, y), gate, rows, values);
}

void gate_outliers(const RecordColumns& rec, double gate, std::vector<std::size_t>& rows,
                   std::vector<double>& values) {
  if (!(gate > 0.0)) return;
  OutlierGateConfig gc;
  gc.gate = gate;
  OutlierGate gate_y(gc);
  // A flagged sample is decided when its successor is read: one sample is held back across chunks.
  bool held = false;
  std::size_t held_k = 0;
  double held_y = 0.0, held_g = 0.0;
  const auto decide = [&](double next) {
    if (std::fabs(next - held_y) < std::fabs(next - held_g)) return;  // a true step: y[k] stays
    rows.push_back(held_k);
    values.push_back(held_g);
  };
  for_chunks(rec.store, std::array<std::size_t, 1>{rec.vy[1]}, 0, rec.size(), [&](std::size_t base, const auto& c) {
    const std::span<const double> y = c[0];
    for (std::size_t j = 0; j < y.size(); ++j) {
      if (held) {
        decide(y[j]);
        held = false;
      }
      const std::uint64_t before = gate_y.rejected();
      const double g = gate_y.step(y[j]);
      if (gate_y.rejected() == before) continue;  // accepted: g is y[k]
      held = true;
      held_k = base + j;
      held_y = y[j];
      held_g = g;
    }
  });
  if (held) decide(held_g);  // the last sample: no successor (compared with itself: replaced)
}

AutoRun estimate_auto(const EstimatorConfig& cfg0, std::span<const double> v, std::span<const double> y,
                      const AutoOptions& o) {
  return estimate_auto(cfg0, RecordColumns::of(v, y), o);
}

AutoRun estimate_auto(const EstimatorConfig& cfg0, const RecordColumns& rec, const AutoOptions& o) {
  AutoRun out;
  // The gate is causal (usable online); over a whole record the sample after a flagged one is also
  // known: when it lies nearer the flagged value than the last accepted one, the output really
  // stepped there (a square-wave input) and the sample is kept. gate 0 = off: y is used as is.
  // The replaced samples are kept apart from y (YEdits): no copy of the record.
  std::vector<std::size_t> edit_rows;
  std::vector<double> edit_values;
  gate_outliers(rec, o.gate, edit_rows, edit_values);
  out.outliers = edit_rows.size();
  const YEdits edits{edit_rows, edit_values};
  out.cfg = cfg0;
  EstimatorConfig& cfg = out.cfg;
  // model switching asked for: the ẏ switching's runs (the guess search, the first run) come first
  const bool forced = cfg.model == ModelKind::deadzone_deadband && cfg.model_switching;
  cfg.model_switching = false;
  const bool search_r = uses_guesses(cfg.model) && std::isinf(cfg.guess_right);
  const bool search_l = uses_guesses(cfg.model) && std::isinf(cfg.guess_left);
  if (search_r || search_l) {
    const auto g = search_guesses(cfg, rec, o.gap_rows, edits,
                                  edit_rows.empty() && o.traits && o.traits->dt_s == cfg.dt_s ? o.traits : nullptr);
    if (search_r) cfg.guess_right = g[0];
    if (search_l) cfg.guess_left = g[1];
  }
  // The edges each side's regression points at are read from the same run's final state (no second pass).
  RunOptions ro;
  ro.keep_trace = o.keep_trace;
  ro.keep_outputs = o.keep_outputs;
  ro.gap_rows = o.gap_rows;
  ro.y_edits = edits;
  ro.score_begin = o.score_begin;
  ro.score_end = o.score_end;
  ro.on_step = o.on_step;
  ro.at_end = [&](const AnyEstimator& est) {
    if (!uses_guesses(cfg.model)) return;
    out.right.edge = est.raw_edge(Side::right);
    out.left.edge = est.raw_edge(Side::left);
  };
  const bool can_switch = cfg.model == ModelKind::deadzone_deadband && cfg.pooled;
  if (!can_switch) {
    out.run = run_estimator(cfg, rec, ro);
  } else {
    // First the ẏ switching; model switching when it leaves a side unidentified, when its
    // estimate has no batch-means interval (below), or when asked for. A trace streamed as it
    // goes (on_step) cannot be taken back: then the first runs keep nothing per sample and the
    // final run is done again with everything; kept outputs and traces are kept by every run and
    // the adopted one is used as it is.
    const EstimatorConfig dcfg = cfg;
    RunOptions probe = ro;
    probe.keep_trace = probe.keep_outputs = false;
    probe.on_step = nullptr;
    const bool streams = static_cast<bool>(ro.on_step);
    EstimationRun direct = run_estimator(dcfg, rec, streams ? probe : ro);
    bool use_model = false;
    // given guesses are the user's switching: kept (a wrong one is reported as such)
    const bool given = std::isfinite(cfg0.guess_right) || std::isfinite(cfg0.guess_left);
    // both sides identified by the ẏ switching: model switching checks the result (§A4.4b) --
    // `no_interval` when batch means cannot reproduce a side (fewer than 5 of 10 sections
    // identify it: the estimate rests on few selected samples, where the ẏ selection's bias
    // shows), `check` otherwise
    std::optional<PerSide<SideIntervals>> direct_ci;  // kept: the report's intervals when the ẏ result stays
    const auto unconfirmed = [&] {
      IntervalSettings is;
      is.gap_rows = o.gap_rows;
      direct_ci = batch_means_intervals(dcfg, rec, {direct.report.right.params, direct.report.left.params}, is);
      return !(direct_ci->right.a1.valid() && direct_ci->left.a1.valid());
    };
    const int direct_sides = sides_identified(direct.report);
    const SwitchTrigger trigger = forced             ? SwitchTrigger::asked
                                  : given            ? SwitchTrigger::none
                                  : direct_sides < 2 ? SwitchTrigger::side_open
                                  : unconfirmed()    ? SwitchTrigger::no_interval
                                                     : SwitchTrigger::check;
    if (trigger != SwitchTrigger::none) {
      out.switching.trigger = trigger;
      const DataTraits d = edit_rows.empty() && o.traits && o.traits->dt_s == cfg.dt_s
                               ? *o.traits
                               : analyse_record(rec, cfg.dt_s, edits);
      EstimatorConfig mc = cfg;
      mc.model_switching = true;
      mc.method = EstimationMethod::iv;  // the instrument is the switching model's output
      mc.noise = NoiseSettings{};        // raw v and y: the instrument, not a filter, handles the noise
      mc.guess_right = kInf;
      mc.guess_left = -kInf;
      // starts with lags of 10, 100, 30 and 300 samples on the sides the ẏ switching left open,
      // until a converged iteration identifies both sides; else the one that identifies most
      std::optional<EstimationRun> best;
      PerSide<SwitchSide> best_model{};
      // both sides start from the ẏ result: every lag gives the same start, and the same run
      const bool one_start = start_from(direct.report, Side::right) && start_from(direct.report, Side::left);
      for (const double lag : {10.0, 100.0, 30.0, 300.0}) {
        if (out.switching.passes >= kSwitchBudget) break;  // a long record: at most 80 + 40 runs
        SwitchingReport rep;
        mc.switch_model =
            iterate_switching(mc, rec, switching_start(direct.report, d, lag), d, o.gap_rows, edits, rep);
        out.switching.passes += rep.passes;
        ++out.switching.starts;
        if (rep.converged) {
          out.switching.converged = true;
          RunOptions mro = streams ? probe : ro;  // kept outputs are kept here: no rerun if adopted
          mro.at_end = nullptr;                   // its edges are not guesses' evidence
          EstimationRun m = run_estimator(mc, rec, mro);
          if (!best || sides_identified(m.report) > sides_identified(best->report)) {
            best = std::move(m);
            best_model = mc.switch_model;
          }
          if (sides_identified(best->report) == 2) break;
        }
        if (one_start) break;  // converged or not, another lag would repeat this iteration
      }
      out.switching.tried = true;
      // adopted: asked for; identifies more sides; or, checking a ẏ result, identifies both (and,
      // for a ẏ result with intervals, departs from it by more than their width or fits better)
      use_model = best && (forced || sides_identified(best->report) > direct_sides ||
                           (sides_identified(best->report) == 2 &&
                            (trigger == SwitchTrigger::no_interval || departs(best->report, direct.report, *direct_ci) ||
                             best->report.fit_nrmse < direct.report.fit_nrmse)));
      if (use_model) {
        mc.switch_model = best_model;
        cfg = mc;
        RunOptions mro = ro;
        mro.at_end = nullptr;
        out.run = streams ? run_estimator(mc, rec, mro) : std::move(*best);
      }
    }
    out.switching.used = use_model;
    if (!use_model) {
      out.ci95 = direct_ci;
      cfg = dcfg;
      out.run = streams ? run_estimator(dcfg, rec, ro) : std::move(direct);
    }
  }
  out.settings = out.switching.used ? cfg0 : cfg;
  if (out.switching.used) {
    out.right.edge = out.left.edge = detail::kNaN;
  } else if (uses_guesses(cfg.model)) {
    for (const auto& [s, searched] : {std::pair{Side::right, search_r}, std::pair{Side::left, search_l}}) {
      GuessReport& g = out.guess(s);
      g.guess = cfg.guess(s);
      g.source = searched ? GuessSource::searched : GuessSource::given;
      g.judge(s);
    }
  }
  return out;
}

AutoRun estimate_auto(const EstimatorConfig& cfg, std::span<const double> v, std::span<const double> y,
                      bool keep_trace, double gate, std::span<const std::size_t> gap_rows) {
  AutoOptions o;
  o.keep_trace = keep_trace;
  o.gate = gate;
  o.gap_rows = gap_rows;
  return estimate_auto(cfg, v, y, o);
}

std::array<double, 2> search_guesses(const EstimatorConfig& cfg0, std::span<const double> v,
                                     std::span<const double> y, std::span<const std::size_t> gap_rows,
                                     YEdits edits, const DataTraits* traits) {
  const std::size_t n = std::min(v.size(), y.size());
  return search_guesses(cfg0, RecordColumns::of(v.first(n), y.first(n)), gap_rows, edits, traits);
}

std::array<double, 2> search_guesses(const EstimatorConfig& cfg0, const RecordColumns& rec,
                                     std::span<const std::size_t> gap_rows, YEdits edits, const DataTraits* traits) {
  if (!uses_guesses(cfg0.model)) return {kInf, -kInf};
  const DataTraits d = traits ? *traits : analyse_record(rec, cfg0.dt_s, edits);
  const double hi = std::max(d.v_hi, 0.0), lo = std::min(d.v_lo, 0.0);
  const double span = hi - lo;
  std::array<double, 2> g{0.7 * hi, 0.7 * lo};
  if (!(span > 0.0)) return {kInf, -kInf};
  EstimatorConfig cfg = cfg0;
  for (int pass = 0; pass < 5; ++pass) {
    cfg.guess_right = g[0] > 0.0 ? g[0] : kInf;
    cfg.guess_left = g[1] < 0.0 ? g[1] : -kInf;
    AnyEstimator est(cfg);
    step_through(est, rec, 0, rec.size(), gap_rows, [](std::size_t, double, const auto&) {}, edits);
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
