#include "candela/preview/tev_client.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "candela/base/error.h"
#include "candela/film/live_film.h"

#ifndef MSG_NOSIGNAL
#define MSG_NOSIGNAL 0  // macOS: SO_NOSIGPIPE on the socket instead
#endif

namespace candela {

// ---- The address.

DisplayServerAddress parse_display_server_address(std::string_view address) {
  auto fail = [&](std::string_view what) {
    throw UsageError(
        fmt::format("display server address '{}': {} (expected HOST:PORT, e.g. 127.0.0.1:14158)", address, what));
  };
  if (address.empty()) fail("empty");
  std::string_view host, port;
  if (address.front() == '[') {
    const size_t close = address.find(']');
    if (close == std::string_view::npos) fail("'[' without ']'");
    host = address.substr(1, close - 1);
    std::string_view rest = address.substr(close + 1);
    if (rest.empty() || rest.front() != ':') fail("no ':PORT' after the bracketed host");
    port = rest.substr(1);
  } else {
    const size_t colon = address.rfind(':');
    if (colon == std::string_view::npos) fail("no ':PORT'");
    host = address.substr(0, colon);
    port = address.substr(colon + 1);
    if (host.find(':') != std::string_view::npos) fail("an IPv6 address goes in brackets, as [::1]:14158");
  }
  if (host.empty()) fail("no host before the ':'");
  for (char c : host)
    if (static_cast<unsigned char>(c) <= ' ' || c == '[' || c == ']' || c == '/')
      fail("the host has a stray character");
  if (port.empty()) fail("no port after the ':'");
  unsigned long value = 0;
  for (char c : port) {
    if (c < '0' || c > '9' || value > 65535) fail(fmt::format("port '{}' is not a number from 1 to 65535", port));
    value = value * 10 + unsigned(c - '0');
  }
  if (value < 1 || value > 65535) fail(fmt::format("port '{}' is not a number from 1 to 65535", port));
  return DisplayServerAddress{std::string(host), uint16_t(value)};
}

// ---- Packets.

namespace tev_ipc {
namespace {

// Appends little-endian values; finish() writes the length in front.
class PacketWriter {
 public:
  PacketWriter(std::vector<uint8_t>& out, uint8_t type) : out_(out) {
    out_.clear();
    u32(0);  // the length, written by finish()
    u8(type);
  }
  void u8(uint8_t v) { out_.push_back(v); }
  void boolean(bool v) { u8(v ? 1 : 0); }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) out_.push_back(uint8_t(v >> (8 * i)));
  }
  void i32(int32_t v) { u32(uint32_t(v)); }
  void i64(int64_t v) {
    for (int i = 0; i < 8; ++i) out_.push_back(uint8_t(uint64_t(v) >> (8 * i)));
  }
  void str(std::string_view s) {
    out_.insert(out_.end(), s.begin(), s.end());
    out_.push_back(0);
  }
  void floats(std::span<const float> v) {
    const size_t at = out_.size();
    out_.resize(at + v.size() * 4);
    if constexpr (std::endian::native == std::endian::little) {
      if (!v.empty()) std::memcpy(out_.data() + at, v.data(), v.size() * 4);
    } else {
      for (size_t i = 0; i < v.size(); ++i) {
        const uint32_t u = std::bit_cast<uint32_t>(v[i]);
        for (int b = 0; b < 4; ++b) out_[at + 4 * i + size_t(b)] = uint8_t(u >> (8 * b));
      }
    }
  }
  void finish() {
    if (out_.size() > UINT32_MAX) throw InternalError("tev packet over 4 GiB");
    const uint32_t n = uint32_t(out_.size());
    for (int i = 0; i < 4; ++i) out_[size_t(i)] = uint8_t(n >> (8 * i));
  }

 private:
  std::vector<uint8_t>& out_;
};

constexpr std::string_view kRgb[3] = {"R", "G", "B"};

}  // namespace

void create_image_packet(std::vector<uint8_t>& out, std::string_view name, bool grab_focus, int32_t width,
                         int32_t height, std::span<const std::string> channel_names) {
  PacketWriter w(out, kCreateImage);
  w.boolean(grab_focus);
  w.str(name);
  w.i32(width);
  w.i32(height);
  w.i32(int32_t(channel_names.size()));
  for (const std::string& c : channel_names) w.str(c);
  w.finish();
}

size_t update_rows_packet_size(std::string_view name, int32_t width, int32_t rows) {
  // length, type, grab focus, name, channel count, names, x y w h, offsets, strides, data
  return 4 + 1 + 1 + (name.size() + 1) + 4 + 3 * 2 + 4 * 4 + 3 * 8 + 3 * 8 +
         size_t(width) * size_t(rows) * 3 * sizeof(float);
}

void update_rows_packet(std::vector<uint8_t>& out, std::string_view name, int32_t width, int32_t y0, int32_t y1,
                        std::span<const float> rgb) {
  if (width <= 0 || y1 <= y0 || rgb.size() != size_t(width) * size_t(y1 - y0) * 3)
    throw InternalError("update_rows_packet: the data does not match the rows");
  out.reserve(update_rows_packet_size(name, width, y1 - y0));
  PacketWriter w(out, kUpdateImageV3);
  w.boolean(false);  // grab focus: CreateImage did
  w.str(name);
  w.i32(3);
  for (std::string_view c : kRgb) w.str(c);
  w.i32(0);  // x
  w.i32(y0);
  w.i32(width);
  w.i32(y1 - y0);
  for (int c = 0; c < 3; ++c) w.i64(c);  // offsets: interleaved
  for (int c = 0; c < 3; ++c) w.i64(3);  // strides
  w.floats(rgb);
  w.finish();
}

}  // namespace tev_ipc

// ---- The client.

namespace {

bool peer_closed(int fd) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, 0) <= 0) return false;
  if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) return true;
  if (p.revents & POLLIN) {
    char buf[256];  // tev never sends anything; whatever comes is dropped
    const ssize_t n = ::recv(fd, buf, sizeof(buf), MSG_DONTWAIT);
    if (n == 0) return true;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return true;
  }
  return false;
}

std::string host_port(const DisplayServerAddress& a) {
  return a.host.find(':') != std::string::npos ? fmt::format("[{}]:{}", a.host, a.port)
                                               : fmt::format("{}:{}", a.host, a.port);
}

std::string seconds_text(std::chrono::milliseconds ms) { return fmt::format("{:g} s", double(ms.count()) / 1000); }

}  // namespace

TevClient::TevClient(std::string_view address, std::string image_name, const LiveFilm& live, TevClientOptions options)
    : address_(parse_display_server_address(address)),
      image_name_(std::move(image_name)),
      live_(live),
      options_(std::move(options)) {
  if (image_name_.empty()) throw InternalError("tev client: empty image name");
  if (image_name_.find('\0') != std::string::npos)
    throw InternalError("tev client: the image name holds a '\\0'");
  const LiveStatus s = live_.status();
  if (s.width <= 0 || s.height <= 0) throw InternalError("tev client: the film has no pixels");
  thread_ = std::thread([this] { run(); });
}

TevClient::~TevClient() { stop(); }

int TevClient::connections() const {
  std::lock_guard lock(mutex_);
  return connections_;
}

void TevClient::log(const std::string& message) const {
  if (options_.log)
    options_.log(message);
  else
    std::fprintf(stderr, "candela: tev: %s\n", message.c_str());
}

bool TevClient::aborting() const {
  std::lock_guard lock(mutex_);
  return abort_;
}

void TevClient::stop() {
  if (!thread_.joinable()) return;
  {
    std::unique_lock lock(mutex_);
    stop_requested_ = true;
    cv_.notify_all();
    const auto deadline = std::chrono::steady_clock::now() + options_.final_wait;
    if (!cv_.wait_until(lock, deadline, [&] { return done_; })) {
      // Out of time: make a blocked send or a pending connection give up.
      abort_ = true;
      if (fd_ >= 0) ::shutdown(fd_, SHUT_RDWR);
    }
  }
  thread_.join();
}

int TevClient::connect_once(std::string& error) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* list = nullptr;
  const std::string port = std::to_string(address_.port);
  if (const int err = ::getaddrinfo(address_.host.c_str(), port.c_str(), &hints, &list); err != 0) {
    error = ::gai_strerror(err);
    return -1;
  }
  int fd = -1;
  error = "no address";
  for (addrinfo* a = list; a && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype, a->ai_protocol);
    if (fd < 0) {
      error = std::strerror(errno);
      continue;
    }
    ::fcntl(fd, F_SETFD, FD_CLOEXEC);
    const int flags = ::fcntl(fd, F_GETFL, 0);
    ::fcntl(fd, F_SETFL, flags | O_NONBLOCK);
    int result = ::connect(fd, a->ai_addr, a->ai_addrlen);
    if (result != 0 && errno == EINPROGRESS) {
      // Wait for it in short slices, so that stop() need not wait for a whole timeout.
      const auto deadline = std::chrono::steady_clock::now() + options_.connect_timeout;
      result = -1;
      errno = ETIMEDOUT;
      while (std::chrono::steady_clock::now() < deadline && !aborting()) {
        pollfd p{fd, POLLOUT, 0};
        const int n = ::poll(&p, 1, 50);
        if (n < 0 && errno != EINTR) break;
        if (n > 0) {
          int so_error = 0;
          socklen_t len = sizeof(so_error);
          ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &so_error, &len);
          result = so_error == 0 ? 0 : -1;
          errno = so_error;
          break;
        }
        errno = ETIMEDOUT;
      }
    }
    if (result != 0) {
      error = std::strerror(errno);
      ::close(fd);
      fd = -1;
      continue;
    }
    ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
    timeval timeout{};
    timeout.tv_sec = time_t(options_.send_timeout.count() / 1000);
    timeout.tv_usec = suseconds_t((options_.send_timeout.count() % 1000) * 1000);
    ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof(timeout));
    const int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
#ifdef SO_NOSIGPIPE
    ::setsockopt(fd, SOL_SOCKET, SO_NOSIGPIPE, &one, sizeof(one));
#endif
  }
  ::freeaddrinfo(list);
  if (fd < 0) return -1;
  std::lock_guard lock(mutex_);
  if (abort_) {
    ::close(fd);
    error = "stopped";
    return -1;
  }
  fd_ = fd;
  ++connections_;
  return fd;
}

bool TevClient::send_all(int fd, const std::vector<uint8_t>& bytes) {
  size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += size_t(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      return false;
    }
  }
  return true;
}

void TevClient::close_socket() {
  std::lock_guard lock(mutex_);
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void TevClient::run() {
  using Clock = std::chrono::steady_clock;
  const std::string where = host_port(address_);
  const std::string retry_text = seconds_text(options_.retry_interval);
  LiveSnapshot snap;
  std::vector<uint8_t> packet;
  const LiveStatus initial = live_.status();
  const int32_t width = initial.width, height = initial.height;
  const size_t header = tev_ipc::update_rows_packet_size(image_name_, width, 0);
  const size_t row_bytes = size_t(width) * 3 * sizeof(float);
  const int max_rows = int(std::clamp<size_t>(
      options_.max_packet_bytes > header ? (options_.max_packet_bytes - header) / row_bytes : 0, 1, size_t(height)));
  const std::string channels[3] = {"R", "G", "B"};

  int fd = -1;
  uint64_t sent_version = 0;  // this connection has every row whose row_version is at most this
  bool failure_reported = false;
  auto next_attempt = Clock::now();

  auto drop = [&](const std::string& why) {
    close_socket();
    fd = -1;
    if (!failure_reported && !aborting())
      log(fmt::format("lost the connection to tev at {} ({}); trying again every {}", where, why, retry_text));
    failure_reported = true;
    next_attempt = Clock::now() + options_.retry_interval;
  };
  auto send_error = [] {
    return errno == EAGAIN || errno == EWOULDBLOCK ? std::string("send timed out") : std::string(std::strerror(errno));
  };

  for (;;) {
    bool stopping;
    {
      std::lock_guard lock(mutex_);
      if (abort_) break;
      stopping = stop_requested_;
    }
    const LiveState state = live_.status().state;  // before the snapshot: a finished render's snapshot is final
    const bool over = state == LiveState::Finished || state == LiveState::Stopped;
    const auto tick = Clock::now();

    if (fd >= 0 && peer_closed(fd)) drop("tev closed it");
    if (fd < 0 && (stopping || tick >= next_attempt)) {
      std::string error;
      fd = connect_once(error);
      if (fd < 0) {
        if (!failure_reported && !stopping)
          log(fmt::format("cannot connect to tev at {} ({}); trying again every {}", where, error, retry_text));
        failure_reported = true;
        next_attempt = Clock::now() + options_.retry_interval;
      } else {
        log(fmt::format("connected to tev at {}", where));
        failure_reported = false;
        sent_version = 0;
        tev_ipc::create_image_packet(packet, image_name_, options_.grab_focus, width, height, channels);
        if (!send_all(fd, packet)) drop(send_error());
      }
    }

    if (fd >= 0) {
      live_.snapshot(snap);
      bool ok = true;
      for (int y = 0; y < height && ok;) {
        if (snap.row_version[size_t(y)] <= sent_version) {
          ++y;
          continue;
        }
        int y1 = y + 1;
        while (y1 < height && y1 - y < max_rows && snap.row_version[size_t(y1)] > sent_version) ++y1;
        const size_t begin = size_t(y) * size_t(width) * 3, count = size_t(y1 - y) * size_t(width) * 3;
        tev_ipc::update_rows_packet(packet, image_name_, width, y, y1,
                                    std::span<const float>(snap.rgb.data() + begin, count));
        ok = send_all(fd, packet);
        y = y1;
      }
      if (!ok) {
        drop(send_error());
      } else {
        sent_version = snap.version;
        if (over || stopping) break;  // tev has the final image
      }
    }
    if (stopping) break;  // one last try only

    std::unique_lock lock(mutex_);
    cv_.wait_until(lock, tick + options_.update_interval, [&] { return stop_requested_; });
  }
  close_socket();
  std::lock_guard lock(mutex_);
  done_ = true;
  cv_.notify_all();
}

}  // namespace candela
