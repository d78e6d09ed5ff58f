#pragma once
// Strict YAML access for configs: every error names file:line (or the --set assignment), the
// dotted key and the value.
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "harness/errors.h"

namespace tgnav::harness {

// A parsed YAML document that remembers where it came from, for error messages: a file, or the
// command line's `--set dotted.key=value` assignments.
class YamlDoc {
 public:
  static YamlDoc load(const std::filesystem::path& file);
  // Each assignment "a.b.c=VALUE" becomes root[a][b][c] = VALUE parsed as YAML (so lists and
  // mappings work: "start=[1, 2, 1, 0]"). InputError naming the assignment when one has no '=',
  // an empty key or key segment, an empty value or bad YAML, repeats a key, or makes a key both
  // a value and a mapping of other keys. Errors about the document's nodes name the assignment
  // instead of a file and line.
  static YamlDoc fromOverrides(const std::vector<std::string>& assignments);

  const YAML::Node& root() const { return root_; }
  const std::filesystem::path& file() const { return file_; }  // empty for overrides
  bool isOverrides() const { return overrides_; }
  // The file, or "--set overrides" for an override document.
  std::string name() const;
  // The assignment text ("camera.width_px=320") whose key is `key`, lies inside it, or contains
  // it (dotted); "" when none does or this is a file.
  std::string assignmentFor(const std::string& key) const;
  // The dotted keys of all assignments, in command-line order.
  std::vector<std::string> assignedKeys() const;

  // Throws InputError "file:line: <what>" located at `node` ("--set ASSIGNMENT: <what>" for
  // overrides, the assignment found by node identity).
  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const;
  // The same for the value of the dotted key `key` (for overrides, the assignment of that key).
  [[noreturn]] void failKey(const YAML::Node& node, const std::string& key, const std::string& what) const;

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
  struct Assignment {
    std::string key;   // dotted
    std::string text;  // as given on the command line
    YAML::Node value;
  };

  std::filesystem::path file_;
  YAML::Node root_;
  bool overrides_ = false;
  std::vector<Assignment> assignments_;
};

std::string joinKey(const std::string& context, const std::string& key);

// The shortest decimal text that reads back as exactly `value` ("0.1", "1e-06", "20").
std::string exactDecimal(double value);
// A flow-style YAML sequence of exactDecimal() scalars.
YAML::Node exactSequence(const double* values, std::size_t count);

// Reads the optional fields of one mapping into a config struct, then rejects any key that no
// field claimed:   FieldReader(doc, node, "position").read("pos_p_xy", c.pos_p_xy).finish();
//
// A writer (FieldReader::writer) runs the same calls the other way: each read() stores the
// field's current value under its key in the output mapping, so one function per config both
// reads and writes it and the two can never disagree on the keys.
class FieldReader {
 public:
  FieldReader(const YamlDoc& doc, YAML::Node map, std::string context);
  // Writes into `out` (made a mapping): doubles as exactDecimal(), ints as integers, bools as
  // true/false, strings as they are, vectors as flow sequences; section() adds a child mapping.
  static FieldReader writer(YAML::Node out, std::string context = "");
  bool writing() const { return doc_ == nullptr; }

  FieldReader& read(const std::string& key, double& out);
  FieldReader& read(const std::string& key, int& out);
  FieldReader& read(const std::string& key, bool& out);
  FieldReader& read(const std::string& key, std::string& out);
  // A string that must be one of `allowed`.
  FieldReader& read(const std::string& key, std::string& out, const std::vector<std::string>& allowed);
  FieldReader& read(const std::string& key, Eigen::Vector3d& out);
  // A nested mapping, when present (the callback reads it with its own FieldReader).
  template <typename Fn>
  FieldReader& section(const std::string& key, Fn&& read_section) {
    known_.push_back(key);
    if (writing()) {
      map_[key] = YAML::Node(YAML::NodeType::Map);
      read_section(writer(map_[key], joinKey(context_, key)));
    } else if (map_[key]) {
      read_section(FieldReader(*doc_, map_[key], joinKey(context_, key)));
    }
    return *this;
  }
  // Rejects keys no read() or section() claimed; nothing to do for a writer.
  void finish() const;

 private:
  FieldReader(YAML::Node out, std::string context);  // a writer

  const YamlDoc* doc_;  // null for a writer
  YAML::Node map_;
  std::string context_;
  std::vector<std::string> known_;
};

}  // namespace tgnav::harness
