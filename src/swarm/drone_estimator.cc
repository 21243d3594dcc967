#include "swarmlio/swarm/drone_estimator.h"

#include <ceres/cost_function.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <map>
#include <memory>
#include <cmath>
#include <deque>
#include <set>
#include <utility>
#include <variant>

#include "factors/active_observation_factor.h"
#include "factors/constant_block_cost.h"
#include "factors/gravity_alignment_factor.h"
#include "factors/passive_observation_factor.h"
#include "drone_estimator_impl.h"
#include "swarmlio/lio/undistortion.h"
#include "swarmlio/math/so3.h"

namespace swarmlio::swarm {
namespace {

using internal::CanRelay;
using internal::ChainPassesThrough;
using internal::ComposeExtrinsic;
using internal::SetProvenance;
using internal::HeardTeammates;
using internal::ObservationShare;
using internal::Predict;
using internal::PredictedTeammate;
using internal::SwarmPart;
using internal::InvertExtrinsic;
using internal::Mahalanobis2;
using internal::PendingPassive;
using internal::Regularized;
using internal::Seconds;
using internal::TeammateInfo;

}  // namespace

std::string DroneEstimatorOptions::Validate() const {
  if (std::string e = odometry.Validate(); !e.empty()) return "odometry." + e;
  if (std::string e = teammate.Validate(); !e.empty()) return "teammate." + e;
  if (std::string e = swarm.Validate(); !e.empty()) return "swarm." + e;
  return "";
}

DroneEstimator::DroneEstimator(int self_id, const DroneEstimatorOptions& options,
                               const LidarOptions& lidar)
    : self_id_(self_id), options_(options), lidar_(lidar), impl_(std::make_unique<Impl>()) {}

DroneEstimator::~DroneEstimator() = default;

Status DroneEstimator::Create(int self_id, const DroneEstimatorOptions& options,
                              const LidarOptions& lidar,
                              std::unique_ptr<DroneEstimator>* estimator) {
  if (self_id < 0) return Status::InvalidArgument("drone id must be >= 0");
  if (const std::string invalid = options.Validate(); !invalid.empty()) {
    return Status::InvalidArgument("drone estimator options: " + invalid);
  }
  std::unique_ptr<DroneEstimator> out(new DroneEstimator(self_id, options, lidar));
  SWARMLIO_RETURN_IF_ERROR(lio::Odometry::Create(options.odometry, lidar, &out->odometry_));
  out->detector_ = std::make_unique<teammate::TeammateDetector>(self_id, options.teammate);
  out->impl_->budget = BroadcastBudget(options.swarm.broadcast_budget);
  if (options.swarm.synchronize_clocks) {
    SWARMLIO_RETURN_IF_ERROR(
        net::ClockSync::Create(self_id, options.swarm.clock_sync, &out->impl_->clock_sync));
  }
  out->odometry_->SetHooks(out.get());
  *estimator = std::move(out);
  return Status::Ok();
}

namespace {

// Joins the odometry's outputs with the swarm parts recorded by OnScanDone.
void Collect(lio::Odometry* odometry, std::vector<lio::ScanOutput>* scratch,
             std::deque<SwarmPart>* parts, std::vector<DroneOutput>* outputs) {
  scratch->clear();
  odometry->PopOutputs(scratch);
  for (lio::ScanOutput& o : *scratch) {
    DroneOutput d;
    d.ego = std::move(o);
    if (!parts->empty()) {
      SwarmPart& p = parts->front();
      d.teammates = std::move(p.teammates);
      d.identifications = std::move(p.identifications);
      d.removed_teammates = std::move(p.removed);
      d.active_observations = p.active;
      d.passive_observations = p.passive;
      d.gravity_alignments = p.gravity;
      d.rejected_observations = p.rejected;
      d.extrinsics_frozen = p.frozen;
      d.num_detector_points = p.detector_points;
      parts->pop_front();
    }
    outputs->push_back(std::move(d));
  }
}

}  // namespace

Status DroneEstimator::AddImu(const ImuSample& sample) {
  if (sample.angular_velocity_rad_s.allFinite()) impl_->last_gyro = sample.angular_velocity_rad_s;
  impl_->now_ns = std::max(impl_->now_ns, sample.stamp_ns);
  const Status status = odometry_->AddImu(sample);
  Collect(odometry_.get(), &impl_->odometry_outputs, &impl_->parts, &impl_->outputs);
  return status;
}

Status DroneEstimator::AddScan(const LidarScan& scan) {
  impl_->now_ns = std::max(impl_->now_ns, scan.stamp_ns);
  const Status status = odometry_->AddScan(scan);
  Collect(odometry_.get(), &impl_->odometry_outputs, &impl_->parts, &impl_->outputs);
  return status;
}

Status DroneEstimator::Flush() {
  const Status status = odometry_->Flush();
  Collect(odometry_.get(), &impl_->odometry_outputs, &impl_->parts, &impl_->outputs);
  return status;
}

void DroneEstimator::PopOutputs(std::vector<DroneOutput>* outputs) {
  for (DroneOutput& o : impl_->outputs) outputs->push_back(std::move(o));
  impl_->outputs.clear();
}

void DroneEstimator::PopMessages(std::vector<net::SwarmMessage>* messages) {
  Impl& im = *impl_;
  for (net::SwarmMessage& m : im.messages) messages->push_back(std::move(m));
  im.messages.clear();
  if (im.clock_sync == nullptr || im.now_ns == std::numeric_limits<int64_t>::min()) return;
  // Clock synchronisation, stamped with the send time: answers to the
  // teammates' requests (t3), then the own requests that are due (t1).
  for (const auto& [request, arrival_ns] : im.sync_requests) {
    net::TimeSyncMessage reply;
    if (im.clock_sync->HandleMessage(request, arrival_ns, std::max(im.now_ns, arrival_ns), &reply)) {
      messages->push_back(reply);
    }
  }
  im.sync_requests.clear();
  std::vector<net::TimeSyncMessage> requests;
  im.clock_sync->DueRequests(im.now_ns, &requests);
  for (const net::TimeSyncMessage& r : requests) messages->push_back(r);
  // TimeSync packets (exchange: requests) are not optional: paid whatever the credit.
  for (const net::SwarmMessage& m : *messages) {
    if (std::holds_alternative<net::TimeSyncMessage>(m)) {
      im.budget.Spend(im.budget.WireBytes(net::TimeSyncPacketBytes()));
    }
  }
}

const net::ClockSync* DroneEstimator::clock_sync() const { return impl_->clock_sync.get(); }

void DroneEstimator::SelectDetectorPoints(const LidarScan& raw, int64_t t_k, const SwarmState& x,
                                          const Eigen::Matrix3d& R_imu_lidar,
                                          LidarScan* selected) const {
  const teammate::TeammateDetectorOptions& d = options_.teammate;
  const float min_reflectivity = static_cast<float>(d.clustering.min_reflectivity);
  // Trackers of the last scan, predicted to t_k, in the body frame. The body
  // moves during the scan and the prediction is rough: a generous margin.
  constexpr double kMarginM = 1.0;
  const double radius = std::max(d.association.teammate_region_radius_m,
                                 d.association.temporary_region_radius_m) +
                        options_.swarm.map_exclusion_radius_m + kMarginM;
  const Eigen::Matrix3d R_b_G = x.ego.R_G_b().transpose();
  std::vector<Eigen::Vector3f> centers_in_lidar;
  for (const teammate::TrackerState& s : impl_->detection.trackers) {
    const double dt = Seconds(t_k) - impl_->last_detection_stamp_s;
    const Eigen::Vector3d p_in_b = R_b_G * (s.p_in_Gi + s.v_in_Gi * dt - x.ego.p_b_in_G);
    centers_in_lidar.push_back(
        (R_imu_lidar.transpose() * (p_in_b - lidar_.p_lidar_in_imu_m)).cast<float>());
  }
  const float r2 = static_cast<float>(radius * radius);
  selected->stamp_ns = raw.stamp_ns;
  selected->frame_id = raw.frame_id;
  selected->points.clear();
  for (const LidarPoint& p : raw.points) {
    bool keep = p.reflectivity >= min_reflectivity;
    if (!keep) {
      const Eigen::Vector3f q(p.x, p.y, p.z);
      for (const Eigen::Vector3f& c : centers_in_lidar) {
        if ((q - c).squaredNorm() <= r2) {
          keep = true;
          break;
        }
      }
    }
    if (keep) selected->points.push_back(p);
  }
}

Status DroneEstimator::OnFrontEnd(const lio::FrontEndScan& scan, SwarmState* x, Eigen::MatrixXd* P,
                                  lio::UpdateRequest* request) {
  Impl& im = *impl_;
  im.part = SwarmPart();
  im.fused_by_teammate.clear();
  im.model.Clear();
  const int64_t t_k = scan.end_stamp_ns;
  const SwarmOptions& so = options_.swarm;

  // 1. The scan at full resolution, motion-compensated to its end, with
  // reflectivity: the points the detector can use (tape returns, and every
  // point near a tracked object, where it re-clusters), not the other ~99 %.
  const Eigen::Matrix3d R_imu_lidar = lidar_.QuaternionImuLidar().toRotationMatrix();
  SelectDetectorPoints(*scan.raw, t_k, *x, R_imu_lidar, &im.selected);
  SWARMLIO_RETURN_IF_ERROR(UndistortScan(im.selected, *scan.poses, R_imu_lidar,
                                         lidar_.p_lidar_in_imu_m, &im.undistorted));
  const double end_offset_s = Seconds(t_k - scan.raw->stamp_ns);
  im.points.resize(im.undistorted.size());
  for (size_t k = 0; k < im.undistorted.size(); ++k) {
    const UndistortedPoint& u = im.undistorted[k];
    teammate::ScanPoint& p = im.points[k];
    p.p_in_b = u.p_in_b_end.cast<float>();
    p.reflectivity = u.reflectivity;
    p.time_offset_s = static_cast<float>(u.offset_time_s - end_offset_s);
  }
  im.part.detector_points = static_cast<int>(im.points.size());

  // 2. Detection, tracking and identification at the predicted pose. The
  // trackers read T_Gi_Gj from the state (its one owner).
  for (int id : x->layout().teammate_ids()) {
    detector_->SetGlobalExtrinsic(id, x->teammate(id).T_Gi_Gj());
  }
  Eigen::Isometry3d T_Gi_bi = Eigen::Isometry3d::Identity();
  T_Gi_bi.linear() = x->ego.R_G_b();
  T_Gi_bi.translation() = x->ego.p_b_in_G;
  SWARMLIO_RETURN_IF_ERROR(detector_->ProcessScan(Seconds(t_k), T_Gi_bi, im.points, &im.detection));
  im.last_detection_stamp_s = Seconds(t_k);

  // 3. State blocks: new teammates in, lost or restarted ones out.
  for (const teammate::TeammateIdentification& id : im.detection.identifications) {
    if (x->HasTeammate(id.drone_id)) continue;
    GlobalExtrinsic T;
    T.q_Gi_Gj = Eigen::Quaterniond(id.R_Gi_Gj).normalized();
    T.p_Gj_in_Gi = id.p_Gj_in_Gi;
    const double sigma_p = std::max(so.init_translation_sigma_floor_m,
                                    so.init_translation_sigma_per_residual * id.mean_residual_m);
    // The excitation flights span about a metre: a translation error sigma_p
    // at the ends of a 1 m lever is a rotation error of sigma_p rad.
    const double sigma_r = std::max(so.init_rotation_sigma_floor_rad, sigma_p / 1.0);
    Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
    C.diagonal().head<3>().setConstant(sigma_r * sigma_r);
    C.diagonal().tail<3>().setConstant(sigma_p * sigma_p);
    x->AddTeammate(id.drone_id, T);
    AppendCovarianceBlock(C, P);
    im.teammates[id.drone_id].last_seen_ns = t_k;
    SetProvenance(false, {}, &im.teammates[id.drone_id]);
    IdentificationEvent event;
    event.drone_id = id.drone_id;
    event.stamp_ns = t_k;
    event.method = "trajectory_match";
    event.mean_residual_m = id.mean_residual_m;
    event.initial_T_Gi_Gj = T;
    im.part.identifications.push_back(event);
    ++counters_.identifications;
  }
  // Mutual identification: j matched this drone's trajectory and sent T_Gj_Gi.
  if (so.mutual_identification) {
    for (const auto& [j, pending] : im.mutual) {
      if (x->HasTeammate(j) || im.teammates[j].restarted) continue;
      GlobalExtrinsic T;
      Eigen::Matrix<double, 6, 6> C;
      InvertExtrinsic(pending.entry, &T, &C);
      if (!detector_->AddIdentifiedTeammate(j, Seconds(t_k), T.R_Gi_Gj(), T.p_Gj_in_Gi)) continue;
      // Positive definite whatever arrived, and at least the covariance of an
      // own match with zero residual.
      C = Regularized<6>(C, 1e-10);
      for (int k = 0; k < 3; ++k) {
        C(k, k) = std::max(C(k, k), so.init_rotation_sigma_floor_rad * so.init_rotation_sigma_floor_rad);
        C(3 + k, 3 + k) = std::max(C(3 + k, 3 + k), so.init_translation_sigma_floor_m *
                                                         so.init_translation_sigma_floor_m);
      }
      x->AddTeammate(j, T);
      AppendCovarianceBlock(C, P);
      im.teammates[j].last_seen_ns = t_k;
      // The inverse of an edge j derived itself stays derived, through
      // teammates j did not name: any teammate heard so far may be in its chain.
      const bool derived = pending.entry.source == net::ExtrinsicSource::kGraph;
      SetProvenance(derived, derived ? HeardTeammates(im.teammates, j) : std::map<int, int64_t>(),
                    &im.teammates[j]);
      IdentificationEvent event;
      event.drone_id = j;
      event.stamp_ns = t_k;
      event.method = "teammate_match";
      event.initial_T_Gi_Gj = T;
      im.part.identifications.push_back(event);
      ++counters_.identifications;
    }
  }
  im.mutual.clear();
  // Identification through teammates: k, identified by a known teammate j
  // (its own match T_Gj_Gk), enters as T_Gi_Gj T_Gj_Gk with the covariance
  // and the cross-covariances it inherits from the T_Gi_Gj block (it is a
  // function of it). Among several such j, the smallest composed covariance.
  if (so.graph_identification) AddTeammatesThroughTeammates(t_k, x, P);
  for (const teammate::TeammateObservation& o : im.detection.observations) {
    im.teammates[o.drone_id].last_seen_ns = t_k;
  }
  const std::vector<int> ids = x->layout().teammate_ids();
  for (int id : ids) {
    TeammateInfo& info = im.teammates[id];
    const int64_t last = std::max(info.last_seen_ns, info.last_heard_ns);
    const bool lost = Seconds(t_k - last) > so.teammate_timeout_s;
    if (!lost && !info.restarted) continue;
    EraseCovarianceBlock(x->layout().TeammateBlock(id), P);
    x->RemoveTeammate(id);
    if (lost) detector_->ForgetTeammate(id);
    info.restarted = false;
    im.part.removed.push_back(id);
    ++counters_.teammates_removed;
  }

  // The own track for the time compensation of passive observations.
  im.dead_reckoning.Append(*scan.poses, so.max_message_age_s + 0.5);

  // 4. Observation factors.
  // After a degenerate scan the observed extrinsics are not corrected
  // (degeneracy_policy): considered (their covariance in the gain) or exact.
  const bool frozen = so.degeneracy_policy != DegeneracyPolicy::kEstimateAll &&
                      scan.previous_scan_degenerate;
  const bool exact = so.degeneracy_policy == DegeneracyPolicy::kFreezeExtrinsics;
  im.part.frozen = frozen && x->layout().NumTeammates() > 0;
  std::set<int> estimated;
  std::set<int> considered;  // frozen: in the update with their covariance, not corrected
  // A well-localized drone does not take a degenerate teammate's pose into
  // its own state; a degenerate one still does (it is its best information).
  // Only a drone that is degenerate most of the time (an exponential average
  // of its flags over ~10 scans above one half), not one with an occasional
  // flagged scan, relies on degenerate teammates.
  im.degenerate_average = 0.9 * im.degenerate_average + (scan.previous_scan_degenerate ? 0.1 : 0.0);
  const bool skip_degenerate = so.skip_degenerate_teammates && im.degenerate_average < 0.5;
  // Each use of an observation takes its share (ObservationShare).
  const auto share_with = [&](bool teammate_degenerate) {
    return ObservationShare(so, scan.previous_scan_degenerate, teammate_degenerate);
  };
  const double gate2 = so.gate_sigma * so.gate_sigma;
  const auto add = [&](std::unique_ptr<ceres::CostFunction> cost, int teammate_id,
                       const Eigen::Vector3d& innovation, const Eigen::Matrix3d& S) {
    if (so.gate_sigma > 0.0 && Mahalanobis2(innovation, S) > gate2) {
      ++im.part.rejected;
      ++counters_.observations_rejected;
      return false;
    }
    if (frozen && exact) {
      std::vector<double> T(GlobalExtrinsic::kAmbientSize);
      x->teammate(teammate_id).ToParameters(T.data());
      im.model.Add(std::make_unique<ConstantBlockCost>(std::move(cost), 1, std::move(T)),
                   {kEgoBlock});
      return true;
    }
    im.model.Add(std::move(cost), {kEgoBlock, teammate_id});
    (frozen ? considered : estimated).insert(teammate_id);
    return true;
  };
  const Eigen::Matrix3d R_Gi_bi = x->ego.R_G_b();
  const double max_age = so.max_message_age_s;
  if (so.fuse_active && fusion_enabled_) {
    for (const teammate::TeammateObservation& o : im.detection.observations) {
      const auto it = im.teammates.find(o.drone_id);
      if (!x->HasTeammate(o.drone_id) || it == im.teammates.end() || !it->second.have_message) {
        continue;
      }
      const net::EgoStateMessage& m = it->second.last;
      if (skip_degenerate && m.degenerated) {
        ++im.part.skipped_degenerate;
        continue;
      }
      const double age = Seconds(t_k - m.stamp_ns);
      if (std::abs(age) > max_age) {
        ++im.part.rejected;
        ++counters_.observations_rejected;
        continue;
      }
      const PredictedTeammate j = Predict(m, so.time_compensation ? age : 0.0);
      const GlobalExtrinsic& T = x->teammate(o.drone_id);
      auto factor = std::make_unique<ActiveObservationFactor>(
          o.p_bj_in_bi, j.p_bj_in_Gj,
          Regularized<3>(o.covariance_m2) / share_with(m.degenerated),
          Regularized<3>(j.cov_p), R_Gi_bi,
          T.R_Gi_Gj());
      const Eigen::Vector3d e = factor->Predict(x->ego, T) - o.p_bj_in_bi;
      const Eigen::Matrix3d S = factor->covariance();
      if (add(std::move(factor), o.drone_id, e, S)) {
        ++im.part.active;
        ++im.fused_by_teammate[o.drone_id].first;
        ++counters_.active_fused;
        if (!frozen) ++it->second.observations_fused;
      }
    }
  }
  if (so.fuse_passive && fusion_enabled_) {
    for (const PendingPassive& p : im.passive) {
      if (!x->HasTeammate(p.from)) continue;
      if (skip_degenerate && p.sender.degenerated) {
        ++im.part.skipped_degenerate;
        continue;
      }
      const double dt = Seconds(p.stamp_ns - t_k);
      if (std::abs(dt) > max_age) {
        ++im.part.rejected;
        ++counters_.observations_rejected;
        continue;
      }
      const GlobalExtrinsic& T = x->teammate(p.from);
      // Own position at t_j: p + v dt + A(R, b_a, g) with A the IMU part of
      // the motion (dead_reckoning.h) when the history covers t_j, else the
      // constant-velocity shift p + v dt.
      ImuRetrodiction retrodiction;
      // The observer fused the same measurement actively: this use takes its
      // share of the information (SwarmOptions::observation_information_share).
      const Eigen::Matrix3d Sigma_obs = Regularized<3>(p.cov) / share_with(p.sender.degenerated);
      if (so.time_compensation) im.dead_reckoning.Retrodiction(p.stamp_ns, t_k, &retrodiction);
      auto factor = std::make_unique<PassiveObservationFactor>(
          p.p_bi_in_bj, so.time_compensation ? dt : 0.0, p.sender.q_Gj_bj.normalized().toRotationMatrix(),
          p.sender.p_bj_in_Gj, Sigma_obs, Regularized<3>(p.sender.cov_theta_Gj_bj, 1e-10),
          Regularized<3>(p.sender.cov_p_bj_in_Gj), x->ego, T, retrodiction);
      const Eigen::Vector3d e = factor->Predict(x->ego, T) - p.p_bi_in_bj;
      const Eigen::Matrix3d S = factor->covariance();
      if (add(std::move(factor), p.from, e, S)) {
        ++im.part.passive;
        ++im.fused_by_teammate[p.from].second;
        if (!frozen) ++im.teammates[p.from].observations_fused;
        ++counters_.passive_fused;
        if (p.repeated) ++counters_.passive_repeated;
      }
    }
  }
  im.passive.clear();  // each passive observation is used in one update at most
  // Gravity alignment: once per received broadcast, not while frozen (it
  // would then only move the own gravity).
  if (so.fuse_gravity && fusion_enabled_ && !frozen) {
    for (int id : x->layout().teammate_ids()) {
      TeammateInfo& info = im.teammates[id];
      if (!info.gravity_pending) continue;
      info.gravity_pending = false;
      const GlobalExtrinsic& T = x->teammate(id);
      auto factor = std::make_unique<GravityAlignmentFactor>(
          info.g_in_Gj, Regularized<3>(info.cov_g_in_Gj, 1e-12), so.gravity_alignment_sigma_m_s2,
          T.R_Gi_Gj());
      const Eigen::Vector3d e = factor->Predict(x->ego, T);
      const Eigen::Matrix3d S = factor->covariance();
      if (add(std::move(factor), id, e, S)) {
        ++im.part.gravity;
        ++counters_.gravity_fused;
      }
    }
  }

  if (!im.model.empty()) request->models.push_back(&im.model);
  request->estimated_teammates.assign(estimated.begin(), estimated.end());
  request->considered_teammates.assign(considered.begin(), considered.end());
  // 5. Tracked objects stay out of the map.
  const Eigen::Isometry3d T_bi_Gi = T_Gi_bi.inverse();
  for (const teammate::TrackerState& s : im.detection.trackers) {
    request->excluded.push_back({T_bi_Gi * s.p_in_Gi, so.map_exclusion_radius_m});
  }
  return Status::Ok();
}
void DroneEstimator::AddTeammatesThroughTeammates(int64_t t_k, SwarmState* x, Eigen::MatrixXd* P) {
  Impl& im = *impl_;
  const SwarmOptions& so = options_.swarm;
  struct Candidate {
    GlobalExtrinsic T;
    Eigen::Matrix<double, 6, 6> J_ij;
    Eigen::Matrix<double, 6, 6> C;  // J_ij P_ij J_ij^T + J_jk C_jk J_jk^T
    int via = -1;
  };
  std::map<int, Candidate> best;  // by k
  for (int j : x->layout().teammate_ids()) {
    const TeammateInfo& info_j = im.teammates[j];
    // Only j's first-hand edges (identified), and only through a derived j
    // that no longer leans on the teammates it came through.
    if (!CanRelay(info_j, *x, im.teammates, so)) continue;
    const Segment bj = x->layout().TeammateBlock(j);
    const Eigen::Matrix<double, 6, 6> P_ij = P->block<6, 6>(bj.offset, bj.offset);
    for (const auto& [k, e] : info_j.identified) {
      if (k == self_id_ || x->HasTeammate(k)) continue;
      if (ChainPassesThrough(info_j, k, im.teammates)) continue;
      const auto it_k = im.teammates.find(k);
      if (it_k != im.teammates.end() && it_k->second.restarted) continue;
      GlobalExtrinsic T_jk;
      T_jk.q_Gi_Gj = e.q_Gi_Gj.normalized();
      T_jk.p_Gj_in_Gi = e.p_Gj_in_Gi;
      Candidate c;
      Eigen::Matrix<double, 6, 6> J_jk;
      ComposeExtrinsic(x->teammate(j), T_jk, &c.T, &c.J_ij, &J_jk);
      const Eigen::Matrix<double, 6, 6> C_jk = Regularized<6>(e.covariance, 1e-10);
      c.C = c.J_ij * P_ij * c.J_ij.transpose() + J_jk * C_jk * J_jk.transpose();
      c.via = j;
      const auto it = best.find(k);
      if (it == best.end() || c.C.trace() < it->second.C.trace()) best[k] = c;
    }
  }
  for (const auto& [k, c] : best) {
    if (!detector_->AddIdentifiedTeammate(k, Seconds(t_k), c.T.R_Gi_Gj(), c.T.p_Gj_in_Gi)) continue;
    // Cross-covariances: d(T_ik) = J_ij d(T_ij) + J_jk d(T_jk) with d(T_jk)
    // independent of this drone's state, so P(k, :) = J_ij P(j, :).
    const int n = static_cast<int>(P->rows());
    const Segment bj = x->layout().TeammateBlock(c.via);
    const Eigen::MatrixXd cross = c.J_ij * P->middleRows(bj.offset, 6);
    Eigen::Matrix<double, 6, 6> C = 0.5 * (c.C + c.C.transpose());
    for (int d = 0; d < 3; ++d) {
      C(d, d) = std::max(C(d, d), so.init_rotation_sigma_floor_rad * so.init_rotation_sigma_floor_rad);
      C(3 + d, 3 + d) =
          std::max(C(3 + d, 3 + d), so.init_translation_sigma_floor_m * so.init_translation_sigma_floor_m);
    }
    x->AddTeammate(k, c.T);
    AppendCovarianceBlock(C, P);
    P->block(n, 0, 6, n) = cross;
    P->block(0, n, n, 6) = cross.transpose();
    // k's chain: j's (empty when j is first-hand) and j itself.
    std::map<int, int64_t> through = im.teammates[c.via].derived_through;
    through[c.via] = im.teammates[c.via].session_start_ns;
    TeammateInfo& info = im.teammates[k];
    info.last_seen_ns = t_k;
    SetProvenance(true, std::move(through), &info);
    IdentificationEvent event;
    event.drone_id = k;
    event.stamp_ns = t_k;
    event.method = "graph";
    event.via_drone_id = c.via;
    event.initial_T_Gi_Gj = c.T;
    im.part.identifications.push_back(event);
    ++counters_.identifications;
  }
}

}  // namespace swarmlio::swarm
