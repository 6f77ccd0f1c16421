#include "convert.hpp"

#include <cmath>

#include "lash/io/error.hpp"

namespace lash::py {

namespace {
std::string dotted(const std::string& prefix, const std::string& key) { return prefix.empty() ? key : prefix + "." + key; }

toml::array to_toml_array(const pyb::handle& seq, const std::string& key);
bool is_bool(const pyb::handle& v);

// Returns the TOML node for one Python value (bool before int: bool is an int in Python).
bool is_bool(const pyb::handle& v) {
  if (PyBool_Check(v.ptr())) return true;
  return pyb::hasattr(v, "dtype") && pyb::str(v.attr("dtype").attr("kind")).cast<std::string>() == "b";
}

// Puts the TOML node for one Python value (bool before int: a bool is an int in Python).
template <class Put>
void put_value(const pyb::handle& v, const std::string& key, Put&& put) {
  if (pyb::isinstance<pyb::dict>(v)) {
    put(to_toml(v.cast<pyb::dict>(), key));
  } else if (pyb::isinstance<pyb::list>(v) || pyb::isinstance<pyb::tuple>(v) || pyb::isinstance<pyb::array>(v)) {
    put(to_toml_array(v, key));
  } else if (is_bool(v)) {
    put(toml::value<bool>(v.cast<bool>()));
  } else if (pyb::isinstance<pyb::str>(v)) {
    put(toml::value<std::string>(v.cast<std::string>()));
  } else if (PyIndex_Check(v.ptr())) {
    put(toml::value<std::int64_t>(pyb::int_(pyb::reinterpret_borrow<pyb::object>(v)).cast<std::int64_t>()));
  } else if (PyFloat_Check(v.ptr()) || pyb::hasattr(v, "__float__")) {
    put(toml::value<double>(pyb::float_(pyb::reinterpret_borrow<pyb::object>(v)).cast<double>()));
  } else {
    throw InputError("", 0, key,
                     "cannot use a value of type " + pyb::str(pyb::type::handle_of(v).attr("__name__")).cast<std::string>() +
                         " (expected a number, bool, string, list or dict)");
  }
}

toml::array to_toml_array(const pyb::handle& seq, const std::string& key) {
  toml::array a;
  std::size_t i = 0;
  for (const auto& item : seq) {
    const std::string k = key + "[" + std::to_string(i++) + "]";
    put_value(item, k, [&](auto&& node) { a.push_back(std::forward<decltype(node)>(node)); });
  }
  return a;
}
}  // namespace

toml::table to_toml(const pyb::dict& d, const std::string& prefix) {
  toml::table t;
  for (const auto& [k, v] : d) {
    const std::string key = pyb::str(k).cast<std::string>();
    if (v.is_none()) continue;  // None = leave the library's default
    const std::string full = dotted(prefix, key);
    put_value(v, full, [&](auto&& node) { t.insert_or_assign(key, std::forward<decltype(node)>(node)); });
  }
  return t;
}

DoubleArray as_doubles(const pyb::handle& obj, const char* name) {
  if (obj.is_none()) throw InputError("", 0, name, "is None (expected a 1-D array of numbers)");
  DoubleArray a;
  try {
    a = DoubleArray::ensure(obj);
  } catch (const pyb::error_already_set&) {
    a = DoubleArray();
  }
  if (!a) {
    PyErr_Clear();
    std::string what = "cannot convert to float64";
    if (pyb::hasattr(obj, "dtype")) what += " (dtype " + pyb::str(obj.attr("dtype")).cast<std::string>() + ")";
    throw InputError("", 0, name, what);
  }
  if (a.ndim() != 1) throw InputError("", 0, name, "expected a 1-D array, got " + std::to_string(a.ndim()) + " dimensions");
  return a;
}

void Doubles::require_length_of(const Doubles& other) const {
  if (size() != other.size())
    throw InputError("", 0, name_,
                     "has " + std::to_string(size()) + " samples, " + other.name_ + " has " + std::to_string(other.size()));
}

pyb::str text(const std::string& s) {
  PyObject* o = PyUnicode_DecodeUTF8(s.data(), static_cast<Py_ssize_t>(s.size()), nullptr);
  if (!o) {
    PyErr_Clear();
    o = PyUnicode_Decode(s.data(), static_cast<Py_ssize_t>(s.size()), "cp1252", "replace");
  }
  if (!o) throw pyb::error_already_set();
  return pyb::reinterpret_steal<pyb::str>(o);
}

pyb::array_t<double> to_numpy(std::vector<double>&& v) {
  auto* heap = new std::vector<double>(std::move(v));
  pyb::capsule owner(heap, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  return pyb::array_t<double>({static_cast<pyb::ssize_t>(heap->size())}, {sizeof(double)}, heap->data(), owner);
}

void register_errors(pyb::module_& m) {
  static pyb::exception<InputError> exc(m, "InputError", PyExc_ValueError);
  pyb::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      const pyb::str what = text(e.what());
      pyb::object err = pyb::reinterpret_steal<pyb::object>(PyObject_CallOneArg(exc.ptr(), what.ptr()));
      if (!err) return;  // the call set its own Python error
      err.attr("file") = text(e.file());
      err.attr("line") = e.line();
      err.attr("key") = text(e.field());
      err.attr("message") = text(e.message());
      PyErr_SetObject(exc.ptr(), err.ptr());
    }
  });
}

}  // namespace lash::py
