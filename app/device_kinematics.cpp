// `fissure device kinematics`: position ↔ arm angles ↔ encoder counts, printed as JSON so a
// user can compare a real device's readings with the model by hand.
//   --ik X Y Z    position (m, device frame) → θ1 (rad) and encoder counts
//   --fk E1 E2 E3 encoder counts → θ1 → position (cold-start FK from the workspace centre)
#include "device_kinematics.hpp"

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "fissure/falcon_hw/encoder_mapping.hpp"
#include "fissure/falcon_hw/falcon_geometry.hpp"
#include "fissure/falcon_hw/kinematics.hpp"

namespace fissure::app {
namespace {

std::string format_vector(const Eigen::Vector3d& v) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.6g, %.6g, %.6g)", v.x(), v.y(), v.z());
  return text;
}

nlohmann::json to_json(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

nlohmann::json describe(const falcon::FalconGeometry& geometry, const Eigen::Vector3d& p_device_m,
                        const Eigen::Vector3d& theta_rad, const std::array<std::int16_t, 3>& encoder) {
  nlohmann::json out;
  out["position_m"] = to_json(p_device_m);
  out["theta_rad"] = to_json(theta_rad);
  out["encoder"] = nlohmann::json::array({encoder[0], encoder[1], encoder[2]});
  out["in_workspace"] = falcon::in_workspace(geometry, p_device_m);
  return out;
}

std::string workspace_description() {
  char text[160];
  std::snprintf(text, sizeof text, "the ball of radius %.3g m around (%.3g, %.3g, %.3g) m, device frame",
                falcon::kWorkspaceRadius_m, falcon::kWorkspaceCentre_device_m[0], falcon::kWorkspaceCentre_device_m[1],
                falcon::kWorkspaceCentre_device_m[2]);
  return text;
}

void run_ik(const std::vector<double>& xyz) {
  const falcon::FalconGeometry geometry;
  const falcon::EncoderMapping mapping;
  const Eigen::Vector3d p{xyz[0], xyz[1], xyz[2]};
  Eigen::Vector3d theta;
  if (!falcon::in_workspace(geometry, p) || !falcon::inverse_kinematics(geometry, p, theta)) {
    throw CommandError("--ik position " + format_vector(p) + " m is outside the Falcon workspace (" +
                       workspace_description() + ")");
  }
  std::printf("%s\n", describe(geometry, p, theta, falcon::theta_to_encoders(mapping, theta)).dump().c_str());
}

void run_fk(const std::vector<int>& counts) {
  const falcon::FalconGeometry geometry;
  const falcon::EncoderMapping mapping;
  std::array<std::int16_t, 3> encoder{};
  for (int i = 0; i < 3; ++i) {
    if (counts[i] < -32768 || counts[i] > 32767) {
      throw CLI::ValidationError("--fk", "encoder count " + std::to_string(counts[i]) + " is not an int16");
    }
    encoder[i] = static_cast<std::int16_t>(counts[i]);
  }
  const Eigen::Vector3d theta = falcon::encoders_to_theta(mapping, encoder);
  Eigen::Vector3d p;
  const falcon::FkResult result = falcon::forward_kinematics_cold(geometry, theta, p, falcon::FkOptions{});
  if (!result.converged) {
    throw CommandError("--fk encoder counts (" + std::to_string(counts[0]) + ", " + std::to_string(counts[1]) + ", " +
                       std::to_string(counts[2]) + ") = arm angles " + format_vector(theta) +
                       " rad match no reachable position (forward kinematics did not converge)");
  }
  nlohmann::json out = describe(geometry, p, theta, encoder);
  out["fk_iterations"] = result.iterations;
  out["fk_residual_rad"] = result.residual_rad;
  std::printf("%s\n", out.dump().c_str());
}

}  // namespace

void register_device_kinematics(CommandTree& tree) {
  auto* command = tree.device.add_subcommand(
      "kinematics", "Falcon kinematics by hand: --ik X Y Z (m) or --fk E1 E2 E3 (encoder counts); prints JSON");
  struct Arguments {
    std::vector<double> ik_xyz;
    std::vector<int> fk_counts;
  };
  auto arguments = std::make_shared<Arguments>();  // outlives main's parse: owned by the callback
  auto* ik = command->add_option("--ik", arguments->ik_xyz, "end-effector position X Y Z in metres, device frame")
                 ->expected(3)
                 ->allow_extra_args(false);
  auto* fk = command->add_option("--fk", arguments->fk_counts, "encoder counts E1 E2 E3 (int16, after homing)")
                 ->expected(3)
                 ->allow_extra_args(false);
  ik->excludes(fk);
  command->callback([arguments, ik, fk] {
    if (ik->count() > 0) {
      run_ik(arguments->ik_xyz);
    } else if (fk->count() > 0) {
      run_fk(arguments->fk_counts);
    } else {
      throw CLI::ValidationError("kinematics", "give --ik X Y Z or --fk E1 E2 E3");
    }
  });
}

}  // namespace fissure::app
