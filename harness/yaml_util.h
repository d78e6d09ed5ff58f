#pragma once
// Strict YAML access for configs: every error names file:line, the dotted key and the value.
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "harness/errors.h"

namespace tgnav::harness {

// A parsed YAML document that remembers where it came from, for error messages.
class YamlDoc {
 public:
  static YamlDoc load(const std::filesystem::path& file);
  const YAML::Node& root() const { return root_; }
  const std::filesystem::path& file() const { return file_; }
  // Throws InputError "file:line: <what>" located at `node`.
  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const;

  // Every key of `map` must be in `allowed`; `context` is the dotted path of `map` ("" = root).
  void requireKeys(const YAML::Node& map, const std::vector<std::string>& allowed,
                   const std::string& context) const;
  // `map[key]` must exist (required) and convert; `context.key` names it in errors.
  double number(const YAML::Node& map, const std::string& key, const std::string& context) const;
  std::string string(const YAML::Node& map, const std::string& key,
                     const std::string& context) const;
  std::vector<double> numbers(const YAML::Node& map, const std::string& key, std::size_t count,
                              const std::string& context) const;
  const YAML::Node child(const YAML::Node& map, const std::string& key,
                         const std::string& context) const;

 private:
  std::filesystem::path file_;
  YAML::Node root_;
};

std::string joinKey(const std::string& context, const std::string& key);

// Reads the optional fields of one mapping into a config struct, then rejects any key that no
// field claimed:   FieldReader(doc, node, "position").read("pos_p_xy", c.pos_p_xy).finish();
class FieldReader {
 public:
  FieldReader(const YamlDoc& doc, YAML::Node map, std::string context);
  FieldReader& read(const std::string& key, double& out);
  FieldReader& read(const std::string& key, int& out);
  FieldReader& read(const std::string& key, bool& out);
  FieldReader& read(const std::string& key, std::string& out);
  FieldReader& read(const std::string& key, Eigen::Vector3d& out);
  // A nested mapping, when present (the callback reads it with its own FieldReader).
  template <typename Fn>
  FieldReader& section(const std::string& key, Fn&& read_section) {
    known_.push_back(key);
    if (map_[key]) read_section(FieldReader(doc_, map_[key], joinKey(context_, key)));
    return *this;
  }
  void finish() const;

 private:
  const YamlDoc& doc_;
  YAML::Node map_;
  std::string context_;
  std::vector<std::string> known_;
};

}  // namespace tgnav::harness
