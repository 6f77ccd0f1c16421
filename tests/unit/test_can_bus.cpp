// In-memory bus and the python-can udp_multicast datagram format.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <string>
#include <vector>

#include "lash/can/bus.hpp"
#include "lash/can/controller_bus.hpp"
#include "lash/can/datagram.hpp"
#include "lash/can/log.hpp"
#include "lash/can/replay.hpp"
#include "lash/io/error.hpp"
#include "lash/signals/rng.hpp"

using namespace lash::can;
using namespace std::chrono_literals;

namespace {
std::vector<std::uint8_t> unhex(const std::string& h) {
  std::vector<std::uint8_t> v;
  for (std::size_t i = 0; i + 1 < h.size(); i += 2) v.push_back(static_cast<std::uint8_t>(std::stoi(h.substr(i, 2), nullptr, 16)));
  return v;
}
// Bytes produced by python-can 4.1 (can.interfaces.udp_multicast.utils.pack_message) for
// Message(timestamp=1.5, arbitration_id=0x123, data=DEADBEEF) and
// Message(timestamp=0, arbitration_id=0x1abcdef0, is_extended_id=True, is_remote_frame=True, dlc=3).
const char* kPy1 =
    "8ba974696d657374616d70cb3ff8000000000000ae6172626974726174696f6e5f6964cd0123ae69735f657874656e6465645f6964c2af6973"
    "5f72656d6f74655f6672616d65c2ae69735f6572726f725f6672616d65c2a76368616e6e656cc0a3646c6304a464617461c404deadbeefa569"
    "735f6664c2ae626974726174655f737769746368c2b56572726f725f73746174655f696e64696361746f72c2";
const char* kPy2 =
    "8ba974696d657374616d70cb0000000000000000ae6172626974726174696f6e5f6964ce1abcdef0ae69735f657874656e6465645f6964c3af"
    "69735f72656d6f74655f6672616d65c3ae69735f6572726f725f6672616d65c2a76368616e6e656cc0a3646c6303a464617461c400a56973"
    "5f6664c2ae626974726174655f737769746368c2b56572726f725f73746174655f696e64696361746f72c2";
}  // namespace

TEST(CanBus, MemBusDeliversToOthersInOrderNotToSelf) {
  auto a = open_bus("mem:t1");
  auto b = open_bus("mem:t1");
  auto c = open_bus("mem:t1");
  auto other = open_bus("mem:t2");
  for (std::uint32_t i = 0; i < 10; ++i) {
    Frame f;
    f.id = i;
    f.len = 1;
    f.data[0] = static_cast<std::uint8_t>(i * 3);
    f.timestamp_s = 0.005 * i;
    ASSERT_TRUE(a->send(f));
  }
  EXPECT_FALSE(a->receive(0ns).has_value());
  EXPECT_FALSE(other->receive(0ns).has_value());
  for (std::uint32_t i = 0; i < 10; ++i) {
    auto fb = b->receive(0ns);
    auto fc = c->receive(1ms);
    ASSERT_TRUE(fb && fc);
    EXPECT_EQ(fb->id, i);
    EXPECT_EQ(fc->data[0], i * 3);
    EXPECT_EQ(fb->timestamp_s, 0.005 * i);
  }
  EXPECT_EQ(a->stats().sent, 10u);
  EXPECT_EQ(b->stats().received, 10u);
  EXPECT_EQ(b->address(), "mem:t1");
}

TEST(CanBus, Filters) {
  auto a = open_bus("mem:f");
  auto b = open_bus("mem:f");
  b->set_filters({{0x100, 0x700, false}, {0x18FF0000, 0x1FFF0000, true}});
  Frame f;
  for (std::uint32_t id : {0x100u, 0x1FFu, 0x200u}) {
    f.id = id;
    a->send(f);
  }
  f.extended = true;
  f.id = 0x18FF1234;
  a->send(f);
  f.id = 0x100;  // extended 0x100 does not match the standard filter
  a->send(f);
  std::vector<std::uint32_t> got;
  while (auto r = b->receive(0ns)) got.push_back(r->id);
  EXPECT_EQ(got, (std::vector<std::uint32_t>{0x100, 0x1FF, 0x18FF1234}));
  EXPECT_EQ(b->stats().filtered, 2u);
}

TEST(CanBus, BadAddresses) {
  EXPECT_THROW(open_bus("nope:x"), lash::InputError);
  EXPECT_THROW(open_bus("mem:"), lash::InputError);
  EXPECT_THROW(open_bus("udp:10.0.0.1:43113"), lash::InputError);
  EXPECT_THROW(open_bus("udp:239.74.163.2:99999"), lash::InputError);
  EXPECT_THROW(open_bus("udp:239.74.163.2:43113,foo=1"), lash::InputError);
  EXPECT_THROW(open_bus("socketcan:lash_no_such_if0"), lash::InputError);
}

TEST(CanDatagram, EncodesExactlyLikePythonCan) {
  Frame f;
  f.id = 0x123;
  f.len = 4;
  f.data = {0xDE, 0xAD, 0xBE, 0xEF};
  std::uint8_t buf[256];
  std::size_t n = udp::encode_datagram(f, 1.5, buf);
  EXPECT_EQ(std::vector<std::uint8_t>(buf, buf + n), unhex(kPy1));
  Frame r;
  r.id = 0x1abcdef0;
  r.extended = true;
  r.remote = true;
  r.len = 3;
  n = udp::encode_datagram(r, 0.0, buf);
  EXPECT_EQ(std::vector<std::uint8_t>(buf, buf + n), unhex(kPy2));
}

TEST(CanDatagram, DecodesPythonCanBytes) {
  Frame f;
  ASSERT_EQ(udp::decode_datagram(unhex(kPy1), f), udp::DecodeStatus::ok);
  EXPECT_EQ(f.id, 0x123u);
  EXPECT_EQ(f.len, 4);
  EXPECT_EQ(f.data[3], 0xEF);
  EXPECT_EQ(f.timestamp_s, 1.5);
  ASSERT_EQ(udp::decode_datagram(unhex(kPy2), f), udp::DecodeStatus::ok);
  EXPECT_TRUE(f.extended && f.remote);
  EXPECT_EQ(f.len, 3);
}

TEST(CanDatagram, RejectsBadDatagrams) {
  Frame f;
  auto ok = unhex(kPy1);
  // unknown key: rename "channel" to "chunnel"
  auto u = ok;
  const std::string ch = "channel";
  auto it = std::search(u.begin(), u.end(), ch.begin(), ch.end());
  ASSERT_NE(it, u.end());
  it[2] = 'u';
  EXPECT_EQ(udp::decode_datagram(u, f), udp::DecodeStatus::unknown_key);
  // truncated
  EXPECT_EQ(udp::decode_datagram(std::span(ok.data(), ok.size() - 1), f), udp::DecodeStatus::malformed);
  // trailing garbage
  auto t = ok;
  t.push_back(0);
  EXPECT_EQ(udp::decode_datagram(t, f), udp::DecodeStatus::malformed);
  // oversized
  std::vector<std::uint8_t> big(udp::kMaxDatagram + 1, 0x90);
  EXPECT_EQ(udp::decode_datagram(big, f), udp::DecodeStatus::oversized);
  // dlc 5 with 4 data bytes
  auto d = ok;
  const std::string dlc = "dlc";
  it = std::search(d.begin(), d.end(), dlc.begin(), dlc.end());
  it[3] = 5;
  EXPECT_EQ(udp::decode_datagram(d, f), udp::DecodeStatus::invalid);
  // random bytes never crash
  lash::Rng rng(3);
  int okc = 0;
  for (int i = 0; i < 20000; ++i) {
    auto m = ok;
    for (int k = 0; k < 3; ++k) m[rng.next() % m.size()] = static_cast<std::uint8_t>(rng.next());
    if (udp::decode_datagram(m, f) == udp::DecodeStatus::ok) ++okc;
  }
  EXPECT_GT(okc, 0);
}

// UDP multicast bus: needs a private network namespace with a multicast route on lo;
// the ctest `can_udp_netns` runs these under tests/cli/can_netns.sh with LASH_NETNS=1.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <thread>

namespace {
bool in_netns() { return std::getenv("LASH_NETNS") != nullptr; }
void send_raw(const std::vector<std::uint8_t>& d, std::uint16_t port) {
  const int s = ::socket(AF_INET, SOCK_DGRAM, 0);
  const unsigned char ttl = 0;
  ::setsockopt(s, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  inet_pton(AF_INET, "239.74.163.2", &a.sin_addr);
  ::sendto(s, d.data(), d.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
  ::close(s);
}
}  // namespace

TEST(CanUdp, OthersReceiveNeverSelf) {
  if (!in_netns()) GTEST_SKIP() << "needs tests/cli/can_netns.sh (LASH_NETNS=1)";
  auto a = open_bus("udp:239.74.163.2:43200");
  auto b = open_bus("udp:239.74.163.2:43200");
  EXPECT_EQ(a->address(), "udp:239.74.163.2:43200");
  Frame f;
  f.id = 0x321;
  f.len = 2;
  f.data[0] = 0xAB;
  f.data[1] = 0xCD;
  ASSERT_TRUE(a->send(f));
  auto r = b->receive(2s);
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(same_content(*r, f));
  EXPECT_GT(r->timestamp_s, 1.5e9);  // kernel receive time, Unix epoch
  EXPECT_FALSE(a->receive(200ms).has_value());  // never its own frame
  ASSERT_TRUE(b->send(f));
  EXPECT_TRUE(a->receive(2s).has_value());
  EXPECT_FALSE(b->receive(200ms).has_value());
}

TEST(CanUdp, DropsAndCountsBadDatagramsAndFilters) {
  if (!in_netns()) GTEST_SKIP() << "needs tests/cli/can_netns.sh (LASH_NETNS=1)";
  auto b = open_bus("udp:239.74.163.2:43201");
  b->set_filters({{0x123, 0x7FF, false}});
  send_raw({0xc1}, 43201);                                // malformed
  send_raw(std::vector<std::uint8_t>(1500, 0x90), 43201);  // oversized
  auto esi = unhex(kPy1);
  esi.back() = 0xc3;  // error_state_indicator without is_fd: python-can rejects it, so do we
  send_raw(esi, 43201);
  send_raw(unhex(kPy1), 43201);
  auto other = unhex(kPy1);
  const std::string id = "arbitration_id";
  auto it = std::search(other.begin(), other.end(), id.begin(), id.end());
  it[id.size() + 2] = 0x24;  // id 0x124: filtered out
  send_raw(other, 43201);
  auto r = b->receive(2s);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->id, 0x123u);
  EXPECT_FALSE(b->receive(300ms).has_value());
  const auto st = b->stats();
  EXPECT_EQ(st.dropped, 3u);
  EXPECT_EQ(st.filtered, 1u);
  EXPECT_EQ(st.received, 1u);
}

TEST(CanUdp, ReceiveBatchReadsAtMostItsBudget) {
  // A flood of 400 filtered frames with one accepted frame behind it: receive_batch reads at
  // most max_reads datagrams and receive(0) gives up after its own budget of 256 reads, so
  // neither drains the flood in one call; the accepted frame comes with the third call.
  if (!in_netns()) GTEST_SKIP() << "needs tests/cli/can_netns.sh (LASH_NETNS=1)";
  auto b = open_bus("udp:239.74.163.2:43202");
  b->set_filters({{0x123, 0x7FF, false}});
  auto other = unhex(kPy1);
  const std::string id = "arbitration_id";
  auto it = std::search(other.begin(), other.end(), id.begin(), id.end());
  it[id.size() + 2] = 0x24;  // id 0x124: filtered out
  for (int i = 0; i < 400; ++i) send_raw(other, 43202);
  send_raw(unhex(kPy1), 43202);
  std::this_thread::sleep_for(100ms);
  std::vector<Frame> out(8);
  BatchResult r = b->receive_batch(out, 100);
  EXPECT_EQ(r.stored, 0u);
  EXPECT_EQ(r.reads, 100u);
  EXPECT_FALSE(r.drained);
  EXPECT_EQ(b->stats().filtered, 100u);
  EXPECT_FALSE(b->receive(0ns).has_value());
  EXPECT_EQ(b->stats().filtered, 356u);
  r = b->receive_batch(out, 100);  // 44 filtered, then the frame, then nothing
  EXPECT_EQ(r.stored, 1u);
  EXPECT_EQ(r.reads, 45u);
  EXPECT_TRUE(r.drained);
  EXPECT_EQ(out[0].id, 0x123u);
  EXPECT_EQ(b->stats().filtered, 400u);
  EXPECT_EQ(b->stats().received, 1u);
  EXPECT_EQ(b->stats().dropped, 0u);
}

TEST(CanController, FifosDecoupleTheTaskFromTheWire) {
  auto wire_a = open_bus("mem:ctl1");
  auto peer = open_bus("mem:ctl1");
  ControllerBus ctl(*wire_a, ControllerConfig{4, 2, 64});
  Frame f;
  f.len = 1;
  // TX: nothing reaches the wire before flush(); a full TX FIFO refuses.
  f.id = 0x10;
  EXPECT_TRUE(ctl.send(f));
  f.id = 0x11;
  EXPECT_TRUE(ctl.send(f));
  f.id = 0x12;
  EXPECT_FALSE(ctl.send(f));
  EXPECT_EQ(ctl.controller_stats().tx_overflows, 1u);
  EXPECT_FALSE(peer->receive(0ns).has_value());
  EXPECT_EQ(ctl.flush(), 2u);
  EXPECT_EQ(peer->receive(0ns)->id, 0x10u);
  EXPECT_EQ(peer->receive(0ns)->id, 0x11u);
  EXPECT_EQ(ctl.tx_pending(), 0u);
  // RX: frames wait on the wire until pull(); 6 frames into a 4-deep FIFO keep the newest 4.
  for (std::uint32_t i = 0; i < 6; ++i) {
    f.id = 0x20 + i;
    ASSERT_TRUE(peer->send(f));
  }
  EXPECT_FALSE(ctl.receive(0ns).has_value());
  EXPECT_EQ(ctl.pull(), 6u);  // drained in two batches of at most one FIFO's worth
  EXPECT_EQ(ctl.controller_stats().rx_overflows, 2u);
  EXPECT_EQ(ctl.controller_stats().pulls_cut, 0u);
  for (std::uint32_t i = 2; i < 6; ++i) EXPECT_EQ(ctl.receive(0ns)->id, 0x20 + i);
  EXPECT_FALSE(ctl.receive(0ns).has_value());
  // Filters are the wire's (the controller's acceptance filters).
  ctl.set_filters({{0x30, 0x7FF, false}});
  f.id = 0x31;
  peer->send(f);
  f.id = 0x30;
  peer->send(f);
  EXPECT_EQ(ctl.pull(), 1u);
  EXPECT_EQ(ctl.receive(0ns)->id, 0x30u);
  EXPECT_EQ(ctl.stats().filtered, 1u);
  EXPECT_THROW(ControllerBus(*wire_a, ControllerConfig{0, 1, 1, 0}), std::invalid_argument);
  EXPECT_THROW(ControllerBus(*wire_a, ControllerConfig{1, 1, 1, -1}), std::invalid_argument);
}

TEST(CanController, PullStopsAtItsReadBudget) {
  // 10 frames queued, at most 3 wire reads per pull(): 3 + 3 + 3 + 1, each cut pull counted.
  auto wire = open_bus("mem:ctl2");
  auto peer = open_bus("mem:ctl2");
  ControllerBus ctl(*wire, ControllerConfig{16, 2, 3, 0});
  Frame f;
  f.len = 1;
  for (std::uint32_t i = 0; i < 10; ++i) {
    f.id = 0x40 + i;
    ASSERT_TRUE(peer->send(f));
  }
  EXPECT_EQ(ctl.pull(), 3u);
  EXPECT_EQ(ctl.pull(), 3u);
  EXPECT_EQ(ctl.pull(), 3u);
  EXPECT_EQ(ctl.pull(), 1u);
  EXPECT_EQ(ctl.controller_stats().pulls_cut, 3u);
  EXPECT_EQ(ctl.controller_stats().rx_reads, 10u);
  for (std::uint32_t i = 0; i < 10; ++i) EXPECT_EQ(ctl.receive(0ns)->id, 0x40 + i);
}

TEST(CanReplay, KeepsErrorRemoteAndFdFlagsOnTheMemBus) {
  // A candump log with an error frame, a remote frame and CAN FD frames with BRS/ESI:
  // replayed on a mem bus, another node receives every frame with its flags.
  const auto entries = lash::can::parse_log(
      "(1.000000) can0 20000080#0000000000000000\n"
      "(1.001000) can0 7FF#R3\n"
      "(1.002000) can0 123##3" + std::string(24, 'A') + "\n"
      "(1.003000) can0 12345678##2AB\n",
      "r.log");
  ASSERT_EQ(entries.size(), 4u);
  auto tx = open_bus("mem:replay");
  auto rx = open_bus("mem:replay");
  std::atomic<bool> stop{false};
  lash::can::ReplayOptions o;
  o.speed = 10.0;
  o.spin_ns = 0;
  const auto r = lash::can::replay(*tx, entries, o, stop);
  EXPECT_EQ(r.sent, 4u);
  EXPECT_FALSE(r.interrupted);
  for (const auto& e : entries) {
    const auto f = rx->receive(std::chrono::milliseconds(100));
    ASSERT_TRUE(f);
    EXPECT_TRUE(same_content(*f, e.frame));
  }
  EXPECT_TRUE(entries[0].frame.error);
  EXPECT_TRUE(entries[2].frame.brs && entries[2].frame.esi && entries[2].frame.len == 12);
  EXPECT_TRUE(!entries[3].frame.brs && entries[3].frame.esi);
  // and a stop request before the start sends nothing
  stop = true;
  EXPECT_EQ(lash::can::replay(*tx, entries, o, stop).sent, 0u);
}
