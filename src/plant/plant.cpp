#include "lash/plant/plant.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <type_traits>
#include <utility>

namespace lash {

const char* block_kind(const Block& b) noexcept {
  struct V {
    const char* operator()(const Deadzone&) const noexcept { return "deadzone"; }
    const char* operator()(const Deadband&) const noexcept { return "deadband"; }
    const char* operator()(const FirstOrder&) const noexcept { return "linear"; }
    const char* operator()(const MovingAverage&) const noexcept { return "moving_average"; }
    const char* operator()(const BackwardDifference&) const noexcept { return "difference"; }
    const char* operator()(const Delay&) const noexcept { return "delay"; }
    const char* operator()(const Saturation&) const noexcept { return "saturation"; }
  };
  return std::visit(V{}, b);
}

namespace {
/// Index of a chain of kinds 0..2 (deadzone, deadband, first order) of length 1..3 in the table
/// below, or −1.
int chain_code(const std::vector<Block>& blocks) noexcept {
  if (blocks.empty() || blocks.size() > 3) return -1;
  int code = 0;
  for (const auto& b : blocks) {
    if (b.index() > 2) return -1;
    code = code * 3 + static_cast<int>(b.index());
  }
  return code;
}
}  // namespace

namespace {
/// Kind of block D (0 = first) of the chain whose code is C among the chains of length L.
constexpr std::size_t kind_digit(std::size_t C, std::size_t L, std::size_t D) noexcept {
  for (std::size_t i = D + 1; i < L; ++i) C /= 3;
  return C % 3;
}

constexpr std::size_t pow3(std::size_t L) noexcept { return L == 0 ? 1 : 3 * pow3(L - 1); }
}  // namespace

template <bool Keep, std::size_t... I>
void Plant::run_fixed(const double* v, double* y, double* x, std::size_t n) noexcept {
  if (n == 0) return;  // signals() keeps the last sample's
  constexpr std::size_t N = sizeof...(I);
  constexpr std::array<std::size_t, N> kind{I...};
  [&]<std::size_t... J>(std::index_sequence<J...>) {
    // The blocks as local values: no store and load of their state per sample (the locals'
    // addresses never leave this function, so the compiler keeps them in registers).
    std::tuple<std::variant_alternative_t<kind[J], Block>...> blk{as_kind<kind[J]>(blocks_[J])...};
    std::array<double, N> last{};
    double v_prev = v_prev_;
    for (std::size_t k = 0; k < n; ++k) {
      const double vk = v[k];  // read before y[k] is written: y may be v
      // step_fixed, step for step
      const Side side = side_of(v_prev);
      double s = vk;
      ((s = step_block(std::get<J>(blk), s, side), last[J] = s), ...);
      if constexpr (Keep) ((x[k * N + J] = last[J]), ...);
      y[k] = s;
      v_prev = vk;
    }
    ((as_kind<kind[J]>(blocks_[J]) = std::get<J>(blk)), ...);
    ((signals_[J] = last[J]), ...);
    v_prev_ = v_prev;
  }(std::make_index_sequence<N>{});
}

void Plant::run_any(const double* v, double* y, double* x, std::size_t n) noexcept {
  const std::size_t nb = signals_.size();
  for (std::size_t k = 0; k < n; ++k) {
    y[k] = step(v[k]);
    if (x) std::copy(signals_.begin(), signals_.end(), x + k * nb);
  }
}

Plant::Compiled Plant::compiled_for(const std::vector<Block>& blocks) noexcept {
  const int code = chain_code(blocks);
  if (code < 0) return {};
  const auto c = static_cast<std::size_t>(code);
  // code = Σ kind·3^(len−1−i): the entry of each length's table for that code
  auto table = [c]<std::size_t L>(std::integral_constant<std::size_t, L>) {
    return [c]<std::size_t... C>(std::index_sequence<C...>) {
      const std::array<Compiled, sizeof...(C)> all{[]<std::size_t Code, std::size_t... D>(std::index_sequence<D...>) {
        return Compiled{&Plant::step_fixed<kind_digit(Code, L, D)...>,
                        &Plant::run_fixed<false, kind_digit(Code, L, D)...>,
                        &Plant::run_fixed<true, kind_digit(Code, L, D)...>};
      }.template operator()<C>(std::make_index_sequence<L>{})...};
      return all[c];
    }(std::make_index_sequence<pow3(L)>{});
  };
  switch (blocks.size()) {
    case 1: return table(std::integral_constant<std::size_t, 1>{});
    case 2: return table(std::integral_constant<std::size_t, 2>{});
    default: return table(std::integral_constant<std::size_t, 3>{});
  }
}

Plant::Plant(std::vector<Block> blocks, double dt_s) : blocks_(std::move(blocks)), dt_s_(dt_s) {
  if (!(std::isfinite(dt_s) && dt_s > 0)) throw std::invalid_argument("dt must be > 0");
  signals_.assign(blocks_.size(), 0.0);
  compiled_ = compiled_for(blocks_);
}

void Plant::run(std::span<const double> v, std::span<double> y) {
  if (y.size() != v.size()) throw std::invalid_argument("run: y must have as many samples as v");
  if (compiled_.run) (this->*compiled_.run)(v.data(), y.data(), nullptr, v.size());
  else run_any(v.data(), y.data(), nullptr, v.size());
}

void Plant::run(std::span<const double> v, std::span<double> y, std::span<double> x) {
  if (y.size() != v.size()) throw std::invalid_argument("run: y must have as many samples as v");
  if (x.size() != v.size() * blocks_.size())
    throw std::invalid_argument("run: x must hold every block's output of every sample (v.size() x blocks)");
  if (compiled_.run_keep) (this->*compiled_.run_keep)(v.data(), y.data(), x.data(), v.size());
  else run_any(v.data(), y.data(), x.data(), v.size());
}

void Plant::reset() noexcept {
  for (auto& b : blocks_) std::visit([](auto& blk) noexcept { blk.reset(); }, b);
  for (auto& s : signals_) s = 0.0;
  v_prev_ = 0.0;
}

}  // namespace lash
