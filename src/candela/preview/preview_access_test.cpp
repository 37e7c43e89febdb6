// Who may use the preview: the token, the Host header and the origin (preview_access.h), checked on
// requests as httplib parses them, and end to end on a running PreviewServer.
#include "candela/preview/preview_access.h"

#include <gtest/gtest.h>
#include <httplib.h>

#include <set>

#include "candela/preview/preview_server.h"

namespace candela {
namespace {

httplib::Request request(const std::string& method, const std::string& host, const std::string& token) {
  httplib::Request req;
  req.method = method;
  req.path = "/status";
  if (!host.empty()) req.set_header("Host", host);
  if (!token.empty()) req.params.emplace("token", token);
  return req;
}

TEST(PreviewAccess, TokensAre192RandomBitsInHex) {
  std::set<std::string> seen;
  for (int i = 0; i < 16; ++i) {
    const std::string t = random_preview_token();
    EXPECT_EQ(t.size(), 48u);
    EXPECT_EQ(t.find_first_not_of("0123456789abcdef"), std::string::npos) << t;
    seen.insert(t);
  }
  EXPECT_EQ(seen.size(), 16u);
}

TEST(PreviewAccess, NeedsTheTokenInTheQueryOrTheHeader) {
  const std::string token = random_preview_token();
  PreviewAccess access(token, "127.0.0.1", 8080, false);
  EXPECT_FALSE(access.refusal(request("GET", "127.0.0.1:8080", token)));
  httplib::Request by_header = request("GET", "127.0.0.1:8080", "");
  by_header.set_header("X-Candela-Token", token);
  EXPECT_FALSE(access.refusal(by_header));
  for (const std::string& wrong : {std::string(), token.substr(0, 47), token + "0", std::string(48, '0')}) {
    auto why = access.refusal(request("GET", "127.0.0.1:8080", wrong));
    ASSERT_TRUE(why) << "'" << wrong << "'";
    EXPECT_NE(why->find("token"), std::string::npos) << *why;
  }
}

TEST(PreviewAccess, HostMustNameThisServerUnlessPublic) {
  const std::string token = random_preview_token();
  PreviewAccess access(token, "127.0.0.1", 8080, false);
  for (const char* ok : {"127.0.0.1:8080", "localhost:8080", "LocalHost:8080", "[::1]:8080"})
    EXPECT_FALSE(access.refusal(request("GET", ok, token))) << ok;
  // DNS rebinding: a page of evil.example whose name now resolves to 127.0.0.1 sends its own name.
  for (const char* bad : {"evil.example:8080", "evil.example", "127.0.0.1:8081", "127.0.0.1", "localhost:80",
                          "127.0.0.1:8080x", "[::1", "", "127.0.0.2:8080"}) {
    auto why = access.refusal(request("GET", bad, token));
    ASSERT_TRUE(why) << "'" << bad << "'";
    EXPECT_NE(why->find("Host"), std::string::npos) << *why;
  }
  httplib::Request two_hosts = request("GET", "127.0.0.1:8080", token);
  two_hosts.headers.emplace("Host", "evil.example");
  EXPECT_TRUE(access.refusal(two_hosts));
  // A server bound to one loopback address also answers to that address.
  EXPECT_FALSE(PreviewAccess(token, "127.0.0.2", 8080, false).refusal(request("GET", "127.0.0.2:8080", token)));
  // Public: reached by any of the machine's names; the token still guards.
  PreviewAccess open(token, "0.0.0.0", 8080, true);
  EXPECT_FALSE(open.refusal(request("GET", "render-node-7.example:8080", token)));
  EXPECT_TRUE(open.refusal(request("GET", "render-node-7.example:8080", "")));
}

TEST(PreviewAccess, RefusesRequestsFromOtherOrigins) {
  const std::string token = random_preview_token();
  PreviewAccess access(token, "127.0.0.1", 8080, false);
  httplib::Request same = request("POST", "127.0.0.1:8080", token);
  same.set_header("Origin", "http://127.0.0.1:8080");
  same.set_header("Referer", "http://127.0.0.1:8080/?token=" + token);
  EXPECT_FALSE(access.refusal(same));
  EXPECT_FALSE(access.refusal(request("POST", "127.0.0.1:8080", token))) << "a script sends neither";
  for (const char* origin : {"http://evil.example", "null", "http://127.0.0.1:8081", "https://127.0.0.1:8080"}) {
    httplib::Request cross = request("POST", "127.0.0.1:8080", token);
    cross.set_header("Origin", origin);
    EXPECT_TRUE(access.refusal(cross)) << origin;
    cross.method = "GET";
    EXPECT_TRUE(access.refusal(cross)) << "GET from " << origin;
  }
  httplib::Request referred = request("POST", "127.0.0.1:8080", token);
  referred.set_header("Referer", "http://evil.example/page");
  EXPECT_TRUE(access.refusal(referred));
  // A link from another site to the page itself is fine: GET changes nothing.
  referred.method = "GET";
  EXPECT_FALSE(access.refusal(referred));
}

// End to end: refused requests change nothing, the render goes on.
TEST(PreviewServer, RefusesRequestsWithoutTokenWithAForeignHostOrFromAnotherOrigin) {
  LiveFilm live(8, 8);
  live.start("test", 16, false, 0, 0);
  int stops = 0;
  PreviewServer server(parse_preview_address("127.0.0.1:0"), live, [&] { ++stops; });
  const std::string host = "127.0.0.1:" + std::to_string(server.port());
  httplib::Client client("127.0.0.1", server.port());
  auto expect_refused = [&](const char* what, const std::string& path, httplib::Headers headers, bool post) {
    auto res = post ? client.Post(path.c_str(), headers, "", "text/plain") : client.Get(path.c_str(), headers);
    ASSERT_TRUE(res) << what;
    EXPECT_EQ(res->status, 403) << what;
    EXPECT_EQ(res->body.find(server.token()), std::string::npos) << "the answer never shows the token";
  };
  const std::string t = "?token=" + server.token();
  expect_refused("the page without the token", "/", {}, false);
  expect_refused("the image without the token", "/image", {}, false);
  expect_refused("stop without the token", "/stop", {}, true);
  expect_refused("a wrong token", "/status?token=" + std::string(48, 'a'), {}, false);
  expect_refused("a foreign Host", "/status" + t, {{"Host", "evil.example:" + std::to_string(server.port())}}, false);
  expect_refused("a cross-origin stop", "/stop" + t, {{"Origin", "http://evil.example"}}, true);
  expect_refused("a stop from another page", "/stop" + t, {{"Referer", "http://evil.example/x"}}, true);
  auto get_stop = client.Get(("/stop" + t).c_str());
  ASSERT_TRUE(get_stop);
  EXPECT_NE(get_stop->status, 200) << "stop is POST only";
  EXPECT_EQ(stops, 0);
  EXPECT_EQ(live.status().state, LiveState::Rendering);

  auto page = client.Get(("/" + t).c_str());
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_EQ(page->get_header_value("X-Frame-Options"), "DENY");
  auto stop = client.Post(("/stop" + t).c_str(), {{"Origin", "http://" + host}}, "", "text/plain");
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->status, 200);
  EXPECT_EQ(stops, 1);
}

}  // namespace
}  // namespace candela
