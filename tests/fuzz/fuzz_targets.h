#pragma once
// Fuzz targets: every parser of a file a user hands to tgnav, driven with arbitrary bytes.
//
// Each target writes its input where the parser expects a file (in a scratch folder of its own)
// and calls the parser. The contract under test is the project's error policy
// (harness/base/errors.h): bad input ends in the parser's documented error — InputError for the
// harness's loaders, std::invalid_argument for the pure libraries' text parsers — and in nothing
// else: no crash, no sanitizer report, no other exception escaping (which the CLI would print as
// an "internal error" without naming the file).
//
// Targets whose parser reads several files take one input cut into sections by lines holding only
// kSectionMark; a missing section is a missing file.
//
// The same functions run in three places: the libFuzzer executables (tests/fuzz/fuzz_main.cpp,
// built with -DTGNAV_FUZZ=ON), the replay test of the normal build (tests/fuzz/fuzz_replay_test.cpp:
// the committed corpora, the crash regressions and the repository's own files), and
// scripts/fuzz.sh, which seeds the corpora from repositorySeeds().
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace tgnav::fuzz {

inline constexpr const char* kSectionMark = "--8<--";

enum class Outcome {
  kAccepted,  // the parser took the input
  kRejected,  // the parser refused it with its documented error
};

struct Target {
  std::string name;
  std::string files;  // what the sections are, for the docs and --help
};

// Every target, in a fixed order.
const std::vector<Target>& targets();

// Runs target `name` on the input; throws std::out_of_range for an unknown name. Any exception
// other than the parser's documented error propagates: it is a finding. `why` (optional) receives
// the documented error's message when the input is rejected.
Outcome run(const std::string& name, const std::uint8_t* data, std::size_t size, std::string* why = nullptr);
inline Outcome run(const std::string& name, const std::string& input, std::string* why = nullptr) {
  return run(name, reinterpret_cast<const std::uint8_t*>(input.data()), input.size(), why);
}

// The input cut at lines that hold only kSectionMark (at most `count` sections; later marks stay
// in the last section). Missing sections are absent from the result.
std::vector<std::string> sections(const std::string& input, std::size_t count);

// Inputs of target `name` made from the repository's own files under `source_dir` (configs,
// scenes, sweeps), with the paths they name rewritten to the target's scratch layout.
std::vector<std::string> repositorySeeds(const std::string& name, const std::filesystem::path& source_dir);

}  // namespace tgnav::fuzz
