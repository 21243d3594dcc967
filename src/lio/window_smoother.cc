#include "window_smoother.h"

#include <algorithm>
#include <string>
#include <utility>

#include "window_state.h"

namespace swarmlio::lio::internal {

WindowSmoother::WindowSmoother() : impl_(std::make_unique<Impl>()) {}
WindowSmoother::~WindowSmoother() = default;

Status WindowSmoother::Create(const WindowOptions& options, const ImuPropagatorOptions& propagation,
                              const AssociationOptions& association,
                              const EsikfUpdateOptions& update, const LocalMap* map,
                              std::unique_ptr<WindowSmoother>* smoother) {
  if (const std::string invalid = options.Validate(); !invalid.empty()) {
    return Status::InvalidArgument("window options: " + invalid);
  }
  std::unique_ptr<WindowSmoother> out(new WindowSmoother());
  Impl& im = *out->impl_;
  im.options = options;
  im.preintegration.process_noise = propagation.process_noise;
  im.preintegration.max_gap_s = propagation.max_gap_s;
  im.preintegration.gravity_stddev_floor_m_s2 = options.gravity_stddev_floor_m_s2;
  if (const std::string invalid = im.preintegration.Validate(); !invalid.empty()) {
    return Status::InvalidArgument("window IMU preintegration (propagation options): " + invalid);
  }
  im.association = association;
  im.update = update;
  im.map = map;
  SWARMLIO_RETURN_IF_ERROR(Marginalizer::Create(options.marginalization, &im.marginalizer));
  *smoother = std::move(out);
  return Status::Ok();
}

int WindowSmoother::size() const { return static_cast<int>(impl_->scans.size()); }
const WindowCounters& WindowSmoother::counters() const { return impl_->counters; }

void WindowSmoother::StartInterval(int64_t stamp_ns, const ImuSample& last_sample,
                                   double acceleration_to_m_s2, const EgoState& newest) {
  Impl& im = *impl_;
  im.interval_ok = ImuPreintegration::Create(im.preintegration, &im.interval).ok() &&
                   im.interval->Reset(stamp_ns, last_sample, acceleration_to_m_s2,
                                      newest.gyro_bias, newest.accel_bias)
                       .ok();
}

void WindowSmoother::AddImu(const ImuSample& sample) {
  Impl& im = *impl_;
  if (im.interval_ok) im.interval_ok = im.interval->AddImu(sample).ok();
}

void WindowSmoother::IntegrateTo(int64_t stamp_ns, const ImuSample* next_sample) {
  Impl& im = *impl_;
  if (im.interval_ok) im.interval_ok = im.interval->IntegrateTo(stamp_ns, next_sample).ok();
}

void WindowSmoother::BreakInterval() { impl_->interval_ok = false; }

Status WindowSmoother::Impl::AddPrior(const MarginalizationPrior& prior) {
  Prior p;
  SWARMLIO_RETURN_IF_ERROR(MarginalizationPriorFactor::Create(prior, prior_options, &p.factor));
  p.blocks = prior.parameter_blocks;
  p.manifolds = prior.manifolds;
  priors.push_back(std::move(p));
  return Status::Ok();
}

Status WindowSmoother::Impl::AddGaussianPrior(const std::vector<double*>& blocks,
                                              const std::vector<const ceres::Manifold*>& manifolds,
                                              const Eigen::MatrixXd& covariance) {
  const Eigen::MatrixXd C = 0.5 * (covariance + covariance.transpose());
  const Eigen::LLT<Eigen::MatrixXd> llt(C);
  if (llt.info() != Eigen::Success || !C.allFinite()) {
    return Status::InvalidArgument("window: prior covariance is not positive definite");
  }
  MarginalizationPrior prior;
  prior.information = llt.solve(Eigen::MatrixXd::Identity(C.rows(), C.cols()));
  prior.information = 0.5 * (prior.information + prior.information.transpose()).eval();
  prior.gradient = Eigen::VectorXd::Zero(C.rows());
  prior.parameter_blocks = blocks;
  prior.manifolds = manifolds;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const int ambient = manifolds[b]->AmbientSize();
    prior.linearization_points.push_back(Eigen::Map<const Eigen::VectorXd>(blocks[b], ambient));
    prior.ambient_sizes.push_back(ambient);
    prior.tangent_sizes.push_back(manifolds[b]->TangentSize());
  }
  return AddPrior(prior);
}

void WindowSmoother::Impl::Leave(WindowScan* scan, std::vector<LeavingScan>* leaving) {
  LeavingScan out;
  out.state = scan->State();
  out.insert = scan->updated && !scan->in_map;
  if (out.insert) {
    out.points_in_b = std::move(scan->points_in_b);
    out.excluded = std::move(scan->excluded);
  }
  leaving->push_back(std::move(out));
}

Status WindowSmoother::Impl::TakeObservations(WindowStateInput* input, WindowScan* scan) {
  Status status;
  for (MeasurementModel* model : input->models) {
    if (model == nullptr) continue;
    std::vector<OwnedResidualTerm> terms;
    if (!model->ReleaseTerms(&terms)) {
      status = Status::FailedPrecondition(std::string("window: measurement model ") +
                                          model->name() + " cannot be kept in the window");
      continue;
    }
    for (OwnedResidualTerm& term : terms) {
      bool valid = term.cost != nullptr &&
                   term.cost->parameter_block_sizes().size() == term.blocks.size();
      for (size_t b = 0; valid && b < term.blocks.size(); ++b) {
        const int id = term.blocks[b];
        valid = (id == kEgoBlock || Teammate(id) != nullptr) &&
                term.cost->parameter_block_sizes()[b] == ManifoldOf(id)->AmbientSize();
      }
      if (!valid) {
        status = Status::InvalidArgument(std::string("window: a residual block of ") +
                                         model->name() + " does not match its state blocks");
        continue;
      }
      scan->observations.push_back(std::move(term));
    }
  }
  return status;
}

Status WindowSmoother::Impl::Restart(WindowStateInput* input, std::vector<LeavingScan>* leaving) {
  if (!scans.empty()) ++counters.restarts;
  for (auto& s : scans) Leave(s.get(), leaving);
  scans.clear();
  priors.clear();
  teammates.clear();
  for (int id : input->x_pred.layout().teammate_ids()) {
    auto t = std::make_unique<TeammateBlock>();
    t->id = id;
    input->x_pred.teammate(id).ToParameters(t->x.data());
    teammates.push_back(std::move(t));
  }
  auto scan = std::make_unique<WindowScan>();
  input->x_pred.ego.ToParameters(scan->ego.data());
  std::vector<double*> blocks{scan->ego.data()};
  std::vector<const ceres::Manifold*> manifolds{&ego_manifold};
  for (const auto& t : teammates) {
    blocks.push_back(t->x.data());
    manifolds.push_back(&teammate_manifold);
  }
  scans.push_back(std::move(scan));
  return AddGaussianPrior(blocks, manifolds, input->P_pred);
}

Status WindowSmoother::Impl::RemoveTeammate(int id) {
  double* T = Teammate(id);
  if (T == nullptr) return Status::Ok();
  for (auto& s : scans) {
    auto& obs = s->observations;
    obs.erase(std::remove_if(obs.begin(), obs.end(),
                             [id](const OwnedResidualTerm& t) {
                               return std::find(t.blocks.begin(), t.blocks.end(), id) !=
                                      t.blocks.end();
                             }),
              obs.end());
  }
  // Its information in the priors moves onto their other blocks.
  marginalizer->Clear();
  std::vector<size_t> consumed;
  std::vector<double*> others;
  for (size_t k = 0; k < priors.size(); ++k) {
    if (!priors[k].Touches(T)) continue;
    consumed.push_back(k);
    SWARMLIO_RETURN_IF_ERROR(marginalizer->AddResidualBlock(
        {priors[k].factor.get(), nullptr, priors[k].blocks, priors[k].manifolds}));
    for (double* b : priors[k].blocks) {
      if (b != T && std::find(others.begin(), others.end(), b) == others.end()) others.push_back(b);
    }
  }
  if (!others.empty()) {
    MarginalizationPrior prior;
    SWARMLIO_RETURN_IF_ERROR(marginalizer->Marginalize({T}, others, &prior));
    SWARMLIO_RETURN_IF_ERROR(AddPrior(prior));
  }
  for (auto it = consumed.rbegin(); it != consumed.rend(); ++it) {
    priors.erase(priors.begin() + static_cast<std::ptrdiff_t>(*it));
  }
  teammates.erase(std::remove_if(teammates.begin(), teammates.end(),
                                 [id](const std::unique_ptr<TeammateBlock>& t) { return t->id == id; }),
                  teammates.end());
  return Status::Ok();
}

Status WindowSmoother::Impl::SyncTeammates(const SwarmState& x_pred, const Eigen::MatrixXd& P_pred) {
  const std::vector<int>& ids = x_pred.layout().teammate_ids();
  std::vector<int> gone;
  for (const auto& t : teammates) {
    if (std::find(ids.begin(), ids.end(), t->id) == ids.end()) gone.push_back(t->id);
  }
  for (int id : gone) SWARMLIO_RETURN_IF_ERROR(RemoveTeammate(id));
  std::vector<std::unique_ptr<TeammateBlock>> ordered;
  for (int id : ids) {
    auto it = std::find_if(teammates.begin(), teammates.end(),
                           [id](const std::unique_ptr<TeammateBlock>& t) {
                             return t != nullptr && t->id == id;
                           });
    if (it != teammates.end()) {
      ordered.push_back(std::move(*it));
      continue;
    }
    // New: its block of the prediction (no cross-covariance with the ego
    // state: an identification is an independent measurement).
    auto t = std::make_unique<TeammateBlock>();
    t->id = id;
    x_pred.teammate(id).ToParameters(t->x.data());
    const Segment s = x_pred.layout().TeammateBlock(id);
    const Eigen::MatrixXd C = P_pred.block(s.offset, s.offset, s.size, s.size);
    double* block = t->x.data();
    ordered.push_back(std::move(t));
    SWARMLIO_RETURN_IF_ERROR(AddGaussianPrior({block}, {&teammate_manifold}, C));
  }
  teammates = std::move(ordered);
  return Status::Ok();
}

Status WindowSmoother::Impl::MarginalizeOldest(std::vector<LeavingScan>* leaving) {
  WindowScan& s0 = *scans[0];
  WindowScan& s1 = *scans[1];
  marginalizer->Clear();
  std::vector<size_t> consumed;
  std::vector<double*> kept{s1.ego.data()};
  const auto keep = [&kept, &s0](double* b) {
    if (b != s0.ego.data() && std::find(kept.begin(), kept.end(), b) == kept.end()) {
      kept.push_back(b);
    }
  };
  for (size_t k = 0; k < priors.size(); ++k) {
    if (!priors[k].Touches(s0.ego.data())) continue;
    consumed.push_back(k);
    SWARMLIO_RETURN_IF_ERROR(marginalizer->AddResidualBlock(
        {priors[k].factor.get(), nullptr, priors[k].blocks, priors[k].manifolds}));
    for (double* b : priors[k].blocks) keep(b);
  }
  if (s0.HasPlaneInformation()) {
    SWARMLIO_RETURN_IF_ERROR(
        marginalizer->AddResidualBlock({&s0.compressed, nullptr, {s0.ego.data()}, {&ego_manifold}}));
  }
  SWARMLIO_RETURN_IF_ERROR(marginalizer->AddResidualBlock(
      {s1.imu_factor.get(), nullptr, {s0.ego.data(), s1.ego.data()}, {&ego_manifold, &ego_manifold}}));
  for (const OwnedResidualTerm& term : s0.observations) {
    MarginalizationResidualBlock block;
    block.cost_function = term.cost.get();
    for (int b : term.blocks) {
      block.parameter_blocks.push_back(BlockOf(s0, b));
      block.manifolds.push_back(ManifoldOf(b));
      keep(BlockOf(s0, b));
    }
    SWARMLIO_RETURN_IF_ERROR(marginalizer->AddResidualBlock(block));
  }
  MarginalizationPrior prior;
  SWARMLIO_RETURN_IF_ERROR(marginalizer->Marginalize({s0.ego.data()}, kept, &prior));
  for (auto it = consumed.rbegin(); it != consumed.rend(); ++it) {
    priors.erase(priors.begin() + static_cast<std::ptrdiff_t>(*it));
  }
  SWARMLIO_RETURN_IF_ERROR(AddPrior(prior));
  ++counters.marginalizations;
  Leave(&s0, leaving);
  scans.pop_front();
  scans.front()->imu_factor.reset();
  scans.front()->imu.reset();
  return Status::Ok();
}

Status WindowSmoother::AddState(WindowStateInput input, std::vector<LeavingScan>* leaving,
                                double* marginalize_s, std::string* model_error) {
  Impl& im = *impl_;
  const Clock::time_point t0 = Clock::now();
  model_error->clear();
  const Status status = im.AddState(&input, leaving, model_error);
  if (!status.ok()) {
    for (auto& s : im.scans) im.Leave(s.get(), leaving);
    im.scans.clear();
    im.priors.clear();
    im.teammates.clear();
  }
  *marginalize_s = SecondsSince(t0);
  return status;
}

Status WindowSmoother::Impl::AddState(WindowStateInput* in, std::vector<LeavingScan>* leaving,
                                      std::string* model_error) {
  Impl& im = *this;
  WindowStateInput& input = *in;
  std::unique_ptr<ImuPreintegrationFactor> factor;
  const bool chained = im.interval_ok && !im.scans.empty() &&
                       im.interval->start_stamp_ns() == im.scans.back()->stamp_ns &&
                       im.interval->stamp_ns() == input.stamp_ns &&
                       ImuPreintegrationFactor::Create(im.interval->preintegrated(), &factor).ok();
  im.interval_ok = false;
  if (!chained) {
    SWARMLIO_RETURN_IF_ERROR(im.Restart(&input, leaving));
  } else {
    SWARMLIO_RETURN_IF_ERROR(im.SyncTeammates(input.x_pred, input.P_pred));
    auto scan = std::make_unique<WindowScan>();
    input.x_pred.ego.ToParameters(scan->ego.data());
    scan->imu = std::move(im.interval);
    scan->imu_factor = std::move(factor);
    im.scans.push_back(std::move(scan));
  }
  WindowScan& scan = *im.scans.back();
  scan.stamp_ns = input.stamp_ns;
  scan.points_in_b = std::move(input.points_in_b);
  scan.excluded = std::move(input.excluded);
  scan.use_planes = input.use_planes;
  scan.associator = std::make_unique<ScanAssociator>(im.map, im.association);
  const Status observations = im.TakeObservations(&input, &scan);
  if (!observations.ok()) *model_error = observations.message();
  while (static_cast<int>(im.scans.size()) > im.options.size) {
    SWARMLIO_RETURN_IF_ERROR(im.MarginalizeOldest(leaving));
  }
  return Status::Ok();
}

void WindowSmoother::MarkNewestInMap() {
  if (!impl_->scans.empty()) impl_->scans.back()->in_map = true;
}

void WindowSmoother::TakeScansForMap(std::vector<LeavingScan>* scans) {
  for (auto& s : impl_->scans) {
    if (s->in_map || !s->updated) continue;
    impl_->Leave(s.get(), scans);
    s->in_map = true;
  }
}

}  // namespace swarmlio::lio::internal
