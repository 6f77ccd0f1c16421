#pragma once
// A CSV log with named columns read line by line in constant memory (the nodes' logs, the
// schedule of `lash hil simulate --schedule`). Private to the hil module.
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "lash/hil/handover.hpp"
#include "lash/io/error.hpp"

namespace lash::hil::detail {

/// A CSV log with a known header, read line by line; a last line without its newline (a node
/// killed mid-write) is dropped and counted.
class LogLines {
 public:
  LogLines(const std::filesystem::path& path, const std::vector<std::string>& columns) : path_(path.string()), in_(path) {
    if (!in_) throw InputError(path_, 0, "", "cannot open the log");
    std::string header;
    if (!std::getline(in_, header) || in_.eof()) {
      header_ok_ = false;  // empty, or killed before the header was out: no rows
      return;
    }
    std::vector<std::string> names = split_names(header);
    for (const auto& c : columns) {
      std::size_t i = 0;
      while (i < names.size() && names[i] != c) ++i;
      if (i == names.size()) throw InputError(path_, 1, c, "column missing from the log's header");
      index_.push_back(i);
    }
    width_ = names.size();
  }
  const std::string& file() const noexcept { return path_; }
  /// The file line of the row next() returned last.
  int line() const noexcept { return line_no_; }
  /// The next whole row's values of the asked columns; false at the end.
  bool next(std::vector<double>& out, LogReadBack& rb) {
    if (!header_ok_) return false;
    std::string line;
    while (std::getline(in_, line)) {
      ++line_no_;
      if (in_.eof()) {  // no newline after it: cut short
        if (!line.empty()) ++rb.cut_lines;
        return false;
      }
      if (line.empty()) continue;
      cells_.clear();
      const char* p = line.c_str();
      for (;;) {
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(p, &end);
        if (end == p || (*end != ',' && *end != '\0'))
          throw InputError(path_, line_no_, column_name(cells_.size()), "not a number");
        cells_.push_back(v);
        if (*end == '\0') break;
        p = end + 1;
      }
      if (cells_.size() != width_)
        throw InputError(path_, line_no_, "", std::to_string(cells_.size()) + " values, the header has " +
                                                  std::to_string(width_));
      out.clear();
      for (std::size_t i : index_) out.push_back(cells_[i]);
      ++rb.rows;
      return true;
    }
    return false;
  }

 private:
  static std::vector<std::string> split_names(const std::string& h) {
    std::vector<std::string> v(1);
    for (char c : h) {
      if (c == ',')
        v.emplace_back();
      else if (c != '\r')
        v.back() += c;
    }
    return v;
  }
  std::string column_name(std::size_t i) const { return "column " + std::to_string(i + 1); }
  std::string path_;
  std::ifstream in_;
  bool header_ok_ = true;
  std::vector<std::size_t> index_;
  std::size_t width_ = 0;
  int line_no_ = 1;
  std::vector<double> cells_;
};

}  // namespace lash::hil::detail
