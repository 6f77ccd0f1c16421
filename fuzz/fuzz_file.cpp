// libFuzzer: the file readers a user feeds lash, one target per reader (LASH_FUZZ_READER picks
// it, fuzz/CMakeLists.txt builds fuzz_<reader>). The input is written to a file with the
// reader's extension and read as `lash` reads it. Any input reads, or is refused with a lash
// error (InputError, or SystemError for an unreadable file) or std::invalid_argument (a value
// a validated config refuses): the CLI's exit 2. Anything else escaping the reader — another
// exception, a crash, undefined behaviour, a leak — is a finding.
#include <fcntl.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "lash/control/gains_file.hpp"
#include "lash/experiments/campaign.hpp"
#include "lash/experiments/closed_loop_scenario.hpp"
#include "lash/experiments/scenario.hpp"
#include "lash/hil/node_run.hpp"
#include "lash/hil/schedule.hpp"
#include "lash/hil/settings.hpp"
#include "lash/identify/config_sources.hpp"
#include "lash/io/error.hpp"
#include "lash/io/table.hpp"
#include "lash/plant/plant_file.hpp"

namespace {

#define LASH_FUZZ_STR2(x) #x
#define LASH_FUZZ_STR(x) LASH_FUZZ_STR2(x)
constexpr const char* kExtension = LASH_FUZZ_STR(LASH_FUZZ_EXTENSION);

/// A file of this process in the temporary folder, rewritten for every input.
const std::filesystem::path& scratch() {
  static const std::filesystem::path p = std::filesystem::temp_directory_path() /
                                         ("lash-fuzz-" + std::to_string(::getpid()) + "." + kExtension);
  return p;
}

void write_file(const std::filesystem::path& p, const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(p.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
}

void read_it(const std::filesystem::path& p) {
  using namespace lash;
#if defined(LASH_FUZZ_TABLE)
  (void)read_table(p);
  TableOptions o;
  o.columns = {"0", "1"};
  o.strict = true;
  (void)read_table(p, o);
#elif defined(LASH_FUZZ_PLANT)
  (void)load_plant(p);
#elif defined(LASH_FUZZ_CAMPAIGN)
  (void)sweep::load_campaign(p);
#elif defined(LASH_FUZZ_SCENARIO)
  (void)load_scenario(p);
#elif defined(LASH_FUZZ_CLOSED_LOOP)
  (void)experiments::load_closed_loop_scenario(p);
#elif defined(LASH_FUZZ_ESTIMATOR)
  SettingsSources src;
  src.config_file = p.string();
  (void)resolve_settings(src, 0.005);
#elif defined(LASH_FUZZ_BENCH)
  (void)hil::load_bench_settings(p);
#elif defined(LASH_FUZZ_GAINS)
  (void)load_controller_config(p);
#elif defined(LASH_FUZZ_SCHEDULE)
  // The same file as master.csv and slave.csv: `hil simulate --schedule` reads both.
  (void)hil::read_schedule(p, p);
  (void)hil::read_master_trace(p);
#elif defined(LASH_FUZZ_RUN)
  // The hand-over a node writes to its session at the end of a run (node_run.hpp).
  const int fd = ::open(p.c_str(), O_RDONLY);
  if (fd < 0) std::abort();
  hil::MasterRun m;
  hil::SlaveRun s;
  (void)hil::read_run(fd, m);
  (void)hil::read_run(fd, s);
  ::close(fd);
#else
#error "LASH_FUZZ_<reader> not set"
#endif
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  write_file(scratch(), data, size);
  try {
    read_it(scratch());
  } catch (const lash::InputError&) {
  } catch (const lash::SystemError&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
