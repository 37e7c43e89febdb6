#pragma once
// An HTTP server (cpp-httplib) that a slow or hostile client cannot use to exhaust threads, memory or
// time: the preview's transport (docs/preview.md, "Limits").
//
// cpp-httplib hands each accepted connection to a pool thread that then waits for the request, so a
// few clients that send one byte every few seconds hold every thread, and it bounds neither the number
// of header lines nor the connections waiting. Here a connection instead waits in a gate: one thread
// polls every waiting connection and collects its bytes until the request line and headers have all
// arrived. Only a complete request goes to a worker, which reads it through a stream that stops at a
// byte budget and a deadline, answers it and closes the connection (one request per connection). So:
//   - a connection that is not complete within `header_time`, or whose headers exceed
//     `max_header_bytes`, is answered 408 / 431 and closed, without ever taking a worker;
//   - at most `max_waiting` connections wait in the gate and `max_ready` complete requests wait for a
//     worker; beyond either, a new connection is answered 503 and closed at once;
//   - a worker spends at most `response_time` on one request (reading its body, answering, sending),
//     whatever the client does, and reads at most `max_header_bytes` + the payload limit;
//   - memory is bounded by those counts: at most max_header_bytes per waiting connection (4 MiB for
//     the defaults), `workers` requests at a time.
#include <httplib.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace candela {

struct HttpLimits {
  int workers = 4;                                   // requests answered at once
  size_t max_waiting = 256;                          // connections whose request has not fully arrived
  size_t max_ready = 32;                             // complete requests waiting for a worker
  size_t max_header_bytes = 16 * 1024;               // request line and headers
  size_t max_body_bytes = 1024;                      // request body (the preview's requests have none)
  std::chrono::milliseconds header_time{5000};       // from accept to the end of the headers
  std::chrono::milliseconds response_time{30000};    // to read the body, answer and send the answer
};

class GuardedHttpServer : public httplib::Server {
 public:
  explicit GuardedHttpServer(const HttpLimits& limits = {});
  // Stops the gate and the workers and closes every connection they hold. Call httplib's stop() first.
  ~GuardedHttpServer() override;

  // Binds `host`:`port` (0: any free port) and returns the port, or -1. The accept queue holds as many
  // connections as the system allows (httplib's is 5: a burst of connections would wait for the
  // client's SYN retry, a second or more, before the gate sees them).
  int bind(const std::string& host, int port);

  // Answers the one request on connected socket `sock` (already complete or not) on the calling thread,
  // within the limits, and closes it: what a worker does; public for the HTTP fuzz target.
  void serve(int sock);

  const HttpLimits& limits() const { return limits_; }

 private:
  struct Waiting {
    int sock;
    std::chrono::steady_clock::time_point deadline;
    std::string received;  // the request's bytes so far (at most max_header_bytes)
  };
  struct Ready {
    int sock = -1;
    std::string received;
  };
  // Called by httplib's accept loop (through an inline task queue) for each new connection.
  bool process_and_close_socket(int sock) override;
  void admit(int sock);
  void gate_loop();
  void worker_loop();
  // Reads the request (`received` first, then the socket) and answers it, within the limits.
  void answer(int sock, std::string received);
  // Sends a short error answer (best effort, without waiting) and closes the connection.
  static void refuse_and_close(int sock, int status, const char* reason);

  HttpLimits limits_;
  std::mutex mutex_;
  std::condition_variable ready_cv_;
  std::vector<Waiting> waiting_;  // the gate's connections, guarded by mutex_
  std::deque<Ready> ready_;       // complete requests for the workers, guarded by mutex_
  std::vector<int> serving_;      // connections the workers are answering, guarded by mutex_
  bool stopping_ = false;
  int wake_pipe_[2] = {-1, -1};  // wakes the gate's poll when a connection arrives or on stop
  std::thread gate_;
  std::vector<std::thread> workers_;
};

}  // namespace candela
