// Camera intrinsics in the ROS camera_info YAML format (camera_info_yaml.h), and recorded with
// every frame.
#include "mapless/recording/camera_info_yaml.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "mapless/core/check.h"
#include "mapless/recording/mcap_reader.h"
#include "mapless/recording/run_recorder.h"

namespace mapless::recording {
namespace {

// As camera_calibration writes it (the ROS camera_calibration_parsers format).
constexpr const char* kCalibrated = R"(image_width: 640
image_height: 480
camera_name: narrow_stereo
camera_matrix:
  rows: 3
  cols: 3
  data: [430.21554, 0, 306.6913, 0, 430.53169, 227.22667, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.337626, 0.116711, -0.000531, -0.000302, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [361.2406, 0, 303.27344, 0, 0, 387.31818, 223.03714, 0, 0, 0, 1, 0]
)";

TEST(CameraInfoYaml, ReadsWhatCameraCalibrationWritesAndWritesItBack) {
  const rosmsg::CameraInfoFields info = ParseCameraInfoYaml(kCalibrated, "cam.yaml");
  EXPECT_EQ(info.width, 640u);
  EXPECT_EQ(info.height, 480u);
  EXPECT_DOUBLE_EQ(info.k[0], 430.21554);
  EXPECT_DOUBLE_EQ(info.k[5], 227.22667);
  ASSERT_EQ(info.d.size(), 5u);
  EXPECT_DOUBLE_EQ(info.d[0], -0.337626);
  EXPECT_DOUBLE_EQ(info.p[6], 223.03714);
  const rosmsg::CameraInfoFields again =
      ParseCameraInfoYaml(FormatCameraInfoYaml(info), "again.yaml");
  EXPECT_EQ(again.k, info.k);
  EXPECT_EQ(again.d, info.d);
  EXPECT_EQ(again.r, info.r);
  EXPECT_EQ(again.p, info.p);
  EXPECT_EQ(again.distortion_model, info.distortion_model);
  // Only the size and K: no distortion, R the identity, P = [K | 0].
  const rosmsg::CameraInfoFields minimal = ParseCameraInfoYaml(
      "image_width: 320\nimage_height: 240\ncamera_matrix: {rows: 3, cols: 3, data: [200, 0, "
      "160, 0, 200, 120, 0, 0, 1]}\n",
      "min.yaml");
  EXPECT_TRUE(minimal.d.empty());
  EXPECT_EQ(minimal.r[4], 1.0);
  EXPECT_EQ(minimal.p[2], 160.0);
  EXPECT_EQ(minimal.p[3], 0.0);
}

TEST(CameraInfoYaml, BadFilesGiveOneErrorNamingTheField) {
  const auto error = [](const std::string& text) {
    try {
      ParseCameraInfoYaml(text, "cam.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string size = "image_width: 320\nimage_height: 240\n";
  const std::string k =
      "camera_matrix: {rows: 3, cols: 3, data: [200, 0, 160, 0, 200, 120, 0, 0, 1]}\n";
  EXPECT_NE(error("image_height: 240\n" + k).find("image_width"), std::string::npos);
  EXPECT_NE(error(size).find("camera_matrix"), std::string::npos);
  EXPECT_NE(error(size + "camera_matrix: {rows: 3, cols: 2, data: [1, 0, 0, 1, 0, 0]}\n")
                .find("expected 3 x 3"),
            std::string::npos);
  EXPECT_NE(error(size + "camera_matrix: {rows: 3, cols: 3, data: [1, 2]}\n").find("data"),
            std::string::npos);
  EXPECT_NE(error(size + "camera_matrix: {rows: 3, cols: 3, data: [0, 0, 160, 0, 200, 120, 0, 0, "
                         "1]}\n")
                .find("focal lengths"),
            std::string::npos);
  EXPECT_NE(error(size + k + "camera_matrx: 1\n").find("camera_matrx"), std::string::npos);
  EXPECT_NE(error("image_width: 99999\nimage_height: 240\n" + k).find("image_width"),
            std::string::npos);
  EXPECT_NE(error(size + k + "projection_matrix: {rows: 3, cols: 3, data: [1,0,0,0,1,0,0,0,1]}\n")
                .find("projection_matrix"),
            std::string::npos);
  EXPECT_NE(error(size + k +
                  "distortion_coefficients: {rows: 1, cols: 5, data: [.nan, 0, 0, 0, "
                  "0]}\n")
                .find("distortion_coefficients"),
            std::string::npos);
  EXPECT_NE(error("[1, 2").find("cam.yaml"), std::string::npos);
}

TEST(CameraInfoYaml, RecordedWithEveryFrameAndCheckedAgainstItsSize) {
  const std::string path = ::testing::TempDir() + "mapless_camera_info.mcap";
  std::filesystem::remove(path);
  RunRecorderOptions options;
  options.camera_info = ParseCameraInfoYaml(kCalibrated, "cam.yaml");
  {
    RunRecorder recorder(path, options);
    recorder.Image(1'000'000, cv::Mat(480, 640, CV_8UC1, cv::Scalar(7)));
    recorder.Image(2'000'000, cv::Mat(480, 640, CV_8UC1, cv::Scalar(9)));
    // A frame of another size than the intrinsics' is refused, naming both sizes.
    try {
      recorder.Image(3'000'000, cv::Mat(240, 320, CV_8UC1, cv::Scalar(9)));
      ADD_FAILURE() << "a 320x240 frame was recorded with 640x480 intrinsics";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("640x480"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("320x240"), std::string::npos) << e.what();
    }
  }
  McapReader reader(path);
  int infos = 0;
  reader.ForEachMessage([&](const McapChannel& channel, const McapSchema*, const McapMessage& m) {
    if (channel.topic != kCameraInfoTopic) return;
    const rosmsg::CameraInfoFields got = rosmsg::DecodeCameraInfo(m.data, rosmsg::Wire::kCdr);
    EXPECT_EQ(got.k, options.camera_info->k);
    EXPECT_EQ(got.d, options.camera_info->d);
    EXPECT_EQ(got.width, 640u);
    ++infos;
  });
  EXPECT_EQ(infos, 2);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace mapless::recording
