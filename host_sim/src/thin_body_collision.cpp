// The thin-body collision pipeline (BRIEF §3): broad phase → swept node detection → infeasible-
// pair exclusion → enforced displacement → Hunt-Crossley force. The model is built once; the
// data is preallocated; step() does not allocate.
#include <fissure/host_sim/thin_body_collision.hpp>

#include "thin_body/collision_state.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace fissure::host {

ThinBodyCollision::~ThinBodyCollision() = default;

namespace {

using Clock = std::chrono::steady_clock;
// A node counts as inside the tool beyond this depth (float noise of positions written at +skin;
// enforced_displacement.cpp's tolerance).
constexpr double kInsideTolerance_m = 1e-7;
double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

class ThinBodyCollisionImpl final : public ThinBodyCollision {
 public:
  ThinBodyCollisionImpl(const ToolNodes& tool, const btSoftBody& soft, const ThinBodyCollisionParams& params, bool paired,
                        SoftNodeBounds* node_bounds)
      : model_(thin_body::build_collision_model(tool, soft, params, paired)), soft_(&soft), node_bounds_(node_bounds) {
    thin_body::allocate_collision_data(model_, data_);
  }

  void step(const ToolPose& previous, const ToolPose& current, double dt_s, btSoftBody& soft,
            CollisionStepResult& out) override {
    if (&soft != soft_ || soft.m_nodes.size() != model_.soft.node_count || soft.m_faces.size() != model_.soft.face_count)
      throw std::invalid_argument("thin-body collision: step() got a different soft body than at construction");
    if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw std::invalid_argument("thin-body collision: dt_s must be > 0");
    const Clock::time_point t0 = Clock::now();
    ++data_.step;
    out.force_on_tool_world_n.setZero();
    out.contacts.clear();
    if (out.contacts.capacity() < static_cast<std::size_t>(model_.soft.face_count))
      out.reserve_for(model_.soft.face_count);  // first call only
    out.colliding_tool_nodes = 0;
    out.excluded_pairs = 0;
    out.both_face_contacts = 0;
    out.contacted_triangles = 0;
    out.displaced_soft_nodes = 0;
    out.guard_corrections = 0;
    out.seconds_narrow = out.seconds_response = out.seconds_force = 0.0;

    if (!had_contact_ && thin_body::broad_phase_out_of_reach(model_, previous, current, node_bounds_, data_)) {
      out.broad_phase_hit = false;
      out.seconds_broad = seconds_between(t0, Clock::now());
      return;
    }
    frame_ = thin_body::make_step_frame(model_, data_.step, previous, current, dt_s);
    out.broad_phase_hit = thin_body::broad_phase(model_, frame_, soft, data_, node_bounds_);
    const Clock::time_point t1 = Clock::now();
    out.seconds_broad = seconds_between(t0, t1);
    if (!out.broad_phase_hit) {
      // Out of contact: nothing else runs; the tool nodes' contact memory ends here.
      if (had_contact_) {
        std::fill(data_.node_face.begin(), data_.node_face.end(), -1);
        std::fill(data_.node_age.begin(), data_.node_age.end(), 0);
        had_contact_ = false;
      }
      return;
    }
    had_contact_ = true;
    thin_body::sweep_tool_nodes(model_, data_);
    out.both_face_contacts = thin_body::exclude_infeasible_pairs(model_, data_);
    out.excluded_pairs = static_cast<int>(data_.exclusion.size());
    out.colliding_tool_nodes = static_cast<int>(data_.contact_nodes.size()) - out.excluded_pairs;
    const Clock::time_point t2 = Clock::now();
    out.seconds_narrow = seconds_between(t1, t2);
    const thin_body::DisplacementCounts counts = thin_body::enforce_displacement(model_, frame_, soft, data_, node_bounds_);
    out.displaced_soft_nodes = counts.displaced;
    out.guard_corrections = counts.guard_corrections;
    const Clock::time_point t3 = Clock::now();
    out.seconds_response = seconds_between(t2, t3);
    thin_body::hunt_crossley_force(model_, frame_, soft, data_, out);
    out.contacted_triangles = static_cast<int>(data_.contacted_faces.size());
    out.seconds_force = seconds_between(t3, Clock::now());
  }

  void reset_rest_state(const btSoftBody& soft) override {
    if (&soft != soft_) throw std::invalid_argument("thin-body collision: reset_rest_state() got a different soft body");
    thin_body::take_rest_state(soft, model_.soft);
  }

  int reseat(const ToolPose& previous, const ToolPose& current, btSoftBody& soft) override {
    if (&soft != soft_) throw std::invalid_argument("thin-body collision: reseat() got a different soft body");
    // Every per-step memory back to how the constructor left it (assign() on vectors of the same
    // size: nothing is allocated). The step counter continues, so the stamps allocate does not
    // touch (the broad phase's own) stay older than every step to come, and every stamp it reset
    // (-1) is older than "last step": held nodes, tool-node contacts, ẋ filters all start afresh.
    const std::int64_t step = data_.step;
    thin_body::allocate_collision_data(model_, data_);
    data_.step = step;
    had_contact_ = false;
    return put_out_nodes_inside(previous, current, soft);
  }

  [[nodiscard]] SceneCollisionMethod method() const override {
    return model_.paired ? SceneCollisionMethod::kPaired : SceneCollisionMethod::kRay;
  }

 private:
  // reseat(): every free soft node inside the tool at `current` onto a face + skin (see the
  // interface for which face and why).
  int put_out_nodes_inside(const ToolPose& previous, const ToolPose& current, btSoftBody& soft) const {
    const Eigen::Matrix3d r_cur = current.orientation_world.toRotationMatrix();
    const Eigen::Matrix3d r_prev = previous.orientation_world.toRotationMatrix();
    const auto& planes = model_.tool.planes();
    const double skin_m = model_.params.skin_m;
    // A face further away than the tool is thick is not a way out of a thin tool: it is its rim
    // seen from the middle of a face (up to half the tool's width away).
    const double reach_m = model_.tool.thickness_m() + skin_m;
    int put_out = 0;
    for (int i = 0; i < soft.m_nodes.size(); ++i) {
      btSoftBody::Node& node = soft.m_nodes[i];
      if (node.m_im == 0) continue;  // fixed nodes are never moved (enforced_displacement.cpp)
      const Eigen::Vector3d x_world(node.m_x.x(), node.m_x.y(), node.m_x.z());
      Eigen::Vector3d p_cur = r_cur.transpose() * (x_world - current.position_world_m);
      double depth_m = -std::numeric_limits<double>::infinity();  // signed distance to the tool, < 0 inside
      int nearest = 0;
      for (std::size_t q = 0; q < planes.size(); ++q) {
        const double d = planes[q].normal_tool.dot(p_cur) - planes[q].offset_m;
        if (d > depth_m) {
          depth_m = d;
          nearest = static_cast<int>(q);
        }
      }
      if (depth_m >= -kInsideTolerance_m) continue;
      const Eigen::Vector3d p_prev = r_prev.transpose() * (x_world - previous.position_world_m);
      int exit = nearest;
      double best_in_front_m = -std::numeric_limits<double>::infinity();
      for (std::size_t q = 0; q < planes.size(); ++q) {
        if (planes[q].offset_m - planes[q].normal_tool.dot(p_cur) > reach_m) continue;
        const double in_front_m = planes[q].normal_tool.dot(p_prev) - planes[q].offset_m;
        if (in_front_m > best_in_front_m) {
          best_in_front_m = in_front_m;
          exit = static_cast<int>(q);
        }
      }
      const ToolPlane& plane = planes[static_cast<std::size_t>(exit)];
      p_cur += (plane.offset_m + skin_m - plane.normal_tool.dot(p_cur)) * plane.normal_tool;
      const Eigen::Vector3d out_world = r_cur * p_cur + current.position_world_m;
      node.m_x.setValue(static_cast<btScalar>(out_world.x()), static_cast<btScalar>(out_world.y()),
                        static_cast<btScalar>(out_world.z()));
      if (node_bounds_ != nullptr) node_bounds_->extend(i, node.m_x);
      ++put_out;
    }
    return put_out;
  }

  thin_body::CollisionModel model_;
  thin_body::CollisionData data_;
  thin_body::StepFrame frame_;
  const btSoftBody* soft_;
  SoftNodeBounds* node_bounds_;  // the solver's node bounds (null: the broad phase reads every node)
  bool had_contact_ = false;
};

}  // namespace

std::unique_ptr<ThinBodyCollision> make_paired_collision(const ToolNodes& tool, const btSoftBody& soft,
                                                         const ThinBodyCollisionParams& params, SoftNodeBounds* node_bounds) {
  return std::make_unique<ThinBodyCollisionImpl>(tool, soft, params, true, node_bounds);
}

std::unique_ptr<ThinBodyCollision> make_ray_collision(const ToolNodes& tool, const btSoftBody& soft,
                                                      const ThinBodyCollisionParams& params, SoftNodeBounds* node_bounds) {
  return std::make_unique<ThinBodyCollisionImpl>(tool, soft, params, false, node_bounds);
}

}  // namespace fissure::host
