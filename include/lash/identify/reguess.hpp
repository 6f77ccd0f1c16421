#pragma once
/// @file reguess.hpp
/// Online re-guessing of a switching guess (docs/method.md §A4.8): the input-side estimators
/// (input-deadzone, deadzone-deadband) update a side only where v(k−1) lies beyond that side's
/// guess c*, and the guess must lie outside the deadzone (eq. 18). Offline, `lash estimate`
/// searches the guesses by a fixed-point iteration over the whole record
/// (docs/identification.md). Online the edge moves while the estimator runs, so a guess that was
/// right can become wrong (the edge drifts out past it: the side reports `wrong_guess`) or
/// useless (the edge and the command shrink and the command seldom reaches the guess: the side
/// starves). One SideReguess per side watches the evidence and moves the guess by two rules,
/// in the outward coordinate x = σ·v (σ = +1 right, −1 left; "beyond" = larger x):
///
///  - **out** (the guess lies inside the deadzone): the side's update-time verdict said
///    `wrong_guess` on `confirm_updates` updates in a row → g ← g + out_fraction·(x_max − g),
///    halfway to the furthest command seen beyond the guess (x_max over the current and the last
///    memory). The old guess becomes the side's *floor*: evidence that the edge lies
///    beyond it, forgotten once the side is identified again.
///  - **in** (the guess starves the side): over the recent `memory_s` (exponentially weighted
///    count, so that the test does not depend on how a window meets the command's period), the
///    command went beyond the side's current edge estimate ĉ on at least `min_beyond` samples,
///    but the guess lies in the top of its reach, g > b + reach_fraction·(x_max − b) (few or no
///    samples beyond the guess, and those with little spread: b1 and the offset inseparable) →
///    g ← b + margin_fraction·(x_max − b), b = max(ĉ, floor), x_max = the largest x of the last
///    memory (8 block maxima: the last 7/8 to 8/8 of it): the offline search's rule
///    (c* = ĉ + m·(v_extreme − ĉ)), applied only when it moves the guess inward. Offline m = 0.15;
///    online the default is 0.5 (the valve's unmodelled solenoid lag biases samples near the
///    edge, the reason the scenarios' guesses start at 1.5 × the edge).
///
/// After each move the caller sets the estimator's guess and restarts that side's recursion
/// (InputDeadzoneEstimator::set_guess, DeadzoneDeadbandEstimator::set_guess); the evidence starts
/// again, and the in rule waits `memory_s` before it may fire.
///
/// Why it converges and never oscillates (docs/method.md §A4.8): once g lies beyond the true
/// edge c, every update obeys the side's linear relation, ĉ ≈ c < g and `wrong_guess` cannot
/// persist, so the out rule stops; the in rule's target b + 0.15·(x_max − b) with b = ĉ ≈ c
/// lies outside the deadzone and receives a fixed share of the samples beyond ĉ (a sine with
/// m = 0.5: about 2/3) and lies at m = 0.5 < reach_fraction of the reach, so the in rule does not
/// fire again: that is the fixed point (the gap between m and reach_fraction is the hysteresis). While g lies inside the deadzone, each out move halves x_max − g; an in move
/// lands at b + m·(x_max − b) with b ≥ floor, and the floor only rises (each out move sets it to
/// the guess it left), so between two identifications x_max − floor shrinks at least by the factor
/// (1 − m) per out/in pair and the floor passes c after finitely many moves: out and in cannot
/// alternate for ever. A side that never sees a command beyond its edge gives no evidence and
/// keeps its guess.
/// Real time: step() is noexcept, O(1), allocation-free.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "lash/blocks/side.hpp"
#include "lash/identify/verdict.hpp"

namespace lash {

struct ReguessSettings {
  bool enabled = true;                 ///< false: the guesses never move
  std::uint32_t confirm_updates = 50;  ///< out rule: `wrong_guess` on this many updates in a row [-]
  double out_fraction = 0.5;           ///< out rule: share of the way from g to x_max [-], (0, 1)
  double margin_fraction = 0.5;        ///< in rule: g = b + margin·(x_max − b) [-], (0, 1)
  double memory_s = 4.0;               ///< in rule: memory of the count and of x_max [s]
  double reach_fraction = 0.8;         ///< in rule: fires when g > b + reach·(x_max − b) [-], (margin, 1)
  std::uint32_t min_beyond = 20;       ///< in rule: samples beyond ĉ a window needs [-]
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// Which rule moved a guess.
enum class ReguessRule : std::uint8_t { none, out, in };
const char* to_string(ReguessRule r) noexcept;

/// One side's guess and its evidence (see the file comment).
class SideReguess {
 public:
  /// guess: the side's switching guess now [v unit] (right > 0 > left is not required);
  /// s valid; dt_s > 0 (the evidence window in samples).
  SideReguess(Side side, double guess, const ReguessSettings& s, double dt_s) noexcept;
  /// One sample: v1 = the switching input the estimator compared with the guess on this sample
  /// (v(k−1)); updated = this side's recursion updated on it; reason = the side's update-time
  /// verdict after it; edge = the side's current edge estimate as a signed value (NaN = none:
  /// the in rule waits). Returns true when the guess moved: guess() is the new one and the caller
  /// sets it on its estimator (set_guess, which restarts that side's recursion).
  bool step(double v1, bool updated, Reason reason, double edge) noexcept;
  double guess() const noexcept { return sigma_ * g_; }
  /// Moves so far, and by each rule.
  std::uint64_t count() const noexcept { return n_out_ + n_in_; }
  std::uint64_t count(ReguessRule r) const noexcept { return r == ReguessRule::out ? n_out_ : (r == ReguessRule::in ? n_in_ : 0); }
  /// The last move: its rule (none before the first) and the guess before it [v unit].
  ReguessRule last_rule() const noexcept { return last_; }
  double last_old_guess() const noexcept { return sigma_ * last_old_; }

 private:
  void new_block() noexcept;
  double xmax() const noexcept;
  double sigma_, g_;
  ReguessSettings s_;
  std::uint64_t window_n_;
  double lambda_;  // exp(−T/memory_s)
  double floor_ = -std::numeric_limits<double>::infinity();
  std::uint32_t wrong_run_ = 0;
  std::uint64_t k_ = 0, since_move_ = 0;
  double beyond_ = 0.0;  // exponentially weighted count of the samples beyond ĉ
  static constexpr std::size_t kBlocks = 8;
  std::array<double, kBlocks> block_max_;  // maxima of the last blocks of memory_s/8 (the current one at blk_)
  std::size_t blk_ = 0;
  std::uint64_t n_out_ = 0, n_in_ = 0;
  ReguessRule last_ = ReguessRule::none;
  double last_old_ = 0.0;
};

/// Both sides' re-guessing for an input-side estimator E (InputDeadzoneEstimator,
/// DeadzoneDeadbandEstimator: anything with set_guess(Side, double), updates(Side), params(Side)).
/// Call follow() after each est.step(v, y) with the v of the step before (the value the estimator
/// compared with its guesses); a move sets the estimator's guess (set_guess restarts that side's
/// recursion). The edge ĉ of the in rule is the side's last c identified on confirm_updates
/// updates in a row (the estimator's own evidence, whatever the caller made of it; a start-up
/// transient that is identified for a few updates is not evidence), and before that the
/// caller's `fallback` (the adaptive compensator: the inverse in use; NaN: the in rule waits).
/// noexcept, O(1), allocation-free.
class Reguesser {
 public:
  Reguesser(double guess_right, double guess_left, const ReguessSettings& s, double dt_s) noexcept
      : side_{SideReguess(Side::right, guess_right, s, dt_s), SideReguess(Side::left, guess_left, s, dt_s)},
        confirm_(s.confirm_updates) {}
  /// Returns which sides moved.
  template <class E>
  PerSide<bool> follow(E& est, double v1) noexcept {
    return follow(est, v1, {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
  }
  /// fallback: each side's edge as a signed value until the side is first identified.
  template <class E>
  PerSide<bool> follow(E& est, double v1, const PerSide<double>& fallback) noexcept {
    return {one(est, Side::right, v1, fallback.right), one(est, Side::left, v1, fallback.left)};
  }
  const SideReguess& side(Side s) const noexcept { return side_[s]; }
  std::uint64_t count(Side s) const noexcept { return side_[s].count(); }
  double guess(Side s) const noexcept { return side_[s].guess(); }

 private:
  template <class E>
  bool one(E& est, Side s, double v1, double fallback) noexcept {
    const std::uint64_t n = est.updates(s);
    const bool updated = n != n_[s];
    n_[s] = n;
    const SideParams p = est.params(s);
    if (updated) run_[s] = p.identified ? run_[s] + 1 : 0;
    if (p.identified && run_[s] >= confirm_) last_c_[s] = p.c;
    if (!side_[s].step(v1, updated, p.reason, std::isnan(last_c_[s]) ? fallback : last_c_[s])) return false;
    est.set_guess(s, side_[s].guess());
    n_[s] = est.updates(s);
    run_[s] = 0;
    return true;
  }
  PerSide<SideReguess> side_;
  PerSide<std::uint64_t> n_{};
  PerSide<std::uint32_t> run_{};  // updates in a row on which the side was identified
  std::uint32_t confirm_;
  PerSide<double> last_c_{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
};

}  // namespace lash
