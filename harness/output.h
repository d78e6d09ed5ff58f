#pragma once
// Result files are written whole or not at all: into a temporary sibling, then renamed.
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

namespace tgnav::harness {

// Creates `dir` (and parents); InputError naming it when that is impossible.
void makeOutputDir(const std::filesystem::path& dir);
void writeFileAtomic(const std::filesystem::path& file, const std::string& content);
// Encodes by extension (.png: 8-bit or 16-bit).
void writeImageAtomic(const std::filesystem::path& file, const cv::Mat& image);

}  // namespace tgnav::harness
