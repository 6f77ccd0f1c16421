#pragma once
/// @file mat.hpp
/// MATLAB .mat files (v4, v5 and — when Debian's libmatio was built with HDF5 —
/// v7.3) read through libmatio into the same named-column table that
/// lash::read_table returns (io/table.hpp), so every command that reads CSV reads MAT too.
/// Not real-time safe.
#include <filesystem>
#include <string>
#include <vector>

#include "lash/io/table.hpp"

namespace lash {

/// Names of the variables stored in a MAT file (file order). Throws InputError if the
/// file is missing or not a MAT file.
std::vector<std::string> mat_variable_names(const std::filesystem::path& path);

/// Reads the named numeric variables (real; any MATLAB numeric or logical class) as columns.
/// A name may also be a small expression over variables, so a recipe can derive its signals
/// without a conversion step (the column keeps the expression as its name):
///   product  = factor ('*' factor | '/' factor)*
///   factor   = variable | number | 'diff(' variable ')'
/// where diff(x) is the backward difference x(k) − x(k−1) with diff(x)(0) = 0. Example (EMPS,
/// docs/emps.md): "gtau*vir" is the drive force [N], "diff(qm)/0.001" the velocity [m/s].
/// Each must be a vector (N×1 or 1×N) of one common length N, or a scalar (1×1), which is
/// repeated N times. At least one must be a vector. Every value must be finite.
/// Errors (missing file, missing variable, wrong shape/class, length mismatch, non-finite
/// value) throw InputError naming the file and the variable.
/// A missing variable's error lists the variables the file holds.
/// Table::line_of_row holds the 1-based element index of each row.
Table read_mat(const std::filesystem::path& path, const std::vector<std::string>& variables);

/// Reads one real scalar (1×1) variable; InputError if absent or not a scalar.
double read_mat_scalar(const std::filesystem::path& path, const std::string& variable);

/// read_table for a MAT file: options.columns are variables/expressions as for read_mat, or,
/// when every entry is a 0-based index and no variable has that name, column indices into the
/// file's only two-dimensional numeric variable (an N×k matrix, one row per sample). A
/// non-finite element is an InputError (MAT records are not filtered).
Table read_mat_table(const std::filesystem::path& path, const TableOptions& options);

/// True if `path` ends in ".mat" (any case): the commands use it to pick the reader.
bool is_mat_file(const std::filesystem::path& path);

}  // namespace lash
