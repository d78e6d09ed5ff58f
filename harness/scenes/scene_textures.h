#pragma once
// Procedural face images of generated scenes, drawn from the scene's random stream (never picked
// from a fixed set): shapes, blobs, rectangles and strokes at three scales over a background with
// fine noise. The level sets the density and the contrast:
//   rich:   many features at every scale, high contrast;
//   medium: fewer features, mid contrast;
//   faint:  low-contrast shapes (a few grey levels) and a sparse handful of slightly stronger
//           marks, so a FAST/ORB tracker thins out on it rather than dying at once;
//   plain:  no image (a flat material).
// Shapes are placed in metres on the face and mapped to the square image anisotropically, so that
// MuJoCo, which stretches a whole image over each face of a box, shows them unstretched.
#include <opencv2/core.hpp>

#include "harness/scenes/scene_layout.h"
#include "harness/scenes/scene_random.h"

namespace tgnav::harness::scenes {

// Square image side for a block whose largest face extent is `extent_m`: 256 or 384 pixels.
int faceImageSize(double extent_m);

// An 8-bit BGR image of `size_px` x `size_px` for a face `width_m` wide and `height_m` high,
// upright (row 0 at the top of the face). `level` must not be plain.
cv::Mat makeFaceImage(TextureLevel level, double width_m, double height_m, int size_px, SceneRng& rng);

}  // namespace tgnav::harness::scenes
