#include "fissure/rt_core/rt_config.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace fissure::rt {
namespace {

TEST(RtConfig, DefaultsBuildAModelWithDerivedConstants) {
  RtModel model;
  const char* error = "unset";
  ASSERT_TRUE(build_model(RtConfig{}, model, &error));
  EXPECT_EQ(error, nullptr);
  EXPECT_EQ(model.period_ns, 1'000'000);
  EXPECT_DOUBLE_EQ(model.period_s, 1e-3);
  EXPECT_GT(model.velocity_lag_s, 0.002);
  EXPECT_LT(model.velocity_lag_s, 0.003);
  EXPECT_EQ(model.config.safety.max_force_n, 8.0);
}

TEST(RtConfig, EveryRateFrom500HzTo10kHzIsAccepted) {
  for (const double rate : {500.0, 1000.0, 2000.0, 4000.0, 8000.0, 10000.0}) {
    RtConfig config;
    config.rate_hz = rate;
    RtModel model;
    EXPECT_TRUE(build_model(config, model)) << rate;
    EXPECT_EQ(model.period_ns, static_cast<TimeNs>(std::llround(1e9 / rate)));
  }
}

TEST(RtConfig, BadFieldsAreNamed) {
  const auto error_of = [](const RtConfig& config) {
    const char* error = check_config(config);
    return std::string(error == nullptr ? "" : error);
  };
  RtConfig config;
  config.rate_hz = 200.0;
  EXPECT_NE(error_of(config).find("rate_hz"), std::string::npos);
  config = RtConfig{};
  config.safety.max_force_n = 9.0;  // above the Falcon's rating
  EXPECT_NE(error_of(config).find("safety.max_force_n"), std::string::npos);
  config = RtConfig{};
  config.safety.max_force_n = 5.0;  // a lower clamp the passivity controller was not told about
  EXPECT_NE(error_of(config).find("passivity.max_force_n"), std::string::npos);
  config.passivity.max_force_n = 5.0;
  EXPECT_EQ(error_of(config), "");
  config = RtConfig{};
  config.velocity.cutoff_hz = 600.0;  // above Nyquist at 1 kHz
  EXPECT_NE(error_of(config).find("velocity.cutoff_hz"), std::string::npos);
  config = RtConfig{};
  config.mapping.axis_permutation = {0, 1, 1};
  EXPECT_NE(error_of(config).find("mapping"), std::string::npos);
  config = RtConfig{};
  config.kinematics.encoder.radians_per_count = std::nan("");
  EXPECT_NE(error_of(config).find("kinematics.encoder"), std::string::npos);
  config = RtConfig{};
  config.proxy.blend_max_step_n = 0.0;
  EXPECT_NE(error_of(config).find("proxy.blend_max_step_n"), std::string::npos);
  RtModel model;
  const char* error = nullptr;
  EXPECT_FALSE(build_model(config, model, &error));
  EXPECT_NE(error, nullptr);
}

}  // namespace
}  // namespace fissure::rt
