// The live film and the preview server's HTTP answers (the page itself is tested in a real browser:
// tests/browser/test_preview.py).
#include "candela/preview/preview_server.h"

#include <gtest/gtest.h>
#include <httplib.h>

#include <cstring>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "candela/base/error.h"

namespace candela {
namespace {

TEST(PreviewServer, ParsesHostAndPort) {
  PreviewAddress a = parse_preview_address("8080");
  EXPECT_EQ(a.host, "127.0.0.1");
  EXPECT_EQ(a.port, 8080);
  EXPECT_TRUE(a.loopback());
  a = parse_preview_address("0.0.0.0:0");
  EXPECT_EQ(a.host, "0.0.0.0");
  EXPECT_EQ(a.port, 0);
  EXPECT_FALSE(a.loopback());
  a = parse_preview_address("[::1]:9000");
  EXPECT_EQ(a.host, "::1");
  EXPECT_TRUE(a.loopback());
  EXPECT_TRUE(parse_preview_address("localhost:1").loopback());
  for (const char* bad : {"", ":80", "host:", "host:65536", "host:-1", "host:8o", "12.5"}) {
    try {
      parse_preview_address(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find("PORT"), std::string::npos) << e.what();
    }
  }
}

TEST(LiveFilm, TilesMarkTheirRowsAndPassesAddTheSplats) {
  Film film(8, 6);
  LiveFilm live(8, 6);
  live.start("test", 4, false, 0, 0);
  LiveSnapshot snap;
  ASSERT_TRUE(live.snapshot(snap));
  EXPECT_FALSE(live.snapshot(snap)) << "nothing changed";
  for (int y = 2; y < 4; ++y)
    for (int x = 0; x < 4; ++x) film.add_sample(x, y, RGB(1.0f, 2.0f, 3.0f), 1.0f);
  const uint64_t before = snap.version;
  live.tile_done(film, 0, 2, 4, 4);
  ASSERT_TRUE(live.snapshot(snap));
  EXPECT_GT(snap.version, before);
  for (int y = 0; y < 6; ++y) EXPECT_EQ(snap.row_version[size_t(y)] > before, y == 2 || y == 3) << y;
  EXPECT_EQ(snap.rgb[(2 * 8 + 1) * 3 + 2], 3.0f);
  EXPECT_EQ(snap.spp[2 * 8 + 1], 1.0f);
  EXPECT_EQ(snap.spp[0], 0.0f);
  EXPECT_DOUBLE_EQ(live.status().mean_spp, 8.0 / 48.0);

  // With splats only whole passes are copied (splats land anywhere), scaled as the image is.
  film.enable_splats();
  film.splats().add_to_pixel(7, 5, RGB(4.0f));
  film.set_splat_scale(0.5);
  const uint64_t v = live.version();
  live.tile_done(film, 4, 4, 8, 6);
  EXPECT_EQ(live.version(), v);
  live.pass_done(film);
  ASSERT_TRUE(live.snapshot(snap));
  EXPECT_FLOAT_EQ(snap.rgb[(5 * 8 + 7) * 3], 2.0f);
  LiveStatus s = live.status();
  EXPECT_EQ(s.state, LiveState::Rendering);
  EXPECT_EQ(s.min_spp, 0u);
  EXPECT_EQ(s.max_spp, 1u);
  live.finish(LiveState::Stopped);
  EXPECT_EQ(live.status().state, LiveState::Stopped);
}

TEST(LiveFilm, EtaFollowsTheProgressAndTheTimeLimit) {
  LiveFilm live(4, 4);
  live.start("test", 64, false, 1000, 0);
  live.progress_fraction().store(0.0);
  EXPECT_NEAR(live.status().eta_seconds, 1000, 1) << "no progress yet: the time limit";
  live.progress_fraction().store(0.5);
  LiveStatus s = live.status();
  EXPECT_NEAR(s.eta_seconds, s.seconds, 0.05) << "half done: as long again";
  live.finish(LiveState::Finished);
  EXPECT_EQ(live.status().fraction, 1.0);
  EXPECT_EQ(live.status().eta_seconds, 0.0);
}

TEST(PreviewServer, ServesStatusImageAndStop) {
  Film film(40, 30);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) film.add_sample(x, y, RGB(float(x), float(y), 1.0f), 1.0f);
  LiveFilm live(40, 30);
  live.start("a test film", 16, true, 0, 0.01);
  live.pass_done(film);
  int stops = 0;
  PreviewServer server(parse_preview_address("127.0.0.1:0"), live, [&] { ++stops; });
  ASSERT_GT(server.port(), 0);
  EXPECT_EQ(server.url(), "http://127.0.0.1:" + std::to_string(server.port()) + "/?token=" + server.token());
  httplib::Client client("127.0.0.1", server.port());
  client.set_default_headers({{"X-Candela-Token", server.token()}});

  auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<canvas id=\"image\""), std::string::npos);

  auto status = client.Get("/status");
  ASSERT_TRUE(status);
  nlohmann::json j = nlohmann::json::parse(status->body);
  EXPECT_EQ(j["state"], "rendering");
  EXPECT_EQ(j["description"], "a test film");
  EXPECT_EQ(j["width"], 40);
  EXPECT_EQ(j["adaptive"], true);
  EXPECT_EQ(j["planned_spp"], 16);
  EXPECT_DOUBLE_EQ(j["mean_spp"].get<double>(), 1.0);

  // Full size: RGBA floats, A the sample count.
  auto image = client.Get("/image");
  ASSERT_TRUE(image);
  ASSERT_EQ(image->get_header_value("X-Width"), "40");
  ASSERT_EQ(image->body.size(), 40u * 30u * 4u * sizeof(float));
  float px[4];
  std::memcpy(px, image->body.data() + (7 * 40 + 5) * 4 * sizeof(float), sizeof(px));
  EXPECT_EQ(px[0], 5.0f);
  EXPECT_EQ(px[1], 7.0f);
  EXPECT_EQ(px[3], 1.0f);
  // Averaged down by 3 to fit 16 pixels (40 / 3 rounded up = 14 wide, 10 high).
  auto small = client.Get("/image?max=16");
  ASSERT_TRUE(small);
  EXPECT_EQ(small->get_header_value("X-Width"), "14");
  EXPECT_EQ(small->get_header_value("X-Height"), "10");
  std::memcpy(px, small->body.data() + (1 * 14 + 2) * 4 * sizeof(float), sizeof(px));
  EXPECT_FLOAT_EQ(px[0], 7.0f);  // the mean of x = 6, 7, 8
  EXPECT_FLOAT_EQ(px[1], 4.0f);  // of y = 3, 4, 5

  auto stop = client.Post("/stop", "", "text/plain");
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->status, 200);
  client.Post("/stop", "", "text/plain");
  EXPECT_EQ(stops, 1) << "pressed twice, stopped once";
  status = client.Get("/status");
  ASSERT_TRUE(status);
  EXPECT_EQ(nlohmann::json::parse(status->body)["state"], "stopping");
  live.finish(LiveState::Stopped);
  status = client.Get("/status");
  ASSERT_TRUE(status);
  EXPECT_EQ(nlohmann::json::parse(status->body)["state"], "stopped");
}

TEST(PreviewServer, RefusesAPortInUse) {
  LiveFilm live(4, 4);
  PreviewServer first(parse_preview_address("127.0.0.1:0"), live, nullptr);
  try {
    PreviewServer second(parse_preview_address("127.0.0.1:" + std::to_string(first.port())), live, nullptr);
    FAIL() << "bound a port in use";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot listen"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace candela
