#pragma once
/// @file handover.hpp
/// What a node process leaves for the session that started it: its run's statistics, handed
/// over in an inherited memory file when it stops, and its logs on disk, read back (also when
/// the node was killed and handed nothing over). Not real-time code.
#include <filesystem>
#include <memory>
#include <vector>

#include "lash/hil/node_run.hpp"

namespace lash::hil {

/// A node's CSV log read back (a killed node's included): the rows and their loop records.
/// A last line cut short is dropped (cut_lines); a value that is not a number is an InputError
/// naming file, line and column. Not real-time code.
struct LogReadBack {
  std::size_t rows = 0;
  std::size_t cut_lines = 0;   ///< an unfinished last line (the node was killed mid-write)
  double last_t_s = -1.0;      ///< t_s of the last row [s]; −1: no row
};
/// A node's CSV log read row by row in constant memory, Row = MasterStepLog (master.csv) or
/// SlaveStepLog (slave.csv): next() fills the next whole row and its loop record, false at the
/// end (a last line cut short is counted in read_back().cut_lines, not returned). Throws
/// InputError as LogReadBack says.
template <class Row>
class LogReader {
 public:
  explicit LogReader(const std::filesystem::path& path);
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;
  bool next(Row& row, rt::StepRecord& record);
  const LogReadBack& read_back() const noexcept { return rb_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  LogReadBack rb_;
};
extern template class LogReader<MasterStepLog>;
extern template class LogReader<SlaveStepLog>;
using MasterLogReader = LogReader<MasterStepLog>;
using SlaveLogReader = LogReader<SlaveStepLog>;

/// Binary hand-over of a run from a node process to its session (same executable on both
/// sides): write at the end of the run to an inherited descriptor, read back after it exited.
/// read_* returns false when the node wrote nothing (it was killed) or the data are cut short.
void write_run(int fd, const SlaveRun& r);
void write_run(int fd, const MasterRun& r);
bool read_run(int fd, SlaveRun& r);
bool read_run(int fd, MasterRun& r);

}  // namespace lash::hil
