#include "harness/run/map_cache.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "harness/base/errors.h"
#include "harness/base/quiet_stderr.h"
#include "harness/io/staged_output.h"
#include "harness/sim/mujoco_sim.h"
#include "harness/sim/vehicle_model.h"

namespace tgnav::harness {

namespace {

// FNV-1a, 64 bit: stable across runs and machines (std::hash is not).
class Fnv1a {
 public:
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ULL;
  }
  void add(const std::string& s) { add(s.data(), s.size()); }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

// The map builder's version, part of every map's key: bump it whenever the code changes what a
// map holds for the same scene and settings (the feature detector, the landmark fusion, the
// occupancy), or a cached map built by the old code would be taken for a new one. v2: ORB
// keypoints at the coarse pyramid levels placed where they are (vo/features.cpp, 42d8b18); maps
// cached before it differ from those a fresh clone builds. v3: landmarks carry their survey
// opportunities (planner::Landmark::detectability). v4: the survey's camera noise is drawn from
// a quantile table (harness/sim/camera.h, CameraNoise), not by cv::RNG.
constexpr const char* kMapBuilderVersion = "tgnav-map-v4";

std::string settingsText(const SceneConfig& scene, const MapBuildConfig& c) {
  std::ostringstream s;
  s.precision(17);
  s << kMapBuilderVersion << "\n"
    << scene.bounds_min_m.transpose() << ' ' << scene.bounds_max_m.transpose() << '\n'
    << scene.survey.spacing_m << ' ' << scene.survey.yaw_count << ' ' << scene.survey.clearance_m;
  for (double h : scene.survey.heights_m) s << ' ' << h;
  s << '\n'
    << c.resolution_m << ' ' << c.max_range_m << ' ' << c.occupancy_stride_px << ' ' << c.merge_radius_m << ' '
    << c.max_hamming << ' ' << c.min_observations << ' ' << c.max_shift_m << ' ' << c.depth_edge_m << '\n'
    << c.camera.name << ' ' << c.camera.width_px << ' ' << c.camera.height_px << ' ' << c.camera.near_clip_m << ' '
    << c.camera.far_clip_m << ' ' << c.camera.min_depth_m << ' ' << c.camera.max_depth_m << ' '
    << c.camera.rgb_noise_sigma << ' ' << c.camera.depth_noise_sigma_per_m2 << ' ' << c.camera.offscreen_samples << '\n'
    << c.features.max_features << ' ' << c.features.grid_cols << ' ' << c.features.grid_rows << ' '
    << c.features.fast_threshold << ' ' << c.features.scale_factor << ' ' << c.features.pyramid_levels << ' '
    << c.features.edge_threshold_px << '\n';
  return s.str();
}

}  // namespace

std::filesystem::path defaultCacheDir() {
  if (const char* d = std::getenv("TGNAV_CACHE_DIR"); d != nullptr && *d != '\0') return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d != nullptr && *d != '\0') {
    return std::filesystem::path(d) / "tgnav";
  }
  if (const char* d = std::getenv("HOME"); d != nullptr && *d != '\0') {
    return std::filesystem::path(d) / ".cache" / "tgnav";
  }
  throw InputError("no cache directory: set TGNAV_CACHE_DIR or HOME, or pass --map-cache");
}

std::string mapKey(const SceneConfig& scene, const MapBuildConfig& config) {
  // The scene's own vehicle carries the survey camera (harness/run/map_builder.cpp); a scenario's
  // choice of vehicle does not enter the key.
  const VehicleModel vehicle = loadVehicleModel(scene.mjcf, scene.vehicle);
  MapBuildConfig resolved = config;
  resolved.camera = config.camera.on(vehicle.vehicle.camera);
  Fnv1a h;
  h.add(settingsText(scene, resolved));
  // The compiled model holds the geometry, materials and decoded textures: what the camera sees.
  const ModelPtr& model = vehicle.model;
  std::vector<unsigned char> bytes(static_cast<std::size_t>(mj_sizeModel(model.get())));
  mj_saveModel(model.get(), nullptr, bytes.data(), static_cast<int>(bytes.size()));
  h.add(bytes.data(), bytes.size());
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h.value()));
  return hex;
}

void saveFeatureMap(const planner::FeatureMap& map, const std::filesystem::path& dir) {
  const QuietStderr quiet;  // OctoMap's writer logs to stderr
  try {
    map.save(dir);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
}

CachedMap cachedFeatureMap(const SceneConfig& scene, const MapBuildConfig& config,
                           const std::filesystem::path& cache_root,
                           const std::function<void(int done, int total)>& progress) {
  const std::string stem = scene.source.stem().string();
  CachedMap out;
  out.dir = cache_root / "maps" / (stem + "-" + mapKey(scene, config));
  if (std::filesystem::is_regular_file(out.dir / "summary.json")) return out;

  std::error_code ec;
  std::filesystem::create_directories(out.dir.parent_path(), ec);
  if (ec) throw InputError("map cache " + out.dir.parent_path().string() + ": cannot create (" + ec.message() + ")");
  MapBuildStats stats;
  const planner::FeatureMap map = buildFeatureMap(scene, config, &stats, progress);
  StagedDir staged(out.dir, "map cache");
  saveFeatureMap(map, staged.staging());
  nlohmann::ordered_json j;
  j["scene"] = scene.source.string();
  j["landmarks"] = stats.landmarks;
  j["frames"] = stats.frames;
  j["build_s"] = stats.total_s;
  writeFileAtomic(staged.staging() / "summary.json", j.dump(2) + "\n");
  // Another process may have finished the same map first: keep its map.
  if (!staged.commit(OnExisting::kKeep)) return out;
  out.built = true;
  return out;
}

planner::FeatureMap loadSceneFeatureMap(const SceneConfig& scene, const std::string& map_dir,
                                        const std::string& cache_root, const std::string& command,
                                        std::filesystem::path* folder) {
  std::filesystem::path dir = map_dir;
  if (dir.empty()) {
    const std::filesystem::path cache = cache_root.empty() ? defaultCacheDir() : std::filesystem::path(cache_root);
    const bool tty = isatty(fileno(stderr)) != 0;
    const CachedMap cached = cachedFeatureMap(scene, MapBuildConfig{}, cache, [&](int done, int total) {
      if (tty && (done % 20 == 0 || done == total)) {
        std::fprintf(stderr, "\r%s: mapping %d/%d frames", command.c_str(), done, total);
      }
    });
    if (tty && cached.built) std::fprintf(stderr, "\n");
    dir = cached.dir;
  }
  if (folder != nullptr) *folder = std::filesystem::absolute(dir).lexically_normal();
  try {
    const QuietStderr quiet;
    return planner::FeatureMap::load(dir);
  } catch (const std::runtime_error& e) {
    throw InputError(std::string("--map: ") + e.what());
  }
}

}  // namespace tgnav::harness
