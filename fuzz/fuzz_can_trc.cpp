// libFuzzer: the TRC log reader, through the round-trip harness of fuzz_can_log_format.hpp.
#include "fuzz_can_log_format.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return lash::can::fuzz::round_trip(&lash::can::detail::parse_trc, &lash::can::detail::write_trc, lash::can::LogFormat::trc, data,
                                         size);
}
