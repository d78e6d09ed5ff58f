#include "harness/yaml_util.h"

#include <cmath>
#include <fstream>
#include <sstream>

namespace tgnav::harness {

std::string joinKey(const std::string& context, const std::string& key) {
  return context.empty() ? key : context + "." + key;
}

YamlDoc YamlDoc::load(const std::filesystem::path& file) {
  YamlDoc doc;
  doc.file_ = file;
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot open file");
  try {
    doc.root_ = YAML::Load(in);
  } catch (const YAML::Exception& e) {
    throw InputError(file.string() + ":" + std::to_string(e.mark.line + 1) +
                     ": YAML syntax error: " + e.msg);
  }
  if (!doc.root_.IsMap()) throw InputError(file.string() + ": expected a mapping of keys at top level");
  return doc;
}

void YamlDoc::fail(const YAML::Node& node, const std::string& what) const {
  const YAML::Mark mark = node.Mark();
  std::string where = file_.string();
  if (mark.line >= 0) where += ":" + std::to_string(mark.line + 1);
  throw InputError(where + ": " + what);
}

void YamlDoc::requireKeys(const YAML::Node& map, const std::vector<std::string>& allowed,
                          const std::string& context) const {
  if (!map.IsMap()) fail(map, "'" + (context.empty() ? "<root>" : context) + "' must be a mapping");
  for (const auto& kv : map) {
    const std::string key = kv.first.as<std::string>();
    bool known = false;
    for (const auto& a : allowed) known = known || a == key;
    if (!known) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(kv.first, "unknown key '" + joinKey(context, key) + "' (allowed: " + list + ")");
    }
  }
}

const YAML::Node YamlDoc::child(const YAML::Node& map, const std::string& key,
                                const std::string& context) const {
  const YAML::Node node = map[key];
  if (!node) fail(map, "missing required key '" + joinKey(context, key) + "'");
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

double YamlDoc::number(const YAML::Node& map, const std::string& key,
                       const std::string& context) const {
  const YAML::Node node = child(map, key, context);
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
    fail(node, "key '" + joinKey(context, key) + "' has value '" + scalarText(node) +
                   "', expected a finite number");
  }
  return value;
}

std::string YamlDoc::string(const YAML::Node& map, const std::string& key,
                            const std::string& context) const {
  const YAML::Node node = child(map, key, context);
  if (!node.IsScalar() || node.Scalar().empty()) {
    fail(node, "key '" + joinKey(context, key) + "' has value '" + scalarText(node) +
                   "', expected a non-empty string");
  }
  return node.Scalar();
}

std::vector<double> YamlDoc::numbers(const YAML::Node& map, const std::string& key,
                                     std::size_t count, const std::string& context) const {
  const YAML::Node node = child(map, key, context);
  std::vector<double> out;
  bool ok = node.IsSequence() && node.size() == count;
  for (std::size_t i = 0; ok && i < node.size(); ++i) {
    double v = 0.0;
    ok = node[i].IsScalar() && YAML::convert<double>::decode(node[i], v) && std::isfinite(v);
    out.push_back(v);
  }
  if (!ok) {
    fail(node, "key '" + joinKey(context, key) + "' has value '" + scalarText(node) +
                   "', expected a list of " + std::to_string(count) + " finite numbers");
  }
  return out;
}

FieldReader::FieldReader(const YamlDoc& doc, YAML::Node map, std::string context)
    : doc_(doc), map_(std::move(map)), context_(std::move(context)) {
  if (!map_.IsMap()) {
    doc_.fail(map_, "'" + (context_.empty() ? std::string("<root>") : context_) + "' must be a mapping");
  }
}

FieldReader& FieldReader::read(const std::string& key, double& out) {
  known_.push_back(key);
  if (map_[key]) out = doc_.number(map_, key, context_);
  return *this;
}

FieldReader& FieldReader::read(const std::string& key, int& out) {
  known_.push_back(key);
  if (!map_[key]) return *this;
  const double v = doc_.number(map_, key, context_);
  if (v != std::floor(v) || std::abs(v) > 1e9) {
    doc_.fail(map_[key], "key '" + joinKey(context_, key) + "' has value '" + map_[key].Scalar() +
                             "', expected an integer");
  }
  out = static_cast<int>(v);
  return *this;
}

FieldReader& FieldReader::read(const std::string& key, bool& out) {
  known_.push_back(key);
  if (!map_[key]) return *this;
  const YAML::Node node = map_[key];
  if (!node.IsScalar() || (node.Scalar() != "true" && node.Scalar() != "false")) {
    doc_.fail(node, "key '" + joinKey(context_, key) + "' has value '" + (node.IsScalar() ? node.Scalar() : "<not a scalar>") +
                        "', expected true or false");
  }
  out = node.Scalar() == "true";
  return *this;
}

FieldReader& FieldReader::read(const std::string& key, std::string& out) {
  known_.push_back(key);
  if (map_[key]) out = doc_.string(map_, key, context_);
  return *this;
}

FieldReader& FieldReader::read(const std::string& key, Eigen::Vector3d& out) {
  known_.push_back(key);
  if (!map_[key]) return *this;
  const std::vector<double> v = doc_.numbers(map_, key, 3, context_);
  out = Eigen::Vector3d(v[0], v[1], v[2]);
  return *this;
}

void FieldReader::finish() const { doc_.requireKeys(map_, known_, context_); }

}  // namespace tgnav::harness
