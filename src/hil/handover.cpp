// The binary hand-over of a node's run to its session (handover.hpp).
#include "lash/hil/handover.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <type_traits>

#include "lash/io/error.hpp"

namespace lash::hil {

// ----------------------------------------------------------------------------- hand-over

namespace {
constexpr std::uint64_t kMagic = 0x6C6173682D72756EULL;  // "lash-run"

void write_all(int fd, const void* p, std::size_t n) {
  const auto* b = static_cast<const char*>(p);
  while (n > 0) {
    const ssize_t w = ::write(fd, b, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) throw SystemError(std::string("cannot hand the run over: ") + std::strerror(errno));
    b += w;
    n -= static_cast<std::size_t>(w);
  }
}

struct Writer {
  int fd;
  template <class T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    write_all(fd, &v, sizeof v);
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod(static_cast<std::uint64_t>(v.size()));
    if (!v.empty()) write_all(fd, v.data(), v.size() * sizeof(T));
  }
  void strings(const std::vector<std::string>& v) {
    pod(static_cast<std::uint64_t>(v.size()));
    for (const auto& s : v) {
      pod(static_cast<std::uint64_t>(s.size()));
      write_all(fd, s.data(), s.size());
    }
  }
};

struct Reader {
  explicit Reader(int f) : fd(f) {
    struct stat st {};
    if (::fstat(fd, &st) == 0 && st.st_size >= 0) size = static_cast<std::uint64_t>(st.st_size);
  }
  int fd;
  off_t at = 0;
  bool ok = true;
  std::uint64_t size = 0;  ///< of the hand-over file: no count read from it may ask for more bytes than it holds
  bool fits(std::uint64_t n, std::uint64_t elem) const noexcept {
    const auto left = size - std::min<std::uint64_t>(size, static_cast<std::uint64_t>(at));
    return elem == 0 || n <= left / elem;
  }
  bool raw(void* p, std::size_t n) {
    auto* b = static_cast<char*>(p);
    while (ok && n > 0) {
      const ssize_t r = ::pread(fd, b, n, at);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) ok = false;
      else {
        b += r;
        n -= static_cast<std::size_t>(r);
        at += r;
      }
    }
    return ok;
  }
  template <class T>
  bool pod(T& v) {
    return raw(&v, sizeof v);
  }
  template <class T>
  bool vec(std::vector<T>& v) {
    std::uint64_t n = 0;
    if (!pod(n) || n > (std::uint64_t{1} << 32) || !fits(n, sizeof(T))) return ok = false;
    v.resize(n);
    return n == 0 || raw(v.data(), n * sizeof(T));
  }
  bool strings(std::vector<std::string>& v) {
    std::uint64_t n = 0;
    if (!pod(n) || n > 4096 || !fits(n, sizeof(std::uint64_t))) return ok = false;
    v.resize(n);
    for (auto& s : v) {
      std::uint64_t len = 0;
      if (!pod(len) || len > (1u << 20) || !fits(len, 1)) return ok = false;
      s.resize(len);
      if (len && !raw(s.data(), len)) return false;
    }
    return ok;
  }
};

void write_common(Writer& w, const NodeStats& st, const LoopTrace& t) {
  w.pod(kMagic);
  w.pod(st);
  w.vec(t.records);
  w.vec(t.overruns);
  w.strings(t.warnings);
}
bool read_common(Reader& r, NodeStats& st, LoopTrace& t) {
  std::uint64_t magic = 0;
  return r.pod(magic) && magic == kMagic && r.pod(st) && r.vec(t.records) && r.vec(t.overruns) && r.strings(t.warnings);
}
}  // namespace

void write_run(int fd, const SlaveRun& run) {
  Writer w{fd};
  write_common(w, run.stats, run.loop);
  w.vec(run.log);
  w.vec(run.events);
}

void write_run(int fd, const MasterRun& run) {
  Writer w{fd};
  write_common(w, run.stats, run.loop);
  w.vec(run.log);
  w.vec(run.events);
  w.vec(run.bus_log);
  w.vec(run.calibration);
}

bool read_run(int fd, SlaveRun& run) {
  Reader r(fd);
  return read_common(r, run.stats, run.loop) && r.vec(run.log) && r.vec(run.events);
}

bool read_run(int fd, MasterRun& run) {
  Reader r(fd);
  return read_common(r, run.stats, run.loop) && r.vec(run.log) && r.vec(run.events) && r.vec(run.bus_log) &&
         r.vec(run.calibration);
}

}  // namespace lash::hil
