#pragma once
// Conversions between Python objects and the library's types, shared by the binding files.
// Keyword settings become a TOML table read by the library's own config readers, so that the
// Python names, defaults and error messages are those of the config files (docs/*.md).
#include <span>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <toml++/toml.h>

namespace lash::py {

namespace pyb = pybind11;
using DoubleArray = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>;

/// A dict of settings (nested dicts = sub-tables, lists = arrays) as a TOML table.
/// Throws lash::InputError naming the key for a value TOML cannot hold.
toml::table to_toml(const pyb::dict& d, const std::string& prefix = "");

/// A 1-D float64 C-contiguous view of `obj` (zero-copy when it already is one; converted otherwise).
/// Throws lash::InputError naming `name` when it cannot be converted or is not 1-D.
DoubleArray as_doubles(const pyb::handle& obj, const char* name);

inline std::span<const double> span_of(const DoubleArray& a) {
  return {a.data(), static_cast<std::size_t>(a.shape(0))};
}

/// Text from the library as a Python str: UTF-8, else Windows-1252 (what DBC files of other tools use).
pyb::str text(const std::string& s);

/// Moves a vector into a numpy array without copying (the array owns the buffer).
pyb::array_t<double> to_numpy(std::vector<double>&& v);

/// Translates lash::InputError into lash.InputError (a ValueError with .file, .line, .key).
void register_errors(pyb::module_& m);

void bind_estimate(pyb::module_& m);
void bind_plant(pyb::module_& m);
void bind_can(pyb::module_& m);
void bind_sweep(pyb::module_& m);
void bind_compensate(pyb::module_& m);

}  // namespace lash::py
