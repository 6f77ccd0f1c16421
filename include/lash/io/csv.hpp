#pragma once
/// @file csv.hpp
/// CSV in and out. Numbers are written in round-trip precision: the shortest
/// text that parses back to the same double (std::to_chars). Not real-time safe.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "lash/io/table.hpp"

namespace lash {

/// Shortest round-trip text of `x` ("0.1", "1e-05", "200"). Non-finite → "nan"/"inf"/"-inf".
std::string format_double(double x);
/// Appends the shortest round-trip text of `x` to `out`.
void append_double(std::string& out, double x);

/// Parses a whole field as a finite double; returns false for junk, empty or non-finite text.
bool parse_double(std::string_view text, double& value) noexcept;

/// The table type of io/table.hpp under its old name.
using CsvTable = Table;

/// Reads every column of a text table (io/table.hpp) strictly: every cell must be a finite
/// number; the first offending cell is reported as InputError(file, line, column). Blank
/// lines and lines starting with '#' are skipped. An empty file or a file with a header but
/// no rows is an error.
Table read_csv(const std::filesystem::path& path);

/// Checks that column `name` is strictly increasing; throws InputError naming the line.
void require_increasing(const Table& table, std::string_view name);

}  // namespace lash
