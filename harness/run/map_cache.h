#pragma once
// Feature maps of scenes, built once and reused: `tgnav plan`/`trial` look the scene's map up by
// a content hash of everything the mapping run depends on (the compiled MJCF model with its
// textures, the survey plan, bounds and the map and camera settings). A missing map is built
// into a temporary folder and renamed into place, so concurrent processes (a sweep, a Slurm
// array) never see half a map; the loser of a race uses the winner's.
#include <filesystem>
#include <functional>
#include <string>

#include "harness/config/scene_config.h"
#include "harness/run/map_builder.h"
#include "planner/feature_map.h"

namespace tgnav::harness {

// $TGNAV_CACHE_DIR, else $XDG_CACHE_HOME/tgnav, else $HOME/.cache/tgnav.
std::filesystem::path defaultCacheDir();

// 16 hex digits naming the map of `scene` built with `config`.
std::string mapKey(const SceneConfig& scene, const MapBuildConfig& config);

struct CachedMap {
  std::filesystem::path dir;  // holds map.bt, landmarks.csv, summary.json
  bool built = false;         // false: found in the cache
};

// Writes map.bt and landmarks.csv into `dir` (a staging folder): InputError naming the file and
// the system's reason when it cannot (a full disk).
void saveFeatureMap(const planner::FeatureMap& map, const std::filesystem::path& dir);

// The map's folder under cache_root/maps/<scene>-<key>, building it when absent.
CachedMap cachedFeatureMap(const SceneConfig& scene, const MapBuildConfig& config,
                           const std::filesystem::path& cache_root,
                           const std::function<void(int done, int total)>& progress = {});

// The scene's feature map for a command: the folder `map_dir` when given (`--map`), else the
// cached one under `cache_root` (`--map-cache`, default defaultCacheDir()), built on first use
// with progress on stderr when that is a terminal ("<command>: mapping i/n frames").
// InputError naming --map when the folder holds no readable map. `folder`, when given, is set to
// the map's folder (absolute).
planner::FeatureMap loadSceneFeatureMap(const SceneConfig& scene, const std::string& map_dir,
                                        const std::string& cache_root, const std::string& command,
                                        std::filesystem::path* folder = nullptr);

}  // namespace tgnav::harness
