#include "swarmlio/state/swarm_state.h"

#include "swarmlio/common/check.h"
#include "swarmlio/math/so3.h"

namespace swarmlio {
namespace {

using L = ErrorStateLayout;

// Ambient offsets of the ego parameter block (see swarm_state.h).
constexpr int kEgoQuat = 0;
constexpr int kEgoPos = 4;
constexpr int kEgoVel = 7;
constexpr int kEgoBg = 10;
constexpr int kEgoBa = 13;
constexpr int kEgoGrav = 16;

// Eigen's quaternion coefficient order (x, y, z, w) is the ambient layout.
void WriteQuaternion(const Eigen::Quaterniond& q, double* x) {
  Eigen::Map<Eigen::Quaterniond> out(x);
  out = q;
}

Eigen::Quaterniond ReadQuaternion(const double* x) {
  return Eigen::Quaterniond(Eigen::Map<const Eigen::Quaterniond>(x));
}

// q (+) dr = q Exp(dr), renormalised against round-off drift.
Eigen::Quaterniond RotationPlus(const Eigen::Quaterniond& q, const Eigen::Vector3d& dr) {
  return (q * so3::ExpQuaternion(dr)).normalized();
}

// q1 (-) q2 = Log(R2^T R1), the shortest rotation.
Eigen::Vector3d RotationMinus(const Eigen::Quaterniond& q1, const Eigen::Quaterniond& q2) {
  return so3::Log(q2.conjugate() * q1);
}

}  // namespace

void EgoState::ToParameters(double* x) const {
  WriteQuaternion(q_G_b, x + kEgoQuat);
  Eigen::Map<Eigen::Vector3d>(x + kEgoPos) = p_b_in_G;
  Eigen::Map<Eigen::Vector3d>(x + kEgoVel) = v_b_in_G;
  Eigen::Map<Eigen::Vector3d>(x + kEgoBg) = gyro_bias;
  Eigen::Map<Eigen::Vector3d>(x + kEgoBa) = accel_bias;
  Eigen::Map<Eigen::Vector3d>(x + kEgoGrav) = g_in_G;
}

EgoState EgoState::FromParameters(const double* x) {
  EgoState s;
  s.q_G_b = ReadQuaternion(x + kEgoQuat);
  s.p_b_in_G = Eigen::Map<const Eigen::Vector3d>(x + kEgoPos);
  s.v_b_in_G = Eigen::Map<const Eigen::Vector3d>(x + kEgoVel);
  s.gyro_bias = Eigen::Map<const Eigen::Vector3d>(x + kEgoBg);
  s.accel_bias = Eigen::Map<const Eigen::Vector3d>(x + kEgoBa);
  s.g_in_G = Eigen::Map<const Eigen::Vector3d>(x + kEgoGrav);
  return s;
}

EgoState EgoState::BoxPlus(const Eigen::Matrix<double, kTangentSize, 1>& dx) const {
  EgoState s;
  s.q_G_b = RotationPlus(q_G_b, dx.segment<3>(L::kRotation.offset));
  s.p_b_in_G = p_b_in_G + dx.segment<3>(L::kPosition.offset);
  s.v_b_in_G = v_b_in_G + dx.segment<3>(L::kVelocity.offset);
  s.gyro_bias = gyro_bias + dx.segment<3>(L::kGyroBias.offset);
  s.accel_bias = accel_bias + dx.segment<3>(L::kAccelBias.offset);
  s.g_in_G = g_in_G + dx.segment<3>(L::kGravity.offset);
  return s;
}

Eigen::Matrix<double, EgoState::kTangentSize, 1> EgoState::BoxMinus(const EgoState& other) const {
  Eigen::Matrix<double, kTangentSize, 1> d;
  d.segment<3>(L::kRotation.offset) = RotationMinus(q_G_b, other.q_G_b);
  d.segment<3>(L::kPosition.offset) = p_b_in_G - other.p_b_in_G;
  d.segment<3>(L::kVelocity.offset) = v_b_in_G - other.v_b_in_G;
  d.segment<3>(L::kGyroBias.offset) = gyro_bias - other.gyro_bias;
  d.segment<3>(L::kAccelBias.offset) = accel_bias - other.accel_bias;
  d.segment<3>(L::kGravity.offset) = g_in_G - other.g_in_G;
  return d;
}

Eigen::Isometry3d GlobalExtrinsic::T_Ga_Gb() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_Ga_Gb();
  T.translation() = p_Gb_in_Ga;
  return T;
}

void GlobalExtrinsic::ToParameters(double* x) const {
  WriteQuaternion(q_Ga_Gb, x);
  Eigen::Map<Eigen::Vector3d>(x + 4) = p_Gb_in_Ga;
}

GlobalExtrinsic GlobalExtrinsic::FromParameters(const double* x) {
  GlobalExtrinsic e;
  e.q_Ga_Gb = ReadQuaternion(x);
  e.p_Gb_in_Ga = Eigen::Map<const Eigen::Vector3d>(x + 4);
  return e;
}

GlobalExtrinsic GlobalExtrinsic::BoxPlus(
    const Eigen::Matrix<double, kTangentSize, 1>& dx) const {
  GlobalExtrinsic e;
  e.q_Ga_Gb = RotationPlus(q_Ga_Gb, dx.segment<3>(L::kTeammateRotationOffset));
  e.p_Gb_in_Ga = p_Gb_in_Ga + dx.segment<3>(L::kTeammateTranslationOffset);
  return e;
}

Eigen::Matrix<double, GlobalExtrinsic::kTangentSize, 1> GlobalExtrinsic::BoxMinus(
    const GlobalExtrinsic& other) const {
  Eigen::Matrix<double, kTangentSize, 1> d;
  d.segment<3>(L::kTeammateRotationOffset) = RotationMinus(q_Ga_Gb, other.q_Ga_Gb);
  d.segment<3>(L::kTeammateTranslationOffset) = p_Gb_in_Ga - other.p_Gb_in_Ga;
  return d;
}

void SwarmState::AddTeammate(int id, const GlobalExtrinsic& T_Gi_Gj) {
  layout_.AddTeammate(id);
  teammates_.push_back(T_Gi_Gj);
}

void SwarmState::RemoveTeammate(int id) {
  const int slot = layout_.SlotOf(id);
  layout_.RemoveTeammate(id);  // CHECKs presence
  teammates_.erase(teammates_.begin() + slot);
}

const GlobalExtrinsic& SwarmState::teammate(int id) const {
  const int slot = layout_.SlotOf(id);
  CHECK_GE(slot, 0) << "teammate " << id << " is not in the state";
  return teammates_[slot];
}

GlobalExtrinsic& SwarmState::teammate(int id) {
  const int slot = layout_.SlotOf(id);
  CHECK_GE(slot, 0) << "teammate " << id << " is not in the state";
  return teammates_[slot];
}

SwarmState SwarmState::BoxPlus(const Eigen::VectorXd& dx) const {
  CHECK_EQ(dx.size(), Dim());
  SwarmState out = *this;
  out.ego = ego.BoxPlus(dx.head<L::kEgoDim>());
  for (int id : layout_.teammate_ids()) {
    const Segment block = layout_.TeammateBlock(id);
    out.teammate(id) = teammate(id).BoxPlus(dx.segment<L::kTeammateDim>(block.offset));
  }
  return out;
}

Eigen::VectorXd SwarmState::BoxMinus(const SwarmState& other) const {
  CHECK(layout_ == other.layout_) << "boxminus of states with different teammate layouts";
  Eigen::VectorXd d(Dim());
  d.head<L::kEgoDim>() = ego.BoxMinus(other.ego);
  for (int id : layout_.teammate_ids()) {
    const Segment block = layout_.TeammateBlock(id);
    d.segment<L::kTeammateDim>(block.offset) = teammate(id).BoxMinus(other.teammate(id));
  }
  return d;
}

}  // namespace swarmlio
