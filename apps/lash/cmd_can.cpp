// lash can: dump | send | encode | decode | replay (see docs/can.md).
#include <sched.h>
#include <time.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "lash/can/bus.hpp"
#include "lash/can/codec.hpp"
#include "lash/can/dbc.hpp"
#include "lash/can/log.hpp"

namespace lash::cli {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }

void install_stop_handler() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

std::string default_iface(const std::string& bus) {
  if (bus.rfind("socketcan:", 0) == 0) return bus.substr(10);
  return "can0";
}

can::Frame parse_frame_arg(const std::string& text, const std::string& field) {
  std::string err;
  auto f = can::parse_frame_text(text, err);
  if (!f) throw InputError("", 0, field, err);
  return *f;
}

struct DumpOptions {
  std::string bus;
  long count = -1;
  double timeout_s = -1;
  std::string log;
  std::string iface;
  std::vector<std::string> filters;
  bool quiet = false;
};

/// "ID:MASK" in hex; 8 hex digits in ID make it a 29-bit filter (like cansend ids).
can::Filter parse_filter(const std::string& text) {
  const auto colon = text.find(':');
  const std::string id = text.substr(0, colon);
  const std::string mask = colon == std::string::npos ? (id.size() == 8 ? "1FFFFFFF" : "7FF") : text.substr(colon + 1);
  can::Filter f;
  f.extended = id.size() == 8;
  std::size_t used1 = 0, used2 = 0;
  try {
    f.id = static_cast<std::uint32_t>(std::stoul(id, &used1, 16));
    f.mask = static_cast<std::uint32_t>(std::stoul(mask, &used2, 16));
  } catch (const std::exception&) {
    used1 = 0;
  }
  if ((id.size() != 3 && id.size() != 8) || used1 != id.size() || used2 != mask.size() ||
      f.id > (f.extended ? 0x1FFFFFFFu : 0x7FFu))
    throw InputError("", 0, "--filter", "expected ID:MASK in hex with a 3- or 8-digit id, got '" + text + "'");
  return f;
}

int run_dump(const DumpOptions& o) {
  std::vector<can::Filter> filters;
  for (const auto& t : o.filters) filters.push_back(parse_filter(t));
  auto bus = can::open_bus(o.bus);
  if (!filters.empty()) bus->set_filters(filters);
  const std::string iface = o.iface.empty() ? default_iface(o.bus) : o.iface;
  std::unique_ptr<AtomicFile> log;
  if (!o.log.empty()) log = std::make_unique<AtomicFile>(o.log);
  install_stop_handler();
  long n = 0;
  timespec start{};
  clock_gettime(CLOCK_MONOTONIC, &start);
  while (!g_stop.load() && (o.count < 0 || n < o.count)) {
    auto chunk = std::chrono::milliseconds(100);
    if (o.timeout_s >= 0) {
      timespec now{};
      clock_gettime(CLOCK_MONOTONIC, &now);
      const double left = o.timeout_s - (static_cast<double>(now.tv_sec - start.tv_sec) +
                                         static_cast<double>(now.tv_nsec - start.tv_nsec) * 1e-9);
      if (left <= 0) break;
      if (left < 0.1) chunk = std::chrono::milliseconds(static_cast<long>(left * 1000) + 1);
    }
    auto f = bus->receive(chunk);
    if (!f) continue;
    const std::string line = can::format_log_line(*f, iface);
    if (!o.quiet) {
      std::fputs(line.c_str(), stdout);
      std::fputc('\n', stdout);
      std::fflush(stdout);
    }
    if (log) log->stream() << line << '\n';
    ++n;
  }
  if (log) log->commit();
  const auto st = bus->stats();
  fmt::print(stderr, "lash can dump: {} frames ({} filtered, {} dropped)\n", n, st.filtered, st.dropped);
  if (o.count >= 0 && n < o.count) return kExitFailed;
  return kExitOk;
}

struct SendOptions {
  std::string bus;
  std::vector<std::string> frames;
  double gap_s = 0.0;
};

int run_send(const SendOptions& o) {
  std::vector<can::Frame> frames;
  for (std::size_t i = 0; i < o.frames.size(); ++i) frames.push_back(parse_frame_arg(o.frames[i], "frame " + o.frames[i]));
  auto bus = can::open_bus(o.bus);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (i && o.gap_s > 0) {
      timespec ts{};
      ts.tv_sec = static_cast<time_t>(o.gap_s);
      ts.tv_nsec = static_cast<long>((o.gap_s - static_cast<double>(ts.tv_sec)) * 1e9);
      nanosleep(&ts, nullptr);
    }
    if (!bus->send(frames[i])) {
      fmt::print(stderr, "lash can send: sending {} failed\n", o.frames[i]);
      return kExitFailed;
    }
  }
  return kExitOk;
}

struct EncodeOptions {
  std::string dbc;
  std::string message;
  std::vector<std::string> assignments;
};

int run_encode(const EncodeOptions& o) {
  const auto db = can::dbc::load_dbc(o.dbc);
  const auto* m = db.message(o.message);
  if (!m) throw InputError(o.dbc, 0, "--message", "no message named '" + o.message + "'");
  std::unique_ptr<can::MessageCodec> codec;
  try {
    codec = std::make_unique<can::MessageCodec>(*m);
  } catch (const std::invalid_argument& e) {
    throw InputError(o.dbc, 0, m->name, e.what());
  }
  std::vector<double> values(codec->signal_count());
  std::vector<bool> given(values.size(), false);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const auto& s = codec->codec(i).signal();
    values[i] = s.mux == can::dbc::MuxRole::multiplexed ? std::nan("") : codec->codec(i).to_physical(0);
  }
  for (const auto& a : o.assignments) {
    const auto eq = a.find('=');
    if (eq == std::string::npos) throw InputError("", 0, a, "expected SIGNAL=VALUE");
    const auto idx = codec->index_of(a.substr(0, eq));
    if (!idx) throw InputError(o.dbc, 0, a.substr(0, eq), "message '" + m->name + "' has no such signal");
    double v = 0;
    if (!parse_double(a.substr(eq + 1), v)) {
      // a value description (VAL_) text is accepted too
      bool found = false;
      for (const auto& vd : codec->codec(*idx).signal().values)
        if (vd.text == a.substr(eq + 1)) {
          v = codec->codec(*idx).to_physical(static_cast<std::uint64_t>(vd.value));
          found = true;
        }
      if (!found) throw InputError("", 0, a, "value is not a number");
    }
    values[*idx] = v;
    given[*idx] = true;
  }
  can::Frame f;
  f.id = m->id;
  f.extended = m->extended;
  f.len = static_cast<std::uint8_t>(m->size);
  if (m->size > 8) f.fd = true;
  const auto r = codec->encode(values, f.payload());
  if (!r.ok) throw InputError(o.dbc, 0, m->name, "cannot encode");
  if (r.clamped) fmt::print(stderr, "lash can encode: {} value(s) clamped to the signal range\n", r.clamped);
  fmt::print("{}\n", can::format_frame_text(f));
  return kExitOk;
}

struct DecodeOptions {
  std::string dbc;
  std::string log;
};

int run_decode(const DecodeOptions& o) {
  const auto db = can::dbc::load_dbc(o.dbc);
  const auto entries = can::read_log(o.log);
  std::map<std::pair<std::uint32_t, bool>, std::unique_ptr<can::MessageCodec>> codecs;
  std::vector<double> values;
  std::string out;
  for (const auto& e : entries) {
    const auto& f = e.frame;
    out.clear();
    char ts[48];
    std::snprintf(ts, sizeof ts, "%.6f", f.timestamp_s);
    out += ts;
    const auto* m = db.message(f.id, f.extended);
    if (!m || f.remote) {
      out += " ? " + can::format_frame_text(f);
      std::puts(out.c_str());
      continue;
    }
    auto& c = codecs[{f.id, f.extended}];
    if (!c) {
      try {
        c = std::make_unique<can::MessageCodec>(*m);
      } catch (const std::invalid_argument& err) {
        throw InputError(o.dbc, 0, m->name, err.what());
      }
    }
    out += " " + m->name;
    values.assign(c->signal_count(), 0.0);
    if (!c->decode(f.payload(), values)) {
      out += fmt::format(" (frame has {} bytes, the DBC says {})", f.len, m->size);
      std::puts(out.c_str());
      continue;
    }
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (std::isnan(values[i]) && c->codec(i).signal().mux == can::dbc::MuxRole::multiplexed) continue;
      const auto& s = c->codec(i).signal();
      out += " " + s.name + "=" + format_double(values[i]);
      if (!s.unit.empty()) out += " " + s.unit;
      if (!s.values.empty()) {
        const auto raw = *c->codec(i).read_raw(f.payload());
        const std::int64_t key = s.is_signed ? static_cast<std::int64_t>(raw << (64 - s.length)) >> (64 - s.length)
                                             : static_cast<std::int64_t>(raw);
        for (const auto& vd : s.values)
          if (vd.value == key) out += " \"" + vd.text + "\"";
      }
    }
    std::puts(out.c_str());
  }
  return kExitOk;
}

struct ReplayOptions {
  std::string bus;
  std::string log;
  double speed = 1.0;
  double spin_us = 2000.0;
  int rt_priority = 0;
};

std::int64_t to_ns(const timespec& t) { return static_cast<std::int64_t>(t.tv_sec) * 1000000000LL + t.tv_nsec; }
timespec from_ns(std::int64_t ns) {
  timespec t{};
  t.tv_sec = static_cast<time_t>(ns / 1000000000LL);
  t.tv_nsec = static_cast<long>(ns % 1000000000LL);
  return t;
}
std::int64_t now_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return to_ns(t);
}

int run_replay(const ReplayOptions& o) {
  const auto entries = can::read_log(o.log);
  if (!(o.speed > 0)) throw InputError("", 0, "--speed", "must be > 0");
  auto bus = can::open_bus(o.bus);
  if (entries.empty()) return kExitOk;
  if (o.rt_priority > 0) {
    sched_param sp{};
    sp.sched_priority = o.rt_priority;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
      fmt::print(stderr, "lash can replay: cannot use SCHED_FIFO {} ({}); continuing without\n", o.rt_priority,
                 std::strerror(errno));
  }
  install_stop_handler();
  // Every frame, the first included, goes out at an absolute deadline; the 10 ms lead
  // lets the first one take the same (warm) path as the rest.
  timespec t0 = from_ns(now_ns() + 10000000);
  const double log0 = entries.front().frame.timestamp_s;
  std::size_t failed = 0;
  for (const auto& e : entries) {
    if (g_stop.load()) break;
    const double dt = (e.frame.timestamp_s - log0) / o.speed;
    {
      // Absolute deadline t0 + dt: sleep until --spin-us before it, then spin on the clock,
      // so that timer wake-up latency does not delay the frame.
      const std::int64_t deadline = to_ns(t0) + static_cast<std::int64_t>(std::llround(dt * 1e9));
      const std::int64_t wake = deadline - static_cast<std::int64_t>(o.spin_us * 1e3);
      const timespec at = from_ns(wake);
      while (now_ns() < wake && clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr) == EINTR &&
             !g_stop.load()) {
      }
      while (now_ns() < deadline) {
      }
    }
    if (!bus->send(e.frame)) ++failed;
  }
  if (failed) {
    fmt::print(stderr, "lash can replay: {} of {} frames failed to send\n", failed, entries.size());
    return kExitFailed;
  }
  return kExitOk;
}

}  // namespace

Command add_can(CLI::App& app) {
  auto* sub = app.add_subcommand("can", "CAN tools: dump, send, encode, decode, replay (docs/can.md)");
  sub->require_subcommand(1);
  auto dump = std::make_shared<DumpOptions>();
  auto* d = sub->add_subcommand("dump", "Print received frames as candump -L lines; optionally write a log");
  d->add_option("--bus", dump->bus, "Bus address: mem:NAME | udp:GROUP:PORT | socketcan:IFACE")->required();
  d->add_option("--count", dump->count, "Stop after N frames (exit 1 if fewer arrive before --timeout)");
  d->add_option("--timeout", dump->timeout_s, "Stop after this many seconds [s]");
  d->add_option("--log", dump->log, "Also write the frames as a candump -L log (written on exit)");
  d->add_option("--iface", dump->iface, "Interface name written in the lines (default: the socketcan name or can0)");
  d->add_flag("--quiet", dump->quiet, "Do not print frames to stdout");
  d->add_option("--filter", dump->filters, "Accept only ID:MASK (hex; 8-digit id = 29-bit); repeatable");
  auto send = std::make_shared<SendOptions>();
  auto* s = sub->add_subcommand("send", "Send frames given as ID#HEX (cansend syntax)");
  s->add_option("--bus", send->bus, "Bus address")->required();
  s->add_option("--gap", send->gap_s, "Pause between frames [s]");
  s->add_option("frames", send->frames, "Frames: 123#DEADBEEF, 12345678#00, 123#R")->required();
  auto enc = std::make_shared<EncodeOptions>();
  auto* e = sub->add_subcommand("encode", "Encode signal values of a DBC message; prints ID#HEX");
  e->add_option("--dbc", enc->dbc, "DBC file")->required();
  e->add_option("--message", enc->message, "Message name")->required();
  e->add_option("signals", enc->assignments, "SIGNAL=VALUE (physical units); unset signals are raw 0");
  auto dec = std::make_shared<DecodeOptions>();
  auto* c = sub->add_subcommand("decode", "Decode a candump -L log with a DBC: time message signal=value unit ...");
  c->add_option("--dbc", dec->dbc, "DBC file")->required();
  c->add_option("log", dec->log, "candump -L log file")->required();
  auto rep = std::make_shared<ReplayOptions>();
  auto* r = sub->add_subcommand("replay", "Send the frames of a candump -L log with their original timing");
  r->add_option("--bus", rep->bus, "Bus address")->required();
  r->add_option("--speed", rep->speed, "Time scale (2 = twice as fast)");
  r->add_option("--spin-us", rep->spin_us, "Busy-wait this long before each deadline [us] (default 2000)")
      ->check(CLI::Range(0.0, 1e6));
  r->add_option("--rt-priority", rep->rt_priority, "Run under SCHED_FIFO with this priority (1-99; needs privileges)")
      ->check(CLI::Range(0, 99));
  r->add_option("log", rep->log, "candump -L log file")->required();
  return {sub, [=] {
            if (d->parsed()) return run_dump(*dump);
            if (s->parsed()) return run_send(*send);
            if (e->parsed()) return run_encode(*enc);
            if (c->parsed()) return run_decode(*dec);
            if (r->parsed()) return run_replay(*rep);
            return kExitBadInput;
          }};
}

}  // namespace lash::cli
