#include "harness/output.h"

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <system_error>
#include <vector>

#include "harness/errors.h"

namespace tgnav::harness {

void makeOutputDir(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw InputError(dir.string() + ": cannot create output directory" +
                     (ec ? ": " + ec.message() : std::string()));
  }
}

void writeFileAtomic(const std::filesystem::path& file, const std::string& content) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(tmp, ignored);
      throw InputError(file.string() + ": cannot write file");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw InputError(file.string() + ": cannot write file: " + ec.message());
  }
}

void writeImageAtomic(const std::filesystem::path& file, const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(file.extension().string(), image, bytes)) {
    throw std::runtime_error(file.string() + ": image encoding failed");
  }
  writeFileAtomic(file, std::string(bytes.begin(), bytes.end()));
}

}  // namespace tgnav::harness
