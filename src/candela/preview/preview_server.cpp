#include "candela/preview/preview_server.h"

#include <httplib.h>
#include <pthread.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "candela/base/error.h"

namespace candela {
namespace {

int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

const char* state_name(LiveState s) {
  switch (s) {
    case LiveState::Waiting: return "waiting";
    case LiveState::Rendering: return "rendering";
    case LiveState::Finished: return "finished";
    case LiveState::Stopped: return "stopped";
  }
  return "unknown";
}

nlohmann::json status_json(const LiveStatus& s, bool stop_requested) {
  nlohmann::json errors = nlohmann::json::array();
  for (const ErrorPoint& p : s.error_history) errors.push_back({p.seconds, p.relmse, p.low, p.high, p.mean_spp});
  return {{"state", stop_requested && s.state == LiveState::Rendering ? "stopping" : state_name(s.state)},
          {"description", s.description},
          {"width", s.width},
          {"height", s.height},
          {"seconds", s.seconds},
          {"fraction", s.fraction},
          {"eta", s.eta_seconds >= 0 ? nlohmann::json(s.eta_seconds) : nlohmann::json(nullptr)},
          {"mean_spp", s.mean_spp},
          {"min_spp", s.min_spp},
          {"max_spp", s.max_spp},
          {"planned_spp", s.planned_spp},
          {"adaptive", s.adaptive},
          {"error_from_halves", s.halves},
          {"time_limit", s.time_limit_seconds},
          {"target_error", s.target_error},
          {"version", s.version},
          {"errors", errors}};
}

// The snapshot as float32 RGBA (A = samples), averaged down by `factor` in each direction.
std::string image_bytes(const LiveSnapshot& snap, int factor, int& out_w, int& out_h) {
  out_w = (snap.width + factor - 1) / factor;
  out_h = (snap.height + factor - 1) / factor;
  std::vector<float> out(size_t(out_w) * size_t(out_h) * 4, 0.0f);
  for (int oy = 0; oy < out_h; ++oy)
    for (int ox = 0; ox < out_w; ++ox) {
      double sum[4] = {0, 0, 0, 0};
      int n = 0;
      for (int y = oy * factor; y < std::min(snap.height, (oy + 1) * factor); ++y)
        for (int x = ox * factor; x < std::min(snap.width, (ox + 1) * factor); ++x, ++n) {
          const size_t i = size_t(y) * size_t(snap.width) + size_t(x);
          for (int c = 0; c < 3; ++c) sum[c] += snap.rgb[3 * i + size_t(c)];
          sum[3] += snap.spp[i];
        }
      float* o = &out[(size_t(oy) * size_t(out_w) + size_t(ox)) * 4];
      for (int c = 0; c < 4; ++c) o[c] = n ? float(sum[c] / n) : 0.0f;
    }
  static_assert(std::endian::native == std::endian::little, "the page reads little-endian floats");
  return std::string(reinterpret_cast<const char*>(out.data()), out.size() * sizeof(float));
}

}  // namespace

bool PreviewAddress::loopback() const {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

PreviewAddress parse_preview_address(const std::string& text) {
  PreviewAddress a;
  std::string port = text;
  if (size_t colon = text.rfind(':'); colon != std::string::npos) {
    a.host = text.substr(0, colon);
    port = text.substr(colon + 1);
    if (a.host.size() >= 2 && a.host.front() == '[' && a.host.back() == ']') a.host = a.host.substr(1, a.host.size() - 2);
    if (a.host.empty()) throw UsageError(fmt::format("--preview '{}': expected [HOST:]PORT, and the host before ':' is empty", text));
  }
  const char* end = port.data() + port.size();
  auto [ptr, ec] = std::from_chars(port.data(), end, a.port);
  if (port.empty() || ec != std::errc() || ptr != end || a.port < 0 || a.port > 65535)
    throw UsageError(
        fmt::format("--preview '{}': expected [HOST:]PORT with PORT from 0 to 65535 (0 = any free port)", text));
  return a;
}

PreviewServer::PreviewServer(const PreviewAddress& address, const LiveFilm& live, std::function<void()> on_stop,
                             bool public_access, const HttpLimits& limits)
    : live_(live),
      on_stop_(std::move(on_stop)),
      access_(random_preview_token(), address.host, address.port, public_access),
      server_(std::make_unique<GuardedHttpServer>(limits)),
      host_(address.host) {
  GuardedHttpServer& server = *server_;
  // Refuse what may not be served before any handler runs (preview_access.h); every answer forbids
  // framing (a page elsewhere cannot overlay the stop button) and sends the token's URL to no other site.
  server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    res.set_header("X-Frame-Options", "DENY");
    res.set_header("Content-Security-Policy", "frame-ancestors 'none'");
    res.set_header("Referrer-Policy", "same-origin");
    res.set_header("X-Content-Type-Options", "nosniff");
    if (std::optional<std::string> why = access_.refusal(req)) {
      res.status = 403;
      res.set_content("candela preview: refused: " + *why + "\n", "text/plain; charset=utf-8");
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  // One cached copy of the image shared by every viewer: copied from the live film only when it changed.
  auto cache = std::make_shared<std::pair<std::mutex, LiveSnapshot>>();
  auto stop_requested = std::make_shared<std::atomic<bool>>(false);
  auto touch = [this] { last_request_ms_.store(now_ms()); };

  server.Get("/", [touch](const httplib::Request&, httplib::Response& res) {
    touch();
    res.set_header("Cache-Control", "no-store");
    res.set_content(std::string(preview_page_html()), "text/html; charset=utf-8");
  });
  server.Get("/status", [this, touch, stop_requested](const httplib::Request&, httplib::Response& res) {
    touch();
    LiveStatus s = live_.status();
    if (s.state == LiveState::Finished || s.state == LiveState::Stopped) final_state_served_.store(true);
    res.set_header("Cache-Control", "no-store");
    res.set_content(status_json(s, stop_requested->load()).dump(), "application/json");
  });
  server.Get("/image", [this, touch, cache](const httplib::Request& req, httplib::Response& res) {
    touch();
    int max_size = 1280;
    if (req.has_param("max")) {
      const std::string v = req.get_param_value("max");
      std::from_chars(v.data(), v.data() + v.size(), max_size);
      max_size = std::clamp(max_size, 16, 16384);
    }
    std::string body;
    int w = 0, h = 0;
    uint64_t version = 0;
    {
      std::lock_guard lock(cache->first);
      live_.snapshot(cache->second);
      const LiveSnapshot& snap = cache->second;
      const int factor = std::max(1, (std::max(snap.width, snap.height) + max_size - 1) / max_size);
      body = image_bytes(snap, factor, w, h);
      version = snap.version;
    }
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Width", std::to_string(w));
    res.set_header("X-Height", std::to_string(h));
    res.set_header("X-Version", std::to_string(version));
    res.set_content(std::move(body), "application/octet-stream");
  });
  server.Post("/stop", [this, touch, stop_requested](const httplib::Request&, httplib::Response& res) {
    touch();
    if (!stop_requested->exchange(true) && on_stop_) on_stop_();
    res.set_content(R"({"stopping":true})", "application/json");
  });
  // SO_REUSEADDR (a port freed by a finished render is free at once) but not cpp-httplib's default
  // SO_REUSEPORT, under which a second render on the same port would bind too and share its visitors.
  server.set_socket_options([](int sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, reinterpret_cast<const void*>(&yes), sizeof(yes));
  });

  port_ = server.bind(address.host, address.port);
  if (port_ <= 0)
    throw UsageError(fmt::format("--preview: cannot listen on {}:{} (address in use or not on this machine)",
                                         address.host, address.port));
  access_.set_port(port_);
  thread_ = std::thread([this] {
    ::pthread_setname_np(::pthread_self(), "http-accept");
    server_->listen_after_bind();
  });
  // stop() only stops a server that is running: wait for it, so that destroying this at once cannot hang.
  for (int ms = 0; ms < 5000 && !server_->is_running(); ++ms) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

std::string PreviewServer::url() const {
  const bool v6 = host_.find(':') != std::string::npos;
  return fmt::format("http://{}{}{}:{}/?token={}", v6 ? "[" : "", host_, v6 ? "]" : "", port_, access_.token());
}

PreviewServer::~PreviewServer() {
  // A page that polled in the last few seconds is watching: give it time to see the end.
  const int64_t start = now_ms();
  while (!final_state_served_.load() && now_ms() - last_request_ms_.load() < 3000 && now_ms() - start < 1500)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  server_->stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace candela
