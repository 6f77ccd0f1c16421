#pragma once
/// @file toml_util.hpp
/// Checked access to TOML configuration: every error names the file, the line
/// and the dotted key; unknown keys are rejected by `finish()`. Not real-time safe.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <toml++/toml.h>

namespace lash {

/// Parses a TOML file; syntax errors become InputError(file, line, "", what toml++ said).
toml::table parse_toml_file(const std::filesystem::path& path);

/// A view of one TOML table that remembers which keys were read.
class TomlTable {
 public:
  TomlTable(const toml::table& table, std::string file, std::string prefix = "");

  const std::string& file() const noexcept { return file_; }
  /// The dotted key path of `key` inside this table ("blocks[1].left").
  std::string path(std::string_view key) const;
  /// 1-based line of `key` (or of the table itself when key is empty or absent).
  int line(std::string_view key = {}) const;
  bool has(std::string_view key) const;

  /// A finite number (integer or float); throws if missing, not numeric or not finite.
  double number(std::string_view key);
  std::optional<double> number_opt(std::string_view key);
  double number_or(std::string_view key, double fallback) { return number_opt(key).value_or(fallback); }
  std::int64_t integer(std::string_view key);
  std::optional<std::int64_t> integer_opt(std::string_view key);
  std::string string(std::string_view key);
  std::optional<std::string> string_opt(std::string_view key);
  std::optional<bool> boolean_opt(std::string_view key);
  /// A list of finite numbers.
  std::vector<double> numbers(std::string_view key);
  std::optional<std::vector<double>> numbers_opt(std::string_view key);
  /// A list of strings.
  std::vector<std::string> strings(std::string_view key);
  std::optional<std::vector<std::string>> strings_opt(std::string_view key);
  /// A sub-table.
  TomlTable table(std::string_view key);
  std::optional<TomlTable> table_opt(std::string_view key);
  /// An array of tables (`[[key]]`).
  std::vector<TomlTable> tables(std::string_view key);
  /// The raw node (marks the key as used), or nullptr.
  const toml::node* node(std::string_view key);

  /// Throws InputError for the first key that was never read.
  void finish() const;
  /// Throws InputError naming `key` (its line if present).
  [[noreturn]] void fail(std::string_view key, const std::string& message) const;

 private:
  const toml::table* table_;
  std::string file_;
  std::string prefix_;
  mutable std::set<std::string, std::less<>> used_;
};

}  // namespace lash
