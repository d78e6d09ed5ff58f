#pragma once
// The `tgnav map` job (paper Sec. IV): survey a scene by rendering, build its occlusion-aware
// feature map, and write it into a folder: map.bt, landmarks.csv, the map layer of the figures
// (map.png, map.json), summary.json and the figure topdown.<format>. The folder is replaced only
// when the new map is complete.
#include <filesystem>
#include <string>

#include "harness/io/figures.h"
#include "harness/run/map_builder.h"

namespace tgnav::harness {

struct MapJob {
  std::filesystem::path scene;  // scene YAML
  std::filesystem::path out;
  double resolution_m = 0.1;
  FigureFormat figure_format = FigureFormat::kPng;
  bool progress = false;  // frame count on stderr
};

struct MapRunResult {
  std::filesystem::path out;
  MapBuildStats stats;
  FigureOutcome figures;
};

// InputError for bad input (scene, resolution, an --out that is the working directory or one of
// its parents, or a folder that holds something other than a map).
MapRunResult runMap(const MapJob& job);

}  // namespace tgnav::harness
