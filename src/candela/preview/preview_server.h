#pragma once
// The browser preview (`candela render --preview [HOST:]PORT`): an HTTP server, on its own threads,
// that serves one page (preview_page.html, compiled in) showing the render as it converges, and the
// data the page polls:
//   GET  /            the page
//   GET  /status      JSON: state, spp, progress, ETA, the convergence curve (film/live_film.h)
//   GET  /image       the image as float32 RGBA, little-endian, row-major, top row first (A = the
//                     pixel's sample count); headers X-Width, X-Height, X-Version. Images wider or
//                     taller than `max` (query parameter, default 1280) are averaged down by an
//                     integer factor, so a 4K render costs a viewer 8 MB a frame, not 130.
//   POST /stop        stops the render as SIGINT does (the image so far is written)
// Every request must carry the run's token and name this server in its Host header, and a browser's
// request from another origin is refused (preview_access.h); the transport bounds connections, sizes
// and times so that slow or hostile clients cannot hold the render's machine (guarded_http_server.h).
// The server is cpp-httplib (Debian's libcpp-httplib-dev): a maintained library that serves HTTP/1.1
// from a thread pool in a few lines, with no event loop to drive and nothing else to link; the render
// threads never wait for it (viewers copy the live film under its lock, which the render holds for one
// tile's means at a time). Any number of browsers can watch; a viewer that disconnects changes nothing.
// By default the server listens on the loopback interface only.
#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <thread>

#include "candela/film/live_film.h"
#include "candela/preview/guarded_http_server.h"
#include "candela/preview/preview_access.h"

namespace candela {

// "[HOST:]PORT": the host (default 127.0.0.1) and port (0 = any free port). Throws
// UsageError with a message naming `text` when it is malformed.
struct PreviewAddress {
  std::string host = "127.0.0.1";
  int port = 0;
  // Whether the host is reachable only from this machine (127.x.x.x, ::1, localhost).
  bool loopback() const;
};
PreviewAddress parse_preview_address(const std::string& text);

// The page (generated from preview_page.html by CMake).
std::string_view preview_page_html();

class PreviewServer {
 public:
  // Starts serving `live` at `address` (throws UsageError if it cannot bind). `on_stop` is
  // called (from a server thread) when a viewer presses stop. `public_access` (--preview-public): any
  // Host header is taken, for an address other machines reach by the machine's own names.
  PreviewServer(const PreviewAddress& address, const LiveFilm& live, std::function<void()> on_stop,
                bool public_access = false, const HttpLimits& limits = {});
  // Keeps serving for up to a second and a half after the render's end so that the pages watching
  // see its final state, then stops.
  ~PreviewServer();
  PreviewServer(const PreviewServer&) = delete;
  PreviewServer& operator=(const PreviewServer&) = delete;

  int port() const { return port_; }
  const std::string& token() const { return access_.token(); }
  // The page's address with the token: http://HOST:PORT/?token=...
  std::string url() const;
  // Answers the request on connected socket `sock` on this thread, as a connection the server
  // accepted is answered, and closes it: for the HTTP fuzz target (fuzz/http_request_fuzz.cpp).
  void serve_connection(int sock) { server_->serve(sock); }

 private:
  const LiveFilm& live_;
  std::function<void()> on_stop_;
  PreviewAccess access_;
  std::unique_ptr<GuardedHttpServer> server_;
  std::thread thread_;
  std::string host_;
  int port_ = 0;
  std::atomic<bool> final_state_served_{false};
  std::atomic<int64_t> last_request_ms_{0};
};

}  // namespace candela
