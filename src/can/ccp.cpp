#include "lash/can/ccp.hpp"

namespace lash::can::ccp {

Layout Layout::from_dbc(const dbc::Database& db, const std::string& file) {
  Layout L;
  const auto& cro = standard_message(db, "CCP_CRO", file);
  const auto& dto = standard_message(db, "CCP_DTO", file);
  L.cro_id = cro.id;
  L.dto_id = dto.id;
  L.cro_len = classic_length(cro, file);
  L.cro_cmd = BitField::from_message(cro, "CRO_CMD", file, 8, 8);
  L.cro_ctr = BitField::from_message(cro, "CRO_CTR", file, 8, 8);
  L.dto_pid = BitField::from_message(dto, "DTO_PID", file, 8, 8);
  L.dto_err = BitField::from_message(dto, "DTO_ERR", file, 8, 8);
  return L;
}

Frame Layout::pack_connect(std::uint8_t ctr) const noexcept {
  Frame f;
  f.id = cro_id;
  f.len = cro_len;
  cro_cmd.put(f, kConnect);
  cro_ctr.put(f, ctr);
  return f;
}

bool Layout::is_connect(const Frame& f) const noexcept {
  return !f.extended && !f.remote && f.id == cro_id && f.len >= 1 && cro_cmd.get(f) == kConnect;
}

bool Layout::is_connect_ack(const Frame& f) const noexcept {
  return !f.extended && !f.remote && f.id == dto_id && f.len >= 2 && dto_pid.get(f) == kCommandReturn &&
         dto_err.get(f) == kAcknowledge;
}

}  // namespace lash::can::ccp
