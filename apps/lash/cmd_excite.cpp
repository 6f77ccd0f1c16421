// lash excite: write an input signal (t,v CSV) that identifies the deadzone-deadband model given
// rough bounds on its edges (docs/excite.md). Parses, calls lash::excite, writes.
#include <cmath>
#include <cstdint>
#include <string>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "csv_stream.hpp"
#include "lash/io/csv.hpp"
#include "lash/signals/excite.hpp"

namespace lash::cli {
namespace {

struct ExciteOptions {
  std::string edges;
  double dt = 0.0;
  double duration = 0.0;
  double period = 0.0;
  std::string kind = "sine";
  std::uint64_t seed = 1;
  std::string out;
};

int run(const ExciteOptions& o) {
  ExciteSpec spec;
  const auto comma = o.edges.find(',');
  if (comma == std::string::npos || o.edges.find(',', comma + 1) != std::string::npos ||
      !parse_double(o.edges.substr(0, comma), spec.edge_left) || !parse_double(o.edges.substr(comma + 1), spec.edge_right))
    throw InputError("", 0, "--edges", "must be two finite numbers c_l,c_r (rough bounds on the deadzone edges), got '" + o.edges + "'");
  try {
    spec.kind = parse_excite_kind(o.kind);
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, "--kind", e.what());
  }
  spec.dt_s = o.dt;
  spec.duration_s = o.duration;
  spec.period_s = o.period;
  spec.seed = o.seed;
  if (const auto p = check_excite(spec)) throw InputError("", 0, "--" + p->field, p->message);
  check_output_path(o.out, "--output");
  if (const char* w = excite_warning(spec.kind)) fmt::print(stderr, "lash excite: warning: {}\n", w);
  Excitation ex(spec);  // the samples one at a time: memory O(1) in the duration
  CsvStream csv(o.out, {"t", "v"});
  for (std::size_t k = 0; k < ex.samples(); ++k) {
    const double row[2] = {static_cast<double>(k) * spec.dt_s, ex.next()};
    csv.row(row);
  }
  csv.commit();
  fmt::print(stderr, "lash excite: {} {} samples at dt = {} s, period {} s, v in [{}, {}] -> {}\n", to_string(spec.kind),
             csv.rows(), format_double(spec.dt_s), format_double(excite_period(spec)),
             format_double(spec.reach * spec.edge_left), format_double(spec.reach * spec.edge_right), o.out);
  return kExitOk;
}

}  // namespace

Command add_excite(CLI::App& app) {
  auto o = std::make_shared<ExciteOptions>();
  auto* sub = app.add_subcommand("excite", "Write an input signal (t,v CSV) that identifies the deadzone-deadband model "
                                           "given rough bounds on its edges (docs/excite.md)");
  sub->add_option("--edges", o->edges, "Rough bounds on the deadzone edges c_l,c_r (c_l < 0 < c_r) [input unit]")
      ->required();
  sub->add_option("--dt", o->dt, "Sample period [s]")->required();
  sub->add_option("--duration", o->duration, "Duration [s]; N = round(duration/dt) samples")->required();
  sub->add_option("--kind", o->kind, "sine (default) | multisine | prbs");
  sub->add_option("--period", o->period, "Period P [s] (default max(2 pi, 1000 dt))");
  sub->add_option("--seed", o->seed, "Seed of the multisine's phases and the prbs");
  sub->add_option("-o,--output", o->out, "Output CSV (t,v)")->required();
  return {sub, [o] { return run(*o); }};
}

}  // namespace lash::cli
