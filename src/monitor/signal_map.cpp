#include "lash/monitor/signal_map.hpp"

#include <algorithm>
#include <cctype>
#include <limits>
#include <stdexcept>

#include "lash/io/error.hpp"

namespace lash::monitor {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

SignalRef parse_ref(const std::string& part, const std::string& text, const std::string& field) {
  const auto dot = part.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == part.size() || part.find('.', dot + 1) != std::string::npos)
    throw InputError("", 0, field, "expected MSG.SIG or MSG.SIG-MSG.SIG, got '" + text + "'");
  return {part.substr(0, dot), part.substr(dot + 1)};
}

bool is_counter_name(const std::string& name) {
  std::string low(name);
  std::transform(low.begin(), low.end(), low.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return low.find("counter") != std::string::npos || low.find("alive") != std::string::npos;
}

}  // namespace

SignalExpr parse_signal_expr(const std::string& text, const std::string& field) {
  SignalExpr e;
  e.text = text;
  const auto minus = text.find('-');
  if (minus == std::string::npos) {
    e.plus = parse_ref(text, text, field);
    return e;
  }
  if (text.find('-', minus + 1) != std::string::npos)
    throw InputError("", 0, field, "expected MSG.SIG or MSG.SIG-MSG.SIG, got '" + text + "'");
  e.plus = parse_ref(text.substr(0, minus), text, field);
  e.minus = parse_ref(text.substr(minus + 1), text, field);
  e.has_minus = true;
  return e;
}

struct SignalMap::Impl {
  struct Counter {
    std::size_t sig = 0;
    std::uint64_t mask = 0;
    bool have = false;
    std::uint64_t last = 0;
  };
  struct Watched {
    std::uint32_t id = 0;
    bool extended = false;
    std::uint32_t size = 0;
    std::unique_ptr<can::MessageCodec> codec;
    std::vector<double> values;
    std::vector<std::size_t> ranged;  ///< watched signals with a DBC range
    std::vector<Counter> counters;
  };
  struct Term {
    std::size_t msg = 0;
    std::size_t sig = 0;
    bool used = false;
    double value = kNaN;
  };
  std::vector<Watched> watched;
  Term terms[4];  // v+, v-, y+, y-

  std::size_t watch(const can::dbc::Database& db, const SignalRef& r, const std::string& field,
                    const std::string& dbc_file, std::size_t& sig) {
    const can::dbc::Message* m = db.message(r.message);
    if (!m) throw InputError(dbc_file, 0, field, "the DBC has no message '" + r.message + "'");
    if (!m->signal(r.signal))
      throw InputError(dbc_file, 0, field, "message '" + r.message + "' has no signal '" + r.signal + "'");
    std::size_t slot = 0;
    while (slot < watched.size() && !(watched[slot].id == m->id && watched[slot].extended == m->extended)) ++slot;
    if (slot == watched.size()) {
      Watched w;
      w.id = m->id;
      w.extended = m->extended;
      w.size = m->size;
      try {
        w.codec = std::make_unique<can::MessageCodec>(*m);
      } catch (const std::invalid_argument& e) {
        throw InputError(dbc_file, 0, field, "message '" + r.message + "' cannot be decoded: " + e.what());
      }
      w.values.assign(w.codec->signal_count(), kNaN);
      for (std::size_t i = 0; i < w.codec->signal_count(); ++i) {
        const auto& s = w.codec->codec(i).signal();
        if (is_counter_name(s.name) && s.mux == can::dbc::MuxRole::none && s.length < 64)
          w.counters.push_back({i, (std::uint64_t{1} << s.length) - 1, false, 0});
      }
      watched.push_back(std::move(w));
    }
    Watched& w = watched[slot];
    sig = *w.codec->index_of(r.signal);
    const auto& s = w.codec->codec(sig).signal();
    if (s.minimum < s.maximum && std::find(w.ranged.begin(), w.ranged.end(), sig) == w.ranged.end())
      w.ranged.push_back(sig);
    return slot;
  }
};

SignalMap::SignalMap(const can::dbc::Database& db, const SignalExpr& v, const SignalExpr& y,
                     const std::string& dbc_file)
    : impl_(std::make_unique<Impl>()) {
  const std::pair<const SignalRef*, const char*> refs[4] = {
      {&v.plus, "--v"}, {v.has_minus ? &v.minus : nullptr, "--v"}, {&y.plus, "--y"}, {y.has_minus ? &y.minus : nullptr, "--y"}};
  for (int k = 0; k < 4; ++k) {
    if (!refs[k].first) continue;
    auto& t = impl_->terms[k];
    t.msg = impl_->watch(db, *refs[k].first, refs[k].second, dbc_file, t.sig);
    t.used = true;
  }
}

SignalMap::~SignalMap() = default;
SignalMap::SignalMap(SignalMap&&) noexcept = default;
SignalMap& SignalMap::operator=(SignalMap&&) noexcept = default;

FrameCheck SignalMap::decode(const can::Frame& f, bool& is_y, bool& counter_jump) noexcept {
  is_y = false;
  counter_jump = false;
  if (f.remote || f.error) return FrameCheck::other;
  auto& ws = impl_->watched;
  std::size_t slot = 0;
  while (slot < ws.size() && !(ws[slot].id == f.id && ws[slot].extended == f.extended)) ++slot;
  if (slot == ws.size()) return FrameCheck::other;
  auto& w = ws[slot];
  if (f.len != w.size || !w.codec->decode(f.payload(), w.values)) return FrameCheck::bad_dlc;
  for (const std::size_t i : w.ranged) {
    const auto& s = w.codec->codec(i).signal();
    const double x = w.values[i];
    if (x == x && (x < s.minimum || x > s.maximum)) return FrameCheck::out_of_range;
  }
  for (auto& c : w.counters) {
    const std::uint64_t raw = *w.codec->codec(c.sig).read_raw(f.payload());
    if (c.have && raw != ((c.last + 1) & c.mask)) counter_jump = true;
    c.have = true;
    c.last = raw;
  }
  for (auto& t : impl_->terms) {
    if (!t.used || t.msg != slot) continue;
    const double x = w.values[t.sig];
    if (x == x) t.value = x;  // NaN: a multiplexed signal this frame does not carry
  }
  is_y = impl_->terms[2].msg == slot && w.values[impl_->terms[2].sig] == w.values[impl_->terms[2].sig];
  return FrameCheck::ok;
}

double SignalMap::v() const noexcept {
  const auto& t = impl_->terms;
  return t[1].used ? t[0].value - t[1].value : t[0].value;
}
double SignalMap::y() const noexcept {
  const auto& t = impl_->terms;
  return t[3].used ? t[2].value - t[3].value : t[2].value;
}

void SignalMap::forget_counters() noexcept {
  for (auto& w : impl_->watched)
    for (auto& c : w.counters) c.have = false;
}

}  // namespace lash::monitor
