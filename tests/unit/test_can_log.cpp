// candump -L lines and cansend frame text.
#include <gtest/gtest.h>

#include <filesystem>

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
  for (const char* bad : {"800#00", "12#00", "123#0", "123#GG", "123#001122334455667788", "3FFFFFFF#00", "123", "123#R9"})
    EXPECT_FALSE(parse_frame_text(bad, err)) << bad;
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
