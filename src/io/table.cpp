// read_table: the one record reader (text or MAT) and the sampling analysis.
#include "lash/io/table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>

#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/io/mat.hpp"
#include "lash/io/order_statistic.hpp"

namespace lash {

namespace {
/// The header's names for an error: "a,b,c", or the first ~200 characters and how many columns.
std::string header_list(const std::vector<std::string>& names) {
  std::string have;
  for (const auto& h : names) {
    if (have.size() + h.size() > 200) return have + ",\u2026 (" + std::to_string(names.size()) + " columns)";
    have += (have.empty() ? "" : ",") + h;
  }
  return have;
}
}  // namespace

ColumnStore Table::store() const& {
  if (spilled.rows()) return spilled;
  std::vector<std::span<const double>> v(cols.begin(), cols.end());
  return ColumnStore(std::move(v));
}

std::size_t Table::column(std::string_view name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return i;
  throw InputError(file, 1, std::string(name), "no such column (the header has: " + header_list(names) + ")");
}

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const noexcept { std::fclose(f); }
};

bool is_blank(char c) noexcept { return c == ' ' || c == '\t'; }

/// Outcome of reading one cell.
enum class Cell { number, non_finite, junk };

/// Parses a cell; fast path: the whole field is a plain number. Slow path: surrounding
/// blanks and quotes, a leading '+', a decimal comma (when allowed), nan/inf, empty.
Cell parse_cell(const char* b, const char* e, bool decimal_comma, double& v) noexcept {
  auto r = std::from_chars(b, e, v);
  if (r.ptr == e && r.ec == std::errc()) return std::isfinite(v) ? Cell::number : Cell::non_finite;
  while (b < e && (is_blank(*b) || *b == '"' || *b == '\r')) ++b;
  while (e > b && (is_blank(e[-1]) || e[-1] == '"' || e[-1] == '\r')) --e;
  if (b < e && *b == '+') ++b;
  if (b == e) return Cell::non_finite;  // an empty cell: a missing value
  char buf[64];
  const std::size_t n = static_cast<std::size_t>(e - b);
  if (n >= sizeof buf) return Cell::junk;
  std::memcpy(buf, b, n);
  if (decimal_comma)
    for (std::size_t i = 0; i < n; ++i)
      if (buf[i] == ',') buf[i] = '.';
  r = std::from_chars(buf, buf + n, v);
  if (r.ptr != buf + n || r.ec == std::errc::invalid_argument) {
    // from_chars does not read "NaN"/"Inf" spelled with capitals the C way only; lower-case it.
    std::string low(buf, n);
    for (char& c : low) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (low == "nan" || low == "-nan" || low == "inf" || low == "-inf" || low == "infinity" || low == "-infinity" ||
        low == "na" || low == "null")
      return Cell::non_finite;
    return Cell::junk;
  }
  if (r.ec == std::errc::result_out_of_range) return Cell::non_finite;
  return std::isfinite(v) ? Cell::number : Cell::non_finite;
}

/// Splits a line into fields (views into it): the sniffed separator, or runs of blanks when 0.
void split(std::string_view line, char sep, std::vector<std::string_view>& out) {
  out.clear();
  if (sep == 0) {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && is_blank(line[i])) ++i;
      if (i == line.size()) break;
      const std::size_t s = i;
      while (i < line.size() && !is_blank(line[i])) ++i;
      out.push_back(line.substr(s, i - s));
    }
    return;
  }
  std::size_t start = 0;
  for (std::size_t i = 0; i <= line.size(); ++i)
    if (i == line.size() || line[i] == sep) {
      out.push_back(line.substr(start, i - start));
      start = i + 1;
    }
}

std::string trim_name(std::string_view s) {
  while (!s.empty() && (is_blank(s.front()) || s.front() == '"')) s.remove_prefix(1);
  while (!s.empty() && (is_blank(s.back()) || s.back() == '"' || s.back() == '\r')) s.remove_suffix(1);
  return std::string(s);
}

bool is_index(const std::string& s) {
  return !s.empty() && s.size() < 9 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

/// Resolves the chosen columns against the header: field index of each, refusing unknown
/// names, indices out of range and a column chosen twice.
std::vector<std::size_t> choose(const std::string& file, int header_line, const std::vector<std::string>& header,
                                const std::vector<std::string>& wanted) {
  std::vector<std::size_t> idx;
  if (wanted.empty()) {
    for (std::size_t i = 0; i < header.size(); ++i) idx.push_back(i);
    return idx;
  }
  for (const auto& w : wanted) {
    auto it = std::find(header.begin(), header.end(), w);
    std::size_t i = 0;
    if (it != header.end()) {
      i = static_cast<std::size_t>(it - header.begin());
    } else if (is_index(w)) {
      i = std::stoul(w);
      if (i >= header.size())
        throw InputError(file, header_line, w,
                         "column index out of range (the file has " + std::to_string(header.size()) +
                             " columns, 0.." + std::to_string(header.size() - 1) + ")");
    } else {
      throw InputError(file, header_line, w, "no such column (the header has: " + header_list(header) + ")");
    }
    if (std::find(idx.begin(), idx.end(), i) != idx.end())
      throw InputError(file, 0, "--columns", "column '" + header[i] + "' (index " + std::to_string(i) +
                                                 ") is chosen twice");
    idx.push_back(i);
  }
  return idx;
}

/// The longest line the text reader takes (a header of 10^6 columns is ~10 MiB).
constexpr std::size_t kMaxLineBytes = std::size_t{64} << 20;

/// The text reader. State across blocks: the header, the chosen fields, the columns.
class TextReader {
 public:
  TextReader(std::string file, const TableOptions& o) : o_(o) { t_.file = std::move(file); }

  Table read(const std::filesystem::path& path) {
    std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
    if (!f) throw InputError(t_.file, 0, "", "cannot open file for reading");
    std::error_code ec;
    file_size_ = std::filesystem::file_size(path, ec);
    if (ec) file_size_ = 0;
    std::vector<char> buf(1 << 20);
    std::size_t have = 0;
    bool first_block = true;
    std::uint64_t offset = 0;  // of buf[0] in the file
    for (;;) {
      if (have == buf.size()) {  // a line longer than the buffer
        if (buf.size() >= kMaxLineBytes)
          throw InputError(t_.file, lineno_ + 1, "",
                           "line longer than " + std::to_string(kMaxLineBytes >> 20) + " MiB: not a text table");
        buf.resize(buf.size() * 2);
      }
      const std::size_t got = std::fread(buf.data() + have, 1, buf.size() - have, f.get());
      if (const void* z = std::memchr(buf.data() + have, '\0', got))
        throw InputError(t_.file, 0, "",
                         "binary data (a NUL byte at offset " +
                             std::to_string(offset + static_cast<std::uint64_t>(static_cast<const char*>(z) - buf.data())) +
                             "): not a text table (CSV, TSV, ...) nor a MAT file");
      const bool eof = got < buf.size() - have;
      have += got;
      const char* p = buf.data();
      const char* end = buf.data() + have;
      if (first_block) {
        first_block = false;
        if (have >= 3 && std::memcmp(p, "\xEF\xBB\xBF", 3) == 0) p += 3;  // UTF-8 byte-order mark
        bytes_first_block_ = have;
        lines_first_block_ = static_cast<std::size_t>(std::count(p, end, '\n')) + 1;
      }
      for (;;) {
        const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
        if (!nl) break;
        line(p, nl);
        p = nl + 1;
      }
      if (eof) {
        if (p < end) line(p, end);
        break;
      }
      offset += static_cast<std::uint64_t>(p - buf.data());
      consumed_ = offset;
      have = static_cast<std::size_t>(end - p);
      std::memmove(buf.data(), p, have);
    }
    if (!have_header_) throw InputError(t_.file, 0, "", "empty file (expected a header line and data rows)");
    if (spill_) t_.spilled = spill_->finish();
    if (t_.rows() == 0)
      throw InputError(t_.file, lineno_, "",
                       t_.skipped_rows ? "no data rows with finite values (" + std::to_string(t_.skipped_rows) +
                                             " rows skipped)"
                                       : std::string("no data rows after the header"));
    return std::move(t_);
  }

 private:
  void line(const char* b, const char* e) {
    ++lineno_;
    if (e > b && e[-1] == '\r') --e;
    const char* q = b;
    while (q < e && is_blank(*q)) ++q;
    if (q == e || *q == '#') return;
    if (!have_header_) return header(std::string_view(b, static_cast<std::size_t>(e - b)));
    row(b, e);
  }

  void header(std::string_view sv) {
    sep_ = sv.find('\t') != std::string_view::npos   ? '\t'
           : sv.find(';') != std::string_view::npos ? ';'
           : sv.find(',') != std::string_view::npos ? ','
                                                    : 0;
    decimal_comma_ = sep_ != ',';
    std::vector<std::string_view> fields;
    split(sv, sep_, fields);
    bool numeric = true;
    for (auto fv : fields) {
      double v;
      if (parse_cell(fv.data(), fv.data() + fv.size(), decimal_comma_, v) != Cell::number) numeric = false;
    }
    std::vector<std::string> names;
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (numeric) {
        names.push_back(std::to_string(i));
        continue;
      }
      std::string n = trim_name(fields[i]);
      if (n.empty()) throw InputError(t_.file, lineno_, "header", "empty column name");
      names.push_back(std::move(n));
    }
    have_header_ = true;
    nfields_ = names.size();
    const auto idx = choose(t_.file, lineno_, names, o_.columns);
    slot_of_field_.assign(nfields_, -1);
    for (std::size_t s = 0; s < idx.size(); ++s) {
      slot_of_field_[idx[s]] = static_cast<int>(s);
      t_.names.push_back(names[idx[s]]);
    }
    last_field_ = *std::max_element(idx.begin(), idx.end());
    t_.cols.resize(idx.size());
    vals_.resize(idx.size());
    // Reserve from the file size and the first block's line density: one allocation per column.
    const double per_line = static_cast<double>(bytes_first_block_) / static_cast<double>(std::max<std::size_t>(1, lines_first_block_));
    auto rows_est = static_cast<std::size_t>(static_cast<double>(file_size_) / std::max(1.0, per_line) * 1.05) + 16;
    if (o_.spill_after_rows) rows_est = std::min(rows_est, o_.spill_after_rows);  // the rest goes to the spill file
    for (auto& c : t_.cols) c.reserve(rows_est);
    if (numeric) row(sv.data(), sv.data() + sv.size());
  }

  void row(const char* b, const char* e) {
    const char* p = b;
    bool bad = false;
    int bad_slot = -1;
    for (std::size_t f = 0; f <= last_field_; ++f) {
      const char* fe;
      // fast path: a chosen field that is a plain finite number ending at the separator (or the
      // line's end) is read in place, without finding the separator first
      if (sep_ != 0 && slot_of_field_[f] >= 0) {
        double v;
        const auto r = std::from_chars(p, e, v);
        if (r.ec == std::errc() && (r.ptr == e || *r.ptr == sep_) && std::isfinite(v)) {
          vals_[static_cast<std::size_t>(slot_of_field_[f])] = v;
          if (f < last_field_) {
            if (r.ptr == e) too_few(f + 1);
            p = r.ptr + 1;
          }
          continue;
        }
      }
      if (sep_ == 0) {
        while (p < e && is_blank(*p)) ++p;
        if (p == e) too_few(f);
        fe = p;
        while (fe < e && !is_blank(*fe)) ++fe;
      } else {
        fe = static_cast<const char*>(std::memchr(p, sep_, static_cast<std::size_t>(e - p)));
        if (!fe) fe = e;
      }
      const int s = slot_of_field_[f];
      if (s >= 0) {
        double v;
        switch (parse_cell(p, fe, decimal_comma_, v)) {
          case Cell::number: vals_[static_cast<std::size_t>(s)] = v; break;
          case Cell::non_finite:
            if (!bad) bad_slot = s;
            bad = true;
            break;
          case Cell::junk:
            throw InputError(t_.file, lineno_, t_.names[static_cast<std::size_t>(s)],
                             "not a number: '" + std::string(p, fe) + "'");
        }
      }
      if (f < last_field_) {
        if (sep_ != 0 && fe == e) too_few(f + 1);
        p = sep_ == 0 ? fe : fe + 1;
      }
    }
    if (bad) {
      if (o_.strict)
        throw InputError(t_.file, lineno_, t_.names[static_cast<std::size_t>(bad_slot)],
                         "not a finite number (rows with nan, inf or empty cells are skipped without --strict)");
      if (t_.skipped_rows++ == 0) t_.first_skipped_line = lineno_;
      return;
    }
    t_.line_of_row.push_back(lineno_);
    if (spill_) {
      spill_->push(vals_.data());
      return;
    }
    if (o_.spill_after_rows && t_.cols[0].size() == o_.spill_after_rows) [[unlikely]] {
      // long: the rows so far and every later one go to a temporary file; the columns are freed
      spill_ = std::make_unique<SpillWriter>(vals_.size());
      spill_->push_columns(t_.cols, t_.cols[0].size());
      for (auto& c : t_.cols) std::vector<double>().swap(c);
      spill_->push(vals_.data());
      return;
    }
    if (t_.cols[0].size() == t_.cols[0].capacity()) [[unlikely]] grow();
    for (std::size_t s = 0; s < vals_.size(); ++s) t_.cols[s].push_back(vals_[s]);
  }

  /// The reservation from the first block was short (later lines are shorter): reserve for the
  /// rest of the file at the density read so far (+5 %), instead of doubling, so that a column
  /// is moved at most about once and the peak stays near the columns' own size.
  void grow() {
    const std::size_t rows = t_.cols[0].size();
    const double per_row = static_cast<double>(std::max<std::uint64_t>(consumed_, 1)) / static_cast<double>(std::max<std::size_t>(rows, 1));
    const double left = static_cast<double>(file_size_ > consumed_ ? file_size_ - consumed_ : 0);
    std::size_t more = static_cast<std::size_t>(left / std::max(1.0, per_row) * 1.05) + 1024;
    // no size to go by (a pipe; still in the first block): double; short again: grow by a quarter
    // at least (geometric, so the moves stay few)
    more = file_size_ == 0 || consumed_ == 0 ? std::max<std::size_t>(rows, 1024) : std::max(more, rows / 4);
    for (auto& c : t_.cols) c.reserve(rows + more);
  }

  [[noreturn]] void too_few(std::size_t found) const {
    throw InputError(t_.file, lineno_, "",
                     "expected " + std::to_string(nfields_) + " fields, found " + std::to_string(found));
  }

  const TableOptions& o_;
  Table t_;
  char sep_ = ',';
  bool decimal_comma_ = false;
  bool have_header_ = false;
  int lineno_ = 0;
  std::size_t nfields_ = 0, last_field_ = 0;
  std::vector<int> slot_of_field_;
  std::vector<double> vals_;
  std::unique_ptr<SpillWriter> spill_;  ///< past spill_after_rows: where the rows go
  std::uintmax_t file_size_ = 0;
  std::uint64_t consumed_ = 0;  ///< bytes of the file before the current block's first line
  std::size_t bytes_first_block_ = 0, lines_first_block_ = 0;
};

bool looks_like_mat(const std::filesystem::path& path) {
  if (is_mat_file(path)) return true;
  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
  char head[6] = {};
  if (!f || std::fread(head, 1, sizeof head, f.get()) != sizeof head) return false;
  return std::memcmp(head, "MATLAB", 6) == 0;  // v5 / v7.3 header text
}

}  // namespace

Table read_table(const std::filesystem::path& path, const TableOptions& options) {
  if (looks_like_mat(path)) return read_mat_table(path, options);
  TextReader r(path.string(), options);
  return r.read(path);
}

namespace {

/// The steps t[i + 1] − t[i] for i in [begin, begin + count) into out (reads t[begin, begin + count]).
void read_steps(const TimeSource& t, std::size_t begin, std::size_t count, double* buf, double* out) {
  const double* x = t.read(begin, count + 1, buf);
  for (std::size_t i = 0; i < count; ++i) out[i] = x[i + 1] - x[i];
}

constexpr std::size_t kStepChunk = 4096;

/// From step j on (the step x[j + 1] − x[j], j < m): the largest |step − med| of the steps up to
/// the first one above gap_above, into max_dev; returns that step's index (m when none). Not
/// inlined: a loop that calls nothing keeps its maximum in a register, where the caller's loop
/// (which appends to a vector) kept it in memory.
[[gnu::noinline]] std::size_t scan_to_gap(const double* x, std::size_t j, std::size_t m, double gap_above, double med,
                                          double& max_dev) noexcept {
  double mx = max_dev;
  for (; j < m; ++j) {
    const double step = x[j + 1] - x[j];
    if (step > gap_above) break;
    mx = std::max(mx, std::abs(step - med));
  }
  max_dev = mx;
  return j;
}

/// The median of the steps t[i] − t[i−1], exactly: the value nth_element gives on a full copy of
/// them (rank n/2; for even n the mean with rank n/2 − 1), by OrderStatistic (Floyd & Rivest's
/// selection): the median of a strided sample of the steps brackets the true one between two
/// sample values lo ≤ hi; one pass counts the steps below lo, equal to lo, equal to hi and above
/// hi and keeps only those strictly between; the median's ranks are then found in those counts or
/// among the kept few. A uniformly sampled record has nearly all steps equal (or a few values
/// apart): the pass keeps almost nothing. Fewer than 8·2048 steps (or a NaN step in the sample):
/// every step is kept. A bracket that misses, or more kept steps than OrderStatistic's cap, take
/// further passes (io/order_statistic.hpp).
double median_step(const TimeSource& t) {
  const std::size_t n = t.rows() - 1;  // steps
  constexpr std::size_t kSample = 2048;
  OrderStatistic med = OrderStatistic::median();
  if (n >= 8 * kSample) {
    std::vector<double> smp(kSample);
    const std::size_t stride = n / kSample;
    double buf[2];
    for (std::size_t j = 0; j < kSample; ++j) read_steps(t, j * stride, 1, buf, &smp[j]);
    std::sort(smp.begin(), smp.end());
    // ±3 standard deviations of the sample median's rank (√kSample / 2 ≈ 23 positions)
    constexpr std::size_t kMargin = 96;
    if (!std::isnan(smp.front()) && !std::isnan(smp.back())) med.bracket(smp[kSample / 2 - kMargin], smp[kSample / 2 + kMargin]);
  }
  std::vector<double> buf(kStepChunk + 1);
  do {
    for (std::size_t i = 0; i < n; i += kStepChunk) {
      const std::size_t c = std::min(kStepChunk, n - i);
      med.add_steps(t.read(i, c + 1, buf.data()), c);
    }
  } while (med.end_pass());
  return med.value();
}

}  // namespace

Sampling analyse_sampling(std::span<const double> t, double gap_factor) {
  return analyse_sampling(SpanTimeSource(t), gap_factor);
}

Sampling analyse_sampling(const TimeSource& t, double gap_factor) {
  Sampling s;
  const std::size_t rows = t.rows();
  if (rows < 2) return s;
  const double med = median_step(t);
  s.median_dt = med;
  // dt = (span − the gap steps) / (steps − gaps): without gaps exactly (t.back() − t.front())/(n − 1).
  // max_jitter = max|step − med| / med: one division at the end (x ↦ x / med is monotone, so the
  // quotient of the largest deviation is the largest quotient, to the bit)
  double gap_sum = 0.0, max_dev = 0.0;
  const double gap_above = gap_factor * med;
  std::vector<double> buf(kStepChunk + 1);
  for (std::size_t i = 0; i + 1 < rows; i += kStepChunk) {
    const std::size_t c = std::min(kStepChunk, rows - 1 - i);
    const double* x = t.read(i, c + 1, buf.data());
    for (std::size_t j = 0; j < c; ++j) {
      j = scan_to_gap(x, j, c, gap_above, med, max_dev);
      if (j == c) break;
      s.gap_rows.push_back(i + j + 1);
      gap_sum += x[j + 1] - x[j];
    }
  }
  if (med > 0) s.max_jitter = max_dev / med;
  const std::size_t n = rows - 1 - s.gap_rows.size();
  double ends[2], b1;
  ends[0] = *t.read(0, 1, &b1);
  ends[1] = *t.read(rows - 1, 1, &b1);
  s.dt = n ? (ends[1] - ends[0] - gap_sum) / static_cast<double>(n) : med;
  return s;
}

namespace {
/// A column of a ColumnStore as a TimeSource (a spilled store is read into the caller's buffer).
class StoreTimeSource final : public TimeSource {
 public:
  StoreTimeSource(const ColumnStore& s, std::size_t column) noexcept : s_(s), c_(column) {}
  std::size_t rows() const override { return s_.rows(); }
  const double* read(std::size_t begin, std::size_t count, double* buf) const override {
    s_.read(c_, begin, count, buf);
    return buf;
  }

 private:
  const ColumnStore& s_;
  std::size_t c_;
};
}  // namespace

Sampling analyse_sampling(const ColumnStore& store, std::size_t column, double gap_factor) {
  if (store.in_memory()) return analyse_sampling(store.column(column), gap_factor);
  return analyse_sampling(StoreTimeSource(store, column), gap_factor);
}

}  // namespace lash
