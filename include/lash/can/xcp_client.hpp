#pragma once
/// @file xcp_client.hpp
/// An XCP-on-CAN master (the tool's side, as CANape or INCA): connect, read and write objects
/// of an A2L (xcp_a2l.hpp) by name, and measure them with one dynamic DAQ list on event 0.
/// The library behind `lash xcp` and Python's lash.xcp.Client. Not real-time code.
///
/// Writes of more than 6 bytes go as one block in master block mode (DOWNLOAD with the whole
/// count, then DOWNLOAD_NEXT), so the slave checks and applies the value as one write; reads use
/// SET_MTA + UPLOAD (slave block mode answers a long UPLOAD in several packets).
/// A DAQ list's bytes are laid out over ODTs of at most 7 data bytes (the first holds the
/// 4-byte timestamp, so 3): a FLOAT64 may span two ODTs of the same list, which the slave
/// samples at the same event (one consistent sample).
#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lash/can/bus.hpp"
#include "lash/can/xcp.hpp"
#include "lash/io/error.hpp"

namespace lash::can::xcp {

/// A negative response (error packet) or no response within the timeout.
class XcpError : public Error {
 public:
  XcpError(const std::string& what, std::optional<Err> code) : Error(what), code_(code) {}
  std::optional<Err> code() const noexcept { return code_; }  ///< empty: timeout
 private:
  std::optional<Err> code_;
};

struct ConnectInfo {
  std::uint8_t resource = 0, comm_mode_basic = 0, max_cto = 0;
  std::uint16_t max_dto = 0;
  std::uint8_t protocol_version = 0, transport_version = 0;
};

/// One DAQ sample: the slave's timestamp [µs] and the values in the order asked for.
struct DaqSample {
  std::uint32_t timestamp_us = 0;
  std::vector<double> values;
};

class Client {
 public:
  /// `bus` should accept res_id (the caller sets its filters). timeout: per response.
  Client(Bus& bus, std::uint32_t cmd_id, std::uint32_t res_id,
         std::chrono::milliseconds timeout = std::chrono::milliseconds(500));

  /// Sends one command and returns the positive response (first packet); throws XcpError.
  std::vector<std::uint8_t> command(std::span<const std::uint8_t> cto);

  ConnectInfo connect();
  void disconnect();
  /// GET_ID of `type` (0 ASCII, 1 A2L name, 5 EPK) followed by its UPLOAD.
  std::string get_id(std::uint8_t type);
  std::vector<std::uint8_t> upload(std::uint32_t address, std::size_t n);
  void download(std::uint32_t address, std::span<const std::uint8_t> bytes);
  double read(const Object& o);
  void write(const Object& o, double value);

  /// Configures one DAQ list (event 0, timestamps) over `objects` and starts it.
  void start_daq(std::span<const Object> objects);
  /// The next complete sample, or nothing within `timeout`.
  std::optional<DaqSample> next_sample(std::chrono::milliseconds timeout);
  void stop_daq();
  std::uint64_t samples_incomplete() const noexcept { return incomplete_; }

 private:
  bool take_dto(const Frame& f);
  Bus& bus_;
  std::uint32_t cmd_id_, res_id_;
  std::chrono::milliseconds timeout_;
  // DAQ: the ODTs' entries as (object index, byte offset, size), the sample being assembled.
  struct Piece { std::size_t object; std::size_t offset; std::size_t size; };
  std::vector<std::vector<Piece>> odts_;
  std::vector<Object> daq_objects_;
  std::uint8_t first_pid_ = 0;
  std::vector<std::uint8_t> raw_;        ///< the sample's bytes, object after object
  std::vector<std::size_t> raw_at_;      ///< where each object starts in raw_
  std::size_t next_odt_ = 0;
  std::uint32_t ts_ = 0;
  std::deque<DaqSample> ready_;
  std::uint64_t incomplete_ = 0;
};

}  // namespace lash::can::xcp
