#pragma once
// Subcommands of the `tgnav` program. Each registers itself on the app; its callback throws
// InputError for bad input (exit 2) and anything else for internal failures (exit 1).
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "harness/base/errors.h"
#include "harness/config/values.h"

namespace tgnav::cli {

using harness::parseNumbers;

void addDefaultsCommand(CLI::App& app);
void addEvalCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addReportCommand(CLI::App& app);
void addSceneCommand(CLI::App& app);
void addSweepCommand(CLI::App& app);
void addFlyCommand(CLI::App& app);
void addMapCommand(CLI::App& app);
void addPlanCommand(CLI::App& app);
void addTrialCommand(CLI::App& app);
void addViewsCommand(CLI::App& app);
void addVoCommand(CLI::App& app);

}  // namespace tgnav::cli
