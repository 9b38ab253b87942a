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
using thin_body::kInsideTolerance_m;
// Rim and node projections alternate this many times after each of Bullet's position iterations:
// each undoes a little of the other (a rim move can push a held node into a face, a node move can
// let a triangle sag back over the rim), and alternating projections converge on what both allow.
constexpr int kProjectionPasses = 2;
double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// What the detection stages (1–4: broad phase, node sweep, pair exclusion, placement) found in a
// step, kept from the solve to the step() that reports it (in-solver response).
struct DetectionReport {
  bool broad_phase_hit = false;
  int colliding_tool_nodes = 0;
  int excluded_pairs = 0;
  int both_face_contacts = 0;
  int displaced_soft_nodes = 0;
  int guard_corrections = 0;
  double seconds_broad = 0.0;
  double seconds_narrow = 0.0;
  double seconds_response = 0.0;
};

class ThinBodyCollisionImpl final : public ThinBodyCollision, public SoftContactConstraint {
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
    out.force_on_tool_world_n.setZero();
    out.friction_force_on_tool_world_n.setZero();
    out.sticking_nodes = 0;
    out.sliding_nodes = 0;
    out.contacts.clear();
    if (out.contacts.capacity() < static_cast<std::size_t>(model_.soft.face_count))
      out.reserve_for(model_.soft.face_count);  // first call only
    if (in_solver()) {
      if (!solved_)
        throw std::logic_error("thin-body collision (in_solver): step() without a solve of the prepared step — call prepare_step(), "
                               "then step the world whose NodeBoundsSolver holds solver_contact()");
      solved_ = false;
    } else {
      detect_and_place(previous, current, dt_s, soft);
    }
    out.colliding_tool_nodes = report_.colliding_tool_nodes;
    out.excluded_pairs = report_.excluded_pairs;
    out.both_face_contacts = report_.both_face_contacts;
    out.displaced_soft_nodes = report_.displaced_soft_nodes;
    out.guard_corrections = report_.guard_corrections;
    out.broad_phase_hit = report_.broad_phase_hit;
    out.seconds_broad = report_.seconds_broad;
    out.seconds_narrow = report_.seconds_narrow;
    out.seconds_response = report_.seconds_response;
    out.seconds_force = 0.0;
    out.seconds_in_solver = in_solver() ? report_.seconds_broad + report_.seconds_narrow + report_.seconds_response : 0.0;
    out.contacted_triangles = 0;
    if (!report_.broad_phase_hit) return;
    const Clock::time_point t0 = Clock::now();
    if (in_solver()) {
      thin_body::take_solved_shares(model_, frame_, soft, data_);
    } else {
      thin_body::hold_near_nodes(model_, frame_, data_);
    }
    thin_body::collect_force_faces(model_, frame_, data_);
    const Clock::time_point t1 = Clock::now();
    out.seconds_response += seconds_between(t0, t1);
    thin_body::hunt_crossley_force(model_, frame_, soft, data_, out);
    if (in_solver()) thin_body::friction_force_on_tool(model_, frame_, soft, data_, out);
    out.contacted_triangles = static_cast<int>(data_.exclusion.contacted_faces.size());
    out.seconds_force = seconds_between(t1, Clock::now());
  }

  [[nodiscard]] SoftContactConstraint* solver_contact() noexcept override { return in_solver() ? this : nullptr; }

  void prepare_step(const ToolPose& previous, const ToolPose& current, double dt_s) override {
    if (!in_solver()) return;
    if (!(dt_s > 0.0) || !std::isfinite(dt_s)) throw std::invalid_argument("thin-body collision: dt_s must be > 0");
    pending_previous_ = previous;
    pending_current_ = current;
    pending_dt_s_ = dt_s;
    pending_ = true;
  }

  void begin_solve(btSoftBody& soft) override {
    if (!pending_ || &soft != soft_) return;  // a step nobody prepared: the body is solved without this contact
    pending_ = false;
    detect_and_place(pending_previous_, pending_current_, pending_dt_s_, soft);
    if (report_.broad_phase_hit) thin_body::start_iterates(model_, frame_, soft, data_);
    solved_ = true;
  }

  void project(btSoftBody& soft) override {
    if (!solved_ || !report_.broad_phase_hit || &soft != soft_) return;
    const Clock::time_point t0 = Clock::now();
    for (int pass = 0; pass < kProjectionPasses; ++pass) {
      report_.guard_corrections += thin_body::project_rim_contacts(model_, frame_, soft, data_);
      report_.guard_corrections += thin_body::project_contacts(model_, frame_, soft, data_);
    }
    report_.seconds_response += seconds_between(t0, Clock::now());
  }

  void end_solve(btSoftBody& soft) override {
    if (!solved_ || !report_.broad_phase_hit || &soft != soft_) return;
    const Clock::time_point t0 = Clock::now();
    report_.guard_corrections += thin_body::guard_swept_paths(model_, frame_, soft, data_, node_bounds_);
    thin_body::inelastic_rim_velocities(frame_, soft, data_);
    report_.seconds_response += seconds_between(t0, Clock::now());
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
    pending_ = false;
    solved_ = false;
    return put_out_nodes_inside(previous, current, soft);
  }

  [[nodiscard]] SceneCollisionMethod method() const override {
    return model_.paired ? SceneCollisionMethod::kPaired : SceneCollisionMethod::kRay;
  }

 private:
  [[nodiscard]] bool in_solver() const noexcept { return model_.params.response == ContactResponse::kInSolver; }

  // Stages 1–4 on the body's m_q (start of the step) and m_x (its end: after Bullet's step for
  // after_step, Bullet's prediction for in_solver): detection, and the contacted nodes placed.
  void detect_and_place(const ToolPose& previous, const ToolPose& current, double dt_s, btSoftBody& soft) {
    const Clock::time_point t0 = Clock::now();
    ++data_.step;
    report_ = DetectionReport{};
    if (!had_contact_ && thin_body::broad_phase_out_of_reach(model_, previous, current, node_bounds_, data_)) {
      report_.seconds_broad = seconds_between(t0, Clock::now());
      return;
    }
    frame_ = thin_body::make_step_frame(model_, data_.step, previous, current, dt_s);
    report_.broad_phase_hit = thin_body::broad_phase(model_, frame_, soft, data_, node_bounds_);
    const Clock::time_point t1 = Clock::now();
    report_.seconds_broad = seconds_between(t0, t1);
    if (!report_.broad_phase_hit) {
      // Out of contact: nothing else runs; the tool nodes' contact memory ends here.
      if (had_contact_) {
        std::fill(data_.sweep.node_face.begin(), data_.sweep.node_face.end(), -1);
        std::fill(data_.sweep.node_age.begin(), data_.sweep.node_age.end(), 0);
        had_contact_ = false;
      }
      return;
    }
    had_contact_ = true;
    thin_body::sweep_tool_nodes(model_, data_);
    report_.both_face_contacts = thin_body::exclude_infeasible_pairs(model_, data_);
    report_.excluded_pairs = static_cast<int>(data_.exclusion.vector.size());
    report_.colliding_tool_nodes = static_cast<int>(data_.sweep.contact_nodes.size()) - report_.excluded_pairs;
    const Clock::time_point t2 = Clock::now();
    report_.seconds_narrow = seconds_between(t1, t2);
    const thin_body::DisplacementCounts counts = thin_body::place_contact_nodes(model_, frame_, soft, data_, node_bounds_);
    report_.displaced_soft_nodes = counts.displaced;
    report_.guard_corrections = counts.guard_corrections;
    report_.seconds_response = seconds_between(t2, Clock::now());
  }

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
  DetectionReport report_;
  // In-solver: the step prepare_step() announced, not yet detected (pending_), and detected inside
  // the solve but not yet reported by step() (solved_).
  ToolPose pending_previous_, pending_current_;
  double pending_dt_s_ = 0.0;
  bool pending_ = false;
  bool solved_ = false;
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
