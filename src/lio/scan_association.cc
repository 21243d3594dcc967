#include "swarmlio/lio/scan_association.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace swarmlio::lio {

double AssociationStats::MinNormalInformation() const {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(normal_information, Eigen::EigenvaluesOnly)
      .eigenvalues()(0);
}

ScanAssociator::ScanAssociator(const LocalMap* map, const ScanAssociationOptions& options,
                               const ParallelFor* parallel)
    : map_(map), options_(options), parallel_(parallel) {}

void ScanAssociator::Reset(const std::vector<Eigen::Vector3d>* points_in_b) {
  points_in_b_ = points_in_b;
  cache_.assign(points_in_b == nullptr ? 0 : points_in_b->size(), CachedPlane());
}

void ScanAssociator::SearchMoved(const Eigen::Matrix3d& R_G_b, const Eigen::Vector3d& p_b_in_G) {
  const std::vector<Eigen::Vector3d>& points = *points_in_b_;
  const double research_sq = options_.research_distance_m * options_.research_distance_m;
  searched_.assign(points.size(), 0);
  queries_in_G_.resize(points.size());
  // Each point reads the map and writes only its own entries:
  // the same result for any thread count.
  const auto search = [&](int64_t begin, int64_t end) {
    std::vector<Neighbor> neighbors;
    neighbors.reserve(static_cast<size_t>(options_.num_neighbors));
    for (int64_t i = begin; i < end; ++i) {
      Eigen::Vector3d& q_in_G = queries_in_G_[static_cast<size_t>(i)];
      q_in_G = R_G_b * points[static_cast<size_t>(i)] + p_b_in_G;
      CachedPlane& cached = cache_[static_cast<size_t>(i)];
      if (research_sq != 0.0 && (q_in_G - cached.searched_at_in_G).squaredNorm() <= research_sq) {
        continue;
      }
      cached.searched_at_in_G = q_in_G;
      map_->KNearest(q_in_G, options_.num_neighbors, &neighbors);
      cached.has_plane = FitPlane(neighbors, options_.plane, &cached.plane) == PlaneFitStatus::kOk;
      searched_[static_cast<size_t>(i)] = 1;
    }
  };
  constexpr int64_t kGrain = 128;  // points per task
  const int64_t n = static_cast<int64_t>(points.size());
  if (parallel_ != nullptr) {
    parallel_->Run(n, kGrain, search);
  } else {
    search(0, n);
  }
}

Status ScanAssociator::Associate(const SwarmState& x, std::vector<PlaneCorrespondence>* out) {
  out->clear();
  stats_ = AssociationStats();
  if (points_in_b_ == nullptr) {
    return Status::FailedPrecondition("ScanAssociator: Reset() with the scan points first");
  }
  const Eigen::Matrix3d R_G_b = x.ego.q_G_b.toRotationMatrix();
  const Eigen::Vector3d& p_b_in_G = x.ego.p_b_in_G;
  const double weight = 1.0 / (options_.point_stddev_m * options_.point_stddev_m);
  const std::vector<Eigen::Vector3d>& points = *points_in_b_;
  stats_.num_points = static_cast<int>(points.size());
  SearchMoved(R_G_b, p_b_in_G);
  out->reserve(points.size());
  planes_.clear();
  matched_.clear();
  for (size_t i = 0; i < points.size(); ++i) {
    stats_.num_searched += searched_[i];
    const CachedPlane& cached = cache_[i];
    if (!cached.has_plane) {
      ++stats_.num_no_plane;
      continue;
    }
    const double z = cached.plane.SignedDistance(queries_in_G_[i]);
    if (!(std::abs(z) < options_.residual_gate_factor * std::sqrt(points[i].norm()))) {
      ++stats_.num_gated;
      continue;
    }
    PlaneCorrespondence c;
    c.p_in_b = points[i];
    c.normal_in_G = cached.plane.normal_in_G;
    c.offset_m = cached.plane.offset_m;
    c.weight = weight;
    out->push_back(c);
    planes_.push_back(&cached.plane);
    matched_.push_back(static_cast<int>(i));
  }
  if (options_.max_normal_stddev_rad > 0.0) ApplyNoisyPlaneRule(out);
  for (const PlaneCorrespondence& c : *out) {
    stats_.normal_information += c.normal_in_G * c.normal_in_G.transpose();
  }
  stats_.num_correspondences = static_cast<int>(out->size());
  return Status::Ok();
}

void ScanAssociator::ApplyNoisyPlaneRule(std::vector<PlaneCorrespondence>* out) {
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d spurious = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < out->size(); ++i) {
    const Eigen::Vector3d& n = (*out)[i].normal_in_G;
    const Plane& plane = *planes_[i];
    information += n * n.transpose();
    spurious += (plane.normal_stddev_rad * plane.normal_stddev_rad) *
                (plane.tilt_axis_in_G * plane.tilt_axis_in_G.transpose());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(information);
  Eigen::Vector3d weak[3];
  int num_weak = 0;
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d e = eig.eigenvectors().col(j);
    if (eig.eigenvalues()(j) < options_.spurious_information_ratio * e.dot(spurious * e)) {
      weak[num_weak++] = e;
    }
  }
  if (num_weak == 0) return;
  const double k = options_.tilt_projection_sigma;
  size_t kept = 0;
  for (size_t i = 0; i < out->size(); ++i) {
    const Plane& plane = *planes_[i];
    bool drop = false;
    for (int j = 0; j < num_weak; ++j) {
      drop |= plane.normal_stddev_rad * std::abs(plane.tilt_axis_in_G.dot(weak[j])) >
              options_.max_normal_stddev_rad;
    }
    if (drop) {
      ++stats_.num_tilt_gated;
      continue;
    }
    PlaneCorrespondence& c = (*out)[i];
    if (k > 0.0) {
      Eigen::Vector3d n = c.normal_in_G;
      bool shrunk = false;
      for (int j = 0; j < num_weak; ++j) {
        // Shrink the lean l toward e to sqrt(max(0, l^2 - (k t_e)^2)): the
        // information (n^T e)^2 loses what tilt noise of k t_e would add.
        const double lean = n.dot(weak[j]);
        const double noise = k * plane.TiltStddevToward(weak[j]);
        if (noise <= 0.0) continue;
        const double remaining = std::sqrt(std::max(0.0, lean * lean - noise * noise));
        n -= (lean - std::copysign(remaining, lean)) * weak[j];
        shrunk = true;
      }
      // A normal that loses more than half its length leaned mostly along
      // noise-dominated directions by no more than its noise: the plane
      // says little else and is dropped.
      const double norm = n.norm();
      if (shrunk && norm <= 0.5) {
        ++stats_.num_tilt_gated;
        continue;
      }
      if (shrunk) {
        c.normal_in_G = n / norm;
        c.offset_m = -c.normal_in_G.dot(plane.centroid_in_G);
        ++stats_.num_tilt_projected;
      }
    }
    matched_[kept] = matched_[i];
    (*out)[kept++] = c;
  }
  out->resize(kept);
  matched_.resize(kept);
}

}  // namespace swarmlio::lio
