#pragma once
/// @file online.hpp
/// The monitor's persistent estimator (docs/monitor.md, "Estimator"): the estimator `lash estimate`
/// runs (AnyEstimator with the settings of lash::resolve_settings, the searched switching guesses,
/// the outlier gate) fed one sample at a time, so that a period's estimate costs O(1) whatever the
/// window, instead of a whole-window estimate_arrays per period.
///
///  - The settings chosen from the data (docs/identification.md, "Defaults chosen from the data")
///    and the searched guesses (search_guesses) are chosen once, from the first `init_s` seconds
///    of samples (kept until then); those samples are then fed, and every later one as it comes.
///    When the first stretch does not resolve (too few samples, no excitation), it is dropped and
///    the next `init_s` seconds are tried.
///  - Regressors restart at timestamp gaps (> kGapFactor median steps of the first stretch, as
///    `lash estimate`) and where the caller says (a silence, an alive-counter jump).
///  - y passes the outlier gate of estimate_auto (auto_gate.hpp) with its one-sample look-ahead:
///    a sample is fed when the next one has come.
///  - Online re-guessing (identify/reguess.hpp, docs/method.md §A4.8) on the input-side models:
///    a side whose guess lies inside the deadzone (`wrong_guess`) or starves (few samples beyond
///    it while the input reaches beyond its edge) moves its guess and restarts that side.
///  - 95 % intervals by batch means (intervals.hpp) over the last `sections` sections of
///    `section_s` seconds, each estimated alone by a second estimator run alongside.
///  - NRMSE: of the estimator's free run over the samples of the period (the snapshot's window).
///  - The verdict's fit check (check 6, `poor_fit`) uses a **forgetting** NRMSE of that free run,
///    exponentially weighted with the estimator's own memory λ (sqrt(Σλ^j e²/Σλ^j) / max|y|), in
///    place of the estimator's fit since its start, which never forgets: a side whose fit was poor
///    for a while (a re-guess, a drift) is judged on its recent fit. Checks 1–5 are the estimator's.
/// add() is O(1) amortised (no allocation after the first stretch); snapshot() is O(sections).
/// Not real-time code (snapshot allocates the JSON).
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "lash/identify/any_estimator.hpp"
#include "lash/identify/auto.hpp"
#include "lash/identify/auto_gate.hpp"
#include "lash/identify/config_sources.hpp"
#include "lash/identify/reguess.hpp"
#include "lash/io/table.hpp"
#include "lash/metrics/fit.hpp"

namespace lash::monitor {

struct OnlineSettings {
  double init_s = 10.0;           ///< settings and guesses chosen from the first init_s seconds [s]
  double section_s = 4.0;         ///< batch means: length of a section [s]
  std::size_t sections = 10;      ///< batch means: the last this many sections are used
  std::size_t min_sections = 5;   ///< an interval needs this many identified sections
  double outlier_gate = 12.0;     ///< estimate_auto's gate [innovation scales] (0 = off)
  ReguessSettings reguess;        ///< online re-guessing (enabled by default)
};

/// One period's estimate.
struct OnlineSnapshot {
  EstimateReport report;          ///< with the intervals
  std::string json;               ///< the keys of `lash estimate --json` plus "reguesses"
};

class OnlineEstimator {
 public:
  /// src: the estimator settings (as `lash estimate`), checked by the caller. Throws InputError
  /// (field "model-switching") when they ask for model switching, which needs a whole record.
  OnlineEstimator(const SettingsSources& src, const OnlineSettings& s);

  /// One sample: t [s, increasing], v, y; restart: the regressors restart before it.
  void add(double t, double v, double y, bool restart);
  /// Whether the settings have been chosen (else snapshot() has nothing).
  bool ready() const noexcept { return est_.has_value(); }
  /// The estimate now; its NRMSE covers the samples fed since the previous snapshot, reported as
  /// the window [t_from, t_to] [s]. nullopt before ready().
  std::optional<OnlineSnapshot> snapshot(double t_from, double t_to);

  std::uint64_t gaps() const noexcept { return gaps_n_; }          ///< timestamp gaps seen
  std::uint64_t restarts() const noexcept { return restarts_; }    ///< regressor restarts
  std::uint64_t reguesses(Side s) const noexcept { return rg_ ? rg_->count(s) : 0; }
  std::uint64_t samples() const noexcept { return fed_; }         ///< samples fed to the estimator
  const EstimatorConfig* config() const noexcept { return est_ ? &est_->config() : nullptr; }

 private:
  void init();
  void process(double t, double v, double y, bool restart);
  void feed(double v, double y, bool restart);

  const SettingsSources& src_;
  OnlineSettings s_;
  // the first stretch, until the settings are chosen
  std::vector<double> bt_, bv_, by_;
  std::vector<std::size_t> brestart_;
  std::optional<AnyEstimator> est_, sec_;
  std::optional<Reguesser> rg_;
  Preset preset_ = Preset::lash;
  GuessSource src_r_ = GuessSource::unused, src_l_ = GuessSource::unused;
  bool uses_guesses_ = false;
  OutlierGate gate_;
  StreamGaps gaps_{0.0};
  double median_dt_ = 0.0;
  // the sample waiting for the next one (the gate's look-ahead)
  bool have_p_ = false, p_flag_ = false, p_restart_ = false;
  double p_v_ = 0.0, p_y_ = 0.0, p_yg_ = 0.0;
  double v_prev_ = 0.0;
  std::uint64_t fed_ = 0, gaps_n_ = 0, restarts_ = 0, outliers_ = 0;
  NrmseAccumulator fit_;
  /// the forgetting fit (verdict check 6): Σλ^j e², Σλ^j, max|y|; samples until a non-finite
  /// free-run error is forgotten
  double ew_sq_ = 0.0, ew_w_ = 0.0, ew_max_ = 0.0;
  std::uint64_t ew_bad_ = 0;
  double forgetting_nrmse() const noexcept;
  std::size_t sec_len_ = 0, sec_n_ = 0;
  std::deque<PerSide<SideParams>> sections_;  ///< the last s_.sections finished sections
};

}  // namespace lash::monitor
