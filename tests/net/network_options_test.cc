// NetworkOptions read from a YAML `network:` section, validation, overrides.
#include "swarmlio/net/network_options.h"

#include <gtest/gtest.h>

#include "swarmlio/config/config_file.h"
#include "swarmlio/config/dump_options.h"

namespace swarmlio::net {
namespace {

Status ReadNetwork(const std::string& yaml, NetworkOptions* options) {
  config::ConfigFile file;
  SWARMLIO_RETURN_IF_ERROR(config::ConfigFile::Parse(yaml, "net.yaml", &file));
  return file.Read("network", options);
}

TEST(NetworkOptions, DefaultsAreValid) { EXPECT_EQ(NetworkOptions().Validate(), ""); }

TEST(NetworkOptions, ReadsSectionWithOverrides) {
  const std::string yaml =
      "network:\n"
      "  seed: 42\n"
      "  default_link:\n"
      "    latency_mean_s: 0.008\n"
      "    loss_probability: 0.05\n"
      "    bandwidth_bytes_per_s: 250000\n"
      "  links:\n"
      "    - {from_id: 0, to_id: 2, link: {loss_probability: 0.5}}\n"
      "    - {to_id: 2, link: {experimental: {duplicate_probability: 0.1}}}\n";
  NetworkOptions o;
  const Status s = ReadNetwork(yaml, &o);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(o.seed, 42);
  EXPECT_EQ(o.default_link.latency_mean_s, 0.008);
  EXPECT_EQ(o.default_link.loss_probability, 0.05);
  EXPECT_EQ(o.default_link.jitter_std_s, LinkOptions().jitter_std_s);
  ASSERT_EQ(o.links.size(), 2u);
  EXPECT_EQ(o.ForLink(0, 1).loss_probability, 0.05);      // default_link
  EXPECT_EQ(o.ForLink(1, 2).duplicate_probability, 0.1);  // second override
  EXPECT_EQ(o.ForLink(0, 2).duplicate_probability, 0.1);  // last match wins
  EXPECT_EQ(o.ForLink(0, 2).loss_probability, 0.0);       // ... with built-in defaults
  EXPECT_EQ(o.ForLink(2, 0).loss_probability, 0.05);
}

TEST(NetworkOptions, ErrorsNameTheKey) {
  NetworkOptions o;
  Status s = ReadNetwork("network:\n  default_link:\n    loss_probability: 1.5\n", &o);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("network.default_link.loss_probability"), std::string::npos)
      << s.message();
  s = ReadNetwork("network:\n  links:\n    - {from_id: 3, to_id: 3}\n", &o);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("links[0].to_id"), std::string::npos) << s.message();
  s = ReadNetwork("network:\n  links:\n    - {from_id: 64}\n", &o);
  EXPECT_NE(s.message().find("links[0].from_id"), std::string::npos) << s.message();
  s = ReadNetwork("network:\n  default_link:\n    experimental: {max_queue_delay_s: 0}\n", &o);
  EXPECT_NE(s.message().find("network.default_link.experimental.max_queue_delay_s"),
            std::string::npos)
      << s.message();
  s = ReadNetwork("network:\n  latency: 3\n", &o);
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(o.seed, NetworkOptions().seed);  // unchanged on error
}

TEST(NetworkOptions, DumpReadsBackIdentically) {
  NetworkOptions o;
  o.seed = 9;
  o.default_link.jitter_std_s = 0.0025;
  LinkOverride override_link;
  override_link.from_id = 1;
  override_link.link.loss_probability = 0.25;
  o.links.push_back(override_link);
  const std::string yaml = config::DumpOptions(o, "network");
  NetworkOptions loaded;
  ASSERT_TRUE(ReadNetwork(yaml, &loaded).ok()) << yaml;
  EXPECT_EQ(config::DumpOptions(loaded, "network"), yaml);
}

}  // namespace
}  // namespace swarmlio::net
