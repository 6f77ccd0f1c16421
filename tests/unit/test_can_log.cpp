// candump -L lines and cansend frame text.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "lash/can/log.hpp"
#include "lash/io/error.hpp"

using namespace lash::can;

TEST(CanLog, FrameText) {
  std::string err;
  auto f = parse_frame_text("123#DEADBEEF", err);
  ASSERT_TRUE(f) << err;
  EXPECT_EQ(f->id, 0x123u);
  EXPECT_FALSE(f->extended);
  EXPECT_EQ(f->len, 4);
  EXPECT_EQ(f->data[0], 0xDE);
  EXPECT_EQ(f->data[3], 0xEF);
  EXPECT_EQ(format_frame_text(*f), "123#DEADBEEF");
  f = parse_frame_text("1ABCDEF0#", err);
  ASSERT_TRUE(f);
  EXPECT_TRUE(f->extended);
  EXPECT_EQ(f->id, 0x1ABCDEF0u);
  EXPECT_EQ(f->len, 0);
  EXPECT_EQ(format_frame_text(*f), "1ABCDEF0#");
  f = parse_frame_text("7FF#R", err);
  ASSERT_TRUE(f);
  EXPECT_TRUE(f->remote);
  EXPECT_EQ(format_frame_text(*f), "7FF#R");
  f = parse_frame_text("001#R3", err);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->len, 3);
  EXPECT_EQ(format_frame_text(*f), "001#R3");
  f = parse_frame_text("001#11.22.33", err);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->len, 3);
  for (const char* bad : {"800#00", "12#00", "123#0", "123#GG", "123#001122334455667788", "5FFFFFFF#00", "123", "123#R9",
                          "123##4AA", "123##1001122334455667788", "123##R"})
    EXPECT_FALSE(parse_frame_text(bad, err)) << bad;
}

TEST(CanLog, ErrorAndFdFlags) {
  std::string err;
  // candump -e: CAN_ERR_FLAG (0x20000000) | error class, 8 data bytes
  auto f = parse_frame_text("20000080#0000000000000000", err);
  ASSERT_TRUE(f) << err;
  EXPECT_TRUE(f->error);
  EXPECT_FALSE(f->extended);
  EXPECT_EQ(f->id, 0x80u);
  EXPECT_TRUE(f->valid());
  EXPECT_EQ(format_frame_text(*f), "20000080#0000000000000000");
  // CAN FD flags digit: 1 = BRS, 2 = ESI
  f = parse_frame_text("123##3AABB", err);
  ASSERT_TRUE(f) << err;
  EXPECT_TRUE(f->fd && f->brs && f->esi);
  EXPECT_EQ(format_frame_text(*f), "123##3AABB");
  f = parse_frame_text("12345678##1" + std::string(24, '0'), err);
  ASSERT_TRUE(f) << err;
  EXPECT_TRUE(f->fd && f->brs && !f->esi && f->extended);
  EXPECT_EQ(f->len, 12);
  Frame g = *f;
  g.brs = false;
  EXPECT_FALSE(same_content(g, *f));  // the flags are part of the content
}

TEST(CanLog, CandumpDefaultOutput) {
  std::string err;
  auto e = parse_log_line("  vcan0  0C8   [8]  F0 00 00 00 00 00 00 01", err);
  ASSERT_TRUE(e) << err;
  EXPECT_EQ(e->frame.id, 0xC8u);
  EXPECT_EQ(e->frame.len, 8);
  EXPECT_EQ(e->frame.data[7], 1);
  e = parse_log_line(" (2020-12-19 12:04:45.485261)  vcan0  1F4   [4]  01 02 03 04", err);
  ASSERT_TRUE(e) << err;
  EXPECT_NEAR(e->frame.timestamp_s, 1608379485.485261, 1e-6);  // calendar.timegm((2020,12,19,12,4,45))
  e = parse_log_line(" (012.831664)  vcan0  1F4   [4]  01 02 03 04", err);
  ASSERT_TRUE(e) << err;
  EXPECT_NEAR(e->frame.timestamp_s, 12.831664, 1e-9);
  e = parse_log_line("  vcan0  20000004   [8]  00 00 00 00 00 00 00 00   ERRORFRAME", err);
  ASSERT_TRUE(e) << err;
  EXPECT_TRUE(e->frame.error);
  EXPECT_EQ(e->frame.id, 4u);
  for (const char* bad : {"  vcan0  064   [10]  F0 01 FF FF FF FF FF FF FF FF", "  vcan0  ERROR", "  vcan0  0C8   [3]  F0 00"})
    EXPECT_FALSE(parse_log_line(bad, err)) << bad;
  // a tolerant read counts and locates the bad lines
  LogReadReport report;
  const auto v = parse_log("  vcan0  0C8   [1]  F0\n  vcan0  ERROR\n\n(1.000000) can0 123#00\n", "x.log", &report);
  EXPECT_EQ(v.size(), 2u);
  EXPECT_EQ(report.dropped, 1u);
  ASSERT_EQ(report.problems.size(), 1u);
  EXPECT_NE(report.problems[0].find("x.log:2"), std::string::npos) << report.problems[0];
  EXPECT_THROW(parse_log("  vcan0  ERROR\n", "x.log"), lash::InputError);
}

TEST(CanLog, Lines) {
  std::string err;
  auto e = parse_log_line("(1600000000.123456) vcan0 123#0102", err);
  ASSERT_TRUE(e) << err;
  EXPECT_EQ(e->interface, "vcan0");
  EXPECT_NEAR(e->frame.timestamp_s, 1600000000.123456, 1e-6);
  EXPECT_EQ(format_log_line(e->frame, e->interface), "(1600000000.123456) vcan0 123#0102");
  e = parse_log_line("(0.000001) can1 12345678#R R", err);  // python-can's trailing direction
  ASSERT_TRUE(e) << err;
  EXPECT_EQ(format_log_line(e->frame, "can1"), "(0.000001) can1 12345678#R");
  Frame f;
  f.timestamp_s = 2.0000004;
  EXPECT_EQ(format_log_line(f, "x"), "(2.000000) x 000#");
  f.timestamp_s = 2.9999996;
  EXPECT_EQ(format_log_line(f, "x"), "(3.000000) x 000#");
  for (const char* bad : {"1600000000.1 vcan0 123#00", "(1.5) vcan0", "(x.5) vcan0 123#00", "(1.5) vcan0 123#0"})
    EXPECT_FALSE(parse_log_line(bad, err)) << bad;
}

TEST(CanLog, FileErrorsNameTheLine) {
  try {
    parse_log("(1.000000) vcan0 123#00\n\n(2.000000) vcan0 123#0G\n", "x.log");
    FAIL();
  } catch (const lash::InputError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.file(), "x.log");
  }
  const auto tmp = std::filesystem::temp_directory_path() / "lash_test_can_log.log";
  std::vector<LogEntry> v = parse_log("(1.000000) vcan0 123#00\n(2.500000) vcan0 1ABCDEF0#R\n");
  write_log(tmp, v);
  const auto back = read_log(tmp);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_TRUE(same_content(back[1].frame, v[1].frame));
  EXPECT_EQ(back[1].frame.timestamp_s, 2.5);
  std::filesystem::remove(tmp);
}

namespace {
std::vector<LogEntry> frames_at(std::initializer_list<double> times) {
  std::vector<LogEntry> v;
  for (double t : times) {
    std::string err;
    LogEntry e{*parse_frame_text("123#01", err), "1"};
    e.frame.timestamp_s = t;
    v.push_back(e);
  }
  return v;
}
/// write_log's InputError for `times` in `ext`, "" when it writes; the file must not exist after a refusal.
std::string refusal(const std::string& ext, std::initializer_list<double> times) {
  const auto p = std::filesystem::temp_directory_path() / ("lash_test_times" + ext);
  std::filesystem::remove(p);
  try {
    write_log(p, frames_at(times));
  } catch (const lash::InputError& e) {
    EXPECT_FALSE(std::filesystem::exists(p)) << "half-written " << p;
    return e.field() + ": " + e.message();
  }
  std::filesystem::remove(p);
  return "";
}
}  // namespace

// Limits from the formats' fields: BLF object times are uint64 nanoseconds from the header's
// start, 2^64 ns = 18446744073.709551616 s; the header's SYSTEMTIME year is a uint16 (year 65536
// begins at 2005949145600 s = day 23217004 after 1970-01-01, days_from_civil evaluated in Python,
// which gives 946684800 s for 2000-01-01); candump's reader takes 12 digits of seconds.
TEST(CanLog, WritersRefuseTimesTheirFormatCannotHold) {
  // the BLF finding of the fuzzer: two frames 1.8446744e10 s apart (just below 2^64 ns + 0.5 rounding)
  EXPECT_EQ(refusal(".blf", {0.0, 18446744073.709551}).rfind("frame 2: timestamp", 0), 0u);
  EXPECT_EQ(refusal(".blf", {0.0, 18446744072.0}), "");
  EXPECT_NE(refusal(".blf", {-1.0, 5.0}).find("frame 1"), std::string::npos);  // before 1990: offsets from 0
  EXPECT_EQ(refusal(".blf", {2005949145599.0}), "");
  EXPECT_NE(refusal(".blf", {2005949145600.0}), "");
  EXPECT_NE(refusal(".blf", {1.0, std::nan("")}).find("frame 2"), std::string::npos);
  EXPECT_NE(refusal(".log", {1.0, -0.5}).find("frame 2"), std::string::npos);
  EXPECT_NE(refusal(".log", {1e12}), "");
  EXPECT_EQ(refusal(".log", {999999999999.0}), "");
  EXPECT_NE(refusal(".asc", {1.0, std::numeric_limits<double>::infinity()}).find("frame 2"), std::string::npos);
  EXPECT_NE(refusal(".trc", {-1e308, 1e308}).find("frame 2"), std::string::npos);  // the offset overflows
  EXPECT_EQ(refusal(".asc", {-5.0, 1e9}), "");
  EXPECT_EQ(refusal(".trc", {-5.0, 1e9}), "");
}

TEST(CanLog, BlfKeepsTimesAtTheEdgeOfItsRange) {
  const auto p = std::filesystem::temp_directory_path() / "lash_test_edge.blf";
  const auto v = frames_at({1.0, 18446744000.0});
  write_log(p, v);
  const auto back = read_log(p);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_DOUBLE_EQ(back[1].frame.timestamp_s, 18446744000.0);
  std::filesystem::remove(p);
}
