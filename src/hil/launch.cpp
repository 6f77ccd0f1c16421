#include "lash/hil/launch.hpp"

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "lash/io/atomic_file.hpp"
#include "lash/io/error.hpp"

namespace lash::hil {

namespace {
using nlohmann::json;

const char* policy_name(rt::OverrunPolicy p) { return p == rt::OverrunPolicy::stop ? "stop" : "tolerate"; }

/// A typed read of one field; errors name it ("loop.fifo").
class Fields {
 public:
  Fields(const json& j, std::string file) : j_(j), file_(std::move(file)) {}
  const json& at(const json& obj, const char* key, const std::string& name) const {
    if (!obj.is_object() || !obj.contains(key)) throw InputError(file_, 0, name, "missing from the launch file");
    return obj.at(key);
  }
  template <class T>
  T get(const json& obj, const char* key, const std::string& prefix = "") const {
    const std::string name = prefix + key;
    const json& v = at(obj, key, name);
    try {
      return v.get<T>();
    } catch (const json::exception&) {
      throw InputError(file_, 0, name, "has the wrong type in the launch file: " + v.dump());
    }
  }
  const json& root() const { return j_; }
  const std::string& file() const { return file_; }

 private:
  const json& j_;
  std::string file_;
};
}  // namespace

const char* to_string(NodeLaunch::Role r) noexcept { return r == NodeLaunch::Role::master ? "master" : "slave"; }

std::string launch_json(const NodeLaunch& l) {
  json j;
  j["role"] = to_string(l.role);
  j["config"] = l.config.string();
  j["bus"] = l.bus;
  j["step_s"] = l.step_s;
  j["seed"] = l.seed;
  j["scenario"] = l.scenario.string();
  j["compensation"] = l.compensation;
  json c = json::array();
  for (const auto& [k, v] : l.controller) c.push_back({k, v});
  j["controller"] = c;
  j["loop"] = {{"step_s", l.loop.step_s},       {"fifo", l.loop.fifo},
               {"cpu", l.loop.cpu},             {"spin_us", l.loop.spin_us},
               {"lock_memory", l.loop.lock_memory}, {"policy", policy_name(l.loop.policy)},
               {"max_overruns", l.loop.max_overruns}, {"hold_dma_latency", l.loop.hold_dma_latency}};
  j["duration_s"] = l.duration_s;
  j["connect_timeout_s"] = l.connect_timeout_s;
  j["reference"] = l.reference;
  j["dto_timeout_s"] = l.dto_timeout_s;
  j["xcp"] = l.xcp;
  j["logs"] = {{"csv", l.logs.csv.string()}, {"events", l.logs.events.string()}, {"bus_log", l.logs.bus_log.string()}};
  j["stats"] = l.stats.string();
  j["result_fd"] = l.result_fd;
  return j.dump(2) + "\n";
}

void write_launch(const std::filesystem::path& path, const NodeLaunch& l) {
  AtomicFile f(path);
  f.stream() << launch_json(l);
  f.commit();
}

NodeLaunch read_launch(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), 0, "", "cannot open the launch file");
  std::stringstream text;
  text << in.rdbuf();
  json j;
  try {
    j = json::parse(text.str());
  } catch (const json::parse_error& e) {
    throw InputError(path.string(), 0, "", std::string("not a launch file (JSON): ") + e.what());
  }
  const Fields f(j, path.string());
  NodeLaunch l;
  const auto role = f.get<std::string>(j, "role");
  if (role != "slave" && role != "master") throw InputError(path.string(), 0, "role", "must be slave or master");
  l.role = role == "master" ? NodeLaunch::Role::master : NodeLaunch::Role::slave;
  l.config = f.get<std::string>(j, "config");
  l.bus = f.get<std::string>(j, "bus");
  l.step_s = f.get<double>(j, "step_s");
  l.seed = f.get<std::int64_t>(j, "seed");
  l.scenario = f.get<std::string>(j, "scenario");
  l.compensation = f.get<std::string>(j, "compensation");
  for (const auto& c : f.at(j, "controller", "controller")) {
    if (!c.is_array() || c.size() != 2 || !c[0].is_string() || !c[1].is_string())
      throw InputError(path.string(), 0, "controller", "each entry must be [key, value text]");
    l.controller.emplace_back(c[0].get<std::string>(), c[1].get<std::string>());
  }
  const json& lo = f.at(j, "loop", "loop");
  l.loop.step_s = f.get<double>(lo, "step_s", "loop.");
  l.loop.fifo = f.get<int>(lo, "fifo", "loop.");
  l.loop.cpu = f.get<int>(lo, "cpu", "loop.");
  l.loop.spin_us = f.get<double>(lo, "spin_us", "loop.");
  l.loop.lock_memory = f.get<bool>(lo, "lock_memory", "loop.");
  try {
    l.loop.policy = parse_overrun_policy(f.get<std::string>(lo, "policy", "loop."));
  } catch (const InputError& e) {
    if (!e.file().empty()) throw;
    throw InputError(path.string(), 0, e.field(), e.message());
  }
  l.loop.max_overruns = f.get<std::size_t>(lo, "max_overruns", "loop.");
  l.loop.hold_dma_latency = f.get<bool>(lo, "hold_dma_latency", "loop.");
  l.duration_s = f.get<double>(j, "duration_s");
  l.connect_timeout_s = f.get<double>(j, "connect_timeout_s");
  l.reference = f.get<std::string>(j, "reference");
  l.dto_timeout_s = f.get<double>(j, "dto_timeout_s");
  l.xcp = f.get<bool>(j, "xcp");
  const json& lg = f.at(j, "logs", "logs");
  l.logs.csv = f.get<std::string>(lg, "csv", "logs.");
  l.logs.events = f.get<std::string>(lg, "events", "logs.");
  l.logs.bus_log = f.get<std::string>(lg, "bus_log", "logs.");
  l.stats = f.get<std::string>(j, "stats");
  l.result_fd = f.get<int>(j, "result_fd");
  return l;
}

}  // namespace lash::hil
