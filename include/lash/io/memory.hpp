#pragma once
/// @file memory.hpp
/// How much memory a run may take, checked before it starts: an option that would need more
/// than the machine has is refused with the figure (exit 2), never a std::bad_alloc or the
/// kernel's OOM killer later. Not real-time safe.
#include <cstdint>
#include <string>

namespace lash {

/// The memory this process can have [bytes]: the machine's physical memory (sysconf), lowered to
/// RLIMIT_AS or RLIMIT_DATA when one is set lower.
std::uint64_t memory_available_bytes() noexcept;

/// "1.5 GB", "800 GB", "64 kB" (decimal units, 3 significant digits).
std::string format_bytes(double bytes);

/// Throws std::invalid_argument("<what> needs <X> of memory; this machine has <Y>") when
/// `bytes` (which may be huge or inf) exceeds memory_available_bytes().
void require_memory(double bytes, const std::string& what);

}  // namespace lash
