// lash can: the subcommand group, dump and send (see docs/can.md).
#include <time.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <optional>

#include <fmt/core.h>

#include "cmd_can.hpp"
#include "lash/can/bus.hpp"
#include "lash/can/log.hpp"
#include "lash/can/log_reader.hpp"
#include "lash/io/atomic_file.hpp"
#include "lash/rt/periodic.hpp"

namespace lash::cli {
namespace can_cmd {

std::atomic<bool> g_stop{false};
namespace {
extern "C" void on_signal(int) { g_stop.store(true); }
}  // namespace

void install_stop_handler() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;  // no SA_RESTART: sleeps return EINTR and see g_stop
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

}  // namespace can_cmd

namespace {
using can_cmd::g_stop;
using can_cmd::install_stop_handler;

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

/// Where `can dump --log FILE` puts the frames while it runs: candump -L lines in a temporary
/// file next to FILE (AtomicFile: `FILE.tmp.<random>`), flushed at least once a second, so that
/// a killed dump leaves every frame but those of its last second there. A candump FILE is that
/// file renamed at the end; a relative format (.asc, .trc, .blf: they need the earliest time up
/// front) is converted from it at the end (times kept to the nanosecond) and it is removed.
class DumpLog {
 public:
  explicit DumpLog(const std::string& target)
      : target_(target), format_(can::log_format_of(target)),
        spool_(format_ == can::LogFormat::candump || !is_stream_output(target)
                   ? std::filesystem::path(target)
                   : std::filesystem::temp_directory_path() / "lash-can-dump.log") {
    if (!spool_.direct())
      fmt::print(stderr, "lash can dump: frames go to {} as they arrive (flushed every second); {} {} at the end\n",
                 spool_.temp_path().string(), format_ == can::LogFormat::candump ? "renamed to" : "converted to", target);
  }
  void add(const can::Frame& f, const std::string& iface, const std::string& line) {
    if (format_ == can::LogFormat::candump)
      spool_.stream() << line << '\n';
    else
      spool_.stream() << can::format_log_line(f, iface, 9) << '\n';
    const std::int64_t now = rt::monotonic_ns();
    if (now - last_flush_ns_ >= 500'000'000) flush(now);
  }
  /// No frame this wait: what is buffered still reaches the disk within the second.
  void add_nothing() {
    const std::int64_t now = rt::monotonic_ns();
    if (now - last_flush_ns_ >= 500'000'000) flush(now);
  }
  void flush(std::int64_t now) {
    spool_.stream().flush();
    last_flush_ns_ = now;
  }
  void finish() {
    flush(rt::monotonic_ns());
    if (format_ == can::LogFormat::candump) {
      spool_.commit();
      return;
    }
    can::LogTimes times;  // a first pass for the earliest time, a second one to write
    {
      can::LogReader r(spool_.temp_path());
      for (can::LogEntry e; r.next(e);) times.add(e.frame.timestamp_s);
    }
    AtomicFile out(target_);
    can::LogWriter w(out.stream(), format_, times, target_);
    can::LogReader r(spool_.temp_path());
    for (can::LogEntry e; r.next(e);) w.write(e);
    w.finish();
    out.commit();
  }  // the spool is removed with spool_ (never committed)

 private:
  std::string target_;
  can::LogFormat format_;
  AtomicFile spool_;
  std::int64_t last_flush_ns_ = rt::monotonic_ns();
};

int run_dump(const DumpOptions& o) {
  std::vector<can::Filter> filters;
  for (const auto& t : o.filters) filters.push_back(parse_filter(t));
  if (!o.log.empty()) check_output_path(o.log, "--log");
  auto bus = can::open_bus(o.bus);
  if (!filters.empty()) bus->set_filters(filters);
  const std::string iface = o.iface.empty() ? default_iface(o.bus) : o.iface;
  std::optional<DumpLog> log;
  if (!o.log.empty()) log.emplace(o.log);
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
    if (!f) {
      if (log) log->add_nothing();
      continue;
    }
    const std::string line = can::format_log_line(*f, iface);
    if (!o.quiet) {
      std::fputs(line.c_str(), stdout);
      std::fputc('\n', stdout);
      std::fflush(stdout);
    }
    if (log) log->add(*f, iface, line);
    ++n;
  }
  if (log) log->finish();
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
  install_stop_handler();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (i && o.gap_s > 0) rt::sleep_until_ns(rt::monotonic_ns() + static_cast<std::int64_t>(o.gap_s * 1e9), &g_stop);
    if (g_stop.load()) return kExitFailed;
    if (!bus->send(frames[i])) {
      fmt::print(stderr, "lash can send: sending {} failed\n", o.frames[i]);
      return kExitFailed;
    }
  }
  return kExitOk;
}

}  // namespace

namespace can_cmd {

std::vector<Sub> add_bus_commands(CLI::App& sub) {
  auto dump = std::make_shared<DumpOptions>();
  auto* d = sub.add_subcommand("dump", "Print received frames as candump -L lines; optionally write a log");
  d->add_option("--bus", dump->bus, "Bus address: mem:NAME | udp:GROUP:PORT | socketcan:IFACE")->required();
  d->add_option("--count", dump->count, "Stop after N frames, N >= 1 (exit 1 if fewer arrive before --timeout)")
      ->check(CLI::Range(1L, 1000000000000L));
  d->add_option("--timeout", dump->timeout_s, "Stop after this many seconds [s], 0 < T <= 1e6 (default: run until a signal)")
      ->check(CLI::Range(1e-6, 1e6));
  d->add_option("--log", dump->log, "Also write the frames to this log on exit; format by extension: .asc, .blf, .trc, else candump -L");
  d->add_option("--iface", dump->iface, "Interface name written in the lines (default: the socketcan name or can0)");
  d->add_flag("--quiet", dump->quiet, "Do not print frames to stdout");
  d->add_option("--filter", dump->filters, "Accept only ID:MASK (hex; 8-digit id = 29-bit); repeatable");
  auto send = std::make_shared<SendOptions>();
  auto* s = sub.add_subcommand("send", "Send frames given as ID#HEX (cansend syntax)");
  s->add_option("--bus", send->bus, "Bus address")->required();
  s->add_option("--gap", send->gap_s, "Pause between frames [s], 0..3600")->check(CLI::Range(0.0, 3600.0))->capture_default_str();
  s->add_option("frames", send->frames, "Frames: 123#DEADBEEF, 12345678#00, 123#R")->required();
  return {{d, [=] { return run_dump(*dump); }}, {s, [=] { return run_send(*send); }}};
}

}  // namespace can_cmd

Command add_can(CLI::App& app) {
  auto* sub = app.add_subcommand("can", "CAN tools: dump, send, encode, decode, replay, dbc (docs/can.md)");
  sub->require_subcommand(1);
  std::vector<can_cmd::Sub> subs;
  for (auto&& group : {can_cmd::add_bus_commands(*sub), can_cmd::add_codec_commands(*sub),
                       can_cmd::add_dbc_commands(*sub), can_cmd::add_replay_command(*sub)})
    subs.insert(subs.end(), group.begin(), group.end());
  return {sub, [subs] {
            for (const auto& x : subs)
              if (x.app->parsed()) return x.run();
            return kExitBadInput;
          }};
}

}  // namespace lash::cli
