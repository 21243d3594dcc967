// StateKey: the name of one state block a residual term depends on
// (ResidualTerm::blocks, measurement_model.h; docs/architecture.md "Named
// states").
//
//   StateKey::Ego()             the ego state of the scan being updated
//   StateKey::EgoAt(stamp_ns)   the ego state at a scan end the back end holds
//                               (int64 ns in the drone's own clock, the
//                               ScanOutput::stamp_ns of that scan)
//   StateKey::Extrinsic(id)     teammate id's global extrinsic T_Gi_Gj
//
// The back end resolves a key to its parameter block: the filter (EsikfUpdate)
// holds one ego state, so it resolves Ego() and EgoAt(t) only for t the stamp
// of the scan being updated; the fixed-lag window resolves EgoAt(t) to the
// window state at t. A key the back end cannot resolve is an error naming
// the key (ToString), never a silent substitution.
#pragma once

#include <cstdint>
#include <string>

namespace swarmlio::lio {

class StateKey {
 public:
  enum class Kind { kEgo, kEgoAt, kTeammateExtrinsic };

  /// The ego state of the scan being updated (the one the model belongs to).
  static StateKey Ego() { return StateKey(Kind::kEgo, -1, 0); }
  /// The ego state at the scan end `stamp_ns` [ns].
  static StateKey EgoAt(int64_t stamp_ns) { return StateKey(Kind::kEgoAt, -1, stamp_ns); }
  /// Teammate `teammate_id`'s global extrinsic block T_Gi_Gj.
  static StateKey Extrinsic(int teammate_id) {
    return StateKey(Kind::kTeammateExtrinsic, teammate_id, 0);
  }

  Kind kind() const { return kind_; }
  /// An ego state (Ego() or EgoAt(t)).
  bool is_ego() const { return kind_ != Kind::kTeammateExtrinsic; }
  /// EgoAt's stamp [ns]; 0 for the other kinds.
  int64_t stamp_ns() const { return stamp_ns_; }
  /// Extrinsic's teammate id; -1 for the other kinds.
  int teammate_id() const { return teammate_id_; }

  /// "Ego()", "EgoAt(<stamp> ns)" or "Extrinsic(<id>)", for errors.
  std::string ToString() const;

  friend bool operator==(const StateKey& a, const StateKey& b) {
    return a.kind_ == b.kind_ && a.teammate_id_ == b.teammate_id_ && a.stamp_ns_ == b.stamp_ns_;
  }
  friend bool operator!=(const StateKey& a, const StateKey& b) { return !(a == b); }

 private:
  StateKey(Kind kind, int teammate_id, int64_t stamp_ns)
      : kind_(kind), teammate_id_(teammate_id), stamp_ns_(stamp_ns) {}

  Kind kind_;
  int teammate_id_;
  int64_t stamp_ns_;
};

inline std::string StateKey::ToString() const {
  switch (kind_) {
    case Kind::kEgo:
      return "Ego()";
    case Kind::kEgoAt:
      return "EgoAt(" + std::to_string(stamp_ns_) + " ns)";
    case Kind::kTeammateExtrinsic:
      break;
  }
  return "Extrinsic(" + std::to_string(teammate_id_) + ")";
}

}  // namespace swarmlio::lio
