#pragma once
/// @file monitor.hpp
/// `lash monitor`: identify a running machine from its CAN bus or a log (docs/monitor.md).
///
///   source (bus or log, source.hpp) → DBC signal mapping and frame checks (signal_map.hpp)
///   → sampler → the estimation `lash estimate` runs (lash::estimate_arrays, same defaults,
///   searched guesses and verdicts) → one snapshot per period → JSONL, SQLite (history.hpp),
///   the record CSV, and events (events.hpp).
///
/// Sampling: each frame of y's message is one sample (t = the frame's time, v = the latest v
/// received before it), or with dt_s > 0 a zero-order hold at t0 + k·dt (v and y the latest
/// values received at or before that instant). t is in seconds since the first sample.
/// Each period's estimate (mode window, the default) is estimate_arrays over the samples of the
/// last window_s seconds; mode online: a snapshot of one persistent estimator fed every sample
/// (online.hpp: settings and guesses from the first stretch, re-guessing, O(1) per period).
/// The final estimate, in both modes, is estimate_arrays over the last window_s seconds (default
/// 120 s; 0 = every sample so far), restarted at the record's timestamp gaps (as `lash estimate`)
/// and where a silence or an alive-counter jump was seen: it equals
/// `lash estimate RECORD.csv --json` on the rows of the record in the last window.
/// One library call serves the CLI and Python. Not real-time code.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "lash/identify/config_sources.hpp"
#include "lash/monitor/events.hpp"
#include "lash/monitor/history.hpp"
#include "lash/monitor/online.hpp"

namespace lash::monitor {

/// How each period's estimate is made (docs/monitor.md, "Estimator").
enum class EstimateMode : std::uint8_t {
  online,  ///< one persistent estimator fed per sample (online.hpp): O(1) per period
  window   ///< estimate_arrays over the period's window from scratch: O(window) per period
};
/// "online" or "window"; std::invalid_argument otherwise.
EstimateMode parse_estimate_mode(const std::string& name);

struct MonitorSettings {
  std::string source;    ///< bus address or log file (source.hpp)
  std::string dbc;       ///< DBC file
  std::string v, y;      ///< signal expressions (signal_map.hpp)
  SettingsSources estimator;  ///< model, preset, estimator keys (as `lash estimate`)
  std::shared_ptr<const toml::table> estimator_keys;  ///< what estimator.keys points to (apply_monitor_config)
  AlarmSettings alarms;
  double every_s = 1.0;            ///< period of the snapshots [s of frame time]
  double dt_s = 0.0;               ///< > 0: zero-order-hold resampling period [s]
  double stale_timeout_s = 0.5;    ///< no frame of a watched message for this long = stale [s]
  /// > 0: each period's estimate covers the samples of the last window_s seconds, T - window_s < t <= T
  /// (T = the period's end), and the monitor keeps at most 2·window_s seconds of samples (bounded
  /// memory and cost per period); 0: every sample since the start (memory and cost grow with the run) [s]
  double window_s = 120.0;
  EstimateMode mode = EstimateMode::window;  ///< per-period estimate (the final one is always the window's)
  OnlineSettings online;           ///< the persistent estimator's settings (mode online)
  double duration_s = 0.0;         ///< > 0: stop after this long (frame time; live: also wall time) [s]
  bool realtime = false;           ///< a log at its recorded pace
  bool until_alarm = false;        ///< stop after the period with the first drift/threshold event
  std::string record_csv;          ///< "" = none: t,v,y as fed to the estimator
  std::string jsonl;               ///< "" = none, "-" = stdout
  std::string db;                  ///< "" = none: SQLite history
  /// Observer of each sample fed to the estimator (t [s since the first], v, y), called on the
  /// monitor's thread: the live console (docs/console.md). Must not block. Empty: none.
  std::function<void(double t, double v, double y)> on_sample;
};

/// Reads a monitor config: `[alarms]` and `[drift]` (events.hpp) and, for the estimator,
/// every other key as `lash estimate --config` reads them (`model` and `preset` when the
/// command line gave none). InputError naming file, line and key.
void apply_monitor_config(const std::string& path, MonitorSettings& s);
/// The same from a table already read (`name` stands for the file in messages): Python's keywords.
void apply_monitor_table(const toml::table& file, const std::string& name, MonitorSettings& s);

/// Checks the settings without reading the source: expressions against the DBC, the
/// estimator settings, the numbers. InputError (exit 2) naming the option, file or signal.
void check_settings(const MonitorSettings& s);

struct MonitorCounts {
  std::uint64_t frames = 0;         ///< frames read from the source
  std::uint64_t other = 0;          ///< frames of messages not watched
  std::uint64_t samples = 0;        ///< samples fed to the estimator
  std::uint64_t garbage = 0;        ///< log lines/objects that could not be read
  std::uint64_t bad_dlc = 0;        ///< watched frames with a wrong length (skipped)
  std::uint64_t out_of_range = 0;   ///< watched frames with a value outside the DBC range (skipped)
  std::uint64_t counter_jumps = 0;  ///< alive-counter jumps (regressor restart)
  std::uint64_t stale = 0;          ///< silences longer than stale_timeout_s (regressor restart)
  std::uint64_t time_back = 0;      ///< samples not after the previous one (skipped)
  std::uint64_t gaps = 0;           ///< timestamp gaps of the samples (> 5 median steps; restart)
  std::uint64_t restarts = 0;       ///< regressor restarts in the estimated samples
  std::uint64_t reguesses = 0;      ///< moves of a switching guess by the online re-guessing (both sides)
  std::uint64_t bus_dropped = 0;    ///< frames the bus dropped
  std::uint64_t periods = 0;
  std::uint64_t events = 0;
  /// frames dropped by the checks: garbage + bad_dlc + out_of_range + time_back + bus_dropped
  std::uint64_t dropped() const noexcept { return garbage + bad_dlc + out_of_range + time_back + bus_dropped; }
};

struct MonitorResult {
  MonitorCounts counts;
  std::string last_json;   ///< the last estimate ("" = none)
  bool alarm = false;      ///< stopped by until_alarm
  bool interrupted = false;
  double t_end = 0.0;      ///< last sample time [s since the first]
  double t0_unix_s = 0.0;  ///< timestamp of the first sample (log or bus epoch) [s]
  double wall_s = 0.0;     ///< run time [s]
};

/// Called after each period is written (status line, Python's collector).
using PeriodCallback = std::function<void(const Period&, const MonitorCounts&)>;

/// Runs the monitor until the source ends, `stop` becomes true, duration_s passes or (with
/// until_alarm) an alarm is raised; the period in progress is then written, the database
/// closed. Throws InputError (bad settings or source), SystemError (an output cannot be written).
MonitorResult run_monitor(const MonitorSettings& s, const std::atomic<bool>* stop = nullptr,
                          const PeriodCallback& on_period = {});

}  // namespace lash::monitor
