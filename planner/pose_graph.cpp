#include "planner/pose_graph.h"

#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <tuple>

#include "planner/check.h"

namespace tgnav::planner {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
const double kGoldenAngle = M_PI * (3.0 - std::sqrt(5.0));  // 137.5 deg

// Angle in [-pi, pi] for arguments within a few turns (cheaper than std::remainder).
double wrapAngle(double a) {
  while (a > M_PI) a -= 2.0 * M_PI;
  while (a < -M_PI) a += 2.0 * M_PI;
  return a;
}

// Unit vectors spanning the plane perpendicular to `tangent`.
void perpendicularBasis(const Eigen::Vector3d& tangent, Eigen::Vector3d* e1, Eigen::Vector3d* e2) {
  const Eigen::Vector3d t = tangent.normalized();
  const Eigen::Vector3d up = std::abs(t.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  *e1 = up.cross(t).normalized();  // horizontal, to the left of the path
  *e2 = t.cross(*e1);              // "up" within the plane
}

// The turn on the spot at `start` from the vehicle's own yaw (yaw_of[0]) to each first-node yaw
// yaw_of[k], the shorter way round (both ways for a half turn, which could go either way).
struct StartTurn {
  // Which yaws it may reach: every lattice yaw it sweeps after the vehicle's own scores at least
  // the floor. Not turning is always allowed: the VO starts from the vehicle's own view whatever
  // the model says of it.
  std::vector<bool> ok;
  std::vector<double> failure;  // the summed -ln p of the views it sweeps (with a model; else 0)
};

StartTurn sweepStartTurn(const Eigen::Vector3d& start, const std::vector<double>& yaw_of, const VoxelMap& voxels,
                         const VisibilityConfig& visibility, const InformationConfig& information, double floor,
                         int substeps) {
  const int yaws = static_cast<int>(yaw_of.size());
  const std::vector<WeightedPoint> points = aggregateSlots(voxels, voxels.visibleSlots(start, visibility));
  // Every view the turn sweeps, `substeps` per lattice step: view[substeps * k] is yaw_of[k]'s.
  const int fine = substeps * yaws;
  const double fine_step = 2.0 * M_PI / fine;
  std::vector<double> view(static_cast<std::size_t>(fine));
  std::vector<double> miss(yaw_of.size(), 0.0);
  for (int j = 0; j < fine; ++j) {
    const double yaw = wrapAngle(yaw_of[0] + j * fine_step);
    ViewSupport support;
    const Matrix6d info =
        poseInformation(cameraPosition(start, yaw, visibility), yaw, points, visibility, information, &support);
    view[static_cast<std::size_t>(j)] = scoreInformation(info, support, information);
    if (information.model && j % substeps == 0) {
      miss[static_cast<std::size_t>(j / substeps)] = failureCost(information.model->probability(support));
    }
  }
  const double kNoView = std::numeric_limits<double>::infinity();
  StartTurn turn{std::vector<bool>(yaw_of.size(), false), std::vector<double>(yaw_of.size(), 0.0)};
  turn.ok[0] = true;
  double left = kNoView;
  double left_miss = 0.0;
  for (int k = 1; 2 * k <= yaws; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    for (int j = substeps * (k - 1) + 1; j <= substeps * k; ++j) {
      left = std::min(left, view[static_cast<std::size_t>(j)]);
    }
    left_miss += miss[ku];
    turn.ok[ku] = left >= floor;
    turn.failure[ku] = left_miss;
  }
  double right = kNoView;
  double right_miss = 0.0;
  for (int k = yaws - 1; 2 * k >= yaws; --k) {
    const auto ku = static_cast<std::size_t>(k);
    for (int j = substeps * k; j < substeps * (k + 1); ++j) {  // inside (0, fine): 2 k >= yaws, k < yaws
      right = std::min(right, view[static_cast<std::size_t>(j)]);
    }
    right_miss += miss[ku];
    const bool fine_turn = right >= floor;
    // Half round: the turn goes either way; both must pass, and the worse sweep counts.
    turn.ok[ku] = 2 * k == yaws ? turn.ok[ku] && fine_turn : fine_turn;
    turn.failure[ku] = 2 * k == yaws ? std::max(turn.failure[ku], right_miss) : right_miss;
  }
  return turn;
}

}  // namespace

double failureCost(double probability) { return -std::log(std::max(probability, kMinTrackProbability)); }

void PoseGraphConfig::validate() const {
  require(nominal_speed_mps > 0.0, "nominal_speed_mps", nominal_speed_mps, "must be > 0");
  require(time_step_s > 0.0, "time_step_s", time_step_s, "must be > 0");
  require(position_samples >= 1, "position_samples", position_samples, "must be >= 1");
  require(sample_radius_m >= 0.0, "sample_radius_m", sample_radius_m, "must be >= 0");
  require(yaw_samples >= 1, "yaw_samples", yaw_samples, "must be >= 1");
  require(yaw_rate_limit_rad_s >= 0.0, "yaw_rate_limit_rad_s", yaw_rate_limit_rad_s, "must be >= 0");
  require(yaw_samples == 1 || 2.0 * M_PI / yaw_samples <= yaw_rate_limit_rad_s * time_step_s + 1e-9, "yaw_samples",
          yaw_samples,
          "the yaw interval 2 pi / yaw_samples must not exceed yaw_rate_limit_rad_s * time_step_s, or the yaw could "
          "never change");
  require(distance_weight >= 0.0, "distance_weight", distance_weight, "must be >= 0");
  require(perception_weight >= 0.0, "perception_weight", perception_weight, "must be >= 0");
  require(robot_radius_m >= 0.0, "robot_radius_m", robot_radius_m, "must be >= 0");
  require(between_checks >= 0 && between_checks <= 20, "between_checks", between_checks, "must be in [0, 20]");
  require(turn_substeps >= 1 && turn_substeps <= 16, "turn_substeps", turn_substeps, "must be in [1, 16]");
  require(max_between_rounds >= 1, "max_between_rounds", max_between_rounds, "must be >= 1");
  require(std::isfinite(failure_weight) && failure_weight >= 0.0, "failure_weight", failure_weight, "must be >= 0");
  require(std::isfinite(look_unknown_m) && look_unknown_m >= 0.0, "look_unknown_m", look_unknown_m, "must be >= 0");
}

double lookAheadHalfFov(const VisibilityConfig& visibility) {
  return std::max(0.0, 0.5 * visibility.hfov_rad - 10.0 * M_PI / 180.0);
}

DagPath shortestLayeredPath(const LayeredDag& dag) {
  DagMemo memo;
  return shortestLayeredPath(dag, &memo, 0);
}

DagPath shortestLayeredPath(const LayeredDag& dag, DagMemo* memo, std::size_t first_changed) {
  DagPath result;
  const std::size_t layers = dag.node_cost.size();
  if (layers == 0) return result;
  std::vector<std::vector<double>>& best = memo->best;
  std::vector<std::vector<int>>& parent = memo->parent;
  if (best.size() != layers) first_changed = 0;
  best.resize(layers);
  parent.resize(layers);
  if (first_changed == 0) {
    best[0] = dag.node_cost[0];
    parent[0].assign(best[0].size(), -1);
  }
  for (std::size_t j = first_changed; j + 1 < layers; ++j) {
    best[j + 1].assign(dag.node_cost[j + 1].size(), kInf);
    parent[j + 1].assign(dag.node_cost[j + 1].size(), -1);
    for (const LayeredDag::Edge& e : dag.edges[j]) {
      const double c = best[j][static_cast<std::size_t>(e.from)] + e.cost;
      const std::size_t to = static_cast<std::size_t>(e.to);
      if (c < best[j + 1][to] || (c == best[j + 1][to] && c < kInf && e.from < parent[j + 1][to])) {
        best[j + 1][to] = c;
        parent[j + 1][to] = e.from;
      }
    }
    for (std::size_t n = 0; n < best[j + 1].size(); ++n) best[j + 1][n] += dag.node_cost[j + 1][n];
  }
  int end = -1;
  for (std::size_t n = 0; n < best.back().size(); ++n) {
    if (best.back()[n] < kInf && (end < 0 || best.back()[n] < best.back()[static_cast<std::size_t>(end)])) {
      end = static_cast<int>(n);
    }
  }
  if (end < 0) return result;
  result.found = true;
  result.cost = best.back()[static_cast<std::size_t>(end)];
  result.nodes.assign(layers, -1);
  for (std::size_t j = layers; j-- > 0;) {
    result.nodes[j] = end;
    end = parent[j][static_cast<std::size_t>(end)];
  }
  return result;
}

PoseGraphResult searchPoseGraph(const std::vector<Eigen::Vector3d>& path, const std::vector<PathSegment>& segments,
                                const VoxelMap& voxels, const VisibilityConfig& visibility,
                                const InformationConfig& information, const PoseGraphConfig& config,
                                double start_yaw_rad, std::uint64_t seed, double turn_from_yaw_rad) {
  PoseGraphResult result;
  const double length = polylineLength3(path);
  const double spacing_max = config.nominal_speed_mps * config.time_step_s;
  const int intervals = std::max(1, static_cast<int>(std::ceil(length / spacing_max - 1e-9)));
  const int layers = intervals + 1;
  const double spacing = length / intervals;
  const int yaws = config.yaw_samples;
  const double yaw_step = 2.0 * M_PI / yaws;
  const bool free_start = std::isnan(start_yaw_rad);
  const double yaw0 = !free_start ? start_yaw_rad : std::isnan(turn_from_yaw_rad) ? 0.0 : turn_from_yaw_rad;
  // Every layer is one time step Ts (layers are at most v_nom * Ts apart): the yaw may change by
  // up to yaw_rate_limit * Ts between layers, at least one yaw interval by validate().
  const int max_yaw_steps =
      yaws == 1
          ? 0
          : std::min(yaws / 2,
                     static_cast<int>(std::floor(config.yaw_rate_limit_rad_s * config.time_step_s / yaw_step + 1e-9)));

  // Landmarks of each segment's co-visible set, grouped by voxel once.
  std::vector<std::vector<WeightedPoint>> segment_points;
  segment_points.reserve(segments.size());
  for (const PathSegment& seg : segments) segment_points.push_back(aggregateSlots(voxels, seg.covisible));

  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::vector<Eigen::Vector3d>> positions(static_cast<std::size_t>(layers));
  LayeredDag dag;
  dag.node_cost.resize(static_cast<std::size_t>(layers));
  dag.edges.resize(static_cast<std::size_t>(layers - 1));
  std::vector<std::vector<double>> scores(static_cast<std::size_t>(layers));
  std::vector<std::vector<WeightedPoint>> layer_seen(static_cast<std::size_t>(layers));
  // What the camera sees around a layer (V of its path point, any yaw): the image coverage of
  // InformationConfig::min_image_coverage is the camera's, not the co-visible set's.
  const bool inner = information.usesInnerDetections();
  static const std::vector<WeightedPoint> kNone;
  auto segmentAt = [&](double s) {
    int seg = 0;
    while (seg + 1 < static_cast<int>(segments.size()) && segments[static_cast<std::size_t>(seg)].s_end_m < s) ++seg;
    return seg;
  };
  auto pointsOf = [&](int seg) -> const std::vector<WeightedPoint>& {
    return segment_points.empty() ? kNone : segment_points[static_cast<std::size_t>(seg)];
  };
  result.layer_s.resize(static_cast<std::size_t>(layers));
  result.layer_segment.resize(static_cast<std::size_t>(layers));
  const int half_window = static_cast<int>(std::ceil(0.5 * visibility.hfov_rad / yaw_step)) + 1;
  const double tan_half_vfov = std::tan(0.5 * visibility.vfov_rad);
  std::vector<double> yaw_of(static_cast<std::size_t>(yaws));
  std::vector<ImageCells> cells_of;
  std::vector<FieldOfView> view_of;  // used where the camera sits off the body's centre
  std::vector<Eigen::Vector3d> camera_of(static_cast<std::size_t>(yaws));  // the camera's offset at each yaw
  cells_of.reserve(static_cast<std::size_t>(yaws));
  view_of.reserve(static_cast<std::size_t>(yaws));
  const bool offset = cameraOffset(visibility);
  for (int k = 0; k < yaws; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    yaw_of[ku] = wrapAngle(yaw0 + k * yaw_step);
    cells_of.emplace_back(yaw_of[ku], visibility);
    view_of.emplace_back(yaw_of[ku], visibility);
    camera_of[ku] = cameraPosition(Eigen::Vector3d::Zero(), yaw_of[ku], visibility);
  }
  // The turn on the spot at the start: guarded (guard_start_turn), and with a model its views'
  // expected failure added to the first layer's nodes (failure_weight).
  const bool turns = free_start && !std::isnan(turn_from_yaw_rad) && !path.empty();
  const bool failures = information.model != nullptr && config.failure_weight > 0.0;
  // Unguarded, the sweep's floor is -inf: every yaw is allowed.
  const StartTurn turn =
      turns && (config.guard_start_turn || failures)
          ? sweepStartTurn(path.front(), yaw_of, voxels, visibility, information,
                           config.guard_start_turn ? config.turn_floor : -std::numeric_limits<double>::infinity(),
                           config.turn_substeps)
          : StartTurn{std::vector<bool>(static_cast<std::size_t>(yaws), true),
                      std::vector<double>(static_cast<std::size_t>(yaws), 0.0)};

  // The look-ahead's way ahead of each layer (look_unknown_m): the path point look_unknown_m on,
  // where it or the one half as far is unobserved; NaN where the layer keeps its own yaws.
  const double half_fov = lookAheadHalfFov(visibility);
  std::vector<Eigen::Vector3d> way_ahead(static_cast<std::size_t>(layers),
                                         Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  // The yaw the look-ahead flies at p for a pose of layer j with yaw `yaw`.
  auto flownYaw = [&](int j, const Eigen::Vector3d& p, double yaw) {
    const Eigen::Vector3d& far = way_ahead[static_cast<std::size_t>(j)];
    if (std::isnan(far.x())) return yaw;
    const Eigen::Vector2d way = (far - p).head<2>();
    if (way.norm() < kLookAheadMinWayM) return yaw;
    const double heading = std::atan2(way.y(), way.x());
    const double off = wrapAngle(yaw - heading);
    return std::abs(off) <= half_fov ? yaw : wrapAngle(heading + std::copysign(half_fov, off));
  };
  // A view's score and support from camera pose (p, yaw): the landmarks `points` (a segment's
  // co-visible set) for the information, `seen` (the camera's V near it) for the image coverage.
  const bool gate = information.usesImageCells();
  auto viewAt = [&](const Eigen::Vector3d& p, double yaw, const std::vector<WeightedPoint>& points,
                    const std::vector<WeightedPoint>& seen, ViewSupport* backing) {
    const Eigen::Vector3d c = cameraPosition(p, yaw, visibility);
    const Matrix6d info = poseInformation(c, yaw, points, visibility, information, backing);
    if (gate) {
      backing->cells = 0;
      const ImageCells cell(yaw, visibility);
      const FieldOfView in_view(yaw, visibility);
      for (const WeightedPoint& pt : seen) {
        if (in_view(c, pt.p_W) && withinIncidence(c, pt, information)) backing->cover(cell(c, pt.p_W));
      }
    }
    return scoreInformation(info, *backing, information);
  };

  for (int j = 0; j < layers; ++j) {
    const double s = j == layers - 1 ? length : spacing * j;
    result.layer_s[static_cast<std::size_t>(j)] = s;
    const Eigen::Vector3d centre = pointAt(path, s);
    if (config.look_unknown_m > 0.0 && j > 0) {
      const Eigen::Vector3d far = pointAt(path, std::min(length, s + config.look_unknown_m));
      const Eigen::Vector3d near = pointAt(path, std::min(length, s + 0.5 * config.look_unknown_m));
      if (!voxels.observed(far) || !voxels.observed(near)) way_ahead[static_cast<std::size_t>(j)] = far;
    }
    std::vector<Eigen::Vector3d> candidates{centre};
    if (j > 0 && j < layers - 1) {
      Eigen::Vector3d e1, e2;
      const Eigen::Vector3d tangent = pointAt(path, s + 0.05) - pointAt(path, s - 0.05);
      perpendicularBasis(tangent.norm() > 1e-9 ? tangent : Eigen::Vector3d::UnitX(), &e1, &e2);
      const int others = config.position_samples - 1;
      for (int k = 1; k <= others; ++k) {
        double r = 0.0;
        double a = 0.0;
        if (config.random_positions) {
          r = config.sample_radius_m * std::sqrt(unit(rng));
          a = 2.0 * M_PI * unit(rng);
        } else {  // sunflower lattice: equal areas per point, the outermost on the rim
          r = config.sample_radius_m * std::sqrt((k - 0.5) / (others - 0.5));
          a = kGoldenAngle * (k + j);
        }
        candidates.push_back(centre + r * (std::cos(a) * e1 + std::sin(a) * e2));
      }
    }
    const int seg = segmentAt(s);
    result.layer_segment[static_cast<std::size_t>(j)] = seg;
    const std::vector<WeightedPoint>& points = pointsOf(seg);
    auto& layer_positions = positions[static_cast<std::size_t>(j)];
    auto& layer_cost = dag.node_cost[static_cast<std::size_t>(j)];
    auto& layer_scores = scores[static_cast<std::size_t>(j)];
    auto& seen = layer_seen[static_cast<std::size_t>(j)];
    if (gate) seen = aggregateSlots(voxels, voxels.visibleSlots(centre, visibility));
    for (const Eigen::Vector3d& p : candidates) {
      if (voxels.clearance(p) < config.robot_radius_m) continue;
      layer_positions.push_back(p);
      // Calls add(yaw index, camera position) for each yaw whose camera's field of view holds pt
      // (range, vertical and horizontal FoV, incidence); only yaws near its azimuth can (all of
      // them when the FoV is wide compared to the yaw grid). A camera ahead of the body's centre
      // (camera_forward_m >= 0) sees pt only along yaws that would see it from the centre too, so
      // the centre's window holds them; each is then tested from its own camera position.
      auto forYawsHolding = [&](const WeightedPoint& pt, auto&& add) {
        const Eigen::Vector3d d = pt.p_W - p;
        if (!offset) {
          const double range = d.norm();
          if (range < visibility.min_range_m || range > visibility.max_range_m) return;
          if (!withinIncidence(p, pt, information)) return;
          if (!withinHalfAngle(std::abs(d.z()), d.head<2>().norm(), 0.5 * visibility.vfov_rad, tan_half_vfov)) {
            return;
          }
        }
        const double azimuth = std::atan2(d.y(), d.x());
        const bool all = 2 * half_window + 1 >= yaws;
        // The window only has to hold every yaw that can see pt (it has a spare yaw each side),
        // so the bin nearest the azimuth may round either way; each yaw is then tested exactly.
        const double bin = (azimuth - yaw0) / yaw_step;
        const int nearest = all ? 0 : static_cast<int>(bin + (bin >= 0.0 ? 0.5 : -0.5));
        const int first = all ? 0 : nearest - half_window;
        const int last = all ? yaws - 1 : nearest + half_window;
        int idx = first % yaws;
        if (idx < 0) idx += yaws;
        for (int k = first; k <= last; ++k) {
          const auto iu = static_cast<std::size_t>(idx);
          if (!offset) {
            if (std::abs(wrapAngle(azimuth - yaw_of[iu])) <= 0.5 * visibility.hfov_rad) add(iu, p);
          } else {
            const Eigen::Vector3d c = p + camera_of[iu];
            if (view_of[iu](c, pt.p_W) && withinIncidence(c, pt, information)) add(iu, c);
          }
          if (++idx == yaws) idx = 0;
        }
      };
      // Information per yaw from the segment's co-visible landmarks (eq. 6).
      std::vector<Matrix6d> info(static_cast<std::size_t>(yaws), Matrix6d::Zero());
      std::vector<ViewSupport> support(static_cast<std::size_t>(yaws));
      for (const WeightedPoint& pt : points) {
        Matrix6d contribution = Matrix6d::Zero();
        bool computed = false;
        double range = 0.0;
        forYawsHolding(pt, [&](std::size_t idx, const Eigen::Vector3d& c) {
          if (offset) {  // each yaw's camera is elsewhere
            addCentredInformation(c, pt.p_W, pt.weight, information.bearing_noise_rad, &info[idx]);
            support[idx].count(pt, (pt.p_W - c).norm(), inner && cells_of[idx].inner(c, pt.p_W));
            return;
          }
          if (!computed) {
            addCentredInformation(p, pt.p_W, pt.weight, information.bearing_noise_rad, &contribution);
            range = (pt.p_W - p).norm();
          }
          computed = true;
          info[idx] += contribution;
          support[idx].count(pt, range, inner && cells_of[idx].inner(p, pt.p_W));
        });
      }
      for (const WeightedPoint& pt : seen) {
        forYawsHolding(
            pt, [&](std::size_t idx, const Eigen::Vector3d& c) { support[idx].cover(cells_of[idx](c, pt.p_W)); });
      }
      // The look-ahead turns a node's camera to one of the window's two edges: those views, once.
      std::map<double, std::pair<double, ViewSupport>> turned;
      for (int k = 0; k < yaws; ++k) {
        const auto ku = static_cast<std::size_t>(k);
        const double flown = flownYaw(j, p, yaw_of[ku]);
        if (flown != yaw_of[ku] && turned.count(flown) == 0) {
          ViewSupport view;
          const double score = viewAt(p, flown, points, seen, &view);
          turned.emplace(flown, std::make_pair(score, view));
        }
        const bool turns = flown != yaw_of[ku];
        const ViewSupport& backing = turns ? turned.at(flown).second : support[ku];
        const double score = turns ? turned.at(flown).first : scoreInformation(info[ku], backing, information);
        const bool allowed = j != 0 || (free_start ? turn.ok[static_cast<std::size_t>(k)] : k == 0);
        layer_scores.push_back(score);
        double cost = -config.perception_weight * rankedScore(score, backing, information) / layers;
        if (failures) {
          cost += config.failure_weight * (failureCost(information.model->probability(backing)) +
                                           (j == 0 ? turn.failure[static_cast<std::size_t>(k)] : 0.0));
        }
        layer_cost.push_back(allowed ? cost : kInf);
      }
    }
    if (layer_positions.empty() && result.blocked_layer < 0) result.blocked_layer = j;
  }

  for (int j = 0; j + 1 < layers; ++j) {
    const auto& from = positions[static_cast<std::size_t>(j)];
    const auto& to = positions[static_cast<std::size_t>(j) + 1];
    auto& edges = dag.edges[static_cast<std::size_t>(j)];
    edges.reserve(from.size() * to.size() * static_cast<std::size_t>(yaws * (2 * max_yaw_steps + 1)));
    for (std::size_t a = 0; a < from.size(); ++a) {
      for (std::size_t b = 0; b < to.size(); ++b) {
        if (!voxels.segmentClear(from[a], to[b], config.robot_radius_m)) continue;
        const double cost = config.distance_weight * (to[b] - from[a]).norm();
        for (int k = 0; k < yaws; ++k) {
          for (int d = -max_yaw_steps; d <= max_yaw_steps; ++d) {
            if (2 * d == yaws) continue;  // the same yaw as d = -yaws / 2
            const int kb = ((k + d) % yaws + yaws) % yaws;
            edges.push_back({static_cast<int>(a) * yaws + k, static_cast<int>(b) * yaws + kb, cost});
          }
        }
      }
    }
    result.edges += static_cast<int>(edges.size());
  }
  for (const auto& layer : dag.node_cost) result.nodes += static_cast<int>(layer.size());

  // Lazy checks of the moves between layers (PoseGraphConfig::between_checks).
  const double blind = logDetInformation(Matrix6d::Zero(), information.epsilon);
  auto isBlind = [&](double score) { return score <= blind + 1e-9; };
  // The lower score of a move's two ends.
  auto lowerEnd = [&](int j, int from, int to) {
    return std::min(scores[static_cast<std::size_t>(j)][static_cast<std::size_t>(from)],
                    scores[static_cast<std::size_t>(j) + 1][static_cast<std::size_t>(to)]);
  };
  // The lowest ranked score of the views between node `from` of layer j and node `to` of layer
  // j + 1 that score blind, or NaN when none does or an end is blind already.
  auto checkMove = [&](int j, int from, int to) {
    const auto ju = static_cast<std::size_t>(j);
    const Eigen::Vector3d& pa = positions[ju][static_cast<std::size_t>(from / yaws)];
    const Eigen::Vector3d& pb = positions[ju + 1][static_cast<std::size_t>(to / yaws)];
    const double ya = yaw_of[static_cast<std::size_t>(from % yaws)];
    const double turn = wrapAngle(yaw_of[static_cast<std::size_t>(to % yaws)] - ya);
    double lowest = std::numeric_limits<double>::quiet_NaN();
    if (isBlind(lowerEnd(j, from, to))) return lowest;
    ++result.between_checked;
    for (int i = 1; i <= config.between_checks; ++i) {
      const double f = static_cast<double>(i) / (config.between_checks + 1);
      const Eigen::Vector3d p = (1.0 - f) * pa + f * pb;
      const double s = (1.0 - f) * result.layer_s[ju] + f * result.layer_s[ju + 1];
      const std::size_t nearer = 2 * i <= config.between_checks + 1 ? ju : ju + 1;
      const double yaw = flownYaw(static_cast<int>(nearer), p, wrapAngle(ya + f * turn));
      ViewSupport backing;
      const double score = viewAt(p, yaw, pointsOf(segmentAt(s)), layer_seen[nearer], &backing);
      if (!isBlind(score)) continue;
      const double ranked = rankedScore(score, backing, information);
      if (!(ranked >= lowest)) lowest = ranked;  // also replaces NaN
    }
    return lowest;
  };
  std::map<std::tuple<int, int, int>, double> checked;  // (layer, from, to) -> checkMove()
  DagMemo memo;
  DagPath best = shortestLayeredPath(dag, &memo, 0);
  result.between_rounds = 1;
  while (config.between_checks > 0 && best.found) {
    bool penalised = false;
    std::size_t first_penalised = 0;
    for (int j = 0; j + 1 < layers; ++j) {
      const int from = best.nodes[static_cast<std::size_t>(j)];
      const int to = best.nodes[static_cast<std::size_t>(j) + 1];
      const auto key = std::make_tuple(j, from, to);
      if (checked.count(key) > 0) continue;
      const double lowest = checkMove(j, from, to);
      checked[key] = lowest;
      if (std::isnan(lowest)) continue;
      // The move costs what it would if its lower end were its blindest view.
      const double penalty = config.perception_weight * (lowerEnd(j, from, to) - lowest) / layers;
      for (LayeredDag::Edge& e : dag.edges[static_cast<std::size_t>(j)]) {
        if (e.from == from && e.to == to) e.cost += penalty;
      }
      if (!penalised) first_penalised = static_cast<std::size_t>(j);
      penalised = true;
    }
    if (!penalised || result.between_rounds >= config.max_between_rounds) break;
    best = shortestLayeredPath(dag, &memo, first_penalised);
    ++result.between_rounds;
  }
  if (!best.found) return result;
  result.found = true;
  for (int j = 0; j < layers; ++j) {
    const int node = best.nodes[static_cast<std::size_t>(j)];
    const int k = node % yaws;
    Pose4 pose;
    pose.p_WB = positions[static_cast<std::size_t>(j)][static_cast<std::size_t>(node / yaws)];
    pose.yaw_rad = yaw_of[static_cast<std::size_t>(k)];
    if (!result.path.empty()) result.c_d += (pose.p_WB - result.path.back().p_WB).norm();
    result.path.push_back(pose);
    result.scores.push_back(scores[static_cast<std::size_t>(j)][static_cast<std::size_t>(node)]);
  }
  // A move of the path that goes blind between two poses that pass: its lower end scores blind
  // (a layer's pose stands for the path around it). Moves left unchecked by the round limit are
  // checked here.
  for (int j = 0; config.between_checks > 0 && j + 1 < layers; ++j) {
    const int from = best.nodes[static_cast<std::size_t>(j)];
    const int to = best.nodes[static_cast<std::size_t>(j) + 1];
    const auto key = std::make_tuple(j, from, to);
    const auto it = checked.find(key);
    const double lowest = it != checked.end() ? it->second : checkMove(j, from, to);
    if (std::isnan(lowest)) continue;
    ++result.between_blind;
    double& a = result.scores[static_cast<std::size_t>(j)];
    double& b = result.scores[static_cast<std::size_t>(j) + 1];
    (a <= b ? a : b) = blind;
  }
  double sum = 0.0;
  for (double s : result.scores) sum += s;
  result.c_p = sum / layers;
  // Eq. 7 of the path found, with its reported scores (the search ranked gated poses and blind
  // moves below them, which is not part of the cost).
  result.cost = config.distance_weight * result.c_d - config.perception_weight * result.c_p;
  return result;
}

}  // namespace tgnav::planner
