// All options of the teammate detector: YAML section `teammate` (read with
// config::ConfigFile::Read("teammate", &options)). Every key, its unit and
// default, and where the default comes from: docs/teammate.md.
#pragma once

#include <string>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/teammate/association.h"
#include "swarmlio/teammate/clustering.h"
#include "swarmlio/teammate/observation.h"
#include "swarmlio/teammate/point_removal.h"
#include "swarmlio/teammate/teammate_tracker.h"
#include "swarmlio/teammate/temporary_tracker.h"
#include "swarmlio/teammate/trajectory_buffer.h"
#include "swarmlio/teammate/trajectory_matcher.h"

namespace swarmlio::teammate {

struct TeammateDetectorOptions {
  ClusteringOptions clustering;
  TrackAssociationOptions association;
  TemporaryTrackerOptions temporary;
  ExcitationOptions excitation;
  MatchingOptions matching;
  TeammateTrackerOptions teammate;
  ObservationOptions observation;
  PointRemovalOptions removal;

  template <class V>
  void VisitFields(V&& v) {
    v("clustering", clustering);
    v("observation", observation);
    config::VisitExperimental(v, [&](auto& x) {
      x("association", association);
      x("temporary", temporary);
      x("excitation", excitation);
      x("matching", matching);
      x("teammate", teammate);
      x("removal", removal);
    });
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

}  // namespace swarmlio::teammate
