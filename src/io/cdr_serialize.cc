#include "src/io/cdr_serialize.h"

#include <map>

#include "src/io/cdr_writer.h"

namespace swarmlio::io::internal {
namespace {

void PutHeader(const std_msgs::Header& header, CdrWriter* w) {
  w->I32(static_cast<int32_t>(header.stamp.sec));
  w->U32(header.stamp.nsec);
  w->String(header.frame_id);
}

template <class Array>
void PutF64s(const Array& values, CdrWriter* w) {
  for (double v : values) w->F64(v);
}

void PutPose(const geometry_msgs::Pose& pose, CdrWriter* w) {
  w->F64(pose.position.x);
  w->F64(pose.position.y);
  w->F64(pose.position.z);
  w->F64(pose.orientation.x);
  w->F64(pose.orientation.y);
  w->F64(pose.orientation.z);
  w->F64(pose.orientation.w);
}

void PutVector3(const geometry_msgs::Vector3& v, CdrWriter* w) {
  w->F64(v.x);
  w->F64(v.y);
  w->F64(v.z);
}

// Field lines of the types (ROS 2 message definitions, comments left out).
constexpr char kTimeFields[] = "int32 sec\nuint32 nanosec\n";
constexpr char kHeaderFields[] = "builtin_interfaces/Time stamp\nstring frame_id\n";
constexpr char kVector3Fields[] = "float64 x\nfloat64 y\nfloat64 z\n";
constexpr char kQuaternionFields[] = "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";
constexpr char kPoseFields[] = "Point position\nQuaternion orientation\n";
constexpr char kPoseWithCovarianceFields[] = "Pose pose\nfloat64[36] covariance\n";
constexpr char kTwistFields[] = "Vector3 linear\nVector3 angular\n";
constexpr char kTwistWithCovarianceFields[] = "Twist twist\nfloat64[36] covariance\n";
constexpr char kImuFields[] =
    "std_msgs/Header header\n"
    "geometry_msgs/Quaternion orientation\n"
    "float64[9] orientation_covariance\n"
    "geometry_msgs/Vector3 angular_velocity\n"
    "float64[9] angular_velocity_covariance\n"
    "geometry_msgs/Vector3 linear_acceleration\n"
    "float64[9] linear_acceleration_covariance\n";
constexpr char kPointFieldFields[] =
    "uint8 INT8    = 1\nuint8 UINT8   = 2\nuint8 INT16   = 3\nuint8 UINT16  = 4\n"
    "uint8 INT32   = 5\nuint8 UINT32  = 6\nuint8 FLOAT32 = 7\nuint8 FLOAT64 = 8\n"
    "string name\nuint32 offset\nuint8 datatype\nuint32 count\n";
constexpr char kPointCloud2Fields[] =
    "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\n"
    "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n";
constexpr char kCustomMsgFields[] =
    "std_msgs/Header header\nuint64 timebase\nuint32 point_num\nuint8 lidar_id\n"
    "uint8[3] rsvd\nCustomPoint[] points\n";
constexpr char kCustomPointFields[] =
    "uint32 offset_time\nfloat32 x\nfloat32 y\nfloat32 z\nuint8 reflectivity\nuint8 tag\n"
    "uint8 line\n";
constexpr char kPoseStampedFields[] = "std_msgs/Header header\nPose pose\n";
constexpr char kOdometryFields[] =
    "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
    "geometry_msgs/TwistWithCovariance twist\n";

// `text`, then a "MSG:" section per (type, text) dependency.
std::string SchemaText(const char* text,
                       std::initializer_list<std::pair<const char*, const char*>> dependencies) {
  const std::string separator(80, '=');
  std::string schema = text;
  for (const auto& [type, dependency] : dependencies) {
    schema += separator + "\nMSG: " + type + "\n" + dependency;
  }
  return schema;
}

std::map<MessageKind, std::string> BuildSchemas() {
  std::map<MessageKind, std::string> schemas;
  schemas[MessageKind::kImu] =
      SchemaText(kImuFields, {{"std_msgs/Header", kHeaderFields},
                              {"builtin_interfaces/Time", kTimeFields},
                              {"geometry_msgs/Quaternion", kQuaternionFields},
                              {"geometry_msgs/Vector3", kVector3Fields}});
  schemas[MessageKind::kPointCloud2] =
      SchemaText(kPointCloud2Fields, {{"std_msgs/Header", kHeaderFields},
                                      {"builtin_interfaces/Time", kTimeFields},
                                      {"sensor_msgs/PointField", kPointFieldFields}});
  schemas[MessageKind::kLivoxCustomMsg] =
      SchemaText(kCustomMsgFields, {{"std_msgs/Header", kHeaderFields},
                                    {"builtin_interfaces/Time", kTimeFields},
                                    {"livox_ros_driver2/CustomPoint", kCustomPointFields}});
  schemas[MessageKind::kPoseStamped] =
      SchemaText(kPoseStampedFields, {{"std_msgs/Header", kHeaderFields},
                                      {"builtin_interfaces/Time", kTimeFields},
                                      {"geometry_msgs/Pose", kPoseFields},
                                      {"geometry_msgs/Point", kVector3Fields},
                                      {"geometry_msgs/Quaternion", kQuaternionFields}});
  schemas[MessageKind::kOdometry] = SchemaText(
      kOdometryFields, {{"std_msgs/Header", kHeaderFields},
                        {"builtin_interfaces/Time", kTimeFields},
                        {"geometry_msgs/PoseWithCovariance", kPoseWithCovarianceFields},
                        {"geometry_msgs/Pose", kPoseFields},
                        {"geometry_msgs/Point", kVector3Fields},
                        {"geometry_msgs/Quaternion", kQuaternionFields},
                        {"geometry_msgs/TwistWithCovariance", kTwistWithCovarianceFields},
                        {"geometry_msgs/Twist", kTwistFields},
                        {"geometry_msgs/Vector3", kVector3Fields}});
  return schemas;
}

}  // namespace

void SerializeCdr(const sensor_msgs::Imu& msg, std::vector<uint8_t>* bytes) {
  CdrWriter w(bytes);
  PutHeader(msg.header, &w);
  w.F64(msg.orientation.x);
  w.F64(msg.orientation.y);
  w.F64(msg.orientation.z);
  w.F64(msg.orientation.w);
  PutF64s(msg.orientation_covariance, &w);
  PutVector3(msg.angular_velocity, &w);
  PutF64s(msg.angular_velocity_covariance, &w);
  PutVector3(msg.linear_acceleration, &w);
  PutF64s(msg.linear_acceleration_covariance, &w);
}

void SerializeCdr(const sensor_msgs::PointCloud2& msg, std::vector<uint8_t>* bytes) {
  CdrWriter w(bytes);
  PutHeader(msg.header, &w);
  w.U32(msg.height);
  w.U32(msg.width);
  w.U32(static_cast<uint32_t>(msg.fields.size()));
  for (const sensor_msgs::PointField& field : msg.fields) {
    w.String(field.name);
    w.U32(field.offset);
    w.U8(field.datatype);
    w.U32(field.count);
  }
  w.U8(msg.is_bigendian);
  w.U32(msg.point_step);
  w.U32(msg.row_step);
  w.U32(static_cast<uint32_t>(msg.data.size()));
  w.Bytes(msg.data.data(), msg.data.size());
  w.U8(msg.is_dense);
}

void SerializeCdr(const LivoxCustomMsg& msg, std::vector<uint8_t>* bytes) {
  CdrWriter w(bytes);
  PutHeader(msg.header, &w);
  w.U64(msg.timebase);
  w.U32(msg.point_num);
  w.U8(msg.lidar_id);
  for (uint8_t byte : msg.rsvd) w.U8(byte);
  w.U32(static_cast<uint32_t>(msg.points.size()));
  for (const LivoxCustomPoint& p : msg.points) {
    w.U32(p.offset_time);
    w.F32(p.x);
    w.F32(p.y);
    w.F32(p.z);
    w.U8(p.reflectivity);
    w.U8(p.tag);
    w.U8(p.line);
  }
}

void SerializeCdr(const geometry_msgs::PoseStamped& msg, std::vector<uint8_t>* bytes) {
  CdrWriter w(bytes);
  PutHeader(msg.header, &w);
  PutPose(msg.pose, &w);
}

void SerializeCdr(const NavOdometry& msg, std::vector<uint8_t>* bytes) {
  CdrWriter w(bytes);
  PutHeader(msg.header, &w);
  w.String(msg.child_frame_id);
  PutPose(msg.pose.pose, &w);
  PutF64s(msg.pose.covariance, &w);
  PutVector3(msg.twist.twist.linear, &w);
  PutVector3(msg.twist.twist.angular, &w);
  PutF64s(msg.twist.covariance, &w);
}

const char* Ros2TypeName(MessageKind kind) {
  switch (kind) {
    case MessageKind::kImu:
      return kRos2ImuType;
    case MessageKind::kPointCloud2:
      return kRos2PointCloud2Type;
    case MessageKind::kLivoxCustomMsg:
      return kRos2CustomMsgType;
    case MessageKind::kPoseStamped:
      return kRos2PoseStampedType;
    case MessageKind::kOdometry:
      return kRos2OdometryType;
    case MessageKind::kUnsupported:
      break;
  }
  return "";
}

const std::string& Ros2SchemaText(MessageKind kind) {
  static const std::map<MessageKind, std::string>* const kSchemas =
      new std::map<MessageKind, std::string>(BuildSchemas());
  static const std::string* const kNone = new std::string();
  const auto it = kSchemas->find(kind);
  return it == kSchemas->end() ? *kNone : it->second;
}

}  // namespace swarmlio::io::internal
