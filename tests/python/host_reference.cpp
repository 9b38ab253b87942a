// The C++ side of tests/python/test_same_numbers.py: runs the library directly and prints every
// figure the Python test compares as a hexadecimal float (%a: exact, so the comparison is bit for
// bit). Two modes:
//   host_reference host SCENE METHOD SETTLE_S STEPS   the scripted trajectory, one line per step,
//                                                      then the soft nodes and the rest shape
//   host_reference kinematics                          ik / jacobian / fk on a fixed point grid
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include <Eigen/Core>

#include "fissure/falcon_hw/falcon_geometry.hpp"
#include "fissure/falcon_hw/kinematics.hpp"
#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_world.hpp"

namespace {

void print_vector(const char* tag, const Eigen::Vector3d& v) { std::printf("%s %a %a %a\n", tag, v.x(), v.y(), v.z()); }

int run_host(const std::string& scene_name, const std::string& method_name, double settle_s, long steps) {
  using namespace fissure::host;
  const SceneDescription scene = load_scene(resolve_scene_path(scene_name));
  const auto method = parse_collision_method(method_name);
  if (!method) {
    std::fprintf(stderr, "host_reference: method '%s'\n", method_name.c_str());
    return 2;
  }
  HostSimulation sim(scene, *method);
  sim.settle(settle_s);
  for (long i = 0; i < steps; ++i) {
    const TrajectorySample target = sim.scripted_target();
    const HostStepResult& r = sim.step(to_tool_pose(target.pose), target.jaw_gap_m);
    std::printf("step %ld %a %d %d %a\n", i, r.time_s, r.contact_count, r.crossing.crossed_nodes, r.crossing.max_penetration_m);
    print_vector("force", r.force_on_tool_world_n);
    for (int p = 0; p < r.part_count; ++p) {
      print_vector("part", r.part_force_world_n[static_cast<std::size_t>(p)]);
      print_vector("friction", r.part_results[static_cast<std::size_t>(p)].friction_force_on_tool_world_n);
    }
  }
  for (const Eigen::Vector3d& p : sim.node_positions_world_m()) print_vector("node", p);
  return 0;
}

int run_kinematics() {
  const fissure::falcon::FalconGeometry geometry{};
  Eigen::Vector3d fk_p(0.0, 0.0, 0.125);
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) {
      const Eigen::Vector3d p(0.01 * i, 0.01 * j, 0.125 + 0.005 * (i + j));
      Eigen::Vector3d theta;
      Eigen::Matrix3d jac;
      if (!fissure::falcon::inverse_kinematics(geometry, p, theta) || !fissure::falcon::jacobian(geometry, p, jac)) return 1;
      print_vector("ik", theta);
      for (int r = 0; r < 3; ++r) print_vector("jac", jac.row(r).transpose());
      const fissure::falcon::FkResult fk = fissure::falcon::forward_kinematics(geometry, theta, fk_p, fissure::falcon::FkOptions{});
      if (!fk.converged) return 1;
      print_vector("fk", fk_p);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "host" && argc == 6) return run_host(argv[2], argv[3], std::atof(argv[4]), std::atol(argv[5]));
    if (mode == "kinematics" && argc == 2) return run_kinematics();
    std::fprintf(stderr, "usage: host_reference host SCENE METHOD SETTLE_S STEPS | host_reference kinematics\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "host_reference: %s\n", e.what());
    return 1;
  }
}
