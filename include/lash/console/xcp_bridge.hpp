#pragma once
/// @file xcp_bridge.hpp
/// Feeds a console from an ECU measured and calibrated as CANape or INCA do: an XCP-on-CAN
/// client (can/xcp_client.hpp) on its own thread connects, reads the calibration objects,
/// starts one DAQ list over the measurements and pushes every sample into the console's Feed.
/// Tuning goes through the same client (the path of `lash xcp set`): write, read back, and
/// the ECU's error on a refusal. The ECU's real-time step is untouched: it already hands its
/// measurements to its XCP thread through a lock-free queue (hil/calibration.hpp: XcpLink).
/// Not real-time code.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <atomic>
#include <vector>

#include "lash/can/xcp.hpp"
#include "lash/can/xcp_a2l.hpp"
#include "lash/console/server.hpp"

namespace lash::console {

/// CLOCK_MONOTONIC (std::chrono::steady_clock) in seconds.
double steady_s() noexcept;

struct XcpBridgeOptions {
  std::string bus;                       ///< e.g. udp:239.74.163.2:43113
  can::xcp::A2lInfo info;                ///< ids
  std::vector<can::xcp::Object> objects; ///< MEASUREMENTs are scoped, CHARACTERISTICs tuned
  /// Name of the measurement holding the ECU's state (a number): changes become events.
  std::string state_signal = "state";
  std::function<std::string(double)> state_name;  ///< number → name (may be empty)
};

class XcpBridge {
 public:
  explicit XcpBridge(XcpBridgeOptions o);
  ~XcpBridge();
  XcpBridge(const XcpBridge&) = delete;
  XcpBridge& operator=(const XcpBridge&) = delete;

  /// The console's signals (the measurements, in DAQ order) and tunables (the characteristics).
  std::vector<std::string> signals() const;
  std::vector<TuneParam> params() const;

  /// Starts the thread (in the caller's network namespace) feeding `server`.
  void start(Server& server);
  void stop();  ///< idempotent
  /// steady_s() - (the ECU's DAQ time) at the earliest-arriving DAQ sample so far [s]: maps a time
  /// taken on this machine onto the ECU's clock (other taps of the bus). NaN before any sample.
  double ecu_time_offset_s() const noexcept { return offset_.load(std::memory_order_relaxed); }
  /// Thread-safe; blocks until the bridge thread did the write and read-back (≤ 3 s).
  TuneResult tune(const std::string& name, double value);

 private:
  struct Request {
    std::string name;
    double value = 0.0;
    bool done = false;
    TuneResult result;
  };
  void run(Server& server);
  XcpBridgeOptions o_;
  std::vector<can::xcp::Object> meas_, cal_;
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<std::shared_ptr<Request>> queue_;
  bool connected_ = false;
  std::atomic<bool> stop_{false};
  std::atomic<double> offset_{std::numeric_limits<double>::quiet_NaN()};
  std::thread thread_;
};

}  // namespace lash::console
