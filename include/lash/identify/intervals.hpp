#pragma once
/// @file intervals.hpp
/// 95 % confidence intervals of identified parameters by **batch means** (sectioning: Schmeiser,
/// "Batch size effects in the analysis of simulation output", Oper. Res. 30(3), 1982; Law &
/// Kelton, Simulation Modeling and Analysis, §9.5.3). Not real-time code (runs the estimator again).
///
/// The record is cut into B consecutive sections; the same estimator runs on each section alone.
/// With the section estimates θ_1 … θ_B (those whose side the estimator identified), their
/// standard deviation s and the memory m of the estimator (m = min(length, 1/(1 − λ)); λ = 1:
/// the length), the standard error of the whole-record estimate θ is s·√(m_section / m_record)
/// and the interval θ ± t_{0.975, B'−1} · SE (Student's t for the B' sections used).
/// Why not σ²·P: with filtered v and y (the moving averages of docs/method.md §A5) the equation error is
/// correlated over the filter length, and with instrumental variables P is not a covariance;
/// sections see both effects as they are. K and τ get their own section estimates (not a
/// linearisation). An interval needs at least 5 identified sections; otherwise it is absent
/// (NaN bounds, JSON null).
#include <cstddef>
#include <limits>
#include <span>

#include "lash/blocks/side.hpp"
#include "lash/identify/config.hpp"
#include "lash/identify/record_columns.hpp"
#include "lash/identify/verdict.hpp"

namespace lash {

struct Interval {
  double lo = std::numeric_limits<double>::quiet_NaN();
  double hi = std::numeric_limits<double>::quiet_NaN();
  bool valid() const noexcept { return lo <= hi; }
};

/// 95 % intervals of one side's parameters (a parameter the model lacks stays invalid).
struct SideIntervals {
  Interval a1, b1, c, d, K, tau_s;
};

struct IntervalSettings {
  std::size_t sections = 10;      ///< B
  std::size_t min_sections = 5;   ///< fewer identified sections → no interval
  std::span<const std::size_t> gap_rows;  ///< rows where the record's timestamps jump (restart there)
};

/// Intervals around `estimate` (the whole-record parameters per side; coupled carts: the shared d
/// in both sides' d). Throws std::invalid_argument when v and y differ in length.
PerSide<SideIntervals> batch_means_intervals(const EstimatorConfig& cfg, std::span<const double> v,
                                             std::span<const double> y, const PerSide<SideParams>& estimate,
                                             const IntervalSettings& s = {});
/// The same over a record's columns (read in chunks: a spilled record streams).
PerSide<SideIntervals> batch_means_intervals(const EstimatorConfig& cfg, const RecordColumns& record,
                                             const PerSide<SideParams>& estimate, const IntervalSettings& s = {});

/// Under model switching with λ = 1 (docs/method.md §A4.4b) add_intervals (any_estimator.hpp)
/// attaches these instead of batch means: the **delete-a-group jackknife** (Quenouille 1956; Efron
/// & Stein 1981; Kott 2001, "The delete-a-group jackknife", J. Official Statistics 17(4)).
/// Replicate b runs the same estimator over the record without its b-th of B consecutive groups
/// (restarting where the group was cut out); with the replicates θ_(1) … θ_(B), var θ = (B − 1)/B ·
/// Σ (θ_(b) − θ̄)² and the interval θ ± t_{0.975, B−1} · √var. Why: with λ = 1 the IV estimate is a
/// smooth function of sums over the samples (the normal equations Σ z φᵀ, Σ z y), which the
/// jackknife covers, and a side driven beyond its edge only now and then gets too few updates in a
/// tenth of the record for batch means' sections, while each replicate holds nine tenths;
/// contiguous groups keep the equation error's correlation inside a group, as sections do. A side
/// gets intervals only when every replicate identifies it.
PerSide<SideIntervals> jackknife_intervals(const EstimatorConfig& cfg, const RecordColumns& record,
                                           const PerSide<SideParams>& estimate, const IntervalSettings& s = {});

/// The same intervals from section estimates already at hand (each section's per-side
/// parameters, identified or not, in order; the monitor's online sections, docs/monitor.md):
/// the estimator's memory over `section_len` samples against `n` samples sets the scale.
/// batch_means_intervals computes its sections and calls this.
PerSide<SideIntervals> section_intervals(const EstimatorConfig& cfg, std::span<const PerSide<SideParams>> sections,
                                         std::size_t section_len, std::size_t n,
                                         const PerSide<SideParams>& estimate, std::size_t min_sections = 5);

/// Check 7 of verdict.hpp on one side's intervals: Reason::uncertain when one of them reaches a
/// physically impossible value — a1 ≥ 0 or τ ≤ 0 (a first-order lag has a pole −a1 in (0, 1) and
/// τ = −T/ln(−a1) > 0), K ≤ 0 (the static gain b1/(1 + a1) is positive), an edge on the wrong
/// side of zero (c_r < 0 or c_l > 0), d < 0 — else Reason::none. An interval not computed
/// (invalid) passes. Not tested: a1 ≤ −1 (a pole at 1 is an integrator, τ → ∞, a limit a slow
/// lag's symmetric interval reaches without the estimate being wrong) and b1 ≤ 0 on its own
/// (where the input excites slowly a1 and b1 are strongly correlated: the valve's b1 interval
/// spans zero while its K interval is 1.25–3.04; the physical quantity is K).
Reason interval_verdict(const SideIntervals& ci, Side s) noexcept;

/// Check 8 of verdict.hpp (`ci_tolerance` > 0): Reason::uncertain unless the K and τ intervals
/// and, where the model has them (`has_c`, `has_d`), the c and d intervals are all computed and
/// each half-width is at most `tolerance` × |its centre| ((hi − lo) / |hi + lo| ≤ tolerance) —
/// else Reason::none. K and τ, not a1 and b1: they are the physical quantities, and a1 near −1
/// hides a loose τ (a1 = −0.99 ± 1 % is τ from 0.5 to ∞ at 5 ms). tolerance ≤ 0: none.
Reason precision_verdict(const SideIntervals& ci, double tolerance, bool has_c, bool has_d) noexcept;

/// The interval check 8 judges that is widest relative to its centre: its name ("K", "tau_s",
/// "c", "d") and (hi − lo) / |hi + lo| (+inf when one of them was not computed, name = the first
/// missing; name nullptr when there is nothing to judge).
struct WidestInterval {
  const char* name = nullptr;
  double relative = 0.0;
};
WidestInterval widest_interval(const SideIntervals& ci, bool has_c, bool has_d) noexcept;

/// Student's t quantile t_{0.975, dof} for dof ≥ 1 (table to 30, then the normal-limit series).
double student_t975(std::size_t dof) noexcept;

}  // namespace lash
