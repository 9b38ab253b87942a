// fissure.Scene (a loaded, validated scene: host::SceneDescription, the const model of one
// simulation), fissure.ToolPose, and the plunge-and-hold cell of the tunnelling sweep
// (host/plunge_hold.hpp) that `fissure bench collision` runs.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include "bindings.hpp"
#include "conversions.hpp"
#include "fissure/host_sim/plunge_hold.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_world.hpp"
#include "fissure/session/scene_plausibility.hpp"
#include "fissure/session/session_runner.hpp"

namespace py = pybind11;

namespace fissure::python {
namespace {

using host::SceneDescription;

const char* tool_kind_name(host::ToolKind kind) {
  switch (kind) {
    case host::ToolKind::kBox: return "box";
    case host::ToolKind::kConvexMesh: return "convex_mesh";
    case host::ToolKind::kClamp: return "clamp";
  }
  return "?";
}

const char* soft_shape_name(const host::SoftBodyDescription& soft) {
  if (std::holds_alternative<host::SoftSphere>(soft.shape)) return "sphere";
  if (std::holds_alternative<host::SoftCylinder>(soft.shape)) return "cylinder";
  if (std::holds_alternative<host::SoftMesh>(soft.shape)) return "mesh";
  return "slab";
}

Eigen::Vector3d vec(const Vec3& v) { return {v[0], v[1], v[2]}; }

const host::PlungeTool& plunge_tool_named(const std::string& name) {
  for (const host::PlungeTool& tool : host::plunge_tools()) {
    if (tool.name == name) return tool;
  }
  std::string names;
  for (const host::PlungeTool& tool : host::plunge_tools()) names += (names.empty() ? "" : ", ") + std::string(tool.name);
  throw std::invalid_argument("no plunge tool '" + name + "' (tools: " + names + ")");
}

// The sweep's cell scene (host::plunge_cell_scene) for a response named as in scene files.
// soft_model "fem": the volumetric sweep ball (host::volumetric_plunge_scene).
SceneDescription plunge_cell_scene(const host::PlungeTool& tool, const std::string& contact_response, bool tool_friction, int icosphere_faces,
                                   const std::string& soft_model) {
  const std::optional<host::ContactResponse> response = host::parse_contact_response(contact_response);
  if (!response) throw std::invalid_argument("contact_response '" + contact_response + "' is not one of: after_step, in_solver");
  if (soft_model == "fem") return host::volumetric_plunge_scene(host::plunge_scene(tool, icosphere_faces), icosphere_faces, *response, tool_friction);
  if (soft_model != "shell") throw std::invalid_argument("soft_model '" + soft_model + "' is not one of: shell, fem");
  return host::plunge_cell_scene(tool, icosphere_faces, *response, tool_friction);
}

}  // namespace

host::ToolPose tool_pose_from(const py::handle& pose, const host::ToolPose& orientation_from) {
  if (py::isinstance<host::ToolPose>(pose)) return pose.cast<host::ToolPose>();
  const auto values = pose.cast<std::vector<double>>();
  host::ToolPose out = orientation_from;
  if (values.size() != 3 && values.size() != 7) {
    throw std::invalid_argument("a tool pose is a ToolPose, a position [x, y, z] (m, world; the orientation is kept) or "
                                "[x, y, z, qw, qx, qy, qz]; got " + std::to_string(values.size()) + " numbers");
  }
  out.position_world_m = {values[0], values[1], values[2]};
  if (values.size() == 7) out.orientation_world = Eigen::Quaterniond(values[3], values[4], values[5], values[6]).normalized();
  return out;
}

void bind_scene(py::module_& m) {
  py::class_<host::ToolPose>(m, "ToolPose",
                             "Pose of the tool frame in the world frame: p_world = R(orientation) · p_tool + position.\n"
                             "position: (3,) float64 [m, world]; orientation_wxyz: (4,) unit quaternion (w, x, y, z).\n"
                             "The tool's thin axis is its local y.")
      .def(py::init([](const Eigen::Vector3d& position, const Eigen::Vector4d& wxyz) {
             host::ToolPose pose;
             pose.position_world_m = position;
             pose.orientation_world = Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized();
             return pose;
           }),
           py::arg("position"), py::arg("orientation_wxyz") = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0))
      .def_property(
          "position", [](const host::ToolPose& p) { return Eigen::Vector3d(p.position_world_m); },
          [](host::ToolPose& p, const Eigen::Vector3d& v) { p.position_world_m = v; }, "(3,) float64: tool origin [m, world]")
      .def_property(
          "orientation_wxyz",
          [](const host::ToolPose& p) {
            const Eigen::Quaterniond& q = p.orientation_world;
            return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
          },
          [](host::ToolPose& p, const Eigen::Vector4d& q) { p.orientation_world = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized(); },
          "(4,) float64: orientation as a unit quaternion (w, x, y, z), tool → world")
      .def("rotation_matrix", [](const host::ToolPose& p) { return Eigen::Matrix3d(p.orientation_world.toRotationMatrix()); },
           "(3, 3) float64: R such that p_world = R @ p_tool + position")
      .def("to_world", &host::ToolPose::to_world, py::arg("p_tool"), "A point from the tool frame to the world frame [m].")
      .def("to_tool", &host::ToolPose::to_tool, py::arg("p_world"), "A point from the world frame to the tool frame [m].")
      .def("__repr__", [](const host::ToolPose& p) {
        const Eigen::Quaterniond& q = p.orientation_world;
        return "ToolPose(position=[" + std::to_string(p.position_world_m.x()) + ", " + std::to_string(p.position_world_m.y()) + ", " +
               std::to_string(p.position_world_m.z()) + "], orientation_wxyz=[" + std::to_string(q.w()) + ", " + std::to_string(q.x()) +
               ", " + std::to_string(q.y()) + ", " + std::to_string(q.z()) + "])";
      });

  py::class_<SceneDescription>(m, "Scene",
                               "A scene (docs/scenes.md): soft body, ground, tool, Hunt-Crossley law, device mapping,\n"
                               "hand script and scripted trajectory, loaded and validated. Immutable from Python: to vary\n"
                               "a parameter, edit the TOML text and use Scene.from_toml.\n"
                               "Errors: fissure.SceneError (ValueError) with .file, .line, .field.")
      .def_static(
          "load",
          [](const std::string& name_or_path, bool check_plausible) {
            const std::filesystem::path path = host::resolve_scene_path(name_or_path);
            SceneDescription scene = host::load_scene(path);
            if (check_plausible) session::require_plausible(scene);
            return scene;
          },
          py::arg("name_or_path"), py::arg("check_plausible") = true,
          "Loads a scene file, or a shipped scene by name ('spatula-sphere': scenes/NAME.toml; FISSURE_SCENES_DIR,\n"
          "./scenes, then the source tree's). check_plausible: also refuse values no Falcon bench has (a 50 m ball),\n"
          "as the command line does. Raises SceneError naming FILE, LINE and FIELD.")
      .def_static(
          "from_toml",
          [](const std::string& text, const std::string& label, const std::optional<std::string>& base_dir, bool check_plausible) {
            const std::filesystem::path base = base_dir ? std::filesystem::path(*base_dir) : std::filesystem::current_path();
            SceneDescription scene = host::load_scene_text(text, label, base);
            if (check_plausible) session::require_plausible(scene);
            return scene;
          },
          py::arg("text"), py::arg("label") = "<toml>", py::arg("base_dir") = py::none(), py::arg("check_plausible") = true,
          "Parses scene TOML text. label names the text in errors (SceneError.file); relative mesh paths resolve\n"
          "against base_dir (default: the working directory).")
      .def_readonly("name", &SceneDescription::name, "scene name (the file's stem)")
      .def_readonly("source_path", &SceneDescription::source_path, "the file it came from ('' for text)")
      .def_readonly("description", &SceneDescription::description)
      .def_property_readonly("time_step_s", [](const SceneDescription& s) { return s.simulation.time_step_s; }, "host step [s]")
      .def_property_readonly("substeps_count", [](const SceneDescription& s) { return s.simulation.substeps_count; },
                             "Bullet steps per host step")
      .def_property_readonly("gravity", [](const SceneDescription& s) { return vec(s.simulation.gravity_world_m_per_s2); },
                             "(3,) gravity [m/s², world]")
      .def_property_readonly("collision_method", [](const SceneDescription& s) { return std::string(host::to_string(s.simulation.collision_method)); },
                             "'paired', 'ray' or 'bullet'")
      .def_property_readonly("contact_response",
                             [](const SceneDescription& s) { return std::string(host::to_string(s.simulation.contact_response)); },
                             "'after_step' (the thin-body response after Bullet's step) or 'in_solver' (inside its position\n"
                             "iterations, with Bullet's links and anchors); paired / ray only")
      .def_property_readonly("friction_static_ratio", [](const SceneDescription& s) { return s.tool.friction_static_ratio; },
                             "tool–tissue Coulomb friction, static (0: frictionless; needs contact_response 'in_solver')")
      .def_property_readonly("friction_kinetic_ratio", [](const SceneDescription& s) { return s.tool.friction_kinetic_ratio; },
                             "tool–tissue Coulomb friction, kinetic (≤ the static ratio)")
      .def_property_readonly("friction_shear_damping_pa_s_per_m", [](const SceneDescription& s) { return s.tool.friction_shear_damping_pa_s_per_m; },
                             "viscous shear of the wet tool–tissue contact per unit contact area [Pa·s/m], acting on sliding contacts")
      .def_property_readonly("soft_model",
                             [](const SceneDescription& s) { return std::string(s.soft_bodies.front().model == host::SoftBodyModel::kFem ? "fem" : "shell"); },
                             "'shell' (Bullet's mass-spring soft body) or 'fem' (Bullet's deformable-world FEM, SI material)")
      .def_property_readonly("tool_kind", [](const SceneDescription& s) { return std::string(tool_kind_name(s.tool.kind)); },
                             "'box', 'convex_mesh' or 'clamp'")
      .def_property_readonly("tool_box_size_m", [](const SceneDescription& s) { return vec(s.tool.box_size_m); },
                             "(3,) box tool extents [m]: x width, y thickness (thin axis), z length")
      .def_property_readonly("soft_shape", [](const SceneDescription& s) { return std::string(soft_shape_name(s.soft_bodies.front())); },
                             "'sphere', 'cylinder', 'slab' or 'mesh'")
      .def_property_readonly(
          "hunt_crossley",
          [](const SceneDescription& s) {
            const host::HuntCrossleyParams& hc = s.hunt_crossley;
            py::dict d;
            d["k"] = hc.k;
            d["lambda"] = hc.lambda;
            d["n"] = hc.n;
            d["per_unit_area"] = hc.per_unit_area;
            d["measure"] = hc.measure == host::DeformationMeasure::kNormalDisplacement ? "normal_displacement" : "centroid_distance";
            return d;
          },
          "F = k·xⁿ + λ·xⁿ·ẋ per contacted triangle: {'k', 'lambda', 'n', 'per_unit_area', 'measure'}.\n"
          "per_unit_area: k in N/m^(n+2), λ in N·s/m^(n+3) (× the contacted rest area); else N/mⁿ, N·s/m^(n+1).")
      .def_property_readonly("trajectory_start", [](const SceneDescription& s) { return host::to_tool_pose(s.trajectory.start); },
                             "ToolPose at t = 0 of the scripted trajectory")
      .def_property_readonly("trajectory_duration_s", [](const SceneDescription& s) { return host::trajectory_duration_s(s); },
                             "length of the scripted trajectory (legs and holds) [s]")
      .def_property_readonly("hand_duration_s", [](const SceneDescription& s) { return session::hand_script_duration_s(s.hand); },
                             "length of the hand script SimFalcon plays in a session [s]")
      .def(
          "sample_trajectory",
          [](const SceneDescription& s, double t_s) {
            const host::TrajectorySample sample = host::sample_trajectory(s, t_s);
            return py::make_tuple(host::to_tool_pose(sample.pose), sample.jaw_gap_m);
          },
          py::arg("t_s"), "(ToolPose, jaw_gap_m) the scripted trajectory prescribes at time t_s [s].")
      .def("__repr__", [](const SceneDescription& s) {
        return "Scene('" + s.name + "', tool=" + tool_kind_name(s.tool.kind) + ", soft=" + soft_shape_name(s.soft_bodies.front()) +
               ", method=" + host::to_string(s.simulation.collision_method) + ")";
      });

  m.def(
      "plunge_tools",
      [] {
        py::list tools;
        for (const host::PlungeTool& tool : host::plunge_tools()) {
          py::dict d;
          d["name"] = std::string(tool.name);
          d["kind"] = tool_kind_name(tool.kind);
          d["box_size_m"] = vec(tool.box_size_m);
          d["orientation_rpy_deg"] = vec(tool.orientation_rpy_deg);
          d["leading_half_m"] = tool.leading_half_m;
          tools.append(d);
        }
        return tools;
      },
      "The tunnelling sweep's tools (issue 5; host/plunge_hold.hpp): a list of dicts with name, kind,\n"
      "box_size_m (3,) [m], orientation_rpy_deg (3,), leading_half_m (tool origin to its lowest point) [m].");
  m.def(
      "plunge_scene",
      [](const std::string& tool, const std::string& contact_response, bool tool_friction, int icosphere_faces, const std::string& soft_model) {
        return plunge_cell_scene(plunge_tool_named(tool), contact_response, tool_friction, icosphere_faces, soft_model);
      },
      py::arg("tool"), py::arg("contact_response") = "after_step", py::arg("tool_friction") = true, py::arg("icosphere_faces") = 0,
      py::arg("soft_model") = "shell",
      "spatula-sphere with the named plunge tool and the plunge ball's pose matching (the sweep's scene); contact_response\n"
      "'in_solver' gives the bench's in-solver cell (the ball's bed anchored; tool_friction: the plunge's Coulomb friction\n"
      "with the default viscous shear); icosphere_faces: an icosphere ball instead (1280: the sweep's fine ball);\n"
      "soft_model 'fem': the same surface filled with tetrahedra, an FEM body on the bed.");
  m.def(
      "run_plunge_hold",
      [](const std::string& tool_name, const std::string& method, double speed_m_s, double hold_s, bool count_cut_triangles,
         const std::string& contact_response, bool tool_friction, int icosphere_faces, const std::string& soft_model) {
        const host::PlungeTool& tool = plunge_tool_named(tool_name);
        const SceneDescription scene = plunge_cell_scene(tool, contact_response, tool_friction, icosphere_faces, soft_model);
        const host::SceneCollisionMethod parsed = parse_method(method);
        host::PlungeHoldResult r;
        {
          py::gil_scoped_release release;
          r = host::run_plunge_hold(scene, parsed, speed_m_s, tool.leading_half_m, hold_s, count_cut_triangles);
        }
        py::dict d;
        d["tool"] = tool_name;
        d["method"] = method;
        d["speed_m_s"] = speed_m_s;
        d["crossed_nodes"] = r.crossed_nodes;
        d["wrong_side_nodes"] = r.wrong_side_nodes;
        d["inside_nodes"] = r.inside_nodes;
        d["max_penetration_m"] = r.max_penetration_m;
        d["hold_force_n"] = to_array(r.hold_force_n);
        d["hold_contact_set_changes"] = r.hold_contact_set_changes;
        d["hold_max_cut_triangles"] = r.hold_max_cut_triangles;
        d["hold_steps_with_cut_triangles"] = r.hold_steps_with_cut_triangles;
        d["step_s"] = to_array(r.step_s);
        d["non_finite"] = r.non_finite;
        py::dict hold;
        hold["in_contact"] = r.hold.in_contact;
        hold["mean_n"] = r.hold.mean_n;
        hold["jitter"] = r.hold.jitter;
        hold["drift"] = r.hold.drift;
        hold["std_over_mean"] = r.hold.std_over_mean;
        hold["step_noise"] = r.hold.step_noise;
        d["hold"] = hold;
        return d;
      },
      py::arg("tool"), py::arg("method"), py::arg("speed_m_s"), py::arg("hold_s") = 0.5, py::arg("count_cut_triangles") = false,
      py::arg("contact_response") = "after_step", py::arg("tool_friction") = true, py::arg("icosphere_faces") = 0,
      py::arg("soft_model") = "shell",
      "One cell of the tunnelling sweep (the function `fissure bench collision` runs): settle the plunge ball,\n"
      "drive `tool` (a plunge_tools() name) 20 mm into it at speed_m_s [m/s] with `method` ('paired', 'ray',\n"
      "'bullet'), hold hold_s [s] after a 50 ms settling window. Lockstep: every figure but step_s is deterministic.\n"
      "Returns crossed/wrong-side/inside nodes (worst step), max_penetration_m [m], hold_force_n (|F| per hold\n"
      "step, (H,) [N]), step_s (wall time per step, (S,) [s]), the hold statistics (fractions of the mean force)\n"
      "and, with count_cut_triangles, the soft triangles cut by the tool during the hold (-1 otherwise).\n"
      "contact_response 'in_solver' runs the bench's in-solver cell (the ball's bed anchored; tool_friction: the\n"
      "plunge's Coulomb friction with the default viscous shear); icosphere_faces: an icosphere ball instead (1280: the sweep's fine ball);\n"
      "soft_model 'fem': the volumetric ball (plunge_scene).");
}

}  // namespace fissure::python
