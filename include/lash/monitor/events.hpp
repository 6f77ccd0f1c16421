#pragma once
/// @file events.hpp
/// The monitor's events (docs/monitor.md, "Events"):
///  - `threshold`: an identified parameter leaves the band of `[alarms]` (`<param>_max`,
///    `<param>_min`; `right`/`left` may stand for the suffixes `r`/`l`: `d_right_max` = `d_r_max`).
///    Edge-triggered: one event on leaving, re-armed on coming back inside. Armed `warmup_s`
///    (`[alarms]`, default 8 s) after the first estimate: a value outside then fires at once.
///  - `drift`: the Page–Hinkley test (lash/metrics/page_hinkley.hpp) on the period-by-period
///    values of every identified parameter, relative to its value when the warm-up ended
///    (x / |x_ref|, so δ and h are fractions), fed each period's value as it is (`median = 1`,
///    the default) or the running median of the last `median` identified values (1..5; a longer
///    median ignores shorter excursions but delays the alarm by (median − 1)/2 periods):
///    settings in `[drift]` (`delta`, `threshold`, `warmup_s`, `median`, `enabled`, `parameters`). `before` is the mean up to the estimated change, `after` the
///    value at the alarm; the test restarts after each alarm.
/// Not real-time code (runs once per period).
#include <array>
#include <map>
#include <string>
#include <vector>

#include "lash/identify/any_estimator.hpp"
#include "lash/io/toml_util.hpp"
#include "lash/metrics/page_hinkley.hpp"

namespace lash::monitor {

struct Threshold {
  std::string param;
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
};

struct DriftSettings {
  bool enabled = true;
  double delta = 0.03;      ///< δ of the Page–Hinkley test [fraction of the reference value]
  double threshold = 0.3;   ///< h [fraction of the reference value]
  double warmup_s = 8.0;    ///< no drift test before this long after the first estimate [s]
  /// the test is fed the running median of the last this many identified period values (1 = the
  /// values themselves; at most kMaxMedian)
  std::size_t median = 1;
  static constexpr std::size_t kMaxMedian = 5;
  /// Parameters the test watches (`parameters = [...]`). Default: the nonlinearity and the gain
  /// (c, d, K per side; K, d); τ's estimate moves by tens of percent between periods on closed-loop
  /// data and is watched only when named.
  std::vector<std::string> parameters{"c_r", "c_l", "d_r", "d_l", "K_r", "K_l", "K", "d"};
};

struct AlarmSettings {
  std::vector<Threshold> thresholds;
  /// no threshold event before this long after the first estimate [s]: the first seconds'
  /// estimates rest on a few hundred samples (docs/monitor.md, "Events")
  double warmup_s = 8.0;
  DriftSettings drift;
};

/// Reads `[alarms]` and `[drift]` of a monitor config (the table `t` is the file's root; the
/// two tables are marked read). InputError naming file, line and key on a bad key or value.
AlarmSettings read_alarm_settings(TomlTable& t);

/// One identified (or not) parameter of a period, with its 95 % interval (NaN when none).
struct ParamValue {
  std::string name;  ///< c_r, c_l, d_r, d_l, K_r, K_l, tau_s_r, tau_s_l (linear: K, tau_s; carts: d)
  double value = std::numeric_limits<double>::quiet_NaN();
  double lo = std::numeric_limits<double>::quiet_NaN();
  double hi = std::numeric_limits<double>::quiet_NaN();
  bool identified = false;
  /// The point estimate passed the verdict's checks 1–6 (identified, or `uncertain` by check 7
  /// only: its interval reaches an impossible value, as a window holding a drift's two levels
  /// makes it): what the events follow.
  bool watched = false;
};

/// The parameters the monitor follows, from a report (sides the model has, names as above).
std::vector<ParamValue> monitored_params(const EstimateReport& r);

struct Event {
  double t = 0.0;          ///< [s] since the first sample
  std::string kind;        ///< drift | threshold | stale | resumed
  std::string param;       ///< "" for stale / resumed
  double before = std::numeric_limits<double>::quiet_NaN();
  double after = std::numeric_limits<double>::quiet_NaN();
  bool alarm() const noexcept { return kind == "drift" || kind == "threshold"; }
};

class EventDetector {
 public:
  explicit EventDetector(const AlarmSettings& s);
  /// One period's parameters at time t [s]; appends the events they raise.
  void update(double t, const std::vector<ParamValue>& params, std::vector<Event>& out);

 private:
  struct Track {
    bool started = false;
    double scale = 1.0;
    PageHinkley ph;
    bool outside = false;
    double last = std::numeric_limits<double>::quiet_NaN();
    std::array<double, DriftSettings::kMaxMedian> recent{};  ///< the last identified values (ring), for the running median
    std::size_t n_recent = 0;
  };
  AlarmSettings s_;
  std::map<std::string, Track> tracks_;
  bool have_t0_ = false;
  double t0_ = 0.0;
};

}  // namespace lash::monitor
