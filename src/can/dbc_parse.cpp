// DBC parser: a small lexer (line/column tracking) and a statement-level
// recursive-descent parser. Every error names file, line and column.
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <set>
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
      std::size_t nl_pos = 0, nl_text = 0;
      int nl_line = 0, nl_col = 0;
      for (;;) {
        if (pos_ >= src_.size()) {
          if (!tolerant_ || nl_line == 0) fail(t.line, t.col, "string", "unterminated string");
          // Recover: the string ends at the end of its first line.
          pos_ = nl_pos;
          line_ = nl_line;
          col_ = nl_col;
          t.text.resize(nl_text);
          unterminated_line_ = t.line;
          break;
        }
        char d = src_[pos_];
        if (d == '\n' && nl_line == 0) {
          nl_pos = pos_;
          nl_line = line_;
          nl_col = col_;
          nl_text = t.text.size();
        }
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
    } else if (is_digit(c) && digit_led_name()) {
      t.kind = Tok::ident;  // e.g. "2017_5": a name starting with a digit (kept as an identifier)
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

  /// At a digit: does an identifier character other than a number's follow the digits
  /// ("2017_5", "3DTest"), i.e. is this a name rather than a number?
  bool digit_led_name() const {
    std::size_t i = pos_;
    while (i < src_.size() && is_digit(src_[i])) ++i;
    if (i >= src_.size() || !is_ident_char(src_[i])) return false;
    if (src_[i] == 'e' || src_[i] == 'E') {  // 1e5, 1E-3 are numbers
      std::size_t j = i + 1;
      if (j < src_.size() && (src_[j] == '-' || src_[j] == '+')) ++j;
      if (j < src_.size() && is_digit(src_[j])) {
        while (j < src_.size() && is_digit(src_[j])) ++j;
        return j < src_.size() && is_ident_char(src_[j]);
      }
    }
    return true;
  }
  std::size_t pos() const { return pos_; }
  void set_tolerant(bool t) { tolerant_ = t; }
  /// Line of a string the lexer had to end at its line's end (tolerant mode), then 0.
  int take_unterminated() {
    const int l = unterminated_line_;
    unterminated_line_ = 0;
    return l;
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
  bool tolerant_ = false;
  int unterminated_line_ = 0;
  std::size_t pos_ = 0;
  int line_ = 1;
  int col_ = 1;
};

bool is_other_keyword(const std::string& k) {
  static const char* const kw[] = {"EV_",          "ENVVAR_DATA_", "SGTYPE_",      "SGTYPE_VAL_",   "BA_DEF_SGTYPE_",
                                   "BA_SGTYPE_",   "SIG_TYPE_REF_", "SIG_GROUP_",  "SIGTYPE_VALTYPE_", "BO_TX_BU_",
                                   "BA_DEF_REL_",  "BA_REL_",      "BA_DEF_DEF_REL_", "BU_SG_REL_", "BU_EV_REL_",
                                   "BU_BO_REL_",   "CAT_DEF_",     "CAT_",          "FILTER",
                                   "NS_DESC_",     "EV_DATA_"};
  for (const char* p : kw)
    if (k == p) return true;
  return false;
}

bool is_keyword(const std::string& k) {
  static const char* const kw[] = {"VERSION", "NS_", "BS_", "BU_", "BO_", "SG_", "CM_", "BA_DEF_", "BA_DEF_DEF_",
                                   "BA_", "VAL_", "VAL_TABLE_", "SIG_VALTYPE_", "SG_MUL_VAL_"};
  for (const char* p : kw)
    if (k == p) return true;
  return is_other_keyword(k);
}

/// A statement naming a message (and maybe a signal) that is resolved once the whole
/// file is read, so that it may come before its BO_.
struct Pending {
  int line = 0;
  const char* kind = "";
  std::string verbatim;  ///< the statement as written, kept when it names nothing known
  std::uint32_t id = 0;
  std::string signal;    ///< empty: the statement names a message only
  std::function<void(Message&, Signal*)> apply;
};

class Parser {
 public:
  Parser(std::string_view text, const std::string& file, const ParseOptions& opt, std::vector<Diagnostic>* diags)
      : lex_(text, file), file_(file), strict_(opt.strict), diags_(diags) {
    lex_.set_tolerant(!strict_);
    tok_ = lex_.next();
    check_unterminated();
  }

  /// Keyword statements read without error (VERSION, BU_, BO_, ...): 0 means no DBC at all.
  std::size_t statements_read() const noexcept { return statements_read_; }

  Database run() {
    while (tok_.kind != Tok::end) guarded_statement();
    resolve();
    for (const auto& m : db_.messages)
      for (auto& d : check_layout(m, file_, false)) add(std::move(d));
    return std::move(db_);
  }

 private:
  void add(Diagnostic d) {
    if (diags_) diags_->push_back(std::move(d));
  }
  /// A dubious construct: a diagnostic (tolerant) or an InputError (strict).
  void warn(int line, const char* kind, const std::string& msg) {
    if (strict_) throw InputError(file_, line, what_, msg);
    add({Diagnostic::Severity::warning, file_, line, kind, msg});
  }
  [[noreturn]] void fail(const Token& t, const std::string& msg) const { lex_.fail(t.line, t.col, what_, msg); }
  Token take() {
    Token t = std::move(tok_);
    prev_line_ = t.line;
    prev_end_ = t.end;
    tok_ = lex_.next();
    check_unterminated();
    return t;
  }
  void check_unterminated() {
    if (const int l = lex_.take_unterminated())
      add({Diagnostic::Severity::warning, file_, l, "unterminated-string", "string without a closing '\"': ended at the end of its line"});
  }
  /// The current token starts a new statement: a keyword first on its line.
  bool at_statement_start() const {
    return tok_.kind == Tok::ident && tok_.line > prev_line_ && is_keyword(tok_.text) &&
           (tok_.col == 1 || tok_.text == "SG_" || tok_.text == "BO_");
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
  /// ';' — or, tolerated with a warning, the start of the next statement / end of file.
  void expect_end() {
    if (accept_punct(';')) return;
    if (tok_.kind == Tok::end || at_statement_start()) {
      warn(prev_line_, "missing-semicolon", what_ + " statement without ';' (ended at the next statement)");
      return;
    }
    fail(tok_, fmt::format("expected ';', found {}", describe(tok_)));
  }

  void guarded_statement() {
    const Token kw = tok_;
    try {
      statement();
      if (kw.kind == Tok::ident && is_keyword(kw.text)) ++statements_read_;
    } catch (const InputError&) {
      if (strict_) throw;
      // Report the statement's first problem and skip to the next statement.
      try {
        throw;
      } catch (const InputError& e) {
        add({Diagnostic::Severity::warning, file_, e.line(), "skipped-statement",
             fmt::format("{} statement skipped: {}", kw.text, e.message())});
      }
      if (tok_.begin == kw.begin && tok_.kind != Tok::end) take();
      while (tok_.kind != Tok::end && !at_statement_start()) {
        const bool semi = tok_.kind == Tok::punct && tok_.text[0] == ';';
        take();
        if (semi) break;
      }
    }
  }

  /// The verbatim text from `kw` to the last token taken.
  std::string verbatim_from(const Token& kw) const {
    std::string out;
    std::string_view all = lex_.slice(kw.begin, prev_end_);
    // collapse line breaks and runs of blanks to one blank (comments and strings keep theirs)
    bool in_string = false, blank = false;
    for (std::size_t i = 0; i < all.size(); ++i) {
      const char c = all[i];
      if (!in_string && c == '/' && i + 1 < all.size() && all[i + 1] == '/') {  // a // comment: dropped
        while (i < all.size() && all[i] != '\n') ++i;
        blank = true;
        continue;
      }
      if (c == '"' && (i == 0 || all[i - 1] != '\\')) in_string = !in_string;
      if (!in_string && (c == ' ' || c == '\t' || c == '\r' || c == '\n')) {
        blank = true;
        continue;
      }
      if (blank && !out.empty()) out.push_back(' ');
      blank = false;
      out.push_back(c);
    }
    return out;
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
      bool several_lines = false;
      while ((tok_.kind == Tok::ident && !at_statement_start()) || (tok_.kind == Tok::punct && tok_.text[0] == ',')) {
        if (tok_.kind == Tok::punct) {
          take();
          continue;
        }
        if (tok_.line != line) {
          if (!several_lines) warn(tok_.line, "nodes-over-several-lines", "BU_ node list continues on the next line (read as one list)");
          several_lines = true;
        }
        db_.nodes.push_back(take().text);
      }
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
      if (db_.messages.empty() && !skipping_signals_) fail(kw, "SG_ outside a BO_ message");
      signal();
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
      while (tok_.kind != Tok::end && !(tok_.kind == Tok::punct && tok_.text[0] == ';') && !at_statement_start()) {
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
      const auto id = integer<std::uint32_t>("the message id");
      const std::string name = ident("the signal name");
      auto values = value_list();
      expect_end();
      defer(kw, "VAL_", id, name, [v = std::move(values)](Message&, Signal* s) mutable { s->values = std::move(v); });
    } else if (k == "SIG_VALTYPE_") {
      take();
      const auto id = integer<std::uint32_t>("the message id");
      const std::string name = ident("the signal name");
      accept_punct(':');
      const Token vt = tok_;
      const auto v = integer<int>("the value type");
      if (v < 0 || v > 2) fail(vt, "value type must be 0 (integer), 1 (float) or 2 (double)");
      expect_end();
      const int line = vt.line;
      defer(kw, "SIG_VALTYPE_", id, name, [this, v, line](Message&, Signal* s) {
        const std::uint32_t need = v == 1 ? 32 : 64;
        if (v != 0 && s->length != need) {
          warn(line, "valtype-length", fmt::format("SIG_VALTYPE_ {} needs a {}-bit signal, '{}' has {} bits: ignored", v,
                                                   need, s->name, s->length));
          return;
        }
        s->value_type = static_cast<ValueType>(v);
      });
    } else if (k == "SG_MUL_VAL_") {
      mux_values(kw);
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
    while (tok_.kind != Tok::end && !(tok_.kind == Tok::punct && tok_.text[0] == ';') && !at_statement_start()) take();
    bool semicolon = true;
    if (tok_.kind == Tok::punct) {
      take();
    } else {
      if (strict_ && tok_.kind == Tok::end) fail(tok_, "missing ';' to end " + kw.text);
      warn(prev_line_, "missing-semicolon", kw.text + " statement without ';' (ended at the next statement)");
      semicolon = false;
    }
    std::string text = verbatim_from(kw);
    if (!semicolon) text += ";";
    db_.other_statements.push_back(std::move(text));
  }

  std::vector<ValueDescription> value_list() {
    std::vector<ValueDescription> out;
    while (tok_.kind == Tok::number) {
      ValueDescription v;
      const Token at = tok_;
      const double d = number("the value");
      if (d != std::floor(d) || d < -9.2e18 || d > 1.8446744073709552e19) fail(at, "value descriptions need integer values");
      if (d > 9.2e18) {  // an unsigned 64-bit value: keep its bits
        std::uint64_t u = 0;
        std::from_chars(at.text.data(), at.text.data() + at.text.size(), u);
        v.value = static_cast<std::int64_t>(u);
      } else {
        std::int64_t i = 0;
        const char* b = at.text.data() + (at.text[0] == '+' ? 1 : 0);
        auto r = std::from_chars(b, at.text.data() + at.text.size(), i);
        v.value = r.ec == std::errc() && r.ptr == at.text.data() + at.text.size() ? i : static_cast<std::int64_t>(d);
      }
      v.text = string("the value description");
      out.push_back(std::move(v));
    }
    return out;
  }

  Message* find_message(std::uint32_t written_id) {
    for (auto& m : db_.messages)
      if (m.dbc_id() == written_id || (m.extended && m.id == written_id)) return &m;
    return nullptr;
  }

  void defer(const Token& kw, const char* kind, std::uint32_t id, std::string signal,
             std::function<void(Message&, Signal*)> apply) {
    Pending p;
    p.line = kw.line;
    p.kind = kind;
    p.verbatim = verbatim_from(kw);
    p.id = id;
    p.signal = std::move(signal);
    p.apply = std::move(apply);
    pending_.push_back(std::move(p));
  }

  void resolve() {
    for (auto& p : pending_) {
      what_ = p.kind;
      Message* m = find_message(p.id);
      const bool skipped = skipped_ids_.count(p.id) != 0;
      if (!m) {
        if (!skipped) warn(p.line, "unknown-message", fmt::format("{} names message id {}, which is not defined: kept aside", p.kind, p.id));
        db_.other_statements.push_back(p.verbatim);
        continue;
      }
      Signal* s = nullptr;
      if (!p.signal.empty()) {
        for (auto& x : m->signals)
          if (x.name == p.signal) s = &x;
        if (!s) {
          warn(p.line, "unknown-signal",
               fmt::format("{} names signal '{}', which message '{}' does not have: kept aside", p.kind, p.signal, m->name));
          db_.other_statements.push_back(p.verbatim);
          continue;
        }
      }
      p.apply(*m, s);
    }
    apply_long_names();
  }

  /// Vector tools keep names over 32 characters in SystemNodeLongSymbol, SystemMessageLongSymbol,
  /// SystemSignalLongSymbol and SystemEnvVarLongSymbol attributes; the long name is the name (as
  /// CANdb++, canmatrix and cantools read it), wherever the short one is used.
  void apply_long_names() {
    for (std::size_t i = 0; i < db_.attributes.size(); ++i) {
      const Attribute& a = db_.attributes[i];
      if (a.name == "SystemNodeLongSymbol" && a.object == "BU_") {
        rename_node(std::string(a.node), std::string(a.value.text));
      } else if (a.name == "SystemEnvVarLongSymbol" && a.object == "EV_") {
        rename_env_var(std::string(a.node), std::string(a.value.text));
      }
    }
    for (auto& a : db_.attributes) {
      if (a.name == "SystemMessageLongSymbol" && a.object == "BO_") {
        if (Message* m = find_message(a.message_dbc_id)) m->name = a.value.text;
      } else if (a.name == "SystemSignalLongSymbol" && a.object == "SG_") {
        Message* m = find_message(a.message_dbc_id);
        if (!m) continue;
        const std::string old = a.signal;
        for (auto& sg : m->signals)
          if (sg.name == old) sg.name = a.value.text;
        for (auto& sg : m->signals)
          if (sg.multiplexor == old) sg.multiplexor = a.value.text;
        for (auto& b : db_.attributes)
          if (b.object == "SG_" && b.signal == old && find_message(b.message_dbc_id) == m) b.signal = a.value.text;
      }
    }
  }

  /// The node `from` is called `to`: in BU_, as transmitter and receiver, in comments and attributes.
  void rename_node(const std::string& from, const std::string& to) {
    if (from == to || to.empty()) return;
    for (auto& n : db_.nodes)
      if (n == from) n = to;
    for (auto& m : db_.messages) {
      if (m.transmitter == from) m.transmitter = to;
      for (auto& sg : m.signals)
        for (auto& r : sg.receivers)
          if (r == from) r = to;
    }
    for (auto& c : db_.node_comments)
      if (c.node == from) c.node = to;
    for (auto& b : db_.attributes)
      if (b.object == "BU_" && b.node == from) b.node = to;
  }

  /// The environment variable `from` is called `to`: in its EV_ statement (kept verbatim) and attributes.
  void rename_env_var(const std::string& from, const std::string& to) {
    if (from == to || to.empty()) return;
    for (auto& text : db_.other_statements) {
      // "EV_ name : ..." (blanks around the name as written)
      if (text.rfind("EV_", 0) != 0 || text.size() < 4 || (text[3] != ' ' && text[3] != '\t')) continue;
      const std::size_t b = text.find_first_not_of(" \t", 3);
      if (b == std::string::npos || text.compare(b, from.size(), from) != 0) continue;
      const std::size_t e = b + from.size();
      if (e < text.size() && text[e] != ' ' && text[e] != '\t' && text[e] != ':') continue;
      text.replace(b, from.size(), to);
    }
    for (auto& b : db_.attributes)
      if (b.object == "EV_" && b.node == from) b.node = to;
  }

  void message() {
    const Token kw = take();
    skipping_signals_ = false;
    current_ = -1;
    Message m;
    const Token at = tok_;
    const auto dbc_id = integer<std::uint32_t>("the message id");
    m.extended = (dbc_id & 0x80000000u) != 0;
    m.id = dbc_id & 0x7FFFFFFFu;
    m.name = ident("the message name");
    expect_punct(':');
    const Token st = tok_;
    m.size = integer<std::uint32_t>("the message size");
    if (m.size > 64) fail(st, "message size must be 0..64 bytes");
    if (tok_.kind == Tok::ident && !at_statement_start()) {
      m.transmitter = take().text;
    } else {
      warn(kw.line, "no-transmitter", fmt::format("message '{}' names no transmitter (Vector__XXX assumed)", m.name));
      m.transmitter = "Vector__XXX";
    }
    if (!m.extended && m.id > 0x7FF && m.id <= 0x1FFFFFFF) {
      warn(at.line, "implicit-extended-id",
           fmt::format("id {} (0x{:X}) of '{}' exceeds 0x7FF without bit 31: read as an extended id", dbc_id, m.id, m.name));
      m.extended = true;
    }
    if (m.id > 0x1FFFFFFF) {
      skipped_ids_.insert(dbc_id);
      skipping_signals_ = true;
      const bool pseudo = m.name == "VECTOR__INDEPENDENT_SIG_MSG";
      if (strict_ && !pseudo) fail(at, fmt::format("id 0x{:X} of '{}' exceeds 29 bits", m.id, m.name));
      if (!pseudo || diags_)
        add({Diagnostic::Severity::warning, file_, at.line, pseudo ? "independent-signals" : "id-out-of-range",
             pseudo ? "VECTOR__INDEPENDENT_SIG_MSG (signals not sent in any frame) skipped"
                    : fmt::format("id 0x{:X} of '{}' exceeds 29 bits: message skipped", m.id, m.name)});
      return;
    }
    if (const Message* o = find_message(m.dbc_id())) {
      warn(at.line, "duplicate-message-id",
           fmt::format("id {} of '{}' is already used by '{}': the later message is skipped", dbc_id, m.name, o->name));
      skipping_signals_ = true;
      return;
    }
    db_.messages.push_back(std::move(m));
    current_ = static_cast<long>(db_.messages.size()) - 1;
  }

  void signal() {
    const Token kw = take();
    Signal s;
    const Token nt = tok_;
    s.name = ident("the signal name");
    if (tok_.kind == Tok::ident) {
      const Token mt = take();
      const std::string& x = mt.text;
      if (x == "M") {
        s.mux = MuxRole::multiplexor;
      } else if (x == "m") {
        warn(mt.line, "bare-m", "multiplexer indicator 'm' without a value: signal '" + s.name + "' read as not multiplexed");
      } else if (x.size() >= 2 && x[0] == 'm') {
        std::string_view digits(x);
        digits.remove_prefix(1);
        if (!digits.empty() && digits.back() == 'M') {  // extended multiplexing "m1M": multiplexed, switch too
          s.mux_switch = true;
          digits.remove_suffix(1);
        }
        auto r = std::from_chars(digits.data(), digits.data() + digits.size(), s.mux_value);
        if (digits.empty() || r.ec != std::errc() || r.ptr != digits.data() + digits.size())
          fail(mt, "expected a multiplexer indicator M or m<n>, found '" + x + "'");
        s.mux = MuxRole::multiplexed;
      } else {
        fail(mt, "expected a multiplexer indicator M or m<n>, found '" + x + "'");
      }
    }
    expect_punct(':');
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
    const int line = prev_line_;
    while (tok_.kind == Tok::ident && tok_.line == line && !at_statement_start()) {
      std::string r = take().text;
      if (r != "Vector__XXX") s.receivers.push_back(std::move(r));  // the DBC's 'no receiver'
      if (tok_.kind == Tok::punct && tok_.text[0] == ',' && tok_.line == line) take();
    }
    if (skipping_signals_ || current_ < 0) return;  // signal of a skipped message
    Message& m = db_.messages[static_cast<std::size_t>(current_)];
    if (m.signal(s.name)) {
      warn(nt.line, "duplicate-signal", "duplicate signal '" + s.name + "' in message '" + m.name + "': the later one is skipped");
      return;
    }
    (void)kw;
    m.signals.push_back(std::move(s));
  }

  /// SG_MUL_VAL_ id signal multiplexor lo-hi, lo-hi ;
  void mux_values(const Token& kw) {
    take();
    const auto id = integer<std::uint32_t>("the message id");
    const std::string name = ident("the signal name");
    const std::string mux = ident("the multiplexor name");
    const std::size_t from = prev_end_;
    while (tok_.kind != Tok::end && !(tok_.kind == Tok::punct && tok_.text[0] == ';') && !at_statement_start()) take();
    const std::string text(lex_.slice(from, prev_end_ > from ? prev_end_ : from));
    expect_end();
    std::vector<MuxRange> ranges;
    std::size_t p = 0;
    while (p < text.size()) {
      while (p < text.size() && (text[p] == ' ' || text[p] == '\t' || text[p] == ',' || text[p] == '\r' || text[p] == '\n')) ++p;
      if (p >= text.size()) break;
      MuxRange r;
      auto a = std::from_chars(text.data() + p, text.data() + text.size(), r.lo);
      if (a.ec != std::errc() || a.ptr >= text.data() + text.size() || *a.ptr != '-')
        lex_.fail(kw.line, kw.col, what_, "expected ranges lo-hi, found '" + text + "'");
      auto b = std::from_chars(a.ptr + 1, text.data() + text.size(), r.hi);
      if (b.ec != std::errc() || r.hi < r.lo) lex_.fail(kw.line, kw.col, what_, "expected ranges lo-hi, found '" + text + "'");
      p = static_cast<std::size_t>(b.ptr - text.data());
      ranges.push_back(r);
    }
    defer(kw, "SG_MUL_VAL_", id, name, [mux, ranges](Message&, Signal* s) {
      s->multiplexor = mux;
      s->mux_ranges = ranges;
    });
  }

  void comment() {
    const Token kw = take();
    if (tok_.kind == Tok::string) {
      db_.comment = take().text;
      expect_end();
      return;
    }
    if (tok_.kind == Tok::number) {  // CM_ 145 "…": no object kind
      warn(kw.line, "comment-without-object", "CM_ with a number but no BO_/SG_: kept aside");
      other_from(kw);
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
      const auto id = integer<std::uint32_t>("the message id");
      std::string text = string("the comment");
      expect_end();
      defer(kw, "CM_ BO_", id, "", [t = std::move(text)](Message& m, Signal*) mutable { m.comment = std::move(t); });
    } else if (obj == "SG_") {
      const auto id = integer<std::uint32_t>("the message id");
      if (tok_.kind == Tok::string) {
        warn(kw.line, "comment-without-signal", fmt::format("CM_ SG_ {} without a signal name: kept aside", id));
        other_from(kw);
        return;
      }
      const std::string name = ident("the signal name");
      std::string text = string("the comment");
      expect_end();
      defer(kw, "CM_ SG_", id, name, [t = std::move(text)](Message&, Signal* s) mutable { s->comment = std::move(t); });
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
    const Token kw = take();
    Attribute a;
    a.name = string("the attribute name");
    if (tok_.kind == Tok::ident) {
      const Token o = take();
      a.object = o.text;
      if (a.object == "BU_" || a.object == "EV_") {
        a.node = ident("the node name");
      } else if (a.object == "BO_") {
        a.message_dbc_id = integer<std::uint32_t>("the message id");
      } else if (a.object == "SG_") {
        a.message_dbc_id = integer<std::uint32_t>("the message id");
        a.signal = ident("the signal name");
      } else {
        fail(o, "expected BU_, BO_, SG_, EV_ or a value, found '" + o.text + "'");
      }
    }
    a.value = attribute_value();
    expect_end();
    if (a.object == "BO_" || a.object == "SG_") {  // checked once the whole file is read
      const std::uint32_t id = a.message_dbc_id;
      std::string sig = a.signal;
      defer(kw, "BA_", id, std::move(sig), [this, a = std::move(a)](Message&, Signal*) { db_.attributes.push_back(a); });
      return;
    }
    db_.attributes.push_back(std::move(a));
  }

  Lexer lex_;
  Token tok_;
  Database db_;
  std::string file_;
  bool strict_ = false;
  std::size_t statements_read_ = 0;
  std::vector<Diagnostic>* diags_ = nullptr;
  std::string what_ = "DBC";
  int prev_line_ = 0;
  std::size_t prev_end_ = 0;
  long current_ = -1;
  bool skipping_signals_ = false;
  std::vector<Pending> pending_;
  std::set<std::uint32_t> skipped_ids_;
};
}  // namespace

Database parse_dbc(std::string_view text, const std::string& file, const ParseOptions& options,
                   std::vector<Diagnostic>* diagnostics) {
  std::vector<Diagnostic> local;
  std::vector<Diagnostic>* diags = diagnostics ? diagnostics : &local;
  const std::size_t before = diags->size();
  Parser p(text, file, options, diags);
  Database db = p.run();
  // Tolerant reading keeps what it can; when not one statement could be read, the file is no DBC.
  if (p.statements_read() == 0 && diags->size() > before)
    throw InputError(file, 0, "",
                     fmt::format("no DBC statement could be read ({} problems, e.g. line {}: {}): not a DBC file?",
                                 diags->size() - before, (*diags)[before].line, (*diags)[before].message));
  return db;
}

std::string Diagnostic::format() const {
  const char* sev = severity == Severity::error ? "error" : "warning";
  if (line <= 0) return fmt::format("{}: {}: {} [{}]", file, sev, message, kind);
  return fmt::format("{}:{}: {}: {} [{}]", file, line, sev, message, kind);
}

Database load_dbc(const std::filesystem::path& path, const ParseOptions& options, std::vector<Diagnostic>* diagnostics) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), 0, "", "cannot open DBC file for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_dbc(ss.str(), path.string(), options, diagnostics);
}

}  // namespace lash::can::dbc
