#include <gtest/gtest.h>

#include "swarmlio/config/config_file.h"
#include "swarmlio/config/dump_options.h"
#include "swarmlio/teammate/teammate_detector_options.h"

namespace swarmlio::teammate {
namespace {

TEST(TeammateDetectorOptions, DefaultsAreValidAndFromTheFieldReference) {
  const TeammateDetectorOptions options;
  EXPECT_EQ(options.Validate(), "");
  EXPECT_EQ(options.clustering.min_reflectivity, 200.0);
  EXPECT_EQ(options.clustering.cluster_tolerance_m, 0.3);
  EXPECT_EQ(options.clustering.max_range_m, 20.0);
  EXPECT_EQ(options.matching.max_mean_residual_m, 0.2);
  EXPECT_EQ(options.excitation.max_positions, 300);
  EXPECT_EQ(options.removal.radius_m, 0.7);
  EXPECT_EQ(options.temporary.max_coast_s, 2.0);
}

TEST(TeammateDetectorOptions, ReadsTheTeammateSection) {
  config::ConfigFile file;
  ASSERT_TRUE(config::ConfigFile::Parse("teammate:\n"
                                        "  clustering: {min_reflectivity: 240, max_object_size_m: 0.5}\n"
                                        "  experimental:\n"
                                        "    excitation: {min_second_singular_value_m2: 12}\n"
                                        "    temporary:\n"
                                        "      filter: {lidar_position_sigma_m: 0.05}\n",
                                        "t.yaml", &file)
                  .ok());
  TeammateDetectorOptions options;
  ASSERT_TRUE(file.Read("teammate", &options).ok());
  EXPECT_EQ(options.clustering.min_reflectivity, 240.0);
  EXPECT_EQ(options.clustering.max_object_size_m, 0.5);
  EXPECT_EQ(options.excitation.min_second_singular_value_m2, 12.0);
  EXPECT_EQ(options.temporary.filter.lidar_position_sigma_m, 0.05);
  EXPECT_EQ(options.matching.window_size, 300);  // untouched
}

TEST(TeammateDetectorOptions, RejectsBadValuesNamingTheKey) {
  config::ConfigFile file;
  ASSERT_TRUE(config::ConfigFile::Parse("teammate:\n  clustering: {experimental: {min_range_m: 30}}\n",
                                        "t.yaml", &file).ok());
  TeammateDetectorOptions options;
  const Status status = file.Read("teammate", &options);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("teammate.clustering.experimental.min_range_m"), std::string::npos)
      << status.message();

  TeammateDetectorOptions bad;
  bad.matching.min_pairs = 500;
  EXPECT_NE(bad.Validate().find("matching.min_pairs"), std::string::npos) << bad.Validate();
  bad = TeammateDetectorOptions();
  bad.association.teammate_gate_m = -1;
  EXPECT_NE(bad.Validate().find("association.teammate_gate_m"), std::string::npos);
}

TEST(TeammateDetectorOptions, DumpsEveryStage) {
  const std::string yaml = config::DumpOptions(TeammateDetectorOptions(), "teammate");
  for (const char* key : {"clustering:", "association:", "temporary:", "filter:", "excitation:",
                          "matching:", "teammate:", "observation:", "removal:",
                          "accel_noise_density_m_s2_sqrt_hz"}) {
    EXPECT_NE(yaml.find(key), std::string::npos) << key;
  }
}

}  // namespace
}  // namespace swarmlio::teammate
