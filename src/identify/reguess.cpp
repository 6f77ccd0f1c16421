#include "lash/identify/reguess.hpp"

#include <cmath>
#include <stdexcept>

#include "lash/io/numeric.hpp"

namespace lash {

void ReguessSettings::validate() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(what);
  };
  require(confirm_updates >= 1, "reguess confirm_updates must be >= 1");
  require(std::isfinite(out_fraction) && out_fraction > 0 && out_fraction < 1, "reguess out_fraction must lie in (0, 1)");
  require(std::isfinite(margin_fraction) && margin_fraction > 0 && margin_fraction < 1,
          "reguess margin_fraction must lie in (0, 1)");
  require(std::isfinite(memory_s) && memory_s > 0, "reguess memory_s must be > 0 [s]");
  require(std::isfinite(reach_fraction) && reach_fraction > margin_fraction && reach_fraction < 1,
          "reguess reach_fraction must lie in (margin_fraction, 1)");
  require(min_beyond >= 1, "reguess min_beyond must be >= 1");
}

const char* to_string(ReguessRule r) noexcept {
  switch (r) {
    case ReguessRule::none: return "none";
    case ReguessRule::out: return "out";
    case ReguessRule::in: return "in";
  }
  return "?";
}

SideReguess::SideReguess(Side side, double guess, const ReguessSettings& s, double dt_s) noexcept
    : sigma_(side == Side::right ? 1.0 : -1.0),
      g_(sigma_ * guess),
      s_(s),
      window_n_(round_clamped<std::uint64_t>(s.memory_s / dt_s / kBlocks, 1, std::uint64_t{1} << 40)),
      lambda_(std::exp(-dt_s / s.memory_s)) {
  block_max_.fill(-std::numeric_limits<double>::infinity());
}

void SideReguess::new_block() noexcept {
  blk_ = (blk_ + 1) % kBlocks;
  block_max_[blk_] = -std::numeric_limits<double>::infinity();
  k_ = 0;
}

double SideReguess::xmax() const noexcept {
  double m = block_max_[0];
  for (std::size_t i = 1; i < kBlocks; ++i) m = block_max_[i] > m ? block_max_[i] : m;
  return m;
}

bool SideReguess::step(double v1, bool updated, Reason reason, double edge) noexcept {
  if (!s_.enabled || !std::isfinite(v1)) return false;
  const double x = sigma_ * v1;
  const double e = sigma_ * edge;  // NaN stays NaN: no in rule
  if (x > block_max_[blk_]) block_max_[blk_] = x;
  beyond_ = lambda_ * beyond_ + (x > e ? 1.0 : 0.0);
  ++since_move_;
  if (updated) {
    wrong_run_ = reason == Reason::wrong_guess ? wrong_run_ + 1 : 0;
    if (reason == Reason::none) floor_ = -std::numeric_limits<double>::infinity();  // identified: ĉ is the evidence
  }
  ++k_;
  auto move = [&](double to, ReguessRule rule) {
    last_old_ = g_;
    last_ = rule;
    g_ = to;
    ++(rule == ReguessRule::out ? n_out_ : n_in_);
    wrong_run_ = 0;
    since_move_ = 0;
    beyond_ = 0.0;
    block_max_.fill(-std::numeric_limits<double>::infinity());  // the evidence after a move is the new recursion's
    k_ = 0;
    return true;
  };
  // out: the guess lies inside the deadzone (the verdict's check 5, held on confirm_updates updates)
  if (wrong_run_ >= s_.confirm_updates && xmax() > g_) {
    floor_ = g_;
    return move(g_ + s_.out_fraction * (xmax() - g_), ReguessRule::out);
  }
  if (k_ >= window_n_) new_block();
  // in: a memory after the last move, the command went beyond the edge estimate, but the guess
  // lies in the top of its reach
  if (since_move_ >= kBlocks * window_n_ && std::isfinite(e) && beyond_ >= s_.min_beyond) {
    const double b = e > floor_ ? e : floor_;
    const double reach = xmax();
    if (reach > b && g_ > b + s_.reach_fraction * (reach - b)) {
      const double to = b + s_.margin_fraction * (reach - b);
      if (to < g_) return move(to, ReguessRule::in);
    }
  }
  return false;
}

}  // namespace lash
