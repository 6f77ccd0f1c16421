// lash demo: the main job of `make demo`.
#include <filesystem>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "plot.hpp"
#include "lash/plant/plant_file.hpp"
#include "lash/plant/simulate.hpp"

namespace lash::cli {
namespace {

struct DemoOptions {
  std::string out_dir = "demo-out";
};

int run(const DemoOptions& o) {
  std::filesystem::create_directories(o.out_dir);
  const std::string plant_file = source_dir() + "/config/plants/thesis_eq34.toml";
  Plant plant = load_plant(plant_file);
  SimulationSpec spec;
  spec.input.kind = Waveform::sine;
  spec.input.amplitude = 600.0;
  spec.input.frequency_rad_s = 1.0;
  spec.duration_s = 20.0;
  SimulationTrace tr = simulate(plant, spec);
  const std::string csv = o.out_dir + "/eq34.csv";
  const std::string png = o.out_dir + "/eq34.png";
  std::vector<const std::vector<double>*> cols;
  for (const auto& c : tr.cols) cols.push_back(&c);
  write_columns_csv(csv, tr.names, cols);
  plot_csv(csv, png, "Thesis eq. (34) plant: DZ(-300, 200) -> G_r/G_l -> DB(30/50), v = 600 sin(t)",
           {{"input v", "t [s]"}, {"signals", "t [s]"}},
           {{"t", "v", "v (input)", 0},
            {"t", "x1_deadzone", "u (deadzone out)", 1},
            {"t", "x2_linear", "w (linear out)", 1},
            {"t", "y", "y (deadband out)", 1}});

  fmt::print("lash demo — simulation of the thesis's eq. (34) plant (E1), v = 600 sin(t), T = {} s\n",
             format_double(plant.dt_s()));
  fmt::print("{:>8} {:>10} {:>12} {:>12} {:>12}\n", "t [s]", "v", "u=DZ(v)", "w=G(u)", "y=DB(w)");
  const auto& t = tr.col("t");
  for (std::size_t k = 0; k < tr.samples(); k += 400)
    fmt::print("{:8.2f} {:10.3f} {:12.4f} {:12.4f} {:12.4f}\n", t[k], tr.col("v")[k], tr.col("x1_deadzone")[k],
               tr.col("x2_linear")[k], tr.col("y")[k]);
  fmt::print("wrote {} and {}\n", csv, png);
  demo_e3_campaign(o.out_dir);
  return kExitOk;
}

}  // namespace

Command add_demo(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  auto* sub = app.add_subcommand("demo", "Run the main demonstration (what `make demo` shows)");
  sub->add_option("--out-dir", o->out_dir, "Where CSV and PNG files go");
  return {sub, [o] { return run(*o); }};
}

}  // namespace lash::cli
