// Helpers shared by the config tests: read a section from YAML text and check
// tables of expected errors.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "swarmlio/config/config_file.h"

namespace swarmlio::config_test {

/// Parses `yaml` as if it were the file "x.yaml" and reads `section` into `*options`.
template <class Options>
Status ParseAndRead(const std::string& yaml, const std::string& section, Options* options) {
  config::ConfigFile file;
  SWARMLIO_RETURN_IF_ERROR(config::ConfigFile::Parse(yaml, "x.yaml", &file));
  return file.Read(section, options);
}

/// YAML text and a part of the error it must give.
struct ReadErrorCase {
  const char* yaml;
  const char* message;
};

/// Reading section "test" of each case into a default `Options` fails with a
/// message that contains the case's message.
template <class Options, size_t N>
void ExpectReadErrors(const ReadErrorCase (&cases)[N]) {
  for (const ReadErrorCase& c : cases) {
    Options options;
    const Status status = ParseAndRead(c.yaml, "test", &options);
    EXPECT_FALSE(status.ok()) << c.yaml;
    EXPECT_THAT(status.message(), ::testing::HasSubstr(c.message)) << c.yaml;
  }
}

}  // namespace swarmlio::config_test
