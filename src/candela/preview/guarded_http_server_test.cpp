// The preview's transport under slow and oversized clients (guarded_http_server.h): loopback only,
// every loop bounded in count and time.
#include "candela/preview/guarded_http_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace candela {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// A server answering GET /hello on a free loopback port, its accept loop on a thread of its own.
struct TestServer {
  explicit TestServer(const HttpLimits& limits) : server(limits) {
    server.Get("/hello", [](const httplib::Request&, httplib::Response& res) { res.set_content("hi", "text/plain"); });
    server.Post("/hello", [](const httplib::Request&, httplib::Response& res) { res.set_content("posted", "text/plain"); });
    port = server.bind("127.0.0.1", 0);
    thread = std::thread([this] { server.listen_after_bind(); });
    while (!server.is_running()) std::this_thread::sleep_for(1ms);
  }
  ~TestServer() {
    server.stop();
    thread.join();
  }
  GuardedHttpServer server;
  int port = 0;
  std::thread thread;
};

int connect_to(int port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(uint16_t(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  EXPECT_EQ(::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
  return s;
}

void send_all(int s, const std::string& bytes) {
  size_t at = 0;
  while (at < bytes.size()) {
    const ssize_t n = ::send(s, bytes.data() + at, bytes.size() - at, MSG_NOSIGNAL);
    if (n <= 0) return;
    at += size_t(n);
  }
}

// Everything the server sends until it closes (or `limit` passes).
std::string read_answer(int s, std::chrono::milliseconds limit = 5000ms) {
  std::string out;
  const auto end = Clock::now() + limit;
  char buf[4096];
  while (Clock::now() < end) {
    pollfd p{s, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    const ssize_t n = ::recv(s, buf, sizeof(buf), 0);
    if (n <= 0) break;
    out.append(buf, size_t(n));
  }
  return out;
}

std::string status_line(const std::string& answer) { return answer.substr(0, answer.find("\r\n")); }

TEST(GuardedHttpServer, AnswersOneRequestPerConnection) {
  TestServer t({});
  const int s = connect_to(t.port);
  send_all(s, "GET /hello HTTP/1.1\r\nHost: x\r\n\r\n");
  const std::string answer = read_answer(s);
  ::close(s);
  EXPECT_EQ(status_line(answer), "HTTP/1.1 200 OK");
  EXPECT_NE(answer.find("Connection: close"), std::string::npos);
  EXPECT_EQ(answer.substr(answer.size() - 2), "hi");
}

TEST(GuardedHttpServer, RefusesOversizedHeadersAndBodies) {
  HttpLimits limits;
  limits.max_header_bytes = 4096;
  TestServer t(limits);
  // Many small header lines: httplib bounds each line, not their number.
  std::string many = "GET /hello HTTP/1.1\r\nHost: x\r\n";
  for (int i = 0; i < 1000; ++i) many += "X-Filler-" + std::to_string(i) + ": y\r\n";
  int s = connect_to(t.port);
  send_all(s, many);
  EXPECT_EQ(status_line(read_answer(s)), "HTTP/1.1 431 Request Header Fields Too Large");
  ::close(s);
  s = connect_to(t.port);
  send_all(s, "POST /hello HTTP/1.1\r\nHost: x\r\nContent-Length: 100000\r\n\r\n" + std::string(100000, 'z'));
  EXPECT_EQ(status_line(read_answer(s)), "HTTP/1.1 413 Payload Too Large");
  ::close(s);
}

TEST(GuardedHttpServer, TooManyWaitingConnectionsAreTurnedAwayAtOnce) {
  HttpLimits limits;
  limits.max_waiting = 4;
  TestServer t(limits);
  std::vector<int> idle;
  for (int i = 0; i < 4; ++i) idle.push_back(connect_to(t.port));
  std::this_thread::sleep_for(200ms);  // the four are in the gate
  const int extra = connect_to(t.port);
  EXPECT_EQ(status_line(read_answer(extra, 2000ms)), "HTTP/1.1 503 Service Unavailable");
  ::close(extra);
  for (int s : idle) ::close(s);
}

// Slowloris: 200 clients that send a byte now and then never complete a request. They are closed
// after header_time without taking a worker, and a client with a whole request is answered meanwhile.
TEST(GuardedHttpServer, SlowClientsHoldNoWorkerAndAreClosedOnTime) {
  HttpLimits limits;
  limits.header_time = 1000ms;
  TestServer t(limits);
  std::vector<int> slow;
  for (int i = 0; i < 200; ++i) {
    slow.push_back(connect_to(t.port));
    send_all(slow.back(), "GET /hello HTTP/1.1\r\n");
  }
  const auto start = Clock::now();
  int answered = 0;
  std::chrono::milliseconds slowest{0};
  for (int round = 0; round < 10; ++round) {
    for (size_t i = 0; i < slow.size(); i += 7) send_all(slow[i], "X");  // a trickle
    const auto asked = Clock::now();
    const int s = connect_to(t.port);
    send_all(s, "GET /hello HTTP/1.1\r\nHost: x\r\n\r\n");
    if (status_line(read_answer(s, 3000ms)) == "HTTP/1.1 200 OK") ++answered;
    slowest = std::max(slowest, std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - asked));
    ::close(s);
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_EQ(answered, 10);
  EXPECT_LT(slowest.count(), 500) << "a whole request waits behind no slow client";
  // Every slow client is closed with 408 by header_time (plus the gate's poll), none answered 200.
  int timed_out = 0;
  for (int s : slow) {
    const std::string answer = read_answer(s, 3000ms);
    if (status_line(answer) == "HTTP/1.1 408 Request Timeout") ++timed_out;
    ::close(s);
  }
  EXPECT_EQ(timed_out, 200);
  EXPECT_LT(Clock::now() - start, 8s);
}

// A client that asks for a large answer and never reads it holds a worker for response_time at most.
TEST(GuardedHttpServer, AnswerToAClientThatDoesNotReadIsCutAtTheDeadline) {
  HttpLimits limits;
  limits.workers = 1;
  limits.response_time = 1000ms;
  TestServer t(limits);
  t.server.Get("/big", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(std::string(64 << 20, 'b'), "application/octet-stream");
  });
  const int reader_that_never_reads = connect_to(t.port);
  int small = 1024;
  ::setsockopt(reader_that_never_reads, SOL_SOCKET, SO_RCVBUF, &small, sizeof(small));
  send_all(reader_that_never_reads, "GET /big HTTP/1.1\r\nHost: x\r\n\r\n");
  std::this_thread::sleep_for(200ms);
  const auto asked = Clock::now();
  const int s = connect_to(t.port);
  send_all(s, "GET /hello HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_EQ(status_line(read_answer(s, 5000ms)), "HTTP/1.1 200 OK");
  const auto waited = Clock::now() - asked;
  EXPECT_LT(waited, 3s) << "the one worker was freed at the deadline";
  ::close(s);
  ::close(reader_that_never_reads);
}

}  // namespace
}  // namespace candela
