// The --frames list and the frame-numbered output names.
#include "candela/animation/frames.h"

#include <gtest/gtest.h>

#include "candela/base/error.h"

namespace candela {
namespace {

TEST(FrameList, RangesStepsAndLists) {
  EXPECT_EQ(parse_frame_list("1-4"), (std::vector<int>{1, 2, 3, 4}));
  EXPECT_EQ(parse_frame_list("1-10x4"), (std::vector<int>{1, 5, 9}));
  EXPECT_EQ(parse_frame_list("7"), (std::vector<int>{7}));
  EXPECT_EQ(parse_frame_list("3,1,20-22"), (std::vector<int>{3, 1, 20, 21, 22}));
  EXPECT_EQ(parse_frame_list("0-0"), (std::vector<int>{0}));
}

TEST(FrameList, RefusesWhatIsNotAFrameList) {
  for (const char* bad : {"", "1,", ",1", "a", "1-", "-3", "5-1", "1-10x0", "1-10x", "1.5", "1,1", "1-3,2", "99999999",
                          "0-9999999x1"}) {
    try {
      parse_frame_list(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find("--frames"), std::string::npos) << e.what();
    }
  }
}

TEST(FrameList, FileNamesCarryTheFrameNumber) {
  EXPECT_TRUE(has_frame_placeholder("shot_####.exr"));
  EXPECT_FALSE(has_frame_placeholder("shots#1/take.exr"));  // a '#' in a directory is not the frame's
  EXPECT_EQ(frame_file_name("shot_####.exr", 7), "shot_0007.exr");
  EXPECT_EQ(frame_file_name("shot_#.exr", 123), "shot_123.exr");
  EXPECT_EQ(frame_file_name("a#/b_##_c_###.png", 5), "a#/b_##_c_005.png");
  EXPECT_EQ(frame_file_name("still.exr", 5), "still.exr");
}

TEST(FrameList, PartsShareTheFramesOut) {
  const std::vector<int> frames = parse_frame_list("1-10");
  EXPECT_EQ(frames_of_part(frames, 0, 4), (std::vector<int>{1, 5, 9}));
  EXPECT_EQ(frames_of_part(frames, 3, 4), (std::vector<int>{4, 8}));
  std::vector<int> all;
  for (int k = 0; k < 3; ++k)
    for (int f : frames_of_part(frames, k, 3)) all.push_back(f);
  std::sort(all.begin(), all.end());
  EXPECT_EQ(all, frames);
  EXPECT_TRUE(frames_of_part(parse_frame_list("1-2"), 2, 3).empty());
}

}  // namespace
}  // namespace candela
