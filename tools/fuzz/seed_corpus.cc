// Seed messages for the packet-decoder fuzz target, written as fuzzer inputs.
#include "tools/fuzz/seed_corpus.h"

#include <Eigen/Geometry>
#include <cstdint>
#include <fstream>

#include "swarmlio/net/packet_codec.h"
#include "tools/fuzz/fuzz_input.h"

namespace swarmlio::fuzz {
namespace {

Eigen::Matrix3d Covariance3(double scale) {
  Eigen::Matrix3d c;
  c << 4, 1, 0.5,  //
      1, 3, 0.25,  //
      0.5, 0.25, 2;
  return scale * c;
}

net::EgoStateMessage EgoState(int sender,
                              int num_observations,
                              int num_past = 0,
                              int num_echoes = 0) {
  net::EgoStateMessage m;
  m.sender_id = sender;
  m.stamp_ns = 1'700'000'000'123'456'789;
  m.session_start_ns = 1'700'000'000'000'000'000;
  m.q_Gj_bj = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  m.p_bj_in_Gj = {1234.5, -67.25, 8.125};
  m.v_bj_in_Gj = {1.5, -0.5, 0.25};
  m.omega_bj_in_bj = {0.1, -0.2, 0.3};
  m.cov_theta_Gj_bj = Covariance3(1e-5);
  m.cov_p_bj_in_Gj = Covariance3(1e-3);
  m.cov_v_bj_in_Gj = Covariance3(1e-2);
  m.degenerated = num_observations % 2 == 0;
  for (int id = 0; static_cast<int>(m.observations.size()) < num_observations; ++id) {
    if (id == sender) continue;
    net::CurrentObservation o;
    o.observed_id = id;
    o.p_bk_in_bj = {2.0 + id, -1.0, 0.5 * id};
    o.cov_p_bk_in_bj = Covariance3(1e-3 * (1 + id));
    m.observations.push_back(o);
  }
  for (int id = 0; static_cast<int>(m.past_observations.size()) < num_past; ++id) {
    if (id == sender) continue;
    net::PastObservation o;
    o.observed_id = id;
    o.age_ns = 100'000'000 + 1'000'000 * id;
    o.p_bk_in_Gj = m.p_bj_in_Gj + Eigen::Vector3d(-3.0 + id, 2.0, 0.25 * id);
    o.cov_p_bk_in_Gj = Covariance3(2e-3 * (1 + id));
    m.past_observations.push_back(o);
  }
  if (num_echoes > 0) m.send_delay_ns = 12'340'000;
  for (int id = 0; static_cast<int>(m.echoes.size()) < num_echoes; ++id) {
    if (id == sender) continue;
    net::StateEcho e;
    e.teammate_id = id;
    e.stamp_ref = static_cast<uint16_t>(1000 * id + 7);
    e.send_delay_ns = 3'000'000 + 10'000 * id;
    e.arrival_ns = m.stamp_ns + m.send_delay_ns - 40'000'000 - 1'000'000 * id;
    m.echoes.push_back(e);
  }
  return m;
}

net::GlobalExtrinsicMessage GlobalExtrinsic(int sender, int num_entries) {
  net::GlobalExtrinsicMessage m;
  m.sender_id = sender;
  m.stamp_ns = 42'000'000'000;
  m.g_in_Gi = {0.01, -0.02, -9.81};
  m.cov_g_in_Gi = Covariance3(1e-4);
  for (int id = 0; static_cast<int>(m.entries.size()) < num_entries; ++id) {
    if (id == sender) continue;
    net::GlobalExtrinsicEntry e;
    e.teammate_id = id;
    e.source = id % 2 == 0 ? net::ExtrinsicSource::kTrajectoryMatch : net::ExtrinsicSource::kGraph;
    e.q_Ga_Gb = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * (id + 1), Eigen::Vector3d::UnitZ()));
    e.p_Gb_in_Ga = {10.0 * id, -2.5, 0.75};
    e.covariance = 1e-4 * Eigen::Matrix<double, 6, 6>::Identity();
    e.covariance(0, 3) = e.covariance(3, 0) = 2e-5;  // rotation-translation correlation
    m.entries.push_back(e);
  }
  return m;
}

net::TimeSyncMessage TimeSync(int sender, int target, bool response) {
  net::TimeSyncMessage m;
  m.sender_id = sender;
  m.target_id = target;
  m.is_response = response;
  m.t1_ns = 1'000'000'123;
  m.t2_ns = response ? 1'000'500'456 : 0;
  m.t3_ns = response ? 1'000'600'789 : 0;
  return m;
}

net::AirframeMessage Airframe(int sender, int shape) {
  net::AirframeMessage m;
  m.sender_id = sender;
  m.stamp_ns = 43'000'000'000;
  m.reflector_shape = shape;
  m.reflector_half_extents_m = {0.102, 0.072, 0.025};
  m.reflector_centre_in_body_m = {0.01, -0.02, -0.035};
  m.depth_offset_m = 0.07;
  m.size_m = 0.45;
  m.min_intensity = 151.0;
  m.centroid_sigma_m = 0.015;
  return m;
}

const char* TypeTag(const net::SwarmMessage& message) {
  switch (net::TypeOf(message)) {
    case net::MessageType::kEgoState:
      return "ego_state";
    case net::MessageType::kGlobalExtrinsic:
      return "global_extrinsic";
    case net::MessageType::kTimeSync:
      return "time_sync";
    case net::MessageType::kAirframe:
      return "airframe";
  }
  return "unknown";
}

Status WriteFile(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) return Status::IoError("cannot write seed " + path);
  return Status::Ok();
}

}  // namespace

std::vector<net::SwarmMessage> SeedMessages() {
  return {EgoState(3, 0),        EgoState(3, 1),         EgoState(3, 2),
          EgoState(7, 5),        EgoState(63, 24),       EgoState(3, 1, 1),
          EgoState(3, 1, 0, 2),  EgoState(9, 24, 24, 8), EgoState(9, 24, 24),
          GlobalExtrinsic(5, 0), GlobalExtrinsic(5, 1),  GlobalExtrinsic(2, 3),
          GlobalExtrinsic(0, 8), TimeSync(1, 2, false),  TimeSync(2, 1, true),
          Airframe(4, 0),        Airframe(63, 2)};
}

Status WriteSeedCorpus(const std::string& dir) {
  const std::vector<net::SwarmMessage> messages = SeedMessages();
  for (size_t i = 0; i < messages.size(); ++i) {
    std::vector<uint8_t> packet;
    SWARMLIO_RETURN_IF_ERROR(FuzzCodec().Encode(messages[i], static_cast<uint32_t>(i), &packet));
    const std::string name = std::to_string(i) + "_" + TypeTag(messages[i]);
    SWARMLIO_RETURN_IF_ERROR(
        WriteFile(dir + "/raw_" + name, InputFromPacket(InputMode::kRawPacket, packet)));
    SWARMLIO_RETURN_IF_ERROR(
        WriteFile(dir + "/signed_" + name, InputFromPacket(InputMode::kSignedPacket, packet)));
  }
  return Status::Ok();
}

}  // namespace swarmlio::fuzz
