#include "lash/io/column_store.hpp"

#include <fcntl.h>
#include <sys/mman.h>
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
    if (map_) ::munmap(map_, map_len_);
    if (fd_ >= 0) ::close(fd_);
  }
  /// Maps the finished file read-only (passes then read it in place, without a copy); without a
  /// mapping (mmap refused, e.g. under a low RLIMIT_AS) every read copies through pread.
  void map(std::size_t bytes) {
    if (bytes == 0) return;
    void* p = ::mmap(nullptr, bytes, PROT_READ, MAP_SHARED, fd_, 0);
    if (p == MAP_FAILED) return;
    map_ = p;
    map_len_ = bytes;
  }
  /// The mapped doubles at byte offset `at`, or nullptr without a mapping.
  const double* mapped(off_t at) const noexcept {
    return map_ ? reinterpret_cast<const double*>(static_cast<const char*>(map_) + at) : nullptr;
  }
  /// Drops the mapping's pages of [at, at + bytes) from the process (they stay in the page cache;
  /// a later touch maps them again): the resident set stays one block whatever the record.
  void release(off_t at, std::size_t bytes) const noexcept {
    if (map_ && bytes) ::madvise(static_cast<char*>(map_) + at, bytes, MADV_DONTNEED);
  }
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  off_t offset(std::size_t block, std::size_t column, std::size_t row_in_block) const noexcept {
    return static_cast<off_t>(((block * columns_ + column) * SpillWriter::kBlockRows + row_in_block) * sizeof(double));
  }
  void write(const double* p, std::size_t n, off_t at) const {
    transfer(const_cast<double*>(p), n, at, "write", [](int fd, char* b, std::size_t len, off_t o) {
      return ::pwrite(fd, b, len, o);
    });
  }
  void read(double* p, std::size_t n, off_t at) const {
    transfer(p, n, at, "read back", [](int fd, char* b, std::size_t len, off_t o) { return ::pread(fd, b, len, o); });
  }
  std::size_t columns() const noexcept { return columns_; }

 private:
  /// n doubles at byte offset `at` through op (pread or pwrite), retried until all are moved.
  template <class Op>
  void transfer(double* p, std::size_t n, off_t at, const char* what, Op op) const {
    char* b = reinterpret_cast<char*>(p);
    std::size_t left = n * sizeof(double);
    while (left > 0) {
      const ssize_t r = op(fd_, b, left, at);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0)
        throw InputError(dir_, 0, "TMPDIR",
                         std::string("cannot ") + what + " the record's temporary spill file: " +
                             (r < 0 ? std::strerror(errno) : "no progress"));
      b += r;
      at += r;
      left -= static_cast<std::size_t>(r);
    }
  }
  std::size_t columns_;
  std::string dir_;
  int fd_ = -1;
  void* map_ = nullptr;
  std::size_t map_len_ = 0;
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

const double* ColumnStore::mapped(std::size_t c, std::size_t begin, std::size_t n) const noexcept {
  constexpr std::size_t B = SpillWriter::kBlockRows;
  if (!file_ || c >= file_columns_ || begin > rows_ || n > rows_ - begin || n == 0 || begin % B + n > B) return nullptr;
  return file_->mapped(file_->offset(begin / B, c, begin % B));
}

void ColumnStore::release_block(std::size_t row) const noexcept {
  constexpr std::size_t B = SpillWriter::kBlockRows;
  if (!file_ || row >= rows_) return;
  const std::size_t blk = row / B;
  const std::size_t in_block = std::min(B, rows_ - blk * B);  // the last block's columns end early
  const off_t at = file_->offset(blk, 0, 0);
  file_->release(at, ((file_columns_ - 1) * B + in_block) * sizeof(double));
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
  if (rows_ > 0) {  // the file ends with the last block's last column
    const std::size_t last = (rows_ - 1) / kBlockRows;
    file_->map(static_cast<std::size_t>(file_->offset(last, columns_ - 1, rows_ - last * kBlockRows)));
  }
  ColumnStore s;
  s.file_ = std::move(file_);
  s.file_columns_ = columns_;
  s.rows_ = rows_;
  return s;
}

}  // namespace lash
