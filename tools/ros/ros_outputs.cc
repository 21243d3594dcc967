// RosOutputs: odometry, path, clouds, teammates and TF (ros_outputs.h).
#include "ros_outputs.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cstring>

#include "swarmlio/state/state_layout.h"

namespace swarmlio::tools {
namespace {

ros::Time RosTime(int64_t stamp_ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(std::max<int64_t>(stamp_ns, 0)));
  return t;
}

void SetPose(const Eigen::Quaterniond& q, const Eigen::Vector3d& p, geometry_msgs::Pose* pose) {
  pose->position.x = p.x();
  pose->position.y = p.y();
  pose->position.z = p.z();
  pose->orientation.x = q.x();
  pose->orientation.y = q.y();
  pose->orientation.z = q.z();
  pose->orientation.w = q.w();
}

void SetVector(const Eigen::Vector3d& v, geometry_msgs::Vector3* out) {
  out->x = v.x();
  out->y = v.y();
  out->z = v.z();
}

// An unorganized cloud of float32 x y z.
void FillCloud(const std::vector<Eigen::Vector3d>& points, const std::string& frame,
               int64_t stamp_ns, sensor_msgs::PointCloud2* cloud) {
  cloud->header.stamp = RosTime(stamp_ns);
  cloud->header.frame_id = frame;
  cloud->height = 1;
  cloud->width = static_cast<uint32_t>(points.size());
  cloud->is_bigendian = false;
  cloud->is_dense = true;
  cloud->point_step = 12;
  cloud->row_step = cloud->point_step * cloud->width;
  cloud->fields.resize(3);
  const char* names[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    cloud->fields[i].name = names[i];
    cloud->fields[i].offset = static_cast<uint32_t>(4 * i);
    cloud->fields[i].datatype = sensor_msgs::PointField::FLOAT32;
    cloud->fields[i].count = 1;
  }
  cloud->data.resize(static_cast<size_t>(cloud->row_step));
  uint8_t* out = cloud->data.data();
  for (const Eigen::Vector3d& p : points) {
    const float xyz[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()),
                          static_cast<float>(p.z())};
    std::memcpy(out, xyz, sizeof(xyz));
    out += sizeof(xyz);
  }
}

}  // namespace

std::string RosOutputOptions::Validate() const {
  if (world_frame.empty() || body_frame.empty()) return "world_frame, body_frame: non-empty";
  if (world_frame == body_frame) return "world_frame and body_frame must differ";
  if (!(local_map_period_s >= 0.0)) return "local_map_period_s: >= 0";
  if (max_path_poses < 1) return "max_path_poses: >= 1";
  if (queue_size < 1) return "queue_size: >= 1";
  if (!(marker_lifetime_s > 0.0)) return "marker_lifetime_s: > 0";
  return "";
}

RosOutputs::RosOutputs(ros::NodeHandle* node, ros::NodeHandle* root,
                       const RosOutputOptions& options, const std::vector<std::string>& names,
                       live::LiveSink* forward, const live::Clock* clock)
    : node_(node), options_(options), names_(names), forward_(forward), clock_(clock) {
  const uint32_t q = static_cast<uint32_t>(options.queue_size);
  odometry_ = node->advertise<nav_msgs::Odometry>("odometry", q);
  odometry_imu_ = node->advertise<nav_msgs::Odometry>("odometry_imu", q);
  path_ = node->advertise<nav_msgs::Path>("path", 2);
  cloud_ = node->advertise<sensor_msgs::PointCloud2>("cloud_registered", 10);
  map_ = node->advertise<sensor_msgs::PointCloud2>("local_map", 1);
  markers_ = node->advertise<visualization_msgs::MarkerArray>("teammate_markers", 10);
  if (options.publish_tf) tf_ = root->advertise<tf2_msgs::TFMessage>("/tf", q);
  path_message_.header.frame_id = options.world_frame;
}

std::string RosOutputs::TeammateName(int id) const {
  if (id >= 0 && static_cast<size_t>(id) < names_.size()) return names_[id];
  return "id" + std::to_string(id);
}

void RosOutputs::OnScan(const swarm::DroneOutput& o, const live::ScanLatency& latency) {
  if (forward_ != nullptr) forward_->OnScan(o, latency);
  const EgoState& x = o.ego.state;
  const ros::Time stamp = RosTime(o.ego.stamp_ns);

  nav_msgs::Odometry odometry;
  odometry.header.stamp = stamp;
  odometry.header.frame_id = options_.world_frame;
  odometry.child_frame_id = options_.body_frame;
  SetPose(x.q_G_b, x.p_b_in_G, &odometry.pose.pose);
  // Pose covariance [x y z rx ry rz] from the error state [dtheta dp ...]
  // (rotation: the estimator's right perturbation, in the body frame).
  const auto& P = o.ego.covariance;
  constexpr int kRot = ErrorStateLayout::kRotation.offset;
  constexpr int kPos = ErrorStateLayout::kPosition.offset;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      const int pr = r < 3 ? kPos + r : kRot + r - 3;
      const int pc = c < 3 ? kPos + c : kRot + c - 3;
      odometry.pose.covariance[static_cast<size_t>(6 * r + c)] = P(pr, pc);
    }
  }
  SetVector(x.q_G_b.conjugate() * x.v_b_in_G, &odometry.twist.twist.linear);
  odometry_.publish(odometry);
  ++odometry_published_;
  // The flush comes when the input ends (an idle timeout later); a scan the
  // in-flight initialization held has its delay, not the pipeline's.
  if (!latency.at_flush && !o.ego.held_by_initialization) {
    latencies_ms_.push_back(static_cast<float>(
        1e-6 * static_cast<double>(clock_->NowNs() - latency.scan_end_clock_ns)));
  }

  geometry_msgs::PoseStamped pose;
  pose.header = odometry.header;
  pose.pose = odometry.pose.pose;
  path_message_.header.stamp = stamp;
  path_message_.poses.push_back(pose);
  if (path_message_.poses.size() > static_cast<size_t>(options_.max_path_poses)) {
    path_message_.poses.erase(path_message_.poses.begin());
  }
  if (path_.getNumSubscribers() > 0) path_.publish(path_message_);

  if (!o.ego.registered_in_G.empty() && cloud_.getNumSubscribers() > 0) {
    sensor_msgs::PointCloud2 cloud;
    FillCloud(o.ego.registered_in_G, options_.world_frame, o.ego.stamp_ns, &cloud);
    cloud_.publish(cloud);
  }
  if (options_.local_map_period_s > 0.0 && drone_ != nullptr &&
      (!map_published_ ||
       ToSeconds(o.ego.stamp_ns - last_map_stamp_ns_) >= options_.local_map_period_s)) {
    map_published_ = true;
    last_map_stamp_ns_ = o.ego.stamp_ns;
    if (map_.getNumSubscribers() > 0) {
      sensor_msgs::PointCloud2 cloud;
      FillCloud(drone_->estimator().MapPoints(), options_.world_frame, o.ego.stamp_ns,
                &cloud);
      map_.publish(cloud);
    }
  }
  if (options_.publish_tf) {
    tf2_msgs::TFMessage tf;
    geometry_msgs::TransformStamped t;
    t.header = odometry.header;
    t.child_frame_id = options_.body_frame;
    t.transform.translation.x = x.p_b_in_G.x();
    t.transform.translation.y = x.p_b_in_G.y();
    t.transform.translation.z = x.p_b_in_G.z();
    t.transform.rotation = odometry.pose.pose.orientation;
    tf.transforms.push_back(t);
    tf_.publish(tf);
  }
  PublishTeammates(o);
}

void RosOutputs::PublishTeammates(const swarm::DroneOutput& o) {
  visualization_msgs::MarkerArray markers;
  const ros::Time stamp = RosTime(o.ego.stamp_ns);
  for (const swarm::TeammateEstimate& e : o.teammates) {
    if (!e.have_pose) continue;
    const std::string name = TeammateName(e.drone_id);
    auto it = teammate_odometry_.find(e.drone_id);
    if (it == teammate_odometry_.end()) {
      it = teammate_odometry_
               .emplace(e.drone_id, node_->advertise<nav_msgs::Odometry>(
                                        "teammates/" + name + "/odometry",
                                        static_cast<uint32_t>(options_.queue_size)))
               .first;
    }
    nav_msgs::Odometry odometry;
    odometry.header.stamp = stamp;
    odometry.header.frame_id = options_.world_frame;
    odometry.child_frame_id = name + "/" + options_.body_frame;
    SetPose(e.q_Gi_bj, e.p_bj_in_Gi, &odometry.pose.pose);
    SetVector(e.q_Gi_bj.conjugate() * e.v_bj_in_Gi, &odometry.twist.twist.linear);
    it->second.publish(odometry);

    visualization_msgs::Marker sphere;
    sphere.header = odometry.header;
    sphere.ns = "teammates";
    sphere.id = 2 * e.drone_id;
    sphere.type = visualization_msgs::Marker::SPHERE;
    sphere.action = visualization_msgs::Marker::ADD;
    sphere.pose = odometry.pose.pose;
    sphere.scale.x = sphere.scale.y = sphere.scale.z = 0.4;
    sphere.color.r = e.seen ? 0.1f : 0.9f;  // green: observed in this scan
    sphere.color.g = e.seen ? 0.9f : 0.6f;
    sphere.color.b = 0.1f;
    sphere.color.a = 0.8f;
    sphere.lifetime = ros::Duration(options_.marker_lifetime_s);
    markers.markers.push_back(sphere);
    visualization_msgs::Marker label = sphere;
    label.id = 2 * e.drone_id + 1;
    label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    label.text = name;
    label.pose.position.z += 0.5;
    label.pose.orientation = geometry_msgs::Quaternion();
    label.pose.orientation.w = 1.0;
    label.scale.x = label.scale.y = 0.0;
    label.scale.z = 0.3;
    label.color.r = label.color.g = label.color.b = 1.0f;
    markers.markers.push_back(label);
  }
  if (!markers.markers.empty()) markers_.publish(markers);
}

void RosOutputs::OnScanDropped(int64_t scan_stamp_ns, live::ScanDropReason reason) {
  if (forward_ != nullptr) forward_->OnScanDropped(scan_stamp_ns, reason);
}

void RosOutputs::OnImuPose(const live::ImuRatePose& p) {
  if (forward_ != nullptr) forward_->OnImuPose(p);
  if (odometry_imu_.getNumSubscribers() == 0) return;
  nav_msgs::Odometry odometry;
  odometry.header.stamp = RosTime(p.stamp_ns);
  odometry.header.frame_id = options_.world_frame;
  odometry.child_frame_id = options_.body_frame;
  SetPose(p.q_G_b, p.p_b_in_G, &odometry.pose.pose);
  SetVector(p.q_G_b.conjugate() * p.v_b_in_G, &odometry.twist.twist.linear);
  SetVector(p.angular_velocity_in_b_rad_s, &odometry.twist.twist.angular);
  odometry_imu_.publish(odometry);
}

}  // namespace swarmlio::tools
