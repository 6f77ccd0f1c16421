#pragma once
// The CCP DTO answer recorded from the bench (config/hil/ccp_connect.log), shared by the HIL tests.
#include <cstddef>
#include <cstdint>

#include "lash/can/frame.hpp"

namespace lash::test {

inline can::Frame recorded_dto() {
  can::Frame f;
  f.id = 0x7E1;
  f.len = 8;
  const std::uint8_t bytes[8] = {0xFF, 0x00, 0x00, 0x21, 0x07, 0x5A, 0x00, 0x03};
  for (int i = 0; i < 8; ++i) f.data[static_cast<std::size_t>(i)] = bytes[i];
  return f;
}

}  // namespace lash::test
