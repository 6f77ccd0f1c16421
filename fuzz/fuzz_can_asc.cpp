// libFuzzer: the ASC log reader, through the round-trip harness of fuzz_can_log_format.hpp.
#include "fuzz_can_log_format.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return lash::can::fuzz::round_trip(&lash::can::detail::parse_asc, &lash::can::detail::write_asc, lash::can::LogFormat::asc, data,
                                         size);
}
