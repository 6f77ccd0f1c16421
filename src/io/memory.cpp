#include "lash/io/memory.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <iterator>
#include <stdexcept>

#include <fmt/core.h>

namespace lash {

std::uint64_t memory_available_bytes() noexcept {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  std::uint64_t bytes = pages > 0 && page > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page)
                                              : UINT64_MAX;
  for (int which : {RLIMIT_AS, RLIMIT_DATA}) {
    rlimit r{};
    if (getrlimit(which, &r) == 0 && r.rlim_cur != RLIM_INFINITY) bytes = std::min<std::uint64_t>(bytes, r.rlim_cur);
  }
  return bytes;
}

std::string format_bytes(double bytes) {
  static constexpr const char* units[] = {"B", "kB", "MB", "GB", "TB", "PB", "EB"};
  if (!(bytes < 1e300)) return "more than 1e300 B";
  std::size_t u = 0;
  while (bytes >= 1000.0 && u + 1 < std::size(units)) {
    bytes /= 1000.0;
    ++u;
  }
  return fmt::format("{:.3g} {}", bytes, units[u]);
}

void require_memory(double bytes, const std::string& what) {
  const auto have = memory_available_bytes();
  if (!(bytes <= static_cast<double>(have)))
    throw std::invalid_argument(fmt::format("{} needs {} of memory; this machine has {}", what, format_bytes(bytes),
                                            format_bytes(static_cast<double>(have))));
}

}  // namespace lash
