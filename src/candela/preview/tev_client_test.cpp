#include "candela/preview/tev_client.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "candela/base/error.h"
#include "candela/film/film.h"
#include "candela/film/live_film.h"

namespace candela {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// ---- A recording receiver: what tev does with the bytes, parsed from tev's documented layout
// (tev_client.h) independently of the client's writer.

class Receiver {
 public:
  // Listens on 127.0.0.1:port (0: any free port).
  explicit Receiver(uint16_t port = 0) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    if (listen_fd_ < 0) throw std::runtime_error("socket() failed");
    const int one = 1;
    ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 || ::listen(listen_fd_, 4) != 0)
      throw std::runtime_error(std::string("bind/listen failed: ") + std::strerror(errno));
    socklen_t len = sizeof(addr);
    ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
    port_ = ntohs(addr.sin_port);
  }
  ~Receiver() { close(); }
  Receiver(const Receiver&) = delete;
  Receiver& operator=(const Receiver&) = delete;

  uint16_t port() const { return port_; }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }

  bool accept_within(std::chrono::milliseconds timeout) {
    pollfd p{listen_fd_, POLLIN, 0};
    if (::poll(&p, 1, int(timeout.count())) <= 0) return false;
    conn_fd_ = ::accept(listen_fd_, nullptr, nullptr);
    return conn_fd_ >= 0;
  }

  // The next whole packet; nullopt on a timeout or at the end of the stream (then eof()).
  std::optional<std::vector<uint8_t>> next_packet(std::chrono::milliseconds timeout) {
    const auto deadline = Clock::now() + timeout;
    for (;;) {
      if (buffer_.size() >= 4) {
        const uint32_t length = uint32_t(buffer_[0]) | uint32_t(buffer_[1]) << 8 | uint32_t(buffer_[2]) << 16 |
                                uint32_t(buffer_[3]) << 24;
        if (length < 5) {
          ADD_FAILURE() << "packet length " << length << " is shorter than its header";
          return std::nullopt;
        }
        if (buffer_.size() >= length) {
          std::vector<uint8_t> packet(buffer_.begin(), buffer_.begin() + length);
          buffer_.erase(buffer_.begin(), buffer_.begin() + length);
          return packet;
        }
      }
      if (eof_ || conn_fd_ < 0) return std::nullopt;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      if (left.count() <= 0) return std::nullopt;
      pollfd p{conn_fd_, POLLIN, 0};
      if (::poll(&p, 1, int(left.count())) <= 0) continue;
      uint8_t chunk[65536];
      const ssize_t n = ::recv(conn_fd_, chunk, sizeof(chunk), 0);
      if (n <= 0) {
        eof_ = true;
        continue;
      }
      buffer_.insert(buffer_.end(), chunk, chunk + n);
    }
  }
  bool eof() const { return eof_ && buffer_.empty(); }

  void close() {
    if (conn_fd_ >= 0) ::close(conn_fd_);
    if (listen_fd_ >= 0) ::close(listen_fd_);
    conn_fd_ = listen_fd_ = -1;
  }

 private:
  int listen_fd_ = -1, conn_fd_ = -1;
  uint16_t port_ = 0;
  std::vector<uint8_t> buffer_;
  bool eof_ = false;
};

// Reads little-endian fields; any read past the end sets !ok.
class Reader {
 public:
  explicit Reader(const std::vector<uint8_t>& bytes) : bytes_(bytes) {}
  uint64_t le(int n) {
    if (at_ + size_t(n) > bytes_.size()) {
      ok = false;
      return 0;
    }
    uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= uint64_t(bytes_[at_ + size_t(i)]) << (8 * i);
    at_ += size_t(n);
    return v;
  }
  uint8_t u8() { return uint8_t(le(1)); }
  int32_t i32() { return int32_t(uint32_t(le(4))); }
  int64_t i64() { return int64_t(le(8)); }
  float f32() { return std::bit_cast<float>(uint32_t(le(4))); }
  std::string str() {
    std::string s;
    for (;;) {
      if (at_ >= bytes_.size()) {
        ok = false;
        return s;
      }
      const char c = char(bytes_[at_++]);
      if (c == '\0') return s;
      s += c;
    }
  }
  size_t left() const { return bytes_.size() - at_; }
  bool ok = true;

 private:
  const std::vector<uint8_t>& bytes_;
  size_t at_ = 0;
};

struct CreateImage {
  bool grab_focus = false;
  std::string name;
  int32_t width = 0, height = 0;
  std::vector<std::string> channels;
};

struct UpdateImage {
  bool grab_focus = false;
  std::string name;
  std::vector<std::string> channels;
  int32_t x = 0, y = 0, width = 0, height = 0;
  std::vector<int64_t> offsets, strides;
  std::vector<float> data;
  // Channel c of pixel (x + i, y + j).
  float at(int i, int j, int c) const {
    return data[size_t(offsets[size_t(c)] + int64_t(j * width + i) * strides[size_t(c)])];
  }
};

uint8_t packet_type(const std::vector<uint8_t>& p) { return p.size() > 4 ? p[4] : 0xff; }

// Length, type 4, grab focus, name, width, height, channel count, channel names; nothing after.
std::optional<CreateImage> parse_create(const std::vector<uint8_t>& p) {
  Reader r(p);
  EXPECT_EQ(r.le(4), p.size()) << "length field";
  EXPECT_EQ(r.u8(), 4) << "CreateImage type";
  CreateImage c;
  c.grab_focus = r.u8() == 1;
  c.name = r.str();
  c.width = r.i32();
  c.height = r.i32();
  const int32_t n = r.i32();
  for (int32_t i = 0; i < n && r.ok; ++i) c.channels.push_back(r.str());
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.left(), 0u) << "bytes after CreateImage";
  if (!r.ok || r.left() != 0) return std::nullopt;
  return c;
}

// Length, type 6, grab focus, name, channel count, names, x, y, width, height, int64 offsets, int64
// strides, floats.
std::optional<UpdateImage> parse_update(const std::vector<uint8_t>& p) {
  Reader r(p);
  EXPECT_EQ(r.le(4), p.size()) << "length field";
  EXPECT_EQ(r.u8(), 6) << "UpdateImageV3 type";
  UpdateImage u;
  u.grab_focus = r.u8() == 1;
  u.name = r.str();
  const int32_t n = r.i32();
  for (int32_t i = 0; i < n && r.ok; ++i) u.channels.push_back(r.str());
  u.x = r.i32();
  u.y = r.i32();
  u.width = r.i32();
  u.height = r.i32();
  for (int32_t i = 0; i < n; ++i) u.offsets.push_back(r.i64());
  for (int32_t i = 0; i < n; ++i) u.strides.push_back(r.i64());
  EXPECT_TRUE(r.ok);
  if (!r.ok || n <= 0) return std::nullopt;
  // As tev's interpretAsUpdateImage: the data reaches the furthest offset + (pixels - 1) * stride.
  int64_t count = 0;
  const int64_t pixels = int64_t(u.width) * u.height;
  for (int32_t c = 0; c < n; ++c)
    count = std::max(count, u.offsets[size_t(c)] + (pixels - 1) * u.strides[size_t(c)] + 1);
  EXPECT_EQ(r.left(), size_t(count) * 4) << "float data size";
  if (r.left() != size_t(count) * 4) return std::nullopt;
  for (int64_t i = 0; i < count; ++i) u.data.push_back(r.f32());
  return u;
}

// The image as tev would hold it.
struct TevImage {
  int width = 0, height = 0;
  std::vector<float> rgb;

  void create(const CreateImage& c) {
    width = c.width;
    height = c.height;
    rgb.assign(size_t(width) * size_t(height) * 3, 0.0f);
  }
  void apply(const UpdateImage& u) {
    ASSERT_GE(u.x, 0);
    ASSERT_GE(u.y, 0);
    ASSERT_LE(u.x + u.width, width);
    ASSERT_LE(u.y + u.height, height);
    for (int j = 0; j < u.height; ++j)
      for (int i = 0; i < u.width; ++i)
        for (int c = 0; c < 3; ++c)
          rgb[(size_t(u.y + j) * size_t(width) + size_t(u.x + i)) * 3 + size_t(c)] = u.at(i, j, c);
  }
};

const std::string kName = "render.exr";

TevClientOptions fast_options() {
  TevClientOptions o;
  o.update_interval = 5ms;
  o.retry_interval = 20ms;
  o.connect_timeout = 500ms;
  o.send_timeout = 1000ms;
  o.final_wait = 1000ms;
  o.log = [](const std::string&) {};
  return o;
}

// Distinct, non-round values in every pixel.
void add_samples(Film& film, int pass) {
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x)
      film.add_sample(
          x, y, RGB(0.1f * float(x) + 0.37f * float(pass), 1.0f / float(1 + y + pass), 0.013f * float(x * y + 1)),
          1.0f);
}

void expect_create(const std::vector<uint8_t>& packet, int width, int height) {
  ASSERT_EQ(packet_type(packet), tev_ipc::kCreateImage);
  std::optional<CreateImage> c = parse_create(packet);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->name, kName);
  EXPECT_EQ(c->width, width);
  EXPECT_EQ(c->height, height);
  EXPECT_EQ(c->channels, (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_TRUE(c->grab_focus);
}

// The first packet of a connection: CreateImage of the film's size, which `image` then mirrors.
void receive_create(Receiver& rx, int width, int height, TevImage& image) {
  std::optional<std::vector<uint8_t>> first = rx.next_packet(2000ms);
  ASSERT_TRUE(first);
  expect_create(*first, width, height);
  image.create(*parse_create(*first));
}

// Receives UpdateImage packets until `rows` have all come (each once), checking each packet's layout
// and that its values are the LiveFilm's; applies them to `image`.
void receive_rows(Receiver& rx, const LiveFilm& live, std::set<int> rows, TevImage& image, int max_rows_per_packet) {
  LiveSnapshot snap;
  live.snapshot(snap);
  std::set<int> seen;
  while (seen != rows) {
    std::optional<std::vector<uint8_t>> p = rx.next_packet(2000ms);
    ASSERT_TRUE(p) << "rows missing: received " << seen.size() << " of " << rows.size();
    ASSERT_EQ(packet_type(*p), tev_ipc::kUpdateImageV3);
    std::optional<UpdateImage> u = parse_update(*p);
    ASSERT_TRUE(u);
    EXPECT_EQ(u->name, kName);
    EXPECT_FALSE(u->grab_focus);
    EXPECT_EQ(u->channels, (std::vector<std::string>{"R", "G", "B"}));
    EXPECT_EQ(u->offsets, (std::vector<int64_t>{0, 1, 2}));
    EXPECT_EQ(u->strides, (std::vector<int64_t>{3, 3, 3}));
    EXPECT_EQ(u->x, 0);
    EXPECT_EQ(u->width, snap.width);
    EXPECT_GE(u->height, 1);
    EXPECT_LE(u->height, max_rows_per_packet);
    for (int j = 0; j < u->height; ++j) {
      const int y = u->y + j;
      EXPECT_TRUE(rows.count(y)) << "row " << y << " was not changed";
      EXPECT_TRUE(seen.insert(y).second) << "row " << y << " sent twice";
      for (int x = 0; x < u->width; ++x)
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(std::bit_cast<uint32_t>(u->at(x, j, c)),
                    std::bit_cast<uint32_t>(snap.rgb[(size_t(y) * size_t(snap.width) + size_t(x)) * 3 + size_t(c)]))
              << "pixel (" << x << ", " << y << ") channel " << c;
    }
    image.apply(*u);
  }
}

// Every remaining packet up to the end of the stream (UpdateImage only), applied to `image`.
void receive_to_end(Receiver& rx, TevImage& image) {
  while (std::optional<std::vector<uint8_t>> p = rx.next_packet(2000ms)) {
    ASSERT_EQ(packet_type(*p), tev_ipc::kUpdateImageV3);
    std::optional<UpdateImage> u = parse_update(*p);
    ASSERT_TRUE(u);
    image.apply(*u);
  }
  EXPECT_TRUE(rx.eof()) << "the client did not close the connection after the render";
}

// tev's image equals the LiveFilm's and the film's means, bit for bit.
void expect_image_equals_film(const TevImage& image, const LiveFilm& live, const Film& film) {
  LiveSnapshot snap;
  live.snapshot(snap);
  ASSERT_EQ(image.rgb.size(), snap.rgb.size());
  EXPECT_EQ(std::memcmp(image.rgb.data(), snap.rgb.data(), snap.rgb.size() * sizeof(float)), 0);
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      const RGB m = film.pixel(x, y).mean();
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(std::bit_cast<uint32_t>(image.rgb[(size_t(y) * size_t(film.width()) + size_t(x)) * 3 + size_t(c)]),
                  std::bit_cast<uint32_t>(m[c]))
            << "pixel (" << x << ", " << y << ")";
    }
}

std::set<int> row_range(int y0, int y1) {
  std::set<int> s;
  for (int y = y0; y < y1; ++y) s.insert(y);
  return s;
}

TEST(TevClient, ParsesAddresses) {
  DisplayServerAddress a = parse_display_server_address("127.0.0.1:14158");
  EXPECT_EQ(a.host, "127.0.0.1");
  EXPECT_EQ(a.port, 14158);
  a = parse_display_server_address("localhost:1");
  EXPECT_EQ(a.host, "localhost");
  EXPECT_EQ(a.port, 1);
  a = parse_display_server_address("[::1]:65535");
  EXPECT_EQ(a.host, "::1");
  EXPECT_EQ(a.port, 65535);
}

TEST(TevClient, RefusesMalformedAddresses) {
  LiveFilm live(2, 2);
  for (const char* bad : {"", "localhost", "14158", ":14158", "localhost:", "localhost:abc", "localhost:0",
                          "localhost:65536", "localhost:99999999999", "localhost:14158x", "::1:14158", "[::1]14158",
                          "[::1:14158", "local host:14158"}) {
    try {
      TevClient client(bad, kName, live, fast_options());
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const UsageError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(std::string("'") + bad + "'"), std::string::npos) << message;
      EXPECT_NE(message.find("expected HOST:PORT"), std::string::npos) << message;
    }
  }
  try {
    parse_display_server_address("localhost:70000");
    ADD_FAILURE();
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(),
                 "display server address 'localhost:70000': port '70000' is not a number from 1 to 65535 "
                 "(expected HOST:PORT, e.g. 127.0.0.1:14158)");
  }
  EXPECT_THROW(TevClient("127.0.0.1:14158", "", live, fast_options()), InternalError);
}

// The bytes of both packets, written out by hand from tev's layout.
TEST(TevClient, PacketBytesFollowTevsLayout) {
  std::vector<uint8_t> p;
  const std::string channels[3] = {"R", "G", "B"};
  tev_ipc::create_image_packet(p, "ab", true, 3, 2, channels);
  const std::vector<uint8_t> create = {27, 0, 0, 0,  4,  1,   'a', 'b', 0, 3, 0, 0,   0, 2,
                                       0,  0, 0, 3,  0,  0,   0,   'R', 0, 'G', 0, 'B', 0};
  EXPECT_EQ(p, create);

  const float rgb[3] = {1.0f, -2.0f, 0.5f};
  tev_ipc::update_rows_packet(p, "ab", 1, 5, 6, rgb);
  std::vector<uint8_t> update = {95, 0, 0, 0, 6, 0, 'a', 'b', 0, 3, 0, 0, 0, 'R', 0, 'G', 0, 'B', 0,
                                 0,  0, 0, 0,   // x
                                 5,  0, 0, 0,   // y
                                 1,  0, 0, 0,   // width
                                 1,  0, 0, 0};  // height
  for (int offset : {0, 1, 2}) update.insert(update.end(), {uint8_t(offset), 0, 0, 0, 0, 0, 0, 0});
  for (int i = 0; i < 3; ++i) update.insert(update.end(), {3, 0, 0, 0, 0, 0, 0, 0});
  update.insert(update.end(), {0, 0, 0x80, 0x3f, 0, 0, 0, 0xc0, 0, 0, 0, 0x3f});
  EXPECT_EQ(p, update);
  EXPECT_EQ(tev_ipc::update_rows_packet_size("ab", 1, 1), update.size());
}

TEST(TevClient, StreamsTheChangedRowsAndTheFinalImage) {
  constexpr int W = 8, H = 7;
  Film film(W, H);
  add_samples(film, 0);
  LiveFilm live(W, H);
  Receiver rx;
  TevClientOptions options = fast_options();
  options.max_packet_bytes = tev_ipc::update_rows_packet_size(kName, W, 2);  // two rows a packet
  TevClient client(rx.address(), kName, live, options);
  ASSERT_TRUE(rx.accept_within(2000ms));
  TevImage image;
  receive_create(rx, W, H, image);
  live.start("test", 2, false, 0, 0);

  live.tile_done(film, 0, 1, W, 4);  // rows 1-3: two packets, rows 1-2 and 3
  receive_rows(rx, live, row_range(1, 4), image, 2);
  live.tile_done(film, 2, 5, 6, 7);  // rows 5-6, part of their width: the whole rows go
  receive_rows(rx, live, row_range(5, 7), image, 2);

  add_samples(film, 1);
  live.pass_done(film);
  live.finish(LiveState::Finished);
  receive_to_end(rx, image);
  expect_image_equals_film(image, live, film);
  EXPECT_EQ(client.connections(), 1);
}

TEST(TevClient, ReconnectsAndSendsEverythingAgain) {
  constexpr int W = 5, H = 4;
  Film film(W, H);
  add_samples(film, 0);
  LiveFilm live(W, H);
  auto rx = std::make_unique<Receiver>();
  const uint16_t port = rx->port();
  TevClient client(rx->address(), kName, live, fast_options());
  ASSERT_TRUE(rx->accept_within(2000ms));
  TevImage image;
  receive_create(*rx, W, H, image);
  live.start("test", 2, false, 0, 0);
  live.pass_done(film);
  receive_rows(*rx, live, row_range(0, H), image, H);

  // tev quits; a new one listens on the same port.
  rx.reset();
  rx = std::make_unique<Receiver>(port);
  ASSERT_TRUE(rx->accept_within(3000ms));
  TevImage again;
  receive_create(*rx, W, H, again);
  receive_rows(*rx, live, row_range(0, H), again, H);
  expect_image_equals_film(again, live, film);

  add_samples(film, 1);
  live.pass_done(film);
  live.finish(LiveState::Finished);
  receive_to_end(*rx, again);
  expect_image_equals_film(again, live, film);
  EXPECT_EQ(client.connections(), 2);
}

// stop() (the destructor) sends what tev has not seen yet, then closes.
TEST(TevClient, StopSendsWhatTevHasNotSeen) {
  constexpr int W = 6, H = 3;
  Film film(W, H);
  add_samples(film, 0);
  LiveFilm live(W, H);
  Receiver rx;
  TevClientOptions options = fast_options();
  options.update_interval = 60s;  // only stop() can send the image
  auto client = std::make_unique<TevClient>(rx.address(), kName, live, options);
  ASSERT_TRUE(rx.accept_within(2000ms));
  TevImage image;
  receive_create(rx, W, H, image);
  live.start("test", 1, false, 0, 0);
  live.pass_done(film);
  const auto t0 = Clock::now();
  client.reset();
  EXPECT_LT(Clock::now() - t0, 1000ms);
  receive_to_end(rx, image);
  expect_image_equals_film(image, live, film);
}

// Nobody listening: the render goes on, stop() returns at once, one line is logged.
TEST(TevClient, NoViewerNeitherBlocksNorThrows) {
  uint16_t port;
  {
    Receiver closed;
    port = closed.port();
  }
  Film film(4, 4);
  add_samples(film, 0);
  LiveFilm live(4, 4);
  std::vector<std::string> lines;
  std::mutex lines_mutex;
  TevClientOptions options = fast_options();
  options.log = [&](const std::string& line) {
    std::lock_guard lock(lines_mutex);
    lines.push_back(line);
  };
  TevClient client("127.0.0.1:" + std::to_string(port), kName, live, options);
  live.start("test", 1, false, 0, 0);
  for (int i = 0; i < 5; ++i) {
    live.pass_done(film);
    std::this_thread::sleep_for(10ms);  // a few retries
  }
  live.finish(LiveState::Finished);
  const auto t0 = Clock::now();
  client.stop();
  EXPECT_LT(Clock::now() - t0, 500ms);
  EXPECT_EQ(client.connections(), 0);
  std::lock_guard lock(lines_mutex);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("cannot connect to tev at 127.0.0.1:" + std::to_string(port)), std::string::npos) << lines[0];
}

// A viewer that accepts and never reads: sends block, and stop() still returns after final_wait.
// One that hangs up mid-stream raises no SIGPIPE (which would end this process).
TEST(TevClient, StalledOrVanishingViewerDoesNotHangOrKill) {
  constexpr int W = 384, H = 384;  // 1.7 MB an image: a few fill the socket buffers
  Film film(W, H);
  add_samples(film, 0);
  LiveFilm live(W, H);
  live.start("test", 1, false, 0, 0);
  {
    Receiver rx;
    TevClientOptions options = fast_options();
    options.final_wait = 200ms;
    options.send_timeout = 5000ms;
    TevClient client(rx.address(), kName, live, options);
    ASSERT_TRUE(rx.accept_within(2000ms));
    for (int i = 0; i < 40; ++i) {
      live.pass_done(film);
      std::this_thread::sleep_for(5ms);
    }
    const auto t0 = Clock::now();
    client.stop();
    const auto took = Clock::now() - t0;
    EXPECT_LT(took, 1000ms);
    RecordProperty("stalled_stop_ms", int(std::chrono::duration_cast<std::chrono::milliseconds>(took).count()));
  }
  {
    Receiver rx;
    TevClient client(rx.address(), kName, live, fast_options());
    ASSERT_TRUE(rx.accept_within(2000ms));
    live.pass_done(film);
    rx.close();  // unread data: the client gets a reset while it sends
    for (int i = 0; i < 10; ++i) {
      live.pass_done(film);
      std::this_thread::sleep_for(5ms);
    }
    client.stop();
    EXPECT_GE(client.connections(), 1);
  }
}

}  // namespace
}  // namespace candela
