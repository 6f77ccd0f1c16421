// The read+parse floor of `lash estimate` (bench/estimate_e2e.py): what a hand-written program
// does at the least to get a t,v,y CSV into memory: read the file in 1 MiB blocks, skip the
// header line, parse the three columns of every line with std::from_chars into three vectors.
// Nothing else: no separator sniffing, no checks, no error messages.
//
//   lash_estimate_floor FILE      prints "rows N seconds S" (wall time of the read and parse)
#include <unistd.h>
#include <fcntl.h>

#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: lash_estimate_floor FILE\n");
    return 2;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const int fd = ::open(argv[1], O_RDONLY);
  if (fd < 0) {
    std::perror(argv[1]);
    return 2;
  }
  std::vector<double> t, v, y;
  // room for the most rows the file can hold ("0,0,0\n" = 6 bytes): never reallocated; pages
  // never written are never resident
  const off_t size = ::lseek(fd, 0, SEEK_END);
  ::lseek(fd, 0, SEEK_SET);
  const auto most = static_cast<std::size_t>(size > 0 ? size : 0) / 6 + 1;
  t.reserve(most);
  v.reserve(most);
  y.reserve(most);
  std::vector<char> buf(1 << 20);
  std::size_t have = 0;
  bool header = true;
  for (;;) {
    const ssize_t got = ::read(fd, buf.data() + have, buf.size() - have);
    if (got < 0) return 2;
    have += static_cast<std::size_t>(got);
    const char* p = buf.data();
    const char* end = buf.data() + have;
    for (;;) {
      const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
      if (!nl) break;
      if (header) {
        header = false;
      } else {
        double a = 0, b = 0, c = 0;
        auto r = std::from_chars(p, nl, a);
        r = std::from_chars(r.ptr + 1, nl, b);
        std::from_chars(r.ptr + 1, nl, c);
        t.push_back(a);
        v.push_back(b);
        y.push_back(c);
      }
      p = nl + 1;
    }
    have = static_cast<std::size_t>(end - p);
    std::memmove(buf.data(), p, have);
    if (got == 0) break;
  }
  ::close(fd);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double sum = 0;  // read the columns once so that nothing is optimised away
  for (std::size_t i = 0; i < t.size(); i += 4096) sum += t[i] + v[i] + y[i];
  std::printf("rows %zu seconds %.6f checksum %g\n", t.size(), s, sum);
  return 0;
}
