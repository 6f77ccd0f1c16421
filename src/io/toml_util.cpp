#include "lash/io/toml_util.hpp"

#include <cmath>

#include "lash/io/error.hpp"

namespace lash {

toml::table parse_toml_file(const std::filesystem::path& path) {
  const std::string file = path.string();
  if (!std::filesystem::exists(path)) throw InputError(file, 0, "", "no such file");
  try {
    return toml::parse_file(file);
  } catch (const toml::parse_error& e) {
    throw InputError(file, static_cast<int>(e.source().begin.line), "",
                     "TOML syntax error at column " + std::to_string(e.source().begin.column) + ": " +
                         std::string(e.description()));
  }
}

TomlTable::TomlTable(const toml::table& table, std::string file, std::string prefix)
    : table_(&table), file_(std::move(file)), prefix_(std::move(prefix)) {}

std::string TomlTable::path(std::string_view key) const {
  if (prefix_.empty()) return std::string(key);
  if (key.empty()) return prefix_;
  return prefix_ + "." + std::string(key);
}

int TomlTable::line(std::string_view key) const {
  if (!key.empty()) {
    if (const auto* n = table_->get(key)) return static_cast<int>(n->source().begin.line);
  }
  return static_cast<int>(table_->source().begin.line);
}

bool TomlTable::has(std::string_view key) const { return table_->contains(key); }

void TomlTable::fail(std::string_view key, const std::string& message) const {
  throw InputError(file_, line(key), path(key), message);
}

const toml::node* TomlTable::node(std::string_view key) {
  const auto* n = table_->get(key);
  if (n) used_.emplace(key);
  return n;
}

std::optional<double> TomlTable::number_opt(std::string_view key) {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  double v;
  if (auto f = n->value_exact<double>()) {
    v = *f;
  } else if (auto i = n->value_exact<std::int64_t>()) {
    v = static_cast<double>(*i);
  } else {
    fail(key, "expected a number");
  }
  if (!std::isfinite(v)) fail(key, "must be a finite number");
  return v;
}

double TomlTable::number(std::string_view key) {
  auto v = number_opt(key);
  if (!v) fail(key, "missing (a number is required)");
  return *v;
}

std::optional<std::int64_t> TomlTable::integer_opt(std::string_view key) {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  if (auto i = n->value_exact<std::int64_t>()) return *i;
  fail(key, "expected an integer");
}

std::int64_t TomlTable::integer(std::string_view key) {
  auto v = integer_opt(key);
  if (!v) fail(key, "missing (an integer is required)");
  return *v;
}

std::optional<std::string> TomlTable::string_opt(std::string_view key) {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  if (auto s = n->value_exact<std::string>()) return *s;
  fail(key, "expected a string");
}

std::string TomlTable::string(std::string_view key) {
  auto v = string_opt(key);
  if (!v) fail(key, "missing (a string is required)");
  return *v;
}

std::optional<bool> TomlTable::boolean_opt(std::string_view key) {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  if (auto b = n->value_exact<bool>()) return *b;
  fail(key, "expected true or false");
}

std::optional<std::vector<double>> TomlTable::numbers_opt(std::string_view key) {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  const auto* arr = n->as_array();
  if (!arr) fail(key, "expected a list of numbers");
  std::vector<double> out;
  for (const auto& e : *arr) {
    double v;
    if (auto f = e.value_exact<double>()) v = *f;
    else if (auto i = e.value_exact<std::int64_t>()) v = static_cast<double>(*i);
    else fail(key, "element " + std::to_string(out.size()) + " is not a number");
    if (!std::isfinite(v)) fail(key, "element " + std::to_string(out.size()) + " is not finite");
    out.push_back(v);
  }
  return out;
}

std::vector<double> TomlTable::numbers(std::string_view key) {
  auto v = numbers_opt(key);
  if (!v) fail(key, "missing (a list of numbers is required)");
  return *v;
}

std::optional<std::vector<std::string>> TomlTable::strings_opt(std::string_view key) {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  const auto* arr = n->as_array();
  if (!arr) fail(key, "expected a list of strings");
  std::vector<std::string> out;
  for (const auto& e : *arr) {
    auto s = e.value_exact<std::string>();
    if (!s) fail(key, "element " + std::to_string(out.size()) + " is not a string");
    out.push_back(*s);
  }
  return out;
}

std::vector<std::string> TomlTable::strings(std::string_view key) {
  auto v = strings_opt(key);
  if (!v) fail(key, "missing (a list of strings is required)");
  return *v;
}

std::optional<TomlTable> TomlTable::table_opt(std::string_view key) {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  const auto* t = n->as_table();
  if (!t) fail(key, "expected a table");
  return TomlTable(*t, file_, path(key));
}

TomlTable TomlTable::table(std::string_view key) {
  auto v = table_opt(key);
  if (!v) fail(key, "missing (a table is required)");
  return *v;
}

std::vector<TomlTable> TomlTable::tables(std::string_view key) {
  const auto* n = node(key);
  if (!n) return {};
  const auto* arr = n->as_array();
  if (!arr) fail(key, "expected an array of tables ([[" + std::string(key) + "]])");
  std::vector<TomlTable> out;
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const auto* t = (*arr)[i].as_table();
    if (!t) fail(key, "element " + std::to_string(i) + " is not a table");
    out.emplace_back(*t, file_, path(key) + "[" + std::to_string(i) + "]");
  }
  return out;
}

void TomlTable::finish() const {
  for (const auto& [k, v] : *table_) {
    if (!used_.contains(k.str()))
      throw InputError(file_, static_cast<int>(v.source().begin.line), path(k.str()), "unknown key");
  }
}

}  // namespace lash
