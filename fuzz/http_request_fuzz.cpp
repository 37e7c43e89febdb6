// libFuzzer target: the browser preview's HTTP request handling (preview/preview_server.h): httplib's
// request parser behind candela's byte and time limits (guarded_http_server.h), the token, Host and
// Origin checks (preview_access.h) and the handlers. The input is the bytes a client sends on one
// connection; "@TOKEN@" and "@PORT@" in it become this run's token and port, so that mutations reach
// the handlers behind the checks. The server must answer (or close) within its limits and never crash,
// hang or leak; the answer itself is read and dropped.
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <string>

#include "candela/film/film.h"
#include "candela/film/live_film.h"
#include "candela/preview/preview_server.h"

namespace {

struct Preview {
  Preview() : live(16, 12) {
    candela::Film film(16, 12);
    for (int y = 0; y < 12; ++y)
      for (int x = 0; x < 16; ++x) film.add_sample(x, y, candela::RGB(float(x), float(y), 1.0f), 1.0f);
    live.start("fuzz", 16, true, 0, 0.01);
    live.pass_done(film);
    // A short response time: an input that makes the server wait (a body it never gets) costs 0.2 s.
    candela::HttpLimits limits;
    limits.response_time = std::chrono::milliseconds(200);
    server = std::make_unique<candela::PreviewServer>(candela::parse_preview_address("127.0.0.1:0"), live,
                                                      [] {}, false, limits);
  }
  candela::LiveFilm live;
  std::unique_ptr<candela::PreviewServer> server;
};

std::string with_placeholders_filled(std::string text, const Preview& p) {
  for (auto [name, value] : {std::pair<std::string, std::string>{"@TOKEN@", p.server->token()},
                             {"@PORT@", std::to_string(p.server->port())}})
    for (size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + value.size()))
      text.replace(at, name.size(), value);
  return text;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Preview preview;
  if (size > 32 * 1024) return 0;  // more than the socket pair buffers without a reader
  const std::string request =
      with_placeholders_filled(std::string(reinterpret_cast<const char*>(data), size), preview);
  int ends[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM, 0, ends) != 0) std::abort();
  size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = ::send(ends[0], request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) std::abort();
    sent += size_t(n);
  }
  ::shutdown(ends[0], SHUT_WR);
  // Every answer fits the pair's buffer (the page is about 12 KB, the 16 x 12 image 3 KB), so it is
  // dropped with the pair unread.
  preview.server->serve_connection(ends[1]);
  ::close(ends[0]);
  return 0;
}
