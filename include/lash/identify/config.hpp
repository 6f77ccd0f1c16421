#pragma once
/// @file config.hpp
/// Settings shared by every estimator of docs/method.md §A4/§A5 (docs/identification.md).
/// Plain structs; `validate()` is called once at construction and throws
/// std::invalid_argument naming the offending field (the CLI turns that into exit 2).
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include "lash/blocks/side.hpp"
#include "lash/identify/rls.hpp"

namespace lash {

/// The models of docs/method.md §A4. Each has its policy and traits under identify/models/,
/// registered in EstimatorModels (estimators.hpp), where names, parameters and defaults come from.
enum class ModelKind : std::uint8_t { linear, input_deadzone, output_deadzone, deadzone_deadband, coupled_carts };
inline constexpr std::size_t kModelCount = 5;

/// "linear", "input-deadzone", "output-deadzone", "deadzone-deadband", "coupled-carts";
/// throws std::invalid_argument otherwise.
ModelKind parse_model_kind(std::string_view name);
const char* to_string(ModelKind m) noexcept;

/// How each keyed regression is solved.
enum class EstimationMethod : std::uint8_t {
  ls,  ///< recursive least squares (eq. 13–16), the thesis's method
  iv   ///< recursive instrumental variables, instrument = output delayed `iv_delay` more samples
};
EstimationMethod parse_method(std::string_view name);
const char* to_string(EstimationMethod m) noexcept;
/// "exponential" or "directional"; throws std::invalid_argument otherwise (one parser for the
/// TOML key [rls] forgetting and the --forgetting option).
Forgetting parse_forgetting(std::string_view name);
const char* to_string(Forgetting f) noexcept;

/// Settings of every RLS inside an estimator (thesis §1.5.1: λ = 0.99, P0 = 1000·I, η0 = [1 1 1]).
/// Parameter order is [a1, b1, e] (docs/method.md §A4); the linear model uses the first two.
/// The smallest forgetting factor an estimator accepts: a memory 1/(1 − λ) of 10 samples.
inline constexpr double kMinLambda = 0.9;

struct RlsSettings {
  double lambda = 0.99;  ///< [kMinLambda, 1]
  double p0 = 1000.0;
  std::array<double, 3> eta0{1.0, 1.0, 1.0};
  Forgetting forgetting = Forgetting::exponential;
  double trace_max = 1e12;
  std::array<double, 3> lower{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                              -std::numeric_limits<double>::infinity()};
  std::array<double, 3> upper{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                              std::numeric_limits<double>::infinity()};
};

/// A set of models (bit i = ModelKind i): which models read a settings struct.
using ModelSet = std::uint8_t;
constexpr ModelSet model_bit(ModelKind m) noexcept { return static_cast<ModelSet>(1u << static_cast<unsigned>(m)); }
constexpr ModelSet kAllModels = static_cast<ModelSet>((1u << kModelCount) - 1);
constexpr bool contains(ModelSet set, ModelKind m) noexcept { return (set & model_bit(m)) != 0; }

/// The moving averages on the regression signals (every model).
struct RegressionFilterSettings {
  /// M-point moving average on y (the regression output) [samples]; 1 = off.
  std::size_t filter_length = 1;
  /// Pass v through the same moving average as y ("consistent filtering": the linear
  /// relation between v and y survives the filter wherever its window stays in one regime).
  bool filter_input = false;
  /// Pure delay of v [samples] that keeps v aligned with a filtered y when v itself is not filtered.
  std::size_t input_delay = 0;
  /// The plant's dead time [samples]: y(k) responds to v(k−1−n), e.g. an actuator's fast lag
  /// (a valve solenoid's) taken as a pure delay. Unlike `input_delay`, the free run (verdict
  /// check 6, y_sim) is driven by the delayed v too: it is part of the model. 0 = none.
  std::size_t dead_time = 0;
  static constexpr ModelSet models = kAllModels;
  void validate() const;
};

/// Switching on the direction of motion ẏ (deadzone-deadband, coupled-carts).
struct DerivativeSwitchingSettings {
  /// Moving average on y before the derivative is taken [samples]; 0 = the same filter as the
  /// regression's (filter_length). Lets the regression use raw y while switching uses a smooth ẏ.
  std::size_t derivative_prefilter_length = 0;
  /// M-point moving average on the backward-difference derivative ẏ [samples]; 1 = off.
  std::size_t derivative_filter_length = 1;
  /// Dead band on ẏ: |ẏ| ≤ threshold counts as "not moving" [y unit/s]. 0 = sign of the difference.
  double derivative_threshold = 0.0;
  /// Delay of the regression signals (v and y after the filters above) so that they line up
  /// with the filtered ẏ used for switching [samples]. Typically (derivative_filter_length − 1)/2.
  std::size_t align_delay = 0;
  static constexpr ModelSet models =
      model_bit(ModelKind::deadzone_deadband) | model_bit(ModelKind::coupled_carts);
  void validate() const;
};

/// Noise handling of docs/method.md §A5 / thesis §1.4.5. Defaults pass the signals through untouched.
/// One struct per model group underneath, so `cfg.noise.derivative_threshold` reads as before.
struct NoiseSettings : RegressionFilterSettings, DerivativeSwitchingSettings {};

/// Settings every model reads.
struct CommonSettings {
  ModelKind model = ModelKind::deadzone_deadband;
  double dt_s = 0.005;             ///< sample period T [s]
  RlsSettings rls;
  NoiseSettings noise;
  std::uint64_t min_updates = 50;  ///< a key needs this many updates before its side is identified
  /// Verdict check 6 (verdict.hpp): a model whose free-run NRMSE (RMS(y − y_sim)/max|y|) over
  /// t ≥ fit_start_s exceeds this fraction is reported `poor_fit`. 0.2 = 20 %: far above what
  /// measurement noise alone gives on a fitting model (E2, noise variance 200: about 1.5 %).
  double fit_threshold = 0.2;
  /// Start of the verdict's fit window [s] (the whole record when it ends earlier); 7.5 s is
  /// the thesis's NRMSE window start and `lash estimate`'s default --nrmse-window.
  double fit_start_s = 7.5;
  /// Verdict check 8 (verdict.hpp), off at 0: where 95 % intervals are computed, a side is
  /// identified only when it has them and each of its K, τ, c and d intervals lies within
  /// ±ci_tolerance of its centre (0.05 = 5 %) — else `uncertain`. Turns "identified" into
  /// "known to this precision": the user's tolerance, not a property of the data.
  double ci_tolerance = 0.0;
  static constexpr ModelSet models = kAllModels;
  void validate() const;
};

/// How the keyed regressions are solved (every model but coupled-carts, whose two stages are RLS).
struct MethodSettings {
  EstimationMethod method = EstimationMethod::ls;
  std::size_t iv_delay = 2;  ///< iv: the instrument for y(k−1) is y(k−1−iv_delay) [samples]
  static constexpr ModelSet models = kAllModels & ~model_bit(ModelKind::coupled_carts);
  void validate() const;
};

/// Switching on the input against the guesses c_l*, c_r* (input-deadzone, deadzone-deadband).
struct InputSwitchingSettings {
  double guess_left = -std::numeric_limits<double>::infinity();  ///< c_l* [v unit]; −inf = searched
  double guess_right = std::numeric_limits<double>::infinity();  ///< c_r* [v unit]; +inf = searched
  /// Free-run simulation inside the input deadzone: false = keep the a1 of the side last used
  /// (thesis §1.4.2, docs/method.md §A4.2); true = side by the sign of v(k−1) (eq. 34).
  bool sim_side_by_sign = false;
  /// The guess of side s (guess_right or guess_left).
  double& guess(Side s) noexcept { return s == Side::right ? guess_right : guess_left; }
  double guess(Side s) const noexcept { return s == Side::right ? guess_right : guess_left; }
  static constexpr ModelSet models =
      model_bit(ModelKind::input_deadzone) | model_bit(ModelKind::deadzone_deadband);
  void validate() const;
};

/// deadzone-deadband only. Defaults are lash's (E2's method); the thesis's: pooled false, direction_run 2.
struct DeadzoneDeadbandSettings {
  /// One 4-parameter regression per side with a1, b1 shared between directions
  /// (η = [a1, b1, −b1·c, d(1+a1)]) instead of the thesis's separate + and − RLS.
  bool pooled = true;
  /// A key is updated only after the direction of motion (and the side of v) has held for this
  /// many consecutive samples. 2 is the thesis's y(k) > y(k−1) > y(k−2); with a moving-average
  /// filter of length M use ≥ M + 1 so the whole filter window lies in one regime.
  std::uint32_t direction_run = 41;
  /// A side counts as identified only after (c, d) moved by at most settle_tol·(|c| + |d|) per
  /// update for settle_updates updates in a row (the 2×2 solve of eq. 31/32 amplifies a key
  /// that has not converged yet; this keeps such transients out).
  double settle_tol = 0.01;
  std::uint32_t settle_updates = 5;
  double singular_tol = 1e-6;  ///< eq. 31/32: |det| below tol·(|a|+|b|) terms counts as singular
  /// Model switching (docs/method.md §A4.4b): the side, the direction and the
  /// instrument of each update come from a switching model (below) driven by v alone, instead of
  /// ẏ and the guesses; pooled only. `lash estimate` iterates it by itself when the ẏ switching
  /// leaves a side unidentified; true makes it iterate on every record.
  bool model_switching = false;
  /// Output-error refinement (docs/method.md §A4.4c; deadzone-deadband, input-deadzone and
  /// output-deadzone, the latter two with d = 0 held): after the switching estimate, move the parameters of both sides to
  /// minimise the free run's error over the NRMSE window
  /// (Levenberg–Marquardt, identify/output_error.hpp) and judge and bound the result. Offline
  /// only (whole-record passes); the online estimator refuses it.
  bool output_error = false;
  /// Output-error check (docs/method.md §A4.4c; same models): with output_error off, the same fits
  /// from the estimate only check it. The estimate is kept; a side the fit moves by more than
  /// 1 % in a1, b1, c or d, beyond three of the fit's 95 % half-widths, where the estimate's
  /// free run misfits by more than 1 % (the bounds: kCheck* in output_error.hpp), is not the
  /// least-squares fit of the output the model reaches from it and is reported poor_fit. On in
  /// the thesis preset of the deadzone-deadband (it has no refinement); the refinement checks so
  /// too when a side is not_excited. Offline only: estimators fed sample by sample do not run it.
  bool output_error_check = false;
  /// Model switching: the model's deadband must have been engaged in one direction, with v on
  /// one side of zero, for this many samples in a row before a sample updates [samples].
  std::uint32_t switch_hold = 4;
  /// Model switching: v(k−1) within switch_margin·|c| of the switching model's edge c updates
  /// nothing [-].
  double switch_margin = 0.05;
  /// One side of the switching model: a1, b1 [-], c [v unit], d [y unit].
  struct SwitchSide {
    double a1 = std::numeric_limits<double>::quiet_NaN();
    double b1 = std::numeric_limits<double>::quiet_NaN();
    double c = std::numeric_limits<double>::quiet_NaN();
    double d = std::numeric_limits<double>::quiet_NaN();
    bool usable() const noexcept;  ///< finite, |a1| < 1, b1 ≠ 0, d ≥ 0
  };
  /// The switching model, held through a run (not a setting: `lash estimate`'s iteration sets it
  /// from the previous run). Not usable: model switching updates nothing.
  PerSide<SwitchSide> switch_model{};
  static constexpr ModelSet models = model_bit(ModelKind::deadzone_deadband);
  void validate() const;
};

/// output-deadzone only.
struct OutputDeadzoneSettings {
  double zero_threshold = 0.0;  ///< |y| ≤ this counts as 0 [y unit]
  static constexpr ModelSet models = model_bit(ModelKind::output_deadzone);
  void validate() const;
};

/// coupled-carts only. Defaults are lash's (before tune_to_data sets accel_limit from the record);
/// the thesis's differ in stage2_start (7.5 s).
struct CoupledCartsSettings {
  /// Stage 1: max |ÿ| [y unit/s²]; +inf = no gate. 1 = the thesis's |free-cart acceleration| ≤ 1 m/s² (§1.6.3).
  double accel_limit = 1.0;
  double stage2_start_s = 5.0;  ///< deadband estimation starts here [s]
  static constexpr ModelSet models = model_bit(ModelKind::coupled_carts);
  void validate() const;
};

/// All settings of one estimator: the common part plus every per-model part, composed by
/// inheritance so that each field keeps its short name (`cfg.pooled`, `cfg.rls.lambda`).
/// A default-constructed config holds lash's data-independent defaults for its model
/// (deadzone-deadband); `EstimatorConfig(model)` those of another model, and
/// `EstimatorConfig::thesis(model)` the thesis's settings (§1.5.1). The settings chosen from a
/// record come on top (auto.hpp: tune_to_data). The field table (config_fields.hpp) lists every
/// field with its TOML key, CLI flag and the struct (hence the models) it belongs to.
struct EstimatorConfig : CommonSettings,
                         MethodSettings,
                         InputSwitchingSettings,
                         DeadzoneDeadbandSettings,
                         OutputDeadzoneSettings,
                         CoupledCartsSettings {
  EstimatorConfig() : EstimatorConfig(ModelKind::deadzone_deadband) {}
  /// lash's data-independent defaults for `model`, sample period dt_s [s].
  explicit EstimatorConfig(ModelKind model, double dt_s = 0.005);
  /// The thesis's settings (§1.5.1: RLS, λ = 0.99, P0 = 1000·I, η0 = [1 1 1], no filters;
  /// coupled carts: |ÿ| ≤ 1, stage 2 from 7.5 s).
  static EstimatorConfig thesis(ModelKind model, double dt_s = 0.005);

  /// Validates the common part and every per-model part `model` reads (the others are not
  /// read, so not checked). Throws std::invalid_argument naming the field.
  void validate() const;
  RlsConfig<3> rls3() const;
  RlsConfig<2> rls2() const;
  RlsConfig<4> rls4() const;
};

}  // namespace lash
