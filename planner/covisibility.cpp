#include "planner/covisibility.h"

#include <algorithm>
#include <iterator>

#include "planner/check.h"

namespace tgnav::planner {

void SegmentConfig::validate() const {
  require(min_length_m > 0.0, "min_length_m", min_length_m, "must be > 0");
  require(covisibility_ratio >= 0.0 && covisibility_ratio <= 1.0, "covisibility_ratio", covisibility_ratio,
          "must be in [0, 1]");
}

double covisibilityRatio(const std::vector<int>& a, const std::vector<int>& b, std::vector<int>* intersection,
                         const KeyWeight& weight, int* common) {
  intersection->clear();
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(*intersection));
  auto count = [&](const std::vector<int>& keys) {
    if (!weight) return static_cast<long long>(keys.size());
    long long n = 0;
    for (int key : keys) n += weight(key);
    return n;
  };
  const long long both = count(*intersection);
  if (common != nullptr) *common = static_cast<int>(both);
  const long long union_size = count(a) + count(b) - both;
  return union_size == 0 ? 0.0 : static_cast<double>(both) / static_cast<double>(union_size);
}

double polylineLength3(const std::vector<Eigen::Vector3d>& path) {
  double len = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) len += (path[i] - path[i - 1]).norm();
  return len;
}

Eigen::Vector3d pointAt(const std::vector<Eigen::Vector3d>& path, double s) {
  if (s <= 0.0 || path.size() == 1) return path.front();
  for (std::size_t i = 1; i < path.size(); ++i) {
    const double len = (path[i] - path[i - 1]).norm();
    if (s <= len) return len > 0.0 ? path[i - 1] + (path[i] - path[i - 1]) * (s / len) : path[i];
    s -= len;
  }
  return path.back();
}

std::vector<PathSegment> extractSegments(const std::vector<Eigen::Vector3d>& path, const SegmentConfig& config,
                                         const VisibilityQuery& visible, int* queries, const KeyWeight& weight) {
  std::vector<PathSegment> segments;
  if (path.empty()) return segments;
  int calls = 0;
  auto query = [&](double s) {
    ++calls;
    return visible(pointAt(path, s));
  };
  // Depth-first, left before right, so segments come out in path order.
  struct Pending {
    double s0, s1;
    std::vector<int> v0, v1;
  };
  const double length = polylineLength3(path);
  std::vector<Pending> stack;
  stack.push_back({0.0, length, query(0.0), length > 0.0 ? query(length) : std::vector<int>{}});
  if (length <= 0.0) stack.back().v1 = stack.back().v0;
  while (!stack.empty()) {
    Pending seg = std::move(stack.back());
    stack.pop_back();
    PathSegment out;
    out.ratio = covisibilityRatio(seg.v0, seg.v1, &out.covisible, weight, &out.covisible_landmarks);
    if (out.ratio >= config.covisibility_ratio || seg.s1 - seg.s0 <= config.min_length_m) {
      out.s_begin_m = seg.s0;
      out.s_end_m = seg.s1;
      out.p_begin = pointAt(path, seg.s0);
      out.p_end = pointAt(path, seg.s1);
      segments.push_back(std::move(out));
      continue;
    }
    const double mid = 0.5 * (seg.s0 + seg.s1);
    std::vector<int> vm = query(mid);
    stack.push_back({mid, seg.s1, vm, std::move(seg.v1)});
    stack.push_back({seg.s0, mid, std::move(seg.v0), std::move(vm)});
  }
  if (queries != nullptr) *queries = calls;
  return segments;
}

}  // namespace tgnav::planner
