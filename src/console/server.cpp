#include "lash/console/server.hpp"

#include <sys/random.h>

#include <cerrno>
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

struct Server::Impl {
  httplib::Server http;
  std::string uplot_js, uplot_css;
};

Server::Server(ConsoleOptions options, Tuner tuner)
    : impl_(std::make_unique<Impl>()),
      o_(std::move(options)),
      tuner_(std::move(tuner)),
      dec_([&] {
        o_.validate();
        DecimatorConfig d = o_.decimation;
        d.signals = o_.signals.size();
        return d;
      }()) {
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
    j["signals"] = o_.signals;
    j["read_only"] = o_.read_only;
    nlohmann::json ps = nlohmann::json::array();
    {
      std::lock_guard lk(m_);
      for (const auto& p : o_.params)
        ps.push_back({{"name", p.name}, {"unit", p.unit}, {"doc", p.doc}, {"min", p.min}, {"max", p.max},
                      {"value", param_values_[p.name]}});
      j["memory_bytes"] = dec_.memory_bytes();
    }
    j["params"] = ps;
    common(res);
    res.set_content(j.dump(), "application/json");
  });

  h.Get("/api/data", [this, api_ok, common](const httplib::Request& req, httplib::Response& res) {
    if (!api_ok(req, res, false)) return;
    double window = 10.0;
    std::size_t columns = 800;
    std::uint64_t since = 0;
    try {
      if (req.has_param("window")) window = std::stod(req.get_param_value("window"));
      if (req.has_param("columns")) columns = std::stoul(req.get_param_value("columns"));
      if (req.has_param("since")) since = std::stoull(req.get_param_value("since"));
    } catch (const std::exception&) {
      res.status = 400;
      return;
    }
    window = std::clamp(window, 0.05, 36000.0);
    columns = std::clamp<std::size_t>(columns, 10, 4000);
    nlohmann::json j;
    {
      std::lock_guard lk(m_);
      const double t_end = dec_.last_t();
      const DecimatedView v = dec_.view(t_end, window, columns);
      j["t_end"] = t_end;
      j["bucket_s"] = v.bucket_s;
      j["t"] = v.t_s;
      j["min"] = v.min;
      j["max"] = v.max;
      j["samples"] = dec_.samples();
      j["status"] = status_;
      j["status_text"] = status_text_;
      nlohmann::json ev = nlohmann::json::array();
      for (const auto& e : events_)
        if (e.id > since) ev.push_back({{"id", e.id}, {"t", e.t_s}, {"kind", e.kind}, {"text", e.text}});
      j["events"] = ev;
      nlohmann::json pv;
      for (const auto& [k, val] : param_values_) pv[k] = val;
      j["params"] = pv;
    }
    j["drops"] = feed_.drops();
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
        for (std::size_t i = 0; i < Feed::kCapacity && feed_.pop(s); ++i)
          dec_.add(s.t_s, std::span<const double>(s.values.data(), std::min<std::size_t>(s.count, kMaxSignals)));
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

std::string Server::url() const {
  const std::string host = o_.bind.find(':') != std::string::npos ? "[" + o_.bind + "]" : o_.bind;
  return "http://" + host + ":" + std::to_string(port_) + "/?token=" + token_;
}

void Server::set_status(const std::string& key, double value) {
  std::lock_guard lk(m_);
  status_[key] = value;
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
void Server::set_param_value(const std::string& name, double value) {
  std::lock_guard lk(m_);
  param_values_[name] = value;
}

}  // namespace lash::console
