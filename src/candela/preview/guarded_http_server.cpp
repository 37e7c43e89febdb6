#include "candela/preview/guarded_http_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "candela/base/error.h"

namespace candela {
namespace {

using Clock = std::chrono::steady_clock;

int remaining_ms(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left <= 0 ? 0 : int(std::min<int64_t>(left, 1000000));
}

bool retry(int error) { return error == EAGAIN || error == EWOULDBLOCK || error == EINTR; }

// Waits until `sock` is ready for `events` or the deadline passes; false on time-out or error.
bool wait_for(int sock, short events, Clock::time_point deadline) {
  for (;;) {
    const int ms = remaining_ms(deadline);
    if (ms == 0) return false;
    pollfd p{sock, events, 0};
    const int r = ::poll(&p, 1, ms);
    if (r > 0) return true;
    if (r == 0 || errno != EINTR) return false;
  }
}

void address_of(int sock, bool peer, std::string& ip, int& port) {
  sockaddr_storage addr{};
  socklen_t len = sizeof(addr);
  if ((peer ? ::getpeername(sock, reinterpret_cast<sockaddr*>(&addr), &len)
            : ::getsockname(sock, reinterpret_cast<sockaddr*>(&addr), &len)) != 0)
    return;
  char text[INET6_ADDRSTRLEN] = {};
  if (addr.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&addr);
    ::inet_ntop(AF_INET, &a->sin_addr, text, sizeof(text));
    port = ntohs(a->sin_port);
  } else if (addr.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&addr);
    ::inet_ntop(AF_INET6, &a->sin6_addr, text, sizeof(text));
    port = ntohs(a->sin6_port);
  }
  ip = text;
}

// The request's bytes as httplib reads them: first those the gate already received, then the socket's,
// never more than `budget` in all and never past the deadline (a read or write then fails, and httplib
// gives up on the request).
class BoundedSocketStream : public httplib::Stream {
 public:
  BoundedSocketStream(int sock, std::string received, size_t budget, Clock::time_point deadline)
      : sock_(sock), received_(std::move(received)), budget_(budget), deadline_(deadline) {}

  bool is_readable() const override { return at_ < received_.size() || wait_for(sock_, POLLIN, deadline_); }
  bool is_writable() const override { return wait_for(sock_, POLLOUT, deadline_); }

  ssize_t read(char* ptr, size_t size) override {
    if (at_ < received_.size()) {
      const size_t n = std::min(size, received_.size() - at_);
      std::memcpy(ptr, received_.data() + at_, n);
      at_ += n;
      return ssize_t(n);
    }
    if (read_ >= budget_) return -1;
    for (;;) {
      if (!wait_for(sock_, POLLIN, deadline_)) return -1;
      const ssize_t n = ::recv(sock_, ptr, std::min(size, budget_ - read_), MSG_DONTWAIT);
      if (n >= 0) {
        read_ += size_t(n);
        return n;
      }
      if (!retry(errno)) return -1;
    }
  }

  ssize_t write(const char* ptr, size_t size) override {
    for (;;) {
      if (!wait_for(sock_, POLLOUT, deadline_)) return -1;
      const ssize_t n = ::send(sock_, ptr, size, MSG_DONTWAIT | MSG_NOSIGNAL);
      if (n >= 0 || !retry(errno)) return n;
    }
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override { address_of(sock_, true, ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { address_of(sock_, false, ip, port); }
  int socket() const override { return sock_; }

 private:
  int sock_;
  std::string received_;
  size_t at_ = 0;
  size_t budget_;
  size_t read_ = 0;
  Clock::time_point deadline_;
};

// httplib's accept loop hands each connection to its task queue; this one runs the hand-off at once on
// the accept thread, where it only puts the connection in the gate.
class InlineTaskQueue : public httplib::TaskQueue {
 public:
  void enqueue(std::function<void()> fn) override { fn(); }
  void shutdown() override {}
};

// The end of a request's headers: an empty line (httplib also accepts bare "\n" line ends).
bool headers_complete(const std::string& bytes) {
  return bytes.find("\r\n\r\n") != std::string::npos || bytes.find("\n\n") != std::string::npos;
}

void close_socket(int sock) {
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
}

}  // namespace

GuardedHttpServer::GuardedHttpServer(const HttpLimits& limits) : limits_(limits) {
  new_task_queue = [] { return new InlineTaskQueue; };
  set_payload_max_length(limits_.max_body_bytes);
  if (::pipe2(wake_pipe_, O_NONBLOCK | O_CLOEXEC) != 0)
    throw InternalError(fmt::format("--preview: cannot create a pipe: {}", std::strerror(errno)));
  // Named, so that a profile or a test (tests/browser/test_preview.py) can tell the server's time apart.
  gate_ = std::thread([this] {
    ::pthread_setname_np(::pthread_self(), "http-gate");
    gate_loop();
  });
  for (int i = 0; i < limits_.workers; ++i)
    workers_.emplace_back([this] {
      ::pthread_setname_np(::pthread_self(), "http-worker");
      worker_loop();
    });
}

GuardedHttpServer::~GuardedHttpServer() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    // A worker waiting on a slow client returns at once.
    for (int sock : serving_) ::shutdown(sock, SHUT_RDWR);
  }
  [[maybe_unused]] const ssize_t woke = ::write(wake_pipe_[1], "x", 1);
  ready_cv_.notify_all();
  gate_.join();
  for (std::thread& w : workers_) w.join();
  for (const Waiting& w : waiting_) close_socket(w.sock);
  for (const Ready& r : ready_) close_socket(r.sock);
  ::close(wake_pipe_[0]);
  ::close(wake_pipe_[1]);
}

int GuardedHttpServer::bind(const std::string& host, int port) {
  const int bound = port == 0 ? bind_to_any_port(host) : (bind_to_port(host, port) ? port : -1);
  if (bound > 0) ::listen(svr_sock_, SOMAXCONN);  // a second listen() only sets the queue's length
  return bound;
}

bool GuardedHttpServer::process_and_close_socket(int sock) {
  admit(sock);
  return true;
}

void GuardedHttpServer::admit(int sock) {
  {
    std::lock_guard lock(mutex_);
    if (!stopping_ && waiting_.size() < limits_.max_waiting) {
      waiting_.push_back({sock, Clock::now() + limits_.header_time, {}});
      [[maybe_unused]] const ssize_t woke = ::write(wake_pipe_[1], "x", 1);
      return;
    }
  }
  refuse_and_close(sock, 503, "Service Unavailable");
}

void GuardedHttpServer::refuse_and_close(int sock, int status, const char* reason) {
  const std::string answer = fmt::format("HTTP/1.1 {} {}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n", status, reason);
  [[maybe_unused]] const ssize_t sent = ::send(sock, answer.data(), answer.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
  close_socket(sock);
}

void GuardedHttpServer::gate_loop() {
  std::vector<pollfd> fds;
  std::vector<char> chunk(4096);
  for (;;) {
    // Wait for the wake pipe, a waiting connection's bytes or the earliest deadline.
    Clock::time_point earliest = Clock::now() + std::chrono::seconds(1);
    fds.assign(1, pollfd{wake_pipe_[0], POLLIN, 0});
    {
      std::lock_guard lock(mutex_);
      if (stopping_) return;
      for (const Waiting& w : waiting_) {
        fds.push_back(pollfd{w.sock, POLLIN, 0});
        earliest = std::min(earliest, w.deadline);
      }
    }
    if (::poll(fds.data(), fds.size(), remaining_ms(earliest) + 1) < 0 && errno != EINTR) return;
    if (fds[0].revents & POLLIN)
      while (::read(wake_pipe_[0], chunk.data(), chunk.size()) > 0) {
      }

    // Receive what arrived; decide each connection that is complete, too big, closed or too late.
    struct Decided {
      int sock;
      int status;  // 0: complete, -1: closed by the client, else the refusal
    };
    std::vector<Decided> decided;
    const Clock::time_point now = Clock::now();
    std::unique_lock lock(mutex_);
    // waiting_ only grows while unlocked (admit appends), so the first fds.size() - 1 entries are those polled.
    for (size_t i = 1; i < fds.size(); ++i) {
      Waiting& w = waiting_[i - 1];
      if (fds[i].revents) {
        const size_t room = limits_.max_header_bytes - w.received.size();
        const ssize_t n = ::recv(w.sock, chunk.data(), std::min(room, chunk.size()), MSG_DONTWAIT);
        if (n == 0 || (n < 0 && !retry(errno))) {
          decided.push_back({w.sock, -1});
          continue;
        }
        if (n > 0) w.received.append(chunk.data(), size_t(n));
      }
      if (headers_complete(w.received))
        decided.push_back({w.sock, 0});
      else if (w.received.size() >= limits_.max_header_bytes)
        decided.push_back({w.sock, 431});
      else if (now >= w.deadline)
        decided.push_back({w.sock, 408});
    }
    std::vector<Decided> refused;
    for (const Decided& d : decided) {
      auto it = std::find_if(waiting_.begin(), waiting_.end(), [&](const Waiting& w) { return w.sock == d.sock; });
      if (d.status == 0 && ready_.size() < limits_.max_ready)
        ready_.push_back({d.sock, std::move(it->received)});
      else
        refused.push_back({d.sock, d.status == 0 ? 503 : d.status});
      waiting_.erase(it);
    }
    lock.unlock();
    if (!decided.empty()) ready_cv_.notify_all();
    for (const Decided& r : refused) {
      if (r.status == -1) close_socket(r.sock);
      else if (r.status == 408) refuse_and_close(r.sock, 408, "Request Timeout");
      else if (r.status == 431) refuse_and_close(r.sock, 431, "Request Header Fields Too Large");
      else refuse_and_close(r.sock, 503, "Service Unavailable");
    }
  }
}

void GuardedHttpServer::worker_loop() {
  for (;;) {
    Ready job;
    {
      std::unique_lock lock(mutex_);
      ready_cv_.wait(lock, [this] { return stopping_ || !ready_.empty(); });
      if (stopping_) return;
      job = std::move(ready_.front());
      ready_.pop_front();
      serving_.push_back(job.sock);
    }
    answer(job.sock, std::move(job.received));
    {
      // Out of serving_ before the close, so that the stop never shuts down a reused descriptor.
      std::lock_guard lock(mutex_);
      serving_.erase(std::find(serving_.begin(), serving_.end(), job.sock));
    }
    close_socket(job.sock);
  }
}

void GuardedHttpServer::answer(int sock, std::string received) {
  BoundedSocketStream stream(sock, std::move(received), limits_.max_header_bytes + limits_.max_body_bytes,
                             Clock::now() + limits_.response_time);
  bool connection_closed = false;
  try {
    process_request(stream, /*close_connection=*/true, connection_closed, [&](httplib::Request& req) {
      stream.get_remote_ip_and_port(req.remote_addr, req.remote_port);
      stream.get_local_ip_and_port(req.local_addr, req.local_port);
    });
  } catch (...) {
    // httplib answers a handler's exception with 500; anything else ends this connection only.
  }
}

void GuardedHttpServer::serve(int sock) {
  answer(sock, {});
  close_socket(sock);
}

}  // namespace candela
