#include "lash/monitor/monitor.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>

#include "lash/can/dbc.hpp"
#include "lash/identify/estimate.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/io/table.hpp"
#include "lash/monitor/signal_map.hpp"
#include "lash/monitor/source.hpp"

namespace lash::monitor {

void apply_monitor_config(const std::string& path, MonitorSettings& s) {
  apply_monitor_table(parse_toml_file(path), path, s);
}

void apply_monitor_table(const toml::table& file, const std::string& path, MonitorSettings& s) {
  TomlTable t(file, path);
  s.alarms = read_alarm_settings(t);
  auto keys = std::make_shared<toml::table>(file);
  keys->erase("alarms");
  keys->erase("drift");
  if (auto m = t.string_opt("model")) {
    if (!s.estimator.model) {
      try {
        s.estimator.model = parse_model_kind(*m);
      } catch (const std::invalid_argument& e) {
        t.fail("model", e.what());
      }
    }
    keys->erase("model");
  }
  if (auto p = t.string_opt("preset")) {
    if (!s.estimator.preset) {
      try {
        s.estimator.preset = parse_preset(*p);
      } catch (const std::invalid_argument& e) {
        t.fail("preset", e.what());
      }
    }
    keys->erase("preset");
  }
  s.estimator_keys = keys;
  s.estimator.keys = keys.get();
}

EstimateMode parse_estimate_mode(const std::string& name) {
  if (name == "online") return EstimateMode::online;
  if (name == "window") return EstimateMode::window;
  throw std::invalid_argument("unknown estimate mode '" + name + "' (expected online or window)");
}

namespace {

void check_positive(double x, const char* field, bool zero_ok) {
  if (!std::isfinite(x) || x < 0 || (!zero_ok && x == 0))
    throw InputError("", 0, field, std::string("must be finite and ") + (zero_ok ? ">= 0" : "> 0"));
}

can::dbc::Database load_dbc_quiet(const std::string& path) {
  std::vector<can::dbc::Diagnostic> diags;
  return can::dbc::load_dbc(path, {}, &diags);
}

std::string estimate_line(double t, const std::string& json) {
  return "{\"t\":" + format_double(t) + "," + json.substr(1);
}

std::string number_or_null(double x) { return std::isfinite(x) ? format_double(x) : "null"; }

std::string event_line(const Event& e) {
  std::string s = "{\"t\":" + format_double(e.t) + ",\"event\":\"" + e.kind + "\"";
  if (!e.param.empty())
    s += ",\"parameter\":\"" + e.param + "\",\"before\":" + number_or_null(e.before) +
         ",\"after\":" + number_or_null(e.after);
  return s + "}";
}

/// The monitor's estimator settings: its periods follow a drift (no whole-window output-error
/// refinement unless asked, SettingsSources::follows_drift).
SettingsSources following(SettingsSources s) {
  s.follows_drift = true;
  return s;
}

/// The pipeline's state between frames.
class Pipeline {
 public:
  Pipeline(const MonitorSettings& s, SignalMap map)
      : s_(s), est_(following(s.estimator)), map_(std::move(map)), detector_(s.alarms) {
    if (s.mode == EstimateMode::online) online_.emplace(est_, s.online);
    if (!s.record_csv.empty()) {
      record_.open(s.record_csv, std::ios::out | std::ios::trunc);
      if (!record_) throw InputError(s.record_csv, 0, "--record", "cannot write the file");
      record_ << "t,v,y\n";
    }
    if (s.jsonl == "-") {
      jsonl_ = stdout;
    } else if (!s.jsonl.empty()) {
      jsonl_ = std::fopen(s.jsonl.c_str(), "w");
      if (!jsonl_) throw InputError(s.jsonl, 0, "--jsonl", "cannot write the file");
    }
  }
  ~Pipeline() {
    if (jsonl_ && jsonl_ != stdout) std::fclose(jsonl_);
  }
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  void open_db(double t0_unix_s) {
    if (s_.db.empty()) return;
    std::map<std::string, std::string> meta{{"source", s_.source},
                                            {"dbc", s_.dbc},
                                            {"v", s_.v},
                                            {"y", s_.y},
                                            {"every_s", format_double(s_.every_s)},
                                            {"t0_unix_s", format_double(t0_unix_s)}};
    if (s_.estimator.model) meta["model"] = to_string(*s_.estimator.model);
    db_.emplace(s_.db, meta);
  }

  /// One frame from the source. Returns false when the run should stop (duration, alarm).
  bool frame(const can::Frame& f, const PeriodCallback& cb) {
    ++counts_.frames;
    const double v_before = map_.v(), y_before = map_.y();
    bool is_y = false, jump = false;
    // after a silence the counters start over (the first frame is not a jump)
    if (have_frame_ && f.timestamp_s - last_frame_ts_ > s_.stale_timeout_s) map_.forget_counters();
    const FrameCheck c = map_.decode(f, is_y, jump);
    switch (c) {
      case FrameCheck::other: ++counts_.other; return true;
      case FrameCheck::bad_dlc: ++counts_.bad_dlc; return true;
      case FrameCheck::out_of_range: ++counts_.out_of_range; return true;
      case FrameCheck::ok: break;
    }
    const double ts = f.timestamp_s;
    if (have_frame_ && ts - last_frame_ts_ > s_.stale_timeout_s) silence(ts);
    have_frame_ = true;
    last_frame_ts_ = std::max(last_frame_ts_, ts);
    stale_now_ = false;
    if (jump) ++counts_.counter_jumps;
    if (jump && (!is_y || s_.dt_s > 0)) restart_pending_ = true;
    if (s_.dt_s > 0) {
      if (std::isfinite(v_before) && std::isfinite(y_before) && have_grid_) {
        while (grid_time() < ts)
          if (!sample(grid_time(), v_before, y_before, cb)) return false; else ++grid_k_;
      }
      if (!have_grid_ && std::isfinite(map_.v()) && std::isfinite(map_.y())) {
        have_grid_ = true;
        grid_t0_ = ts;
        grid_k_ = 0;
      }
      return true;
    }
    if (!is_y) return true;
    // y(k) is paired with the command sent in response to it: the latest v before y(k+1)
    bool go = true;
    if (have_pending_ && std::isfinite(v_before)) go = sample(pending_t_, v_before, pending_y_, cb);
    if (jump) restart_pending_ = true;  // y's own counter jumped: the restart is at this y
    have_pending_ = std::isfinite(map_.y());
    pending_t_ = ts;
    pending_y_ = map_.y();
    return go;
  }

  /// A live bus said nothing for a while: stale once the timeout has passed.
  void idle(double now_s) {
    if (have_frame_ && !stale_now_ && now_s - last_frame_ts_ > s_.stale_timeout_s) {
      stale_now_ = true;
      ++counts_.stale;
      restart_pending_ = true;
      map_.forget_counters();
      pending_events_.push_back({rel(last_frame_ts_ + s_.stale_timeout_s), "stale", "", NAN, NAN});
    }
  }

  /// End of the run: the period in progress, then the final estimate of every sample.
  void finish(const PeriodCallback& cb) {
    if (have_pending_ && s_.dt_s <= 0 && std::isfinite(map_.v()) && !stopped_)
      sample(pending_t_, map_.v(), pending_y_, cb);  // the last y with the latest v
    have_pending_ = false;
    if (!t_.empty() && (counts_.samples != last_snapshot_total_ || !pending_events_.empty()))
      snapshot(t_.back(), "final", cb);
    if (record_.is_open()) record_.flush();
    if (db_) {
      const auto& c = counts_;
      std::map<std::string, std::string> m;
      for (const auto& [k, v] : {std::pair{"frames", c.frames}, {"other", c.other}, {"samples", c.samples},
                                 {"garbage", c.garbage}, {"bad_dlc", c.bad_dlc}, {"out_of_range", c.out_of_range},
                                 {"counter_jumps", c.counter_jumps}, {"stale", c.stale}, {"time_back", c.time_back},
                                 {"gaps", c.gaps}, {"restarts", c.restarts}, {"reguesses", c.reguesses},
                                 {"bus_dropped", c.bus_dropped},
                                 {"periods", c.periods}, {"events", c.events}})
        m[std::string("count_") + k] = std::to_string(v);
      db_->set_meta(m);
      db_->close();
    }
  }

  MonitorCounts& counts() noexcept { return counts_; }
  const std::string& last_json() const noexcept { return last_json_; }
  bool alarm() const noexcept { return alarm_; }
  double t_end() const noexcept { return t_.empty() ? 0.0 : t_.back(); }
  double t0() const noexcept { return t0_; }
  bool started() const noexcept { return have_t0_; }

 private:
  double grid_time() const noexcept { return grid_t0_ + static_cast<double>(grid_k_) * s_.dt_s; }
  double rel(double ts) const noexcept { return have_t0_ ? ts - t0_ : 0.0; }

  void silence(double ts) {
    if (!stale_now_) {
      ++counts_.stale;
      pending_events_.push_back({rel(last_frame_ts_ + s_.stale_timeout_s), "stale", "", NAN, NAN});
    }
    pending_events_.push_back({rel(ts), "resumed", "", NAN, NAN});
    restart_pending_ = true;
    have_pending_ = false;  // the last y before the silence: the command that answered it is unknown
    map_.forget_counters();
    if (s_.dt_s > 0 && have_grid_) {  // no samples made up over the silence: the grid goes on after it
      const double k = std::ceil((ts - grid_t0_) / s_.dt_s);
      grid_k_ = std::max(grid_k_, static_cast<std::uint64_t>(k));
    }
  }

  bool sample(double ts, double v, double y, const PeriodCallback& cb) {
    if (!have_t0_) {
      have_t0_ = true;
      t0_ = ts;
      next_period_ = s_.every_s;  // periods end at k·every_s, k >= 1
      open_db(ts);
    }
    const double t = ts - t0_;
    if (!t_.empty() && !(t > t_.back())) {
      ++counts_.time_back;
      return true;
    }
    if (s_.duration_s > 0 && t > s_.duration_s) return !(stopped_ = true);
    if (t > next_period_) {
      if (!t_.empty()) snapshot(next_period_, stale_now_ ? "stale" : "ok", cb);
      next_period_ = (std::floor(t / s_.every_s) + 1.0) * s_.every_s;
      if (alarm_ && s_.until_alarm) return !(stopped_ = true);
    }
    const bool restart = restart_pending_ && !t_.empty();
    if (restart) extra_gaps_.push_back(t_.size());
    restart_pending_ = false;
    t_.push_back(t);
    v_.push_back(v);
    y_.push_back(y);
    if (online_) online_->add(t, v, y, restart);
    ++counts_.samples;
    if (s_.on_sample) s_.on_sample(t, v, y);  // the console's observer (monitor.hpp)
    if (record_.is_open()) record_ << format_double(t) << ',' << format_double(v) << ',' << format_double(y) << '\n';
    // bounded memory: once the kept samples span 2 windows, those before the last window go
    // (amortised O(1) per sample: each sample is moved at most once)
    if (s_.window_s > 0 && t - t_.front() > 2 * s_.window_s) trim(t - s_.window_s);
    return true;
  }

  /// Drops the samples at or before `t_from` (window_s), keeping the restart rows aligned.
  void trim(double t_from) {
    const auto n = static_cast<std::size_t>(std::upper_bound(t_.begin(), t_.end(), t_from) - t_.begin());
    t_.erase(t_.begin(), t_.begin() + static_cast<std::ptrdiff_t>(n));
    v_.erase(v_.begin(), v_.begin() + static_cast<std::ptrdiff_t>(n));
    y_.erase(y_.begin(), y_.begin() + static_cast<std::ptrdiff_t>(n));
    std::vector<std::size_t> kept;
    for (const std::size_t r : extra_gaps_)
      if (r > n) kept.push_back(r - n);
    extra_gaps_ = std::move(kept);
    trimmed_ += n;
  }

  void snapshot(double t, const std::string& status, const PeriodCallback& cb) {
    Period p;
    p.t = t;
    p.status = status;
    // the samples up to t (the period's end; the final snapshot: the last sample's time) and,
    // with a window S, after t - S: T - S < t_k <= T
    const auto n = static_cast<std::size_t>(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin());
    const std::size_t b =
        s_.window_s > 0
            ? static_cast<std::size_t>(std::upper_bound(t_.begin(), t_.begin() + static_cast<std::ptrdiff_t>(n),
                                                        t - s_.window_s) - t_.begin())
            : 0;
    const std::size_t m = n - b;
    p.samples = m;
    last_snapshot_total_ = trimmed_ + n;
    const double t_from = last_period_t_;
    last_period_t_ = t;
    const bool online_period = online_ && status != "final" && online_->ready();
    if (online_period) {
      // the persistent estimator's state now: O(1) whatever the window (online.hpp)
      auto snap = online_->snapshot(t_from, t);
      p.json = std::move(snap->json);
      p.params = monitored_params(snap->report);
      p.samples = trimmed_ + n;  // the samples received up to T (the estimator has stepped all but
                                 // the last, held for the outlier gate's look-ahead: the JSON's samples)
    } else if (m >= 3) {
      // the window's estimate from scratch: mode window, the final estimate, and (online) the
      // periods of the first online.init_s seconds, before the settings are chosen
      const std::span<const double> tt(t_.data() + b, m), vv(v_.data() + b, m), yy(y_.data() + b, m);
      Sampling smp = analyse_sampling(tt);
      if (!online_) {
        for (const std::size_t r : smp.gap_rows)  // gaps counted once over the run (windows overlap)
          if (trimmed_ + b + r > last_gap_row_) {
            ++counts_.gaps;
            last_gap_row_ = trimmed_ + b + r;
          }
      }
      if (!extra_gaps_.empty()) {
        for (const std::size_t r : extra_gaps_)
          if (r > b && r < n) smp.gap_rows.push_back(r - b);
        std::sort(smp.gap_rows.begin(), smp.gap_rows.end());
        smp.gap_rows.erase(std::unique(smp.gap_rows.begin(), smp.gap_rows.end()), smp.gap_rows.end());
      }
      if (!online_) counts_.restarts = smp.gap_rows.size();
      ArrayEstimateOptions eo;
      eo.sampling = &smp;
      try {
        const ArrayEstimate e = estimate_arrays(est_, tt, vv, yy, eo);
        p.json = e.json;
        p.params = monitored_params(e.run.run.report);
      } catch (const InputError&) {
        p.status = "warming_up";  // too few samples for the settings chosen from the data
      } catch (const std::invalid_argument&) {
        p.status = "warming_up";
      }
    } else {
      p.status = "warming_up";
    }
    if (online_) {
      counts_.gaps = online_->gaps();
      counts_.restarts = online_->restarts();
      counts_.reguesses = online_->reguesses(Side::right) + online_->reguesses(Side::left);
    }
    // online: the final estimate (over the window, from scratch) is another estimator than the
    // periods'; the detector follows the periods' only
    // online: the detector follows the persistent estimator's periods only (not the window
    // estimates of the first init_s seconds nor the final one: other estimators, other levels)
    if (!p.params.empty() && !(online_ && !online_period)) detector_.update(t, p.params, pending_events_);
    p.events = std::move(pending_events_);
    pending_events_.clear();
    for (const Event& e : p.events)
      if (e.alarm()) alarm_ = true;
    ++counts_.periods;
    counts_.events += p.events.size();
    if (db_) db_->write(p);  // committed before the JSON lines say so
    if (jsonl_) {
      if (!p.json.empty()) {
        const std::string line = estimate_line(t, p.json);
        std::fputs(line.c_str(), jsonl_);
        std::fputc('\n', jsonl_);
      }
      for (const Event& e : p.events) {
        const std::string line = event_line(e);
        std::fputs(line.c_str(), jsonl_);
        std::fputc('\n', jsonl_);
      }
      std::fflush(jsonl_);
    }
    if (!p.json.empty()) last_json_ = p.json;
    if (record_.is_open()) record_.flush();
    if (cb) cb(p, counts_);
  }

  const MonitorSettings& s_;
  SettingsSources est_;  ///< s_.estimator, following a drift
  SignalMap map_;
  EventDetector detector_;
  MonitorCounts counts_;
  std::ofstream record_;
  std::FILE* jsonl_ = nullptr;
  std::optional<HistoryDb> db_;
  std::optional<OnlineEstimator> online_;
  double last_period_t_ = 0.0;  ///< end of the previous period [s]
  std::vector<double> t_, v_, y_;
  std::vector<std::size_t> extra_gaps_;  ///< rows where a silence or counter jump restarts the regressors
  std::vector<Event> pending_events_;
  std::string last_json_;
  bool have_t0_ = false, have_frame_ = false, stale_now_ = false, restart_pending_ = false, alarm_ = false;
  bool have_grid_ = false;
  bool have_pending_ = false, stopped_ = false;  ///< a y frame waiting for its v; duration/alarm stop
  double pending_t_ = 0.0, pending_y_ = 0.0;
  double t0_ = 0.0, last_frame_ts_ = 0.0, next_period_ = 0.0, grid_t0_ = 0.0;
  std::uint64_t grid_k_ = 0;
  std::uint64_t last_snapshot_total_ = 0;  ///< samples of the run up to the last snapshot's end
  std::uint64_t trimmed_ = 0;              ///< samples dropped from the front of t_, v_, y_
  std::uint64_t last_gap_row_ = 0;         ///< run row of the last gap counted
};

SignalMap make_map(const MonitorSettings& s) {
  const SignalExpr v = parse_signal_expr(s.v, "--v");
  const SignalExpr y = parse_signal_expr(s.y, "--y");
  return SignalMap(load_dbc_quiet(s.dbc), v, y, s.dbc);
}

}  // namespace

void check_settings(const MonitorSettings& s) {
  check_positive(s.every_s, "--every", false);
  check_positive(s.dt_s, "--dt", true);
  check_positive(s.stale_timeout_s, "--stale-timeout", false);
  check_positive(s.window_s, "--window", true);
  check_positive(s.duration_s, "--duration", true);
  check_positive(s.online.init_s, "--init", false);
  try {
    s.online.reguess.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, "reguess", e.what());
  }
  (void)resolve_settings(following(s.estimator));  // the estimator's settings (a bad key or value fails here)
  // what the online estimator refuses (model switching), refused before the source opens
  if (s.mode == EstimateMode::online) (void)OnlineEstimator(following(s.estimator), s.online);
  (void)make_map(s);
}

MonitorResult run_monitor(const MonitorSettings& s, const std::atomic<bool>* stop, const PeriodCallback& cb) {
  check_settings(s);
  const auto wall0 = std::chrono::steady_clock::now();
  auto source = open_source(s.source, s.realtime, stop);
  Pipeline p(s, make_map(s));
  MonitorResult r;
  can::Frame f;
  const auto wall_s = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  };
  while (!(stop && stop->load())) {
    const auto next = source->next(f, std::chrono::milliseconds(100));
    if (next == FrameSource::Next::end) break;
    if (next == FrameSource::Next::idle) {
      p.idle(source->now_s());
    } else if (!p.frame(f, cb)) {
      break;
    }
    if (source->live() && s.duration_s > 0 && wall_s() > s.duration_s) break;
  }
  r.interrupted = stop && stop->load();
  p.counts().garbage = source->garbage();
  p.counts().bus_dropped = source->bus_dropped();
  p.finish(cb);
  r.counts = p.counts();
  r.last_json = p.last_json();
  r.alarm = p.alarm() && s.until_alarm;
  r.t_end = p.t_end();
  r.t0_unix_s = p.t0();
  r.wall_s = wall_s();
  return r;
}

}  // namespace lash::monitor
