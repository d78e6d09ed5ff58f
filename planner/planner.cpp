#include "planner/planner.h"

#include <stdexcept>

#include "planner/perception_planner.h"
#include "planner/rrt_star.h"

namespace tgnav::planner {

const char* toString(PlannerKind kind) {
  switch (kind) {
    case PlannerKind::kProposed:
      return "proposed";
    case PlannerKind::kAgnostic:
      return "agnostic";
    case PlannerKind::kRrtStar:
      return "rrtstar";
  }
  return "unknown";
}

bool parsePlannerKind(const std::string& text, PlannerKind* kind) {
  for (PlannerKind k : {PlannerKind::kProposed, PlannerKind::kAgnostic, PlannerKind::kRrtStar}) {
    if (text == toString(k)) {
      *kind = k;
      return true;
    }
  }
  return false;
}

std::unique_ptr<Planner> makePlanner(PlannerKind kind, const VoxelMap& voxels,
                                     const PerceptionPlannerConfig& perception, const RrtStarConfig& rrt_star) {
  switch (kind) {
    case PlannerKind::kProposed:
      return std::make_unique<ProposedPlanner>(voxels, perception);
    case PlannerKind::kAgnostic:
      return std::make_unique<AgnosticPlanner>(voxels, perception);
    case PlannerKind::kRrtStar:
      return std::make_unique<PerceptionRrtStar>(voxels, rrt_star);
  }
  throw std::invalid_argument("makePlanner: unknown planner kind");
}

}  // namespace tgnav::planner
