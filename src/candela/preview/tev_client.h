#pragma once
// Streams the image as it renders to the tev image viewer (https://github.com/Tom94/tev), as pbrt-v4's
// --display-server does: `candela render scene.json --display-server 127.0.0.1:14158` with tev running
// (tev listens on 127.0.0.1:14158 by default).
//
// What is sent, and when (all from the client's own thread; the render never waits for it):
//  - On connecting: CreateImage (the image name, the film's size, channels R, G, B, grabbing focus),
//    which makes tev create a black image of that name or replace the one it has; then every row the
//    render has written so far (rows it has not reached are black, as tev's new image is).
//  - Then every `update_interval` (0.25 s) when the LiveFilm's version changed: UpdateImage packets for
//    the rows changed since the version last sent, linear RGB means as 32-bit floats. Consecutive
//    changed rows go as one full-width rectangle, split so that no packet exceeds `max_packet_bytes`.
//  - When the render is over (LiveFilm::status().state is Finished or Stopped): the rows changed since,
//    then the client closes the connection and its thread ends.
//  - If the viewer is not there, goes away or stops reading (a send blocked for `send_timeout`), the
//    client closes the socket and tries again every `retry_interval`; a new connection starts with
//    CreateImage and the whole image again, so a restarted tev catches up. It also keeps trying after
//    the render is over, until stop(). Sends use MSG_NOSIGNAL: a dead viewer raises no SIGPIPE.
//  - stop() (and the destructor) sends what the viewer has not seen yet, waiting at most `final_wait`
//    (a blocked send is cut off by shutting the socket down), and joins the thread.
//
// The protocol is tev's IPC protocol, as tev's include/tev/Ipc.h and src/Ipc.cpp define it (IpcPacket:
// EType, OStream, setCreateImage, setUpdateImage / interpretAsUpdateImage) and its Python client
// src/python/ipc.py writes it. A packet is
//     uint32  length of the whole packet in bytes, these 4 included
//     uint8   type
//     fields
// integers little-endian, bools one byte (0 or 1), strings UTF-8 with a terminating '\0', floats IEEE
// binary32 little-endian. The two packets used here:
//   CreateImage   (type 4):  bool grab_focus, string name, int32 width, int32 height, int32 n_channels,
//                            n_channels x string channel name
//   UpdateImageV3 (type 6):  bool grab_focus, string name, int32 n_channels, n_channels x string channel
//                            name, int32 x, int32 y, int32 width, int32 height, n_channels x int64 offset,
//                            n_channels x int64 stride, then floats: channel c of pixel p (row-major in
//                            the rectangle) at float index offset[c] + p * stride[c]
// UpdateImageV3 (custom offsets and strides, so interleaved RGB goes as it is) is what tev's own ipc.py
// sends (offsets 0, 1, 2, strides 3, as here); tev has read it since well before 1.23.
// (pbrt-v4's display.cpp sends the older single-channel UpdateImage, type 3, one packet per channel.)
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace candela {

class LiveFilm;

// "host:port": host a name, an IPv4 address or a bracketed IPv6 address ("[::1]:14158"), port 1-65535.
struct DisplayServerAddress {
  std::string host;  // without brackets
  uint16_t port = 0;
};
// Throws UsageError naming the address and what is wrong with it.
DisplayServerAddress parse_display_server_address(std::string_view address);

// tev's packets, as bytes (the layout above).
namespace tev_ipc {
inline constexpr uint8_t kCreateImage = 4;    // tev IpcPacket::EType::CreateImage
inline constexpr uint8_t kUpdateImageV3 = 6;  // tev IpcPacket::EType::UpdateImageV3

// Replaces `out` with a CreateImage packet.
void create_image_packet(std::vector<uint8_t>& out, std::string_view name, bool grab_focus, int32_t width,
                         int32_t height, std::span<const std::string> channel_names);
// Replaces `out` with an UpdateImageV3 packet for rows [y0, y1) of an image `width` pixels wide,
// channels R, G, B, interleaved (`rgb` holds those rows, 3 floats per pixel).
void update_rows_packet(std::vector<uint8_t>& out, std::string_view name, int32_t width, int32_t y0, int32_t y1,
                        std::span<const float> rgb);
// The size of update_rows_packet's packet for `rows` rows.
size_t update_rows_packet_size(std::string_view name, int32_t width, int32_t rows);
}  // namespace tev_ipc

struct TevClientOptions {
  std::chrono::milliseconds update_interval{250};   // how often the film's version is looked at
  std::chrono::milliseconds retry_interval{1000};   // between connection attempts
  std::chrono::milliseconds connect_timeout{1000};  // one connection attempt
  std::chrono::milliseconds send_timeout{3000};     // a send blocked this long drops the connection
  std::chrono::milliseconds final_wait{2000};       // stop(): the most it waits for the last packets
  size_t max_packet_bytes = size_t(4) << 20;        // UpdateImage packets stay below this (one row at least)
  bool grab_focus = true;                           // CreateImage makes tev show the image
  // Connections made, refused and lost (one line each, not one per retry). Empty: "candela: tev: ..."
  // on stderr.
  std::function<void(const std::string&)> log;
};

class TevClient {
 public:
  // Parses `address` (throwing UsageError if malformed, InternalError for an empty or '\0'-holding
  // image name) and starts the client's thread, which connects and sends as above.
  // `live` must outlive the client.
  TevClient(std::string_view address, std::string image_name, const LiveFilm& live, TevClientOptions options = {});
  ~TevClient();  // stop()
  TevClient(const TevClient&) = delete;
  TevClient& operator=(const TevClient&) = delete;

  // Sends what tev has not seen yet (at most options.final_wait) and joins the thread. Idempotent.
  void stop();

  const DisplayServerAddress& address() const { return address_; }
  // Connections made so far (tests, diagnostics).
  int connections() const;

 private:
  void run();
  // One connection attempt; the socket, or -1.
  int connect_once(std::string& error);
  bool send_all(int fd, const std::vector<uint8_t>& bytes);
  void close_socket();
  void log(const std::string& message) const;
  bool aborting() const;

  const DisplayServerAddress address_;
  const std::string image_name_;
  const LiveFilm& live_;
  const TevClientOptions options_;

  mutable std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_requested_ = false;  // under mutex_
  bool abort_ = false;           // under mutex_: stop()'s wait is over, give up
  bool done_ = false;            // under mutex_: the thread has nothing more to do
  int fd_ = -1;                  // under mutex_ (the thread also reads it without: only it changes it)
  int connections_ = 0;          // under mutex_
  std::thread thread_;
};

}  // namespace candela
