#pragma once
// YAML <-> module Config structs. Keys are optional (defaults come from the structs), unknown
// keys are errors, and validate() failures are reported with the file they came from.
//
// One read*Config function per struct names its keys; run on a FieldReader::writer it emits
// the struct instead (toYaml), so files written by the harness always load back.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "control/cascade.h"
#include "harness/camera.h"
#include "harness/errors.h"
#include "harness/trial_config.h"
#include "harness/yaml_util.h"
#include "vo/odometry.h"

namespace tgnav::harness {

// Keys: the fields of CameraConfig (configs/camera.yaml).
void readCameraConfig(FieldReader r, CameraConfig* c);
// Keys: rates_hz {position, attitude, rate}, position, attitude, rate (configs/controller.yaml).
void readCascadeConfig(FieldReader r, control::CascadeConfig* c);
// Keys: the fields of vo::OdometryConfig, `features:` those of vo::FeatureConfig (configs/vo.yaml).
void readOdometryConfig(FieldReader r, vo::OdometryConfig* c);
// Keys: state_source (gt | vo), camera_rate_hz, goal_radius_m, pipeline, and the sections flight
// (FlightConfig), imu (ImuConfig), estimator (control::EstimatorConfig) (configs/trial.yaml).
void readTrialConfig(FieldReader r, TrialConfig* c);

// A whole file read over `base`, then validated (InputError naming the file).
CameraConfig loadCameraConfig(const std::filesystem::path& yaml, CameraConfig base = {});
control::CascadeConfig loadCascadeConfig(const std::filesystem::path& yaml, control::CascadeConfig base = {});
vo::OdometryConfig loadOdometryConfig(const std::filesystem::path& yaml, vo::OdometryConfig base = {});
TrialConfig loadTrialConfig(const std::filesystem::path& yaml, TrialConfig base = {});

// Every key with its value, in the order and form the read functions take.
YAML::Node toYaml(const CameraConfig& c);
YAML::Node toYaml(const control::CascadeConfig& c);
YAML::Node toYaml(const vo::OdometryConfig& c);
YAML::Node toYaml(const TrialConfig& c);

// Runs config.validate(), re-raising std::invalid_argument as InputError "<source>: <what>".
template <typename Config>
void validateConfig(const Config& config, const std::string& source) {
  try {
    config.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(source + ": " + e.what());
  }
}

}  // namespace tgnav::harness
