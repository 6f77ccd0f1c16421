// DBC parser: a small lexer (line/column tracking) and a statement-level
// recursive-descent parser. Every error names file, line and column.
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/core.h>

#include "lash/can/dbc.hpp"
#include "lash/io/error.hpp"

namespace lash::can::dbc {

const Signal* Message::signal(std::string_view signal_name) const noexcept {
  for (const auto& s : signals)
    if (s.name == signal_name) return &s;
  return nullptr;
}

const Message* Database::message(std::string_view name) const noexcept {
  for (const auto& m : messages)
    if (m.name == name) return &m;
  return nullptr;
}

const Message* Database::message(std::uint32_t id, bool extended) const noexcept {
  for (const auto& m : messages)
    if (m.id == id && m.extended == extended) return &m;
  return nullptr;
}

namespace {

enum class Tok { end, ident, number, string, punct };

struct Token {
  Tok kind = Tok::end;
  std::string text;  ///< identifier/number text, unescaped string contents, or the punctuation char
  int line = 1;
  int col = 1;
  std::size_t begin = 0;  ///< byte offsets into the source
  std::size_t end = 0;
};

bool is_ident_start(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
bool is_ident_char(char c) { return is_ident_start(c) || (c >= '0' && c <= '9'); }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

class Lexer {
 public:
  Lexer(std::string_view src, const std::string& file) : src_(src), file_(file) {}

  [[noreturn]] void fail(int line, int col, const std::string& what, const std::string& msg) const {
    throw InputError(file_, line, what, fmt::format("column {}: {}", col, msg));
  }

  Token next() {
    skip_space();
    Token t;
    t.line = line_;
    t.col = col_;
    t.begin = pos_;
    if (pos_ >= src_.size()) {
      t.end = pos_;
      return t;
    }
    const char c = src_[pos_];
    if (c == '"') {
      t.kind = Tok::string;
      advance();
      for (;;) {
        if (pos_ >= src_.size()) fail(t.line, t.col, "string", "unterminated string");
        char d = src_[pos_];
        if (d == '"') {
          advance();
          break;
        }
        if (d == '\\' && pos_ + 1 < src_.size() && (src_[pos_ + 1] == '"' || src_[pos_ + 1] == '\\')) {
          advance();
          d = src_[pos_];
        }
        t.text.push_back(d);
        advance();
      }
    } else if (is_ident_start(c)) {
      t.kind = Tok::ident;
      while (pos_ < src_.size() && is_ident_char(src_[pos_])) {
        t.text.push_back(src_[pos_]);
        advance();
      }
    } else if (is_digit(c) || ((c == '-' || c == '+' || c == '.') && pos_ + 1 < src_.size() &&
                               (is_digit(src_[pos_ + 1]) || src_[pos_ + 1] == '.'))) {
      t.kind = Tok::number;
      t.text.push_back(c);
      advance();
      while (pos_ < src_.size()) {
        const char d = src_[pos_];
        const char prev = t.text.back();
        if (is_digit(d) || d == '.' || d == 'e' || d == 'E' ||
            ((d == '-' || d == '+') && (prev == 'e' || prev == 'E'))) {
          t.text.push_back(d);
          advance();
        } else {
          break;
        }
      }
    } else {
      t.kind = Tok::punct;
      t.text.push_back(c);
      advance();
    }
    t.end = pos_;
    return t;
  }

  std::string_view slice(std::size_t b, std::size_t e) const { return src_.substr(b, e - b); }
  /// Rest of the current line (without the newline), consumed.
  std::string rest_of_line() {
    std::string out;
    while (pos_ < src_.size() && src_[pos_] != '\n') {
      out.push_back(src_[pos_]);
      advance();
    }
    while (!out.empty() && (out.back() == '\r' || out.back() == ' ' || out.back() == '\t')) out.pop_back();
    std::size_t s = 0;
    while (s < out.size() && (out[s] == ' ' || out[s] == '\t')) ++s;
    return out.substr(s);
  }

 private:
  void advance() {
    if (src_[pos_] == '\n') {
      ++line_;
      col_ = 1;
    } else {
      ++col_;
    }
    ++pos_;
  }
  void skip_space() {
    while (pos_ < src_.size()) {
      const char c = src_[pos_];
      if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v') {
        advance();
      } else if (c == '/' && pos_ + 1 < src_.size() && src_[pos_ + 1] == '/') {
        while (pos_ < src_.size() && src_[pos_] != '\n') advance();
      } else {
        break;
      }
    }
  }

  std::string_view src_;
  const std::string& file_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int col_ = 1;
};

bool is_other_keyword(const std::string& k) {
  static const char* const kw[] = {"EV_",          "ENVVAR_DATA_", "SGTYPE_",      "SGTYPE_VAL_",   "BA_DEF_SGTYPE_",
                                   "BA_SGTYPE_",   "SIG_TYPE_REF_", "SIG_GROUP_",  "SIGTYPE_VALTYPE_", "BO_TX_BU_",
                                   "BA_DEF_REL_",  "BA_REL_",      "BA_DEF_DEF_REL_", "BU_SG_REL_", "BU_EV_REL_",
                                   "BU_BO_REL_",   "SG_MUL_VAL_",  "CAT_DEF_",     "CAT_",          "FILTER",
                                   "NS_DESC_",     "ENVVAR_DATA_"};
  for (const char* p : kw)
    if (k == p) return true;
  return false;
}

class Parser {
 public:
  Parser(std::string_view text, const std::string& file) : lex_(text, file) { tok_ = lex_.next(); }

  Database run() {
    while (tok_.kind != Tok::end) statement();
    return std::move(db_);
  }

 private:
  [[noreturn]] void fail(const Token& t, const std::string& msg) const {
    lex_.fail(t.line, t.col, what_, msg);
  }
  Token take() {
    Token t = std::move(tok_);
    tok_ = lex_.next();
    return t;
  }
  static std::string describe(const Token& t) {
    switch (t.kind) {
      case Tok::end: return "end of file";
      case Tok::string: return "a string";
      default: return "'" + t.text + "'";
    }
  }
  void expect_punct(char c) {
    if (tok_.kind != Tok::punct || tok_.text[0] != c) fail(tok_, fmt::format("expected '{}', found {}", c, describe(tok_)));
    take();
  }
  bool accept_punct(char c) {
    if (tok_.kind == Tok::punct && tok_.text[0] == c) {
      take();
      return true;
    }
    return false;
  }
  std::string ident(const char* what) {
    if (tok_.kind != Tok::ident) fail(tok_, fmt::format("expected {}, found {}", what, describe(tok_)));
    return take().text;
  }
  std::string string(const char* what) {
    if (tok_.kind != Tok::string) fail(tok_, fmt::format("expected {} (a quoted string), found {}", what, describe(tok_)));
    return take().text;
  }
  double number(const char* what) {
    if (tok_.kind != Tok::number) fail(tok_, fmt::format("expected {} (a number), found {}", what, describe(tok_)));
    const Token t = take();
    std::string_view s = t.text;
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    double v = 0;
    auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v))
      fail(t, fmt::format("{} is not a valid number: '{}'", what, t.text));
    return v;
  }
  template <class Int>
  Int integer(const char* what) {
    if (tok_.kind != Tok::number) fail(tok_, fmt::format("expected {} (an integer), found {}", what, describe(tok_)));
    const Token t = take();
    std::string_view s = t.text;
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    Int v{};
    auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size())
      fail(t, fmt::format("{} is not a valid integer in range: '{}'", what, t.text));
    return v;
  }
  void expect_end() { expect_punct(';'); }

  Message& message_by_id(const Token& at, std::uint32_t dbc_id) {
    for (auto& m : db_.messages)
      if (m.dbc_id() == dbc_id) return m;
    fail(at, fmt::format("no message with id {} (BO_ must come first)", dbc_id));
  }
  Signal& signal_of(const Token& at, Message& m, const std::string& name) {
    for (auto& s : m.signals)
      if (s.name == name) return s;
    fail(at, fmt::format("message '{}' has no signal '{}'", m.name, name));
  }

  void statement() {
    const Token kw = tok_;
    if (kw.kind != Tok::ident) {
      what_ = "DBC";
      fail(kw, "expected a DBC keyword, found " + describe(kw));
    }
    what_ = kw.text;
    const std::string& k = kw.text;
    if (k == "VERSION") {
      take();
      db_.version = string("the version");
    } else if (k == "NS_") {
      take();
      expect_punct(':');
      // The NS_ list is indented; it ends at the first token in column 1.
      while (tok_.kind == Tok::ident && tok_.col > 1) db_.new_symbols.push_back(take().text);
    } else if (k == "BS_") {
      take();
      if (tok_.kind != Tok::punct || tok_.text[0] != ':') fail(tok_, "expected ':' after BS_");
      // Do not lex further: the rest of the line is free text.
      db_.bit_timing = lex_.rest_of_line();
      tok_ = lex_.next();
    } else if (k == "BU_") {
      take();
      expect_punct(':');
      const int line = kw.line;
      while (tok_.kind == Tok::ident && tok_.line == line) db_.nodes.push_back(take().text);
    } else if (k == "VAL_TABLE_") {
      take();
      ValueTable vt;
      vt.name = ident("a value table name");
      vt.values = value_list();
      expect_end();
      db_.value_tables.push_back(std::move(vt));
    } else if (k == "BO_") {
      message();
    } else if (k == "SG_") {
      if (db_.messages.empty()) fail(kw, "SG_ outside a BO_ message");
      signal(db_.messages.back());
    } else if (k == "CM_") {
      comment();
    } else if (k == "BA_DEF_") {
      take();
      AttributeDefinition d;
      if (tok_.kind == Tok::ident) {
        const Token o = take();
        if (o.text != "BU_" && o.text != "BO_" && o.text != "SG_" && o.text != "EV_")
          fail(o, "expected BU_, BO_, SG_, EV_ or the attribute name, found '" + o.text + "'");
        d.object = o.text;
      }
      d.name = string("the attribute name");
      if (tok_.kind != Tok::ident) fail(tok_, "expected the attribute type (INT, HEX, FLOAT, STRING, ENUM)");
      const std::string type = tok_.text;
      if (type != "INT" && type != "HEX" && type != "FLOAT" && type != "STRING" && type != "ENUM")
        fail(tok_, "unknown attribute type '" + type + "'");
      std::size_t prev_end = tok_.begin;
      while (tok_.kind != Tok::end && !(tok_.kind == Tok::punct && tok_.text[0] == ';')) {
        append_token(d.type, tok_, prev_end);
        take();
      }
      expect_end();
      db_.attribute_definitions.push_back(std::move(d));
    } else if (k == "BA_DEF_DEF_") {
      take();
      AttributeDefault d;
      d.name = string("the attribute name");
      d.value = attribute_value();
      expect_end();
      db_.attribute_defaults.push_back(std::move(d));
    } else if (k == "BA_") {
      attribute();
    } else if (k == "VAL_") {
      take();
      if (tok_.kind == Tok::ident) {  // environment variable: keep verbatim
        other_from(kw);
        return;
      }
      const Token at = tok_;
      const auto id = integer<std::uint32_t>("the message id");
      Message& m = message_by_id(at, id);
      const Token st = tok_;
      Signal& s = signal_of(st, m, ident("the signal name"));
      s.values = value_list();
      expect_end();
    } else if (k == "SIG_VALTYPE_") {
      take();
      const Token at = tok_;
      const auto id = integer<std::uint32_t>("the message id");
      Message& m = message_by_id(at, id);
      const Token st = tok_;
      Signal& s = signal_of(st, m, ident("the signal name"));
      accept_punct(':');
      const Token vt = tok_;
      const auto v = integer<int>("the value type");
      if (v == 0) {
        s.value_type = ValueType::integer;
      } else if (v == 1) {
        if (s.length != 32) fail(vt, "SIG_VALTYPE_ 1 (float) needs a 32-bit signal");
        s.value_type = ValueType::float32;
      } else if (v == 2) {
        if (s.length != 64) fail(vt, "SIG_VALTYPE_ 2 (double) needs a 64-bit signal");
        s.value_type = ValueType::float64;
      } else {
        fail(vt, "value type must be 0 (integer), 1 (float) or 2 (double)");
      }
      expect_end();
    } else if (is_other_keyword(k)) {
      take();
      other_from(kw);
    } else {
      fail(kw, "unknown DBC keyword '" + k + "'");
    }
  }

  /// Appends a token's source text; one blank where the source had blanks or comments.
  void append_token(std::string& out, const Token& t, std::size_t& prev_end) const {
    if (!out.empty() && t.begin > prev_end) out.push_back(' ');
    out += lex_.slice(t.begin, t.end);
    prev_end = t.end;
  }

  /// Skips to the statement's ';' (lexing, so strings may hold ';') and keeps the text.
  void other_from(const Token& kw) {
    std::string text(lex_.slice(kw.begin, kw.end));
    std::size_t prev_end = kw.end;
    while (tok_.kind != Tok::end && !(tok_.kind == Tok::punct && tok_.text[0] == ';')) {
      append_token(text, tok_, prev_end);
      take();
    }
    if (tok_.kind == Tok::end) fail(tok_, "missing ';' to end " + kw.text);
    append_token(text, tok_, prev_end);
    take();
    db_.other_statements.push_back(std::move(text));
  }

  std::vector<ValueDescription> value_list() {
    std::vector<ValueDescription> out;
    while (tok_.kind == Tok::number) {
      ValueDescription v;
      const Token at = tok_;
      const double d = number("the value");
      if (d != std::floor(d) || d < -9.2e18 || d > 9.2e18) fail(at, "value descriptions need integer values");
      v.value = static_cast<std::int64_t>(d);
      v.text = string("the value description");
      out.push_back(std::move(v));
    }
    return out;
  }

  void message() {
    take();
    Message m;
    const Token at = tok_;
    const auto dbc_id = integer<std::uint32_t>("the message id");
    m.extended = (dbc_id & 0x80000000u) != 0;
    m.id = dbc_id & 0x7FFFFFFFu;
    if (!m.extended && m.id > 0x7FF) fail(at, fmt::format("standard id {} exceeds 0x7FF (extended ids set bit 31)", m.id));
    m.name = ident("the message name");
    expect_punct(':');
    const Token st = tok_;
    m.size = integer<std::uint32_t>("the message size");
    if (m.size > 64) fail(st, "message size must be 0..64 bytes");
    m.transmitter = ident("the transmitter");
    for (const auto& o : db_.messages)
      if (o.dbc_id() == m.dbc_id()) fail(at, fmt::format("duplicate message id {} ('{}' and '{}')", dbc_id, o.name, m.name));
    db_.messages.push_back(std::move(m));
  }

  void signal(Message& m) {
    take();
    Signal s;
    const Token nt = tok_;
    s.name = ident("the signal name");
    if (m.signal(s.name)) fail(nt, "duplicate signal '" + s.name + "' in message '" + m.name + "'");
    if (tok_.kind == Tok::ident) {
      const Token mt = take();
      const std::string& x = mt.text;
      if (x == "M") {
        s.mux = MuxRole::multiplexor;
      } else if (x.size() >= 2 && x[0] == 'm') {
        std::string_view digits(x);
        digits.remove_prefix(1);
        bool also_mux = false;
        if (!digits.empty() && digits.back() == 'M') {  // extended multiplexing "m1M": multiplexed, switch too
          also_mux = true;
          digits.remove_suffix(1);
        }
        auto r = std::from_chars(digits.data(), digits.data() + digits.size(), s.mux_value);
        if (digits.empty() || r.ec != std::errc() || r.ptr != digits.data() + digits.size())
          fail(mt, "expected a multiplexer indicator M or m<n>, found '" + x + "'");
        if (also_mux) fail(mt, "extended multiplexing ('" + x + "') is not supported");
        s.mux = MuxRole::multiplexed;
      } else {
        fail(mt, "expected a multiplexer indicator M or m<n>, found '" + x + "'");
      }
    }
    expect_punct(':');
    const Token sb = tok_;
    s.start_bit = integer<std::uint32_t>("the start bit");
    expect_punct('|');
    const Token lt = tok_;
    s.length = integer<std::uint32_t>("the bit length");
    if (s.length < 1 || s.length > 64) fail(lt, "bit length must be 1..64");
    expect_punct('@');
    const Token bo = tok_;
    if (bo.kind == Tok::number && bo.text == "1") {
      s.byte_order = ByteOrder::intel;
    } else if (bo.kind == Tok::number && bo.text == "0") {
      s.byte_order = ByteOrder::motorola;
    } else {
      fail(bo, "byte order must be 0 (Motorola) or 1 (Intel)");
    }
    take();
    if (tok_.kind == Tok::punct && (tok_.text[0] == '+' || tok_.text[0] == '-')) {
      s.is_signed = take().text[0] == '-';
    } else {
      fail(tok_, "expected '+' (unsigned) or '-' (signed)");
    }
    if (s.start_bit > 511) fail(sb, "start bit must be 0..511");
    if (s.byte_order == ByteOrder::intel) {
      if (s.start_bit + s.length > 512) fail(sb, "signal runs past byte 64");
    } else {
      const std::uint32_t msb_be = (s.start_bit / 8) * 8 + (7 - s.start_bit % 8);
      if (msb_be + s.length > 512) fail(sb, "signal runs past byte 64");
    }
    expect_punct('(');
    s.factor = number("the factor");
    expect_punct(',');
    s.offset = number("the offset");
    expect_punct(')');
    expect_punct('[');
    s.minimum = number("the minimum");
    expect_punct('|');
    s.maximum = number("the maximum");
    expect_punct(']');
    s.unit = string("the unit");
    const int line = tok_.line;
    while (tok_.kind == Tok::ident && tok_.line == line) {
      std::string r = take().text;
      if (r != "Vector__XXX") s.receivers.push_back(std::move(r));  // the DBC's 'no receiver'
      if (tok_.kind == Tok::punct && tok_.text[0] == ',' && tok_.line == line) take();
    }
    if (s.mux == MuxRole::multiplexor)
      for (const auto& o : m.signals)
        if (o.mux == MuxRole::multiplexor) fail(nt, "message '" + m.name + "' has two multiplexors");
    m.signals.push_back(std::move(s));
  }

  void comment() {
    const Token kw = take();
    if (tok_.kind == Tok::string) {
      db_.comment = take().text;
      expect_end();
      return;
    }
    const Token o = tok_;
    const std::string obj = ident("BU_, BO_, SG_, EV_ or a string");
    if (obj == "BU_") {
      NodeComment c;
      c.node = ident("the node name");
      c.text = string("the comment");
      expect_end();
      db_.node_comments.push_back(std::move(c));
    } else if (obj == "BO_") {
      const Token at = tok_;
      Message& m = message_by_id(at, integer<std::uint32_t>("the message id"));
      m.comment = string("the comment");
      expect_end();
    } else if (obj == "SG_") {
      const Token at = tok_;
      Message& m = message_by_id(at, integer<std::uint32_t>("the message id"));
      const Token st = tok_;
      Signal& s = signal_of(st, m, ident("the signal name"));
      s.comment = string("the comment");
      expect_end();
    } else if (obj == "EV_") {
      other_from(kw);
    } else {
      fail(o, "expected BU_, BO_, SG_, EV_ or a string after CM_");
    }
  }

  AttributeValue attribute_value() {
    AttributeValue v;
    if (tok_.kind == Tok::string) {
      v.text = take().text;
      v.quoted = true;
    } else if (tok_.kind == Tok::number) {
      const Token t = tok_;
      number("the attribute value");
      v.text = t.text;
    } else {
      fail(tok_, "expected an attribute value (number or string), found " + describe(tok_));
    }
    return v;
  }

  void attribute() {
    take();
    Attribute a;
    a.name = string("the attribute name");
    if (tok_.kind == Tok::ident) {
      const Token o = take();
      a.object = o.text;
      if (a.object == "BU_" || a.object == "EV_") {
        a.node = ident("the node name");
      } else if (a.object == "BO_") {
        const Token at = tok_;
        a.message_dbc_id = integer<std::uint32_t>("the message id");
        message_by_id(at, a.message_dbc_id);
      } else if (a.object == "SG_") {
        const Token at = tok_;
        a.message_dbc_id = integer<std::uint32_t>("the message id");
        Message& m = message_by_id(at, a.message_dbc_id);
        const Token st = tok_;
        a.signal = ident("the signal name");
        signal_of(st, m, a.signal);
      } else {
        fail(o, "expected BU_, BO_, SG_, EV_ or a value, found '" + o.text + "'");
      }
    }
    a.value = attribute_value();
    expect_end();
    db_.attributes.push_back(std::move(a));
  }

  Lexer lex_;
  Token tok_;
  Database db_;
  std::string what_ = "DBC";
};

}  // namespace

Database parse_dbc(std::string_view text, const std::string& file) {
  Parser p(text, file);
  return p.run();
}

Database load_dbc(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), 0, "", "cannot open DBC file for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_dbc(ss.str(), path.string());
}

}  // namespace lash::can::dbc
