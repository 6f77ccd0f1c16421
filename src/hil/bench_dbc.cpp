// BenchLayout::from_dbc: the frame layout read from config/hydraulic_bench.dbc.
#include <string>

#include "lash/can/dbc.hpp"
#include "lash/hil/bench_layout.hpp"

namespace lash::hil {

BenchLayout BenchLayout::from_dbc(const std::filesystem::path& dbc_file) {
  const can::dbc::Database db = can::dbc::load_dbc(dbc_file);
  const std::string file = dbc_file.string();
  BenchLayout L;
  const auto& cmd = can::standard_message(db, "BenchCommand", file);
  const auto& sen = can::standard_message(db, "BenchSensors", file);
  static_cast<can::ccp::Layout&>(L) = can::ccp::Layout::from_dbc(db, file);
  L.command_id = cmd.id;
  L.sensors_id = sen.id;
  L.command_len = can::classic_length(cmd, file);
  L.sensors_len = can::classic_length(sen, file);
  L.solenoid_a = BitField::from_message(cmd, "SolenoidA_Current", file);
  L.solenoid_b = BitField::from_message(cmd, "SolenoidB_Current", file);
  L.restrictor = BitField::from_message(cmd, "RestrictorValve_Cmd", file);
  L.command_counter = BitField::from_message(cmd, "Command_Counter", file, 16, 16);
  L.pilot = BitField::from_message(sen, "PilotPressure_Duty", file, 16, 16);
  L.supply = BitField::from_message(sen, "SupplyPressure_Duty", file, 16, 16);
  L.sensor_counter = BitField::from_message(sen, "Sensor_Counter", file, 16, 16);
  return L;
}

}  // namespace lash::hil
