#pragma once
/// @file error.hpp
/// Errors a person sees: every bad input names the file, line and field.
/// The CLI maps `InputError` to exit status 2.
#include <stdexcept>
#include <string>

namespace lash {

/// A problem with something a person wrote (config, data file, argument).
/// `line` is 1-based; 0 means "not tied to one line" (e.g. a command-line option).
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, int line, std::string field, const std::string& message);

  const std::string& file() const noexcept { return file_; }
  int line() const noexcept { return line_; }
  const std::string& field() const noexcept { return field_; }
  /// The message without the location prefix.
  const std::string& message() const noexcept { return message_; }

 private:
  std::string file_;
  int line_;
  std::string field_;
  std::string message_;
};

}  // namespace lash
