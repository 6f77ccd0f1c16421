// lash can replay | convert: parse, call lash::can, print.
#include <filesystem>
#include <memory>

#include <fmt/core.h>

#include "cmd_can.hpp"
#include "lash/can/bus.hpp"
#include "lash/can/log.hpp"
#include "lash/can/replay.hpp"
#include "lash/io/atomic_file.hpp"
#include "lash/io/error.hpp"

namespace lash::cli::can_cmd {
namespace {

/// replay and convert read their input twice: a pipe (or `-`) would be empty the second time.
void require_rereadable(const std::string& path, const char* who) {
  std::error_code ec;
  if (path == "-" || (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec)))
    throw InputError(path, 0, "", fmt::format("lash can {} reads the log twice (a check, then the work): give a regular "
                                              "file, not a pipe", who));
}

struct ReplayArgs {
  std::string bus;
  std::string log;
  double speed = 1.0;
  double spin_us = 2000.0;
  int rt_priority = 0;
};

int run_replay(const ReplayArgs& a) {
  // a first pass checks the log (drops reported, exit 2 when nothing is valid) and counts its
  // frames before the bus is opened; the second sends them as they are read
  require_rereadable(a.log, "replay");
  std::uint64_t total = 0;
  {
    ReportingReader check(a.log, "replay");
    for (can::LogEntry e; check.next(e);) {
    }
    total = check.finish();
  }
  can::LogReadReport again;
  can::LogReader reader(a.log, &again);
  reader.keep_problems(0);
  auto bus = can::open_bus(a.bus);
  can::ReplayOptions o;
  o.speed = a.speed;
  o.spin_ns = static_cast<std::int64_t>(a.spin_us * 1e3);
  o.fifo_priority = a.rt_priority;
  install_stop_handler();
  const auto r = can::replay(*bus, [&](can::LogEntry& e) { return reader.next(e); }, o, g_stop);
  if (!r.warning.empty()) fmt::print(stderr, "lash can replay: {}; continuing without\n", r.warning);
  if (r.interrupted) fmt::print(stderr, "lash can replay: stopped by a signal after {} of {} frames\n", r.sent + r.failed, total);
  if (r.failed) {
    fmt::print(stderr, "lash can replay: {} of {} frames failed to send\n", r.failed, total);
    return kExitFailed;
  }
  return kExitOk;
}

struct ConvertArgs {
  std::string in;
  std::string out;
};

int run_convert(const ConvertArgs& a) {
  // two passes, each one frame at a time: the first checks the log and finds its earliest time
  // (the relative formats write offsets from it), the second writes
  require_rereadable(a.in, "convert");
  can::LogTimes times;
  {
    ReportingReader check(a.in, "convert");
    for (can::LogEntry e; check.next(e);) times.add(e.frame.timestamp_s);
    check.finish();
  }
  can::LogReadReport again;
  can::LogReader reader(a.in, &again);
  reader.keep_problems(0);
  AtomicFile out(a.out);
  can::LogWriter writer(out.stream(), can::log_format_of(a.out), times, a.out);
  for (can::LogEntry e; reader.next(e);) writer.write(e);
  writer.finish();
  out.commit();
  fmt::print(stderr, "lash can convert: {} frames, {} -> {}\n", times.count, can::to_string(can::log_format_of(a.in)),
             can::to_string(can::log_format_of(a.out)));
  return kExitOk;
}

}  // namespace

namespace {
constexpr std::size_t kShown = 20;  // a binary file is thousands of bad "lines": the count says the rest
}  // namespace

ReportingReader::ReportingReader(const std::string& path, const char* who)
    : path_(path), who_(who), reader_(path, &report_) {
  reader_.keep_problems(kShown);
}

std::uint64_t ReportingReader::finish() {
  const auto& report = report_;
  for (std::size_t i = 0; i < report.problems.size() && i < kShown; ++i) {
    const std::string& p = report.problems[i];
    fmt::print(stderr, "lash can {}: dropped: {}\n", who_, bounded(p));
  }
  if (report.dropped > kShown)
    fmt::print(stderr, "lash can {}: ... and {} more dropped records\n", who_, report.dropped - kShown);
  const std::uint64_t n = reader_.count();
  if (report.dropped)
    fmt::print(stderr, "lash can {}: {} of {} records of {} dropped\n", who_, report.dropped, report.dropped + n, path_);
  if (n == 0 && report.dropped)
    throw InputError(path_, 0, "", "no valid frame: all " + std::to_string(report.dropped) + " records were dropped (not a CAN log?)");
  return n;
}

std::vector<Sub> add_replay_command(CLI::App& sub) {
  auto rep = std::make_shared<ReplayArgs>();
  auto* r = sub.add_subcommand("replay", "Send the frames of a log (.asc, .blf, .trc, candump) with their original timing (stops at SIGINT/SIGTERM)");
  r->add_option("--bus", rep->bus, "Bus address")->required();
  r->add_option("--speed", rep->speed, "Time scale, 1e-6..1e6 (2 = twice as fast)")->check(CLI::Range(1e-6, 1e6))->capture_default_str();
  r->add_option("--spin-us", rep->spin_us, "Busy-wait this long before each deadline [us], 0..1e6")
      ->check(CLI::Range(0.0, 1e6))->capture_default_str();
  r->add_option("--rt-priority", rep->rt_priority, "Run under SCHED_FIFO with this priority (1-99; 0 = default scheduler; needs privileges)")
      ->check(CLI::Range(0, 99))->capture_default_str();
  r->add_option("log", rep->log, "Log file: .asc, .blf, .trc or candump")->required();
  auto conv = std::make_shared<ConvertArgs>();
  auto* c = sub.add_subcommand("convert", "Convert a log between candump (-L), Vector ASC (.asc), Vector BLF (.blf) and PEAK TRC (.trc), by extension");
  c->add_option("in", conv->in, "Log to read")->required()->check(CLI::ExistingFile);
  c->add_option("out", conv->out, "Log to write (written atomically)")->required();
  return {{r, [=] { return run_replay(*rep); }}, {c, [=] { return run_convert(*conv); }}};
}

}  // namespace lash::cli::can_cmd
