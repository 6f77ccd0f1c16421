#include "lash/io/column_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "lash/io/error.hpp"

namespace lash {

/// The unlinked temporary file of a spilled store. Layout: blocks of kBlockRows rows; block b
/// holds its columns one after the other, column c at offset (b·columns + c)·kBlockRows·8 bytes
/// (the last block's columns are written only as far as its rows go).
class SpillFile {
 public:
  explicit SpillFile(std::size_t columns) : columns_(columns) {
    const char* env = std::getenv("TMPDIR");
    dir_ = env && *env ? env : "/tmp";
#ifdef O_TMPFILE
    fd_ = ::open(dir_.c_str(), O_TMPFILE | O_RDWR | O_EXCL | O_CLOEXEC, 0600);
#endif
    if (fd_ < 0) {  // a file system without O_TMPFILE: a random name, unlinked at once
      std::string tmpl = dir_ + "/lash-spill.XXXXXXXXXX";
      fd_ = ::mkostemp(tmpl.data(), O_CLOEXEC);
      if (fd_ >= 0) ::unlink(tmpl.c_str());
    }
    if (fd_ < 0)
      throw InputError(dir_, 0, "TMPDIR",
                       std::string("cannot create the record's temporary spill file: ") + std::strerror(errno));
  }
  ~SpillFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  off_t offset(std::size_t block, std::size_t column, std::size_t row_in_block) const noexcept {
    return static_cast<off_t>(((block * columns_ + column) * SpillWriter::kBlockRows + row_in_block) * sizeof(double));
  }
  void write(const double* p, std::size_t n, off_t at) const {
    const char* b = reinterpret_cast<const char*>(p);
    std::size_t left = n * sizeof(double);
    while (left > 0) {
      const ssize_t w = ::pwrite(fd_, b, left, at);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0)
        throw InputError(dir_, 0, "TMPDIR",
                         std::string("cannot write the record's temporary spill file: ") +
                             (w < 0 ? std::strerror(errno) : "no progress"));
      b += w;
      at += w;
      left -= static_cast<std::size_t>(w);
    }
  }
  void read(double* p, std::size_t n, off_t at) const {
    char* b = reinterpret_cast<char*>(p);
    std::size_t left = n * sizeof(double);
    while (left > 0) {
      const ssize_t r = ::pread(fd_, b, left, at);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0)
        throw InputError(dir_, 0, "TMPDIR",
                         std::string("cannot read back the record's temporary spill file: ") +
                             (r < 0 ? std::strerror(errno) : "short file"));
      b += r;
      at += r;
      left -= static_cast<std::size_t>(r);
    }
  }
  std::size_t columns() const noexcept { return columns_; }

 private:
  std::size_t columns_;
  std::string dir_;
  int fd_ = -1;
};

ColumnStore::ColumnStore(std::vector<std::span<const double>> cols) : mem_(std::move(cols)) {
  rows_ = mem_.empty() ? 0 : mem_[0].size();
  for (const auto& c : mem_)
    if (c.size() != rows_) throw std::invalid_argument("ColumnStore: columns differ in length");
}

std::span<const double> ColumnStore::column(std::size_t c) const {
  if (file_) throw std::logic_error("ColumnStore::column: the store is spilled to a file (read it in chunks)");
  return mem_.at(c);
}

void ColumnStore::read(std::size_t c, std::size_t begin, std::size_t n, double* out) const {
  if (c >= columns() || begin > rows_ || n > rows_ - begin) throw std::out_of_range("ColumnStore::read: past the end");
  if (!file_) {
    if (n) std::memcpy(out, mem_[c].data() + begin, n * sizeof(double));
    return;
  }
  constexpr std::size_t B = SpillWriter::kBlockRows;
  while (n > 0) {
    const std::size_t blk = begin / B, off = begin % B, m = std::min(n, B - off);
    file_->read(out, m, file_->offset(blk, c, off));
    out += m;
    begin += m;
    n -= m;
  }
}

double ColumnStore::at(std::size_t c, std::size_t row) const {
  double x = 0.0;
  read(c, row, 1, &x);
  return x;
}

SpillWriter::SpillWriter(std::size_t columns)
    : columns_(columns), block_(columns * kBlockRows), file_(std::make_shared<SpillFile>(columns)) {}

SpillWriter::~SpillWriter() = default;

void SpillWriter::flush_block() {
  for (std::size_t c = 0; c < columns_; ++c) file_->write(block_.data() + c * kBlockRows, fill_, file_->offset(blocks_, c, 0));
  if (fill_ == kBlockRows) {
    ++blocks_;
    fill_ = 0;
  }
}

void SpillWriter::push_columns(const std::vector<std::vector<double>>& cols, std::size_t n) {
  std::vector<double> row(columns_);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < columns_; ++c) row[c] = cols[c][i];
    push(row.data());
  }
}

ColumnStore SpillWriter::finish() {
  if (!file_) throw std::logic_error("SpillWriter::finish called twice");
  if (fill_ > 0) flush_block();  // the last, partial block
  ColumnStore s;
  s.file_ = std::move(file_);
  s.file_columns_ = columns_;
  s.rows_ = rows_;
  return s;
}

}  // namespace lash
