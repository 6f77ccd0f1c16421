#include "lash/monitor/events.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

namespace lash::monitor {

namespace {

const std::set<std::string>& known_params() {
  static const std::set<std::string> k{"c_r", "c_l", "d_r", "d_l", "K_r", "K_l", "tau_s_r", "tau_s_l",
                                       "K", "tau_s", "d"};
  return k;
}

/// `d_right` → `d_r`, `tau_s_left` → `tau_s_l`.
std::string canonical(std::string p) {
  for (const auto& [long_sfx, short_sfx] : {std::pair{"_right", "_r"}, std::pair{"_left", "_l"}}) {
    const std::string l(long_sfx);
    if (p.size() > l.size() && p.compare(p.size() - l.size(), l.size(), l) == 0)
      return p.substr(0, p.size() - l.size()) + short_sfx;
  }
  return p;
}

/// A warm-up key (`[alarms]` or `[drift]` `warmup_s`) [s]: `fallback` when absent; InputError
/// naming it unless finite and ≥ 0.
double read_warmup(TomlTable& t, double fallback) {
  const double v = t.number_or("warmup_s", fallback);
  if (!(v >= 0) || !std::isfinite(v)) t.fail("warmup_s", "must be finite and >= 0");
  return v;
}
}  // namespace

AlarmSettings read_alarm_settings(TomlTable& t) {
  AlarmSettings s;
  if (t.has("alarms")) {
    const toml::table* raw = t.node("alarms")->as_table();
    if (!raw) t.fail("alarms", "must be a table");
    std::optional<TomlTable> a(std::in_place, *raw, t.file(), t.path("alarms"));
    std::map<std::string, Threshold> by;
    for (const auto& [key, node] : *raw) {
      const std::string k(key.str());
      if (k == "warmup_s") {
        s.warmup_s = read_warmup(*a, s.warmup_s);
        continue;
      }
      const bool is_max = k.size() > 4 && k.compare(k.size() - 4, 4, "_max") == 0;
      const bool is_min = k.size() > 4 && k.compare(k.size() - 4, 4, "_min") == 0;
      const std::string p = canonical(k.substr(0, k.size() >= 4 ? k.size() - 4 : 0));
      if ((!is_max && !is_min) || !known_params().count(p))
        a->fail(k, "expected warmup_s, or <parameter>_max or <parameter>_min with a parameter of c_r, c_l, d_r, d_l, "
                   "K_r, K_l, tau_s_r, tau_s_l, K, tau_s, d (right/left for r/l)");
      const double v = a->number(k);
      if (!std::isfinite(v)) a->fail(k, "must be finite");
      auto& th = by[p];
      th.param = p;
      (is_max ? th.max : th.min) = v;
    }
    for (auto& [p, th] : by) {
      if (!(th.min < th.max)) a->fail(p + "_min", "must be below " + p + "_max");
      s.thresholds.push_back(th);
    }
    a->finish();
  }
  if (auto d = t.table_opt("drift")) {
    if (auto b = d->boolean_opt("enabled")) s.drift.enabled = *b;
    s.drift.delta = d->number_or("delta", s.drift.delta);
    s.drift.threshold = d->number_or("threshold", s.drift.threshold);
    s.drift.warmup_s = read_warmup(*d, s.drift.warmup_s);
    if (d->has("median")) {
      const double m = d->number("median");
      if (!(m >= 1 && m <= static_cast<double>(DriftSettings::kMaxMedian)) || m != std::floor(m))
        d->fail("median", "must be an integer from 1 to " + std::to_string(DriftSettings::kMaxMedian));
      s.drift.median = static_cast<std::size_t>(m);
    }
    if (auto ps = d->strings_opt("parameters")) {
      s.drift.parameters.clear();
      for (const auto& p : *ps) {
        if (!known_params().count(canonical(p))) d->fail("parameters", "not a parameter: '" + p + "'");
        s.drift.parameters.push_back(canonical(p));
      }
    }
    try {
      PageHinkleySettings{s.drift.delta, s.drift.threshold}.validate();
    } catch (const std::invalid_argument& e) {
      d->fail(std::string(e.what()).rfind("delta", 0) == 0 ? "delta" : "threshold", e.what());
    }
    d->finish();
  }
  return s;
}

std::vector<ParamValue> monitored_params(const EstimateReport& r) {
  std::vector<ParamValue> out;
  const auto put = [&](const std::string& name, double v, const Interval& iv, const SideParams& sp) {
    ParamValue p;
    p.name = name;
    p.value = v;
    p.identified = sp.identified && std::isfinite(v);
    p.watched = (sp.identified || sp.reason == Reason::uncertain) && std::isfinite(v);
    if (iv.valid()) {
      p.lo = iv.lo;
      p.hi = iv.hi;
    }
    out.push_back(p);
  };
  if (r.model == ModelKind::linear) {
    put("K", r.right.K, r.right.ci95.K, r.right.params);
    put("tau_s", r.right.tau_s, r.right.ci95.tau_s, r.right.params);
    return out;
  }
  for (const auto& [sfx, s] : {std::pair{"_r", &r.right}, std::pair{"_l", &r.left}}) {
    if (r.has_c) put(std::string("c") + sfx, s->params.c, s->ci95.c, s->params);
    if (r.has_side_d) put(std::string("d") + sfx, s->params.d, s->ci95.d, s->params);
    put(std::string("K") + sfx, s->K, s->ci95.K, s->params);
    put(std::string("tau_s") + sfx, s->tau_s, s->ci95.tau_s, s->params);
  }
  if (r.has_shared_d) {
    SideParams dp;
    dp.reason = r.d_reason;
    dp.identified = r.d_reason == Reason::none;
    put("d", r.d, r.right.ci95.d, dp);
  }
  return out;
}

EventDetector::EventDetector(const AlarmSettings& s) : s_(s) {}

void EventDetector::update(double t, const std::vector<ParamValue>& params, std::vector<Event>& out) {
  if (!have_t0_) {
    have_t0_ = true;
    t0_ = t;
  }
  for (const ParamValue& p : params) {
    if (!p.watched) continue;
    auto it = tracks_.find(p.name);
    if (it == tracks_.end())
      it = tracks_.emplace(p.name, Track{false, 1.0, PageHinkley({s_.drift.delta, s_.drift.threshold}), false,
                                         std::numeric_limits<double>::quiet_NaN(), {}, 0})
               .first;
    Track& tr = it->second;
    for (const Threshold& th : s_.thresholds) {
      if (th.param != p.name || t - t0_ < s_.warmup_s) continue;  // armed after the warm-up
      const bool outside = p.value > th.max || p.value < th.min;
      if (outside && !tr.outside) out.push_back({t, "threshold", p.name, tr.last, p.value});
      tr.outside = outside;
    }
    const auto& watch = s_.drift.parameters;
    if (s_.drift.enabled && t - t0_ >= s_.drift.warmup_s &&
        std::find(watch.begin(), watch.end(), p.name) != watch.end()) {
      if (!tr.started) {
        tr.started = true;
        tr.scale = std::max(std::abs(p.value), 1e-12);
      }
      const std::size_t len = s_.drift.median;
      tr.recent[tr.n_recent++ % len] = p.value;
      std::array<double, DriftSettings::kMaxMedian> m = tr.recent;
      const std::size_t k = std::min(tr.n_recent, len);
      std::nth_element(m.begin(), m.begin() + static_cast<std::ptrdiff_t>(k / 2), m.begin() + static_cast<std::ptrdiff_t>(k));
      const auto c = tr.ph.update(m[k / 2] / tr.scale);
      if (c != PageHinkley::Change::none) {
        out.push_back({t, "drift", p.name, tr.ph.mean_before(c) * tr.scale, p.value});
        tr.ph.reset();
        tr.scale = std::max(std::abs(p.value), 1e-12);
        tr.n_recent = 0;
      }
    }
    tr.last = p.value;
  }
}

}  // namespace lash::monitor
