#include "harness/sim/vehicle_model.h"

#include <cctype>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

#include "harness/base/errors.h"
#include "harness/base/files.h"

namespace tgnav::harness {

namespace fs = std::filesystem;

namespace {

bool sameFile(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  return fs::equivalent(a, b, ec);
}

// MuJoCo 2.2's virtual file system is a 2 MB struct: on the heap.
struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;  // NOLINT(cppcoreguidelines-owning-memory): paired with the new below
  }
};

ModelPtr compileText(const fs::path& mjcf, const std::string& text, const std::string& what) {
  installMujocoHandlers();
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);  // NOLINT(cppcoreguidelines-owning-memory)
  mj_defaultVFS(vfs.get());
  const std::string name = mjcf.string();
  if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(text.size())) != 0) {
    throw std::runtime_error("MuJoCo: cannot stage " + name + " in the virtual file system");
  }
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name.c_str())], text.data(), text.size());
  char error[1024] = "";
  ModelPtr m(mj_loadXML(name.c_str(), vfs.get(), error, sizeof(error)));
  if (!m) throw InputError(mjcf.string() + " with " + what + ": invalid MJCF: " + error);
  return m;
}

}  // namespace

std::string composeVehicleScene(const fs::path& mjcf, const VehicleDescription& vehicle) {
  std::string text = readTextFile(mjcf);
  const std::string rel = fs::relative(vehicle.mjcf, fs::absolute(mjcf).parent_path()).generic_string();
  fs::path description;
  if (const std::optional<IncludeRef> inc = vehicleInclude(mjcf, text, &description)) {
    text.replace(inc->value_begin, inc->value_end - inc->value_begin, rel);
    return text;
  }
  // No vehicle yet: include it first, as the paper's scenes do theirs.
  std::size_t root = text.find("<mujoco");
  while (root != std::string::npos && text.compare(root, 7, "<mujoco") == 0 &&
         std::isspace(static_cast<unsigned char>(text[root + 7])) == 0 && text[root + 7] != '>') {
    root = text.find("<mujoco", root + 7);
  }
  const std::size_t open_end = root == std::string::npos ? std::string::npos : text.find('>', root);
  if (open_end == std::string::npos) throw InputError(mjcf.string() + ": no <mujoco> element to add the vehicle to");
  text.insert(open_end + 1, "\n  <include file=\"" + rel + "\"/>");
  return text;
}

VehicleModel loadVehicleModel(const fs::path& mjcf, const fs::path& vehicle_yaml) {
  if (!isRegularFile(mjcf)) throw InputError(mjcf.string() + ": MJCF file not found");
  const fs::path included = includedVehicle(mjcf);
  const fs::path yaml = vehicle_yaml.empty() ? included : vehicle_yaml;
  if (yaml.empty()) {
    // A scene with no vehicle: what is wrong with its MJCF comes first, then that it has none.
    loadModel(mjcf);
    resolveVehicle(mjcf, yaml);  // throws, saying how to name one
  }
  VehicleModel out;
  out.vehicle = loadVehicleDescription(yaml);
  const bool as_written =
      !included.empty() && (yaml == included || sameFile(loadVehicleDescription(included).mjcf, out.vehicle.mjcf));
  if (as_written) {
    out.model = loadModel(mjcf);
  } else if (!descriptionBeside(mjcf).empty()) {
    throw InputError(mjcf.string() + ": is itself a vehicle (" + descriptionBeside(mjcf).string() +
                     " beside it); it cannot be flown by " + yaml.string());
  } else {
    out.model = compileText(mjcf, composeVehicleScene(mjcf, out.vehicle), "vehicle " + yaml.string());
  }
  if (out.vehicle.timestep_s > 0.0) out.model->opt.timestep = out.vehicle.timestep_s;
  out.ids = VehicleIds::find(out.model.get(), out.vehicle);
  return out;
}

}  // namespace tgnav::harness
