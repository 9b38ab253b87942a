// The thin-body collision pipeline (BRIEF §3): broad phase → swept node detection → infeasible-
// pair exclusion → enforced displacement → Hunt-Crossley force. The model is built once; the
// data is preallocated; step() does not allocate.
#include <fissure/host_sim/thin_body_collision.hpp>

#include "thin_body/collision_state.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace fissure::host {

ThinBodyCollision::~ThinBodyCollision() = default;

namespace {

using Clock = std::chrono::steady_clock;
double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

class ThinBodyCollisionImpl final : public ThinBodyCollision {
 public:
  ThinBodyCollisionImpl(const ToolNodes& tool, const btSoftBody& soft, const ThinBodyCollisionParams& params, bool paired)
      : model_(thin_body::build_collision_model(tool, soft, params, paired)), soft_(&soft) {
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

    frame_ = thin_body::make_step_frame(model_, data_.step, previous, current, dt_s);
    out.broad_phase_hit = thin_body::broad_phase(model_, frame_, soft, data_);
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
    const thin_body::DisplacementCounts counts = thin_body::enforce_displacement(model_, frame_, soft, data_);
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

  [[nodiscard]] CollisionMethod method() const override {
    return model_.paired ? CollisionMethod::kPaired : CollisionMethod::kRay;
  }

 private:
  thin_body::CollisionModel model_;
  thin_body::CollisionData data_;
  thin_body::StepFrame frame_;
  const btSoftBody* soft_;
  bool had_contact_ = false;
};

}  // namespace

std::unique_ptr<ThinBodyCollision> make_paired_collision(const ToolNodes& tool, const btSoftBody& soft,
                                                         const ThinBodyCollisionParams& params) {
  return std::make_unique<ThinBodyCollisionImpl>(tool, soft, params, true);
}

std::unique_ptr<ThinBodyCollision> make_ray_collision(const ToolNodes& tool, const btSoftBody& soft,
                                                      const ThinBodyCollisionParams& params) {
  return std::make_unique<ThinBodyCollisionImpl>(tool, soft, params, false);
}

}  // namespace fissure::host
