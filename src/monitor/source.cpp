#include "lash/monitor/source.hpp"

#include <time.h>

#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "lash/can/bus.hpp"
#include "lash/can/log.hpp"
#include "lash/io/error.hpp"

namespace lash::monitor {

double FrameSource::now_s() const noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

namespace {

class BusSource final : public FrameSource {
 public:
  explicit BusSource(const std::string& address) : bus_(can::open_bus(address)) {}
  Next next(can::Frame& out, std::chrono::nanoseconds wait) override {
    auto f = bus_->receive(wait);
    if (!f) return Next::idle;
    out = *f;
    return Next::frame;
  }
  std::uint64_t garbage() const noexcept override { return 0; }
  std::uint64_t bus_dropped() const noexcept override { return bus_->stats().dropped; }
  bool live() const noexcept override { return true; }

 private:
  std::unique_ptr<can::Bus> bus_;
};

/// Paces frames at their recorded times when asked to.
class Pacer {
 public:
  Pacer(bool on, const std::atomic<bool>* stop) : on_(on), stop_(stop) {}
  void wait_for(double t_s) {
    if (!on_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!started_) {
      started_ = true;
      t0_ = t_s;
      wall0_ = now;
      return;
    }
    const auto due = wall0_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  std::chrono::duration<double>(t_s - t0_));
    while (std::chrono::steady_clock::now() < due && !(stop_ && stop_->load())) {
      const auto slice = std::min<std::chrono::steady_clock::duration>(due - std::chrono::steady_clock::now(),
                                                                        std::chrono::milliseconds(100));
      std::this_thread::sleep_for(slice);
    }
  }

 private:
  bool on_;
  const std::atomic<bool>* stop_;
  bool started_ = false;
  double t0_ = 0.0;
  std::chrono::steady_clock::time_point wall0_;
};

/// candump -L, line by line.
class CandumpSource final : public FrameSource {
 public:
  CandumpSource(const std::string& path, bool realtime, const std::atomic<bool>* stop)
      : in_(path), pacer_(realtime, stop) {
    if (!in_) throw InputError(path, 0, "SOURCE", "cannot open the log");
  }
  Next next(can::Frame& out, std::chrono::nanoseconds) override {
    while (std::getline(in_, line_)) {
      std::string_view s(line_);
      while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
      std::size_t b = 0;
      while (b < s.size() && (s[b] == ' ' || s[b] == '\t')) ++b;
      s.remove_prefix(b);
      if (s.empty() || s.front() == '#') continue;
      auto e = can::parse_log_line(s, error_);
      if (!e) {
        ++garbage_;
        continue;
      }
      out = e->frame;
      pacer_.wait_for(out.timestamp_s);
      return Next::frame;
    }
    return Next::end;
  }
  std::uint64_t garbage() const noexcept override { return garbage_; }
  bool live() const noexcept override { return false; }

 private:
  std::ifstream in_;
  std::string line_, error_;
  std::uint64_t garbage_ = 0;
  Pacer pacer_;
};

/// ASC, BLF, TRC: read by the can module's readers (whole file), delivered one by one.
class WholeLogSource final : public FrameSource {
 public:
  WholeLogSource(const std::string& path, bool realtime, const std::atomic<bool>* stop) : pacer_(realtime, stop) {
    can::LogReadReport report;
    entries_ = can::read_log(path, &report);
    garbage_ = report.dropped;
  }
  Next next(can::Frame& out, std::chrono::nanoseconds) override {
    if (i_ >= entries_.size()) return Next::end;
    out = entries_[i_++].frame;
    pacer_.wait_for(out.timestamp_s);
    return Next::frame;
  }
  std::uint64_t garbage() const noexcept override { return garbage_; }
  bool live() const noexcept override { return false; }

 private:
  std::vector<can::LogEntry> entries_;
  std::size_t i_ = 0;
  std::uint64_t garbage_ = 0;
  Pacer pacer_;
};

}  // namespace

std::unique_ptr<FrameSource> open_source(const std::string& spec, bool realtime, const std::atomic<bool>* stop) {
  for (const char* scheme : {"udp:", "socketcan:", "mem:"})
    if (spec.rfind(scheme, 0) == 0) return std::make_unique<BusSource>(spec);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(spec, ec))
    throw InputError(spec, 0, "SOURCE", "no such log file (and not a bus address udp:… / socketcan:… / mem:…)");
  if (can::log_format_of(spec) == can::LogFormat::candump)
    return std::make_unique<CandumpSource>(spec, realtime, stop);
  return std::make_unique<WholeLogSource>(spec, realtime, stop);
}

}  // namespace lash::monitor
