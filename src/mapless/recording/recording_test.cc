// Recording runs and playing recordings (run_recorder.h, recording_link.h, playback.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/core/testing.h"
#include "mapless/io/atomic_file.h"
#include "mapless/recording/mcap_reader.h"
#include "mapless/recording/mcap_source.h"
#include "mapless/recording/playback.h"
#include "mapless/recording/run_recorder.h"
#include "mapless/recording/tum_poses.h"
#include "mapless/rosmsg/messages.h"

namespace mapless::recording {
namespace {

namespace fs = std::filesystem;

std::string FreshRecordingPath(const std::string& name) {
  const std::string path = ::testing::TempDir() + "mapless_recording_" + name + ".mcap";
  fs::remove(path);
  return path;
}

cv::Mat Pattern(int i) {
  cv::Mat img(48, 64, CV_8UC1);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x)
      img.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>((x * 3 + y * 5 + i * 7) & 255);
  return img;
}

Timestamp FrameTime(int i) { return 100'000'000LL * i; }

// `n` frames at 10 Hz, each with odometry written after its image (as RecordingLink does), a
// command and a decision.
void RecordFrames(const std::string& path, int n, const std::string& images = "raw") {
  RunRecorderOptions options;
  options.images = images;
  options.mcap.chunk_ns = 300'000'000;  // several chunks
  RunRecorder rec(path, options);
  for (int i = 0; i < n; ++i) {
    rec.Image(FrameTime(i), Pattern(i));
    rec.Odometry(FrameTime(i), Pose2{0.1 * i, 0.0, 0.01 * i});
    rec.GroundTruth(FrameTime(i), Pose2{0.1 * i, 0.001, 0.0});
    rec.Command(FrameTime(i), Twist2{0.2, 0.0});
    rec.Decision(FrameTime(i), {{"frame", i}});
  }
  rec.Close();
}

TEST(Recording, FramesPlayBackWithTheirTimesAndOdometry) {
  const std::string path = FreshRecordingPath("frames");
  RecordFrames(path, 25);
  std::unique_ptr<io::FrameSource> source = OpenSource(path, {});
  io::Frame f;
  for (int i = 0; i < 25; ++i) {
    ASSERT_TRUE(source->Next(&f)) << i;
    EXPECT_EQ(f.t_ns, FrameTime(i));
    EXPECT_EQ(cv::norm(f.image, Pattern(i), cv::NORM_INF), 0.0) << i;
    ASSERT_TRUE(f.odometry.has_value()) << i;
    EXPECT_DOUBLE_EQ(f.odometry->x_m, 0.1 * i);  // its own odometry, written after it
  }
  EXPECT_FALSE(source->Next(&f));
}

TEST(Recording, CompressedFramesPlayBack) {
  for (const std::string images : {"png", "jpeg"}) {
    const std::string path = FreshRecordingPath("compressed_" + images);
    RecordFrames(path, 5, images);
    std::unique_ptr<io::FrameSource> source = OpenSource(path, {});
    io::Frame f;
    for (int i = 0; i < 5; ++i) {
      ASSERT_TRUE(source->Next(&f)) << images << " " << i;
      const double err = cv::norm(f.image, Pattern(i), cv::NORM_L1) / f.image.total();
      if (images == "png")
        EXPECT_EQ(err, 0.0);
      else
        EXPECT_LT(err, 6.0);  // jpeg at quality 90
    }
  }
}

TEST(Recording, StartAndLoopLikeRos2BagPlay) {
  const std::string path = FreshRecordingPath("loop");
  RecordFrames(path, 10);
  PlaybackOptions options;
  options.start_s = 0.45;  // frames 5..9
  options.loop = true;
  std::unique_ptr<io::FrameSource> source = OpenSource(path, options);
  io::Frame f;
  std::vector<Timestamp> times;
  for (int i = 0; i < 12; ++i) {
    ASSERT_TRUE(source->Next(&f));
    times.push_back(f.t_ns);
    EXPECT_EQ(cv::norm(f.image, Pattern(5 + i % 5), cv::NORM_INF), 0.0) << i;
  }
  for (std::size_t i = 1; i < times.size(); ++i)
    EXPECT_EQ(times[i] - times[i - 1], 100'000'000) << "time goes on across a loop, " << i;
}

TEST(Recording, TopicsAreChosenOrRefusedByName) {
  const std::string path = FreshRecordingPath("topics");
  RecordFrames(path, 3);
  McapReader reader(path);
  std::vector<std::string> names;
  for (const RecordedTopic& t : McapTopics(reader)) names.push_back(t.topic + " " + t.type);
  EXPECT_EQ(names,
            (std::vector<std::string>{
                "/camera/image_raw sensor_msgs/msg/Image", "/cmd_vel geometry_msgs/msg/Twist",
                "/ground_truth geometry_msgs/msg/PoseStamped", "/mapless/decision mapless/Decision",
                "/odom nav_msgs/msg/Odometry"}));
  PlaybackOptions options;
  options.topic = "/cmd_vel";
  EXPECT_NE(testing::InputErrorOf([&] {
              OpenSource(path, options);
            }).find("topic /cmd_vel is geometry_msgs/msg/Twist, not camera image"),
            std::string::npos);
  options.topic = "/front/image";
  EXPECT_NE(testing::InputErrorOf([&] { OpenSource(path, options); }).find("no topic /front/image"),
            std::string::npos);
  options.topic = "/camera/image_raw";
  options.odom_topic = "none";
  io::Frame f;
  ASSERT_TRUE(OpenSource(path, options)->Next(&f));
  EXPECT_FALSE(f.odometry.has_value());
}

TEST(Recording, ACutRecordingPlaysEveryWholeFrameBeforeTheCut) {
  const std::string path = FreshRecordingPath("cut");
  RecordFrames(path, 30);
  const auto size = fs::file_size(path);
  fs::resize_file(path, size * 2 / 3);
  std::unique_ptr<io::FrameSource> source = OpenSource(path, {});
  io::Frame f;
  int n = 0;
  while (source->Next(&f)) {
    EXPECT_EQ(cv::norm(f.image, Pattern(n), cv::NORM_INF), 0.0) << n;
    ++n;
  }
  EXPECT_GT(n, 6);  // the chunks before the cut (3 frames a chunk)
  EXPECT_LT(n, 30);
}

TEST(Recording, RecorderRefusesToOverwrite) {
  const std::string path = FreshRecordingPath("exists");
  RecordFrames(path, 1);
  EXPECT_THROW(RecordFrames(path, 1), InputError);
  EXPECT_THROW(RecordFrames(FreshRecordingPath("bad_images"), 1, "bmp"), InputError);
}

// The fixtures of foxglove/rosbag (tests/data/rosbag1/README.md): the same recording stored
// uncompressed, with lz4 and with bz2 chunks.
// An image folder at 10 Hz with TUM poses (--poses): each frame carries the newest pose not later
// than its time, counted from the first pose; past the trajectory's end (plus kPosesCoverS), none.
TEST(Recording, TumPosesAreTheOdometryOfAFolder) {
  const fs::path dir = fs::path(::testing::TempDir()) / "mapless_recording_poses";
  fs::remove_all(dir);
  fs::create_directories(dir / "frames");
  for (int i = 0; i < 30; ++i) {
    char name[16];
    std::snprintf(name, sizeof(name), "%03d.png", i);
    io::WriteImageAtomic((dir / "frames" / name).string(), Pattern(i));
  }
  // Poses every 0.2 s from t = 1000 s to 1001.4 s: frame i is at 1000 + i / 10 s.
  std::string tum = "# timestamp tx ty tz qx qy qz qw\n";
  for (int k = 0; k <= 7; ++k) {
    tum += std::to_string(1000.0 + 0.2 * k) + " " + std::to_string(k) + " 0 0 0 0 0 1\n";
  }
  io::WriteFileAtomic((dir / "odometry.tum").string(), tum);
  PlaybackOptions options;
  options.poses = (dir / "odometry.tum").string();
  const auto source = OpenSource((dir / "frames").string(), options);
  io::Frame frame;
  for (int i = 0; i < 30; ++i) {
    ASSERT_TRUE(source->Next(&frame)) << i;
    EXPECT_NEAR(ToSeconds(frame.t_ns), 1000.0 + 0.1 * i, 1e-6) << i;
    if (i <= 24) {  // the last pose is at 1001.4 s; frames up to 1002.4 s still carry it
      ASSERT_TRUE(frame.odometry.has_value()) << i;
      EXPECT_DOUBLE_EQ(frame.odometry->x_m, std::min(i / 2, 7)) << i;
    } else {
      EXPECT_FALSE(frame.odometry.has_value()) << i;
    }
  }
  EXPECT_FALSE(source->Next(&frame));

  // Bad trajectories: one error naming the file and the pose or line.
  const auto refused = [&](const std::string& text, const std::string& what) {
    io::WriteFileAtomic((dir / "bad.tum").string(), text);
    options.poses = (dir / "bad.tum").string();
    try {
      OpenSource((dir / "frames").string(), options);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.tum"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused("# only a header\n", "no poses");
  refused("1 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n", "pose 2 at 0.5");
  refused("1 0 0 0 0 0 0 1\n2 1e999 0 0 0 0 0 1\n", ":2: ");  // overflows: not a number
  refused("1e12 0 0 0 0 0 0 1\n", ":1: timestamp");
  refused("1 0 0 0\n2 0 0 0 0 0 0 1\n", ":1: expected 8 numbers");
  // A recording has its own odometry topic; a camera has no time to match poses with.
  options.poses = (dir / "odometry.tum").string();
  EXPECT_THROW(OpenSource((dir / "run.mcap").string(), options), InputError);
  EXPECT_THROW(OpenSource("camera:0", options), InputError);
  fs::remove_all(dir);
}

TEST(RosBag, TheThreeCompressionsGiveTheSameMessages) {
  if (!CanReadBags()) GTEST_SKIP() << "mapless was built without ROS 1 bags (setup.sh --ros)";
  const std::string dir = std::string(MAPLESS_SOURCE_DIR) + "/tests/data/rosbag1/";
  std::vector<std::vector<std::string>> all;
  for (const char* name : {"example.bag", "example-lz4.bag", "example-bz2.bag"}) {
    std::unique_ptr<MessageStream> bag = OpenBagMessages(dir + name);
    std::vector<std::string> seen;
    RecordedMessage m;
    int twists = 0;
    while (bag->Next(&m)) {
      std::string line = m.topic->topic + " " + std::to_string(m.log_ns);
      if (m.topic->type == "geometry_msgs/msg/Twist") {
        const Twist2 t = rosmsg::DecodeTwist(m.data, rosmsg::Wire::kRos1);
        line += " " + std::to_string(t.v_mps) + " " + std::to_string(t.omega_radps);
        ++twists;
      }
      seen.push_back(line);
    }
    EXPECT_EQ(seen.size(), 8647u) << name;
    EXPECT_GT(twists, 0) << name;
    all.push_back(seen);
  }
  EXPECT_EQ(all[0], all[1]);
  EXPECT_EQ(all[0], all[2]);
  RecordedMessage m;
  EXPECT_FALSE(OpenBagMessages(dir + "no-messages.bag")->Next(&m));
  // No camera in these bags: a clear error naming the file and the topics it has.
  const std::string error = testing::InputErrorOf([&] { OpenSource(dir + "example.bag", {}); });
  EXPECT_NE(error.find("example.bag: no camera image topic (topics: /rosout"), std::string::npos)
      << error;
}

// rosbag_storage trusts the lengths in a bag; bag_check.h must refuse a bad one before the
// library reads it (under ASan, an over-read or a huge allocation here fails the test).
TEST(RosBag, BadLengthsAreRefusedBeforeTheLibraryReadsThem) {
  if (!CanReadBags()) GTEST_SKIP() << "mapless was built without ROS 1 bags (setup.sh --ros)";
  const std::string good = io::ReadFile(
      std::string(MAPLESS_SOURCE_DIR) + "/tests/data/rosbag1/example-lz4.bag", 1u << 20);
  ASSERT_GT(good.size(), 100000u);
  const std::string path = ::testing::TempDir() + "mapless_recording_bad.bag";
  const auto read_all = [&](const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    return testing::InputErrorOf([&] {
      std::unique_ptr<MessageStream> bag = OpenBagMessages(path);
      RecordedMessage m;
      while (bag->Next(&m)) {
      }
    });
  };
  EXPECT_EQ(read_all(good), "");
  std::string bad = good;
  bad.replace(13, 4, std::string("\xff\xff\xff\x7f", 4));  // the bag header's header length
  std::string error = read_all(bad);
  EXPECT_NE(error.find("mapless_recording_bad.bag: not a readable ROS 1 bag: at byte 13: a record "
                       "header of 2147483647 bytes"),
            std::string::npos)
      << error;
  // The first chunk says it decompresses to 4 GB.
  const std::size_t size_field = good.find("size=");  // the first chunk's header
  ASSERT_NE(size_field, std::string::npos);
  ASSERT_LT(good.find("compression=lz4") - size_field, 40u);
  bad = good;
  bad.replace(size_field + 5, 4, std::string("\xff\xff\xff\xff", 4));
  error = read_all(bad);
  EXPECT_NE(error.find("a chunk of 4294967295 bytes (at most"), std::string::npos) << error;
  // Cut short (the index at the end is gone): refused, with the reason.
  error = read_all(good.substr(0, good.size() / 2));
  EXPECT_NE(error.find("runs past the end"), std::string::npos) << error;
  // Four bytes of 0xff at 40 places spread over the file: each bag is read to its end or refused
  // with one error naming the file.
  int refused = 0;
  for (int k = 0; k < 40; ++k) {
    bad = good;
    bad.replace(13 + (good.size() - 20) * static_cast<std::size_t>(k) / 40 + k % 7, 4,
                std::string("\xff\xff\xff\xff", 4));
    error = read_all(bad);
    if (error.empty()) continue;
    ++refused;
    EXPECT_EQ(error.rfind(path, 0), 0u) << error;
  }
  EXPECT_GT(refused, 0);
  fs::remove(path);
}

}  // namespace
}  // namespace mapless::recording
