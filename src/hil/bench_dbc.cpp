// BenchLayout::from_dbc: the frame layout read from config/hydraulic_bench.dbc.
#include <cstdio>
#include <stdexcept>

#include "lash/can/dbc.hpp"
#include "lash/hil/bench_layout.hpp"
#include "lash/io/error.hpp"

namespace lash::hil {
namespace {

struct Reader {
  const can::dbc::Database& db;
  std::string file;

  const can::dbc::Message& message(const char* name) const {
    const auto* m = db.message(std::string_view(name));
    if (m == nullptr) throw InputError(file, 0, name, std::string("the DBC has no message ") + name);
    if (m->extended) throw InputError(file, 0, name, std::string(name) + " must use an 11-bit identifier (CAN 2.0A)");
    return *m;
  }
  BitField field(const can::dbc::Message& m, const char* name, std::uint32_t min_bits = 1,
                 std::uint32_t max_bits = 64) const {
    const auto* s = m.signal(name);
    const std::string where = m.name + "." + name;
    if (s == nullptr) throw InputError(file, 0, where, "the DBC has no signal " + where);
    if (s->is_signed || s->value_type != can::dbc::ValueType::integer)
      throw InputError(file, 0, where, "must be an unsigned integer signal");
    if (s->length < min_bits || s->length > max_bits)
      throw InputError(file, 0, where,
                       "must be " + std::to_string(min_bits) + ".." + std::to_string(max_bits) + " bits long");
    if (s->factor == 0.0) throw InputError(file, 0, where, "factor must not be 0");
    try {
      return BitField(*s);
    } catch (const std::invalid_argument& e) {
      throw InputError(file, 0, where, e.what());
    }
  }
};

// An E2E CRC signal: one whole byte (8 bits, Intel, byte-aligned) inside the frame.
BitField crc_field(const Reader& r, const can::dbc::Message& m, const char* name) {
  BitField f = r.field(m, name, 8, 8);
  const auto& s = f.signal();
  if (s.byte_order != can::dbc::ByteOrder::intel || s.start_bit % 8 != 0 || s.start_bit / 8 >= m.size)
    throw InputError(r.file, 0, m.name + "." + name, "an E2E CRC must be one whole byte of the frame (start bit a multiple of 8, Intel)");
  return f;
}

std::uint8_t len_of(const can::dbc::Message& m, const std::string& file) {
  if (m.size > 8) throw InputError(file, 0, m.name, "classic CAN frames carry at most 8 bytes");
  return static_cast<std::uint8_t>(m.size);
}

}  // namespace

BenchLayout BenchLayout::from_dbc(const std::filesystem::path& dbc_file) {
  const can::dbc::Database db = can::dbc::load_dbc(dbc_file);
  const Reader r{db, dbc_file.string()};
  BenchLayout L;
  const auto& cmd = r.message("BenchCommand");
  const auto& sen = r.message("BenchSensors");
  const auto& cro = r.message("CCP_CRO");
  const auto& dto = r.message("CCP_DTO");
  L.command_id = cmd.id;
  L.sensors_id = sen.id;
  L.cro_id = cro.id;
  L.dto_id = dto.id;
  L.command_len = len_of(cmd, r.file);
  L.sensors_len = len_of(sen, r.file);
  L.cro_len = len_of(cro, r.file);
  L.solenoid_a = r.field(cmd, "SolenoidA_Current");
  L.solenoid_b = r.field(cmd, "SolenoidB_Current");
  L.restrictor = r.field(cmd, "RestrictorValve_Cmd");
  L.command_counter = r.field(cmd, "Command_Counter", 4, 16);
  L.command_crc = crc_field(r, cmd, "Command_CRC");
  L.pilot = r.field(sen, "PilotPressure_Duty", 16, 16);
  L.supply = r.field(sen, "SupplyPressure_Duty", 16, 16);
  L.sensor_counter = r.field(sen, "Sensor_Counter", 16, 16);
  L.sensors_crc = crc_field(r, sen, "Sensor_CRC");
  L.cro_cmd = r.field(cro, "CRO_CMD", 8, 8);
  L.cro_ctr = r.field(cro, "CRO_CTR", 8, 8);
  L.dto_pid = r.field(dto, "DTO_PID", 8, 8);
  L.dto_err = r.field(dto, "DTO_ERR", 8, 8);
  return L;
}

}  // namespace lash::hil
