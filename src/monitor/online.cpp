#include "lash/monitor/online.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>

#include "lash/identify/estimate_report.hpp"
#include "lash/identify/intervals.hpp"
#include "lash/identify/output_error.hpp"
#include "lash/io/error.hpp"

namespace lash::monitor {

namespace {
/// What the re-guessing needs of an estimator (Reguesser::follow), over AnyEstimator.
struct AnyAdaptor {
  AnyEstimator& e;
  std::uint64_t updates(Side s) const noexcept { return e.updates(s); }
  SideParams params(Side s) const noexcept { return e.params(s); }
  void set_guess(Side s, double g) noexcept { e.set_guess(s, g); }
};
}  // namespace

OnlineEstimator::OnlineEstimator(const SettingsSources& src, const OnlineSettings& s) : src_(src), s_(s) {
  if (!(std::isfinite(s.init_s) && s.init_s > 0)) throw std::invalid_argument("init_s must be > 0 [s]");
  if (s.sections < 2) throw std::invalid_argument("sections must be >= 2");
  if (!(std::isfinite(s.section_s) && s.section_s > 0)) throw std::invalid_argument("section_s must be > 0 [s]");
  s.reguess.validate();
  // model switching is an offline iteration over a whole record (docs/method.md §A4.4b): there is
  // no switching model to run with sample by sample (the estimator would refuse every stretch)
  if (resolve_settings(src).cfg.model_switching)
    throw InputError("", 0, "model-switching",
                     "needs --estimate window: model switching iterates over a whole window, the online "
                     "estimator cannot");
  refuse_output_error_online(resolve_settings(src).cfg, "--estimate window (whole windows)");
  OutlierGateConfig gc;
  gc.gate = s.outlier_gate;
  gate_ = OutlierGate(gc);
}

void OnlineEstimator::add(double t, double v, double y, bool restart) {
  if (est_) {
    process(t, v, y, restart);
    return;
  }
  if (restart && !bt_.empty()) brestart_.push_back(bt_.size());
  bt_.push_back(t);
  bv_.push_back(v);
  by_.push_back(y);
  if (bt_.size() >= 3 && t - bt_.front() >= s_.init_s) init();
}

void OnlineEstimator::init() {
  Sampling smp = analyse_sampling(bt_);
  for (const std::size_t r : brestart_) smp.gap_rows.push_back(r);
  std::sort(smp.gap_rows.begin(), smp.gap_rows.end());
  smp.gap_rows.erase(std::unique(smp.gap_rows.begin(), smp.gap_rows.end()), smp.gap_rows.end());
  EstimatorConfig cfg;
  try {
    const EstimateSettings set = resolve_settings(src_, smp.dt, bv_, by_);
    cfg = set.cfg;
    preset_ = set.preset;
    uses_guesses_ = model_traits(cfg.model).uses_guesses;
    const bool search_r = uses_guesses_ && std::isinf(cfg.guess_right);
    const bool search_l = uses_guesses_ && std::isinf(cfg.guess_left);
    if (search_r || search_l) {
      // the guesses estimate_auto would search on this stretch (y through the same gate)
      std::vector<double> yc(by_);
      std::vector<std::size_t> rows;
      std::vector<double> values;
      gate_outliers(by_, s_.outlier_gate, rows, values);
      for (std::size_t i = 0; i < rows.size(); ++i) yc[rows[i]] = values[i];
      const auto g = search_guesses(cfg, bv_, yc, smp.gap_rows);
      if (search_r) cfg.guess_right = g[0];
      if (search_l) cfg.guess_left = g[1];
    }
    src_r_ = uses_guesses_ ? (search_r ? GuessSource::searched : GuessSource::given) : GuessSource::unused;
    src_l_ = uses_guesses_ ? (search_l ? GuessSource::searched : GuessSource::given) : GuessSource::unused;
    est_.emplace(cfg);
    sec_.emplace(cfg);
  } catch (const InputError&) {
    est_.reset();
  } catch (const std::invalid_argument&) {
    est_.reset();
  }
  if (!est_) {  // this stretch does not resolve: try the next one
    bt_.clear();
    bv_.clear();
    by_.clear();
    brestart_.clear();
    return;
  }
  if (uses_guesses_ && s_.reguess.enabled) rg_.emplace(cfg.guess_right, cfg.guess_left, s_.reguess, cfg.dt_s);
  median_dt_ = smp.median_dt;
  gaps_ = StreamGaps(median_dt_);
  sec_len_ = std::max<std::size_t>(
      2, static_cast<std::size_t>(std::llround(s_.section_s / cfg.dt_s)));
  // the stretch, then free it
  std::vector<double> t, v, y;
  std::vector<std::size_t> rs;
  t.swap(bt_);
  v.swap(bv_);
  y.swap(by_);
  rs.swap(brestart_);
  auto r = rs.begin();
  for (std::size_t k = 0; k < t.size(); ++k) {
    const bool restart = r != rs.end() && *r == k;
    if (restart) ++r;
    process(t[k], v[k], y[k], restart);
  }
}

void OnlineEstimator::process(double t, double v, double y, bool restart) {
  if (gaps_.gap_before(t)) {
    ++gaps_n_;
    restart = true;
  }
  const std::uint64_t before = gate_.rejected();
  const double yg = gate_.step(y);
  const bool flagged = gate_.rejected() != before;
  if (have_p_) {  // the sample before is decided now that its next one is known (estimate_auto's rule)
    double yc = p_yg_;
    if (p_flag_) {
      if (std::fabs(y - p_y_) < std::fabs(y - p_yg_)) yc = p_y_;
      else ++outliers_;
    }
    feed(p_v_, yc, p_restart_);
  }
  have_p_ = true;
  p_v_ = v;
  p_y_ = y;
  p_yg_ = yg;
  p_flag_ = flagged;
  p_restart_ = restart;
}

void OnlineEstimator::feed(double v, double y, bool restart) {
  AnyEstimator& e = *est_;
  const double v1 = restart || fed_ == 0 ? std::nan("") : v_prev_;
  if (restart && fed_ > 0) {
    e.restart();
    sec_->restart();
    ++restarts_;
  }
  e.step(v, y);
  fit_.add(y, e.simulated());
  {
    const double lam = e.config().rls.lambda;
    const double err = y - e.simulated();
    ew_max_ = std::max(ew_max_, std::fabs(y));
    if (std::isfinite(err)) {
      ew_sq_ = lam * ew_sq_ + err * err;
      ew_w_ = lam * ew_w_ + 1.0;
      if (ew_bad_ > 0) --ew_bad_;
    } else {  // as bad as can be until the estimator's memory has passed
      ew_bad_ = lam < 1.0 ? static_cast<std::uint64_t>(std::ceil(1.0 / (1.0 - lam))) : ~std::uint64_t{0};
    }
  }
  if (rg_) {
    AnyAdaptor a{e};
    const PerSide<bool> moved = rg_->follow(a, v1);
    for (const Side s : {Side::right, Side::left})
      if (moved[s]) sec_->set_guess(s, rg_->guess(s));
  }
  sec_->step(v, y);
  if (++sec_n_ >= sec_len_) {
    sections_.push_back({sec_->params(Side::right), sec_->params(Side::left)});
    if (sections_.size() > s_.sections) sections_.pop_front();
    sec_->reset();
    sec_n_ = 0;
  }
  v_prev_ = v;
  ++fed_;
}

double OnlineEstimator::forgetting_nrmse() const noexcept {
  if (ew_bad_ > 0) return std::numeric_limits<double>::infinity();
  if (ew_w_ == 0.0 || ew_max_ == 0.0) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(ew_sq_ / ew_w_) / ew_max_;
}

std::optional<OnlineSnapshot> OnlineEstimator::snapshot(double t_from, double t_to) {
  if (!est_) return std::nullopt;
  const AnyEstimator& e = *est_;
  OnlineSnapshot out;
  AutoRun ar;
  ar.cfg = e.config();
  ar.run.report = e.report();
  EstimateReport& rep = ar.run.report;
  {  // check 6 on the forgetting fit (online.hpp); checks 1-5 passed when the reason is none or poor_fit
    const double nr = forgetting_nrmse();
    for (SideReport* sr : {&rep.right, &rep.left}) {
      Reason& why = sr->params.reason;
      if (why != Reason::none && why != Reason::poor_fit) continue;
      why = nr > ar.cfg.fit_threshold ? Reason::poor_fit : Reason::none;  // NaN: no evidence against
      sr->params.identified = why == Reason::none;
    }
    const bool two = model_traits(ar.cfg.model).two_sided;
    rep.identified = rep.right.params.identified && (!two || rep.left.params.identified) &&
                     (!rep.has_shared_d || rep.d_reason == Reason::none);
  }
  {  // too few sections yet: no intervals (checks 7 and 8 see invalid ones)
    PerSide<SideIntervals> ci{};
    if (sections_.size() >= s_.min_sections) {
      const std::vector<PerSide<SideParams>> secs(sections_.begin(), sections_.end());
      ci = section_intervals(ar.cfg, secs, sec_len_, static_cast<std::size_t>(fed_),
                             {rep.right.params, rep.left.params}, s_.min_sections);
    }
    attach_intervals(rep, ci, ar.cfg.ci_tolerance);
  }
  if (uses_guesses_) {
    for (const auto& [side, source] : {std::pair{Side::right, src_r_}, std::pair{Side::left, src_l_}}) {
      GuessReport& g = ar.guess(side);
      g.guess = ar.cfg.guess(side);
      g.source = source;
      g.edge = e.raw_edge(side);
      g.judge(side);
    }
  }
  ar.outliers = outliers_;
  ReportFit fit;
  fit.nrmse = fit_.value();
  fit.t0_s = t_from;
  fit.t1_s = t_to;
  fit.gaps = gaps_n_;
  fit.median_dt_s = median_dt_;
  fit_ = NrmseAccumulator{};
  out.json = estimate_auto_json(ar, preset_, fit);
  if (uses_guesses_ && !out.json.empty() && out.json.back() == '}') {
    out.json.pop_back();
    out.json += ",\"reguesses\":{\"right\":" + std::to_string(reguesses(Side::right)) +
                ",\"left\":" + std::to_string(reguesses(Side::left)) + "}}";
  }
  out.report = std::move(rep);
  return out;
}

}  // namespace lash::monitor
