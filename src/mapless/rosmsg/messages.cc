#include "mapless/rosmsg/messages.h"

#include <cmath>

#include "mapless/core/check.h"

namespace mapless::rosmsg {

namespace {

// CameraInfo.d: plumb_bob has 5, rational_polynomial 8, equidistant 4; more is not a camera.
constexpr std::uint32_t kMaxDistortion = 64;

void WriteHeader(CdrWriter& w, const Header& h) {
  w.Time(h.stamp_ns);
  w.String(h.frame_id);
}

Header ReadHeader(WireReader& r, Wire wire) {
  Header h;
  if (wire == Wire::kRos1) r.U32("header.seq");
  h.stamp_ns = r.Time("header.stamp");
  h.frame_id = r.String("header.frame_id");
  return h;
}

void WritePose(CdrWriter& w, const Pose2& p) {
  w.F64(p.x_m);
  w.F64(p.y_m);
  w.F64(0.0);
  w.F64(0.0);  // quaternion about z
  w.F64(0.0);
  w.F64(std::sin(p.theta_rad / 2.0));
  w.F64(std::cos(p.theta_rad / 2.0));
}

Pose2 ReadPose(WireReader& r) {
  Pose2 p;
  p.x_m = r.F64("pose.position.x");
  p.y_m = r.F64("pose.position.y");
  r.F64("pose.position.z");
  const double qx = r.F64("pose.orientation.x");
  const double qy = r.F64("pose.orientation.y");
  const double qz = r.F64("pose.orientation.z");
  const double qw = r.F64("pose.orientation.w");
  p.theta_rad = YawFromQuaternion(qx, qy, qz, qw);
  return p;
}

void WriteTwist(CdrWriter& w, const Twist2& t) {
  w.F64(t.v_mps);
  w.F64(0.0);
  w.F64(0.0);
  w.F64(0.0);
  w.F64(0.0);
  w.F64(t.omega_radps);
}

Twist2 ReadTwist(WireReader& r) {
  Twist2 t;
  t.v_mps = r.F64("linear.x");
  r.F64("linear.y");
  r.F64("linear.z");
  r.F64("angular.x");
  r.F64("angular.y");
  t.omega_radps = r.F64("angular.z");
  return t;
}

void Covariance(CdrWriter& w) {
  for (int i = 0; i < 36; ++i) w.F64(0.0);
}

void SkipCovariance(WireReader& r) {
  for (int i = 0; i < 36; ++i) r.F64("covariance");
}

}  // namespace

std::vector<std::uint8_t> EncodeImage(const ImageFields& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  w.U32(m.height);
  w.U32(m.width);
  w.String(m.encoding);
  w.U8(m.big_endian ? 1 : 0);
  w.U32(m.step);
  w.Bytes(m.data);
  return w.Take();
}

std::vector<std::uint8_t> EncodeCompressedImage(const CompressedImageFields& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  w.String(m.format);
  w.Bytes(m.data);
  return w.Take();
}

std::vector<std::uint8_t> EncodeCameraInfo(const CameraInfoFields& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  w.U32(m.height);
  w.U32(m.width);
  w.String(m.distortion_model);
  w.F64Sequence(m.d);
  for (double v : m.k) w.F64(v);
  for (double v : m.r) w.F64(v);
  for (double v : m.p) w.F64(v);
  w.U32(0);                              // binning_x
  w.U32(0);                              // binning_y
  for (int i = 0; i < 4; ++i) w.U32(0);  // roi: the full image
  w.Bool(false);
  return w.Take();
}

std::vector<std::uint8_t> EncodeTwist(const Twist2& m) {
  CdrWriter w;
  WriteTwist(w, m);
  return w.Take();
}

std::vector<std::uint8_t> EncodeOdometry(const OdometryFields& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  w.String(m.child_frame_id);
  WritePose(w, m.pose);
  Covariance(w);
  WriteTwist(w, m.twist);
  Covariance(w);
  return w.Take();
}

std::vector<std::uint8_t> EncodePoseStamped(const PoseStampedFields& m) {
  CdrWriter w;
  WriteHeader(w, m.header);
  WritePose(w, m.pose);
  return w.Take();
}

ImageFields DecodeImage(std::string_view bytes, Wire wire) {
  WireReader r(bytes, wire, "sensor_msgs/Image");
  ImageFields m;
  m.header = ReadHeader(r, wire);
  m.height = r.U32("height");
  m.width = r.U32("width");
  m.encoding = r.String("encoding");
  m.big_endian = r.U8("is_bigendian") != 0;
  m.step = r.U32("step");
  m.data = r.Bytes("data");
  return m;
}

CompressedImageFields DecodeCompressedImage(std::string_view bytes, Wire wire) {
  WireReader r(bytes, wire, "sensor_msgs/CompressedImage");
  CompressedImageFields m;
  m.header = ReadHeader(r, wire);
  m.format = r.String("format");
  m.data = r.Bytes("data");
  return m;
}

CameraInfoFields DecodeCameraInfo(std::string_view bytes, Wire wire) {
  WireReader r(bytes, wire, "sensor_msgs/CameraInfo");
  CameraInfoFields m;
  m.header = ReadHeader(r, wire);
  m.height = r.U32("height");
  m.width = r.U32("width");
  m.distortion_model = r.String("distortion_model");
  // ROS 1 names them D, K, R, P; the layout is the same.
  m.d = r.F64Sequence("d", kMaxDistortion);
  for (double& v : m.k) v = r.F64("k");
  for (double& v : m.r) v = r.F64("r");
  for (double& v : m.p) v = r.F64("p");
  return m;  // binning and roi are not used
}

Twist2 DecodeTwist(std::string_view bytes, Wire wire) {
  WireReader r(bytes, wire, "geometry_msgs/Twist");
  return ReadTwist(r);
}

OdometryFields DecodeOdometry(std::string_view bytes, Wire wire) {
  WireReader r(bytes, wire, "nav_msgs/Odometry");
  OdometryFields m;
  m.header = ReadHeader(r, wire);
  m.child_frame_id = r.String("child_frame_id");
  m.pose = ReadPose(r);
  SkipCovariance(r);
  m.twist = ReadTwist(r);
  SkipCovariance(r);
  return m;
}

PoseStampedFields DecodePoseStamped(std::string_view bytes, Wire wire) {
  WireReader r(bytes, wire, "geometry_msgs/PoseStamped");
  PoseStampedFields m;
  m.header = ReadHeader(r, wire);
  m.pose = ReadPose(r);
  return m;
}

}  // namespace mapless::rosmsg
