#include "mapless/rosmsg/messages.h"

#include <gtest/gtest.h>

#include <cstring>

#include "mapless/core/check.h"
#include "mapless/rosmsg/definitions.h"

namespace mapless::rosmsg {
namespace {

std::string_view View(const std::vector<std::uint8_t>& b) {
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

TEST(RosMsgCdr, TwistHasTheLayoutOfCdr) {
  const std::vector<std::uint8_t> b = EncodeTwist({0.25, -0.5});
  ASSERT_EQ(b.size(), 4u + 6 * 8);  // header, six float64 (aligned from byte 4)
  EXPECT_EQ(b[0], 0);
  EXPECT_EQ(b[1], 1);  // CDR_LE
  double v = 0.0;
  std::memcpy(&v, b.data() + 4, 8);
  EXPECT_EQ(v, 0.25);
  std::memcpy(&v, b.data() + 4 + 40, 8);
  EXPECT_EQ(v, -0.5);
  const Twist2 t = DecodeTwist(View(b), Wire::kCdr);
  EXPECT_EQ(t.v_mps, 0.25);
  EXPECT_EQ(t.omega_radps, -0.5);
}

TEST(RosMsgCdr, ImageRoundTripsWithAlignment) {
  const std::string pixels = "abcdefghijkl";
  ImageFields in;
  in.header = {-1'500'000'000, "camera"};  // before the epoch: sec -2, nanosec 5e8
  in.height = 3;
  in.width = 4;
  in.encoding = "mono8";
  in.step = 4;
  in.data = pixels;
  const std::vector<std::uint8_t> b = EncodeImage(in);
  // stamp 8, frame_id 4+7, pad to 20 -> height, width at 20, 24; encoding 4+6 at 28..37;
  // is_bigendian at 38; pad; step at 40; data length at 44; data at 48.
  ASSERT_EQ(b.size(), 4u + 48 + 12);
  const ImageFields out = DecodeImage(View(b), Wire::kCdr);
  EXPECT_EQ(out.header.stamp_ns, -1'500'000'000);
  EXPECT_EQ(out.header.frame_id, "camera");
  EXPECT_EQ(out.height, 3u);
  EXPECT_EQ(out.width, 4u);
  EXPECT_EQ(out.encoding, "mono8");
  EXPECT_FALSE(out.big_endian);
  EXPECT_EQ(out.step, 4u);
  EXPECT_EQ(out.data, pixels);
}

TEST(RosMsgCdr, OdometryCameraInfoAndPoseRoundTrip) {
  OdometryFields odo;
  odo.header = {1'732'454'400'123'456'789, "odom"};
  odo.child_frame_id = "base_link";
  odo.pose = {1.5, -2.25, 0.75};
  odo.twist = {0.2, 0.1};
  const OdometryFields o = DecodeOdometry(View(EncodeOdometry(odo)), Wire::kCdr);
  EXPECT_EQ(o.header.stamp_ns, odo.header.stamp_ns);
  EXPECT_EQ(o.child_frame_id, "base_link");
  EXPECT_DOUBLE_EQ(o.pose.x_m, 1.5);
  EXPECT_DOUBLE_EQ(o.pose.y_m, -2.25);
  EXPECT_NEAR(o.pose.theta_rad, 0.75, 1e-12);
  EXPECT_EQ(o.twist.v_mps, 0.2);
  EXPECT_EQ(o.twist.omega_radps, 0.1);

  CameraInfoFields info;
  info.header.frame_id = "camera";
  info.width = 320;
  info.height = 240;
  info.d = {0.1, 0.0, 0.0, 0.0, 0.0};
  info.k = {200, 0, 160, 0, 200, 120, 0, 0, 1};
  const CameraInfoFields c = DecodeCameraInfo(View(EncodeCameraInfo(info)), Wire::kCdr);
  EXPECT_EQ(c.width, 320u);
  EXPECT_EQ(c.distortion_model, "plumb_bob");
  EXPECT_EQ(c.d, info.d);
  EXPECT_EQ(c.k, info.k);

  const PoseStampedFields p =
      DecodePoseStamped(View(EncodePoseStamped({{5, "world"}, {1, 2, -3}})), Wire::kCdr);
  EXPECT_EQ(p.header.frame_id, "world");
  EXPECT_NEAR(p.pose.theta_rad, -3, 1e-12);
}

TEST(RosMsgWire, ReadsBigEndianCdr) {
  std::vector<std::uint8_t> b = {0, 0, 0, 0};  // CDR_BE
  auto put64 = [&](double v) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    for (int i = 7; i >= 0; --i) b.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
  };
  for (double v : {0.5, 0.0, 0.0, 0.0, 0.0, -1.0}) put64(v);
  const Twist2 t = DecodeTwist(View(b), Wire::kCdr);
  EXPECT_EQ(t.v_mps, 0.5);
  EXPECT_EQ(t.omega_radps, -1.0);
}

TEST(RosMsgWire, ReadsRos1Images) {
  // ROS 1: seq, time (uint32 sec, nsec), strings and arrays with a length and no NUL, packed.
  std::string b;
  auto u32 = [&](std::uint32_t v) { b.append(reinterpret_cast<const char*>(&v), 4); };
  auto str = [&](const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    b += s;
  };
  u32(7);
  u32(100);
  u32(5);
  str("cam");
  u32(2);
  u32(3);
  str("mono8");
  b.push_back('\0');
  u32(3);
  str("abcdef");
  const ImageFields m = DecodeImage(b, Wire::kRos1);
  EXPECT_EQ(m.header.stamp_ns, 100'000'000'005);
  EXPECT_EQ(m.header.frame_id, "cam");
  EXPECT_EQ(m.height, 2u);
  EXPECT_EQ(m.width, 3u);
  EXPECT_EQ(m.encoding, "mono8");
  EXPECT_EQ(m.data, "abcdef");
}

TEST(RosMsgWire, RefusesShortAndOversizedFieldsNamingThem) {
  std::vector<std::uint8_t> b = EncodeImage({{0, "c"}, 1, 1, "mono8", false, 1, "x"});
  b.resize(b.size() - 1);
  try {
    DecodeImage(View(b), Wire::kCdr);
    FAIL() << "decoded a cut image";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sensor_msgs/Image.data"), std::string::npos) << e.what();
  }
  std::vector<std::uint8_t> huge = {0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff, 0xff, 0xff};
  EXPECT_THROW(DecodeCompressedImage(View(huge), Wire::kCdr), InputError);
  EXPECT_THROW(DecodeTwist(std::string_view("\x00\x02\x00\x00", 4), Wire::kCdr), InputError);
  EXPECT_THROW(DecodeTwist(std::string_view(), Wire::kCdr), InputError);
}

TEST(RosMsgDefinitions, CameraInfoNamesItsRegionOfInterest) {
  const std::string text = ConcatenatedDefinition("sensor_msgs/msg/CameraInfo");
  EXPECT_NE(text.find("float64[9] k\n"), std::string::npos);
  EXPECT_NE(text.find("sensor_msgs/RegionOfInterest roi\n"), std::string::npos);
  EXPECT_NE(text.find("MSG: sensor_msgs/RegionOfInterest\n"), std::string::npos);
}

}  // namespace
}  // namespace mapless::rosmsg
