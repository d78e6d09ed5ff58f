// Vehicle descriptions: any MJCF multirotor flies by the names its description gives, composed
// into a scene by reference; the allocation follows the rotor geometry of the MJCF with no code
// change; bad descriptions and models are one-line errors naming the file and the element.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "control/allocator.h"
#include "harness/base/files.h"
#include "harness/config/planner_config.h"
#include "harness/config/scenario.h"
#include "harness/config/scene_config.h"
#include "harness/run/map_cache.h"
#include "harness/run/trial_job.h"
#include "harness/sim/camera.h"
#include "harness/sim/egl_context.h"
#include "harness/sim/vehicle_model.h"
#include "test_util.h"

namespace tgnav::harness {
namespace {

namespace fs = std::filesystem;

fs::path src(const std::string& p) { return test::sourceDir() / p; }
fs::path emptyScene() { return loadSceneConfig(src("configs/scenes/empty.yaml")).mjcf; }

std::string replaced(std::string text, const std::vector<std::pair<std::string, std::string>>& edits) {
  for (const auto& [from, to] : edits) {
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  }
  return text;
}

// A copy of models/quadrotor.xml with `mjcf_edits`, and its description with `yaml_edits`, in a
// fresh folder: the description's path.
fs::path quadVariant(const std::vector<std::pair<std::string, std::string>>& mjcf_edits,
                     const std::vector<std::pair<std::string, std::string>>& yaml_edits = {}) {
  const fs::path dir = test::tempDir();
  test::writeFile(dir / "quadrotor.xml", replaced(readTextFile(src("models/quadrotor.xml")), mjcf_edits));
  return test::writeFile(dir / "quadrotor.yaml", replaced(readTextFile(src("models/quadrotor.yaml")), yaml_edits));
}

control::VehicleParams paramsOf(const fs::path& description) {
  const VehicleModel v = loadVehicleModel(emptyScene(), description);
  return vehicleParamsFromModel(v.model.get(), v.ids);
}

std::string modelError(const fs::path& description) {
  return test::inputError([&] {
    const VehicleModel v = loadVehicleModel(emptyScene(), description);
    vehicleParamsFromModel(v.model.get(), v.ids);
  });
}

void expectOneLine(const std::string& msg) {
  EXPECT_FALSE(msg.empty());
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

TEST(VehicleDescription, ShippedAirframesLoadWithTheirRotorCounts) {
  const std::vector<std::pair<std::string, std::size_t>> shipped = {{"models/quadrotor.yaml", 4},
                                                                    {"models/vehicles/quad250.yaml", 4},
                                                                    {"models/vehicles/hexarotor.yaml", 6},
                                                                    {"tests/data/x2_like/x2_like.yaml", 4}};
  for (const auto& [file, rotors] : shipped) {
    const VehicleDescription d = loadVehicleDescription(src(file));
    EXPECT_EQ(d.rotors.size(), rotors) << file;
    EXPECT_TRUE(fs::is_regular_file(d.mjcf)) << file;
    const control::VehicleParams p = paramsOf(src(file));
    EXPECT_EQ(p.rotors.size(), rotors) << file;
    EXPECT_LT(p.hoverThrust(), 0.6) << file;
  }
}

TEST(VehicleModel, ThePlannersDefaultRobotRadiusBoundsTheDefaultVehicle) {
  // The propeller discs (radius 0.12 m, 0.25 m out along the arms, 0.03 m up) reach 0.372 m.
  const VehicleModel own = loadVehicleModel(emptyScene());
  const double reach = vehicleReach(own.model.get(), own.ids);
  EXPECT_NEAR(reach, std::hypot(0.177 * std::sqrt(2.0), 0.03) + std::hypot(0.12, 0.005), 1e-6);
  const PlannerSettings defaults;
  EXPECT_GE(defaults.perception.robot_radius_m, reach);
  EXPECT_EQ(defaults.rrt_star.robot_radius_m, defaults.perception.robot_radius_m);
  EXPECT_EQ(defaults.trajectory.robot_radius_m, defaults.perception.robot_radius_m);
  // The shipped planner.yaml says the same.
  EXPECT_EQ(loadPlannerSettings(src("configs/planner.yaml")).perception.robot_radius_m,
            defaults.perception.robot_radius_m);
}

TEST(VehicleModel, ATrialRefusesARobotRadiusLessThanTheVehiclesReach) {
  // The hexarotor's rotor discs reach about 0.404 m, beyond the default 0.38 m: its trial is refused
  // before any map is built, with the radius it needs; at that radius it may fly. The default
  // vehicle flies at the default.
  const fs::path smoke = src("configs/scenarios/smoke.yaml");
  EXPECT_NO_THROW(checkRobotRadiusBoundsVehicle(loadScenario(smoke)));
  const YamlDoc hex = YamlDoc::fromOverrides({"vehicle=" + src("models/vehicles/hexarotor.yaml").string()});
  const Scenario scenario = loadScenario(smoke, &hex);
  const std::string msg = test::inputError([&] { checkRobotRadiusBoundsVehicle(scenario); });
  expectOneLine(msg);
  for (const char* part : {"smoke.yaml", "planner.robot_radius_m = 0.38", "hexarotor.yaml (0.40", "at least 0.41"}) {
    EXPECT_NE(msg.find(part), std::string::npos) << part << " in: " << msg;
  }
  const YamlDoc wider = YamlDoc::fromOverrides(
      {"vehicle=" + src("models/vehicles/hexarotor.yaml").string(), "planner.robot_radius_m=0.41"});
  EXPECT_NO_THROW(checkRobotRadiusBoundsVehicle(loadScenario(smoke, &wider)));
}

TEST(VehicleModel, TheSameSceneFlownByAnotherAirframe) {
  const VehicleModel own = loadVehicleModel(emptyScene());
  EXPECT_EQ(own.vehicle.source, src("models/quadrotor.yaml"));
  EXPECT_GE(mj_name2id(own.model.get(), mjOBJ_BODY, "quadrotor"), 0);

  const VehicleModel hex = loadVehicleModel(emptyScene(), src("models/vehicles/hexarotor.yaml"));
  EXPECT_LT(mj_name2id(hex.model.get(), mjOBJ_BODY, "quadrotor"), 0);
  EXPECT_EQ(hex.ids.body, mj_name2id(hex.model.get(), mjOBJ_BODY, "hexarotor"));
  EXPECT_EQ(hex.ids.rotorCount(), 6);
  EXPECT_GE(mj_name2id(hex.model.get(), mjOBJ_GEOM, "floor"), 0);  // the scene is still there
  EXPECT_NEAR(vehicleMass(hex.model.get(), hex.ids), 2.5, 1e-9);
  // Composed at the XML level: the scene's text with its vehicle include pointing elsewhere.
  const std::string text = composeVehicleScene(emptyScene(), hex.vehicle);
  EXPECT_NE(text.find("vehicles/hexarotor.xml\"/>"), std::string::npos) << text;
  EXPECT_EQ(text.find("quadrotor.xml"), std::string::npos);
}

TEST(VehicleModel, ASceneWithoutAVehicleGetsTheNamedOneAndOtherwiseSaysHow) {
  const fs::path dir = test::tempDir();
  const fs::path bare = test::writeFile(dir / "bare.xml",
                                        "<mujoco model=\"bare\">\n  <worldbody>\n    <geom name=\"floor\" "
                                        "type=\"plane\" size=\"5 5 0.1\"/>\n  </worldbody>\n</mujoco>\n");
  const VehicleModel v = loadVehicleModel(bare, src("models/vehicles/quad250.yaml"));
  EXPECT_EQ(v.ids.rotorCount(), 4);
  const std::string msg = test::inputError([&] { loadVehicleModel(bare); });
  expectOneLine(msg);
  EXPECT_EQ(msg.rfind(bare.string() + ": includes no vehicle", 0), 0u) << msg;
}

TEST(VehicleModel, X2LikeDirectThrustMotorsTakeTheirLagAndTimestepFromTheDescription) {
  const VehicleModel x2 = loadVehicleModel(emptyScene(), src("tests/data/x2_like/x2_like.yaml"));
  EXPECT_DOUBLE_EQ(x2.model->opt.timestep, 0.002);  // the MJCF says 0.01
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(x2.ids.motor_act[i], -1);
    EXPECT_NEAR(x2.ids.max_thrust_n[i], 13.0, 1e-12);
  }
  EXPECT_DOUBLE_EQ(x2.ids.direct_lag_s, 0.02);
  const control::VehicleParams p = vehicleParamsFromModel(x2.model.get(), x2.ids);
  EXPECT_NEAR(p.mass_kg, 1.325, 1e-9);
  EXPECT_NEAR(p.rotors[0].yaw_moment_ratio_m, 0.0201, 1e-12);
  // Rotors at two heights, relative to the centre of mass.
  EXPECT_NEAR(p.rotors[2].p_B.z() - p.rotors[0].p_B.z(), 0.03, 1e-9);
  EXPECT_GT(x2.ids.landed_height_m, 0.0);
}

TEST(Allocation, FollowsTheRotorGeometryOfTheMjcfWithoutCodeChanges) {
  const control::VehicleParams base = paramsOf(src("models/quadrotor.yaml"));
  // Longer arms: every rotor twice as far out, so twice the roll and pitch moment per newton
  // (the same thrust limits: twice per unit command too).
  std::vector<std::pair<std::string, std::string>> longer;
  for (const char* site : {"rotor0\" pos=\"0.177 -0.177", "rotor1\" pos=\"-0.177 0.177", "rotor2\" pos=\"0.177 0.177",
                           "rotor3\" pos=\"-0.177 -0.177"}) {
    std::string s = site;
    std::string to = s;
    for (std::size_t at = to.find("0.177"); at != std::string::npos; at = to.find("0.177", at + 5)) {
      to.replace(at, 5, "0.354");
    }
    longer.emplace_back(s, to);
  }
  const control::VehicleParams wide = paramsOf(quadVariant(longer));
  const Eigen::MatrixXd e0 = base.effectiveness();
  const Eigen::MatrixXd e1 = wide.effectiveness();
  EXPECT_TRUE(e1.topRows<2>().isApprox(2.0 * e0.topRows<2>(), 1e-9)) << e0 << "\n\n" << e1;
  EXPECT_TRUE(e1.bottomRows<2>().isApprox(e0.bottomRows<2>(), 1e-9));

  // Spins swapped: the yaw moment of every rotor changes sign, and so does the allocation of a
  // yaw demand.
  const control::VehicleParams swapped =
      paramsOf(quadVariant({{"site=\"rotor0\" gear=\"0 0 1 0 0 -0.02\"", "site=\"rotor0\" gear=\"0 0 1 0 0 0.02\""},
                            {"site=\"rotor1\" gear=\"0 0 1 0 0 -0.02\"", "site=\"rotor1\" gear=\"0 0 1 0 0 0.02\""},
                            {"site=\"rotor2\" gear=\"0 0 1 0 0 0.02\"", "site=\"rotor2\" gear=\"0 0 1 0 0 -0.02\""},
                            {"site=\"rotor3\" gear=\"0 0 1 0 0 0.02\"", "site=\"rotor3\" gear=\"0 0 1 0 0 -0.02\""}}));
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(swapped.rotors[i].spin, -base.rotors[i].spin) << i;
  control::ControlDemand yaw;
  yaw.torque = Eigen::Vector3d(0.0, 0.0, 0.2);
  yaw.thrust = 0.5;
  const Eigen::VectorXd u0 = control::ControlAllocator(base).allocate(yaw);
  const Eigen::VectorXd u1 = control::ControlAllocator(swapped).allocate(yaw);
  for (int i = 0; i < 4; ++i) {
    EXPECT_LT((u0[i] - 0.5) * (u1[i] - 0.5), 0.0) << "rotor " << i << ": " << u0[i] << " vs " << u1[i];
  }
}

TEST(VehicleErrors, MissingPartsNameTheMjcfElement) {
  const fs::path mjcf = src("models/quadrotor.xml");
  struct Case {
    std::vector<std::pair<std::string, std::string>> yaml_edits;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {{{"motor3]", "motorX]"}}, mjcf.string() + ": no actuator 'motorX'"},
      {{{"gyro: gyro", "gyro: gyr0"}}, mjcf.string() + ": no sensor 'gyr0'"},
      {{{"accelerometer: accel", "accelerometer: gyro"}}, mjcf.string() + ": sensor 'gyro' is not an <accelerometer>"},
      {{{"camera: front", "camera: rear"}}, mjcf.string() + ": no camera 'rear'"},
      {{{"body: quadrotor", "body: quad"}}, mjcf.string() + ": no body 'quad'"},
  };
  for (const Case& c : cases) {
    // The same MJCF, a broken description beside a copy of it: the copy is what is named.
    const fs::path description = quadVariant({}, c.yaml_edits);
    std::string expected = c.expected;
    expected.replace(0, mjcf.string().size(), (description.parent_path() / "quadrotor.xml").string());
    const std::string msg = modelError(description);
    expectOneLine(msg);
    EXPECT_EQ(msg.rfind(expected, 0), 0u) << msg;
  }
}

TEST(VehicleErrors, RotorWithoutThrustAxisUnsupportedCountsAndUncontrollableGeometry) {
  const fs::path no_axis =
      quadVariant({{"site=\"rotor0\" gear=\"0 0 1 0 0 -0.02\"", "site=\"rotor0\" gear=\"0 0 0 0 0 -0.02\""}});
  std::string msg = modelError(no_axis);
  expectOneLine(msg);
  EXPECT_NE(msg.find("actuator 'motor0' has no thrust axis"), std::string::npos) << msg;

  for (const char* rotors : {"[motor0, motor1, motor2]", "[motor0, motor1, motor2, motor3, motor0x]"}) {
    const fs::path d = quadVariant({}, {{"[motor0, motor1, motor2, motor3]", rotors}});
    msg = test::inputError([&] { loadVehicleDescription(d); });
    expectOneLine(msg);
    EXPECT_EQ(msg.rfind(d.string() + ":", 0), 0u) << msg;
    EXPECT_NE(msg.find("supported rotor counts are 4, 6 and 8"), std::string::npos) << msg;
  }

  // Every rotor spinning the same way: no yaw authority.
  const fs::path same_spin =
      quadVariant({{"site=\"rotor2\" gear=\"0 0 1 0 0 0.02\"", "site=\"rotor2\" gear=\"0 0 1 0 0 -0.02\""},
                   {"site=\"rotor3\" gear=\"0 0 1 0 0 0.02\"", "site=\"rotor3\" gear=\"0 0 1 0 0 -0.02\""}});
  msg = modelError(same_spin);
  expectOneLine(msg);
  EXPECT_NE(msg.find("cannot command roll, pitch, yaw and thrust independently"), std::string::npos) << msg;
}

TEST(VehicleErrors, DirectThrustNeedsItsLagAndFilteredMotorsRefuseOne) {
  const fs::path dir = test::tempDir();
  const std::string x2 = readTextFile(src("tests/data/x2_like/x2_like.yaml"));
  test::writeFile(dir / "x2_like.xml", readTextFile(src("tests/data/x2_like/x2_like.xml")));
  const fs::path no_lag =
      test::writeFile(dir / "x2_like.yaml", replaced(x2, {{"motor:\n  time_constant_s: 0.02\n", ""}}));
  std::string msg = modelError(no_lag);
  expectOneLine(msg);
  EXPECT_NE(msg.find("actuator 'thrust1' is a direct-thrust actuator"), std::string::npos) << msg;
  EXPECT_NE(msg.find("motor.time_constant_s"), std::string::npos) << msg;

  const fs::path lag_on_filter =
      quadVariant({}, {{"camera: front\n", "camera: front\nmotor: {time_constant_s: 0.03}\n"}});
  msg = modelError(lag_on_filter);
  expectOneLine(msg);
  EXPECT_NE(msg.find("has its own filter dynamics"), std::string::npos) << msg;
}

TEST(VehicleScenario, VehicleKeyAndGainsLayering) {
  const fs::path scenario = src("configs/scenarios/smoke.yaml");
  const Scenario own = loadScenario(scenario);
  EXPECT_EQ(own.vehicle, src("models/quadrotor.yaml"));
  EXPECT_DOUBLE_EQ(own.controller.rate.p[0], control::CascadeConfig{}.rate.p[0]);

  const std::string q250 = src("models/vehicles/quad250.yaml").string();
  const YamlDoc set = YamlDoc::fromOverrides({"vehicle=" + q250});
  const Scenario small = loadScenario(scenario, &set);
  EXPECT_EQ(small.vehicle, q250);
  EXPECT_DOUBLE_EQ(small.controller.rate.p[0], 0.029);  // quad250_gains.yaml
  EXPECT_DOUBLE_EQ(small.controller.position.pos_p_xy, control::CascadeConfig{}.position.pos_p_xy);

  const YamlDoc both = YamlDoc::fromOverrides({"vehicle=" + q250, "controller.rate.p=[0.03, 0.03, 0.02]"});
  EXPECT_DOUBLE_EQ(loadScenario(scenario, &both).controller.rate.p[0], 0.03);  // --set over the vehicle's

  // The resolved scenario names the vehicle and loads back the same.
  const Scenario back = loadScenario(test::writeFile(test::tempDir() / "resolved.yaml", resolvedScenarioYaml(small)));
  EXPECT_EQ(back.vehicle, q250);
  EXPECT_DOUBLE_EQ(back.controller.rate.p[0], 0.029);

  // The map is of the scene: the flown vehicle does not enter its key.
  EXPECT_EQ(mapKey(small.scene, MapBuildConfig{}), mapKey(own.scene, MapBuildConfig{}));

  const YamlDoc missing = YamlDoc::fromOverrides({"vehicle=no/such/vehicle.yaml"});
  const std::string msg = test::inputError([&] { loadScenario(scenario, &missing); });
  expectOneLine(msg);
  EXPECT_NE(msg.find("vehicle=no/such/vehicle.yaml"), std::string::npos) << msg;
}

TEST(VehicleCamera, TheOnboardCameraDoesNotSeeItsOwnVehicle) {
  // An opaque part of the vehicle 0.2 m in front of its camera, in geom group 0 (so no render
  // group hides it): the onboard camera must still see only the scene, the floor metres away.
  const fs::path described = quadVariant({{"<site name=\"imu\"",
                                           "<geom name=\"bumper\" group=\"0\" type=\"box\" pos=\"0.3 0 0.02\" "
                                           "size=\"0.01 0.08 0.08\" rgba=\"1 0 0 1\"/>\n      <site name=\"imu\""}});
  const VehicleModel v = loadVehicleModel(emptyScene(), described);
  DataPtr data = makeData(v.model.get());
  planner::Pose4 pose;
  pose.p_WB = Eigen::Vector3d(0.0, 0.0, 1.5);
  setVehiclePose(v.model.get(), data.get(), v.ids, pose);
  const EglContext gl;
  Camera camera(v.model.get(), gl, CameraConfig{}.on(v.vehicle.camera), 0);
  const RgbdFrame frame = camera.render(data.get());
  double nearest = 1e9;
  for (int r = 0; r < frame.depth_m.rows; ++r) {
    for (int c = 0; c < frame.depth_m.cols; ++c) {
      const float z = frame.depth_m.at<float>(r, c);
      if (z > 0.0f) nearest = std::min(nearest, static_cast<double>(z));
    }
  }
  EXPECT_GT(nearest, 1.5);
  const cv::Vec3b centre = frame.bgr.at<cv::Vec3b>(frame.bgr.rows / 2, frame.bgr.cols / 2);
  EXPECT_LT(centre[2], 200);  // not the red bumper
}

}  // namespace
}  // namespace tgnav::harness

namespace tgnav::harness {
namespace {

TEST(VehicleCli, BadVehicleIsAOneLineErrorAndExit2) {
  const std::filesystem::path dir = test::tempDir();
  const std::filesystem::path bad = quadVariant({}, {{"motor3]", "motor9]"}});
  const test::CmdResult run =
      test::runShell(std::string(TGNAV_BIN) + " fly --scene " + src("configs/scenes/smoke.yaml").string() +
                     " --trajectory " + src("configs/trajectories/smoke_around_pillar.csv").string() + " --vehicle " +
                     bad.string() + " --out " + (dir / "out").string());
  EXPECT_EQ(run.rc, 2) << run.output;
  EXPECT_EQ(run.output, "tgnav: error: " + (bad.parent_path() / "quadrotor.xml").string() +
                            ": no actuator 'motor9' (vehicle description " + bad.string() + ")\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace
}  // namespace tgnav::harness
