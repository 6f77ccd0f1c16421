// DBC parser/writer: fields of the test database, round trip, errors with line and column.
#include <gtest/gtest.h>

#include <string>

#include "lash/can/dbc.hpp"
#include "lash/io/error.hpp"
#include "lash/signals/rng.hpp"

using namespace lash::can::dbc;

namespace {
const std::string kTestDbc = std::string(LASH_SOURCE_DIR) + "/tests/data/can/lash_test.dbc";

/// Line number of the InputError thrown by parsing `text` (0 if none thrown).
int error_line(const std::string& text, std::string* what = nullptr) {
  try {
    parse_dbc(text, "t.dbc");
  } catch (const lash::InputError& e) {
    if (what) *what = e.what();
    return e.line();
  }
  return 0;
}
}  // namespace

TEST(CanDbc, ParsesTheTestDatabase) {
  const Database db = load_dbc(kTestDbc);
  EXPECT_EQ(db.version, "lash test 1");
  EXPECT_EQ(db.nodes, (std::vector<std::string>{"Master", "Slave", "Logger"}));
  ASSERT_EQ(db.messages.size(), 5u);
  const Message* m = db.message("IntelMix");
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->id, 256u);
  EXPECT_EQ(m->size, 8u);
  EXPECT_EQ(m->transmitter, "Master");
  EXPECT_EQ(m->comment, "Intel signals of several kinds");
  const Signal* t = m->signal("Temp");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->start_bit, 16u);
  EXPECT_EQ(t->length, 8u);
  EXPECT_TRUE(t->is_signed);
  EXPECT_EQ(t->byte_order, ByteOrder::intel);
  EXPECT_EQ(t->factor, 0.5);
  EXPECT_EQ(t->offset, -20.0);
  EXPECT_EQ(t->minimum, -84.0);
  EXPECT_EQ(t->maximum, 43.5);
  EXPECT_EQ(t->unit, "degC");
  EXPECT_EQ(m->signal("Speed")->receivers, (std::vector<std::string>{"Slave", "Logger"}));
  EXPECT_EQ(m->signal("Speed")->comment, "vehicle speed; with a \"quoted\" word");
  EXPECT_EQ(m->signal("Flag")->values.size(), 2u);
  const Message* mo = db.message(0x200, false);
  ASSERT_NE(mo, nullptr);
  EXPECT_EQ(mo->signal("Pressure")->byte_order, ByteOrder::motorola);
  EXPECT_EQ(mo->signal("Pressure")->start_bit, 7u);
  const Message* mux = db.message("Muxed");
  EXPECT_EQ(mux->signal("Mode")->mux, MuxRole::multiplexor);
  EXPECT_EQ(mux->signal("B_Current")->mux, MuxRole::multiplexed);
  EXPECT_EQ(mux->signal("B_Current")->mux_value, 1u);
  const Message* ext = db.message("ExtFloat");
  EXPECT_TRUE(ext->extended);
  EXPECT_EQ(ext->id, 0x600u);
  EXPECT_EQ(ext->dbc_id(), 2147485184u);
  EXPECT_EQ(ext->signal("Value")->value_type, ValueType::float32);
  EXPECT_EQ(db.value_tables.size(), 1u);
  EXPECT_EQ(db.attribute_definitions.size(), 4u);
  EXPECT_EQ(db.attribute_defaults.size(), 4u);
  EXPECT_EQ(db.attributes.size(), 5u);
  EXPECT_EQ(db.other_statements, (std::vector<std::string>{"BO_TX_BU_ 256 : Master,Logger;"}));
  EXPECT_EQ(db.new_symbols.size(), 28u);
}

TEST(CanDbc, WriterRoundTrips) {
  const Database db = load_dbc(kTestDbc);
  const std::string text = write_dbc(db);
  const Database again = parse_dbc(text, "written.dbc");
  EXPECT_EQ(again, db);
  EXPECT_EQ(write_dbc(again), text);
}

TEST(CanDbc, ErrorsNameLineAndColumn) {
  std::string what;
  EXPECT_EQ(error_line("VERSION \"\"\nBU_: A\nBO_ 100 M: 8 A\n SG_ S : 0|8@2+ (1,0) [0|1] \"\" A\n", &what), 4);
  EXPECT_NE(what.find("t.dbc:4"), std::string::npos) << what;
  EXPECT_NE(what.find("column 14"), std::string::npos) << what;
  EXPECT_NE(what.find("byte order"), std::string::npos) << what;
  EXPECT_EQ(error_line("BO_ 100 M: 8 A\n SG_ S : 0|0@1+ (1,0) [0|1] \"\" A\n"), 2);
  EXPECT_EQ(error_line("BO_ 100 M: 8 A\n SG_ S : 0|8@1+ (1,0) [0|1] \"unterminated\n"), 2);
  EXPECT_EQ(error_line("BO_ 100 M: 8 A\n\nCM_ SG_ 100 Nope \"x\";\n", &what), 3);
  EXPECT_NE(what.find("no signal 'Nope'"), std::string::npos) << what;
  EXPECT_EQ(error_line("BO_ 100 M: 8 A\nVAL_ 101 S 1 \"x\" ;\n"), 2);
  EXPECT_EQ(error_line("FOO_ 1;\n", &what), 1);
  EXPECT_NE(what.find("unknown DBC keyword"), std::string::npos);
  EXPECT_EQ(error_line("BO_ 4096 M: 8 A\n"), 1);  // 11-bit id too large without bit 31
  EXPECT_EQ(error_line("BO_ 1 M: 8 A\nBO_ 1 N: 8 A\n"), 2);
  EXPECT_EQ(error_line("BO_ 1 M: 8 A\n SG_ F : 0|16@1+ (1,0) [0|1] \"\" A\nSIG_VALTYPE_ 1 F : 1;\n"), 3);
  EXPECT_EQ(error_line("BO_ 1 M: 8 A\n SG_ F : 0|16@1+ (1,0) [0|1] \"\" A\n SG_ F : 16|16@1+ (1,0) [0|1] \"\" A\n"), 3);
}

TEST(CanDbc, MutatedInputNeverCrashes) {
  // Bounded in-process fuzz: every mutation either parses or throws InputError.
  std::string base = write_dbc(load_dbc(kTestDbc));
  lash::Rng rng(7);
  int errors = 0;
  for (int i = 0; i < 3000; ++i) {
    std::string s = base;
    const int edits = 1 + static_cast<int>(rng.next() % 4);
    for (int e = 0; e < edits; ++e) {
      const std::size_t p = rng.next() % s.size();
      switch (rng.next() % 3) {
        case 0: s[p] = static_cast<char>(rng.next() % 128); break;
        case 1: s.erase(p, 1 + rng.next() % 8); break;
        default: s.insert(p, 1, "\";|@:()[]M-+0 9\n"[rng.next() % 16]);
      }
      if (s.empty()) s = "x";
    }
    try {
      const Database db = parse_dbc(s, "m.dbc");
      EXPECT_EQ(parse_dbc(write_dbc(db), "w.dbc"), db);
    } catch (const lash::InputError&) {
      ++errors;
    }
  }
  EXPECT_GT(errors, 100);
}
