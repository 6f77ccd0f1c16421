#pragma once
/// @file xcp.hpp
/// XCP on CAN (ASAM MCD-1 XCP V1.1, Part 2 "Protocol Layer", Part 3 "Transport Layer: CAN"):
/// the protocol engine of a slave, over classic CAN frames, with no knowledge of any node.
///
/// The slave owns a memory image of its objects (one table of measurements and calibration
/// objects, Object below) at absolute addresses; a calibration write (DOWNLOAD, and
/// DOWNLOAD_NEXT in master block mode) is checked against the objects' limits as a whole and
/// only then copied into the image, and the owner is told which bytes changed (on_write), so
/// that it can hand the new page to its real-time task at the next step boundary. DAQ lists
/// (dynamic configuration) are sampled by sample_event(): the owner first copies its
/// measurements into the image, then calls it for event channel 0.
///
/// Packets (Part 2, "the XCP packet" and "description of commands"): command CTO = [PID = command code, parameters…]; response
/// [0xFF, …]; error [0xFE, code, …]; DAQ DTO = [PID = absolute ODT number, (timestamp,
/// first ODT of a list only), data…]. Byte order Intel (COMM_MODE_BASIC bit 0 = 0), address
/// granularity BYTE, MAX_CTO = MAX_DTO = 8. In DISCONNECTED state the slave answers CONNECT
/// only and ignores every other command (Part 2, the slave's state machine; Vector's XCPlite does the same).
///
/// Not real-time code: the engine runs outside the control step (a node's XCP thread).
/// on_frame/sample_event do not allocate (the DAQ pools are fixed-size arrays).
#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "lash/can/frame.hpp"

namespace lash::can::xcp {

// ----------------------------------------------------------------------------- codes (Part 2, "description of commands")
namespace cmd {
inline constexpr std::uint8_t connect = 0xFF, disconnect = 0xFE, get_status = 0xFD, synch = 0xFC,
                              get_comm_mode_info = 0xFB, get_id = 0xFA, set_mta = 0xF6, upload = 0xF5,
                              short_upload = 0xF4, download = 0xF0, download_next = 0xEF, set_daq_ptr = 0xE2,
                              write_daq = 0xE1, set_daq_list_mode = 0xE0, start_stop_daq_list = 0xDE,
                              start_stop_synch = 0xDD, get_daq_processor_info = 0xDA,
                              get_daq_resolution_info = 0xD9, free_daq = 0xD6, alloc_daq = 0xD5, alloc_odt = 0xD4,
                              alloc_odt_entry = 0xD3;
}  // namespace cmd

inline constexpr std::uint8_t kPidResponse = 0xFF;  ///< positive response packet
inline constexpr std::uint8_t kPidError = 0xFE;     ///< error packet

/// Error codes (Part 2, "error handling", table of error codes).
enum class Err : std::uint8_t {
  cmd_synch = 0x00, cmd_busy = 0x10, daq_active = 0x11, pgm_active = 0x12, cmd_unknown = 0x20, cmd_syntax = 0x21,
  out_of_range = 0x22, write_protected = 0x23, access_denied = 0x24, access_locked = 0x25, page_not_valid = 0x26,
  mode_not_valid = 0x27, segment_not_valid = 0x28, sequence = 0x29, daq_config = 0x2A, memory_overflow = 0x30,
  generic = 0x31, verify = 0x32,
};
const char* to_string(Err e) noexcept;

/// Bits of CONNECT's RESOURCE and COMM_MODE_BASIC, GET_COMM_MODE_INFO's COMM_MODE_OPTIONAL,
/// GET_STATUS's SESSION_STATUS and GET_DAQ_PROCESSOR_INFO's DAQ_PROPERTIES (Part 2, standard and DAQ commands).
inline constexpr std::uint8_t kResourceCalPag = 0x01, kResourceDaq = 0x04;
inline constexpr std::uint8_t kCommModeSlaveBlock = 0x40, kCommModeOptional = 0x80;
inline constexpr std::uint8_t kCommOptionalMasterBlock = 0x01;
inline constexpr std::uint8_t kSessionDaqRunning = 0x40;
inline constexpr std::uint8_t kDaqPropDynamic = 0x01, kDaqPropTimestamp = 0x10;
/// SET_DAQ_LIST_MODE's MODE bits.
inline constexpr std::uint8_t kDaqModeTimestamp = 0x10, kDaqModePidOff = 0x20, kDaqModeDirectionStim = 0x02;
/// GET_DAQ_RESOLUTION_INFO's TIMESTAMP_MODE: size 4 bytes (bits 0–2), fixed (bit 3), unit 1 µs (bits 4–7 = 3).
inline constexpr std::uint8_t kTimestampMode = 0x04 | 0x08 | (3 << 4);
inline constexpr std::uint8_t kTimestampSize = 4;
/// GET_ID identification types (Part 2, GET_ID): ASCII text, A2L name without extension, EPK.
inline constexpr std::uint8_t kIdAscii = 0, kIdAsamName = 1, kIdEpk = 5;

inline constexpr std::uint8_t kMaxCto = 8, kMaxDto = 8;
inline constexpr std::uint8_t kMaxBs = 32;        ///< master block mode: most DOWNLOAD_NEXT packets per block
inline constexpr std::uint8_t kMaxOdtEntrySize = kMaxDto - 1;

// ----------------------------------------------------------------------------- the object table

/// A2L data types of the objects (ASAP2 "datatype").
enum class Type : std::uint8_t { u8, i8, u16, i16, u32, i32, f32, f64 };
std::size_t size_of(Type t) noexcept;
const char* a2l_name(Type t) noexcept;  ///< UBYTE, SBYTE, UWORD, SWORD, ULONG, SLONG, FLOAT32_IEEE, FLOAT64_IEEE
/// The value of `bytes` (Intel byte order, size_of(t) bytes) as a double.
double decode(Type t, std::span<const std::uint8_t> bytes) noexcept;
/// Writes v as type t (Intel byte order) into out (size_of(t) bytes); integers round to nearest.
void encode(Type t, double v, std::span<std::uint8_t> out) noexcept;

enum class Kind : std::uint8_t { measurement, characteristic };

/// One row of a node's table: a measurement (read, DAQ) or a calibration object (read, write).
struct Object {
  std::string name;
  Kind kind = Kind::measurement;
  Type type = Type::f64;
  std::string unit;
  double min = 0.0, max = 0.0;   ///< limits (A2L LowerLimit/UpperLimit); writes outside are refused
  std::uint32_t address = 0;     ///< ECU_ADDRESS
  std::string description;
  /// A characteristic whose values are names (compensation mode): COMPU_VTAB entries i → names[i];
  /// a write must then be an integer (a fraction is refused with ERR_OUT_OF_RANGE).
  std::vector<std::string> names;
};

/// The slave's fixed settings.
struct SlaveConfig {
  std::uint32_t cmd_id = 0x7F0;     ///< master → slave (CAN_ID_MASTER)
  std::uint32_t res_id = 0x7F1;     ///< slave → master (CAN_ID_SLAVE), responses and DTOs
  std::string epk = "lash";         ///< EPK (software version id), at epk_address; GET_ID type 5
  std::string ascii_id = "lash";    ///< GET_ID type 0
  std::string a2l_name = "master";  ///< GET_ID type 1
  std::uint32_t epk_address = 0x10000;  ///< the memory segment starts here
  std::vector<Object> objects;      ///< addresses inside [epk_address, epk_address + size)
  std::uint16_t max_daq = 8;        ///< DAQ lists
  std::uint16_t max_odt = 64;       ///< ODTs over all lists
  std::uint16_t max_entries = 256;  ///< ODT entries over all lists
  /// Throws std::invalid_argument on overlapping objects, a limit that is not finite or min > max,
  /// an EPK longer than 255 bytes or ids outside 11 bits.
  void validate() const;
};

/// The slave's protocol engine. Feed it every frame with cmd_id (on_frame); it sends
/// responses, error packets and DTOs through `send`.
class Slave {
 public:
  using Send = std::function<void(const Frame&)>;
  /// Called after a calibration write was checked and copied into the image: [address, +len).
  using OnWrite = std::function<void(std::uint32_t address, std::size_t len)>;

  /// Throws std::invalid_argument (SlaveConfig::validate). Not real-time safe.
  Slave(SlaveConfig config, Send send, OnWrite on_write = {});

  /// Handles one frame (others than cmd_id are ignored). Returns true when it was a command.
  bool on_frame(const Frame& f);
  /// Samples the DAQ lists of event channel `event` and sends their DTOs, with `timestamp` (4
  /// bytes, unit 1 µs) in the first ODT of each list in timestamp mode. No allocation.
  void sample_event(std::uint16_t event, std::uint32_t timestamp);

  /// The memory image: [epk_address, epk_address + size). The owner copies its measurements in
  /// (measurement(name) gives the address) before sample_event, and reads the calibration page.
  std::span<std::uint8_t> image() noexcept { return image_; }
  std::span<const std::uint8_t> image() const noexcept { return image_; }
  std::uint32_t base() const noexcept { return cfg_.epk_address; }
  const SlaveConfig& config() const noexcept { return cfg_; }
  /// The object named `name`, or nullptr.
  const Object* find(std::string_view name) const noexcept;
  /// Reads / writes an object's value in the image (no limit check; for the owner).
  double get(const Object& o) const noexcept;
  void set(const Object& o, double v) noexcept;

  bool connected() const noexcept { return connected_; }
  bool daq_running() const noexcept;
  std::uint64_t dtos_sent() const noexcept { return dtos_; }
  std::uint64_t commands() const noexcept { return commands_; }
  std::uint64_t errors() const noexcept { return errors_; }
  /// Drops the connection (DISCONNECT without a request: the owner's timeout), stops DAQ; the
  /// calibration page stays as it is.
  void disconnect() noexcept;

 private:
  struct Entry { std::uint32_t address = 0; std::uint8_t size = 0; };
  struct Odt { std::uint16_t first_entry = 0; std::uint8_t entries = 0; };
  struct DaqList {
    std::uint16_t first_odt = 0;
    std::uint8_t odts = 0;
    std::uint8_t mode = 0;
    std::uint16_t event = 0;
    std::uint8_t prescaler = 1;
    std::uint8_t count = 0;
    bool selected = false, running = false;
  };
  enum class AllocStage : std::uint8_t { freed, daq, odt, entry };

  void respond(std::span<const std::uint8_t> bytes);
  void error(Err e, std::span<const std::uint8_t> extra = {});
  void command(const Frame& f);
  void daq_command(const Frame& f, std::uint8_t code);
  bool in_image(std::uint32_t address, std::size_t len) const noexcept;
  Err check_write(std::uint32_t address, std::span<const std::uint8_t> bytes) const;
  void finish_download();

  SlaveConfig cfg_;
  Send send_;
  OnWrite on_write_;
  std::vector<std::uint8_t> image_;
  bool connected_ = false;
  std::uint32_t mta_ = 0;
  // A download block (master block mode): the bytes so far, the address and how many remain.
  std::array<std::uint8_t, 6u * (kMaxBs + 1)> block_{};
  std::size_t block_len_ = 0, block_left_ = 0;
  std::uint32_t block_address_ = 0;
  // DAQ pools.
  std::vector<DaqList> lists_;
  std::vector<Odt> odts_;
  std::vector<Entry> entries_;
  std::uint16_t n_lists_ = 0, n_odts_ = 0, n_entries_ = 0;
  AllocStage stage_ = AllocStage::freed;
  std::uint16_t ptr_list_ = 0, ptr_entry_ = 0, ptr_end_ = 0;
  bool ptr_valid_ = false;
  std::uint64_t dtos_ = 0, commands_ = 0, errors_ = 0;
};

/// Little-endian helpers for frame bytes.
inline std::uint16_t get_u16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
inline void put_u16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_u32(std::uint8_t* p, std::uint32_t v) noexcept {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

}  // namespace lash::can::xcp
