#include "lash/hil/xcp_server.hpp"

#include <chrono>
#include <cstdio>

namespace lash::hil {

namespace {
namespace xcp = can::xcp;

std::vector<xcp::Object> master_objects() {
  std::vector<xcp::Object> o;
  std::uint32_t a = kXcpCalibrationBase;
  for (const auto& f : calibration_fields()) {
    o.push_back({f.name, xcp::Kind::characteristic, xcp::Type::f64, f.unit, f.min, f.max, a, f.doc,
                 std::vector<std::string>(f.names.begin(), f.names.end())});
    a += 8;
  }
  a = kXcpMeasurementBase;
  for (const auto& f : measurement_fields()) {
    o.push_back({f.name, xcp::Kind::measurement, xcp::Type::f64, f.unit, f.min, f.max, a, f.doc, {}});
    a += 8;
  }
  return o;
}

CalibrationPage page_of(const xcp::Slave& s) {
  CalibrationPage p;
  for (const auto& f : calibration_fields()) p.*f.member = s.get(*s.find(f.name));
  return p;
}
}  // namespace

std::string master_epk() {
  // FNV-1a over the table's names, types and addresses.
  std::uint32_t h = 2166136261u;
  auto mix = [&](const std::string& s) {
    for (unsigned char c : s) h = (h ^ c) * 16777619u;
  };
  for (const auto& o : master_objects()) {
    mix(o.name);
    mix(xcp::a2l_name(o.type));
    mix(std::to_string(o.address));
  }
  char b[32];
  std::snprintf(b, sizeof b, "LASH_MASTER_%08X", h);
  return b;
}

xcp::SlaveConfig master_xcp_config(const BenchLayout& layout) {
  xcp::SlaveConfig c;
  c.cmd_id = layout.xcp_cmd_id;
  c.res_id = layout.xcp_res_id;
  c.epk = master_epk();
  c.ascii_id = "lash hil master";
  c.a2l_name = "master";
  c.epk_address = kXcpSegmentBase;
  c.objects = master_objects();
  return c;
}

xcp::A2lInfo master_a2l_info(const BenchLayout& layout, double step_s, std::uint32_t baudrate) {
  xcp::A2lInfo a;
  a.project = "lash";
  a.module = "master";
  a.comment = "lash emulated master ECU of the hydraulic bench (XCP on CAN)";
  a.cmd_id = layout.xcp_cmd_id;
  a.res_id = layout.xcp_res_id;
  a.baudrate = baudrate;
  a.epk = master_epk();
  a.epk_address = kXcpSegmentBase;
  a.segment_size = kXcpMeasurementBase + 8 * static_cast<std::uint32_t>(measurement_fields().size()) - kXcpSegmentBase;
  a.event_name = "step";
  a.event_period_s = step_s;
  return a;
}

XcpServer::XcpServer(const std::string& bus_address, const BenchLayout& layout, XcpLink& link,
                     const CalibrationPage& initial)
    : bus_(can::open_bus(bus_address)), link_(link) {
  bus_->set_filters({{layout.xcp_cmd_id, 0x7FF, false}});
  slave_ = std::make_unique<xcp::Slave>(
      master_xcp_config(layout), [this](const can::Frame& f) { bus_->send(f); },
      [this](std::uint32_t, std::size_t) {
        pending_ = page_of(*slave_);
        has_pending_ = true;
        if (link_.pages.push(pending_)) {
          has_pending_ = false;
          ++pages_;
        }
      });
  for (const auto& f : calibration_fields()) slave_->set(*slave_->find(f.name), initial.*f.member);
  thread_ = std::thread([this] { run(); });
}

XcpServer::~XcpServer() { stop(); }

void XcpServer::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void XcpServer::drain_samples() {
  MeasurementSample s;
  const auto fields = measurement_fields();
  while (link_.samples.pop(s)) {
    std::size_t i = 0;
    for (const auto& f : fields) {
      slave_->set(slave_->config().objects[calibration_fields().size() + i], s.page.*f.member);
      ++i;
    }
    slave_->sample_event(0, static_cast<std::uint32_t>(s.t_us));
    ++samples_;
  }
}

void XcpServer::run() {
  while (!stop_.load()) {
    // Wake every 1 ms while DAQ runs (samples go out within a millisecond of their step), else
    // only for commands or every 20 ms: an idle slave costs the host (and the step) nearly nothing.
    const auto wait = slave_->daq_running() ? std::chrono::milliseconds(1) : std::chrono::milliseconds(20);
    if (auto f = bus_->receive(wait)) slave_->on_frame(*f);
    drain_samples();
    if (has_pending_ && link_.pages.push(pending_)) {
      has_pending_ = false;
      ++pages_;
    }
  }
  drain_samples();
}

XcpServerStats XcpServer::stats() const {
  XcpServerStats s;
  s.commands = slave_->commands();
  s.errors = slave_->errors();
  s.dtos = slave_->dtos_sent();
  s.samples = samples_;
  s.samples_lost = link_.samples_lost.load();
  s.pages = pages_;
  return s;
}

}  // namespace lash::hil
