#include "fissure/rt_core/rt_data.hpp"

namespace fissure::rt {

void reset_data(const RtModel& model, RtData& data) noexcept {
  data = RtData{};
  data.kinematics.p_device_m = model.config.safety.workspace_centre_device_m;
  start_ramp_in(data.safety, model.config.safety.ramp_in_s);
}

}  // namespace fissure::rt
