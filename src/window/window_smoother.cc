#include "window_smoother.h"

#include <algorithm>
#include <string>
#include <utility>

#include "factors/constant_block_cost.h"
#include "window_state.h"

namespace swarmlio::window {

WindowSmoother::WindowSmoother() : impl_(std::make_unique<Impl>()) {}
WindowSmoother::~WindowSmoother() = default;

Status WindowSmoother::Create(const lio::WindowOptions& options,
                              const lio::ImuPropagatorOptions& propagation,
                              const lio::ScanAssociationOptions& association,
                              const lio::EsikfUpdateOptions& update,
                              const lio::LocalMap* map,
                              std::unique_ptr<WindowSmoother>* smoother,
                              const lio::ParallelFor* parallel) {
  if (const std::string invalid = options.Validate(); !invalid.empty()) {
    return Status::InvalidArgument("window options: " + invalid);
  }
  std::unique_ptr<WindowSmoother> out(new WindowSmoother());
  Impl& im = *out->impl_;
  im.options = options;
  im.preintegration.process_noise = propagation.process_noise;
  im.preintegration.max_gap_s = propagation.max_gap_s;
  im.preintegration.gravity_stddev_floor_m_s2 = options.gravity_stddev_floor_m_s2;
  im.process_noise = propagation.process_noise;
  if (const std::string invalid = im.preintegration.Validate(); !invalid.empty()) {
    return Status::InvalidArgument("window IMU preintegration (propagation options): " + invalid);
  }
  im.association = association;
  im.update = update;
  im.map = map;
  im.parallel = parallel;
  SWARMLIO_RETURN_IF_ERROR(Marginalizer::Create(options.marginalization, &im.marginalizer));
  *smoother = std::move(out);
  return Status::Ok();
}

int WindowSmoother::size() const { return static_cast<int>(impl_->scans.size()); }
const WindowCounters& WindowSmoother::counters() const { return impl_->counters; }

void WindowSmoother::StartInterval(int64_t stamp_ns,
                                   const ImuSample& last_sample,
                                   double acceleration_to_m_s2,
                                   const EgoState& newest) {
  Impl& im = *impl_;
  im.interval_ok =
      lio::ImuPreintegration::Create(im.preintegration, &im.interval).ok() &&
      im.interval
          ->Reset(stamp_ns, last_sample, acceleration_to_m_s2, newest.gyro_bias, newest.accel_bias)
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

Status WindowSmoother::Impl::SetPrior(MarginalizationPrior system) {
  std::unique_ptr<MarginalizationPriorFactor> factor;
  SWARMLIO_RETURN_IF_ERROR(MarginalizationPriorFactor::Create(system, prior_options, &factor));
  prior.system = std::move(system);
  prior.factor = std::move(factor);
  return Status::Ok();
}

namespace {

// Information (and gradient 0) of N(current values, covariance) over blocks.
Status GaussianSystem(const std::vector<double*>& blocks,
                      const std::vector<const ceres::Manifold*>& manifolds,
                      const Eigen::MatrixXd& covariance,
                      MarginalizationPrior* system) {
  const Eigen::MatrixXd C = 0.5 * (covariance + covariance.transpose());
  const Eigen::LLT<Eigen::MatrixXd> llt(C);
  if (llt.info() != Eigen::Success || !C.allFinite()) {
    return Status::InvalidArgument("window: prior covariance is not positive definite");
  }
  MarginalizationPrior& s = *system;
  s = MarginalizationPrior();
  s.information = llt.solve(Eigen::MatrixXd::Identity(C.rows(), C.cols()));
  s.information = 0.5 * (s.information + s.information.transpose()).eval();
  s.gradient = Eigen::VectorXd::Zero(C.rows());
  s.parameter_blocks = blocks;
  s.manifolds = manifolds;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const int ambient = manifolds[b]->AmbientSize();
    s.linearization_points.push_back(Eigen::Map<const Eigen::VectorXd>(blocks[b], ambient));
    s.ambient_sizes.push_back(ambient);
    s.tangent_sizes.push_back(manifolds[b]->TangentSize());
  }
  return Status::Ok();
}

}  // namespace

Status WindowSmoother::Impl::SetGaussianPrior(const std::vector<double*>& blocks,
                                              const std::vector<const ceres::Manifold*>& manifolds,
                                              const Eigen::MatrixXd& covariance) {
  MarginalizationPrior system;
  SWARMLIO_RETURN_IF_ERROR(GaussianSystem(blocks, manifolds, covariance, &system));
  return SetPrior(std::move(system));
}

Status WindowSmoother::Impl::ExtendPrior(double* block,
                                         const ceres::Manifold* manifold,
                                         const Eigen::MatrixXd& covariance) {
  MarginalizationPrior extra;
  SWARMLIO_RETURN_IF_ERROR(GaussianSystem({block}, {manifold}, covariance, &extra));
  MarginalizationPrior s = prior.system;
  const int n = static_cast<int>(s.gradient.size());
  const int m = static_cast<int>(extra.gradient.size());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n + m, n + m);
  H.topLeftCorner(n, n) = s.information;
  H.bottomRightCorner(m, m) = extra.information;
  s.information = std::move(H);
  s.gradient.conservativeResize(n + m);
  s.gradient.tail(m).setZero();
  s.parameter_blocks.push_back(block);
  s.manifolds.push_back(manifold);
  s.linearization_points.push_back(extra.linearization_points[0]);
  s.ambient_sizes.push_back(extra.ambient_sizes[0]);
  s.tangent_sizes.push_back(extra.tangent_sizes[0]);
  return SetPrior(std::move(s));
}

void WindowSmoother::Impl::AddTeammateRandomWalk(double sum_dt2,
                                                 MarginalizationPrior* system) const {
  // x' = x + E w, w ~ N(0, Q): marginalizing w from 1/2 |x' - E w|^2_H + b^T (x' - E w)
  // + 1/2 w^T Q^-1 w gives H' = H - H E M^-1 E^T H, b' = b - H E M^-1 E^T b,
  // M = Q^-1 + E^T H E (the covariance form: P' = P + E Q E^T).
  const double q_rotation = sum_dt2 * process_noise.teammate_rotation_cov_rad2_s2;
  const double q_translation = sum_dt2 * process_noise.teammate_translation_cov_m2_s2;
  if (!(q_rotation > 0.0) || !(q_translation > 0.0)) return;
  std::vector<int> index;
  std::vector<double> q;
  int offset = 0;
  for (size_t b = 0; b < system->parameter_blocks.size(); ++b) {
    if (system->manifolds[b] == &teammate_manifold) {
      for (int k = 0; k < kTeammateDim; ++k) {
        index.push_back(offset + k);
        q.push_back(k < 3 ? q_rotation : q_translation);
      }
    }
    offset += system->tangent_sizes[b];
  }
  if (index.empty()) return;
  const int n = offset;
  const int m = static_cast<int>(index.size());
  Eigen::MatrixXd HE(n, m);
  for (int j = 0; j < m; ++j) HE.col(j) = system->information.col(index[static_cast<size_t>(j)]);
  Eigen::MatrixXd M(m, m);
  Eigen::VectorXd Eb(m);
  for (int i = 0; i < m; ++i) {
    M.row(i) = HE.row(index[static_cast<size_t>(i)]);
    M(i, i) += 1.0 / q[static_cast<size_t>(i)];
    Eb(i) = system->gradient(index[static_cast<size_t>(i)]);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (M + M.transpose()));
  if (llt.info() != Eigen::Success) return;
  system->information -= HE * llt.solve(HE.transpose());
  system->information = 0.5 * (system->information + system->information.transpose()).eval();
  system->gradient -= HE * llt.solve(Eb);
}

void WindowSmoother::Impl::Leave(WindowScan* scan, std::vector<LeavingScan>* leaving) {
  LeavingScan out;
  out.state = scan->State();
  out.insert = scan->updated && !scan->in_map;
  if (out.insert) {
    out.points_in_b = std::move(scan->points_in_b);
    out.excluded = std::move(scan->excluded);
    if (scan->associator != nullptr) out.matched = scan->associator->matched_point_indices();
  }
  leaving->push_back(std::move(out));
}

namespace {

bool Names(const lio::OwnedResidualTerm& term, const lio::StateKey& key) {
  return std::find(term.blocks.begin(), term.blocks.end(), key) != term.blocks.end();
}

}  // namespace

Status WindowSmoother::Impl::AdoptTerm(int64_t stamp_ns,
                                       const char* model,
                                       lio::OwnedResidualTerm* term) const {
  for (lio::StateKey& key : term->blocks) {
    if (key.kind() == lio::StateKey::Kind::kEgo) key = lio::StateKey::EgoAt(stamp_ns);
  }
  if (term->cost == nullptr || term->cost->parameter_block_sizes().size() != term->blocks.size()) {
    return Status::InvalidArgument(std::string("window: a residual block of ") + model +
                                   " does not match its state blocks");
  }
  for (size_t b = 0; b < term->blocks.size(); ++b) {
    const lio::StateKey& key = term->blocks[b];
    if (BlockOf(key) == nullptr) {
      return Status::InvalidArgument(std::string("window: a residual block of ") + model +
                                     " names " + key.ToString() +
                                     ", which the window does not hold (marginalized, "
                                     "never added, or not a teammate in the state)");
    }
    if (term->cost->parameter_block_sizes()[b] != ManifoldOf(key)->AmbientSize()) {
      return Status::InvalidArgument(std::string("window: a residual block of ") + model +
                                     " does not match its state blocks");
    }
  }
  return Status::Ok();
}

Status WindowSmoother::Impl::TakeObservations(WindowStateInput* input, WindowScan* scan) {
  Status status;
  for (lio::MeasurementModel* model : input->models) {
    if (model == nullptr) continue;
    std::vector<lio::OwnedResidualTerm> terms;
    if (!model->ReleaseTerms(&terms)) {
      status = Status::FailedPrecondition(std::string("window: measurement model ") +
                                          model->name() + " cannot be kept in the window");
      continue;
    }
    for (lio::OwnedResidualTerm& term : terms) {
      if (Status adopted = AdoptTerm(scan->stamp_ns, model->name(), &term); !adopted.ok()) {
        status = std::move(adopted);
        continue;
      }
      // Considered teammates: held at the prediction in this scan's terms.
      for (int id : input->considered_teammates) {
        const auto at =
            std::find(term.blocks.begin(), term.blocks.end(), lio::StateKey::Extrinsic(id));
        if (at == term.blocks.end() || !input->x_pred.HasTeammate(id)) continue;
        std::vector<double> value(GlobalExtrinsic::kAmbientSize);
        input->x_pred.teammate(id).ToParameters(value.data());
        term.cost = std::make_unique<ConstantBlockCost>(
            std::move(term.cost), static_cast<int>(at - term.blocks.begin()), std::move(value));
        term.blocks.erase(at);
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
  prior = Prior();
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
  return SetGaussianPrior(blocks, manifolds, input->P_pred);
}

Status WindowSmoother::Impl::RemoveTeammate(int id) {
  double* T = Teammate(id);
  if (T == nullptr) return Status::Ok();
  for (auto& s : scans) {
    auto& obs = s->observations;
    obs.erase(std::remove_if(obs.begin(), obs.end(),
                             [id](const lio::OwnedResidualTerm& t) {
                               return Names(t, lio::StateKey::Extrinsic(id));
                             }),
              obs.end());
  }
  // Its information in the prior moves onto the prior's other blocks.
  if (prior.factor != nullptr && prior.Touches(T)) {
    std::vector<double*> others;
    for (double* b : prior.system.parameter_blocks) {
      if (b != T) others.push_back(b);
    }
    marginalizer->Clear();
    SWARMLIO_RETURN_IF_ERROR(marginalizer->AddResidualBlock(
        {prior.factor.get(), nullptr, prior.system.parameter_blocks, prior.system.manifolds}));
    MarginalizationPrior system;
    SWARMLIO_RETURN_IF_ERROR(marginalizer->Marginalize({T}, others, &system));
    SWARMLIO_RETURN_IF_ERROR(SetPrior(std::move(system)));
  }
  teammates.erase(
      std::remove_if(teammates.begin(), teammates.end(),
                     [id](const std::unique_ptr<TeammateBlock>& t) { return t->id == id; }),
      teammates.end());
  return Status::Ok();
}

Status WindowSmoother::Impl::SyncTeammates(const SwarmState& x_pred,
                                           const Eigen::MatrixXd& P_pred) {
  const std::vector<int>& ids = x_pred.layout().teammate_ids();
  std::vector<int> gone;
  for (const auto& t : teammates) {
    if (std::find(ids.begin(), ids.end(), t->id) == ids.end()) gone.push_back(t->id);
  }
  for (int id : gone) SWARMLIO_RETURN_IF_ERROR(RemoveTeammate(id));
  std::vector<std::unique_ptr<TeammateBlock>> ordered;
  for (int id : ids) {
    auto it = std::find_if(
        teammates.begin(), teammates.end(),
        [id](const std::unique_ptr<TeammateBlock>& t) { return t != nullptr && t->id == id; });
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
    SWARMLIO_RETURN_IF_ERROR(ExtendPrior(block, &teammate_manifold, C));
  }
  teammates = std::move(ordered);
  return Status::Ok();
}

Status WindowSmoother::Impl::AddTermsNaming(const WindowScan& s0, std::vector<double*>* kept) {
  const lio::StateKey leaving = lio::StateKey::EgoAt(s0.stamp_ns);
  for (const auto& s : scans) {
    for (const lio::OwnedResidualTerm& term : s->observations) {
      if (!Names(term, leaving)) continue;
      MarginalizationResidualBlock block;
      block.cost_function = term.cost.get();
      BlocksOf(term, &block.parameter_blocks, &block.manifolds);
      for (double* b : block.parameter_blocks) {
        if (b != s0.ego.data() && std::find(kept->begin(), kept->end(), b) == kept->end()) {
          kept->push_back(b);
        }
      }
      SWARMLIO_RETURN_IF_ERROR(marginalizer->AddResidualBlock(block));
    }
  }
  return Status::Ok();
}

void WindowSmoother::Impl::DropTermsNaming(WindowScan* s0) {
  const lio::StateKey leaving = lio::StateKey::EgoAt(s0->stamp_ns);
  for (size_t i = 1; i < scans.size(); ++i) {
    auto& obs = scans[i]->observations;
    obs.erase(
        std::remove_if(obs.begin(), obs.end(),
                       [&leaving](const lio::OwnedResidualTerm& t) { return Names(t, leaving); }),
        obs.end());
  }
  // A term of the leaving scan that does not name its state (teammate
  // blocks only) stays in the window, with the next state.
  for (lio::OwnedResidualTerm& term : s0->observations) {
    if (!Names(term, leaving)) scans[1]->observations.push_back(std::move(term));
  }
  s0->observations.clear();
}

Status WindowSmoother::Impl::MarginalizeOldest(std::vector<LeavingScan>* leaving) {
  WindowScan& s0 = *scans[0];
  WindowScan& s1 = *scans[1];
  if (prior.factor == nullptr || !prior.Touches(s0.ego.data())) {
    return Status::Internal("window: the prior does not hold the oldest state");
  }
  marginalizer->Clear();
  std::vector<double*> kept{s1.ego.data()};
  const auto keep = [&kept, &s0](double* b) {
    if (b != s0.ego.data() && std::find(kept.begin(), kept.end(), b) == kept.end()) {
      kept.push_back(b);
    }
  };
  SWARMLIO_RETURN_IF_ERROR(marginalizer->AddResidualBlock(
      {prior.factor.get(), nullptr, prior.system.parameter_blocks, prior.system.manifolds}));
  for (double* b : prior.system.parameter_blocks) keep(b);
  if (s0.HasPlaneInformation()) {
    SWARMLIO_RETURN_IF_ERROR(marginalizer->AddResidualBlock(
        {&s0.compressed, nullptr, {s0.ego.data()}, {&ego_manifold}}));
  }
  SWARMLIO_RETURN_IF_ERROR(marginalizer->AddResidualBlock({s1.imu_factor.get(),
                                                           nullptr,
                                                           {s0.ego.data(), s1.ego.data()},
                                                           {&ego_manifold, &ego_manifold}}));
  // Every kept term on the leaving state, whichever scan took it over (a
  // term may name several window states: loop closures, relocalization).
  SWARMLIO_RETURN_IF_ERROR(AddTermsNaming(s0, &kept));
  MarginalizationPrior system;
  SWARMLIO_RETURN_IF_ERROR(marginalizer->Marginalize({s0.ego.data()}, kept, &system));
  // The teammate blocks random-walk over the interval [s0, s1] as in the
  // filter (one shared block per teammate inside the window).
  AddTeammateRandomWalk(s1.imu->SumOfSquaredSteps(), &system);
  SWARMLIO_RETURN_IF_ERROR(SetPrior(std::move(system)));
  ++counters.marginalizations;
  DropTermsNaming(&s0);
  Leave(&s0, leaving);
  scans.pop_front();
  scans.front()->imu_factor.reset();
  scans.front()->imu.reset();
  return Status::Ok();
}

Status WindowSmoother::AddState(WindowStateInput input,
                                std::vector<LeavingScan>* leaving,
                                double* marginalize_s,
                                std::string* model_error) {
  Impl& im = *impl_;
  const Clock::time_point t0 = Clock::now();
  model_error->clear();
  const Status status = im.AddState(&input, leaving, model_error);
  if (!status.ok()) {
    for (auto& s : im.scans) im.Leave(s.get(), leaving);
    im.scans.clear();
    im.prior = Prior();
    im.teammates.clear();
  }
  *marginalize_s = SecondsSince(t0);
  return status;
}

Status WindowSmoother::Impl::AddState(WindowStateInput* in,
                                      std::vector<LeavingScan>* leaving,
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
  scan.associator = std::make_unique<lio::ScanAssociator>(im.map, im.association, im.parallel);
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

}  // namespace swarmlio::window
