// DBC parser/writer: fields of the test database, round trip, errors with line and column.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "lash/can/codec.hpp"
#include "lash/can/dbc.hpp"
#include "lash/io/error.hpp"
#include "lash/signals/rng.hpp"

using namespace lash::can::dbc;

namespace {
const std::string kTestDbc = std::string(LASH_SOURCE_DIR) + "/tests/data/can/lash_test.dbc";

/// Line number of the InputError thrown by parsing `text` (0 if none thrown).
int error_line(const std::string& text, std::string* what = nullptr) {
  try {
    parse_dbc(text, "t.dbc", ParseOptions{true});
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
  EXPECT_NE(what.find("signal 'Nope'"), std::string::npos) << what;
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
  int errors = 0, tolerant_loads = 0;
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
      const Database db = parse_dbc(s, "m.dbc", ParseOptions{true});
      EXPECT_EQ(parse_dbc(write_dbc(db), "w.dbc", ParseOptions{true}), db);
    } catch (const lash::InputError&) {
      ++errors;
    }
    // Tolerant: the same text loads (what is dubious becomes a diagnostic) and what it
    // loads writes back to the same messages.
    try {
      std::vector<Diagnostic> diags;
      const Database db = parse_dbc(s, "m.dbc", {}, &diags);
      std::vector<Diagnostic> again_diags;
      const Database again = parse_dbc(write_dbc(db), "w.dbc", {}, &again_diags);
      EXPECT_EQ(again.messages, db.messages) << s;
      ++tolerant_loads;
    } catch (const lash::InputError&) {
    }
  }
  EXPECT_GT(errors, 100);
  EXPECT_GT(tolerant_loads, 2900);  // only what cannot be read at all (e.g. an unterminated string) is refused
}

namespace {
bool has_kind(const std::vector<Diagnostic>& d, const std::string& kind) {
  for (const auto& x : d)
    if (x.kind == kind) return true;
  return false;
}
}  // namespace

TEST(CanDbc, TolerantReadingWarnsInsteadOfRefusing) {
  // One statement for each cause of refusal seen in real files (issue 14).
  const std::string text =
      "VERSION \"\"\n"
      "BU_: A B\n"
      "  C\n"                                                      // node list over two lines
      "VAL_ 100 S 0 \"zero\" 1 \"one\" ;\n"                         // VAL_ before its BO_
      "BO_ 100 M: 8 A\n"
      " SG_ S : 0|8@1+ (1,0) [0|255] \"\" B\n"
      " SG_ T m : 8|8@1+ (1,0) [0|255] \"\" B\n"                   // a bare 'm'
      "BO_ 2048 Big: 8 A\n"                                        // > 0x7FF without bit 31
      " SG_ X : 0|8@1+ (1,0) [0|0] \"\" B\n"
      "BO_ 1275 2017_5: 8 A\n"                                     // a name starting with a digit
      " SG_ 3DValue : 0|8@1+ (1,0) [0|0] \"\" B\n"
      "BO_ 3221225472 VECTOR__INDEPENDENT_SIG_MSG: 0 Vector__XXX\n"  // id 0x40000000
      " SG_ Free : 0|8@1+ (1,0) [0|0] \"\" B\n"
      "CM_ SG_ 100 \"no signal name\";\n"
      "CM_ SG_ 100 Nope \"unknown signal\";\n"
      "CM_ 145 \"no object kind\";\n"
      "VAL_ 100 Nope 1 \"x\" ;\n"
      "CM_ BO_ 100 \"no semicolon\"\n"
      "BA_DEF_ \"X\" INT 0 1;\n";
  std::vector<Diagnostic> d;
  const Database db = parse_dbc(text, "t.dbc", {}, &d);
  for (const char* kind : {"nodes-over-several-lines", "bare-m", "implicit-extended-id", "independent-signals",
                           "comment-without-signal", "unknown-signal", "comment-without-object", "missing-semicolon"})
    EXPECT_TRUE(has_kind(d, kind)) << kind;
  EXPECT_EQ(db.nodes, (std::vector<std::string>{"A", "B", "C"}));
  ASSERT_EQ(db.messages.size(), 3u);
  EXPECT_EQ(db.messages[0].signal("S")->values.size(), 2u);
  EXPECT_EQ(db.messages[0].signal("T")->mux, MuxRole::none);
  EXPECT_EQ(db.messages[0].comment, "no semicolon");
  EXPECT_TRUE(db.messages[1].extended);
  EXPECT_EQ(db.messages[1].id, 2048u);
  EXPECT_EQ(db.messages[2].name, "2017_5");
  EXPECT_NE(db.messages[2].signal("3DValue"), nullptr);
  EXPECT_EQ(db.attribute_definitions.size(), 1u);  // parsing went on after the missing ';'
  for (const auto& x : d) EXPECT_EQ(x.severity, Diagnostic::Severity::warning) << x.format();
  // what is kept aside is written back verbatim
  EXPECT_NE(write_dbc(db).find("CM_ SG_ 100 \"no signal name\";"), std::string::npos);
  // strict mode: the first of them is an error naming file and line
  EXPECT_EQ(error_line(text), 3);
}

TEST(CanDbc, LayoutErrorsAreFoundAtLoadPerMessage) {
  const std::string text =
      "BO_ 1 Bad: 1 A\n SG_ S : 8|1@1+ (1,0) [0|1] \"\" A\n"
      "BO_ 2 Good: 8 A\n SG_ G : 0|8@1+ (1,0) [0|1] \"\" A\n SG_ H : 4|8@1+ (1,0) [0|1] \"\" A\n";
  std::vector<Diagnostic> d;
  const Database db = parse_dbc(text, "t.dbc", {}, &d);
  ASSERT_EQ(db.messages.size(), 2u);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].severity, Diagnostic::Severity::error);
  EXPECT_EQ(d[0].kind, "signal-out-of-frame");
  EXPECT_THROW(lash::can::MessageCodec{db.messages[0]}, std::invalid_argument);
  EXPECT_NO_THROW(lash::can::MessageCodec{db.messages[1]});
  // dbc check's overlap test: G (bits 0-7) and H (bits 4-11) share 4 bits
  const auto checked = check_layout(db.messages[1], "t.dbc", true);
  ASSERT_EQ(checked.size(), 1u);
  EXPECT_EQ(checked[0].kind, "overlap");
  EXPECT_NE(checked[0].message.find("share 4 bit"), std::string::npos) << checked[0].message;
}

TEST(CanDbc, ExtendedMultiplexingDecodesAndEncodes) {
  // A selects B (m1M) for A in 1..2; B selects C for B = 3 and D for B in 4..5 (SG_MUL_VAL_).
  const std::string text =
      "BO_ 2147483649 Ext: 8 A\n"
      " SG_ A M : 0|8@1+ (1,0) [0|0] \"\" A\n"
      " SG_ B m1M : 8|8@1+ (1,0) [0|0] \"\" A\n"
      " SG_ C m3 : 16|8@1+ (1,0) [0|0] \"\" A\n"
      " SG_ D m4 : 16|8@1+ (2,0) [0|0] \"\" A\n"
      "SG_MUL_VAL_ 2147483649 B A 1-2;\n"
      "SG_MUL_VAL_ 2147483649 C B 3-3;\n"
      "SG_MUL_VAL_ 2147483649 D B 4-5;\n";
  std::vector<Diagnostic> d;
  const Database db = parse_dbc(text, "t.dbc", {}, &d);
  EXPECT_TRUE(d.empty()) << (d.empty() ? "" : d[0].format());
  lash::can::MessageCodec codec(db.messages[0]);
  std::vector<double> v(4);
  const std::uint8_t f1[8] = {2, 5, 7, 0, 0, 0, 0, 0};  // A=2 selects B; B=5 selects D = 7 × 2
  ASSERT_TRUE(codec.decode(f1, v));
  EXPECT_EQ(v[0], 2);
  EXPECT_EQ(v[1], 5);
  EXPECT_TRUE(std::isnan(v[2]));
  EXPECT_EQ(v[3], 14);
  const std::uint8_t f2[8] = {3, 3, 7, 0, 0, 0, 0, 0};  // A=3 selects nothing below it
  ASSERT_TRUE(codec.decode(f2, v));
  EXPECT_TRUE(std::isnan(v[1]) && std::isnan(v[2]) && std::isnan(v[3]));
  const std::uint8_t f3[8] = {1, 3, 9, 0, 0, 0, 0, 0};  // A=1, B=3 selects C
  ASSERT_TRUE(codec.decode(f3, v));
  EXPECT_EQ(v[2], 9);
  EXPECT_TRUE(std::isnan(v[3]));
  std::uint8_t out[8] = {};
  const double in[4] = {1, 4, 1, 6};  // C is not selected by B=4: not written
  ASSERT_TRUE(codec.encode(in, out).ok);
  EXPECT_EQ(out[0], 1);
  EXPECT_EQ(out[1], 4);
  EXPECT_EQ(out[2], 3);  // D = 6 / 2
  // written back and read again: the same database
  EXPECT_EQ(parse_dbc(write_dbc(db), "w.dbc"), db);
}

// CANdb++ writes names over 32 characters short and keeps the long one in an attribute; the
// long one is the name everywhere (the DBC text below is the layout of cantools' issue_784.dbc).
TEST(CanDbc, NodeAndEnvVarLongNamesReplaceTheShortOnes) {
  const std::string text = R"(VERSION ""
BS_:
BU_: ECU2_123456789012345678901234567 ECU1
BO_ 256 M: 8 ECU2_123456789012345678901234567
 SG_ S : 0|8@1+ (1,0) [0|255] "" ECU1,ECU2_123456789012345678901234567
EV_ EnvVar_12345678901234567890123456: 0 [0|1] "" 0 1 DUMMY_NODE_VECTOR0 Vector__XXX;
CM_ BU_ ECU2_123456789012345678901234567 "Second ECU";
BA_DEF_ BU_  "SystemNodeLongSymbol" STRING ;
BA_DEF_ EV_  "SystemEnvVarLongSymbol" STRING ;
BA_DEF_ BU_  "NodeLayerModules" STRING ;
BA_ "SystemNodeLongSymbol" BU_ ECU2_123456789012345678901234567 "ECU2_12345678901234567890123456789012";
BA_ "NodeLayerModules" BU_ ECU2_123456789012345678901234567 "CANoeILNLVector.dll";
BA_ "SystemEnvVarLongSymbol" EV_ EnvVar_12345678901234567890123456 "EnvVar_1234567890123456789012345678901234";
)";
  const Database db = parse_dbc(text);
  const std::string longer = "ECU2_12345678901234567890123456789012";
  ASSERT_EQ(db.nodes.size(), 2u);
  EXPECT_EQ(db.nodes[0], longer);
  ASSERT_EQ(db.messages.size(), 1u);
  EXPECT_EQ(db.messages[0].transmitter, longer);
  EXPECT_EQ(db.messages[0].signals[0].receivers, (std::vector<std::string>{"ECU1", longer}));
  ASSERT_EQ(db.node_comments.size(), 1u);
  EXPECT_EQ(db.node_comments[0].node, longer);
  int module_attrs = 0;
  for (const auto& a : db.attributes)
    if (a.name == "NodeLayerModules") {
      EXPECT_EQ(a.node, longer);
      ++module_attrs;
    }
  EXPECT_EQ(module_attrs, 1);
  bool env = false;
  for (const auto& s : db.other_statements)
    env = env || s.rfind("EV_ EnvVar_1234567890123456789012345678901234:", 0) == 0;
  EXPECT_TRUE(env);
  // written and read back: the same database (the long names are a fixed point)
  EXPECT_EQ(parse_dbc(write_dbc(db)), db);
}

// Tolerant reading keeps what it can, but a file in which not one statement could be read is
// no DBC (exit 2), while a file of valid but empty statements is one. The second text is the
// fuzzer's: its verbatim statement's open quote swallows the next statement when written back,
// and the written text must still load.
TEST(CanDbc, NothingReadIsNoDbcButEmptyStatementsAre) {
  std::vector<Diagnostic> diags;
  EXPECT_THROW(parse_dbc(std::string("\x01\x02 garbage\n\xff\xfe;\n", 14), "g.dbc", {}, &diags), lash::InputError);
  EXPECT_NO_THROW(parse_dbc("VERSION \"\"\nBU_:\n"));
  const Database db = parse_dbc("CM_\"s\";CM_\nSG_ 6 S\"\n", "f.dbc", {}, &diags);
  EXPECT_EQ(db.comment, "s");
  EXPECT_NO_THROW(parse_dbc(write_dbc(db), "written.dbc", {}, &diags));
}
