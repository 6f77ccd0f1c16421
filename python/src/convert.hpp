#pragma once
// Conversions between Python objects and the library's types, shared by the binding files.
// Keyword settings become a TOML table read by the library's own config readers, so that the
// Python names, defaults and error messages are those of the config files (docs/*.md).
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <toml++/toml.h>

#include "lash/io/error.hpp"

namespace lash::py {

namespace pyb = pybind11;
using DoubleArray = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>;

/// A dict of settings (nested dicts = sub-tables, lists = arrays) as a TOML table.
/// Throws lash::InputError naming the key for a value TOML cannot hold.
toml::table to_toml(const pyb::dict& d, const std::string& prefix = "");

/// A 1-D float64 C-contiguous view of `obj` (zero-copy when it already is one; converted otherwise).
/// Throws lash::InputError naming `name` when it cannot be converted or is not 1-D.
DoubleArray as_doubles(const pyb::handle& obj, const char* name);

/// A 1-D float64 array argument of a binding: the numpy array (zero-copy when `obj` already is a
/// contiguous float64 array, converted otherwise) kept alive, with a span over it and its name for
/// error messages. Every binding that takes sample arrays reads them through this.
/// Throws lash::InputError naming `name` (see as_doubles).
class Doubles {
 public:
  Doubles() = default;
  Doubles(const pyb::handle& obj, const char* name) : array_(as_doubles(obj, name)), name_(name) {}
  std::span<const double> span() const noexcept {
    if (!array_) return {};
    return {array_.data(), static_cast<std::size_t>(array_.shape(0))};
  }
  std::size_t size() const noexcept { return span().size(); }
  const char* name() const noexcept { return name_; }
  /// Throws lash::InputError naming this array when its length differs from `other`'s.
  void require_length_of(const Doubles& other) const;

 private:
  DoubleArray array_;
  const char* name_ = "";
};

/// Runs f(); a std::invalid_argument from the library becomes lash::InputError naming `key`.
template <class F>
auto checked(const char* key, F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, key, e.what());
  }
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
void bind_xcp(pyb::module_& m);
void bind_monitor(pyb::module_& m);

}  // namespace lash::py
