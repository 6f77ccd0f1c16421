// MAT-file reading through libmatio (Debian libmatio-dev).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <memory>

#include <matio.h>

#include "lash/io/csv.hpp"
#include "lash/io/table.hpp"
#include "lash/io/error.hpp"
#include "lash/io/mat.hpp"

namespace lash {
namespace {

struct MatCloser {
  void operator()(mat_t* m) const noexcept { Mat_Close(m); }
};
struct VarFreer {
  void operator()(matvar_t* v) const noexcept { Mat_VarFree(v); }
};
using MatPtr = std::unique_ptr<mat_t, MatCloser>;
using VarPtr = std::unique_ptr<matvar_t, VarFreer>;

MatPtr open_mat(const std::filesystem::path& path) {
  const std::string file = path.string();
  if (!std::filesystem::exists(path)) throw InputError(file, 0, "", "no such file");
  MatPtr m(Mat_Open(file.c_str(), MAT_ACC_RDONLY));
  if (!m) throw InputError(file, 0, "", "not a MATLAB .mat file libmatio can read (v4, v5 or v7.3)");
  return m;
}

/// The variables of an open file, comma-separated (for messages); rewinds the file.
std::string variables_of(mat_t* mat) {
  Mat_Rewind(mat);
  std::string out;
  while (matvar_t* v = Mat_VarReadNextInfo(mat)) {
    VarPtr guard(v);
    if (v->name) out += (out.empty() ? "" : ", ") + std::string(v->name);
  }
  Mat_Rewind(mat);
  return out.empty() ? "no variables" : out;
}

template <class T>
void convert(const void* data, std::size_t n, std::vector<double>& out) {
  const T* p = static_cast<const T*>(data);
  out.resize(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<double>(p[i]);
}

/// Reads variable `name` as a flat vector of doubles; `elements` = its element count.
std::vector<double> read_numeric(mat_t* mat, const std::string& file, const std::string& name, bool& is_scalar,
                                 std::size_t* matrix_cols = nullptr) {
  VarPtr var(Mat_VarRead(mat, name.c_str()));
  if (!var) throw InputError(file, 0, name, "no variable named '" + name + "' in this MAT file (it holds: " + variables_of(mat) + ")");
  if (var->isComplex) throw InputError(file, 0, name, "is complex; a real numeric variable is needed");
  if (var->rank != 2) throw InputError(file, 0, name, "has " + std::to_string(var->rank) + " dimensions; a vector is needed");
  const std::size_t r = var->dims[0], c = var->dims[1];
  if (matrix_cols) *matrix_cols = c;
  if (r != 1 && c != 1 && !matrix_cols)
    throw InputError(file, 0, name,
                     "is a " + std::to_string(r) + "x" + std::to_string(c) + " matrix; a vector (Nx1 or 1xN) is needed");
  const std::size_t n = r * c;
  if (n == 0) throw InputError(file, 0, name, "is empty");
  if (!var->data) throw InputError(file, 0, name, "has no data");
  std::vector<double> out;
  switch (var->class_type) {
    case MAT_C_DOUBLE: convert<double>(var->data, n, out); break;
    case MAT_C_SINGLE: convert<float>(var->data, n, out); break;
    case MAT_C_INT8: convert<std::int8_t>(var->data, n, out); break;
    case MAT_C_UINT8: convert<std::uint8_t>(var->data, n, out); break;
    case MAT_C_INT16: convert<std::int16_t>(var->data, n, out); break;
    case MAT_C_UINT16: convert<std::uint16_t>(var->data, n, out); break;
    case MAT_C_INT32: convert<std::int32_t>(var->data, n, out); break;
    case MAT_C_UINT32: convert<std::uint32_t>(var->data, n, out); break;
    case MAT_C_INT64: convert<std::int64_t>(var->data, n, out); break;
    case MAT_C_UINT64: convert<std::uint64_t>(var->data, n, out); break;
    default: throw InputError(file, 0, name, "is not a numeric array (struct, cell, char or sparse)");
  }
  if (var->isLogical) {
    for (auto& x : out) x = x != 0.0 ? 1.0 : 0.0;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(out[i]))
      throw InputError(file, 0, name, "element " + std::to_string(i + 1) + " is not a finite number");
  is_scalar = n == 1;
  return out;
}

/// One column: a variable or a product/quotient expression of variables, numbers and diff(x).
std::vector<double> read_column(mat_t* mat, const std::string& file, const std::string& spec, bool& is_scalar) {
  const bool plain = spec.find_first_of("*/()") == std::string::npos;
  if (plain) return read_numeric(mat, file, spec, is_scalar);
  std::vector<double> acc{1.0};
  bool acc_scalar = true;
  std::size_t pos = 0;
  char op = '*';
  while (pos <= spec.size()) {
    std::size_t end = spec.find_first_of("*/", pos);
    if (end == std::string::npos) end = spec.size();
    std::string f = spec.substr(pos, end - pos);
    while (!f.empty() && f.front() == ' ') f.erase(f.begin());
    while (!f.empty() && f.back() == ' ') f.pop_back();
    if (f.empty()) throw InputError(file, 0, spec, "empty factor in column expression '" + spec + "'");
    std::vector<double> x;
    bool sc = true;
    double num = 0.0;
    if (parse_double(f, num)) {
      x = {num};
    } else if (f.rfind("diff(", 0) == 0 && f.back() == ')') {
      const std::string var = f.substr(5, f.size() - 6);
      x = read_numeric(mat, file, var, sc);
      if (sc) throw InputError(file, 0, spec, "diff() needs a vector, '" + var + "' is a scalar");
      for (std::size_t i = x.size() - 1; i > 0; --i) x[i] -= x[i - 1];
      x[0] = 0.0;
    } else {
      if (f.find_first_of("()") != std::string::npos)
        throw InputError(file, 0, spec, "unknown function in '" + f + "' (only diff(variable) is known)");
      x = read_numeric(mat, file, f, sc);
    }
    if (op == '/') {
      for (double& v : x) {
        if (v == 0.0) throw InputError(file, 0, spec, "division by zero in column expression");
        v = 1.0 / v;
      }
    }
    if (!sc && !acc_scalar && x.size() != acc.size())
      throw InputError(file, 0, spec, "vectors of different lengths in column expression");
    if (acc_scalar && !sc) {
      const double a = acc[0];
      acc = x;
      for (double& v : acc) v *= a;
      acc_scalar = false;
    } else if (sc) {
      for (double& v : acc) v *= x[0];
    } else {
      for (std::size_t i = 0; i < acc.size(); ++i) acc[i] *= x[i];
    }
    if (end == spec.size()) break;
    op = spec[end];
    pos = end + 1;
  }
  is_scalar = acc_scalar;
  return acc;
}

}  // namespace

bool is_mat_file(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext == ".mat";
}

std::vector<std::string> mat_variable_names(const std::filesystem::path& path) {
  MatPtr mat = open_mat(path);
  std::vector<std::string> names;
  while (matvar_t* v = Mat_VarReadNextInfo(mat.get())) {
    VarPtr guard(v);
    if (v->name) names.emplace_back(v->name);
  }
  return names;
}

Table read_mat(const std::filesystem::path& path, const std::vector<std::string>& variables) {
  const std::string file = path.string();
  if (variables.empty()) throw InputError(file, 0, "", "no variables named to read");
  MatPtr mat = open_mat(path);
  Table t;
  t.file = file;
  std::vector<bool> scalar(variables.size());
  std::size_t n = 0;
  std::string n_from;
  for (std::size_t i = 0; i < variables.size(); ++i) {
    bool s = false;
    t.cols.push_back(read_column(mat.get(), file, variables[i], s));
    t.names.push_back(variables[i]);
    scalar[i] = s;
    if (!s) {
      if (n == 0) {
        n = t.cols.back().size();
        n_from = variables[i];
      } else if (t.cols.back().size() != n) {
        throw InputError(file, 0, variables[i],
                         "has " + std::to_string(t.cols.back().size()) + " elements but '" + n_from + "' has " +
                             std::to_string(n));
      }
    }
  }
  if (n == 0) throw InputError(file, 0, variables.front(), "every named variable is a scalar; at least one vector is needed");
  for (std::size_t i = 0; i < variables.size(); ++i)
    if (scalar[i]) t.cols[i].assign(n, t.cols[i][0]);
  t.line_of_row.assign_consecutive(n, 1);
  return t;
}

Table read_mat_table(const std::filesystem::path& path, const TableOptions& options) {
  const std::string file = path.string();
  const auto& cols = options.columns;
  if (cols.empty()) throw InputError(file, 0, "--columns", "name the variables to read from a MAT file");
  for (std::size_t i = 0; i < cols.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (cols[i] == cols[j]) throw InputError(file, 0, "--columns", "column '" + cols[i] + "' is chosen twice");
  const bool indices = std::all_of(cols.begin(), cols.end(), [](const std::string& c) {
    return !c.empty() && c.size() < 9 && c.find_first_not_of("0123456789") == std::string::npos;
  });
  if (!indices) return read_mat(path, cols);
  MatPtr mat = open_mat(path);
  std::vector<std::string> vars;
  while (matvar_t* v = Mat_VarReadNextInfo(mat.get())) {
    VarPtr guard(v);
    if (v->name) vars.emplace_back(v->name);
  }
  for (const auto& c : cols)
    if (std::find(vars.begin(), vars.end(), c) != vars.end()) return read_mat(path, cols);  // variables named "0"…
  if (vars.size() != 1)
    throw InputError(file, 0, "--columns",
                     "column indices need a MAT file holding one N×k matrix; it holds: " + variables_of(mat.get()));
  bool scalar = false;
  std::size_t k = 0;
  Mat_Rewind(mat.get());
  const std::vector<double> m = read_numeric(mat.get(), file, vars[0], scalar, &k);
  const std::size_t n = k ? m.size() / k : 0;
  Table t;
  t.file = file;
  for (const auto& c : cols) {
    const std::size_t j = std::stoul(c);
    if (j >= k)
      throw InputError(file, 0, c, "column index out of range ('" + vars[0] + "' is " + std::to_string(n) + "x" +
                                       std::to_string(k) + ", columns 0.." + std::to_string(k - 1) + ")");
    t.names.push_back(c);
    t.cols.emplace_back(m.begin() + static_cast<std::ptrdiff_t>(j * n), m.begin() + static_cast<std::ptrdiff_t>((j + 1) * n));
  }
  t.line_of_row.assign_consecutive(n, 1);
  return t;
}

double read_mat_scalar(const std::filesystem::path& path, const std::string& variable) {
  MatPtr mat = open_mat(path);
  bool s = false;
  auto v = read_numeric(mat.get(), path.string(), variable, s);
  if (!s) throw InputError(path.string(), 0, variable, "is a vector; a scalar (1x1) is needed");
  return v[0];
}

}  // namespace lash
