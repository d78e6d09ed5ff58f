// The face images of a generated scene's blocks (harness/scenes/scene_files.h).
#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "harness/scenes/scene_files.h"
#include "harness/scenes/scene_textures.h"

namespace tgnav::harness::scenes {

namespace {

// Faces narrower than this (the ends of thin walls) reuse another face's image.
constexpr double kThinFaceM = 0.35;
// A cylinder's quarter of circumference spans one cube face.
constexpr double kCylinderFaceFactor = 1.6;

// MuJoCo shows a cube face image upright on -y as it is, on +y turned 180 degrees, on -x turned
// 90 degrees clockwise and on +x 90 degrees counter-clockwise (scripts/make_textures.py).
enum class Face { kMinusY, kPlusY, kMinusX, kPlusX };

struct FaceWriter {
  std::map<std::string, std::string>& files;
  SceneRng& rng;

  std::string operator()(const Block& b, Face face, double width_m, int size_px) {
    cv::Mat image = makeFaceImage(b.level, width_m, b.height_m, size_px, rng);
    static const char* const kSuffix[] = {"ym", "yp", "xm", "xp"};
    if (face == Face::kPlusY) cv::rotate(image, image, cv::ROTATE_180);
    if (face == Face::kMinusX) cv::rotate(image, image, cv::ROTATE_90_CLOCKWISE);
    if (face == Face::kPlusX) cv::rotate(image, image, cv::ROTATE_90_COUNTERCLOCKWISE);
    std::vector<uchar> png;
    if (!cv::imencode(".png", image, png, {cv::IMWRITE_PNG_COMPRESSION, 6})) {
      throw std::runtime_error("cannot encode a PNG texture");
    }
    std::string name = b.name + "_" + kSuffix[static_cast<int>(face)] + ".png";
    files["textures/" + name] = std::string(png.begin(), png.end());
    return name;
  }
};

// An outer wall panel shows one face, towards the room; its other faces reuse that image.
FaceFiles wallFaces(const Block& b, FaceWriter& write, int size_px) {
  const char side = b.name.size() > 5 ? b.name[5] : 's';
  const bool along_x = side == 's' || side == 'n';
  const Face inward = side == 's'   ? Face::kPlusY
                      : side == 'n' ? Face::kMinusY
                      : side == 'w' ? Face::kPlusX
                                    : Face::kMinusX;
  const std::string name = write(b, inward, along_x ? 2.0 * b.hx : 2.0 * b.hy, size_px);
  return {name, name, name, name};
}

FaceFiles blockFaces(const Block& b, FaceWriter& write) {
  const double y_width = b.cylinder ? kCylinderFaceFactor * b.hx : 2.0 * b.hx;  // the +-y faces
  const double x_width = b.cylinder ? kCylinderFaceFactor * b.hy : 2.0 * b.hy;  // the +-x faces
  const int size_px = faceImageSize(std::max({y_width, x_width, b.height_m}));
  if (b.obstacle < 0) return wallFaces(b, write, size_px);
  FaceFiles f;
  if (y_width >= kThinFaceM || x_width < kThinFaceM) {
    f.down = write(b, Face::kMinusY, y_width, size_px);
    f.up = write(b, Face::kPlusY, y_width, size_px);
  }
  if (x_width >= kThinFaceM) {
    f.left = write(b, Face::kMinusX, x_width, size_px);
    f.right = write(b, Face::kPlusX, x_width, size_px);
  }
  if (f.down.empty()) f.down = f.up = f.left;
  if (f.left.empty()) f.left = f.right = f.down;
  return f;
}

}  // namespace

std::vector<FaceFiles> addFaceImages(const Layout& layout, SceneRng& rng, std::map<std::string, std::string>& files) {
  FaceWriter write{files, rng};
  std::vector<FaceFiles> faces;
  for (const Block& b : layout.blocks) {
    faces.push_back(b.level == TextureLevel::kPlain ? FaceFiles{} : blockFaces(b, write));
  }
  return faces;
}

}  // namespace tgnav::harness::scenes
