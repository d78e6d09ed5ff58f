#pragma once
// Strict YAML access for configs: every error names file:line (or the --set assignment), the
// dotted key and the value. The config structs list their keys once, in a visit() that
// YamlArchive reads and writes (below).
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "harness/base/errors.h"
#include "planner/pose4.h"

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
  void requireKeys(const YAML::Node& map, const std::vector<std::string>& allowed, const std::string& context) const;
  // `map[key]` must exist (required) and convert; `context.key` names it in errors.
  double number(const YAML::Node& map, const std::string& key, const std::string& context) const;
  std::string string(const YAML::Node& map, const std::string& key, const std::string& context) const;
  std::vector<double> numbers(const YAML::Node& map, const std::string& key, std::size_t count,
                              const std::string& context) const;
  YAML::Node child(const YAML::Node& map, const std::string& key, const std::string& context) const;

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

// --- Config structs and their archives -------------------------------------------------------
//
// Every config struct names its keys once, in a member template
//
//   template <typename Archive> void visit(Archive& a) {
//     a("pos_p_xy", pos_p_xy);                  // a field: double, int, bool, std::string,
//                                               //   Eigen::Vector3d (and, for the harness's own
//                                               //   structs, std::vector<double>, planner::Pose4,
//                                               //   std::filesystem::path)
//     a("position", position);                  // a nested struct with its own visit: a mapping
//     a.group("rates_hz", [&](auto& g) {        // a mapping that is not a struct of its own
//       g("position", position_rate_hz);
//     });
//     a.choice("state_source", state_source,    // an enum, by name
//              {{"gt", StateSource::kGroundTruth}, {"vo", StateSource::kVo}});
//   }
//
// and every archive (YamlArchive reading or writing YAML, KeyLister listing the keys, the tests'
// own) runs that one list: the key order of a visit is the order written, and a key's name is
// its name everywhere. The structs themselves stay free of YAML.

namespace detail {
template <typename T, typename Archive, typename = void>
struct HasVisit : std::false_type {};
template <typename T, typename Archive>
struct HasVisit<T, Archive, std::void_t<decltype(std::declval<T&>().visit(std::declval<Archive&>()))>>
    : std::true_type {};
}  // namespace detail

// True when T is a config struct: it has a `template <typename Archive> void visit(Archive&)`
// usable with Archive (Eigen's matrices, whose visit() takes a coefficient visitor, are not).
template <typename T, typename Archive>
constexpr bool kHasVisit = detail::HasVisit<T, Archive>::value && !std::is_base_of_v<Eigen::EigenBase<T>, T>;

// An archive that lists the keys a visit names, in its order. Flat (the default): the keys of
// the visited mapping only. Nested: every key of every level, dotted ("position.pos_p_xy"), each
// mapping's key before its own keys.
class KeyLister {
 public:
  explicit KeyLister(bool nested = false, std::string context = "") : nested_(nested), context_(std::move(context)) {}

  template <typename T>
  KeyLister& operator()(const std::string& key, T& field) {
    add(key);
    if constexpr (kHasVisit<T, KeyLister>) {
      if (nested_) {
        KeyLister inner(true, joinKey(context_, key));
        field.visit(inner);
        append(inner);
      }
    }
    return *this;
  }
  template <typename Fn>
  KeyLister& group(const std::string& key, Fn&& visit_group) {
    add(key);
    if (nested_) {
      KeyLister inner(true, joinKey(context_, key));
      visit_group(inner);
      append(inner);
    }
    return *this;
  }
  template <typename E>
  KeyLister& choice(const std::string& key, E&, const std::vector<std::pair<std::string, E>>&) {
    return add(key);
  }

  const std::vector<std::string>& keys() const { return keys_; }

 private:
  KeyLister& add(const std::string& key) {
    keys_.push_back(nested_ ? joinKey(context_, key) : key);
    return *this;
  }
  void append(const KeyLister& inner) { keys_.insert(keys_.end(), inner.keys_.begin(), inner.keys_.end()); }

  bool nested_;
  std::string context_;
  std::vector<std::string> keys_;
};

// An archive adaptor for laying out a struct whose fields are not all settings of their own: every
// call goes on to `archive` except those for the dotted keys in `skip` (relative to the mapping
// visited, e.g. "rrt_star.visibility"), whose fields then have no key in this layout.
//
//   SkipKeys<Archive> s(a, {"trajectory.robot_radius_m"});   // it follows another field
//   s("trajectory", trajectory);
template <typename Archive>
class SkipKeys {
 public:
  SkipKeys(Archive& archive, const std::vector<std::string>& skip, std::string context = "")
      : archive_(archive), skip_(skip), context_(std::move(context)) {}

  template <typename T>
  SkipKeys& operator()(const std::string& key, T& field) {
    const std::string full = joinKey(context_, key);
    if (skipped(full)) return *this;
    if constexpr (kHasVisit<T, KeyLister>) {
      if (skipsWithin(full)) {
        archive_.group(key, [&](auto& g) {
          SkipKeys<std::decay_t<decltype(g)>> inner(g, skip_, full);
          field.visit(inner);
        });
        return *this;
      }
    }
    archive_(key, field);
    return *this;
  }
  template <typename Fn>
  SkipKeys& group(const std::string& key, Fn&& visit_group) {
    const std::string full = joinKey(context_, key);
    if (skipped(full)) return *this;
    archive_.group(key, [&](auto& g) {
      SkipKeys<std::decay_t<decltype(g)>> inner(g, skip_, full);
      visit_group(inner);
    });
    return *this;
  }
  template <typename E>
  SkipKeys& choice(const std::string& key, E& value, const std::vector<std::pair<std::string, E>>& names) {
    if (!skipped(joinKey(context_, key))) archive_.choice(key, value, names);
    return *this;
  }

 private:
  bool skipped(const std::string& full) const {
    for (const std::string& s : skip_) {
      if (s == full) return true;
    }
    return false;
  }
  bool skipsWithin(const std::string& full) const {
    for (const std::string& s : skip_) {
      if (s.size() > full.size() && s.compare(0, full.size(), full) == 0 && s[full.size()] == '.') return true;
    }
    return false;
  }

  Archive& archive_;
  const std::vector<std::string>& skip_;
  std::string context_;
};

// The YAML archive: reads the keys of one mapping into fields, or writes fields into one.
//
// Reading (YamlArchive(doc, node, context)): a key that is present replaces the field (keys are
// optional: the field keeps its value, the built-in default or an earlier layer's, unless
// required() was called); a key no field names is an error, and so is a value of the wrong type:
// InputError naming file:line (or the --set assignment), the dotted key and the value.
//
// Writing (YamlArchive::writer(out)): every field is stored under its key in `out`, in visit
// order: doubles as exactDecimal() (they read back exactly), ints as integers, bools as
// true/false, strings as they are, vectors and poses as flow sequences, nested structs and
// groups as mappings.
//
//   readConfig(YamlArchive(doc, doc.root(), ""), &config);   // a whole config struct
//   YAML::Node yaml = toYaml(config);
class YamlArchive {
 public:
  // Reading `map` (which must be a mapping) of `doc`; `context` is its dotted key ("" = root).
  YamlArchive(const YamlDoc& doc, const YAML::Node& map, std::string context);
  // Writing into `out` (made a mapping).
  static YamlArchive writer(const YAML::Node& out, std::string context = "");
  bool writing() const { return doc_ == nullptr; }
  bool reading() const { return doc_ != nullptr; }
  // Reading: every key a visit names must be present ("missing required key 'a.b'"), in nested
  // mappings too. No effect on a writer.
  YamlArchive& required() {
    required_ = true;
    return *this;
  }
  // Reading with required(): these keys of this archive's own mapping stay optional.
  YamlArchive& except(std::vector<std::string> optional_keys) {
    optional_ = std::move(optional_keys);
    return *this;
  }

  // One field.
  YamlArchive& operator()(const std::string& key, double& field);
  YamlArchive& operator()(const std::string& key, int& field);
  YamlArchive& operator()(const std::string& key, bool& field);
  YamlArchive& operator()(const std::string& key, std::string& field);            // non-empty
  YamlArchive& operator()(const std::string& key, Eigen::Vector3d& field);        // [x, y, z]
  YamlArchive& operator()(const std::string& key, std::vector<double>& field);    // [a, b, ...]
  YamlArchive& operator()(const std::string& key, planner::Pose4& field);         // [x, y, z, yaw]
  YamlArchive& operator()(const std::string& key, std::filesystem::path& field);  // as a string
  // A nested config struct (one with a visit): the mapping under `key`, when present.
  template <typename Config, typename = std::enable_if_t<kHasVisit<Config, YamlArchive>>>
  YamlArchive& operator()(const std::string& key, Config& config) {
    return group(key, [&config](auto& a) { config.visit(a); });
  }
  // A mapping under `key` whose keys `visit_group` names on the archive it is given (a generic
  // lambda: it also runs on the other archives).
  template <typename Fn>
  YamlArchive& group(const std::string& key, Fn&& visit_group) {
    known_.push_back(key);
    if (writing()) {
      map_[key] = YAML::Node(YAML::NodeType::Map);
      YamlArchive inner = writer(map_[key], joinKey(context_, key));
      visit_group(inner);
    } else if (map_[key]) {
      YamlArchive inner(*doc_, map_[key], joinKey(context_, key));
      inner.required_ = required_;
      inner.visitMapping(visit_group);
    } else if (required_) {
      missing(key);
    }
    return *this;
  }
  // An enum stored as one of its names: {{"gt", StateSource::kGroundTruth}, ...}. Reading
  // another text is "key 'K' has value 'V', expected one of gt, vo"; writing a value that has
  // no name is std::logic_error.
  template <typename E>
  YamlArchive& choice(const std::string& key, E& value, const std::vector<std::pair<std::string, E>>& names) {
    if (writing()) {
      for (const auto& [name, v] : names) {
        if (v == value) {
          std::string text = name;
          return (*this)(key, text);
        }
      }
      throw std::logic_error("key '" + joinKey(context_, key) + "': value without a name");
    }
    std::string text;
    (*this)(key, text);
    if (!map_[key]) return *this;
    for (const auto& [name, v] : names) {
      if (name == text) {
        value = v;
        return *this;
      }
    }
    std::string list;
    for (const auto& nv : names) list += (list.empty() ? "" : ", ") + nv.first;
    badChoice(key, text, list);
  }

  // All of `config`'s keys in this archive's own mapping (the root of a file, or a section read
  // by the caller): reading checks for unknown keys first, then reads.
  template <typename Config>
  YamlArchive& fields(Config& config) {
    visitMapping([&config](auto& a) { config.visit(a); });
    return *this;
  }

  // The older, chained spelling of operator() for code that reads a mapping field by field
  // (YamlArchive(doc, node, "").read("fx", k.fx).read("fy", k.fy).finish()).
  template <typename T>
  YamlArchive& read(const std::string& key, T& field) {
    return (*this)(key, field);
  }
  // Rejects keys of the mapping that no call named (fields() and group() do this themselves);
  // nothing to do for a writer.
  void finish() const;

 private:
  YamlArchive(const YAML::Node& out, std::string context);  // a writer

  // Reading: rejects the keys `visit_keys` does not name, then reads them; writing: writes them.
  template <typename Fn>
  void visitMapping(Fn&& visit_keys) {
    if (reading()) {
      KeyLister keys;
      visit_keys(keys);
      doc_->requireKeys(map_, keys.keys(), context_);
    }
    visit_keys(*this);
  }
  [[noreturn]] void missing(const std::string& key) const;
  [[noreturn]] void badChoice(const std::string& key, const std::string& text, const std::string& list) const;
  // The node of `key` when reading and present; null otherwise (missing() when required).
  YAML::Node present(const std::string& key);

  const YamlDoc* doc_;  // null for a writer
  YAML::Node map_;
  std::string context_;
  bool required_ = false;
  std::vector<std::string> optional_;  // exempt from required_
  std::vector<std::string> known_;
};

// The archive's earlier name (it read, and wrote with FieldReader::writer).
using FieldReader = YamlArchive;

// Reads the keys present in `r`'s mapping over `config` (unknown keys are errors). No validate().
template <typename Config>
void readConfig(YamlArchive r, Config* config) {
  r.fields(*config);
}

// Runs config.validate(), re-raising std::invalid_argument as InputError "<source>: <what>".
template <typename Config>
void validateConfig(const Config& config, const std::string& source) {
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(source + ": " + e.what());
  }
}

// A whole file (a mapping of `config`'s keys, all optional) read over `base`, then validated
// (InputError naming the file).
template <typename Config>
Config loadConfigFile(const std::filesystem::path& yaml, Config base = {}) {
  const YamlDoc doc = YamlDoc::load(yaml);
  readConfig(YamlArchive(doc, doc.root(), ""), &base);
  validateConfig(base, yaml.string());
  return base;
}

// Every key of `config` with its value, in visit order.
template <typename Config, typename = std::enable_if_t<kHasVisit<Config, YamlArchive>>>
YAML::Node toYaml(const Config& config) {
  Config copy = config;  // visit() is not const (the same function reads)
  YAML::Node out(YAML::NodeType::Map);
  YamlArchive::writer(out).fields(copy);
  return out;
}

}  // namespace tgnav::harness
