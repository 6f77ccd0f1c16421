#include "lash/console/server.hpp"

#include <sys/random.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "lash/io/error.hpp"

namespace lash::console {

extern const char* const kPageHtml;  // page.cpp, generated from src/console/page/
extern const char* const kPageJs;

std::string random_token(std::size_t bytes) {
  std::vector<unsigned char> b(bytes);
  std::size_t got = 0;
  while (got < bytes) {
    const ssize_t r = getrandom(b.data() + got, bytes - got, 0);
    if (r < 0) {
      if (errno == EINTR) continue;
      throw SystemError(std::string("getrandom failed: ") + std::strerror(errno));
    }
    got += static_cast<std::size_t>(r);
  }
  static const char* hex = "0123456789abcdef";
  std::string s;
  for (unsigned char c : b) {
    s += hex[c >> 4];
    s += hex[c & 15];
  }
  return s;
}

void ConsoleOptions::validate() const {
  if (port < 0 || port > 65535) throw InputError("", 0, "--console", "port must be 0..65535 (0 = any free port)");
  if (bind.empty()) throw InputError("", 0, "--console-bind", "empty address");
  if (signals.empty() || signals.size() > kMaxSignals)
    throw InputError("", 0, "--console", "1.." + std::to_string(kMaxSignals) + " signals, got " +
                                              std::to_string(signals.size()));
  for (const auto& f : extra_feeds)
    if (f.empty() || f.size() > kMaxSignals)
      throw InputError("", 0, "--console", "an extra feed needs 1.." + std::to_string(kMaxSignals) + " signals");
}

namespace {

std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  if (!f) return {};
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

bool equal_ct(const std::string& a, const std::string& b) {  // constant time in the content
  if (a.size() != b.size()) return false;
  unsigned char d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d |= static_cast<unsigned char>(a[i] ^ b[i]);
  return d == 0;
}

bool loopback(const std::string& a) { return a == "127.0.0.1" || a == "::1" || a == "localhost"; }

}  // namespace

struct Server::Group {
  explicit Group(const DecimatorConfig& d) : dec(d) {}
  Feed feed;
  Decimator dec;
};

struct Server::Impl {
  httplib::Server http;
  std::string uplot_js, uplot_css;
};

Server::Server(ConsoleOptions options, Tuner tuner)
    : impl_(std::make_unique<Impl>()),
      o_(std::move(options)),
      tuner_(std::move(tuner)) {
  o_.validate();
  for (std::size_t g = 0; g <= o_.extra_feeds.size(); ++g) {
    const auto& names = g == 0 ? o_.signals : o_.extra_feeds[g - 1];
    DecimatorConfig d = o_.decimation;
    d.signals = names.size();
    groups_.push_back(std::make_unique<Group>(d));
    all_signals_.insert(all_signals_.end(), names.begin(), names.end());
  }
  impl_->uplot_js = read_file(o_.uplot_dir / "uPlot.iife.min.js");
  impl_->uplot_css = read_file(o_.uplot_dir / "uPlot.min.css");
  if (impl_->uplot_js.empty() || impl_->uplot_css.empty())
    throw InputError(o_.uplot_dir.string(), 0, "--console",
                     "uPlot (uPlot.iife.min.js, uPlot.min.css) not found there; run scripts/install-deps.sh or set "
                     "LASH_UPLOT_DIR");
  token_ = random_token();
  for (const auto& p : o_.params) param_values_[p.name] = std::numeric_limits<double>::quiet_NaN();

  auto& h = impl_->http;
  const std::string csp =
      "default-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; connect-src 'self'; "
      "frame-ancestors 'none'";
  auto common = [csp](httplib::Response& res) {
    res.set_header("Content-Security-Policy", csp);
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("Cache-Control", "no-store");
    res.set_header("Referrer-Policy", "no-referrer");
  };
  // Host must name this server (no DNS rebinding); /api needs the token; changes need Origin too.
  auto host_ok = [this](const httplib::Request& req) {
    const std::string host = req.get_header_value("Host");
    const std::string p = ":" + std::to_string(port_);
    if (host == o_.bind + p) return true;
    return loopback(o_.bind) && (host == "127.0.0.1" + p || host == "localhost" + p || host == "[::1]" + p);
  };
  auto deny = [common](httplib::Response& res, const std::string& why) {
    common(res);
    res.status = 403;
    res.set_content(nlohmann::json{{"ok", false}, {"error", why}}.dump(), "application/json");
  };
  auto api_ok = [this, host_ok, deny](const httplib::Request& req, httplib::Response& res, bool change) {
    ++requests_;
    if (!host_ok(req)) return deny(res, "Host does not name this console"), false;
    if (!equal_ct(req.get_header_value("X-Lash-Token"), token_))
      return deny(res, "missing or wrong X-Lash-Token"), false;
    if (change) {
      const std::string origin = req.get_header_value("Origin");
      if (origin != "http://" + req.get_header_value("Host")) return deny(res, "cross-origin request refused"), false;
      if (o_.read_only) return deny(res, "the console is read-only (--console-read-only)"), false;
    }
    return true;
  };

  h.Get("/", [common](const httplib::Request&, httplib::Response& res) {
    common(res);
    res.set_content(kPageHtml, "text/html; charset=utf-8");
  });
  h.Get("/console.js", [common](const httplib::Request&, httplib::Response& res) {
    common(res);
    res.set_content(kPageJs, "text/javascript; charset=utf-8");
  });
  h.Get("/uplot/uPlot.iife.min.js", [this, common](const httplib::Request&, httplib::Response& res) {
    common(res);
    res.set_content(impl_->uplot_js, "text/javascript; charset=utf-8");
  });
  h.Get("/uplot/uPlot.min.css", [this, common](const httplib::Request&, httplib::Response& res) {
    common(res);
    res.set_content(impl_->uplot_css, "text/css; charset=utf-8");
  });
  h.Get("/favicon.ico", [](const httplib::Request&, httplib::Response& res) { res.status = 204; });

  h.Get("/api/meta", [this, api_ok, common](const httplib::Request& req, httplib::Response& res) {
    if (!api_ok(req, res, false)) return;
    nlohmann::json j;
    j["title"] = o_.title;
    j["signals"] = all_signals_;
    j["read_only"] = o_.read_only;
    nlohmann::json ps = nlohmann::json::array();
    {
      std::lock_guard lk(m_);
      for (const auto& p : o_.params)
        ps.push_back({{"name", p.name}, {"unit", p.unit}, {"doc", p.doc}, {"min", p.min}, {"max", p.max},
                      {"value", param_values_[p.name]}});
      std::size_t mem = 0;
      for (const auto& g : groups_) mem += g->dec.memory_bytes();
      j["memory_bytes"] = mem;
    }
    j["params"] = ps;
    common(res);
    res.set_content(j.dump(), "application/json");
  });

  // The decimated window, binary (little-endian): 64 bytes of header ("LSH1", u32 columns,
  // u32 signals, u32 0, f64 t_end, t0, column width, bucket width [s], samples, drops), then
  // per signal asked for (sig=i,j,..; default all) `columns` float32 minima, then maxima.
  // Columns lie on a fixed grid (Decimator::view_f32): from=J sends only the window's columns
  // from index J on (the page's incremental stream: J = its newest column, partial, minus a
  // margin), t0 / column width = the first one's index.
  h.Get("/api/frame", [this, api_ok, common](const httplib::Request& req, httplib::Response& res) {
    if (!api_ok(req, res, false)) return;
    double window = 10.0;
    std::size_t columns = 800;
    std::vector<std::size_t> sig;
    std::int64_t from = Decimator::kWholeWindow;
    try {
      if (req.has_param("from")) from = std::stoll(req.get_param_value("from"));
      if (req.has_param("window")) window = std::stod(req.get_param_value("window"));
      if (req.has_param("columns")) columns = std::stoul(req.get_param_value("columns"));
      if (req.has_param("sig")) {
        std::stringstream ss(req.get_param_value("sig"));
        for (std::string item; std::getline(ss, item, ',');)
          if (!item.empty()) sig.push_back(std::stoul(item));
      }
    } catch (const std::exception&) {
      res.status = 400;
      return;
    }
    if (!(window > 0.0) || !std::isfinite(window)) window = 10.0;
    window = std::clamp(window, 0.05, 36000.0);
    columns = std::clamp<std::size_t>(columns, 10, 4000);
    std::sort(sig.begin(), sig.end());
    sig.erase(std::unique(sig.begin(), sig.end()), sig.end());
    while (!sig.empty() && sig.back() >= all_signals_.size()) sig.pop_back();
    if (sig.empty())
      for (std::size_t i = 0; i < all_signals_.size(); ++i) sig.push_back(i);
    std::vector<float> mm, part;
    double t_end = 0, t0 = 0, col = 0, bucket = 0, samples = 0;
    std::size_t ncol = 0;
    {
      std::lock_guard lk(m_);
      for (const auto& g : groups_) t_end = std::max(t_end, g->dec.last_t());
      std::size_t first = 0, k = 0;
      for (const auto& g : groups_) {  // the groups hold consecutive signals; sig is sorted
        std::vector<std::size_t> local;
        for (; k < sig.size() && sig[k] < first + g->dec.config().signals; ++k) local.push_back(sig[k] - first);
        first += g->dec.config().signals;
        if (local.empty()) continue;
        ncol = g->dec.view_f32(t_end, window, columns, local, part, t0, col, bucket, from);
        mm.insert(mm.end(), part.begin(), part.end());
      }
      samples = static_cast<double>(groups_.front()->dec.samples());
      ++frames_served_;
    }
    static_assert(std::endian::native == std::endian::little, "the frame is written little-endian");
    std::string body(64 + mm.size() * sizeof(float), '\0');
    const std::uint32_t u[4] = {0x3148534Cu /* "LSH1" */, static_cast<std::uint32_t>(ncol),
                                static_cast<std::uint32_t>(sig.size()), 0};
    const double d[6] = {t_end, t0, col, bucket, samples, static_cast<double>(drops())};
    std::memcpy(body.data(), u, sizeof u);
    std::memcpy(body.data() + 16, d, sizeof d);
    if (!mm.empty()) std::memcpy(body.data() + 64, mm.data(), mm.size() * sizeof(float));
    common(res);
    res.set_content(std::move(body), "application/octet-stream");
  });

  // Status, events and estimates newer than the ids the page has (since, est_since), params.
  h.Get("/api/status", [this, api_ok, common](const httplib::Request& req, httplib::Response& res) {
    if (!api_ok(req, res, false)) return;
    std::uint64_t since = 0, est_since = 0;
    try {
      if (req.has_param("since")) since = std::stoull(req.get_param_value("since"));
      if (req.has_param("est_since")) est_since = std::stoull(req.get_param_value("est_since"));
    } catch (const std::exception&) {
      res.status = 400;
      return;
    }
    nlohmann::json j;
    {
      std::lock_guard lk(m_);
      j["t_end"] = groups_.front()->dec.last_t();
      j["samples"] = groups_.front()->dec.samples();
      j["frames_served"] = frames_served_;
      j["status"] = status_;
      j["status_text"] = status_text_;
      nlohmann::json ev = nlohmann::json::array();
      for (const auto& e : events_)
        if (e.id > since) ev.push_back({{"id", e.id}, {"t", e.t_s}, {"kind", e.kind}, {"text", e.text}});
      j["events"] = ev;
      nlohmann::json es = nlohmann::json::array();
      const auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
      for (const auto& e : estimates_)
        if (e.id > est_since)
          es.push_back({{"id", e.id}, {"t", e.t_s}, {"name", e.name}, {"value", num(e.value)}, {"lo", num(e.lo)},
                        {"hi", num(e.hi)}, {"identified", e.identified}});
      j["estimates"] = es;
      nlohmann::json pv;
      for (const auto& [k, val] : param_values_) pv[k] = val;
      j["params"] = pv;
    }
    j["drops"] = drops();
    common(res);
    res.set_content(j.dump(), "application/json");
  });

  h.Post("/api/tune", [this, api_ok, common](const httplib::Request& req, httplib::Response& res) {
    if (!api_ok(req, res, true)) return;
    common(res);
    std::string name;
    double value = 0.0;
    try {
      const auto j = nlohmann::json::parse(req.body);
      name = j.at("name").get<std::string>();
      value = j.at("value").get<double>();
    } catch (const std::exception&) {
      res.status = 400;
      res.set_content(nlohmann::json{{"ok", false}, {"error", "body must be {\"name\": ..., \"value\": number}"}}.dump(),
                      "application/json");
      return;
    }
    bool known = false;
    for (const auto& p : o_.params) known = known || p.name == name;
    if (!known || !tuner_) {
      res.status = 404;
      res.set_content(nlohmann::json{{"ok", false}, {"error", "no tunable object " + name}}.dump(), "application/json");
      return;
    }
    TuneResult r;
    try {
      r = tuner_(name, value);
    } catch (const std::exception& e) {
      r.ok = false;
      r.error = e.what();
    }
    if (r.ok) set_param_value(name, r.readback);
    res.status = 200;  // handled: ok or the ECU's refusal (ok false, error)
    nlohmann::json out{{"ok", r.ok}, {"name", name}, {"error", r.error}};
    if (r.ok) out["readback"] = r.readback;
    res.set_content(out.dump(), "application/json");
  });

  h.set_tcp_nodelay(true);             // small answers go out at once (no Nagle / delayed-ACK wait)
  h.set_keep_alive_max_count(1000000);  // one connection for the page's stream of frames
  if (o_.port == 0) {
    port_ = h.bind_to_any_port(o_.bind);
    if (port_ <= 0) throw InputError("", 0, "--console-bind", "cannot bind " + o_.bind + " (any port)");
  } else {
    if (!h.bind_to_port(o_.bind, o_.port))
      throw InputError("", 0, "--console",
                       "cannot bind " + o_.bind + ":" + std::to_string(o_.port) + " (in use or not allowed)");
    port_ = o_.port;
  }
}

Server::~Server() { stop(); }

void Server::start() {
  if (started_) return;
  started_ = true;
  http_thread_ = std::thread([this] { impl_->http.listen_after_bind(); });
  drain_thread_ = std::thread([this] {
    Sample s;
    while (!stop_.load()) {
      {
        std::lock_guard lk(m_);
        for (auto& g : groups_)
          for (std::size_t i = 0; i < Feed::kCapacity && g->feed.pop(s); ++i)
            g->dec.add(s.t_s, std::span<const double>(s.values.data(), std::min<std::size_t>(s.count, kMaxSignals)));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
}

void Server::stop() {
  if (stop_.exchange(true)) return;
  impl_->http.stop();
  if (http_thread_.joinable()) http_thread_.join();
  if (drain_thread_.joinable()) drain_thread_.join();
}

Feed& Server::feed(std::size_t i) noexcept { return groups_[std::min(i, groups_.size() - 1)]->feed; }

std::uint64_t Server::drops() const noexcept {
  std::uint64_t n = 0;
  for (const auto& g : groups_) n += g->feed.drops();
  return n;
}

std::string Server::url() const {
  const std::string host = o_.bind.find(':') != std::string::npos ? "[" + o_.bind + "]" : o_.bind;
  return "http://" + host + ":" + std::to_string(port_) + "/?token=" + token_;
}

void Server::set_status(const std::string& key, double value) {
  std::lock_guard lk(m_);
  status_[key] = value;
}
void Server::set_statuses(const std::vector<std::pair<std::string, double>>& values) {
  std::lock_guard lk(m_);
  for (const auto& [k, v] : values) status_[k] = v;
}
void Server::set_status_text(const std::string& key, const std::string& value) {
  std::lock_guard lk(m_);
  status_text_[key] = value;
}
void Server::add_event(double t_s, const std::string& kind, const std::string& text) {
  std::lock_guard lk(m_);
  events_.push_back({next_event_++, t_s, kind, text});
  while (events_.size() > 1000) events_.pop_front();
}
void Server::add_estimate(double t_s, const std::string& name, double value, double lo, double hi, bool identified) {
  std::lock_guard lk(m_);
  estimates_.push_back({next_estimate_++, t_s, name, value, lo, hi, identified});
  while (estimates_.size() > 20000) estimates_.pop_front();
}
void Server::set_param_value(const std::string& name, double value) {
  std::lock_guard lk(m_);
  param_values_[name] = value;
}

}  // namespace lash::console
