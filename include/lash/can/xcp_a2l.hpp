#pragma once
/// @file xcp_a2l.hpp
/// ASAP2 (ASAM MCD-2 MC, "A2L") description of an XCP-on-CAN slave's object table, and a reader
/// of the subset lash writes (what `lash xcp` needs: objects, ids, EPK). Written: PROJECT /
/// MODULE with MOD_PAR (EPK, ADDR_EPK, MEMORY_SEGMENT), MOD_COMMON (BYTE_ORDER MSB_LAST, i.e.
/// Intel), one RECORD_LAYOUT per data type, one COMPU_METHOD per object (IDENTICAL, or TAB_VERB
/// with a COMPU_VTAB for named values), MEASUREMENTs and CHARACTERISTICs (VALUE), and
/// IF_DATA XCP with PROTOCOL_LAYER, DAQ (dynamic, one EVENT) and XCP_ON_CAN (CAN_ID_MASTER,
/// CAN_ID_SLAVE, BAUDRATE). Not real-time code.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "lash/can/xcp.hpp"

namespace lash::can::xcp {

struct A2lInfo {
  std::string project = "lash";
  std::string module = "master";
  std::string comment;
  std::uint32_t cmd_id = 0x7F0, res_id = 0x7F1;
  std::uint32_t baudrate = 500000;
  std::string epk;
  std::uint32_t epk_address = 0x10000;
  std::uint32_t segment_size = 0x1000;
  std::string event_name = "step";
  double event_period_s = 0.005;
  std::uint16_t max_daq = 8;
};

/// The A2L text. Object names must be A2L identifiers ([A-Za-z_][A-Za-z0-9_.]*).
std::string write_a2l(const A2lInfo& info, std::span<const Object> objects);

struct A2lFile {
  A2lInfo info;
  std::vector<Object> objects;
};
/// Reads MEASUREMENT / CHARACTERISTIC (name, type through its RECORD_LAYOUT or datatype,
/// address, limits, unit), MOD_PAR's EPK and ADDR_EPK, and XCP_ON_CAN's ids and baud rate.
/// Throws lash::InputError naming the file and line on a block it cannot read.
A2lFile read_a2l(const std::filesystem::path& file);
A2lFile parse_a2l(const std::string& text, const std::string& file = "<a2l>");

}  // namespace lash::can::xcp
