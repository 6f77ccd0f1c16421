#include "lash/hil/log_writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "lash/can/log.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"

namespace lash::hil {

namespace {
constexpr std::size_t kBatchBytes = std::size_t{1} << 20;

double us(std::int64_t ns) { return static_cast<double>(ns) * 1e-3; }

void header(std::string& out, const std::vector<std::string>& names) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i) out += ',';
    out += names[i];
  }
  out += '\n';
}

void row(std::string& out, std::initializer_list<double> values) {
  bool first = true;
  for (double v : values) {
    if (!first) out += ',';
    first = false;
    append_double(out, v);
  }
}
}  // namespace

NodeLogWriter::NodeLogWriter(Node node, LogPaths paths, std::size_t max_steps)
    : node_(node),
      ring_(std::make_unique<rt::SpscQueue<LogItem, kLogRing>>()),
      tet_(max_steps),
      io_(max_steps),
      cycle_(max_steps),
      wake_(max_steps) {
  auto open = [](File& f, const std::filesystem::path& p) {
    if (p.empty()) return;
    f.path = p.string();
    f.fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (f.fd < 0) throw SystemError("cannot open the log " + f.path + " for writing: " + std::strerror(errno));
  };
  open(csv_, paths.csv);
  open(events_, paths.events);
  open(bus_, paths.bus_log);
  if (node_ == Node::master) {
    std::vector<std::string> names{"step", "t_s", "state", "control_step", "reference_kPa", "measured_kPa",
                                   "sensor_counter", "sensor_fresh", "sensor_seq", "dropped", "current_mA",
                                   "integrator_mA", "command_counter", "tet_us", "io_us", "wake_latency_us"};
    for (const auto& f : calibration_fields()) names.emplace_back(f.name);  // the step's calibration page
    header(csv_.pending, names);
    events_.pending = "step,t_s,event,from,to,name,old,new\n";
  } else {
    header(csv_.pending, {"step", "t_s", "state", "command_counter", "command_fresh", "dropped", "current_mA",
                          "pressure_kPa", "measured_kPa", "pilot_raw", "tet_us", "io_us", "wake_latency_us"});
    events_.pending = "step,t_s,event,from,to\n";
  }
  pending_events_.reserve(64);
  pending_calibration_.reserve(64);
  write_all();  // the headers: a node killed before its first step leaves readable, empty logs
  thread_ = std::thread([this] { run(); });
}

NodeLogWriter::~NodeLogWriter() {
  try {
    stop();
  } catch (...) {
  }
}

void NodeLogWriter::run() noexcept {
  auto last = std::chrono::steady_clock::now();
  while (!done_.load(std::memory_order_acquire)) {
    try {
      drain();
      const auto now = std::chrono::steady_clock::now();
      if (now - last >= kLogFlushPeriod) {
        write_all();
        last = now;
      }
    } catch (const std::exception& e) {  // formatting ran out of memory: stop writing, say so
      if (error_.empty()) error_ = e.what();
    }
    std::this_thread::sleep_for(kLogPollPeriod);
  }
}

void NodeLogWriter::drain() {
  LogItem item;
  while (ring_->pop(item)) {
    take(item);
    for (File* f : {&csv_, &events_, &bus_})
      if (f->pending.size() >= kBatchBytes) write_out(*f);
  }
}

void NodeLogWriter::flush_events(std::uint32_t) {
  // State events first, then the calibration writes of the same step (write_events' order).
  const bool master = node_ == Node::master;
  for (const auto& e : pending_events_) {
    std::string& o = events_.pending;
    o += std::to_string(e.step);
    o += ',';
    o += format_double(e.t_s);
    o += ',';
    o += to_string(e.kind);
    o += ',';
    o += to_string(e.from);
    o += ',';
    o += to_string(e.to);
    o += master ? ",,,\n" : "\n";
    ++stats_.events;
  }
  const auto fields = calibration_fields();
  for (const auto& c : pending_calibration_) {
    std::string& o = events_.pending;
    o += std::to_string(c.step);
    o += ',';
    o += format_double(c.t_s);
    o += ",calibration,,,";
    o += fields[c.field].name;
    o += ',';
    o += format_double(c.old_value);
    o += ',';
    o += format_double(c.new_value);
    o += '\n';
    ++stats_.events;
  }
  pending_events_.clear();
  pending_calibration_.clear();
}

void NodeLogWriter::count_step(const rt::StepRecord& r) noexcept {
  ++stats_.rows;
  stats_.last_t_s = static_cast<double>(r.release_ns) * 1e-9;
  tet_.add(us(r.tet_ns));
  io_.add(us(r.io_ns));
  cycle_.add(us(r.io_ns + r.tet_ns));
  wake_.add(us(r.wake_latency_ns));
}

void NodeLogWriter::take(const LogItem& item) {
  if (const auto* m = std::get_if<MasterRow>(&item)) {
    flush_events(m->log.step);
    const auto& l = m->log;
    const auto& r = m->rec;
    std::string& o = csv_.pending;
    row(o, {static_cast<double>(l.step), static_cast<double>(r.release_ns) * 1e-9, static_cast<double>(l.state),
            static_cast<double>(l.control_step), l.reference_kPa, l.measured_kPa, static_cast<double>(l.sensor_counter),
            l.sensor_fresh ? 1.0 : 0.0, static_cast<double>(l.sensor_seq), static_cast<double>(l.dropped), l.current_mA,
            l.integrator_mA, l.command_sent ? static_cast<double>(l.command_counter) : -1.0, us(r.tet_ns), us(r.io_ns),
            us(r.wake_latency_ns)});
    for (const auto& f : calibration_fields()) {
      o += ',';
      append_double(o, l.calibration.*f.member);
    }
    o += '\n';
    count_step(r);
  } else if (const auto* s = std::get_if<SlaveRow>(&item)) {
    flush_events(s->log.step);
    const auto& l = s->log;
    const auto& r = s->rec;
    row(csv_.pending, {static_cast<double>(l.step), static_cast<double>(r.release_ns) * 1e-9,
                       static_cast<double>(l.state), static_cast<double>(l.command_counter),
                       l.command_fresh ? 1.0 : 0.0, static_cast<double>(l.dropped), l.current_mA, l.pressure_kPa,
                       l.measured_kPa, static_cast<double>(l.pilot_raw), us(r.tet_ns), us(r.io_ns),
                       us(r.wake_latency_ns)});
    csv_.pending += '\n';
    count_step(r);
  } else if (const auto* f = std::get_if<LoggedFrame>(&item)) {
    if (bus_.fd < 0) return;
    can::Frame g = f->frame;
    // Sent frames carry the loop time of their step; received ones the bus's wall-clock receive
    // time (kernel timestamp), which must not get the epoch a second time.
    if (f->sent) g.timestamp_s += epoch_s_.load(std::memory_order_relaxed);
    bus_.pending += can::format_log_line(g, "hil0");
    bus_.pending += '\n';
    ++stats_.frames;
  } else if (const auto* e = std::get_if<NodeEvent>(&item)) {
    pending_events_.push_back(*e);
  } else if (const auto* c = std::get_if<CalibrationEvent>(&item)) {
    pending_calibration_.push_back(*c);
  }
}

void NodeLogWriter::write_out(File& f) {
  if (f.fd < 0 || f.pending.empty()) {
    f.pending.clear();
    return;
  }
  const char* p = f.pending.data();
  std::size_t n = f.pending.size();
  while (n > 0) {
    const ssize_t w = ::write(f.fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      if (error_.empty()) error_ = "cannot write the log " + f.path + ": " + std::strerror(errno);
      ::close(f.fd);
      f.fd = -1;
      break;
    }
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  ++stats_.writes;
  f.pending.clear();
}

void NodeLogWriter::write_all() {
  write_out(csv_);
  write_out(events_);
  write_out(bus_);
}

void NodeLogWriter::stop() {
  if (stopped_) return;
  stopped_ = true;
  done_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  drain();
  flush_events(0);
  write_all();
  for (File* f : {&csv_, &events_, &bus_})
    if (f->fd >= 0) {
      ::close(f->fd);
      f->fd = -1;
    }
  stats_.ring_full = ring_full_.load();
  if (!error_.empty()) throw SystemError(error_);
}

LoopSummaries NodeLogWriter::loop() const { return {tet_.result(), io_.result(), cycle_.result(), wake_.result()}; }

}  // namespace lash::hil
