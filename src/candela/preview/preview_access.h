#pragma once
// Who may use the browser preview (docs/preview.md, "Safety"). On a shared workstation or a cluster's
// login node every local user can reach a loopback port, and every web page the user visits can make
// the user's browser send requests to it. So, as Jupyter does:
//   - every request carries the run's token, 192 random bits from the OS, printed in the page's URL
//     (`?token=...`; the page sends it back in the X-Candela-Token header);
//   - the Host header names this server (the bound address, localhost, 127.0.0.1 or [::1]) with its
//     port: a page of another site that rebinds its DNS name to 127.0.0.1 sends its own name and is
//     refused. With --preview-public the server is reached by whatever name the machine has, so any
//     host is taken (the token still guards);
//   - a request a browser marks as coming from another origin (Origin, or for POST the Referer) is
//     refused, and the state-changing request, POST /stop, is POST only.
#include <optional>
#include <string>

namespace httplib {
struct Request;
}

namespace candela {

// 192 bits from the OS's random source (getrandom), as 48 hexadecimal digits. Throws
// InternalError if the OS has none to give.
std::string random_preview_token();

class PreviewAccess {
 public:
  // `bound_host` as given to --preview ("127.0.0.1", "localhost", "::1", "0.0.0.0", ...).
  PreviewAccess(std::string token, std::string bound_host, int port, bool public_access);

  // Why the request may not be served (a sentence for the 403 answer), or nothing when it may.
  std::optional<std::string> refusal(const httplib::Request& req) const;

  const std::string& token() const { return token_; }
  void set_port(int port) { port_ = port; }

 private:
  bool host_allowed(const std::string& host_header) const;
  bool token_matches(const std::string& given) const;

  std::string token_;
  std::string bound_host_;
  int port_;
  bool public_access_;
};

}  // namespace candela
