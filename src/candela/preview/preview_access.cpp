#include "candela/preview/preview_access.h"

#include <httplib.h>
#include <sys/random.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "candela/base/error.h"

namespace candela {
namespace {

std::string lowercase(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

}  // namespace

std::string random_preview_token() {
  unsigned char bytes[24];
  size_t got = 0;
  while (got < sizeof(bytes)) {
    const ssize_t n = ::getrandom(bytes + got, sizeof(bytes) - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw InternalError(fmt::format("--preview: no random bytes from the OS: {}", std::strerror(errno)));
    got += size_t(n);
  }
  std::string token;
  for (unsigned char b : bytes) token += fmt::format("{:02x}", b);
  return token;
}

PreviewAccess::PreviewAccess(std::string token, std::string bound_host, int port, bool public_access)
    : token_(std::move(token)), bound_host_(lowercase(std::move(bound_host))), port_(port), public_access_(public_access) {}

bool PreviewAccess::host_allowed(const std::string& host_header) const {
  if (public_access_) return true;
  // "name", "name:port", "[v6]" or "[v6]:port".
  std::string name = lowercase(host_header), port;
  if (!name.empty() && name.front() == '[') {
    const size_t close = name.find(']');
    if (close == std::string::npos) return false;
    port = name.substr(close + 1);
    name = name.substr(1, close - 1);
    if (!port.empty() && port.front() != ':') return false;
    if (!port.empty()) port.erase(0, 1);
  } else if (const size_t colon = name.find(':'); colon != std::string::npos) {
    port = name.substr(colon + 1);
    name.resize(colon);
  }
  int given_port = 80;
  if (!port.empty()) {
    auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), given_port);
    if (ec != std::errc() || end != port.data() + port.size()) return false;
  }
  if (given_port != port_) return false;
  return name == bound_host_ || name == "localhost" || name == "127.0.0.1" || name == "::1";
}

bool PreviewAccess::token_matches(const std::string& given) const {
  // Compared in time independent of where they differ, so that timing reveals nothing of the token.
  if (given.size() != token_.size()) return false;
  unsigned char diff = 0;
  for (size_t i = 0; i < given.size(); ++i) diff |= static_cast<unsigned char>(given[i] ^ token_[i]);
  return diff == 0;
}

std::optional<std::string> PreviewAccess::refusal(const httplib::Request& req) const {
  if (req.get_header_value_count("Host") != 1 || !host_allowed(req.get_header_value("Host")))
    return "the Host header does not name this server (open the address candela printed)";
  const std::string given =
      req.has_header("X-Candela-Token") ? req.get_header_value("X-Candela-Token") : req.get_param_value("token");
  if (!token_matches(given)) return "no valid token (open the address candela printed, with its ?token=...)";
  // A browser says where a request comes from; the page's own requests come from this origin.
  const std::string origin = "http://" + lowercase(req.get_header_value("Host"));
  if (req.has_header("Origin") && lowercase(req.get_header_value("Origin")) != origin)
    return "a request from another origin";
  const bool changes_state = req.method != "GET" && req.method != "HEAD";
  if (changes_state && !req.has_header("Origin") && req.has_header("Referer") &&
      lowercase(req.get_header_value("Referer")).rfind(origin + "/", 0) != 0)
    return "a request from another page";
  return std::nullopt;
}

}  // namespace candela
