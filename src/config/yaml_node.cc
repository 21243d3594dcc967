#include "swarmlio/config/yaml_node.h"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <system_error>
#include <utility>

namespace swarmlio::config {

struct YamlNode::Impl {
  YAML::Node node;
  int line = 0;  // 1-based, 0 unknown
};

namespace {

int LineOf(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? 0 : mark.line + 1;
}

// Strict decimal integer with an optional sign, e.g. "-12", "+7".
bool ParseInt64(const std::string& text, int64_t* value) {
  const char* begin = text.data();
  const char* end = begin + text.size();
  if (begin != end && *begin == '+') ++begin;
  if (begin == end) return false;
  int64_t parsed = 0;
  const auto [ptr, ec] = std::from_chars(begin, end, parsed);
  if (ec != std::errc() || ptr != end) return false;
  *value = parsed;
  return true;
}

// Decimal or scientific number, plus the YAML 1.2 spellings of inf and nan.
bool ParseDouble(const std::string& text, double* value) {
  static const std::pair<const char*, double> kSpecial[] = {
      {".inf", std::numeric_limits<double>::infinity()},
      {"+.inf", std::numeric_limits<double>::infinity()},
      {"-.inf", -std::numeric_limits<double>::infinity()},
      {".nan", std::numeric_limits<double>::quiet_NaN()},
      {".Inf", std::numeric_limits<double>::infinity()},
      {"+.Inf", std::numeric_limits<double>::infinity()},
      {"-.Inf", -std::numeric_limits<double>::infinity()},
      {".NaN", std::numeric_limits<double>::quiet_NaN()},
  };
  for (const auto& [spelling, special] : kSpecial) {
    if (text == spelling) {
      *value = special;
      return true;
    }
  }
  const char* begin = text.data();
  const char* end = begin + text.size();
  if (begin != end && *begin == '+') ++begin;
  if (begin == end) return false;
  // from_chars also accepts "inf"/"nan" spelled C-style; YAML does not.
  if (std::isalpha(static_cast<unsigned char>(*begin)) ||
      (*begin == '-' && end - begin > 1 && std::isalpha(static_cast<unsigned char>(begin[1])))) {
    return false;
  }
  double parsed = 0.0;
  const auto [ptr, ec] = std::from_chars(begin, end, parsed);
  if (ec != std::errc() || ptr != end) return false;
  *value = parsed;
  return true;
}

}  // namespace

YamlNode::YamlNode() = default;
YamlNode::~YamlNode() = default;
YamlNode::YamlNode(const YamlNode&) = default;
YamlNode& YamlNode::operator=(const YamlNode&) = default;
YamlNode::YamlNode(YamlNode&&) noexcept = default;
YamlNode& YamlNode::operator=(YamlNode&&) noexcept = default;
YamlNode::YamlNode(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

YamlNode::Kind YamlNode::kind() const {
  if (!impl_) return Kind::kUndefined;
  switch (impl_->node.Type()) {
    case YAML::NodeType::Null:
      return Kind::kNull;
    case YAML::NodeType::Scalar:
      return Kind::kScalar;
    case YAML::NodeType::Sequence:
      return Kind::kSequence;
    case YAML::NodeType::Map:
      return Kind::kMap;
    case YAML::NodeType::Undefined:
      break;
  }
  return Kind::kUndefined;
}

int YamlNode::line() const { return impl_ ? impl_->line : 0; }

std::string YamlNode::Scalar() const { return IsScalar() ? impl_->node.Scalar() : std::string(); }

bool YamlNode::IsQuoted() const { return IsScalar() && impl_->node.Tag() == "!"; }

std::size_t YamlNode::size() const { return IsSequence() ? impl_->node.size() : 0; }

YamlNode YamlNode::Element(std::size_t i) const {
  if (i >= size()) return YamlNode();
  auto impl = std::make_shared<Impl>();
  impl->node = impl_->node[i];
  impl->line = LineOf(impl->node);
  if (impl->line == 0) impl->line = impl_->line;
  return YamlNode(std::move(impl));
}

std::vector<YamlNode::Entry> YamlNode::Entries() const {
  std::vector<Entry> entries;
  if (!IsMap()) return entries;
  for (YAML::const_iterator it = impl_->node.begin(); it != impl_->node.end(); ++it) {
    Entry entry;
    entry.key_is_scalar = it->first.IsScalar();
    entry.key = entry.key_is_scalar ? it->first.Scalar() : std::string();
    entry.line = LineOf(it->first);
    entries.push_back(std::move(entry));
  }
  return entries;
}

YamlNode YamlNode::Child(const std::string& key) const {
  if (!IsMap()) return YamlNode();
  for (YAML::const_iterator it = impl_->node.begin(); it != impl_->node.end(); ++it) {
    if (!it->first.IsScalar() || it->first.Scalar() != key) continue;
    auto impl = std::make_shared<Impl>();
    impl->node = it->second;
    impl->line = LineOf(it->first);
    return YamlNode(std::move(impl));
  }
  return YamlNode();
}

YamlNode YamlNode::FindPath(const std::string& path) const {
  YamlNode node = *this;
  std::size_t pos = 0;
  while (pos < path.size() && node.IsDefined()) {
    if (path[pos] == '.') {
      ++pos;
      continue;
    }
    if (path[pos] == '[') {
      const std::size_t close = path.find(']', pos);
      if (close == std::string::npos) return YamlNode();
      int64_t index = -1;
      if (!ParseInt64(path.substr(pos + 1, close - pos - 1), &index) || index < 0) {
        return YamlNode();
      }
      node = node.Element(static_cast<std::size_t>(index));
      pos = close + 1;
      continue;
    }
    const std::size_t next = path.find_first_of(".[", pos);
    const std::size_t stop = next == std::string::npos ? path.size() : next;
    node = node.Child(path.substr(pos, stop - pos));
    pos = stop;
  }
  return node;
}

bool YamlNode::AsBool(bool* value) const {
  if (!IsScalar() || IsQuoted()) return false;
  const std::string& text = impl_->node.Scalar();
  if (text == "true" || text == "True" || text == "TRUE") {
    *value = true;
    return true;
  }
  if (text == "false" || text == "False" || text == "FALSE") {
    *value = false;
    return true;
  }
  return false;
}

bool YamlNode::AsInt64(int64_t* value) const {
  return IsScalar() && !IsQuoted() && ParseInt64(impl_->node.Scalar(), value);
}

bool YamlNode::AsDouble(double* value) const {
  return IsScalar() && !IsQuoted() && ParseDouble(impl_->node.Scalar(), value);
}

std::string YamlNode::Describe() const {
  switch (kind()) {
    case Kind::kUndefined:
      return "nothing";
    case Kind::kNull:
      return "an empty value";
    case Kind::kMap:
      return "a map";
    case Kind::kSequence: {
      const std::size_t n = size();
      return "a sequence of " + std::to_string(n) + (n == 1 ? " element" : " elements");
    }
    case Kind::kScalar:
      break;
  }
  std::string text = impl_->node.Scalar();
  constexpr std::size_t kMaxShown = 40;
  if (text.size() > kMaxShown) text = text.substr(0, kMaxShown) + "...";
  return (IsQuoted() ? "the quoted string '" : "'") + text + "'";
}

bool YamlDocument::Parse(const std::string& text,
                         YamlNode* root,
                         int* error_line,
                         std::string* error_message) {
  *error_line = 0;
  try {
    std::vector<YAML::Node> documents = YAML::LoadAll(text);
    if (documents.size() > 1) {
      *error_message = "a config file must hold a single YAML document, found " +
                       std::to_string(documents.size());
      return false;
    }
    auto impl = std::make_shared<YamlNode::Impl>();
    impl->node = documents.empty() ? YAML::Node(YAML::NodeType::Null) : documents.front();
    impl->line = LineOf(impl->node);
    *root = YamlNode(std::move(impl));
    return true;
  } catch (const YAML::Exception& e) {
    *error_line = e.mark.is_null() ? 0 : e.mark.line + 1;
    *error_message = e.msg;
  } catch (const std::exception& e) {
    *error_message = e.what();
  }
  return false;
}

}  // namespace swarmlio::config
