#pragma once
/// @file netns.hpp
/// A private network namespace for an emulation, so that its multicast traffic
/// cannot leave the machine: unshare(CLONE_NEWNET) (as root), or a user namespace
/// plus a network namespace when unprivileged user namespaces are allowed; then
/// loopback up and 224.0.0.0/4 routed on it (ioctl SIOCSIFFLAGS / SIOCADDRT, no
/// iproute2 needed). Not real-time safe; call while the process is single-threaded.
#include <string>

namespace lash::hil {

struct NetnsResult {
  bool ok = false;
  std::string how;    ///< "root" or "user namespace" when ok
  std::string error;  ///< why not, when !ok
};

/// Moves the calling process (and the children it starts afterwards) into a new network namespace.
NetnsResult enter_private_netns();

}  // namespace lash::hil
