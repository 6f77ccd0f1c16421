// The nodes' CSV logs read back (handover.hpp: LogReader): what a session
// reports from, and what it recovers when a node was killed before it could hand its run over.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "lash/hil/handover.hpp"
#include "lash/io/error.hpp"
#include "csv_lines.hpp"

namespace lash::hil {

using detail::LogLines;

namespace {

std::int64_t ns(double us) { return std::llround(us * 1e3); }

rt::StepRecord record_of(double t_s, double tet_us, double io_us, double wake_us) {
  return rt::StepRecord{std::llround(t_s * 1e9), ns(wake_us), ns(tet_us), ns(io_us)};
}

}  // namespace

// ----------------------------------------------------------------------------- row by row

namespace {
std::vector<std::string> master_columns() {
  std::vector<std::string> cols{"step",       "t_s",           "state",         "control_step",    "reference_kPa",
                                "measured_kPa", "sensor_counter", "sensor_fresh", "sensor_seq",     "dropped",
                                "current_mA", "integrator_mA", "command_counter", "tet_us",         "io_us",
                                "wake_latency_us"};
  for (const auto& f : calibration_fields()) cols.emplace_back(f.name);
  return cols;
}
const std::vector<std::string> kSlaveColumns{"step",         "t_s",          "state",        "command_counter",
                                             "command_fresh", "dropped",     "current_mA",   "pressure_kPa",
                                             "measured_kPa", "pilot_raw",    "tet_us",       "io_us",
                                             "wake_latency_us"};

// What differs between the two logs: their columns and how a row's values fill a Row. fill()
// returns the index of tet_us (io_us and wake_latency_us follow it).
std::vector<std::string> columns_of(const MasterStepLog*) { return master_columns(); }
std::vector<std::string> columns_of(const SlaveStepLog*) { return kSlaveColumns; }

std::size_t fill(MasterStepLog& l, const std::vector<double>& v) {
  static const auto fields = calibration_fields();
  l.step = static_cast<std::uint32_t>(v[0]);
  l.state = static_cast<NodeState>(static_cast<int>(v[2]));
  l.control_step = static_cast<std::int64_t>(v[3]);
  l.reference_kPa = v[4];
  l.measured_kPa = v[5];
  l.sensor_counter = static_cast<std::uint16_t>(v[6]);
  l.sensor_fresh = v[7] != 0.0;
  l.sensor_seq = static_cast<std::int64_t>(v[8]);
  l.dropped = static_cast<std::uint16_t>(v[9]);
  l.current_mA = v[10];
  l.integrator_mA = v[11];
  l.command_sent = v[12] >= 0.0;
  l.command_counter = l.command_sent ? static_cast<std::uint16_t>(v[12]) : 0;
  for (std::size_t j = 0; j < fields.size(); ++j) l.calibration.*fields[j].member = v[16 + j];
  return 13;
}

std::size_t fill(SlaveStepLog& l, const std::vector<double>& v) {
  l.step = static_cast<std::uint32_t>(v[0]);
  l.state = static_cast<NodeState>(static_cast<int>(v[2]));
  l.command_counter = static_cast<std::uint64_t>(v[3]);
  l.command_fresh = v[4] != 0.0;
  l.dropped = static_cast<std::uint16_t>(v[5]);
  l.current_mA = v[6];
  l.pressure_kPa = v[7];
  l.measured_kPa = v[8];
  l.pilot_raw = static_cast<std::uint16_t>(v[9]);
  return 10;
}
}  // namespace

template <class Row>
struct LogReader<Row>::Impl {
  explicit Impl(const std::filesystem::path& p) : in(p, columns_of(static_cast<const Row*>(nullptr))) {}
  LogLines in;
  std::vector<double> v;
};

template <class Row>
LogReader<Row>::LogReader(const std::filesystem::path& path) : impl_(std::make_unique<Impl>(path)) {}
template <class Row>
LogReader<Row>::~LogReader() = default;

template <class Row>
bool LogReader<Row>::next(Row& l, rt::StepRecord& record) {
  if (!impl_->in.next(impl_->v, rb_)) return false;
  const std::vector<double>& v = impl_->v;
  l = Row{};
  const std::size_t tet = fill(l, v);
  record = record_of(v[1], v[tet], v[tet + 1], v[tet + 2]);
  rb_.last_t_s = v[1];
  return true;
}

template class LogReader<MasterStepLog>;
template class LogReader<SlaveStepLog>;

}  // namespace lash::hil
