// can::LogReader / LogWriter: the log formats one record at a time (log_reader.hpp).
#include "lash/can/log_reader.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <deque>
#include <memory>
#include <vector>

#include <fmt/core.h>

#include "lash/io/error.hpp"
#include "log_formats.hpp"

namespace lash::can {

namespace detail {

std::size_t ByteSource::read_full(char* dst, std::size_t n) {
  std::size_t got = 0;
  while (got < n) {
    const std::size_t k = read(dst + got, n - got);
    if (k == 0) break;
    got += k;
  }
  return got;
}

std::uint64_t ByteSource::skip(std::uint64_t n) {
  char scratch[1 << 14];
  std::uint64_t done = 0;
  while (done < n) {
    const std::size_t k = read(scratch, static_cast<std::size_t>(std::min<std::uint64_t>(n - done, sizeof scratch)));
    if (k == 0) break;
    done += k;
  }
  return done;
}

}  // namespace detail

namespace {

/// A file, FIFO or standard input, read(2) as the bytes come.
class FdSource final : public detail::ByteSource {
 public:
  explicit FdSource(const std::filesystem::path& path) : file_(path.string()) {
    if (file_ == "-") {
      fd_ = 0;
      own_ = false;
      return;
    }
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw InputError(file_, 0, "", "cannot open log file for reading");
  }
  ~FdSource() override {
    if (own_) ::close(fd_);
  }
  FdSource(const FdSource&) = delete;
  FdSource& operator=(const FdSource&) = delete;
  std::size_t read(char* dst, std::size_t n) override {
    for (;;) {
      const ssize_t r = ::read(fd_, dst, n);
      if (r >= 0) return static_cast<std::size_t>(r);
      if (errno != EINTR) throw InputError(file_, 0, "", std::string("cannot read the log: ") + std::strerror(errno));
    }
  }

 private:
  std::string file_;
  int fd_ = -1;
  bool own_ = true;
};

/// Bytes in memory, handed over in pieces of `chunk` (0: as asked).
class MemSource final : public detail::ByteSource {
 public:
  MemSource(std::string_view bytes, std::size_t chunk) : bytes_(bytes), chunk_(chunk) {}
  std::size_t read(char* dst, std::size_t n) override {
    n = std::min(n, bytes_.size() - at_);
    if (chunk_ > 0) n = std::min(n, chunk_);
    if (n) std::memcpy(dst, bytes_.data() + at_, n);
    at_ += n;
    return n;
  }

 private:
  std::string_view bytes_;
  std::size_t chunk_;
  std::size_t at_ = 0;
};

/// Lines of a byte source ('\n' ends a line; a last line without one counts), at most
/// LogReader::kMaxLineBytes each: a longer one is skipped to its end and reported as overlong.
/// A byte buffer that is not zeroed: the reader writes every byte before it reads it. The zeroed
/// 256 KiB vector of before cost each reader a memset and its page faults, and under ASan an
/// mmap and munmap, whatever the input's size: the fuzz gates' small inputs ran at 1 200
/// executions/s on a paravirtualised host (500 000 of them past the gate's 300 s); with this
/// buffer and a 64 KiB first chunk, 20 000/s.
class RawBuffer {
 public:
  explicit RawBuffer(std::size_t n) : p_(new char[n]), n_(n) {}
  char* data() noexcept { return p_.get(); }
  std::size_t size() const noexcept { return n_; }
  /// Twice the size, the first `keep` bytes kept.
  void grow(std::size_t keep) {
    std::unique_ptr<char[]> q(new char[2 * n_]);
    std::memcpy(q.get(), p_.get(), keep);
    p_ = std::move(q);
    n_ *= 2;
  }

 private:
  std::unique_ptr<char[]> p_;
  std::size_t n_;
};

class LineSource {
 public:
  explicit LineSource(detail::ByteSource& src) : src_(src), buf_(kChunk) {}
  bool next(std::string_view& line, bool& overlong) {
    overlong = false;
    for (;;) {
      if (const void* nl = std::memchr(buf_.data() + begin_, '\n', end_ - begin_)) {
        const std::size_t at = static_cast<std::size_t>(static_cast<const char*>(nl) - buf_.data());
        line = std::string_view(buf_.data() + begin_, at - begin_);
        begin_ = at + 1;
        if (line.size() > LogReader::kMaxLineBytes) {  // whole in the buffer, still too long
          line = {};
          overlong = true;
        }
        return true;
      }
      if (eof_) {
        if (begin_ == end_) return false;
        line = std::string_view(buf_.data() + begin_, end_ - begin_);
        begin_ = end_;
        if (line.size() > LogReader::kMaxLineBytes) {
          line = {};
          overlong = true;
        }
        return true;
      }
      if (end_ - begin_ > LogReader::kMaxLineBytes) {
        skip_line();
        overlong = true;
        line = {};
        return true;
      }
      if (begin_ > 0) {  // keep the partial line at the front
        std::memmove(buf_.data(), buf_.data() + begin_, end_ - begin_);
        end_ -= begin_;
        begin_ = 0;
      }
      if (end_ == buf_.size()) buf_.grow(end_);
      const std::size_t n = src_.read(buf_.data() + end_, buf_.size() - end_);
      if (n == 0) eof_ = true;
      end_ += n;
    }
  }

 private:
  static constexpr std::size_t kChunk = std::size_t{1} << 16;  // 64 KiB: below ASan's mmap threshold
  /// Forgets bytes up to and including the next '\n' (or the end).
  void skip_line() {
    begin_ = end_ = 0;
    for (;;) {
      const std::size_t n = src_.read(buf_.data(), buf_.size());
      if (n == 0) {
        eof_ = true;
        return;
      }
      if (const void* nl = std::memchr(buf_.data(), '\n', n)) {
        begin_ = static_cast<std::size_t>(static_cast<const char*>(nl) - buf_.data()) + 1;
        end_ = n;
        return;
      }
    }
  }
  detail::ByteSource& src_;
  RawBuffer buf_;
  std::size_t begin_ = 0, end_ = 0;
  bool eof_ = false;
};

}  // namespace

struct LogReader::Impl {
  std::string file;
  LogFormat format = LogFormat::candump;
  LogReadReport* report = nullptr;
  std::size_t keep = static_cast<std::size_t>(-1);
  std::unique_ptr<detail::ByteSource> src;
  std::unique_ptr<LineSource> lines;
  long lineno = 0;
  detail::AscLines asc;
  detail::TrcLines trc;
  std::unique_ptr<detail::BlfStream> blf;
  std::deque<LogEntry> queue;
  std::uint64_t count = 0;

  void open() {
    if (format == LogFormat::blf) blf = std::make_unique<detail::BlfStream>(*src, file, report);
    else lines = std::make_unique<LineSource>(*src);
  }
  bool next(LogEntry& out) {
    if (blf) {
      while (queue.empty())
        if (!blf->fill(queue)) return false;
      out = std::move(queue.front());
      queue.pop_front();
      return true;
    }
    std::string_view line;
    bool overlong = false;
    while (lines->next(line, overlong)) {
      ++lineno;
      if (overlong) {
        detail::drop(report, file, lineno, "line", fmt::format("longer than {} bytes: skipped", kMaxLineBytes));
        continue;
      }
      bool got = false;
      switch (format) {
        case LogFormat::asc: got = asc.line(line, lineno, file, report, out); break;
        case LogFormat::trc: got = trc.line(line, lineno, file, report, out); break;
        default: got = detail::candump_line(line, lineno, file, report, out); break;
      }
      if (got) return true;
    }
    return false;
  }
};

LogReader::LogReader(const std::filesystem::path& path, LogReadReport* report) : impl_(std::make_unique<Impl>()) {
  impl_->file = path.string();
  impl_->format = log_format_of(path);
  impl_->report = report;
  impl_->src = std::make_unique<FdSource>(path);
  impl_->open();
}

LogReader::LogReader(std::string_view bytes, LogFormat format, std::string name, LogReadReport* report, std::size_t chunk)
    : impl_(std::make_unique<Impl>()) {
  impl_->file = std::move(name);
  impl_->format = format;
  impl_->report = report;
  impl_->src = std::make_unique<MemSource>(bytes, chunk);
  impl_->open();
}

LogReader::~LogReader() = default;
LogReader::LogReader(LogReader&&) noexcept = default;
LogReader& LogReader::operator=(LogReader&&) noexcept = default;

bool LogReader::next(LogEntry& out) {
  const bool got = impl_->next(out);
  if (impl_->report && impl_->report->problems.size() > impl_->keep) impl_->report->problems.resize(impl_->keep);
  if (got) ++impl_->count;
  return got;
}

LogFormat LogReader::format() const noexcept { return impl_->format; }
std::uint64_t LogReader::count() const noexcept { return impl_->count; }
void LogReader::keep_problems(std::size_t n) noexcept { impl_->keep = n; }

struct LogWriter::Impl {
  std::ostream& os;
  LogFormat format;
  detail::TimeCheck check;
  double t0;
  std::uint64_t n = 0;
  std::unique_ptr<detail::BlfWriter> blf;
};

LogWriter::LogWriter(std::ostream& out, LogFormat format, const LogTimes& times, std::string file)
    : impl_(std::make_unique<Impl>(Impl{out, format, detail::TimeCheck(format, times, std::move(file)),
                                        times.count ? times.earliest_s : 0.0, 0, nullptr})) {
  switch (format) {
    case LogFormat::asc: detail::asc_header(out); break;
    case LogFormat::trc: detail::trc_header(out); break;
    case LogFormat::blf: {
      // the header's start time is the earliest frame's (logs may go backwards): no object time is negative
      const TimeSpan span = writable_times(LogFormat::blf);
      const double t0 = impl_->t0;
      const bool ok = std::isfinite(t0) && t0 >= span.min_abs_s && t0 < span.max_abs_s;
      impl_->blf = std::make_unique<detail::BlfWriter>(out, ok ? detail::blf_start_of(t0) : 0.0);
      break;
    }
    default: break;
  }
}

LogWriter::~LogWriter() = default;

void LogWriter::write(const LogEntry& e) {
  auto& m = *impl_;
  m.check.check(e.frame.timestamp_s, m.n);
  ++m.n;
  switch (m.format) {
    case LogFormat::asc: detail::asc_entry(m.os, e, m.t0); break;
    case LogFormat::trc: detail::trc_entry(m.os, e, m.t0, m.n); break;
    case LogFormat::blf: m.blf->entry(e); break;
    default: m.os << format_log_line(e.frame, e.interface) << '\n'; break;
  }
}

void LogWriter::finish() {
  auto& m = *impl_;
  if (m.format == LogFormat::asc) detail::asc_trailer(m.os);
  if (m.blf) m.blf->finish();
}

}  // namespace lash::can
