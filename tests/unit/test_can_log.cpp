// candump -L lines and cansend frame text.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "lash/can/log.hpp"
#include "lash/can/log_reader.hpp"
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

namespace {
/// Random frames of every kind (classic, extended, remote, error, FD with BRS/ESI), 1 ms apart.
std::vector<LogEntry> random_entries(std::size_t n, std::uint32_t seed) {
  std::uint64_t s = seed * 6364136223846793005ull + 1442695040888963407ull;
  const auto next = [&] {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<std::uint32_t>(s >> 33);
  };
  std::vector<LogEntry> v;
  for (std::size_t i = 0; i < n; ++i) {
    LogEntry e;
    e.interface = "1";
    Frame& f = e.frame;
    f.timestamp_s = 1600000000.0 + 0.001 * static_cast<double>(i);
    const std::uint32_t kind = next() % 10;
    f.extended = kind == 1 || kind == 5;
    f.id = next() & (f.extended ? 0x1FFFFFFFu : 0x7FFu);
    if (kind == 2) {
      f.remote = true;
      f.len = static_cast<std::uint8_t>(next() % 9);
    } else if (kind == 3) {
      f.error = true;  // ASC and TRC error frames hold no class bits nor data
      f.extended = false;
      f.id = 0;
      f.len = 0;
    } else if (kind >= 4 && kind <= 5) {
      static constexpr std::uint8_t fd[] = {0, 5, 8, 12, 16, 20, 24, 32, 48, 64};
      f.fd = true;
      f.brs = next() % 2;
      f.esi = next() % 2;
      f.len = fd[next() % 10];
    } else {
      f.len = static_cast<std::uint8_t>(next() % 9);
    }
    if (!f.remote)
      for (std::size_t k = 0; k < f.len; ++k) f.data[k] = static_cast<std::uint8_t>(next());
    v.push_back(e);
  }
  return v;
}

std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct Read {
  std::vector<LogEntry> entries;
  LogReadReport report;
};
Read read_chunked(std::string_view bytes, LogFormat format, std::size_t chunk) {
  Read r;
  LogReader reader(bytes, format, "x", &r.report, chunk);
  for (LogEntry e; reader.next(e);) r.entries.push_back(e);
  EXPECT_EQ(reader.count(), r.entries.size());
  return r;
}
}  // namespace

// LogReader hands out the frames and drops of the whole text whatever pieces the bytes arrive in
// (a FIFO written slowly): every record boundary, BLF objects continued in the next container
// (lash writes 128 KiB containers: 20 000 frames span several) and damage included.
TEST(CanLog, StreamingReadIsTheWholeRead) {
  const auto entries = random_entries(20000, 7);
  for (const char* ext : {".log", ".asc", ".trc", ".blf"}) {
    const auto p = std::filesystem::temp_directory_path() / (std::string("lash_test_stream") + ext);
    write_log(p, entries);
    std::string bytes = file_bytes(p);
    std::filesystem::remove(p);
    const LogFormat format = log_format_of(p);
    const Read whole = read_chunked(bytes, format, 0);
    ASSERT_EQ(whole.entries.size(), entries.size()) << ext;
    EXPECT_EQ(whole.report.dropped, 0u) << ext;
    for (std::size_t i = 0; i < entries.size(); ++i)
      ASSERT_TRUE(same_content(whole.entries[i].frame, entries[i].frame)) << ext << " frame " << i;
    // damage: garbage lines in the texts; a BLF cut in the middle of a container
    std::size_t expect_dropped = 0;
    if (format == LogFormat::blf) {
      bytes.resize(bytes.size() * 2 / 3);
      expect_dropped = 1;
    } else {
      for (std::size_t at = bytes.size() / 7, k = 0; k < 5; ++k, at += bytes.size() / 7) {
        at = bytes.find('\n', at) + 1;
        bytes.insert(at, format == LogFormat::candump ? "(1.0) x 12#0\n"
                         : format == LogFormat::asc   ? "1.000000 1 7FF Rx d 9 00\n"
                                                      : "      1       1.000 DT  1     07FF Rx -  9    00\r\n");
        ++expect_dropped;
      }
    }
    const Read damaged = read_chunked(bytes, format, 0);
    EXPECT_EQ(damaged.report.dropped, expect_dropped) << ext;
    for (const std::size_t chunk : {std::size_t{1}, std::size_t{3}, std::size_t{4093}}) {
      const Read r = read_chunked(bytes, format, chunk);
      ASSERT_EQ(r.entries.size(), damaged.entries.size()) << ext << " chunk " << chunk;
      for (std::size_t i = 0; i < r.entries.size(); ++i) {
        ASSERT_TRUE(same_content(r.entries[i].frame, damaged.entries[i].frame)) << ext << " chunk " << chunk << " frame " << i;
        ASSERT_EQ(r.entries[i].frame.timestamp_s, damaged.entries[i].frame.timestamp_s);
        ASSERT_EQ(r.entries[i].interface, damaged.entries[i].interface);
      }
      EXPECT_EQ(r.report.problems, damaged.report.problems) << ext << " chunk " << chunk;
    }
  }
}

TEST(CanLog, StreamingReadDropsOverlongLinesAndKeepsFewProblems) {
  std::string text = "(1.000000) can0 123#00\n" + std::string(LogReader::kMaxLineBytes + 10, 'x') + "\n";
  for (int i = 0; i < 50; ++i) text += "garbage\n";
  text += "(2.000000) can0 124#01\n";
  LogReadReport report;
  LogReader r(text, LogFormat::candump, "big.log", &report, 100000);
  r.keep_problems(3);
  std::vector<LogEntry> got;
  for (LogEntry e; r.next(e);) got.push_back(e);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[1].frame.id, 0x124u);
  EXPECT_EQ(report.dropped, 51u);
  ASSERT_EQ(report.problems.size(), 3u);
  EXPECT_EQ(report.problems[0].rfind("big.log:2: line: longer than", 0), 0u) << report.problems[0];
  EXPECT_EQ(report.problems[1].rfind("big.log:3: candump line", 0), 0u) << report.problems[1];
}
