// lash.DeadzoneInverse, lash.BacklashInverse: the compensation blocks of docs/compensation.md
// (include/lash/blocks/*_inverse.hpp). Conversion only; apply() loops over samples without the GIL.
#include <cmath>
#include <stdexcept>

#include "convert.hpp"
#include "lash/blocks/backlash_inverse.hpp"
#include "lash/blocks/deadzone_inverse.hpp"
#include "lash/io/error.hpp"

namespace lash::py {

namespace {

template <class Params>
void check(const Params& p) {
  checked("", [&] { p.validate(); });
}

/// Steps `block` through every sample of `u_obj` with the GIL released; the outputs as a new array.
template <class Block>
pyb::array_t<double> apply(Block& block, const pyb::handle& u_obj) {
  const Doubles ua(u_obj, "u");
  const auto u = ua.span();
  std::vector<double> out(u.size());
  {
    pyb::gil_scoped_release nogil;
    for (std::size_t k = 0; k < u.size(); ++k) out[k] = block.step(u[k]);
  }
  return to_numpy(std::move(out));
}

DeadzoneInverseParams dz_params(double right, double left, double slope_right, double slope_left, double smoothing) {
  DeadzoneInverseParams p;
  p.offset_right = right;
  p.offset_left = left;
  p.slope_right = slope_right;
  p.slope_left = slope_left;
  p.smoothing = smoothing;
  return p;
}

BacklashInverseParams bl_params(double right, double left, double smoothing) {
  BacklashInverseParams p;
  p.right = right;
  p.left = left;
  p.smoothing = smoothing;
  return p;
}

}  // namespace

void bind_compensate(pyb::module_& m) {
  pyb::class_<DeadzoneInverse>(
      m, "DeadzoneInverse",
      "DeadzoneInverse(right, left, *, slope_right=1, slope_left=1, smoothing=0): the deadzone inverse of\n"
      "docs/compensation.md. It undoes DZ(v) = m_r (v - c_r) for v > c_r, 0 for -left <= v <= right,\n"
      "m_l (v + left) for v < -left: v = right + u/m_r (u > 0), -left + u/m_l (u < 0), 0 (u = 0), so\n"
      "DZ(DI(u)) = u. right = c_r >= 0 and left = |c_l| >= 0 [input unit]; slopes > 0 [output unit / input\n"
      "unit]; smoothing = band delta >= 0 around u = 0 [output unit] replacing the jump by a line (0 = exact).\n"
      "Raises lash.InputError for a value outside its domain.")
      .def(pyb::init([](double right, double left, double sr, double sl, double smoothing) {
             const auto p = dz_params(right, left, sr, sl, smoothing);
             check(p);
             return DeadzoneInverse(p);
           }),
           pyb::arg("right"), pyb::arg("left"), pyb::kw_only(), pyb::arg("slope_right") = 1.0,
           pyb::arg("slope_left") = 1.0, pyb::arg("smoothing") = 0.0)
      .def("step", &DeadzoneInverse::step, pyb::arg("u"),
           "step(u) -> v: desired deadzone output u [output unit] -> command v [input unit].")
      .def("apply", &apply<DeadzoneInverse>, pyb::arg("u"),
           "apply(u) -> ndarray: step() on every sample of the 1-D array u (GIL released); same bits.")
      .def("set_params",
           [](DeadzoneInverse& b, double right, double left, double sr, double sl, double smoothing) {
             const auto& o = b.params();
             b.set_params(dz_params(std::isnan(right) ? o.offset_right : right,
                                    std::isnan(left) ? o.offset_left : left, std::isnan(sr) ? o.slope_right : sr,
                                    std::isnan(sl) ? o.slope_left : sl, std::isnan(smoothing) ? o.smoothing : smoothing));
           },
           pyb::kw_only(), pyb::arg("right") = NAN, pyb::arg("left") = NAN, pyb::arg("slope_right") = NAN,
           pyb::arg("slope_left") = NAN, pyb::arg("smoothing") = NAN,
           "set_params(*, right=, left=, slope_right=, slope_left=, smoothing=): replaces the given parameters\n"
           "between samples (as from an online estimate). Edges outside [0, inf) become 0; a slope or smoothing\n"
           "outside its domain keeps the old value (the C++ block's rule: the step stays well defined).")
      .def_property_readonly("params", [](const DeadzoneInverse& b) {
        const auto& p = b.params();
        pyb::dict d;
        d["right"] = p.offset_right;
        d["left"] = p.offset_left;
        d["slope_right"] = p.slope_right;
        d["slope_left"] = p.slope_left;
        d["smoothing"] = p.smoothing;
        return d;
      }, "Current parameters: right, left [input unit], slope_right, slope_left, smoothing [output unit].");

  pyb::class_<BacklashInverse>(
      m, "BacklashInverse",
      "BacklashInverse(right, left, *, smoothing=0): the backlash (deadband) inverse of docs/compensation.md.\n"
      "It undoes the backlash y(k) = w - right if w > y(k-1) + right, w + left if w < y(k-1) - left, else\n"
      "y(k-1) (lash's deadband with half-width d: right = left = d) [unit of w]: w = u + right while u rises,\n"
      "u - left while u falls, held while u holds. Starts engaged pushing up at u = 0 (w = right); started\n"
      "from the backlash's output, B(BI(u)) = u. smoothing = travel of u [unit of u] over which the gap is\n"
      "crossed (0 = jump). Raises lash.InputError for a value outside its domain.")
      .def(pyb::init([](double right, double left, double smoothing) {
             const auto p = bl_params(right, left, smoothing);
             check(p);
             return BacklashInverse(p);
           }),
           pyb::arg("right"), pyb::arg("left"), pyb::kw_only(), pyb::arg("smoothing") = 0.0)
      .def("step", &BacklashInverse::step, pyb::arg("u"),
           "step(u) -> w: desired output u(k) -> backlash input w(k) [unit of w].")
      .def("apply", &apply<BacklashInverse>, pyb::arg("u"),
           "apply(u) -> ndarray: step() on every sample of the 1-D array u (GIL released), continuing from\n"
           "the current state; same bits as step() sample by sample.")
      .def("reset", &BacklashInverse::reset, pyb::arg("u0") = 0.0, pyb::arg("rising") = true,
           "reset(u0=0, rising=True): from rest at output u0, engaged on the rising (w = u0 + right) or\n"
           "falling (w = u0 - left) side; the backlash being inverted must start at y = u0.")
      .def("set_params",
           [](BacklashInverse& b, double right, double left, double smoothing) {
             const auto& o = b.params();
             b.set_params(bl_params(std::isnan(right) ? o.right : right, std::isnan(left) ? o.left : left,
                                    std::isnan(smoothing) ? o.smoothing : smoothing));
           },
           pyb::kw_only(), pyb::arg("right") = NAN, pyb::arg("left") = NAN, pyb::arg("smoothing") = NAN,
           "set_params(*, right=, left=, smoothing=): replaces the given widths between samples [unit of w]; a\n"
           "value outside [0, inf) keeps the old one; the current offset is moved to the same place in the new gap.")
      .def_property_readonly("offset", &BacklashInverse::offset, "The current offset w - u [unit of w].")
      .def_property_readonly("params", [](const BacklashInverse& b) {
        const auto& p = b.params();
        pyb::dict d;
        d["right"] = p.right;
        d["left"] = p.left;
        d["smoothing"] = p.smoothing;
        return d;
      }, "Current parameters: right, left [unit of w], smoothing [unit of u].");
}

}  // namespace lash::py
