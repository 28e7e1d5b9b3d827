// The ROS 2 message definitions (common_interfaces and rcl_interfaces as in Humble and Jazzy,
// comments and constants left out), concatenated the way rosbag2 and Foxglove store them. Written
// here from the ROS 2 .msg files, independently of mapless's own copy (src/mapless/ros2/
// type_hash.cc), which the test compares with these.
const SEP = "\n================================================================================\n";
const TIME = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec";
const HEADER = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id";
const VECTOR3 = "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z";
const join = (...parts) => parts.join(SEP) + "\n";

export const DEFINITIONS = {
  "geometry_msgs/msg/Twist": join("Vector3  linear\nVector3  angular", VECTOR3),
  "std_msgs/msg/String": join("string data"),
  "std_msgs/msg/Bool": join("bool data"),
  "rosgraph_msgs/msg/Clock": join("builtin_interfaces/Time clock", TIME),
  "nav_msgs/msg/Odometry": join(
    "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n" +
      "geometry_msgs/TwistWithCovariance twist",
    HEADER,
    TIME,
    "MSG: geometry_msgs/PoseWithCovariance\nPose pose\nfloat64[36] covariance",
    "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation",
    "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z",
    "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1",
    "MSG: geometry_msgs/TwistWithCovariance\nTwist twist\nfloat64[36] covariance",
    "MSG: geometry_msgs/Twist\nVector3  linear\nVector3  angular",
    VECTOR3,
  ),
  "sensor_msgs/msg/Image": join(
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n" +
      "uint32 step\nuint8[] data",
    HEADER,
    TIME,
  ),
  "sensor_msgs/msg/CompressedImage": join(
    "std_msgs/Header header\nstring format\nuint8[] data",
    HEADER,
    TIME,
  ),
};
