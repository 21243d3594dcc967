// Options fields that are lists of options structs (std::vector<T>).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "swarmlio/config/config_file.h"
#include "swarmlio/config/dump_options.h"
#include "tests/config/config_test_util.h"
#include "tests/config/test_options.h"

namespace swarmlio::config {
namespace {

using config_test::InnerOptions;
using config_test::ParseAndRead;
using ::testing::HasSubstr;

struct StepOptions {
  std::string label = "step";
  double duration_s = 1.0;
  std::vector<double> weights;

  template <class V>
  void VisitFields(V&& v) {
    v("label", label, FieldSpec::Doc("a label"));
    v("duration_s", duration_s, FieldSpec::AtLeast(0.0, "s", "a duration"));
    v("weights", weights);
  }
  std::string Validate() const {
    std::string error = ValidateFields(*this);
    if (error.empty() && label == "bad") error = "label: must not be 'bad'";
    return error;
  }
  bool operator==(const StepOptions& o) const {
    return label == o.label && duration_s == o.duration_s && weights == o.weights;
  }
};

struct GroupOptions {
  std::string name;
  InnerOptions inner;
  std::vector<StepOptions> steps;  // a list inside a list element

  template <class V>
  void VisitFields(V&& v) {
    v("name", name, FieldSpec::Doc("a name"));
    v("inner", inner);
    v("steps", steps, FieldSpec::Doc("the steps"));
  }
  std::string Validate() const { return ValidateFields(*this); }
  bool operator==(const GroupOptions& o) const {
    return name == o.name && inner == o.inner && steps == o.steps;
  }
};

struct ListOptions {
  int count = 1;
  std::vector<InnerOptions> items;
  std::vector<GroupOptions> groups = {GroupOptions()};

  template <class V>
  void VisitFields(V&& v) {
    v("count", count, FieldSpec::AtLeast(0, "", "a count"));
    v("items", items, FieldSpec::Doc("a list of sections"));
    v("groups", groups);
  }
  std::string Validate() const { return ValidateFields(*this); }
  bool operator==(const ListOptions& o) const {
    return count == o.count && items == o.items && groups == o.groups;
  }
};

TEST(ConfigListTest, EachElementStartsFromDefaults) {
  const std::string yaml = R"(
test:
  items:
    - {gain: 4}
    - steps: 7
    -
  groups:
    - name: a
      steps:
        - {label: s1, duration_s: 2}
        - {weights: [1, 2]}
)";
  ListOptions options;
  options.items = {InnerOptions(), InnerOptions(), InnerOptions(), InnerOptions()};
  const Status status = ParseAndRead(yaml, "test", &options);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(options.items.size(), 3u);  // the list is replaced, not merged
  EXPECT_EQ(options.items[0].gain, 4.0);
  EXPECT_EQ(options.items[0].steps, 3);
  EXPECT_EQ(options.items[1].gain, 2.0);
  EXPECT_EQ(options.items[1].steps, 7);
  EXPECT_TRUE(options.items[2] == InnerOptions());  // an empty element: all defaults
  ASSERT_EQ(options.groups.size(), 1u);
  EXPECT_EQ(options.groups[0].name, "a");
  ASSERT_EQ(options.groups[0].steps.size(), 2u);
  EXPECT_EQ(options.groups[0].steps[0].label, "s1");
  EXPECT_EQ(options.groups[0].steps[0].duration_s, 2.0);
  EXPECT_EQ(options.groups[0].steps[1].label, "step");
  EXPECT_EQ(options.groups[0].steps[1].weights, (std::vector<double>{1, 2}));
}

TEST(ConfigListTest, EmptyValueKeepsTheListAndBracketsEmptyIt) {
  ListOptions options;
  options.items = {InnerOptions()};
  ASSERT_TRUE(ParseAndRead("test:\n  items:\n  groups: []\n", "test", &options).ok());
  EXPECT_EQ(options.items.size(), 1u);
  EXPECT_TRUE(options.groups.empty());
}

TEST(ConfigListTest, ErrorsNameTheIndexedKeyAndLine) {
  const config_test::ReadErrorCase cases[] = {
      {"test:\n  items:\n    - {gain: 1}\n    - {gain: 0}\n",
       "x.yaml:4: test.items[1].gain: value 0 is out of range (must be > 0)"},
      {"test:\n  items:\n    - gain: 1\n    - gian: 2\n",
       "x.yaml:4: test.items[1].gian: unknown key; did you mean 'gain'?"},
      {"test:\n  items:\n    - {steps: x}\n",
       "x.yaml:3: test.items[0].steps: expected an integer, got 'x'"},
      {"test:\n  items: {gain: 1}\n", "x.yaml:2: test.items: expected a list"},
      {"test:\n  items: [5]\n", "x.yaml:2: test.items[0]: expected a section"},
      {"test:\n  groups:\n    - name: a\n    - name: b\n      steps:\n        - label: ok\n"
       "        - label: bad\n",
       "x.yaml:7: test.groups[1].steps[1].label: must not be 'bad'"},
      {"test:\n  groups:\n    - steps:\n        - {duration_s: -1}\n",
       "x.yaml:4: test.groups[0].steps[0].duration_s: value -1 is out of range"},
      {"test:\n  groups:\n    - steps:\n        - {weights: [1, a]}\n",
       "x.yaml:4: test.groups[0].steps[0].weights[1]: expected a number, got 'a'"},
  };
  config_test::ExpectReadErrors<ListOptions>(cases);
}

TEST(ConfigListTest, ErrorLeavesTheListUnchanged) {
  ListOptions options;
  options.items = {InnerOptions()};
  options.items[0].gain = 9.0;
  const ListOptions before = options;
  EXPECT_FALSE(
      ParseAndRead("test:\n  items: [{gain: 1}, {gain: 2}, {steps: 0}]\n", "test", &options).ok());
  EXPECT_TRUE(options == before);
}

TEST(ConfigListTest, IndexedSectionPathsReadOverExistingValues) {
  ConfigFile file;
  ASSERT_TRUE(
      ConfigFile::Parse("test:\n  items:\n    - {gain: 4}\n    - {steps: 2}\n", "x.yaml", &file)
          .ok());
  InnerOptions inner;
  inner.gain = 8.0;  // e.g. a value from a preset: only the file's keys override it
  ASSERT_TRUE(file.Read("test.items[1]", &inner).ok());
  EXPECT_EQ(inner.gain, 8.0);
  EXPECT_EQ(inner.steps, 2);
  InnerOptions untouched = inner;
  ASSERT_TRUE(file.Read("test.items[5]", &untouched).ok());  // missing element: kept
  EXPECT_TRUE(untouched == inner);
  EXPECT_THAT(file.Read("test.items.x", &inner).message(),
              HasSubstr("x.yaml:2: test.items: expected a section"));
  EXPECT_THAT(file.Read("test[0]", &inner).message(),
              HasSubstr("x.yaml:1: test: expected a list, got a map"));

  EXPECT_TRUE(file.HasKey("test.items[1].steps"));
  EXPECT_FALSE(file.HasKey("test.items[1].gain"));
  EXPECT_FALSE(file.HasKey(""));
  // A caller's own check names the key and its line, or its closest parent's.
  EXPECT_EQ(file.KeyError("test.items[1].steps", "too many").message(),
            "x.yaml:4: test.items[1].steps: too many");
  EXPECT_EQ(file.KeyError("test.items[1].gain", "missing").message(),
            "x.yaml:4: test.items[1].gain: missing");
  EXPECT_EQ(file.KeyError("other", "absent").message(), "x.yaml: other: absent");
}

TEST(ConfigListTest, CrossFieldErrorOnAnOmittedKeyPointsAtItsSection) {
  ConfigFile file;
  ASSERT_TRUE(ConfigFile::Parse("a: 1\nlist:\n  - label: ok\n  -\n    duration_s: 2\n"
                                "    label: bad\n  - {}\n",
                                "x.yaml", &file)
                  .ok());
  StepOptions step;
  EXPECT_EQ(file.Read("list[1]", &step).message(), "x.yaml:6: list[1].label: must not be 'bad'");
  step.label = "bad";  // a bad value the file does not set: the element's own line
  EXPECT_EQ(file.Read("list[2]", &step).message(), "x.yaml:7: list[2].label: must not be 'bad'");
}

TEST(ConfigListTest, DumpRoundTripsAndReadsBack) {
  ListOptions options;
  options.count = 3;
  options.items = {InnerOptions(), InnerOptions()};
  options.items[1].gain = 0.1 + 0.2;
  options.groups.resize(3);
  options.groups[0].name = "first: with colon";
  options.groups[0].steps = {StepOptions(), StepOptions()};
  options.groups[0].steps[1].label = "- dash";
  options.groups[0].steps[1].weights = {1.0 / 3.0};
  options.groups[2].inner.steps = 9;
  const std::string yaml = DumpOptions(options, "test");
  ConfigFile file;
  ASSERT_TRUE(ConfigFile::Parse(yaml, "dump.yaml", &file).ok()) << yaml;
  ListOptions loaded;
  loaded.groups.clear();
  const Status status = file.Read("test", &loaded);
  ASSERT_TRUE(status.ok()) << status.message() << "\n" << yaml;
  EXPECT_TRUE(loaded == options) << yaml << "\nvs\n" << DumpOptions(loaded, "test");
  EXPECT_EQ(DumpOptions(loaded, "test"), yaml);
  EXPECT_THAT(yaml, HasSubstr("  # a list of sections\n  items:\n    - # a gain; > 0\n"
                              "      gain: 2\n      # a count; in [1, 10]\n      steps: 3\n"));

  ListOptions empty;
  empty.groups.clear();
  EXPECT_THAT(DumpOptions(empty), HasSubstr("\nitems: []\n"));
  ASSERT_TRUE(ConfigFile::Parse(DumpOptions(empty), "dump.yaml", &file).ok());
  ListOptions reloaded;
  ASSERT_TRUE(file.Read("", &reloaded).ok());
  EXPECT_TRUE(reloaded == empty);
}

}  // namespace
}  // namespace swarmlio::config
