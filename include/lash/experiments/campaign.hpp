#pragma once
/// @file campaign.hpp
/// A campaign: the thesis's matrix of runs on one virtual rig (docs/method.md §A7, E3–E5)
/// with the estimator settings, read from a TOML file (docs/sweep.md).
/// Not real-time safe.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "lash/identify/config.hpp"
#include "lash/rigs/rig.hpp"
#include "lash/signals/signal.hpp"

namespace lash::sweep {

/// One run of a campaign.
struct RunSpec {
  std::size_t index = 0;       ///< 0-based position in the campaign
  Waveform waveform = Waveform::sine;
  double amplitude = 0.0;      ///< [rig input unit]; randomized: 0 (see Campaign::random_*)
  double frequency_rad_s = 0.0;///< randomized: 0
  int repeat = 0;              ///< 1-based repeat number within its matrix cell
  std::uint64_t seed = 0;      ///< seeds the rig's noise and the randomized input
};

struct Campaign {
  std::string file;                   ///< where it came from (for messages)
  std::string name;                   ///< human title
  rigs::RigConfig rig;                ///< which rig and its parameters
  double dt_s = 0.001;                ///< campaign sample period T [s]
  double duration_s = 30.0;           ///< run length [s]
  double window_start_s = 7.5;        ///< NRMSE window (thesis: 7.5–30 s) [s]
  double window_end_s = 30.0;
  double good_nrmse = 0.10;           ///< a run is "good" below this NRMSE (fraction)
  double param_tolerance = 0.05;      ///< relative tolerance of the parameter check against the rig's truth
  std::uint64_t seed = 1;             ///< base seed; run i uses run_seed(seed, i)
  double random_variance = 10000.0;   ///< randomized input: variance drawn every step (thesis: 10000)
  double random_tau_s = 0.5;          ///< randomized input: low-pass τ (thesis: 0.5 s)
  EstimatorConfig estimator;          ///< lash's settings for the rig's model unless the file says otherwise
  /// No [estimator] table: each run first records the rig's open-loop response and takes the
  /// settings that depend on the data (and the switching guesses) from it (lash/identify/auto.hpp).
  bool estimator_from_data = false;
  std::vector<RunSpec> runs;
};

/// Seed of run `index`: splitmix64 of (base, index), so every repeat has its own noise.
std::uint64_t run_seed(std::uint64_t base, std::size_t index) noexcept;

/// The thesis's estimator settings for a rig (§1.6): λ = 0.99, P0 = 1000·I, η0 = [1 1 1] and
///  - motor_cart: output deadzone (eq. 36);
///  - pilot_valve: input deadzone, guesses ±500 mA, bounds a1 ∈ [−1, 0], b1 ∈ [0.0001, 2],
///    e ∈ [−500, 500] (the thesis bounds e per side; see docs/sweep.md);
///  - coupled_carts: coupled-carts estimator, |acceleration| ≤ 1 m/s², deadband from 7.5 s.
EstimatorConfig thesis_estimator(rigs::RigKind kind, double dt_s);
/// lash's settings for a rig (lash::preset_config of the rig's model, Preset::lash).
EstimatorConfig lash_estimator(rigs::RigKind kind, double dt_s);

/// Reads and validates a campaign file. Every problem (syntax, unknown key, empty matrix,
/// non-positive duration, bad estimator setting, …) throws InputError naming file, line and key.
Campaign load_campaign(const std::filesystem::path& path);

}  // namespace lash::sweep
