// lash.Plant and lash.signal: conversion only; the work is lash::load_plant / plant_from_toml,
// lash::simulate and lash::Signal, the calls `lash simulate` makes.
#include <cmath>
#include <optional>

#include "convert.hpp"
#include "lash/io/error.hpp"
#include "lash/plant/plant_file.hpp"
#include "lash/plant/simulate.hpp"
#include "lash/signals/signal.hpp"

namespace lash::py {

namespace {

struct PyPlant {
  Plant plant;

  static PyPlant from_toml(const std::string& path, std::optional<double> dt_s) {
    return PyPlant{load_plant(path, dt_s.value_or(0.0))};
  }
  static PyPlant from_blocks(const pyb::list& blocks, double dt_s) {
    pyb::dict d;
    d["dt"] = dt_s;
    d["blocks"] = blocks;
    const toml::table tbl = to_toml(d);
    TomlTable t(tbl, "");
    Plant p = plant_from_toml(t);
    t.finish();
    return PyPlant{std::move(p)};
  }

  pyb::dict simulate(const pyb::handle& v_obj, double noise_variance, std::uint64_t seed) {
    const Doubles va(v_obj, "v");
    const auto v = va.span();
    std::optional<SimulationTrace> tr;
    {
      pyb::gil_scoped_release nogil;
      tr.emplace(checked("noise_variance", [&] { return lash::simulate(plant, v, noise_variance, seed); }));
    }
    pyb::dict out;
    for (std::size_t i = 0; i < tr->names.size(); ++i) out[pyb::str(tr->names[i])] = to_numpy(std::move(tr->cols[i]));
    return out;
  }

  std::vector<std::string> block_kinds() const {
    std::vector<std::string> k;
    for (const auto& b : plant.blocks()) k.emplace_back(block_kind(b));
    return k;
  }
};

pyb::array_t<double> signal(const std::string& kind, double duration_s, double dt_s, double amplitude,
                            double frequency_rad_s, double offset, double phase_rad, double variance, double tau_s,
                            std::uint64_t seed, const std::vector<std::pair<double, double>>& steps) {
  SignalSpec s;
  s.kind = checked("kind", [&] { return parse_waveform(kind); });
  s.amplitude = amplitude;
  s.frequency_rad_s = frequency_rad_s;
  s.offset = offset;
  s.phase_rad = phase_rad;
  s.variance = variance;
  s.tau_s = tau_s;
  s.seed = seed;
  for (const auto& [t, value] : steps) s.steps.push_back({t, value});
  const std::size_t n = checked("duration_s", [&] { return sample_count(duration_s, dt_s); });
  std::optional<Signal> sig;
  checked("kind", [&] { sig.emplace(s, dt_s); return 0; });
  std::vector<double> out(n);
  {
    pyb::gil_scoped_release nogil;
    for (auto& x : out) x = sig->next();
  }
  return to_numpy(std::move(out));
}

}  // namespace

void bind_plant(pyb::module_& m) {
  pyb::class_<PyPlant>(m, "Plant",
                       "A chain of blocks (docs/method.md §A1): Plant(blocks=[{'kind': 'deadzone', ...}, ...], dt_s=0.005)\n"
                       "with the [[blocks]] tables of a plant file (docs/plant-files.md), or Plant.from_toml(path).")
      .def(pyb::init(&PyPlant::from_blocks), pyb::kw_only(), pyb::arg("blocks"), pyb::arg("dt_s") = 0.005)
      .def_static("from_toml", &PyPlant::from_toml, pyb::arg("path"), pyb::arg("dt_s") = pyb::none(),
                  "Loads a plant file; dt_s [s] replaces the file's dt when given.")
      .def("simulate", &PyPlant::simulate, pyb::arg("v"), pyb::kw_only(), pyb::arg("noise_variance") = 0.0,
           pyb::arg("seed") = 1,
           "simulate(v, *, noise_variance=0.0, seed=1) -> dict of arrays\n\n"
           "Runs the plant from its zero state over the input v (one sample per step): t [s], v, y (with noise of\n"
           "noise_variance [y unit^2], seeded), y_true, and each block's output x<i>_<kind>, as `lash simulate`.")
      .def_property_readonly("dt_s", [](const PyPlant& p) { return p.plant.dt_s(); }, "Sample period [s].")
      .def_property_readonly("blocks", &PyPlant::block_kinds, "Kinds of the blocks in chain order.");

  m.def("signal", &signal, pyb::arg("kind"), pyb::arg("duration_s"), pyb::arg("dt_s"), pyb::kw_only(),
        pyb::arg("amplitude") = 1.0, pyb::arg("frequency_rad_s") = 1.0, pyb::arg("offset") = 0.0,
        pyb::arg("phase_rad") = 0.0, pyb::arg("variance") = 10000.0, pyb::arg("tau_s") = 0.5, pyb::arg("seed") = 1,
        pyb::arg("steps") = std::vector<std::pair<double, double>>{},
        "signal(kind, duration_s, dt_s, **params) -> ndarray\n\n"
        "An excitation of `lash simulate` (docs/method.md §A2): kind sine | square | triangle | randomized | steps | constant;\n"
        "round(duration_s/dt_s) samples at t_k = k*dt_s. amplitude [input unit], frequency_rad_s [rad/s],\n"
        "offset [input unit], phase_rad [rad], variance [unit^2] and tau_s [s] (randomized), seed,\n"
        "steps = [(t_s, value), ...] (steps).");
}

}  // namespace lash::py
