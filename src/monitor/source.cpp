#include "lash/monitor/source.hpp"

#include <time.h>

#include <filesystem>
#include <thread>
#include <vector>

#include "lash/can/bus.hpp"
#include "lash/can/log.hpp"
#include "lash/can/log_reader.hpp"
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

/// A log file (candump, ASC, BLF, TRC), one frame at a time (can::LogReader: bounded memory).
class LogSource final : public FrameSource {
 public:
  LogSource(const std::string& path, bool realtime, const std::atomic<bool>* stop)
      : reader_(path, &report_), pacer_(realtime, stop) {
    reader_.keep_problems(0);  // counted, not kept
  }
  Next next(can::Frame& out, std::chrono::nanoseconds) override {
    if (!reader_.next(entry_)) return Next::end;
    out = entry_.frame;
    pacer_.wait_for(out.timestamp_s);
    return Next::frame;
  }
  std::uint64_t garbage() const noexcept override { return report_.dropped; }
  bool live() const noexcept override { return false; }

 private:
  can::LogReadReport report_;
  can::LogReader reader_;
  can::LogEntry entry_;
  Pacer pacer_;
};

}  // namespace

std::unique_ptr<FrameSource> open_source(const std::string& spec, bool realtime, const std::atomic<bool>* stop) {
  for (const char* scheme : {"udp:", "socketcan:", "mem:"})
    if (spec.rfind(scheme, 0) == 0) return std::make_unique<BusSource>(spec);
  std::error_code ec;
  if (!std::filesystem::exists(spec, ec) || std::filesystem::is_directory(spec, ec))
    throw InputError(spec, 0, "SOURCE", "no such log file (and not a bus address udp:… / socketcan:… / mem:…)");
  return std::make_unique<LogSource>(spec, realtime, stop);
}

}  // namespace lash::monitor
