// lash._lash: the extension module. Each bind_* file converts arguments, calls the library
// and converts results; no computation lives here (DESIGN.md, faces).
#include "convert.hpp"

PYBIND11_MODULE(_lash, m) {
  m.doc() = "lash: deadzone/backlash identification, simulation and CAN tools (C++ core)";
  lash::py::register_errors(m);
  lash::py::bind_estimate(m);
  lash::py::bind_plant(m);
  lash::py::bind_can(m);
  lash::py::bind_sweep(m);
  lash::py::bind_compensate(m);
  lash::py::bind_xcp(m);
  lash::py::bind_monitor(m);
}
