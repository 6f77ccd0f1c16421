// libFuzzer: python-can udp_multicast datagram decoder. Never crashes; a datagram that
// decodes re-encodes to one that decodes to the same frame.
#include <cstdint>
#include <cstdlib>

#include "lash/can/datagram.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  lash::can::Frame f;
  if (lash::can::udp::decode_datagram({data, size}, f) != lash::can::udp::DecodeStatus::ok) return 0;
  if (!f.valid()) std::abort();
  std::uint8_t buf[512];
  const std::size_t n = lash::can::udp::encode_datagram(f, f.timestamp_s, buf);
  lash::can::Frame g;
  if (n == 0 || lash::can::udp::decode_datagram({buf, n}, g) != lash::can::udp::DecodeStatus::ok) std::abort();
  if (!lash::can::same_content(f, g) || f.fd != g.fd) std::abort();
  return 0;
}
