// A test-only options struct that uses every supported field type.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::config_test {

enum class Color { kRed, kGreen, kBlue };

}  // namespace swarmlio::config_test

namespace swarmlio::config {
template <>
struct EnumTraits<config_test::Color> {
  static constexpr std::array<std::pair<config_test::Color, const char*>, 3> kNames{{
      {config_test::Color::kRed, "red"},
      {config_test::Color::kGreen, "green"},
      {config_test::Color::kBlue, "blue"},
  }};
};
}  // namespace swarmlio::config

namespace swarmlio::config_test {

struct InnerOptions {
  double gain = 2.0;
  int steps = 3;

  template <class V>
  void VisitFields(V&& v) {
    v("gain", gain, config::FieldSpec::Positive("", "a gain"));
    v("steps", steps, config::FieldSpec::InRange(1, 10, "", "a count"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
  bool operator==(const InnerOptions& o) const { return gain == o.gain && steps == o.steps; }
};

struct TestOptions {
  bool enabled = true;
  int count = 5;
  uint8_t small = 7;
  int64_t big = 1;
  float ratio = 0.5f;
  double distance_m = 1.5;
  double time_s = 0.1;
  std::string name = "default";
  Color color = Color::kRed;
  Eigen::Vector3d offset_m = Eigen::Vector3d(0.1, 0.2, 0.3);
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  std::vector<double> weights = {1.0, 2.0};
  std::vector<std::string> tags = {"a", "b"};
  InnerOptions inner;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("enabled", enabled, FieldSpec::Doc("a switch"));
    v("count", count, FieldSpec::AtLeast(0, "", "a count"));
    v("small", small);
    v("big", big);
    v("ratio", ratio, FieldSpec::InRange(0.0, 1.0, "", "a ratio"));
    v("distance_m", distance_m, FieldSpec::AtLeast(0.0, "m", "a distance"));
    v("time_s", time_s, FieldSpec::Positive("s", "a duration"));
    v("name", name, FieldSpec::Doc("a name"));
    v("color", color, FieldSpec::Doc("a color"));
    v("offset_m", offset_m, FieldSpec::InRange(-5.0, 5.0, "m", "an offset"));
    v("rotation", rotation, FieldSpec::InRange(-1.0, 1.0, "", "a matrix"));
    v("weights", weights, FieldSpec::AtLeast(0.0, "", "weights"));
    v("tags", tags, FieldSpec::Doc("tags"));
    v("inner", inner);
  }

  std::string Validate() const {
    std::string error = config::ValidateFields(*this);
    if (error.empty() && count > 100) error = "count: must be at most 100";
    return error;
  }

  bool operator==(const TestOptions& o) const {
    return enabled == o.enabled && count == o.count && small == o.small && big == o.big &&
           ratio == o.ratio && distance_m == o.distance_m && time_s == o.time_s && name == o.name &&
           color == o.color && offset_m == o.offset_m && rotation == o.rotation &&
           weights == o.weights && tags == o.tags && inner == o.inner;
  }
};

}  // namespace swarmlio::config_test
