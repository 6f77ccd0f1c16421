#pragma once
/// @file error.hpp
/// Errors a person sees. Every error lash throws to a person derives from lash::Error:
///   InputError   something a person wrote is wrong (config, data file, argument); names
///                the file, line and field. The CLI exits with status 2.
///   SystemError  the operating system refused (fork, pipe, socket, a file it cannot use
///                that is not the user's input). Exit status 1.
///   RunError     the job ran but did not reach its goal (a node that never started, an
///                estimator that did not identify what a design needs). Exit status 1.
/// Configuration structs validated by the library throw std::invalid_argument (also exit 2:
/// the values came from a person); anything else reaching `main` is a bug: exit 1, never abort.
#include <stdexcept>
#include <cstddef>
#include <string>

namespace lash {

/// At most `max` bytes of `s` (cut before a UTF-8 continuation byte), then "… (N bytes)": an
/// error never echoes a whole 300 MB header line or a million column names. InputError bounds
/// its field to 200 bytes and its message to 1000 this way.
std::string bounded(std::string s, std::size_t max = 200);

/// Base of every error lash throws to a person; what() is the whole message.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The operating system refused a request (exit status 1).
class SystemError : public Error {
 public:
  using Error::Error;
};

/// The job ran but failed to reach its goal (exit status 1).
class RunError : public Error {
 public:
  using Error::Error;
};

/// A problem with something a person wrote (config, data file, argument).
/// `line` is 1-based; 0 means "not tied to one line" (e.g. a command-line option).
class InputError : public Error {
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
