// lash xcp get|set|daq|info (an XCP-on-CAN master over an A2L) and lash hil a2l: parse, call
// lash::can::xcp / lash::hil, print. docs/xcp.md.
#include <chrono>
#include <cstdio>
#include <memory>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "cmd_hil.hpp"
#include "lash/can/bus.hpp"
#include "lash/can/xcp_a2l.hpp"
#include "lash/can/xcp_client.hpp"
#include "lash/hil/xcp_server.hpp"

namespace lash::cli {
namespace {
namespace xcp = can::xcp;

struct XcpArgs {
  std::string bus = "udp:239.74.163.2:43113";
  std::string a2l;
  double timeout_ms = 500.0;
  std::string name;
  double value = 0.0;
  std::vector<std::string> names;
  double duration = 1.0;
  std::string csv;
};

const xcp::Object& object(const xcp::A2lFile& a, const std::string& file, const std::string& name) {
  for (const auto& o : a.objects)
    if (o.name == name) return o;
  std::string known;
  for (const auto& o : a.objects) known += (known.empty() ? "" : ", ") + o.name;
  throw InputError(file, 0, name, "no MEASUREMENT or CHARACTERISTIC of that name (known: " + known + ")");
}

struct Session {
  xcp::A2lFile a2l;
  std::unique_ptr<can::Bus> bus;
  std::unique_ptr<xcp::Client> client;
  explicit Session(const XcpArgs& x) : a2l(xcp::read_a2l(x.a2l)), bus(can::open_bus(x.bus)) {
    bus->set_filters({{a2l.info.res_id, 0x7FF, false}});
    client = std::make_unique<xcp::Client>(*bus, a2l.info.cmd_id, a2l.info.res_id,
                                           std::chrono::milliseconds(static_cast<long>(x.timeout_ms)));
    client->connect();
  }
  ~Session() {
    try {
      client->disconnect();
    } catch (const std::exception&) {  // the slave is gone: nothing to close
    }
  }
};

// An error packet names the command that failed; say what the person asked for.
[[noreturn]] void refused(const std::string& what, const xcp::XcpError& e) {
  const auto c = e.code();
  throw xcp::XcpError(c ? fmt::format("xcp: {}: {} (0x{:02X})", what, xcp::to_string(*c), static_cast<int>(*c))
                        : std::string(e.what()),
                      c);
}

int run_get(const XcpArgs& x) {
  Session s(x);
  const auto& o = object(s.a2l, x.a2l, x.name);
  fmt::print("{} = {}{}\n", o.name, s.client->read(o), o.unit.empty() ? "" : " " + o.unit);
  return kExitOk;
}

int run_set(const XcpArgs& x) {
  Session s(x);
  const auto& o = object(s.a2l, x.a2l, x.name);
  if (o.kind != xcp::Kind::characteristic)
    throw InputError(x.a2l, 0, o.name, "a MEASUREMENT cannot be written; CHARACTERISTICs can");
  try {
    s.client->write(o, x.value);
  } catch (const xcp::XcpError& e) {
    refused(fmt::format("set {} {} (limits {} .. {})", o.name, x.value, o.min, o.max), e);
  }
  fmt::print("{} = {}{}\n", o.name, s.client->read(o), o.unit.empty() ? "" : " " + o.unit);
  return kExitOk;
}

int run_daq(const XcpArgs& x) {
  Session s(x);
  std::vector<xcp::Object> objs;
  for (const auto& n : x.names) objs.push_back(object(s.a2l, x.a2l, n));
  s.client->start_daq(objs);
  std::vector<std::vector<double>> cols(objs.size() + 1);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(x.duration);
  while (std::chrono::steady_clock::now() < end) {
    auto smp = s.client->next_sample(std::chrono::milliseconds(100));
    if (!smp) continue;
    cols[0].push_back(smp->timestamp_us);
    for (std::size_t i = 0; i < objs.size(); ++i) cols[i + 1].push_back(smp->values[i]);
  }
  s.client->stop_daq();
  std::vector<std::string> names{"timestamp_us"};
  for (const auto& o : objs) names.push_back(o.name);
  std::vector<const std::vector<double>*> ptrs;
  for (const auto& c : cols) ptrs.push_back(&c);
  if (!x.csv.empty()) write_columns_csv(x.csv, names, ptrs);
  fmt::print("daq: {} samples of {} in {} s ({} incomplete){}\n", cols[0].size(), objs.size(), x.duration,
             s.client->samples_incomplete(), x.csv.empty() ? "" : " -> " + x.csv);
  if (!cols[0].empty()) {
    fmt::print("last sample (t = {} us):", cols[0].back());
    for (std::size_t i = 0; i < objs.size(); ++i) fmt::print(" {} = {}", objs[i].name, cols[i + 1].back());
    fmt::print("\n");
  }
  return cols[0].empty() ? kExitFailed : kExitOk;
}

int run_info(const XcpArgs& x) {
  xcp::A2lFile a = xcp::read_a2l(x.a2l);
  auto bus = can::open_bus(x.bus);
  bus->set_filters({{a.info.res_id, 0x7FF, false}});
  xcp::Client c(*bus, a.info.cmd_id, a.info.res_id, std::chrono::milliseconds(static_cast<long>(x.timeout_ms)));
  const xcp::ConnectInfo i = c.connect();
  fmt::print("connected on {}: CAN_ID_MASTER 0x{:X}, CAN_ID_SLAVE 0x{:X}\n", x.bus, a.info.cmd_id, a.info.res_id);
  fmt::print("RESOURCE 0x{:02X} (CAL/PAG {}, DAQ {}), COMM_MODE_BASIC 0x{:02X} (Intel, slave block mode {}), "
             "MAX_CTO {}, MAX_DTO {}, protocol {}, transport {}\n",
             i.resource, (i.resource & xcp::kResourceCalPag) ? "yes" : "no", (i.resource & xcp::kResourceDaq) ? "yes" : "no",
             i.comm_mode_basic, (i.comm_mode_basic & xcp::kCommModeSlaveBlock) ? "yes" : "no", i.max_cto, i.max_dto,
             i.protocol_version, i.transport_version);
  const std::string epk = c.get_id(xcp::kIdEpk);
  fmt::print("ECU: {}; EPK {} ({} the A2L's EPK {})\n", c.get_id(xcp::kIdAscii), epk,
             epk == a.info.epk ? "matches" : "DOES NOT MATCH", a.info.epk);
  for (const auto& o : a.objects)
    fmt::print("  {:<12} {:<22} {:<12} [{} .. {}] at 0x{:X}\n",
               o.kind == xcp::Kind::characteristic ? "CHARACTERISTIC" : "MEASUREMENT", o.name, o.unit, o.min, o.max,
               o.address);
  c.disconnect();
  return epk == a.info.epk ? kExitOk : kExitFailed;
}

}  // namespace

Command add_xcp(CLI::App& app) {
  auto a = std::make_shared<XcpArgs>();
  auto* x = app.add_subcommand("xcp", "XCP-on-CAN master: read, write and measure an ECU's objects by their A2L names");
  x->require_subcommand(1);
  x->add_option("--bus", a->bus, "Bus address (udp:GROUP:PORT, socketcan:IFACE, mem:NAME)")->capture_default_str();
  x->add_option("--a2l", a->a2l, "The ECU's A2L file (lash hil a2l)")->required()->check(CLI::ExistingFile);
  x->add_option("--timeout-ms", a->timeout_ms, "Wait this long for each response [ms]")
      ->check(CLI::Range(1.0, 60000.0))
      ->capture_default_str();
  auto* get = x->add_subcommand("get", "Read one object");
  get->add_option("NAME", a->name, "MEASUREMENT or CHARACTERISTIC")->required();
  auto* set = x->add_subcommand("set", "Write one CHARACTERISTIC (refused outside its A2L limits)");
  set->add_option("NAME", a->name, "CHARACTERISTIC")->required();
  set->add_option("VALUE", a->value, "Physical value")->required();
  auto* daq = x->add_subcommand("daq", "Measure objects every step (DAQ list on event 0, with timestamps)");
  daq->add_option("NAME", a->names, "MEASUREMENTs (or CHARACTERISTICs)")->required();
  daq->add_option("--duration", a->duration, "How long to measure [s]")->check(CLI::Range(0.001, 86400.0))->capture_default_str();
  daq->add_option("--csv", a->csv, "Write the samples here (timestamp_us and one column per name)");
  auto* info = x->add_subcommand("info", "Connect and print the slave's properties, its EPK and the A2L's objects");
  return {x, [=]() -> int {
            if (get->parsed()) return run_get(*a);
            if (set->parsed()) return run_set(*a);
            if (daq->parsed()) return run_daq(*a);
            if (info->parsed()) return run_info(*a);
            return kExitBadInput;
          }};
}

namespace hilcli {

void add_hil_a2l(CLI::App* hil, std::function<int()>& run_selected) {
  auto config = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>("master.a2l");
  auto baud = std::make_shared<std::uint32_t>(500000);
  auto* a2l = hil->add_subcommand("a2l", "Write the master ECU's A2L file (XCP on CAN; docs/xcp.md)");
  a2l->add_option("--config", *config, "Node settings (TOML; default config/hil/bench.toml)");
  a2l->add_option("-o,--output", *out, "A2L file to write")->capture_default_str();
  a2l->add_option("--baudrate", *baud, "BAUDRATE of XCP_ON_CAN [bit/s]")->capture_default_str();
  run_selected = [=]() -> int {
    if (!a2l->parsed()) return -1;
    CommonOptions co;
    co.config = *config;
    const hil::BenchSettings s = load_settings(co);
    const hil::BenchLayout L = hil::BenchLayout::from_dbc(s.dbc_file);
    const auto cfg = hil::master_xcp_config(L);
    AtomicFile f(*out);
    f.stream() << xcp::write_a2l(hil::master_a2l_info(L, s.step_s, *baud), cfg.objects);
    f.commit();
    fmt::print(stderr, "lash hil a2l: {} objects, EPK {}, CAN_ID_MASTER 0x{:X}, CAN_ID_SLAVE 0x{:X} -> {}\n",
               cfg.objects.size(), cfg.epk, L.xcp_cmd_id, L.xcp_res_id, *out);
    return kExitOk;
  };
}

}  // namespace hilcli
}  // namespace lash::cli
