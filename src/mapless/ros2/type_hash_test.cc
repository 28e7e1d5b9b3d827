#include "mapless/ros2/type_hash.h"

#include <gtest/gtest.h>

namespace mapless::ros2 {
namespace {

// The hashes ROS 2 Jazzy prints for these types (`ros2 topic info -v`, "Topic type hash"), as
// published in the ROS 2 documentation and in the outputs of many public projects.
TEST(TypeHash, MatchesTheHashesRos2JazzyPublishes) {
  const std::pair<const char*, const char*> kJazzy[] = {
      {"geometry_msgs/msg/Twist",
       "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"},
      {"std_msgs/msg/String",
       "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"},
      {"std_msgs/msg/Bool",
       "RIHS01_feb91e995ff9ebd09c0cb3d2aed18b11077585839fb5db80193b62d74528f6c9"},
      {"sensor_msgs/msg/Image",
       "RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47"},
      {"sensor_msgs/msg/CompressedImage",
       "RIHS01_15640771531571185e2efc8a100baf923961a4d15d5569652e6cb6691e8e371a"},
      {"nav_msgs/msg/Odometry",
       "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0"},
      {"rosgraph_msgs/msg/Clock",
       "RIHS01_692f7a66e93a3c83e71765d033b60349ba68023a8c689a79e48078bcb5c58564"},
      {"std_msgs/msg/Header",
       "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01"},
  };
  for (const auto& [type, hash] : kJazzy) EXPECT_EQ(TypeHash(type), hash) << type;
}

TEST(TypeHash, ReferencedTypesAreSortedAndDeduplicated) {
  const std::string json = TypeDescriptionJson("nav_msgs/msg/Odometry");
  // Header and Time once each, Point before Pose before PoseWithCovariance ... by name.
  const auto first = json.find("{\"type_name\": \"builtin_interfaces/msg/Time\"");
  ASSERT_NE(first, std::string::npos);
  EXPECT_EQ(json.find("{\"type_name\": \"builtin_interfaces/msg/Time\"", first + 1),
            std::string::npos);
  EXPECT_LT(json.find("\"geometry_msgs/msg/Point\", \"fields\""),
            json.find("\"geometry_msgs/msg/Pose\", \"fields\""));
  EXPECT_NE(json.find("\"name\": \"covariance\", \"type\": {\"type_id\": 59, \"capacity\": 36"),
            std::string::npos);  // float64[36]
}

TEST(TypeHash, UnknownTypesAreRefused) {
  EXPECT_THROW(TypeHash("sensor_msgs/msg/LaserScan"), std::out_of_range);
}

TEST(ConcatenatedDefinition, HasEveryReferencedTypeOnce) {
  const std::string text = ConcatenatedDefinition("sensor_msgs/msg/Image");
  EXPECT_EQ(text.rfind("std_msgs/Header header\n", 0), 0u);
  EXPECT_NE(text.find("\nuint8[] data\n"), std::string::npos);
  EXPECT_NE(text.find("MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"),
            std::string::npos);
  EXPECT_NE(text.find("MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"),
            std::string::npos);
}

}  // namespace
}  // namespace mapless::ros2
