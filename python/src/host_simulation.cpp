// fissure.HostSimulation: one scene's host side (host::HostSimulation — Bullet soft body, the
// thin-body collision per tool part, the method-independent metrics) and fissure.StepResult.
//
// Copies, stated: step() copies the step's result once (a few scalars and the contact list:
// O(contacts)) into a StepResult, whose array properties are built when read. node_positions(),
// rest_positions() and faces() return fresh arrays (one copy of N×3 doubles); node_positions_view()
// returns a read-only array over the simulation's own buffer (no copy) that the next step()
// overwrites in place.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <BulletSoftBody/btSoftBody.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "fissure/host_sim/contact_metrics.hpp"
#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/soft_world.hpp"

namespace py = pybind11;

namespace fissure::python {
namespace {

using host::HostSimulation;
using host::HostStepResult;
using host::SceneDescription;

/// One step's outcome as Python sees it: the C++ result (copied once) and the optional cut count.
struct StepResult {
  HostStepResult result;
  int cut_triangles = -1;
  std::vector<int> first_face;  ///< where each soft body's triangles start in faces(): contacts' soft_face is made global
};

/// The scene with its contact response overridden, refused as the loader refuses a file that
/// asks for friction without the in-solver response (friction is solved only there).
SceneDescription with_contact_response(const SceneDescription& scene, const std::optional<std::string>& name) {
  SceneDescription out = scene;
  if (!name) return out;
  out.simulation.contact_response = parse_contact_response(*name);
  if (out.tool.friction_static_ratio > 0.0 && out.simulation.contact_response != host::ContactResponse::kInSolver) {
    throw std::invalid_argument("scene '" + scene.name + "' has tool friction (static " + std::to_string(scene.tool.friction_static_ratio) +
                                "), which is solved inside the soft-body solver: contact_response must be 'in_solver', not '" + *name + "'");
  }
  return out;
}

class PyHostSimulation {
 public:
  PyHostSimulation(const SceneDescription& scene, const std::optional<std::string>& method, bool solver_node_bounds,
                   const std::optional<std::string>& contact_response) {
    std::optional<host::SceneCollisionMethod> parsed;
    if (method) parsed = parse_method(*method);
    host::HostSimulationOptions options;
    options.solver_node_bounds = solver_node_bounds;
    sim_ = std::make_unique<HostSimulation>(with_contact_response(scene, contact_response), parsed, options);
    faces_.reserve(sim_->soft_faces().size() * 3);
    for (const std::array<int, 3>& face : sim_->soft_faces()) {
      for (int v : face) faces_.push_back(static_cast<std::int32_t>(v));
    }
    rest_ = sim_->node_positions_world_m();
    const bool clamp = scene.tool.kind == host::ToolKind::kClamp;
    jaw_gap_m_ = !clamp ? 0.0 : (scene.trajectory.start_jaw_gap_m >= 0.0 ? scene.trajectory.start_jaw_gap_m : scene.tool.clamp.jaw_gap_open_m);
  }

  HostSimulation& sim() { return *sim_; }
  const HostSimulation& sim() const { return *sim_; }
  double jaw_gap_m() const { return jaw_gap_m_; }

  void settle(double seconds) {
    {
      py::gil_scoped_release release;
      sim_->settle(seconds);
    }
    rest_ = sim_->node_positions_world_m();
  }

  StepResult step(const py::handle& pose, const std::optional<double>& jaw_gap_m, bool count_cut_triangles, double cut_depth_tolerance_m) {
    const host::ToolPose target = tool_pose_from(pose, sim_->tool_pose());
    StepResult out{sim_->step(target, jaw_gap_m.value_or(jaw_gap_m_)), -1, {}};
    for (int b = 0; b < sim_->soft_body_count(); ++b) out.first_face.push_back(sim_->first_face(b));
    jaw_gap_m_ = out.result.jaw_gap_m;
    if (count_cut_triangles) out.cut_triangles = sim_->triangles_cut_by_tool(cut_depth_tolerance_m);
    return out;
  }

  int reseat_tool(const py::handle& pose, const std::optional<double>& jaw_gap_m) {
    const host::ToolPose target = tool_pose_from(pose, sim_->tool_pose());
    const int moved = sim_->reseat_tool(target, jaw_gap_m.value_or(jaw_gap_m_));
    if (sim_->scene().tool.kind == host::ToolKind::kClamp) {
      const host::ClampDescription& c = sim_->scene().tool.clamp;
      jaw_gap_m_ = std::clamp(jaw_gap_m.value_or(jaw_gap_m_), c.jaw_gap_min_m, c.jaw_gap_open_m);
    }
    return moved;
  }

  py::array_t<std::int32_t> faces() const {
    return to_array(std::vector<std::int32_t>(faces_), {static_cast<py::ssize_t>(faces_.size() / 3), 3});
  }
  const std::vector<Eigen::Vector3d>& rest() const { return rest_; }

 private:
  std::unique_ptr<HostSimulation> sim_;
  std::vector<std::int32_t> faces_;       // node indices, 3 per soft face (fixed topology)
  std::vector<Eigen::Vector3d> rest_;     // as built, then the settled shape (the Hunt-Crossley rest state)
  double jaw_gap_m_ = 0.0;                // the gap step() keeps when given none
};

/// (P, 3) float64: one vector per tool part, `vector_of(r, part)`.
template <typename VectorOf>
py::array_t<double> per_part(const HostStepResult& r, VectorOf vector_of) {
  std::vector<double> out;
  for (int p = 0; p < r.part_count; ++p) {
    const Eigen::Vector3d v = vector_of(r, static_cast<std::size_t>(p));
    out.insert(out.end(), {v.x(), v.y(), v.z()});
  }
  return to_array(std::move(out), {r.part_count, 3});
}

py::dict contacts_dict(const StepResult& s) {
  const HostStepResult& r = s.result;
  const auto n = static_cast<std::size_t>(r.contact_count);
  std::vector<std::int32_t> face(n), body(n), node(n), plane(n), jaw(n);
  std::vector<double> point(3 * n), normal(3 * n), penetration(n), rate(n), weight(n), force(n);
  for (std::size_t i = 0; i < n; ++i) {
    const host::ContactRecord& c = r.contacts[i];
    // Into faces(), which holds every body's triangles.
    face[i] = s.first_face[static_cast<std::size_t>(c.soft_body)] + c.soft_face;
    body[i] = c.soft_body;
    node[i] = c.tool_node;
    plane[i] = c.tool_plane;
    jaw[i] = c.jaw;
    for (int k = 0; k < 3; ++k) {
      point[3 * i + static_cast<std::size_t>(k)] = c.point_world_m[k];
      normal[3 * i + static_cast<std::size_t>(k)] = c.normal_world[k];
    }
    penetration[i] = c.penetration_m;
    rate[i] = c.penetration_rate_m_s;
    weight[i] = c.weight;
    force[i] = c.force_n;
  }
  const auto rows = static_cast<py::ssize_t>(n);
  py::dict d;
  d["soft_face"] = to_array(std::move(face));
  d["soft_body"] = to_array(std::move(body));
  d["tool_node"] = to_array(std::move(node));
  d["tool_plane"] = to_array(std::move(plane));
  d["jaw"] = to_array(std::move(jaw));
  d["point_world_m"] = to_array(std::move(point), {rows, 3});
  d["normal_world"] = to_array(std::move(normal), {rows, 3});
  d["penetration_m"] = to_array(std::move(penetration));
  d["penetration_rate_m_s"] = to_array(std::move(rate));
  d["weight"] = to_array(std::move(weight));
  d["force_n"] = to_array(std::move(force));
  return d;
}

py::dict part_report(const host::CollisionStepResult& r) {
  py::dict d;
  d["force_on_tool_world_n"] = Eigen::Vector3d(r.force_on_tool_world_n);
  d["colliding_tool_nodes"] = r.colliding_tool_nodes;
  d["excluded_pairs"] = r.excluded_pairs;
  d["both_face_contacts"] = r.both_face_contacts;
  d["contacted_triangles"] = r.contacted_triangles;
  d["displaced_soft_nodes"] = r.displaced_soft_nodes;
  d["guard_corrections"] = r.guard_corrections;
  d["broad_phase_hit"] = r.broad_phase_hit;
  d["seconds_broad"] = r.seconds_broad;
  d["seconds_narrow"] = r.seconds_narrow;
  d["seconds_response"] = r.seconds_response;
  d["seconds_force"] = r.seconds_force;
  return d;
}

}  // namespace

void bind_host(py::module_& m) {
  m.attr("INSIDE_TOLERANCE_M") = host::kInsideToleranceM;

  py::class_<StepResult>(m, "StepResult",
                         "What one HostSimulation.step() produced (a copy; later steps do not change it).\n"
                         "Forces are the soft body's force ON THE TOOL [N, world frame] at the step's last sub-step;\n"
                         "the crossing metrics are the step's worst sub-step, summed over tool parts (jaws).")
      .def_property_readonly("time_s", [](const StepResult& s) { return s.result.time_s; }, "simulated time at the end of the step [s]")
      .def_property_readonly("force", [](const StepResult& s) { return Eigen::Vector3d(s.result.force_on_tool_world_n); },
                             "(3,) float64: total force on the tool [N, world], summed over parts")
      .def_property_readonly(
          "part_forces",
          [](const StepResult& s) { return per_part(s.result, [](const HostStepResult& r, std::size_t p) { return r.part_force_world_n[p]; }); },
          "(P, 3) float64: force on each tool part [N, world]; P = 1 (spatula) or 2 (clamp: jaw A at +y, jaw B at −y)")
      .def_property_readonly(
          "friction_force",
          [](const StepResult& s) {
            Eigen::Vector3d total = Eigen::Vector3d::Zero();
            for (int p = 0; p < s.result.part_count; ++p) total += s.result.part_results[static_cast<std::size_t>(p)].friction_force_on_tool_world_n;
            return total;
          },
          "(3,) float64: the friction part of `force` [N, world] (0 without tool friction)")
      .def_property_readonly(
          "part_friction_forces",
          [](const StepResult& s) {
            return per_part(s.result, [](const HostStepResult& r, std::size_t p) { return r.part_results[p].friction_force_on_tool_world_n; });
          },
          "(P, 3) float64: the friction part of each part's force [N, world] (clamp: jaw A at +y, jaw B at −y)")
      .def_property_readonly("part_count", [](const StepResult& s) { return s.result.part_count; })
      .def_property_readonly("contact_count", [](const StepResult& s) { return s.result.contact_count; })
      .def_property_readonly("contacts", [](const StepResult& s) { return contacts_dict(s); },
                             "Contacted soft triangles (C of them), a dict of arrays: soft_face (C,) int32 (a row of faces()),\n"
                             "soft_body (C,) int32 (which of the scene's soft bodies), tool_node (C,)\n"
                             "int32 (-1: none), tool_plane (C,) int32, jaw (C,) int32, point_world_m (C, 3) [m] (triangle\n"
                             "centroid after the response), normal_world (C, 3) (tool face outward normal), penetration_m (C,)\n"
                             "[m] (Hunt-Crossley deformation x), penetration_rate_m_s (C,) [m/s], weight (C,) (contacted rest\n"
                             "area [m²] in per-unit-area mode), force_n (C,) [N] (the triangle's HC force magnitude).")
      .def_property_readonly("crossed_nodes", [](const StepResult& s) { return s.result.crossing.crossed_nodes; },
                             "soft nodes that went through the tool (wrong side ∪ through ∪ inside; target 0)")
      .def_property_readonly("wrong_side_nodes", [](const StepResult& s) { return s.result.crossing.wrong_side_nodes; })
      .def_property_readonly("inside_nodes", [](const StepResult& s) { return s.result.crossing.inside_nodes; })
      .def_property_readonly("through_nodes", [](const StepResult& s) { return s.result.crossing.through_nodes; })
      .def_property_readonly("rim_passes", [](const StepResult& s) { return s.result.crossing.rim_passes; })
      .def_property_readonly("endpoint_crossed_nodes", [](const StepResult& s) { return s.result.crossing.endpoint_crossed_nodes; })
      .def_property_readonly("penetration_m", [](const StepResult& s) { return s.result.crossing.max_penetration_m; },
                             "deepest soft node inside the tool volume [m] (max over nodes and parts)")
      .def_readonly("cut_triangles", &StepResult::cut_triangles,
                    "soft triangles reaching deeper than the tolerance into the tool after the step\n"
                    "(step(..., count_cut_triangles=True)); -1 when not counted")
      .def_property_readonly("jaw_gap_m", [](const StepResult& s) { return s.result.jaw_gap_m; }, "clamp: the gap applied [m]")
      .def_property_readonly(
          "times",
          [](const StepResult& s) {
            py::dict d;
            d["bullet_s"] = s.result.times.bullet_s;
            d["collision_s"] = s.result.times.collision_s;
            d["metrics_s"] = s.result.times.metrics_s;
            d["total_s"] = s.result.times.total_s;
            return d;
          },
          "wall-clock time of the step by stage [s]: bullet_s, collision_s, metrics_s, total_s (total without metrics)")
      .def_property_readonly(
          "part_reports",
          [](const StepResult& s) {
            py::list parts;
            for (int p = 0; p < s.result.part_count; ++p) parts.append(part_report(s.result.part_results[static_cast<std::size_t>(p)]));
            return parts;
          },
          "the collision method's own report per part (colliding tool nodes, excluded pairs, stage seconds, ...)")
      .def("__repr__", [](const StepResult& s) {
        const Eigen::Vector3d& f = s.result.force_on_tool_world_n;
        return "StepResult(t=" + std::to_string(s.result.time_s) + " s, force=[" + std::to_string(f.x()) + ", " + std::to_string(f.y()) +
               ", " + std::to_string(f.z()) + "] N, contacts=" + std::to_string(s.result.contact_count) +
               ", crossed=" + std::to_string(s.result.crossing.crossed_nodes) + ")";
      });

  py::class_<PyHostSimulation>(m, "HostSimulation",
                               "One scene's host side: the Bullet soft body and ground, the tool (a spatula, or a clamp's two\n"
                               "jaws), the thin-body collision ('paired', 'ray') or Bullet's own ('bullet'), and the\n"
                               "method-independent metrics (crossed nodes, penetration). Simulated time only: nothing waits.\n\n"
                               "Units: SI (m, s, N); frames: world = Bullet's (y up), tool = the tool's own (thin axis y).\n"
                               "Typical use:\n"
                               "    sim = fissure.HostSimulation(fissure.Scene.load('spatula-sphere'))\n"
                               "    sim.settle(1.0)\n"
                               "    for i in range(500):               # down at 5 cm/s: 0.05 mm per 1 ms step\n"
                               "        r = sim.step([0.0, 0.12 - 0.05e-3 * i, 0.0])   # tool target [m, world]\n"
                               "    print(r.force, r.crossed_nodes)    # force on the tool [N, world]; 0")
      .def(py::init<const SceneDescription&, const std::optional<std::string>&, bool, const std::optional<std::string>&>(), py::arg("scene"),
           py::arg("method") = py::none(), py::arg("solver_node_bounds") = true, py::arg("contact_response") = py::none(),
           "method: 'paired', 'ray' or 'bullet' (None: the scene's). solver_node_bounds=False: Bullet's stock soft\n"
           "solver (the same simulation bit for bit; the broad phase then reads every node). contact_response:\n"
           "'after_step' or 'in_solver' (None: the scene's [simulation] contact_response); a scene with tool friction\n"
           "needs 'in_solver' (ValueError otherwise).")
      .def("settle", &PyHostSimulation::settle, py::arg("seconds"),
           "Lets the soft body settle under gravity with the tool at the trajectory start, takes the settled shape\n"
           "as the Hunt-Crossley rest state (rest_positions()) and restarts the clock at 0. Call once before contact.")
      .def("step", &PyHostSimulation::step, py::arg("tool_pose"), py::arg("jaw_gap") = py::none(), py::arg("count_cut_triangles") = false,
           py::arg("cut_depth_tolerance_m") = host::kInsideToleranceM,
           "One host step (scene.time_step_s) moving the tool to tool_pose: a ToolPose, a position [x, y, z]\n"
           "(m, world; the current orientation is kept) or [x, y, z, qw, qx, qy, qz]. The tool sweeps from its pose\n"
           "to the target (no tunnelling at any speed). jaw_gap [m]: clamp scenes only (None keeps the current gap;\n"
           "clamped to the scene's range). count_cut_triangles: also count soft triangles cut by the tool's interior\n"
           "(a diagnostic; costs faces × planes² work). Returns a StepResult.")
      .def("reseat_tool", &PyHostSimulation::reseat_tool, py::arg("tool_pose"), py::arg("jaw_gap") = py::none(),
           "Places the tool at tool_pose without sweeping through the space between (no time passes); soft nodes\n"
           "inside the tool at the new pose are put out onto a face. Returns how many were.")
      .def(
          "scripted_target",
          [](const PyHostSimulation& s) {
            const host::TrajectorySample t = s.sim().scripted_target();
            return py::make_tuple(host::to_tool_pose(t.pose), t.jaw_gap_m);
          },
          "(ToolPose, jaw_gap_m) of the scene's scripted trajectory at the current time.")
      .def_property_readonly("scene", [](const PyHostSimulation& s) { return s.sim().scene(); }, "the Scene (a copy)")
      .def_property_readonly("method", [](const PyHostSimulation& s) { return std::string(host::to_string(s.sim().method())); })
      .def_property_readonly("contact_response",
                             [](const PyHostSimulation& s) { return std::string(host::to_string(s.sim().scene().simulation.contact_response)); },
                             "'after_step' or 'in_solver': where the thin-body response acts (paired / ray)")
      .def_property_readonly("time_s", [](const PyHostSimulation& s) { return s.sim().time_s(); }, "simulated time [s]")
      .def_property_readonly("tool_pose", [](const PyHostSimulation& s) { return s.sim().tool_pose(); }, "the tool's current ToolPose")
      .def_property_readonly("jaw_gap_m", &PyHostSimulation::jaw_gap_m, "clamp: the jaw gap step() keeps when given none [m]; 0 otherwise")
      .def_property_readonly("part_count", [](PyHostSimulation& s) { return s.sim().world().part_count(); },
                             "collidable tool parts: 1, or 2 for a clamp")
      .def_property_readonly("soft_node_count", [](const PyHostSimulation& s) { return s.sim().soft_node_count(); })
      .def_property_readonly("soft_face_count", [](const PyHostSimulation& s) { return s.sim().soft_face_count(); })
      .def_property_readonly("soft_body_count", [](const PyHostSimulation& s) { return s.sim().soft_body_count(); },
                             "soft bodies in the scene ([[soft_body]]); node and face arrays hold them body after body")
      .def(
          "soft_body_nodes",
          [](const PyHostSimulation& s, int body) {
            if (body < 0 || body >= s.sim().soft_body_count())
              throw py::index_error("soft body " + std::to_string(body) + " of " + std::to_string(s.sim().soft_body_count()));
            return py::slice(s.sim().first_node(body), s.sim().first_node(body + 1), 1);
          },
          py::arg("body"), "slice of node_positions() rows that are soft body `body`'s nodes")
      .def_property_readonly("last",
                             [](const PyHostSimulation& s) {
                               StepResult out{s.sim().last(), -1, {}};
                               for (int b = 0; b < s.sim().soft_body_count(); ++b) out.first_face.push_back(s.sim().first_face(b));
                               return out;
                             },
                             "the last step's StepResult (zeros before the first)")
      .def(
          "node_positions", [](const PyHostSimulation& s) { return to_array(s.sim().node_positions_world_m()); },
          "(N, 3) float64: soft node positions [m, world] as of the last step/settle (a copy).")
      .def(
          "node_positions_view",
          [](py::object self) {
            const std::vector<Eigen::Vector3d>& nodes = self.cast<const PyHostSimulation&>().sim().node_positions_world_m();
            py::array_t<double> view({static_cast<py::ssize_t>(nodes.size()), py::ssize_t{3}},
                                     {static_cast<py::ssize_t>(sizeof(Eigen::Vector3d)), static_cast<py::ssize_t>(sizeof(double))},
                                     nodes.empty() ? nullptr : nodes.front().data(), self);
            py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
            return view;
          },
          "(N, 3) float64, read-only, NO copy: a view of the simulation's node buffer [m, world]. The next step()\n"
          "overwrites it in place (copy it to keep a frame); it keeps the simulation alive.")
      .def(
          "rest_positions", [](const PyHostSimulation& s) { return to_array(s.rest()); },
          "(N, 3) float64: the soft body's rest shape [m, world] — as built, and after settle() the settled shape\n"
          "(the Hunt-Crossley rest state). A copy.")
      .def("faces", &PyHostSimulation::faces, "(F, 3) int32: node indices (rows of node_positions()) of every soft body's triangles, body after body (fixed topology). A copy.")
      .def(
          "soft_bounds",
          [](const PyHostSimulation& s) {
            const Eigen::AlignedBox3d b = s.sim().soft_bounds_world_m();
            Eigen::Matrix<double, 2, 3, Eigen::RowMajor> out;
            out.row(0) = b.min().transpose();
            out.row(1) = b.max().transpose();
            return out;
          },
          "(2, 3) float64: [min, max] corners of the soft nodes' bounding box [m, world]")
      .def(
          "triangles_cut_by_tool", [](const PyHostSimulation& s, double tolerance) { return s.sim().triangles_cut_by_tool(tolerance); },
          py::arg("depth_tolerance_m") = host::kInsideToleranceM,
          "Soft triangles reaching deeper than depth_tolerance_m [m] into the tool now (summed over parts).")
      .def(
          "tool_nodes",
          [](PyHostSimulation& s, int part) -> py::object {
            if (part < 0 || part >= s.sim().world().part_count()) throw py::index_error("tool part " + std::to_string(part) + " does not exist");
            const host::ToolNodes* nodes = s.sim().tool_nodes(part);
            if (nodes == nullptr) return py::none();
            std::array<host::ToolPose, host::kMaxToolParts> poses{};
            host::tool_part_poses(s.sim().scene(), s.sim().tool_pose(), s.jaw_gap_m(), poses);
            std::vector<Eigen::Vector3d> world;
            world.reserve(nodes->positions_tool_m().size());
            for (const Eigen::Vector3d& p : nodes->positions_tool_m()) world.push_back(poses[static_cast<std::size_t>(part)].to_world(p));
            std::vector<std::int32_t> edge(nodes->edge_node_flags().begin(), nodes->edge_node_flags().end());
            py::dict d;
            d["positions_tool_m"] = to_array(nodes->positions_tool_m());
            d["normals_tool"] = to_array(nodes->normals_tool());
            d["positions_world_m"] = to_array(world);
            d["pair_of"] = to_array(std::vector<int>(nodes->pair_of()));
            d["plane_of_node"] = to_array(std::vector<int>(nodes->plane_of_node()));
            d["edge_node"] = to_array(std::move(edge));
            d["part_pose"] = poses[static_cast<std::size_t>(part)];
            d["thickness_m"] = nodes->thickness_m();
            d["thin_axis"] = nodes->thin_axis();
            d["is_thin"] = nodes->is_thin();
            return d;
          },
          py::arg("part") = 0,
          "The collision model of tool part `part` (None for the bullet method): positions_tool_m (M, 3) [m, part\n"
          "frame], normals_tool (M, 3), positions_world_m (M, 3) [m, world, at the current pose], pair_of (M,)\n"
          "(-1: unpaired), plane_of_node (M,), edge_node (M,) (1: a rim node), part_pose, thickness_m, thin_axis, is_thin.");
}

}  // namespace fissure::python
