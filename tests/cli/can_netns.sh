#!/usr/bin/env bash
# Runs a command inside a private network namespace with multicast on loopback:
#   unshare -n; ip link set lo up; ip route add 224.0.0.0/4 dev lo
# No traffic leaves the namespace. Needs root (or user namespaces).
set -euo pipefail
if ! unshare -n true 2>/dev/null; then
  if ! unshare -rn true 2>/dev/null; then
    echo "can_netns: cannot create a network namespace (unshare -n); run as root" >&2
    exit 1
  fi
  exec unshare -rn bash -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"' netns "$@"
fi
exec unshare -n bash -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"' netns "$@"
