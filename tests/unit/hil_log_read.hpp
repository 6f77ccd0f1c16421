#pragma once
// A node's whole CSV log read into memory, the reference the HIL log tests (test_hil_logs,
// test_hil_report_logs) hold the library's streamed reading against: the library's LogReader
// (hil/handover.hpp) row by row into vectors.
#include <filesystem>
#include <vector>

#include "lash/hil/handover.hpp"

namespace lash::test {

/// Every row of the log and its loop record appended to log / records; what the reader read back
/// (a cut last line dropped and counted). Throws InputError as the reader does.
template <class Row>
hil::LogReadBack read_log(const std::filesystem::path& path, std::vector<Row>& log,
                          std::vector<rt::StepRecord>& records) {
  hil::LogReader<Row> in(path);
  Row l;
  rt::StepRecord r;
  while (in.next(l, r)) {
    log.push_back(l);
    records.push_back(r);
  }
  return in.read_back();
}

inline hil::LogReadBack read_master_log(const std::filesystem::path& path, std::vector<hil::MasterStepLog>& log,
                                        std::vector<rt::StepRecord>& records) {
  return read_log(path, log, records);
}
inline hil::LogReadBack read_slave_log(const std::filesystem::path& path, std::vector<hil::SlaveStepLog>& log,
                                       std::vector<rt::StepRecord>& records) {
  return read_log(path, log, records);
}

}  // namespace lash::test
