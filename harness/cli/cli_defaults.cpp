// tgnav defaults: every setting of a scenario's sections (planner, controller, camera, vo, trial)
// with its built-in default, in the form config.yaml and scenario files take them.
#include <cstdio>

#include "harness/cli/cli.h"
#include "harness/config/scenario.h"

namespace tgnav::cli {

void addDefaultsCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("defaults", "Print every setting with its built-in default (YAML)");
  cmd->callback([] { std::fputs(harness::defaultSectionsYaml().c_str(), stdout); });
}

}  // namespace tgnav::cli
