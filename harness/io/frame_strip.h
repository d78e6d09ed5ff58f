#pragma once
// A montage of onboard camera frames with captions (a trial's frames.png). It is an image of the
// data, not a plot: figures are drawn by scripts/tgnav_plots.py.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace tgnav::harness {

// Frames (CV_8UC3, any sizes) scaled to `thumb_width` and laid out in rows of `per_row`, each
// with its caption underneath. Empty input gives an empty Mat; std::invalid_argument for frames
// and captions of different counts, a frame that is not CV_8UC3, or a bad layout.
cv::Mat drawFrameStrip(const std::vector<cv::Mat>& frames, const std::vector<std::string>& captions,
                       int thumb_width = 240, int per_row = 4);

}  // namespace tgnav::harness
