#pragma once
// Pinhole intrinsics of an undistorted camera (pixels; the centre of the top-left pixel at (0, 0)).

namespace tgnav::vo {

struct CameraIntrinsics {
  int width_px = 0;
  int height_px = 0;
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;
};

}  // namespace tgnav::vo
