// The XCP slave engine at the byte level: every request and every expected reply below is
// written by hand from the tables of ASAM MCD-1 XCP V1.1 Part 2 (command/response layouts,
// "description of commands") and Part 3 CAN (classic frames, MAX_CTO = MAX_DTO = 8), not produced by lash's client.
#include <cstdio>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "lash/can/xcp.hpp"

namespace xcp = lash::can::xcp;
using lash::can::Frame;
using Bytes = std::vector<std::uint8_t>;

namespace {

// Objects: kp (f64, 0..10) at 0x10010, mode (u8, 0..2) at 0x10018, y (f64 measurement) at 0x10020,
// n (u16 measurement) at 0x10028. EPK "EPK1" at 0x10000, ascii "lash" at 0x10004, name "m" at 0x10008.
xcp::SlaveConfig config() {
  xcp::SlaveConfig c;
  c.epk = "EPK1";
  c.ascii_id = "lash";
  c.a2l_name = "m";
  c.epk_address = 0x10000;
  c.objects = {
      {"kp", xcp::Kind::characteristic, xcp::Type::f64, "mA/kPa", 0.0, 10.0, 0x10010, "", {}},
      {"mode", xcp::Kind::characteristic, xcp::Type::u8, "", 0.0, 2.0, 0x10018, "", {}},
      {"y", xcp::Kind::measurement, xcp::Type::f64, "kPa", -1e4, 1e4, 0x10020, "", {}},
      {"n", xcp::Kind::measurement, xcp::Type::u16, "", 0, 65535, 0x10028, "", {}},
  };
  return c;
}

struct Fixture {
  std::vector<Frame> out;
  std::vector<std::pair<std::uint32_t, std::size_t>> writes;
  xcp::Slave slave{config(), [this](const Frame& f) { out.push_back(f); },
                   [this](std::uint32_t a, std::size_t n) { writes.emplace_back(a, n); }};

  // Sends one command frame (id 0x7F0) and returns the frames the slave sent.
  std::vector<Bytes> cmd(Bytes b) {
    Frame f;
    f.id = 0x7F0;
    f.len = static_cast<std::uint8_t>(b.size());
    std::memcpy(f.data.data(), b.data(), b.size());
    out.clear();
    slave.on_frame(f);
    std::vector<Bytes> r;
    for (const auto& g : out) {
      EXPECT_EQ(g.id, 0x7F1u);
      r.emplace_back(g.data.begin(), g.data.begin() + g.len);
    }
    return r;
  }
  Bytes one(Bytes b) {
    auto r = cmd(std::move(b));
    EXPECT_EQ(r.size(), 1u);
    return r.empty() ? Bytes{} : r[0];
  }
  void connect() { ASSERT_EQ(one({0xFF, 0x00}).at(0), 0xFF); }
};

// kp = 0.7 as IEEE 754 binary64, little-endian: 0x3FE6666666666666.
const Bytes kKp07 = {0x66, 0x66, 0x66, 0x66, 0x66, 0x66, 0xE6, 0x3F};
// 20.0 = 0x4034000000000000 (outside kp's 0..10).
const Bytes k20 = {0, 0, 0, 0, 0, 0, 0x34, 0x40};

}  // namespace

TEST(Xcp, ConnectResponseBytes) {
  Fixture x;
  // Part 2, CONNECT: FF RESOURCE COMM_MODE_BASIC MAX_CTO MAX_DTO(WORD) PROTOCOL TRANSPORT.
  // RESOURCE = CAL/PAG (bit 0) | DAQ (bit 2) = 0x05; COMM_MODE_BASIC = OPTIONAL (bit 7) |
  // SLAVE_BLOCK_MODE (bit 6), BYTE_ORDER Intel (bit 0 = 0), granularity BYTE = 0xC0.
  EXPECT_EQ(x.one({0xFF, 0x00}), (Bytes{0xFF, 0x05, 0xC0, 0x08, 0x08, 0x00, 0x01, 0x01}));
  EXPECT_TRUE(x.slave.connected());
}

TEST(Xcp, CommandsBeforeConnectAreIgnored) {
  Fixture x;
  // Part 2, state machine: in DISCONNECTED state the slave answers CONNECT only.
  EXPECT_TRUE(x.cmd({0xFD}).empty());                                        // GET_STATUS
  EXPECT_TRUE(x.cmd({0xF6, 0, 0, 0, 0x10, 0x00, 0x01, 0x00}).empty());      // SET_MTA
  EXPECT_TRUE(x.cmd({0xF0, 0x06, 1, 2, 3, 4, 5, 6}).empty());               // DOWNLOAD
  EXPECT_TRUE(x.writes.empty());
  EXPECT_EQ(x.slave.get(*x.slave.find("kp")), 0.0);
}

TEST(Xcp, StatusSynchCommModeAndUnknown) {
  Fixture x;
  x.connect();
  EXPECT_EQ(x.one({0xFD}), (Bytes{0xFF, 0x00, 0x00, 0x00, 0x00, 0x00}));      // GET_STATUS
  EXPECT_EQ(x.one({0xFC}), (Bytes{0xFE, 0x00}));                              // SYNCH → ERR_CMD_SYNCH
  // GET_COMM_MODE_INFO: FF, reserved, COMM_MODE_OPTIONAL (MASTER_BLOCK_MODE), reserved, MAX_BS, MIN_ST, QUEUE, version
  EXPECT_EQ(x.one({0xFB}), (Bytes{0xFF, 0x00, 0x01, 0x00, 32, 0x00, 0x00, 0x10}));
  EXPECT_EQ(x.one({0xC9}), (Bytes{0xFE, 0x20}));                              // unknown → ERR_CMD_UNKNOWN
  EXPECT_EQ(x.one({0xF6, 0, 0}), (Bytes{0xFE, 0x21}));                        // SET_MTA, DLC 3 → ERR_CMD_SYNTAX
  EXPECT_EQ(x.one({}), (Bytes{0xFE, 0x21}));                                  // DLC 0
  EXPECT_EQ(x.one({0xFE}), (Bytes{0xFF}));                                    // DISCONNECT
  EXPECT_TRUE(x.cmd({0xFD}).empty());
}

TEST(Xcp, GetIdReturnsTheEpkByUpload) {
  Fixture x;
  x.connect();
  // GET_ID type 5 (EPK): FF MODE=0 (upload) reserved(2) LENGTH(DWORD) = 4; MTA at the EPK.
  EXPECT_EQ(x.one({0xFA, 0x05}), (Bytes{0xFF, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00}));
  EXPECT_EQ(x.one({0xF5, 0x04}), (Bytes{0xFF, 'E', 'P', 'K', '1'}));
  EXPECT_EQ(x.one({0xFA, 0x01}), (Bytes{0xFF, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00}));
  EXPECT_EQ(x.one({0xF5, 0x01}), (Bytes{0xFF, 'm'}));
  EXPECT_EQ(x.one({0xFA, 0x09}), (Bytes{0xFE, 0x22}));
}

TEST(Xcp, DownloadNextBlockIsOneConsistentWrite) {
  Fixture x;
  x.connect();
  EXPECT_EQ(x.one({0xF6, 0, 0, 0, 0x10, 0x00, 0x01, 0x00}), (Bytes{0xFF}));  // SET_MTA 0x00010010 (kp)
  // DOWNLOAD 8 elements, 6 in this packet: master block mode, no response yet.
  EXPECT_TRUE(x.cmd({0xF0, 0x08, 0x66, 0x66, 0x66, 0x66, 0x66, 0x66}).empty());
  EXPECT_TRUE(x.writes.empty());
  EXPECT_EQ(x.slave.get(*x.slave.find("kp")), 0.0);  // nothing half-written
  // DOWNLOAD_NEXT, 2 remaining.
  EXPECT_EQ(x.one({0xEF, 0x02, 0xE6, 0x3F}), (Bytes{0xFF}));
  ASSERT_EQ(x.writes.size(), 1u);
  EXPECT_EQ(x.writes[0], (std::pair<std::uint32_t, std::size_t>{0x10010, 8}));
  EXPECT_EQ(x.slave.get(*x.slave.find("kp")), 0.7);
  // Read back: SHORT_UPLOAD 7 bytes at 0x10010, then UPLOAD 8 bytes in slave block mode (7 + 1).
  EXPECT_EQ(x.one({0xF4, 0x07, 0x00, 0x00, 0x10, 0x00, 0x01, 0x00}),
            (Bytes{0xFF, 0x66, 0x66, 0x66, 0x66, 0x66, 0x66, 0xE6}));
  x.one({0xF6, 0, 0, 0, 0x10, 0x00, 0x01, 0x00});
  const auto up = x.cmd({0xF5, 0x08});
  ASSERT_EQ(up.size(), 2u);
  EXPECT_EQ(up[0], (Bytes{0xFF, 0x66, 0x66, 0x66, 0x66, 0x66, 0x66, 0xE6}));
  EXPECT_EQ(up[1], (Bytes{0xFF, 0x3F}));
}

TEST(Xcp, DownloadNextWrongCountIsSequenceErrorAndNothingWritten) {
  Fixture x;
  x.connect();
  x.one({0xF6, 0, 0, 0, 0x10, 0x00, 0x01, 0x00});
  EXPECT_TRUE(x.cmd({0xF0, 0x08, 0x66, 0x66, 0x66, 0x66, 0x66, 0x66}).empty());
  // Remaining should be 2: ERR_SEQUENCE (0x29) with the number expected.
  EXPECT_EQ(x.one({0xEF, 0x03, 0xE6, 0x3F, 0x00}), (Bytes{0xFE, 0x29, 0x02}));
  EXPECT_TRUE(x.writes.empty());
  // The block is gone: another DOWNLOAD_NEXT is out of sequence too.
  EXPECT_EQ(x.one({0xEF, 0x02, 0xE6, 0x3F}), (Bytes{0xFE, 0x29}));
  // A SYNCH in the middle of a block abandons it as well.
  x.one({0xF6, 0, 0, 0, 0x10, 0x00, 0x01, 0x00});
  EXPECT_TRUE(x.cmd({0xF0, 0x08, 0x66, 0x66, 0x66, 0x66, 0x66, 0x66}).empty());
  EXPECT_EQ(x.one({0xFC}), (Bytes{0xFE, 0x00}));
  EXPECT_EQ(x.one({0xEF, 0x02, 0xE6, 0x3F}), (Bytes{0xFE, 0x29}));
  EXPECT_TRUE(x.writes.empty());
  EXPECT_EQ(x.slave.get(*x.slave.find("kp")), 0.0);
}

TEST(Xcp, OutOfRangeProtectedAndDenied) {
  Fixture x;
  x.connect();
  x.one({0xF6, 0, 0, 0, 0x10, 0x00, 0x01, 0x00});
  x.cmd({0xF0, 0x08, k20[0], k20[1], k20[2], k20[3], k20[4], k20[5]});
  EXPECT_EQ(x.one({0xEF, 0x02, k20[6], k20[7]}), (Bytes{0xFE, 0x22}));  // 20 > 10: ERR_OUT_OF_RANGE
  EXPECT_EQ(x.slave.get(*x.slave.find("kp")), 0.0);
  x.one({0xF6, 0, 0, 0, 0x18, 0x00, 0x01, 0x00});                       // mode (u8, 0..2)
  EXPECT_EQ(x.one({0xF0, 0x01, 0x03}), (Bytes{0xFE, 0x22}));
  x.one({0xF6, 0, 0, 0, 0x18, 0x00, 0x01, 0x00});
  EXPECT_EQ(x.one({0xF0, 0x01, 0x02}), (Bytes{0xFF}));
  EXPECT_EQ(x.slave.get(*x.slave.find("mode")), 2.0);
  x.one({0xF6, 0, 0, 0, 0x20, 0x00, 0x01, 0x00});                       // y: a measurement
  EXPECT_EQ(x.one({0xF0, 0x01, 0x00}), (Bytes{0xFE, 0x23}));            // ERR_WRITE_PROTECTED
  x.one({0xF6, 0, 0, 0, 0x00, 0x00, 0x01, 0x00});                       // the EPK
  EXPECT_EQ(x.one({0xF0, 0x01, 0x00}), (Bytes{0xFE, 0x23}));
  x.one({0xF6, 0, 0, 0, 0x00, 0x00, 0x02, 0x00});                       // outside the segment
  EXPECT_EQ(x.one({0xF0, 0x01, 0x00}), (Bytes{0xFE, 0x24}));            // ERR_ACCESS_DENIED
  EXPECT_EQ(x.one({0xF5, 0x01}), (Bytes{0xFE, 0x24}));
  EXPECT_EQ(x.one({0xF4, 0x08, 0, 0, 0x10, 0x00, 0x01, 0x00}), (Bytes{0xFE, 0x22}));  // SHORT_UPLOAD > 7
  // Malformed DLC: DOWNLOAD of 4 elements carrying 2.
  x.one({0xF6, 0, 0, 0, 0x10, 0x00, 0x01, 0x00});
  EXPECT_EQ(x.one({0xF0, 0x04, 0x00, 0x00}), (Bytes{0xFE, 0x21}));
  EXPECT_TRUE(x.writes.size() == 1u);  // only the mode write
}

// A named characteristic (COMPU_METHOD TAB_VERB, the master's compensation mode) stored as f64:
// only integers inside its limits are written. 1.5 = 0x3FF8000000000000, 1.0 = 0x3FF0000000000000.
TEST(Xcp, NamedValueOnlyAnInteger) {
  xcp::SlaveConfig c = config();
  c.objects[0] = {"comp", xcp::Kind::characteristic, xcp::Type::f64, "", 0.0, 2.0, 0x10010, "", {"none", "fixed", "adaptive"}};
  std::vector<Frame> out;
  xcp::Slave s{c, [&](const Frame& f) { out.push_back(f); }, nullptr};
  auto one = [&](Bytes b, std::size_t answers = 1) {
    Frame f;
    f.id = 0x7F0;
    f.len = static_cast<std::uint8_t>(b.size());
    std::memcpy(f.data.data(), b.data(), b.size());
    out.clear();
    s.on_frame(f);
    EXPECT_EQ(out.size(), answers);
    return out.empty() ? Bytes{} : Bytes(out[0].data.begin(), out[0].data.begin() + out[0].len);
  };
  ASSERT_EQ(one({0xFF, 0x00}).at(0), 0xFF);
  one({0xF6, 0, 0, 0, 0x10, 0x00, 0x01, 0x00});
  one({0xF0, 0x08, 0, 0, 0, 0, 0, 0}, 0);  // master block mode: no answer yet
  EXPECT_EQ(one({0xEF, 0x02, 0xF8, 0x3F}), (Bytes{0xFE, 0x22}));  // 1.5: ERR_OUT_OF_RANGE
  EXPECT_EQ(s.get(*s.find("comp")), 0.0);
  one({0xF6, 0, 0, 0, 0x10, 0x00, 0x01, 0x00});
  one({0xF0, 0x08, 0, 0, 0, 0, 0, 0}, 0);  // master block mode: no answer yet
  EXPECT_EQ(one({0xEF, 0x02, 0xF0, 0x3F}), (Bytes{0xFF}));
  EXPECT_EQ(s.get(*s.find("comp")), 1.0);
}

TEST(Xcp, DynamicDaqListAndOdtLayout) {
  Fixture x;
  x.connect();
  // GET_DAQ_PROCESSOR_INFO: FF, DAQ_PROPERTIES (dynamic 0x01 | timestamp 0x10), MAX_DAQ = 8,
  // MAX_EVENT_CHANNEL = 1, MIN_DAQ = 0, DAQ_KEY_BYTE = 0 (absolute ODT number identification).
  EXPECT_EQ(x.one({0xDA}), (Bytes{0xFF, 0x11, 0x08, 0x00, 0x01, 0x00, 0x00, 0x00}));
  // GET_DAQ_RESOLUTION_INFO: granularity 1, max entry 7, STIM 1/0, TIMESTAMP_MODE 0x3C (4 bytes, fixed, 1 µs), ticks 1.
  EXPECT_EQ(x.one({0xD9}), (Bytes{0xFF, 0x01, 0x07, 0x01, 0x00, 0x3C, 0x01, 0x00}));
  // Out of sequence: ALLOC_ODT before ALLOC_DAQ.
  EXPECT_EQ(x.one({0xD4, 0, 0, 0, 2}), (Bytes{0xFE, 0x29}));
  EXPECT_EQ(x.one({0xD6}), (Bytes{0xFF}));                     // FREE_DAQ
  EXPECT_EQ(x.one({0xD5, 0, 9, 0}), (Bytes{0xFE, 0x30}));      // 9 lists > MAX_DAQ: ERR_MEMORY_OVERFLOW
  EXPECT_EQ(x.one({0xD5, 0, 1, 0}), (Bytes{0xFF}));            // ALLOC_DAQ 1
  EXPECT_EQ(x.one({0xD4, 0, 0, 0, 2}), (Bytes{0xFF}));         // ALLOC_ODT list 0: 2 ODTs
  EXPECT_EQ(x.one({0xD3, 0, 0, 0, 0, 2}), (Bytes{0xFF}));      // ODT 0: 2 entries
  EXPECT_EQ(x.one({0xD3, 0, 0, 0, 1, 2}), (Bytes{0xFF}));      // ODT 1: 2 entries
  EXPECT_EQ(x.one({0xD5, 0, 1, 0}), (Bytes{0xFE, 0x29}));      // ALLOC_DAQ after ALLOC_ODT
  // ODT 0 (timestamp: 1 + 4 + 3 bytes): n (2 bytes) and y's first byte; ODT 1: y's bytes 1..7.
  EXPECT_EQ(x.one({0xE2, 0, 0, 0, 0, 0}), (Bytes{0xFF}));      // SET_DAQ_PTR 0/0/0
  EXPECT_EQ(x.one({0xE1, 0xFF, 2, 0, 0x28, 0x00, 0x01, 0x00}), (Bytes{0xFF}));
  EXPECT_EQ(x.one({0xE1, 0xFF, 1, 0, 0x20, 0x00, 0x01, 0x00}), (Bytes{0xFF}));
  EXPECT_EQ(x.one({0xE1, 0xFF, 1, 0, 0x20, 0x00, 0x01, 0x00}), (Bytes{0xFE, 0x22}));  // past the ODT's entries
  EXPECT_EQ(x.one({0xE2, 0, 0, 0, 1, 0}), (Bytes{0xFF}));
  EXPECT_EQ(x.one({0xE1, 0xFF, 4, 0, 0x21, 0x00, 0x01, 0x00}), (Bytes{0xFF}));
  EXPECT_EQ(x.one({0xE1, 0xFF, 3, 0, 0x25, 0x00, 0x01, 0x00}), (Bytes{0xFF}));
  // SET_DAQ_LIST_MODE: timestamp, list 0, event 0, prescaler 1, priority 0. Event 1 does not exist.
  EXPECT_EQ(x.one({0xE0, 0x10, 0, 0, 1, 0, 1, 0}), (Bytes{0xFE, 0x22}));
  EXPECT_EQ(x.one({0xE0, 0x10, 0, 0, 0, 0, 1, 0}), (Bytes{0xFF}));
  EXPECT_EQ(x.one({0xDE, 0x02, 0, 0}), (Bytes{0xFF, 0x00}));   // select list 0: FIRST_PID 0
  EXPECT_EQ(x.one({0xDD, 0x01}), (Bytes{0xFF}));               // START_STOP_SYNCH start selected
  EXPECT_EQ(x.one({0xFD}).at(1), 0x40);                        // SESSION_STATUS DAQ_RUNNING

  // y = -1.5 = 0xBFF8000000000000, n = 0x1234; timestamp 0x0A0B0C0D.
  x.slave.set(*x.slave.find("y"), -1.5);
  x.slave.set(*x.slave.find("n"), 0x1234);
  x.out.clear();
  x.slave.sample_event(0, 0x0A0B0C0D);
  ASSERT_EQ(x.out.size(), 2u);
  const Bytes odt0(x.out[0].data.begin(), x.out[0].data.begin() + x.out[0].len);
  const Bytes odt1(x.out[1].data.begin(), x.out[1].data.begin() + x.out[1].len);
  EXPECT_EQ(odt0, (Bytes{0x00, 0x0D, 0x0C, 0x0B, 0x0A, 0x34, 0x12, 0x00}));
  EXPECT_EQ(odt1, (Bytes{0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF8, 0xBF}));
  EXPECT_EQ(x.out[0].id, 0x7F1u);
  x.out.clear();
  x.slave.sample_event(1, 0);  // another event channel: nothing
  EXPECT_TRUE(x.out.empty());
  EXPECT_EQ(x.one({0xDD, 0x00}), (Bytes{0xFF}));  // stop all
  x.out.clear();
  x.slave.sample_event(0, 0);
  EXPECT_TRUE(x.out.empty());
}

TEST(Xcp, DaqConfigErrors) {
  Fixture x;
  x.connect();
  x.one({0xD6});
  x.one({0xD5, 0, 1, 0});
  x.one({0xD4, 0, 0, 0, 1});
  x.one({0xD3, 0, 0, 0, 0, 2});
  x.one({0xE2, 0, 0, 0, 0, 0});
  x.one({0xE1, 0xFF, 7, 0, 0x20, 0x00, 0x01, 0x00});
  x.one({0xE1, 0xFF, 1, 0, 0x28, 0x00, 0x01, 0x00});
  x.one({0xE0, 0x10, 0, 0, 0, 0, 1, 0});
  // 1 + 4 (timestamp) + 8 bytes > MAX_DTO: ERR_DAQ_CONFIG.
  EXPECT_EQ(x.one({0xDE, 0x01, 0, 0}), (Bytes{0xFE, 0x2A}));
  EXPECT_EQ(x.one({0xE1, 0xFF, 8, 0, 0x20, 0x00, 0x01, 0x00}), (Bytes{0xFE, 0x22}));  // entry > 7 bytes (ptr at end too)
  EXPECT_EQ(x.one({0xE0, 0x20, 0, 0, 0, 0, 1, 0}), (Bytes{0xFE, 0x27}));  // PID_OFF: ERR_MODE_NOT_VALID
}

// Malformed and random command frames (seeded): never a crash, every answer a valid classic frame
// on the response id, and the calibration objects always inside their limits — a write is whole
// or refused. Part of the frames are well-formed DOWNLOADs of random bytes to kp's address, so
// that both accepted and refused writes happen.
TEST(Xcp, RandomFramesNeverBreakTheLimits) {
  Fixture x;
  std::uint64_t s = 0x9E3779B97F4A7C15ull;  // splitmix64, fixed seed
  auto next = [&] {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  std::size_t accepted = 0;
  for (int i = 0; i < 200000; ++i) {
    Bytes b(next() % 9);
    for (auto& v : b) v = static_cast<std::uint8_t>(next());
    const auto kind = next() % 8;
    if (kind == 0) b = {0xFF, 0x00};                                          // CONNECT
    if (kind == 1) b = {0xF6, 0, 0, 0, static_cast<std::uint8_t>(0x10 + (next() % 3) * 8), 0x00, 0x01, 0x00};
    if (kind == 2 && !b.empty()) b[0] = static_cast<std::uint8_t>(0xEF + next() % 17);  // DOWNLOAD.. family
    if (kind == 3) {  // mode = 0..3 (3 is out of range)
      x.cmd({0xF6, 0, 0, 0, 0x18, 0x00, 0x01, 0x00});
      b = {0xF0, 0x01, static_cast<std::uint8_t>(next() % 4)};
    }
    if (kind == 4) {  // kp = -5..15 in one block (half of them out of range)
      const double v = static_cast<double>(next() % 2001) / 100.0 - 5.0;
      std::uint8_t e[8];
      std::memcpy(e, &v, 8);  // x86/ARM little-endian: the Intel byte order of the slave
      x.cmd({0xF6, 0, 0, 0, 0x10, 0x00, 0x01, 0x00});
      x.cmd({0xF0, 0x08, e[0], e[1], e[2], e[3], e[4], e[5]});
      b = {0xEF, 0x02, e[6], e[7]};
    }
    const auto writes = x.writes.size();
    for (const auto& r : x.cmd(b)) ASSERT_LE(r.size(), 8u);
    accepted += x.writes.size() - writes;
    const double kp = x.slave.get(*x.slave.find("kp"));
    const double mode = x.slave.get(*x.slave.find("mode"));
    ASSERT_TRUE(kp >= 0.0 && kp <= 10.0) << i;
    ASSERT_TRUE(mode >= 0.0 && mode <= 2.0) << i;
  }
  EXPECT_GT(accepted, 5000u);
  EXPECT_GT(x.slave.errors(), 10000u);
  std::printf("random frames: %zu writes accepted, %llu error packets\n", accepted,
              static_cast<unsigned long long>(x.slave.errors()));
}
