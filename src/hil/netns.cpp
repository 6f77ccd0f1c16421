#include "lash/hil/netns.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <net/if.h>
#include <net/route.h>
#include <netinet/in.h>
#include <sched.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

namespace lash::hil {
namespace {

bool write_file(const char* path, const std::string& text) {
  std::ofstream f(path);
  if (!f) return false;
  f << text;
  f.close();
  return static_cast<bool>(f);
}

std::string errno_text(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

std::string setup_loopback() {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return errno_text("socket");
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, "lo", IFNAMSIZ - 1);
  std::string err;
  if (ioctl(fd, SIOCGIFFLAGS, &ifr) != 0) {
    err = errno_text("SIOCGIFFLAGS lo");
  } else {
    ifr.ifr_flags = static_cast<short>(ifr.ifr_flags | IFF_UP | IFF_RUNNING);
    if (ioctl(fd, SIOCSIFFLAGS, &ifr) != 0) err = errno_text("bringing lo up");
  }
  if (err.empty()) {
    rtentry rt{};
    auto* dst = reinterpret_cast<sockaddr_in*>(&rt.rt_dst);
    dst->sin_family = AF_INET;
    dst->sin_addr.s_addr = htonl(0xE0000000u);  // 224.0.0.0
    auto* mask = reinterpret_cast<sockaddr_in*>(&rt.rt_genmask);
    mask->sin_family = AF_INET;
    mask->sin_addr.s_addr = htonl(0xF0000000u);  // /4
    auto* gw = reinterpret_cast<sockaddr_in*>(&rt.rt_gateway);
    gw->sin_family = AF_INET;
    rt.rt_flags = RTF_UP;
    char dev[] = "lo";
    rt.rt_dev = dev;
    if (ioctl(fd, SIOCADDRT, &rt) != 0 && errno != EEXIST) err = errno_text("route 224.0.0.0/4 dev lo");
  }
  close(fd);
  return err;
}

}  // namespace

NetnsResult enter_private_netns() {
  NetnsResult r;
  if (unshare(CLONE_NEWNET) == 0) {
    r.how = "root";
  } else {
    const std::string root_err = errno_text("unshare(CLONE_NEWNET)");
    const uid_t uid = getuid();
    const gid_t gid = getgid();
    if (unshare(CLONE_NEWUSER | CLONE_NEWNET) != 0) {
      r.error = root_err + "; " + errno_text("unshare(CLONE_NEWUSER|CLONE_NEWNET)");
      return r;
    }
    write_file("/proc/self/setgroups", "deny");
    if (!write_file("/proc/self/uid_map", "0 " + std::to_string(uid) + " 1\n") ||
        !write_file("/proc/self/gid_map", "0 " + std::to_string(gid) + " 1\n")) {
      r.error = "user namespace: cannot write uid/gid map";
      return r;
    }
    r.how = "user namespace";
  }
  const std::string err = setup_loopback();
  if (!err.empty()) {
    r.error = err;
    return r;
  }
  r.ok = true;
  return r;
}

}  // namespace lash::hil
