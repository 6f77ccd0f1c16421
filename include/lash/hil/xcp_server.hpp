#pragma once
/// @file xcp_server.hpp
/// The master ECU's XCP-on-CAN slave (docs/xcp.md): the protocol engine of can/xcp.hpp on its
/// own thread and its own socket on the bench's bus, with the master's object table
/// (calibration.hpp) as its memory map. The real-time step and this thread meet only through
/// an XcpLink (two lock-free SPSC queues): a calibration write that the engine accepted is
/// pushed as a complete page and taken by the step at its next start; the step pushes its
/// measurements, which this thread copies into the image and samples as DAQ event channel 0.
/// A tool that stops talking changes nothing: the last page stays in force. Not real-time code.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "lash/can/bus.hpp"
#include "lash/can/xcp.hpp"
#include "lash/can/xcp_a2l.hpp"
#include "lash/hil/bench_layout.hpp"
#include "lash/hil/calibration.hpp"

namespace lash::hil {

/// Where the master's objects sit in the XCP memory segment.
inline constexpr std::uint32_t kXcpSegmentBase = 0x00010000;      ///< EPK, then the GET_ID strings
inline constexpr std::uint32_t kXcpCalibrationBase = 0x00010100;  ///< calibration page, 8 bytes per object
inline constexpr std::uint32_t kXcpMeasurementBase = 0x00010200;  ///< measurements, 8 bytes per object

/// The EPK: names the table's layout (a hash of names, types and addresses), so that a tool
/// holding an A2L of another build sees the mismatch (GET_ID type 5 vs MOD_PAR EPK).
std::string master_epk();
/// The XCP slave configuration of the master: ids from the layout, objects from the tables.
can::xcp::SlaveConfig master_xcp_config(const BenchLayout& layout);
/// The A2L description of the master (`lash hil a2l`): the same objects, the bus's ids, the
/// step as the DAQ event's period.
can::xcp::A2lInfo master_a2l_info(const BenchLayout& layout, double step_s, std::uint32_t baudrate = 500000);

struct XcpServerStats {
  std::uint64_t commands = 0, errors = 0, dtos = 0, samples = 0, samples_lost = 0, pages = 0;
};

class XcpServer {
 public:
  /// Opens its own endpoint on `bus_address` (filter: the command id), writes `initial` into
  /// the image and starts the thread. Throws InputError when the bus cannot be opened.
  XcpServer(const std::string& bus_address, const BenchLayout& layout, XcpLink& link, const CalibrationPage& initial);
  ~XcpServer();
  XcpServer(const XcpServer&) = delete;
  XcpServer& operator=(const XcpServer&) = delete;
  /// Stops and joins the thread (idempotent); the queued samples are sampled first.
  void stop();
  XcpServerStats stats() const;

 private:
  void run();
  void drain_samples();
  std::unique_ptr<can::Bus> bus_;
  XcpLink& link_;
  std::unique_ptr<can::xcp::Slave> slave_;
  CalibrationPage pending_{};
  bool has_pending_ = false;
  std::uint64_t samples_ = 0, pages_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace lash::hil
