#include "cli_common.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace lash::cli {

int guarded(const std::function<int()>& fn) noexcept {
  try {
    return fn();
  } catch (const InputError& e) {
    std::fprintf(stderr, "lash: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {  // a config struct's validate(): values a person chose
    std::fprintf(stderr, "lash: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const Error& e) {
    std::fprintf(stderr, "lash: error: %s\n", e.what());
    return kExitFailed;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lash: internal error: %s\n", e.what());
    return kExitFailed;
  } catch (...) {
    std::fputs("lash: internal error: unknown exception\n", stderr);
    return kExitFailed;
  }
}

void write_columns_csv(const std::string& path, const std::vector<std::string>& names,
                       const std::vector<const std::vector<double>*>& cols) {
  AtomicFile f(path);
  std::string line;
  for (std::size_t i = 0; i < names.size(); ++i) line += (i ? "," : "") + names[i];
  line += '\n';
  f.stream() << line;
  const std::size_t n = cols.empty() ? 0 : cols[0]->size();
  for (std::size_t k = 0; k < n; ++k) {
    line.clear();
    for (std::size_t c = 0; c < cols.size(); ++c) {
      if (c) line += ',';
      append_double(line, (*cols[c])[k]);
    }
    line += '\n';
    f.stream() << line;
  }
  f.commit();
}

std::string source_dir() {
  if (const char* s = std::getenv("LASH_SOURCE_DIR")) return s;
  return LASH_SOURCE_DIR;
}

}  // namespace lash::cli
