#include "csv_stream.hpp"

#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"

namespace lash::cli {

namespace {
constexpr std::size_t kFlushAt = 1 << 16;
}

CsvStream::CsvStream(const std::string& path, const std::vector<std::string>& names) : file_(path) {
  buf_.reserve(kFlushAt + 4096);
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i) buf_ += ',';
    buf_ += names[i];
  }
  buf_ += '\n';
}

void CsvStream::row(std::span<const double> values) {
  for (std::size_t c = 0; c < values.size(); ++c) {
    if (c) buf_ += ',';
    append_double(buf_, values[c]);
  }
  buf_ += '\n';
  ++rows_;
  if (buf_.size() >= kFlushAt) flush();
}

void CsvStream::flush() {
  file_.stream().write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
  buf_.clear();
  if (!file_.stream())
    throw InputError(file_.target().string(), 0, "", "cannot write (" + std::string(file_.direct() ? "output" : "disk") +
                                                         " full or closed?)");
}

void CsvStream::commit() {
  flush();
  file_.commit();
}

}  // namespace lash::cli
