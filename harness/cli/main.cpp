// tgnav: headless closed-loop harness for topology-guided perception-aware MAV navigation.
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>

#include "harness/base/errors.h"
#include "harness/cli/cli.h"

namespace {

// Parses the command line and runs the command; the exit code. Exceptions other than the ones
// that name a bad command line or input go on to main().
int runCommandLine(int argc, char** argv) {
  CLI::App app{"tgnav: topology-guided, perception-aware MAV navigation in MuJoCo, closed loop"};
  app.require_subcommand(1);
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return "tgnav: error: " + std::string(e.what()) + " (see --help)\n";
  });
  tgnav::cli::addRenderCommand(app);
  tgnav::cli::addFlyCommand(app);
  tgnav::cli::addMapCommand(app);
  tgnav::cli::addPlanCommand(app);
  tgnav::cli::addTrialCommand(app);
  tgnav::cli::addSweepCommand(app);
  tgnav::cli::addReportCommand(app);
  tgnav::cli::addViewsCommand(app);
  tgnav::cli::addVoCommand(app);
  tgnav::cli::addEvalCommand(app);
  tgnav::cli::addSceneCommand(app);
  tgnav::cli::addDefaultsCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {  // a command's own exit code (e.g. 130: interrupted)
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  } catch (const tgnav::InputError& e) {
    std::fprintf(stderr, "tgnav: error: %s\n", tgnav::oneLine(e.what()).c_str());
    return 2;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return runCommandLine(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tgnav: internal error: %s\n", tgnav::oneLine(e.what()).c_str());
    return 1;
  } catch (...) {
    std::fprintf(stderr, "tgnav: internal error: unknown exception\n");
    return 1;
  }
}
