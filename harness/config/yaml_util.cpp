#include "harness/config/yaml_util.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace tgnav::harness {

std::string joinKey(const std::string& context, const std::string& key) {
  return context.empty() ? key : context + "." + key;
}

std::string exactDecimal(double value) {
  char buf[64];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof(buf), value);
  return std::string(buf, r.ptr);
}

YAML::Node exactSequence(const double* values, std::size_t count) {
  YAML::Node seq(YAML::NodeType::Sequence);
  for (std::size_t i = 0; i < count; ++i) seq.push_back(exactDecimal(values[i]));
  seq.SetStyle(YAML::EmitterStyle::Flow);
  return seq;
}

namespace {
// Every mapping key in `node` is a plain scalar: yaml-cpp compares keys as strings when a key is
// looked up, and a key that is itself a mapping or a list ("{}: 1", found by fuzzing) would throw
// its own exception there instead of an error naming the file.
void checkScalarKeys(const YAML::Node& node, const std::filesystem::path& file) {
  if (node.IsMap()) {
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) {
        throw InputError(file.string() + ":" + std::to_string(kv.first.Mark().line + 1) +
                         ": a mapping key must be a plain name, not a mapping or a list");
      }
      checkScalarKeys(kv.second, file);
    }
  } else if (node.IsSequence()) {
    for (const auto& item : node) checkScalarKeys(item, file);
  }
}
}  // namespace

YamlDoc YamlDoc::load(const std::filesystem::path& file) {
  YamlDoc doc;
  doc.file_ = file;
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot open file");
  try {
    doc.root_ = YAML::Load(in);
  } catch (const YAML::Exception& e) {
    throw InputError(file.string() + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  if (!doc.root_.IsMap()) throw InputError(file.string() + ": expected a mapping of keys at top level");
  checkScalarKeys(doc.root_, file);
  return doc;
}

namespace {
std::vector<std::string> splitKey(const std::string& key) {
  std::vector<std::string> segments;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = key.find('.', begin);
    segments.push_back(key.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin));
    if (dot == std::string::npos) return segments;
    begin = dot + 1;
  }
}

bool isPrefixKey(const std::string& prefix, const std::string& key) {
  return key.size() > prefix.size() && key.compare(0, prefix.size(), prefix) == 0 && key[prefix.size()] == '.';
}

bool containsNode(const YAML::Node& tree, const YAML::Node& node) {
  if (tree.is(node)) return true;
  if (tree.IsSequence()) {
    for (const auto& item : tree) {
      if (containsNode(item, node)) return true;
    }
  } else if (tree.IsMap()) {
    for (const auto& kv : tree) {
      if (containsNode(kv.first, node) || containsNode(kv.second, node)) return true;
    }
  }
  return false;
}
}  // namespace

YamlDoc YamlDoc::fromOverrides(const std::vector<std::string>& assignments) {
  YamlDoc doc;
  doc.overrides_ = true;
  doc.root_ = YAML::Node(YAML::NodeType::Map);
  std::set<std::string> leaves;
  std::set<std::string> maps;
  for (const std::string& text : assignments) {
    auto bad = [&](const std::string& why) {
      throw InputError("--set " + text + ": " + why + " (expected dotted.key=value)");
    };
    const std::size_t eq = text.find('=');
    if (eq == std::string::npos) bad("no '='");
    const std::string key = text.substr(0, eq);
    const std::string value_text = text.substr(eq + 1);
    if (key.empty()) bad("empty key");
    const std::vector<std::string> segments = splitKey(key);
    for (const std::string& s : segments) {
      if (s.empty()) bad("empty segment in key '" + key + "'");
    }
    if (leaves.count(key)) bad("key '" + key + "' is set twice");
    if (maps.count(key)) bad("key '" + key + "' is both a value and a mapping of other --set keys");
    YAML::Node value;
    try {
      value = YAML::Load(value_text);
    } catch (const YAML::Exception& e) {
      throw InputError("--set " + text + ": YAML syntax error in the value: " + e.msg);
    }
    if (value.IsNull()) bad("no value");
    YAML::Node node = doc.root_;
    std::string path;
    for (std::size_t i = 0; i + 1 < segments.size(); ++i) {
      path = joinKey(path, segments[i]);
      if (leaves.count(path)) bad("key '" + path + "' is both a value and a mapping of other --set keys");
      maps.insert(path);
      if (!node[segments[i]]) node[segments[i]] = YAML::Node(YAML::NodeType::Map);
      node.reset(node[segments[i]]);
    }
    node[segments.back()] = value;
    leaves.insert(key);
    doc.assignments_.push_back({key, text, value});
  }
  return doc;
}

std::string YamlDoc::name() const { return overrides_ ? std::string("--set overrides") : file_.string(); }

std::string YamlDoc::assignmentFor(const std::string& key) const {
  const Assignment* inside = nullptr;  // the longest assignment key that contains `key`
  const Assignment* below = nullptr;   // the first assignment inside `key`
  for (const Assignment& a : assignments_) {
    if (a.key == key) return a.text;
    if (isPrefixKey(a.key, key) && (!inside || a.key.size() > inside->key.size())) inside = &a;
    if (isPrefixKey(key, a.key) && !below) below = &a;
  }
  if (inside) return inside->text;
  return below ? below->text : std::string();
}

std::vector<std::string> YamlDoc::assignedKeys() const {
  std::vector<std::string> keys;
  for (const Assignment& a : assignments_) keys.push_back(a.key);
  return keys;
}

void YamlDoc::fail(const YAML::Node& node, const std::string& what) const {
  if (overrides_) {
    for (const Assignment& a : assignments_) {
      if (containsNode(a.value, node)) throw InputError("--set " + a.text + ": " + what);
    }
    throw InputError(name() + ": " + what);
  }
  const YAML::Mark mark = node.Mark();
  std::string where = file_.string();
  if (mark.line >= 0) where += ":" + std::to_string(mark.line + 1);
  throw InputError(where + ": " + what);
}

void YamlDoc::failKey(const YAML::Node& node, const std::string& key, const std::string& what) const {
  if (overrides_) {
    const std::string text = assignmentFor(key);
    throw InputError((text.empty() ? name() : "--set " + text) + ": " + what);
  }
  fail(node, what);
}

void YamlDoc::requireKeys(const YAML::Node& map, const std::vector<std::string>& allowed,
                          const std::string& context) const {
  if (!map.IsMap()) failKey(map, context, "'" + (context.empty() ? "<root>" : context) + "' must be a mapping");
  for (const auto& kv : map) {
    const std::string key = kv.first.as<std::string>();
    bool known = false;
    for (const auto& a : allowed) known = known || a == key;
    if (!known) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      failKey(kv.first, joinKey(context, key), "unknown key '" + joinKey(context, key) + "' (allowed: " + list + ")");
    }
  }
}

YAML::Node YamlDoc::child(const YAML::Node& map, const std::string& key, const std::string& context) const {
  const YAML::Node node = map[key];
  if (!node) failKey(map, joinKey(context, key), "missing required key '" + joinKey(context, key) + "'");
  return node;
}

namespace {
std::string scalarText(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  std::ostringstream os;
  os << YAML::Dump(node);
  std::string s = os.str();
  for (char& c : s) c = (c == '\n') ? ' ' : c;
  return s;
}
}  // namespace

double YamlDoc::number(const YAML::Node& map, const std::string& key, const std::string& context) const {
  const YAML::Node node = child(map, key, context);
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
    failKey(node, joinKey(context, key),
            "key '" + joinKey(context, key) + "' has value '" + scalarText(node) + "', expected a finite number");
  }
  return value;
}

std::string YamlDoc::string(const YAML::Node& map, const std::string& key, const std::string& context) const {
  const YAML::Node node = child(map, key, context);
  if (!node.IsScalar() || node.Scalar().empty()) {
    failKey(node, joinKey(context, key),
            "key '" + joinKey(context, key) + "' has value '" + scalarText(node) + "', expected a non-empty string");
  }
  return node.Scalar();
}

std::vector<double> YamlDoc::numbers(const YAML::Node& map, const std::string& key, std::size_t count,
                                     const std::string& context) const {
  const YAML::Node node = child(map, key, context);
  std::vector<double> out;
  bool ok = node.IsSequence() && node.size() == count;
  for (std::size_t i = 0; ok && i < node.size(); ++i) {
    double v = 0.0;
    ok = node[i].IsScalar() && YAML::convert<double>::decode(node[i], v) && std::isfinite(v);
    out.push_back(v);
  }
  if (!ok) {
    failKey(node, joinKey(context, key),
            "key '" + joinKey(context, key) + "' has value '" + scalarText(node) + "', expected a list of " +
                std::to_string(count) + " finite numbers");
  }
  return out;
}

YamlArchive::YamlArchive(const YamlDoc& doc, const YAML::Node& map, std::string context)
    : doc_(&doc), map_(map), context_(std::move(context)) {
  if (!map_.IsMap()) {
    doc_->failKey(map_, context_, "'" + (context_.empty() ? std::string("<root>") : context_) + "' must be a mapping");
  }
}

YamlArchive::YamlArchive(const YAML::Node& out, std::string context)
    : doc_(nullptr), map_(out), context_(std::move(context)) {
  if (!map_.IsMap()) map_ = YAML::Node(YAML::NodeType::Map);
}

YamlArchive YamlArchive::writer(const YAML::Node& out, std::string context) {
  return YamlArchive(out, std::move(context));
}

void YamlArchive::missing(const std::string& key) const {
  doc_->failKey(map_, joinKey(context_, key), "missing required key '" + joinKey(context_, key) + "'");
}

void YamlArchive::badChoice(const std::string& key, const std::string& text, const std::string& list) const {
  doc_->failKey(map_[key], joinKey(context_, key),
                "key '" + joinKey(context_, key) + "' has value '" + text + "', expected one of " + list);
}

YAML::Node YamlArchive::present(const std::string& key) {
  known_.push_back(key);
  if (writing()) return YAML::Node();
  YAML::Node node = map_[key];
  if (!node && required_ && std::find(optional_.begin(), optional_.end(), key) == optional_.end()) missing(key);
  return node;
}

YamlArchive& YamlArchive::operator()(const std::string& key, double& field) {
  if (writing()) {
    known_.push_back(key);
    map_[key] = exactDecimal(field);
  } else if (present(key)) {
    field = doc_->number(map_, key, context_);
  }
  return *this;
}

YamlArchive& YamlArchive::operator()(const std::string& key, int& field) {
  if (writing()) {
    known_.push_back(key);
    map_[key] = std::to_string(field);
    return *this;
  }
  const YAML::Node node = present(key);
  if (!node) return *this;
  double v = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, v) || v != std::floor(v) || std::abs(v) > 1e9) {
    doc_->failKey(node, joinKey(context_, key),
                  "key '" + joinKey(context_, key) + "' has value '" + scalarText(node) + "', expected an integer");
  }
  field = static_cast<int>(v);
  return *this;
}

YamlArchive& YamlArchive::operator()(const std::string& key, bool& field) {
  if (writing()) {
    known_.push_back(key);
    map_[key] = field ? "true" : "false";
    return *this;
  }
  const YAML::Node node = present(key);
  if (!node) return *this;
  if (!node.IsScalar() || (node.Scalar() != "true" && node.Scalar() != "false")) {
    doc_->failKey(node, joinKey(context_, key),
                  "key '" + joinKey(context_, key) + "' has value '" + scalarText(node) + "', expected true or false");
  }
  field = node.Scalar() == "true";
  return *this;
}

YamlArchive& YamlArchive::operator()(const std::string& key, std::string& field) {
  if (writing()) {
    known_.push_back(key);
    map_[key] = field;
  } else if (present(key)) {
    field = doc_->string(map_, key, context_);
  }
  return *this;
}

YamlArchive& YamlArchive::operator()(const std::string& key, Eigen::Vector3d& field) {
  if (writing()) {
    known_.push_back(key);
    map_[key] = exactSequence(field.data(), 3);
  } else if (present(key)) {
    const std::vector<double> v = doc_->numbers(map_, key, 3, context_);
    field = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  return *this;
}

YamlArchive& YamlArchive::operator()(const std::string& key, std::vector<double>& field) {
  if (writing()) {
    known_.push_back(key);
    map_[key] = exactSequence(field.data(), field.size());
    return *this;
  }
  const YAML::Node node = present(key);
  if (!node) return *this;
  if (!node.IsSequence()) {
    doc_->failKey(
        node, joinKey(context_, key),
        "key '" + joinKey(context_, key) + "' has value '" + scalarText(node) + "', expected a list of finite numbers");
  }
  field = doc_->numbers(map_, key, node.size(), context_);
  return *this;
}

YamlArchive& YamlArchive::operator()(const std::string& key, planner::Pose4& field) {
  if (writing()) {
    known_.push_back(key);
    const double v[4] = {field.p_WB.x(), field.p_WB.y(), field.p_WB.z(), field.yaw_rad};
    map_[key] = exactSequence(v, 4);
  } else if (present(key)) {
    const std::vector<double> v = doc_->numbers(map_, key, 4, context_);
    field.p_WB = Eigen::Vector3d(v[0], v[1], v[2]);
    field.yaw_rad = v[3];
  }
  return *this;
}

YamlArchive& YamlArchive::operator()(const std::string& key, std::filesystem::path& field) {
  std::string text = field.string();
  (*this)(key, text);
  field = text;
  return *this;
}

void YamlArchive::finish() const {
  if (!writing()) doc_->requireKeys(map_, known_, context_);
}

}  // namespace tgnav::harness
