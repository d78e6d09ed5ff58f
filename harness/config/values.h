#pragma once
// Values given as text: numbers on the command line ("x,y,z,yaw"), and YAML config documents
// turned into JSON for the JSON summaries that embed them.
#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace tgnav::harness {

// Parses "a,b,c" into exactly `count` finite numbers; InputError "<option>: '<text>' is not
// <form>" otherwise.
std::vector<double> parseNumbers(const std::string& text, std::size_t count, const std::string& option,
                                 const std::string& form);

// A YAML document as JSON: mappings keep their order; scalars become integers, numbers, booleans
// or strings, whichever reads back exactly.
nlohmann::ordered_json toJson(const YAML::Node& node);

}  // namespace tgnav::harness
