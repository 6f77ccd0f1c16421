// BenchLayout::from_dbc: the frame layout read from config/hydraulic_bench.dbc.
#include <string>

#include "lash/can/dbc.hpp"
#include "lash/hil/bench_layout.hpp"

#include "lash/io/error.hpp"

namespace lash::hil {
namespace {

// An E2E CRC signal: one whole byte (8 bits, Intel, byte-aligned) inside the frame.
BitField crc_field(const can::dbc::Message& m, const char* name, const std::string& file) {
  BitField f = BitField::from_message(m, name, file, 8, 8);
  const auto& s = f.signal();
  if (s.byte_order != can::dbc::ByteOrder::intel || s.start_bit % 8 != 0 || s.start_bit / 8 >= m.size)
    throw InputError(file, 0, m.name + "." + name,
                     "an E2E CRC must be one whole byte of the frame (start bit a multiple of 8, Intel)");
  return f;
}

}  // namespace

BenchLayout BenchLayout::from_dbc(const std::filesystem::path& dbc_file) {
  const can::dbc::Database db = can::dbc::load_dbc(dbc_file);
  const std::string file = dbc_file.string();
  BenchLayout L;
  const auto& cmd = can::standard_message(db, "BenchCommand", file);
  const auto& sen = can::standard_message(db, "BenchSensors", file);
  static_cast<can::ccp::Layout&>(L) = can::ccp::Layout::from_dbc(db, file);
  L.command_id = cmd.id;
  L.sensors_id = sen.id;
  // XCP on CAN (optional messages; defaults 0x7F0 / 0x7F1): the calibration tool's commands
  // and the master ECU's responses and DAQ packets.
  if (db.message("XCP_CMD")) L.xcp_cmd_id = can::standard_message(db, "XCP_CMD", file).id;
  if (db.message("XCP_RES")) L.xcp_res_id = can::standard_message(db, "XCP_RES", file).id;
  L.command_len = can::classic_length(cmd, file);
  L.sensors_len = can::classic_length(sen, file);
  L.solenoid_a = BitField::from_message(cmd, "SolenoidA_Current", file);
  L.solenoid_b = BitField::from_message(cmd, "SolenoidB_Current", file);
  L.restrictor = BitField::from_message(cmd, "RestrictorValve_Cmd", file);
  L.command_counter = BitField::from_message(cmd, "Command_Counter", file, 4, 16);
  L.command_crc = crc_field(cmd, "Command_CRC", file);
  L.pilot = BitField::from_message(sen, "PilotPressure_Duty", file, 16, 16);
  L.supply = BitField::from_message(sen, "SupplyPressure_Duty", file, 16, 16);
  L.sensor_counter = BitField::from_message(sen, "Sensor_Counter", file, 16, 16);
  L.sensors_crc = crc_field(sen, "Sensor_CRC", file);
  L.refresh_checks();
  return L;
}

}  // namespace lash::hil
