#include "lash/plant/plant_file.hpp"

#include <cmath>
#include <stdexcept>

#include "lash/io/error.hpp"

namespace lash {
namespace {

// A number or a {left, right} table; `name` names the per-side quantity.
PerSide<double> per_side_number(TomlTable& t, std::string_view key) {
  const auto* n = t.node(key);
  if (!n) t.fail(key, "missing");
  if (n->is_table()) {
    TomlTable s = t.table(key);
    PerSide<double> v{s.number("right"), s.number("left")};
    s.finish();
    return v;
  }
  return PerSide<double>::both(t.number(key));
}

FirstOrderParams linear_side(TomlTable& s, double dt_s) {
  FirstOrderParams p;
  const bool discrete = s.has("a1") || s.has("b1");
  const bool continuous = s.has("gain") || s.has("tau");
  if (discrete && continuous) s.fail("", "give either a1/b1 or gain/tau, not both");
  if (discrete) {
    p = {s.number("a1"), s.number("b1")};
  } else if (continuous) {
    const double k = s.number("gain");
    const double tau = s.number("tau");
    if (tau <= 0) s.fail("tau", "time constant must be > 0 [s]");
    p = FirstOrderParams::from_continuous(k, tau, dt_s);
  } else {
    s.fail("", "needs a1 and b1, or gain and tau");
  }
  return p;
}

Block make_block(TomlTable& b, double dt_s) {
  const std::string kind = b.string("kind");
  if (kind == "deadzone") {
    DeadzoneParams p{b.number("left"), b.number("right")};
    if (p.left > p.right) b.fail("left", "deadzone needs left <= right (c_l <= c_r)");
    return Deadzone(p);
  }
  if (kind == "deadband" || kind == "backlash") {
    PerSide<double> d;
    if (b.has("half_width") && b.has("width")) b.fail("width", "give half_width or width, not both");
    if (b.has("width")) {
      d = per_side_number(b, "width");
      d.left *= 0.5;
      d.right *= 0.5;
      if (d.left < 0 || d.right < 0) b.fail("width", "width must be >= 0");
    } else {
      d = per_side_number(b, "half_width");
      if (d.left < 0 || d.right < 0) b.fail("half_width", "half-width must be >= 0");
    }
    return Deadband(d);
  }
  if (kind == "linear") {
    PerSide<FirstOrderParams> p;
    if (b.has("right") || b.has("left")) {
      if (b.has("a1") || b.has("b1") || b.has("gain") || b.has("tau"))
        b.fail("right", "give either per-side tables (right/left) or one set of coefficients");
      for (Side side : {Side::right, Side::left}) {
        if (!b.has(to_string(side))) continue;
        TomlTable st = b.table(to_string(side));
        p[side] = linear_side(st, dt_s);
        st.finish();
      }
      if (!b.has("left")) p.left = p.right;
      if (!b.has("right")) p.right = p.left;
    } else {
      p = PerSide<FirstOrderParams>::both(linear_side(b, dt_s));
    }
    return FirstOrder(p);
  }
  if (kind == "moving_average") {
    const auto m = b.integer("length");
    if (m < 1 || m > 1'000'000) b.fail("length", "moving-average length must be 1..1000000 [samples]");
    return MovingAverage(static_cast<std::size_t>(m));
  }
  if (kind == "difference") return BackwardDifference(dt_s);
  if (kind == "delay") {
    const auto n = b.integer("samples");
    if (n < 0 || n > 1'000'000) b.fail("samples", "delay must be 0..1000000 [samples]");
    return Delay(static_cast<std::size_t>(n));
  }
  if (kind == "saturation") {
    const double lo = b.number_or("lower", -INFINITY);
    const double hi = b.number_or("upper", INFINITY);
    if (lo > hi) b.fail("lower", "saturation needs lower <= upper");
    return Saturation(lo, hi);
  }
  b.fail("kind", "unknown block kind '" + kind +
                     "' (expected deadzone, deadband, linear, moving_average, difference, delay, saturation)");
}

}  // namespace

Plant plant_from_toml(TomlTable& t, double dt_override) {
  double dt = dt_override;
  if (t.has("dt")) {
    const double file_dt = t.number("dt");
    if (file_dt <= 0) t.fail("dt", "sample period must be > 0 [s]");
    if (!(dt_override > 0)) dt = file_dt;
  } else if (!(dt > 0)) {
    t.fail("dt", "missing (sample period in seconds)");
  }
  std::vector<Block> blocks;
  if (!t.has("blocks")) t.fail("blocks", "missing (at least one [[blocks]] table)");
  for (auto& b : t.tables("blocks")) {
    try {
      blocks.push_back(make_block(b, dt));
    } catch (const std::invalid_argument& e) {
      b.fail("", e.what());
    }
    b.finish();
  }
  if (blocks.empty()) t.fail("blocks", "a plant needs at least one block");
  return Plant(std::move(blocks), dt);
}

Plant load_plant(const std::filesystem::path& path, double dt_s_override) {
  auto root = parse_toml_file(path);
  TomlTable t(root, path.string());
  t.string_opt("name");
  t.string_opt("description");
  Plant p = plant_from_toml(t, dt_s_override);
  t.finish();
  return p;
}

}  // namespace lash
